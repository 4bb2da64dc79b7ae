//! NPZ (numpy's zip of `.npy` arrays) of a view's line segments and of its
//! per-vertex fields, for dataset builders who load them with
//! `numpy.load`: one row per segment piece, or one value per vertex,
//! written whole or not at all. The arrays are built by the caller
//! ([`SegmentArrays`]); the `.npy` and zip encoding is `ndarray-npy`'s.

use std::io::Cursor;
use std::path::Path;

use ndarray::{Array, Array1, Array2, Array3, ShapeError};
use ndarray_npy::NpzWriter;

use crate::error::{Error, Result};
use crate::spec::feature_lines::ViewFields;

/// The segment pieces of one view, row by row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SegmentArrays {
    /// First end of each piece (world coordinates), `(n, 3)` float32.
    pub a: Vec<[f32; 3]>,
    /// Second end, `(n, 3)` float32.
    pub b: Vec<[f32; 3]>,
    /// The family or layer code of each piece, `(n,)` uint32.
    pub family: Vec<u32>,
    /// The segment's strength, `(n,)` float32.
    pub strength: Vec<f32>,
    /// 1 where the piece is visible, `(n,)` uint8.
    pub visible: Vec<u8>,
    /// The faces the segment lies on, `-1` past the last, `(n, 4)` int64.
    pub faces: Vec<[i64; 4]>,
    /// The chain of each piece, `(n,)` uint32.
    pub chain: Vec<u32>,
    /// The face the piece lies in (`-1` for a line on no face, such as a
    /// stroke traced on a volume), `(n,)` int64.
    pub face: Vec<i64>,
    /// The barycentric coordinates of each end in `face` (zero where
    /// none), `(n, 2, 3)` float32.
    pub bary: Vec<[[f32; 3]; 2]>,
    /// Where the lines of an animation keep their chains' identity across
    /// frames ([`crate::spec::coherence::ChainIds`]): each piece's chain's
    /// id, the same for a chain and its continuation in the frames before,
    /// `(n,)` uint32, written as `chain_id`.
    pub chain_id: Option<Vec<u32>>,
}

/// Writes `arrays` to `path` as an uncompressed NPZ (`a`, `b`, `family`,
/// `strength`, `visible`, `faces`, `chain`, `face`, `bary`, and the table
/// naming the codes of `family`: `family_codes` (uint32) and `family_names`
/// (`<U24`), [`crate::spec::feature_lines::family_codes`]), whole or not
/// at all.
///
/// # Errors
///
/// [`Error::InvalidArgument`] for arrays of unequal lengths, [`Error::Write`]
/// naming the file.
pub fn write_segments(path: &Path, arrays: &SegmentArrays) -> Result<()> {
    check_lengths(arrays)
        .map_err(|e| Error::InvalidArgument(format!("{}: {e}", path.display())))?;
    write(path, encode(arrays))
}

/// The bytes [`write_segments`] writes, for a caller that stores them
/// itself (the Python package's batches): the same bytes for the same
/// arrays, whoever writes them.
///
/// # Errors
///
/// [`Error::InvalidArgument`] for arrays of unequal lengths or an array the
/// encoder refuses.
pub fn segments_npz_bytes(arrays: &SegmentArrays) -> Result<Vec<u8>> {
    check_lengths(arrays).map_err(Error::InvalidArgument)?;
    encode(arrays).map_err(Error::InvalidArgument)
}

/// Equal lengths of every array, or what differs.
fn check_lengths(arrays: &SegmentArrays) -> std::result::Result<(), String> {
    let n = arrays.a.len();
    let lens = [
        arrays.b.len(),
        arrays.family.len(),
        arrays.strength.len(),
        arrays.visible.len(),
        arrays.faces.len(),
        arrays.chain.len(),
        arrays.face.len(),
        arrays.bary.len(),
        arrays.chain_id.as_ref().map_or(n, Vec::len),
    ];
    if lens.iter().any(|&l| l != n) {
        return Err(format!(
            "segment arrays of unequal lengths ({n} and {})",
            lens.map(|l| l.to_string()).join(", ")
        ));
    }
    Ok(())
}

/// A view's per-vertex fields ([`ViewFields`]: `ndotv`, `kr`, `dwkr`,
/// `q1`, each `(V,)` float32) as an uncompressed NPZ, whole or not at all.
///
/// # Errors
///
/// [`Error::InvalidArgument`] for fields of unequal lengths, [`Error::Write`]
/// naming the file.
pub fn write_fields(path: &Path, f: &ViewFields) -> Result<()> {
    if !fields_equal_lengths(f) {
        return Err(Error::InvalidArgument(format!(
            "{}: view fields of unequal lengths",
            path.display()
        )));
    }
    write(path, encode_fields(f))
}

/// The bytes [`write_fields`] writes (see [`segments_npz_bytes`]).
///
/// # Errors
///
/// [`Error::InvalidArgument`] for fields of unequal lengths.
pub fn fields_npz_bytes(f: &ViewFields) -> Result<Vec<u8>> {
    if !fields_equal_lengths(f) {
        return Err(Error::InvalidArgument(
            "view fields of unequal lengths".into(),
        ));
    }
    encode_fields(f).map_err(Error::InvalidArgument)
}

fn fields_equal_lengths(f: &ViewFields) -> bool {
    let n = f.ndotv.len();
    [f.kr.len(), f.dwkr.len(), f.q1.len()]
        .iter()
        .all(|&l| l == n)
}

/// The NPZ bytes of `f` (of equal lengths).
fn encode_fields(f: &ViewFields) -> std::result::Result<Vec<u8>, String> {
    let mut npz = Npz::new();
    for (name, v) in [
        ("ndotv", &f.ndotv),
        ("kr", &f.kr),
        ("dwkr", &f.dwkr),
        ("q1", &f.q1),
    ] {
        npz.add(name, &Array1::from(v.clone()));
    }
    npz.finish()
}

/// Writes encoded bytes, or the encoder's error naming the file.
fn write(path: &Path, bytes: std::result::Result<Vec<u8>, String>) -> Result<()> {
    let bytes = bytes.map_err(|e| Error::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })?;
    crate::output::write_bytes_atomic(path, &bytes)
}

/// An NPZ in memory; the first error of any step is kept and given by
/// [`Npz::finish`].
struct Npz {
    w: NpzWriter<Cursor<Vec<u8>>>,
    err: Option<String>,
}

impl Npz {
    fn new() -> Npz {
        Npz {
            w: NpzWriter::new(Cursor::new(Vec::new())),
            err: None,
        }
    }

    /// Adds `array` as `name.npy`.
    fn add<S, D>(&mut self, name: &str, array: &ndarray::ArrayBase<S, D>)
    where
        S: ndarray::Data,
        S::Elem: ndarray_npy::WritableElement,
        D: ndarray::Dimension,
    {
        if self.err.is_none()
            && let Err(e) = self.w.add_array(name, array)
        {
            self.err = Some(format!("{name}: {e}"));
        }
    }

    /// Adds a shaped array, or keeps the shape error.
    fn add_shaped<T, D>(&mut self, name: &str, a: std::result::Result<Array<T, D>, ShapeError>)
    where
        T: ndarray_npy::WritableElement,
        D: ndarray::Dimension,
    {
        match a {
            Ok(a) => self.add(name, &a),
            Err(e) => {
                self.err.get_or_insert(format!("{name}: {e}"));
            }
        }
    }

    fn finish(self) -> std::result::Result<Vec<u8>, String> {
        if let Some(e) = self.err {
            return Err(e);
        }
        let cursor = self.w.finish().map_err(|e| e.to_string())?;
        Ok(cursor.into_inner())
    }
}

/// The NPZ bytes of `arrays` (of equal lengths).
fn encode(arrays: &SegmentArrays) -> std::result::Result<Vec<u8>, String> {
    let n = arrays.a.len();
    let mut npz = Npz::new();
    npz.add_shaped("a", Array2::from_shape_vec((n, 3), arrays.a.concat()));
    npz.add_shaped("b", Array2::from_shape_vec((n, 3), arrays.b.concat()));
    npz.add("family", &Array1::from(arrays.family.clone()));
    npz.add("strength", &Array1::from(arrays.strength.clone()));
    npz.add("visible", &Array1::from(arrays.visible.clone()));
    npz.add_shaped(
        "faces",
        Array2::from_shape_vec((n, 4), arrays.faces.concat()),
    );
    npz.add("chain", &Array1::from(arrays.chain.clone()));
    npz.add("face", &Array1::from(arrays.face.clone()));
    let bary: Vec<f32> = arrays.bary.iter().flatten().flatten().copied().collect();
    npz.add_shaped("bary", Array3::from_shape_vec((n, 2, 3), bary));
    if let Some(ids) = &arrays.chain_id {
        npz.add("chain_id", &Array1::from(ids.clone()));
    }
    // The code-to-name table of `family`, in every file.
    let table = crate::spec::feature_lines::family_codes();
    npz.add(
        "family_codes",
        &Array1::from(table.iter().map(|t| t.0).collect::<Vec<u32>>()),
    );
    npz.add(
        "family_names",
        &Array1::from(table.iter().map(|t| Name::of(t.1)).collect::<Vec<Name>>()),
    );
    npz.finish()
}

/// A family name as a NumPy unicode string of [`Name::CHARS`] characters
/// (`<U24`, UCS-4), so that `numpy.load` gives the names as `str`s.
#[derive(Clone, Copy)]
struct Name([u32; Name::CHARS]);

impl Name {
    const CHARS: usize = 24;

    /// `s`, cut at [`Name::CHARS`] characters (every family name is shorter).
    fn of(s: &str) -> Name {
        let mut n = [0u32; Name::CHARS];
        for (slot, c) in n.iter_mut().zip(s.chars()) {
            *slot = c as u32;
        }
        Name(n)
    }
}

impl ndarray_npy::WritableElement for Name {
    fn type_descriptor() -> py_literal::Value {
        py_literal::Value::String(format!("<U{}", Name::CHARS))
    }

    fn write<W: std::io::Write>(
        &self,
        mut w: W,
    ) -> std::result::Result<(), ndarray_npy::WriteDataError> {
        for c in self.0 {
            w.write_all(&c.to_le_bytes())?;
        }
        Ok(())
    }

    fn write_slice<W: std::io::Write>(
        slice: &[Self],
        mut w: W,
    ) -> std::result::Result<(), ndarray_npy::WriteDataError> {
        for n in slice {
            n.write(&mut w)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_npz_holds_each_array_under_its_name_and_unequal_lengths_are_refused() {
        let arrays = SegmentArrays {
            a: vec![[0.0, 1.0, 2.0]],
            b: vec![[3.0, 4.0, 5.0]],
            family: vec![2],
            strength: vec![0.5],
            visible: vec![1],
            faces: vec![[7, -1, -1, -1]],
            chain: vec![0],
            face: vec![7],
            bary: vec![[[1.0, 0.0, 0.0], [0.0, 0.5, 0.5]]],
            chain_id: None,
        };
        let bytes = encode(&arrays).unwrap();
        // A zip (local file header) holding the nine .npy files.
        assert_eq!(&bytes[..4], b"PK\x03\x04");
        let names = [
            "a",
            "b",
            "family",
            "strength",
            "visible",
            "faces",
            "chain",
            "face",
            "bary",
            "family_codes",
            "family_names",
        ];
        for name in names {
            let entry = format!("{name}.npy");
            assert!(
                bytes.windows(entry.len()).any(|w| w == entry.as_bytes()),
                "{name}"
            );
        }
        let dir = std::env::temp_dir().join(format!("shapecue-npz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("x.npz");
        let mut bad = arrays.clone();
        bad.chain.clear();
        let e = write_segments(&p, &bad).unwrap_err().to_string();
        assert!(e.contains("unequal") && e.contains("x.npz"), "{e}");
        assert!(!p.exists());
        write_segments(&p, &arrays).unwrap();
        assert!(std::fs::metadata(&p).unwrap().len() > 100);
        let f = dir.join("f.npz");
        let mut fields = ViewFields {
            ndotv: vec![0.5, -0.5],
            kr: vec![1.0, 2.0],
            dwkr: vec![0.0, 1.0],
            q1: vec![3.0, 4.0],
        };
        write_fields(&f, &fields).unwrap();
        assert!(std::fs::metadata(&f).unwrap().len() > 100);
        fields.q1.pop();
        std::fs::remove_file(&f).unwrap();
        assert!(write_fields(&f, &fields).is_err());
        assert!(!f.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
