//! PLY output: the mesh with, optionally, every per-vertex curvature quantity,
//! as `binary_little_endian` with `float` properties.
//!
//! Vertex properties, in order: `x y z` ([`POSITION_PROPERTIES`]), then with a
//! field `nx ny nz area k1 k2 d1x d1y d1z d2x d2y d2z dk0 dk1 dk2 dk3`
//! ([`FIELD_PROPERTIES`]). Faces: `property list uchar int vertex_indices`.

use std::io::{BufWriter, Write};
use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, PropertyType};

use super::output::OutputFile;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::spec::curvature::{CurvatureField, VertexCurvature};

/// Names of the vertex position properties, first in every file.
pub const POSITION_PROPERTIES: [&str; 3] = ["x", "y", "z"];

/// Names of the per-vertex curvature properties written after the position
/// when a field is given, in file order.
pub const FIELD_PROPERTIES: [&str; 16] = [
    "nx", "ny", "nz", "area", "k1", "k2", "d1x", "d1y", "d1z", "d2x", "d2y", "d2z", "dk0", "dk1",
    "dk2", "dk3",
];

/// What [`write_ply`] wrote.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlyWritten {
    /// `Some(why)` when the vertex properties were written as `double`
    /// because a value lies outside the range of `float` (it would have
    /// become infinite or zero); names the property, the vertex and the value.
    pub double: Option<String>,
}

/// Writes `mesh` (and `field`, when given) to `path` as a binary
/// little-endian PLY file with `float` vertex properties, or `double` ones
/// when a value does not fit a `float` (see [`PlyWritten`]): a value is
/// never written as infinity or flushed to zero.
///
/// # Errors
///
/// [`Error::InvalidArgument`] when the field's arrays do not all have one
/// entry per vertex, a face index does not fit a PLY `int`, or a value is
/// not finite (named with its property and vertex);
/// [`Error::Write`] when the file cannot be created or written.
pub fn write_ply(path: &Path, mesh: &Mesh, field: Option<&CurvatureField>) -> Result<PlyWritten> {
    let n = mesh.n_vertices();
    if let Some(f) = field {
        let lens = [
            ("normals", f.normals.len()),
            ("areas", f.areas.len()),
            ("k1", f.k1.len()),
            ("k2", f.k2.len()),
            ("d1", f.d1.len()),
            ("d2", f.d2.len()),
            ("dk", f.dk.len()),
        ];
        if let Some((what, len)) = lens.iter().find(|(_, len)| *len != n) {
            return Err(Error::InvalidArgument(format!(
                "curvature field '{what}' has {len} entries for a mesh of {n} vertices"
            )));
        }
    }
    match field {
        Some(f) => write_ply_vertices(path, mesh, n, |i| f.vertex(i)),
        None => {
            check_face_indices(mesh)?;
            write_rows(path, mesh, &POSITION_PROPERTIES, |_, _| {})
        }
    }
}

/// [`write_ply`] with a field given vertex by vertex: `vertex(i)` gives the
/// values of vertex `i` of the `n` (e.g. read in place from the device
/// buffers, with no copy of the whole field). Each vertex is asked for once,
/// its values checked as they are written; twice when a value needs the
/// file started again as `double`.
///
/// # Errors
///
/// As [`write_ply`]; [`Error::InvalidArgument`] also when `n` is not the
/// mesh's number of vertices.
pub fn write_ply_vertices(
    path: &Path,
    mesh: &Mesh,
    n: usize,
    vertex: impl Fn(usize) -> VertexCurvature,
) -> Result<PlyWritten> {
    if n != mesh.n_vertices() {
        return Err(Error::InvalidArgument(format!(
            "a curvature field of {n} vertices for a mesh of {} vertices",
            mesh.n_vertices()
        )));
    }
    check_face_indices(mesh)?;
    let names: Vec<&str> = POSITION_PROPERTIES
        .iter()
        .chain(&FIELD_PROPERTIES)
        .copied()
        .collect();
    write_rows(path, mesh, &names, |i, row| {
        row.copy_from_slice(&vertex(i).row());
    })
}

/// Writes `mesh` with per-vertex normals (`x y z nx ny nz`), e.g. an
/// isosurface with normals from the volume gradient.
///
/// # Errors
///
/// As [`write_ply`]; also when `normals` does not have one entry per vertex.
pub fn write_ply_with_normals(
    path: &Path,
    mesh: &Mesh,
    normals: &[[f64; 3]],
) -> Result<PlyWritten> {
    if normals.len() != mesh.n_vertices() {
        return Err(Error::InvalidArgument(format!(
            "{} normals for a mesh of {} vertices",
            normals.len(),
            mesh.n_vertices()
        )));
    }
    check_face_indices(mesh)?;
    write_rows(path, mesh, &["x", "y", "z", "nx", "ny", "nz"], |i, row| {
        row.copy_from_slice(&normals[i]);
    })
}

fn check_face_indices(mesh: &Mesh) -> Result<()> {
    if let Some(v) = mesh
        .faces
        .iter()
        .flatten()
        .find(|&&v| i32::try_from(v).is_err())
    {
        return Err(Error::InvalidArgument(format!(
            "face index {v} does not fit the PLY 'int' face list"
        )));
    }
    Ok(())
}

/// The bits of `|x|` (ordered as `|x|` is, NaN above infinity).
fn abs_bits(x: f64) -> u64 {
    x.to_bits() & !(1 << 63)
}

/// True when `x` is finite (as [`f64::is_finite`], on the bits, so that a
/// loop over many values needs no branch).
fn fits_f64(x: f64) -> bool {
    abs_bits(x) < f64::INFINITY.to_bits()
}

/// True when `x` is finite and at most `f32`'s largest magnitude, so that it
/// is written as a `float` (beyond, it would become infinite, and the file
/// is written as `double`). Values below `f32`'s smallest normal are written
/// as the nearest `float` (a subnormal, or zero): their absolute error is
/// under 1.2e-38, where a file of doubles would be twice as large for
/// nothing. On the bits, as [`fits_f64`].
fn fits_f32(x: f64) -> bool {
    const HI: u64 = (f32::MAX as f64).to_bits();
    abs_bits(x) <= HI
}

/// Writes the header, one row of properties per vertex (position first,
/// then what `extra` fills in) and the faces; `float` unless a value needs
/// `double`, in which case the file is started again with `double`. One pass
/// over the values when they all fit a `float` (the usual case): each value
/// is checked as it is written, and a value that is not finite stops the
/// write, leaving no file.
fn write_rows(
    path: &Path,
    mesh: &Mesh,
    names: &[&str],
    extra: impl Fn(usize, &mut [f64]),
) -> Result<PlyWritten> {
    let mut written = PlyWritten::default();
    let write_err = |source| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    super::output::write_atomic(path, |w| {
        if let Some(why) = write_body(w, path, mesh, names, &extra, false)? {
            w.flush().map_err(write_err)?;
            w.get_mut().restart().map_err(write_err)?;
            write_body(w, path, mesh, names, &extra, true)?;
            written.double = Some(why);
        }
        Ok(())
    })?;
    Ok(written)
}

/// Vertices converted and written per block: small enough for the values
/// and their bytes to stay in cache, large enough that the per-block work
/// (a check, a conversion loop, one buffered write) runs over many values.
const BLOCK_VERTICES: usize = 1024;

/// The bytes of [`write_rows`], into a writer: `Some(why)` (and the file
/// left unfinished) when a value does not fit the `float` asked for.
///
/// `extra(i, row)` fills the values after the position of vertex `i`
/// (`names.len() - 3` of them). Vertices go in blocks of
/// [`BLOCK_VERTICES`]: their values gathered, checked in one loop, then
/// converted in one loop; the faces in blocks of 13-byte records.
fn write_body(
    w: &mut BufWriter<OutputFile>,
    path: &Path,
    mesh: &Mesh,
    names: &[&str],
    extra: &impl Fn(usize, &mut [f64]),
    double: bool,
) -> Result<Option<String>> {
    let write_err = |source| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    w.write_all(header(mesh, names, double).as_bytes())
        .map_err(write_err)?;
    let cols = names.len();
    let width = if double { 8 } else { 4 };
    let mut vals = vec![0.0f64; BLOCK_VERTICES * cols];
    let mut bytes = vec![0u8; BLOCK_VERTICES * cols * width];
    for (b, block) in mesh.positions.chunks(BLOCK_VERTICES).enumerate() {
        let first = b * BLOCK_VERTICES;
        let vals = &mut vals[..block.len() * cols];
        for (k, (row, p)) in vals.chunks_exact_mut(cols).zip(block).enumerate() {
            row[..3].copy_from_slice(p);
            extra(first + k, &mut row[3..]);
        }
        if let Some(why) = check_block(vals, first, names, path, double)? {
            return Ok(Some(why));
        }
        let bytes = &mut bytes[..vals.len() * width];
        encode(vals, bytes, double);
        w.write_all(bytes).map_err(write_err)?;
    }
    write_faces(w, path, mesh)?;
    Ok(None)
}

/// The PLY header: the vertex properties, all `float` or all `double`, and
/// the face index lists.
fn header(mesh: &Mesh, names: &[&str], double: bool) -> String {
    let n = mesh.n_vertices();
    let ty = if double { "double" } else { "float" };
    let mut header = String::new();
    header.push_str("ply\nformat binary_little_endian 1.0\ncomment written by shapecue\n");
    header.push_str(&format!("element vertex {n}\n"));
    for name in names {
        header.push_str(&format!("property {ty} {name}\n"));
    }
    header.push_str(&format!("element face {}\n", mesh.n_faces()));
    header.push_str("property list uchar int vertex_indices\nend_header\n");
    header
}

/// Checks a block of values (rows of `names.len()`, the first of vertex
/// `first`): an error for a value that is not finite, `Some(why)` for one
/// outside the range of `float` when `float` is written, else `None`.
fn check_block(
    vals: &[f64],
    first: usize,
    names: &[&str],
    path: &Path,
    double: bool,
) -> Result<Option<String>> {
    // The common case, all finite and (for float) all in range, is one
    // branch-free pass over the values' bits; the first value that is
    // not is then found.
    let fine = if double {
        vals.iter().fold(true, |ok, &x| ok & fits_f64(x))
    } else {
        vals.iter().fold(true, |ok, &x| ok & fits_f32(x))
    };
    if fine {
        return Ok(None);
    }
    let cols = names.len();
    let at = vals
        .iter()
        .position(|&x| if double { !fits_f64(x) } else { !fits_f32(x) })
        .expect("a value that is not fine");
    let (i, k, x) = (first + at / cols, at % cols, vals[at]);
    if !x.is_finite() {
        return Err(Error::InvalidArgument(format!(
            "{}: property '{}' of vertex {i} is {x}: not written",
            path.display(),
            names[k]
        )));
    }
    Ok(Some(format!(
        "property '{}' of vertex {i} is {x:e}, outside the range of float \
         (about 1.2e-38 to 3.4e38)",
        names[k]
    )))
}

/// Converts checked values to little-endian `double` or `float` bytes.
fn encode(vals: &[f64], bytes: &mut [u8], double: bool) {
    if double {
        for (o, x) in bytes.chunks_exact_mut(8).zip(vals.iter()) {
            o.copy_from_slice(&x.to_le_bytes());
        }
    } else {
        for (o, &x) in bytes.chunks_exact_mut(4).zip(vals.iter()) {
            o.copy_from_slice(&(x as f32).to_le_bytes());
        }
    }
}

/// Writes the faces, in blocks of 13-byte records (a count of 3 and three
/// `int` indices).
fn write_faces(w: &mut BufWriter<OutputFile>, path: &Path, mesh: &Mesh) -> Result<()> {
    const REC: usize = 13;
    let mut recs = vec![0u8; BLOCK_VERTICES * REC];
    for block in mesh.faces.chunks(BLOCK_VERTICES) {
        let recs = &mut recs[..block.len() * REC];
        for (rec, face) in recs.chunks_exact_mut(REC).zip(block) {
            rec[0] = 3;
            for (k, &v) in face.iter().enumerate() {
                // Checked above to fit an i32, so the u32 bytes are the i32 bytes.
                rec[1 + 4 * k..5 + 4 * k].copy_from_slice(&v.to_le_bytes());
            }
        }
        w.write_all(recs).map_err(|source| Error::Write {
            path: path.to_path_buf(),
            source,
        })?;
    }
    Ok(())
}

/// The contents of a PLY file as [`read_ply_properties`] returns them: the
/// vertex property names in file order, one row of values per vertex (in the
/// same order, converted to `f32`) and the faces, fan-triangulated.
pub type PlyProperties = (Vec<String>, Vec<Vec<f32>>, Vec<[u32; 3]>);

/// Reads back any PLY file (used by tests to check what [`write_ply`] wrote):
/// the names of the scalar properties of element `vertex` in file order, their
/// values per vertex, and the faces of element `face` (`vertex_indices` or
/// `vertex_index`), fan-triangulated.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read; [`Error::InvalidInput`] when it
/// is not a well-formed PLY file or a face has fewer than three or negative
/// indices.
pub fn read_ply_properties(path: &Path) -> Result<PlyProperties> {
    let source = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let flat = |s: String| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut &bytes[..])
        .map_err(|e| Error::input(&source, "file", flat(e.to_string())))?;

    let names: Vec<String> = ply
        .header
        .elements
        .get("vertex")
        .map(|def| {
            def.properties
                .values()
                .filter(|p| matches!(p.data_type, PropertyType::Scalar(_)))
                .map(|p| p.name.clone())
                .collect()
        })
        .unwrap_or_default();

    let mut rows = Vec::new();
    for (i, v) in ply.payload.get("vertex").into_iter().flatten().enumerate() {
        let row = names
            .iter()
            .map(|n| v.get(n).and_then(|p| p.to_f32_lossy()))
            .collect::<Option<Vec<f32>>>()
            .ok_or_else(|| Error::input(&source, format!("vertex {i}"), "missing property"))?;
        rows.push(row);
    }

    let mut faces = Vec::new();
    for (i, f) in ply.payload.get("face").into_iter().flatten().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(|p| p.to_u32_list())
            .ok_or_else(|| {
                Error::input(
                    &source,
                    format!("face {i}"),
                    "no list of non-negative integer vertex indices",
                )
            })?;
        if list.len() < 3 {
            return Err(Error::input(
                &source,
                format!("face {i}"),
                format!("{} vertex indices; a face needs at least 3", list.len()),
            ));
        }
        for k in 1..list.len() - 1 {
            faces.push([list[0], list[k], list[k + 1]]);
        }
    }
    Ok((names, rows, faces))
}

#[cfg(test)]
mod tests {
    use super::{fits_f32, fits_f64};

    /// The range test written plainly, as the bit tests must agree with.
    fn plain_fits_f32(x: f64) -> bool {
        x.is_finite() && x.abs() <= f64::from(f32::MAX)
    }

    #[test]
    fn bit_range_tests_agree_with_the_plain_ones() {
        let max = f64::from(f32::MAX);
        let min = f64::from(f32::MIN_POSITIVE);
        let mut xs = vec![
            0.0,
            1.0,
            1e-300,
            1e300,
            max,
            min,
            f64::from(f32::MIN_POSITIVE / 2.0),
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::INFINITY,
            f64::NAN,
            -f64::NAN,
        ];
        for x in [max, min] {
            xs.extend([x.next_up(), x.next_down()]);
        }
        for x in xs.clone() {
            xs.push(-x);
        }
        for x in xs {
            assert_eq!(fits_f32(x), plain_fits_f32(x), "{x:e}");
            assert_eq!(fits_f64(x), x.is_finite(), "{x:e}");
        }
    }
}
