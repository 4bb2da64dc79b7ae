//! Mesh loaders: Wavefront OBJ (by hand), PLY in ASCII and both binary
//! byte orders (through `ply-rs-bw`) and OFF (by hand).
//!
//! Every loader fan-triangulates polygons, keeps degenerate faces and faces
//! with repeated indices (they are valid input), and reports bad input as
//! [`Error::InvalidInput`] naming the file, the element (`vertex 12`,
//! `face 7`, `header`) and, for text formats, the line.

use std::path::Path;

use super::Mesh;
use crate::error::{Error, Result};

/// How [`load`] post-processes a mesh.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Merge vertices with bit-identical positions (see [`Mesh::weld`]), as
    /// needed for exports that split vertices per corner or per UV seam.
    pub weld: bool,
    /// Keep the normals the file stores ([`NormalsSource::File`], checked
    /// by [`Mesh::check_normals`]) or drop them.
    pub normals: NormalsSource,
}

/// Where the vertex normals that curvature (and so every line family) starts
/// from come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum NormalsSource {
    /// The normals the mesh file stores (OBJ `vn`, PLY `nx ny nz`), as
    /// trimesh2 reads them and rtsc uses them; computed where the file
    /// stores none, and on animations (a file's normals are its rest pose's).
    #[default]
    File,
    /// Always computed from the faces (area-weighted), whatever the file
    /// stores.
    Computed,
}

impl NormalsSource {
    /// Both choices, in the order `--help` lists them.
    pub const ALL: [NormalsSource; 2] = [NormalsSource::File, NormalsSource::Computed];

    /// The name used on the command line (`--normals`), in scenes and stats.
    pub fn name(self) -> &'static str {
        match self {
            NormalsSource::File => "file",
            NormalsSource::Computed => "computed",
        }
    }
}

crate::spec::named_choice!(NormalsSource, "normals source");

/// Loads a triangle mesh from an `.obj`, `.ply` or `.off` file (extension
/// matched case-insensitively), welds it if asked, and validates it.
///
/// Polygons are fan-triangulated. OBJ vertices keep the order of the file.
/// Stored vertex normals are kept as trimesh2 2.16 reads them (OBJ `vn`
/// lines in order when there is one per vertex, PLY `nx ny nz`; OFF stores
/// none) and checked, or dropped, as `opts.normals` says. OBJ texture
/// coordinates, groups and materials are ignored, as are any other PLY and
/// OFF properties.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read, [`Error::UnsupportedFormat`]
/// for an unknown extension, and [`Error::InvalidInput`] (naming the file and
/// the element) for malformed or truncated content, faces with fewer than
/// three indices, negative or out-of-range indices, non-finite coordinates or
/// a mesh without faces.
pub fn load(path: &Path, opts: &LoadOptions) -> Result<Mesh> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let parse: fn(&[u8], &str) -> Result<Mesh> = match ext.as_deref() {
        Some("obj") => obj::parse,
        Some("ply") => ply::parse,
        Some("off") => off::parse,
        Some(other) => {
            return Err(Error::UnsupportedFormat {
                path: path.to_path_buf(),
                problem: format!(
                    "unknown extension '.{other}' (shapecue reads .obj, .ply and .off)"
                ),
            });
        }
        None => {
            let what = if path.is_dir() {
                "a folder, not a mesh file"
            } else {
                "no file extension"
            };
            return Err(Error::UnsupportedFormat {
                path: path.to_path_buf(),
                problem: format!("{what} (shapecue reads .obj, .ply and .off)"),
            });
        }
    };
    let mut mesh = if ext.as_deref() == Some("ply") {
        ply::load(path, &name)?
    } else {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        parse(&bytes, &name)?
    };
    // Validate before welding: `Mesh::weld` indexes with the face indices.
    mesh.validate(&name)?;
    match opts.normals {
        NormalsSource::File => mesh.check_normals(&name)?,
        NormalsSource::Computed => mesh.normals = None,
    }
    if opts.weld {
        mesh = mesh.weld().0;
    }
    Ok(mesh)
}

/// Several mesh files as one mesh ([`Mesh::concat`], `what` naming it in
/// errors), with each file's face count in order.
///
/// # Errors
/// As [`load`] for each file, and as [`Mesh::concat`].
pub fn load_several(
    paths: &[std::path::PathBuf],
    opts: &LoadOptions,
    what: &str,
) -> Result<(Mesh, Vec<usize>)> {
    let meshes = (paths.iter())
        .map(|p| load(p, opts))
        .collect::<Result<Vec<_>>>()?;
    let counts = meshes.iter().map(Mesh::n_faces).collect();
    Ok((Mesh::concat(&meshes, what)?, counts))
}

/// The vertex and face (polygon) counts that a PLY or OFF file's header
/// declares, read from the header alone: a cheap check of a file's size
/// before it is loaded (a flipbook's frames against its first). `None` for
/// OBJ, which has no header, and for a header these counts cannot be read
/// from (loading the file reports what is wrong with it).
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be opened or read.
pub fn header_counts(path: &Path) -> Result<Option<(usize, usize)>> {
    use std::io::Read;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let open = || {
        std::fs::File::open(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })
    };
    match ext.as_deref() {
        Some("ply") => Ok(ply::header_counts(std::io::BufReader::new(open()?))),
        Some("off") => {
            // The counts are on the first lines after comments; 64 KiB
            // holds them in any file whose comments are not a book.
            let mut head = Vec::new();
            open()?
                .take(64 << 10)
                .read_to_end(&mut head)
                .map_err(|source| Error::Io {
                    path: path.to_path_buf(),
                    source,
                })?;
            Ok(off::header_counts(&head))
        }
        _ => Ok(None),
    }
}

/// Appends the fan triangulation of `poly` (at least three indices) to `faces`.
fn fan(poly: &[u32], faces: &mut Vec<[u32; 3]>) {
    if let Some((&first, rest)) = poly.split_first() {
        for w in rest.windows(2) {
            faces.push([first, w[0], w[1]]);
        }
    }
}

/// Capacity to reserve for `declared` elements of at least `min_bytes` each
/// in a file of `len` bytes, so that a lying header cannot make us allocate
/// more than the file could hold.
fn capped(declared: usize, len: usize, min_bytes: usize) -> usize {
    declared.min(len / min_bytes.max(1) + 1)
}

/// Converts a vertex index read from a file, checking it against the number
/// of vertices the file declares. `element` names the face.
fn vertex_index(
    value: i64,
    n_vertices: usize,
    source: &str,
    element: impl FnOnce() -> String,
) -> Result<u32> {
    if value < 0 {
        return Err(Error::input(
            source,
            element(),
            format!("negative vertex index {value}"),
        ));
    }
    match u32::try_from(value) {
        Ok(v) if (v as usize) < n_vertices => Ok(v),
        _ => Err(Error::input(
            source,
            element(),
            format!("vertex index {value} out of range (the file has {n_vertices} vertices)"),
        )),
    }
}

/// Hand-written OFF reader (`OFF`, `COFF`, `NOFF`, `STOFF`, ... ASCII only).
mod off;

/// PLY reader: the header through `ply-rs-bw`; ASCII payloads one element at
/// a time through it, so that errors name the element and the line; binary
/// payloads read directly from the bytes, a chunk of the file at a time.
mod ply;

/// OBJ reader, by hand: one pass over the bytes reading `v` and `f`
/// statements. `tobj`, which the tests compare it with, numbers vertices in
/// order of first use; with the extra work of keeping the file's order it
/// took 3.3 times as long on the Stanford bunny and 5.3 times on a 500k-vertex
/// torus (`cargo bench --bench mesh_io`). A file it stops on is read again as
/// text to name the element, the line and the problem.
mod obj;

#[cfg(test)]
mod tests {
    use super::ply;

    const HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n";

    #[test]
    fn ascii_ply_line_with_an_extra_value_is_an_error_naming_the_line() {
        let good = format!("{HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        assert_eq!(ply::parse(good.as_bytes(), "t.ply").unwrap().faces.len(), 1);
        let bad = format!("{HEAD}0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n");
        let e = ply::parse(bad.as_bytes(), "t.ply").unwrap_err().to_string();
        assert!(
            e.contains("t.ply") && e.contains("vertex 1") && e.contains("line 11"),
            "{e}"
        );
        let bad_face = format!("{HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2 2\n");
        let e = ply::parse(bad_face.as_bytes(), "t.ply")
            .unwrap_err()
            .to_string();
        assert!(e.contains("face 0"), "{e}");
    }

    #[test]
    fn non_text_header_names_the_line() {
        let mut bytes = b"ply\nformat ascii 1.0\ncomment caf".to_vec();
        bytes.extend_from_slice(&[0xe9, b'\n']);
        bytes.extend_from_slice(&HEAD.as_bytes()[20..]);
        let e = ply::parse(&bytes, "t.ply").unwrap_err().to_string();
        assert!(e.contains("header line 3") && e.contains("0xe9"), "{e}");
    }

    /// A binary PLY file with `nv` vertices of 25 bytes (x y z, a normal, a
    /// flag) and `nv` faces (triangles and quads, with a property after the
    /// list), behind a header of `comments` comment lines.
    fn binary_ply(nv: usize, comments: usize, big: bool) -> Vec<u8> {
        let order = if big { "big" } else { "little" };
        let mut h = format!("ply\nformat binary_{order}_endian 1.0\n");
        for i in 0..comments {
            h.push_str(&format!("comment line {i} of a long header\n"));
        }
        h.push_str(&format!(
            "element vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\nproperty uchar flag\n\
             element face {nv}\nproperty list uchar int vertex_indices\nproperty int flags\n\
             end_header\n"
        ));
        let mut b = h.into_bytes();
        let f = |x: f32| {
            if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        let i = |x: i32| {
            if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        for v in 0..nv {
            let t = v as f32;
            for x in [t, 0.5 * t, (t * 0.01).sin(), 0.0, 0.0, 1.0] {
                b.extend(f(x));
            }
            b.push(7);
        }
        for k in 0..nv {
            let n = if k % 5 == 0 { 4 } else { 3 };
            b.push(n as u8);
            for c in 0..n {
                b.extend(i(((k + c) % nv) as i32));
            }
            b.extend(i(-1));
        }
        b
    }

    /// Loading a PLY file a chunk at a time gives what parsing its bytes
    /// whole gives: the same mesh, or the same error, for files spanning
    /// many chunks, headers longer than one read, both byte orders, and
    /// files cut anywhere (in the header, a row, a face list, between
    /// chunks).
    #[test]
    fn chunked_ply_load_matches_parsing_the_bytes() {
        let dir = std::env::temp_dir().join(format!("shapecue-ply-chunks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("m.ply");
        let check = |bytes: &[u8], what: &str| {
            std::fs::write(&path, bytes).unwrap();
            let whole = ply::parse(bytes, "m.ply");
            let chunked = ply::load(&path, "m.ply");
            match (whole, chunked) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a.positions, b.positions, "{what}");
                    assert_eq!(a.faces, b.faces, "{what}");
                    a.faces.len()
                }
                (Err(a), Err(b)) => {
                    assert_eq!(a.to_string(), b.to_string(), "{what}");
                    0
                }
                (a, b) => panic!("{what}: whole {:?}, chunked {:?}", a.err(), b.err()),
            }
        };
        for (nv, comments, big) in [(120_000, 0, false), (90_001, 3000, true), (5, 0, false)] {
            let b = binary_ply(nv, comments, big);
            let faces = check(&b, "whole file");
            assert_eq!(faces, nv + nv.div_ceil(5), "quads give two triangles");
            let body = b.len() - (25 + 17) * nv - nv.div_ceil(5) * 4;
            let cuts = [
                10,
                body - 3,
                body + 25 * (nv / 2) + 11,
                body + 25 * nv + 2,
                body + 25 * nv + 1 + 4 + 17 * (nv / 3),
                b.len() - 1,
                (1 << 20) + 1,
            ];
            for cut in cuts.into_iter().filter(|&c| c < b.len()) {
                check(&b[..cut], &format!("{nv} vertices cut at {cut}"));
            }
        }
        // An ASCII file through the same entry point.
        let ascii = format!("{HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        assert_eq!(check(ascii.as_bytes(), "ascii"), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
