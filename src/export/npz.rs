//! NPZ (numpy's zip of `.npy` arrays) of a view's line segments, for
//! dataset builders who load them with `numpy.load`: one row per segment
//! piece, written whole or not at all. The arrays are built by the caller
//! ([`SegmentArrays`]); the `.npy` and zip encoding is `ndarray-npy`'s.

use std::io::Cursor;
use std::path::Path;

use ndarray::{Array1, Array2};
use ndarray_npy::NpzWriter;

use crate::error::{Error, Result};

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
}

/// Writes `arrays` to `path` as an uncompressed NPZ (`a`, `b`, `family`,
/// `strength`, `visible`, `faces`, `chain`), whole or not at all.
///
/// # Errors
///
/// [`Error::InvalidArgument`] for arrays of unequal lengths, [`Error::Write`]
/// naming the file.
pub fn write_segments(path: &Path, arrays: &SegmentArrays) -> Result<()> {
    let n = arrays.a.len();
    let lens = [
        arrays.b.len(),
        arrays.family.len(),
        arrays.strength.len(),
        arrays.visible.len(),
        arrays.faces.len(),
        arrays.chain.len(),
    ];
    if lens.iter().any(|&l| l != n) {
        return Err(Error::InvalidArgument(format!(
            "{}: segment arrays of unequal lengths ({n} and {lens:?})",
            path.display()
        )));
    }
    let bytes = encode(arrays).map_err(|e| Error::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })?;
    crate::output::write_bytes_atomic(path, &bytes)
}

/// The NPZ bytes of `arrays` (of equal lengths).
fn encode(arrays: &SegmentArrays) -> std::result::Result<Vec<u8>, String> {
    let n = arrays.a.len();
    let rows3 = |v: &[[f32; 3]]| Array2::from_shape_vec((n, 3), v.concat());
    let faces = Array2::from_shape_vec((n, 4), arrays.faces.concat());
    let mut npz = NpzWriter::new(Cursor::new(Vec::new()));
    let e = |e: &dyn std::fmt::Display| e.to_string();
    npz.add_array("a", &rows3(&arrays.a).map_err(|x| e(&x))?)
        .map_err(|x| e(&x))?;
    npz.add_array("b", &rows3(&arrays.b).map_err(|x| e(&x))?)
        .map_err(|x| e(&x))?;
    npz.add_array("family", &Array1::from(arrays.family.clone()))
        .map_err(|x| e(&x))?;
    npz.add_array("strength", &Array1::from(arrays.strength.clone()))
        .map_err(|x| e(&x))?;
    npz.add_array("visible", &Array1::from(arrays.visible.clone()))
        .map_err(|x| e(&x))?;
    npz.add_array("faces", &faces.map_err(|x| e(&x))?)
        .map_err(|x| e(&x))?;
    npz.add_array("chain", &Array1::from(arrays.chain.clone()))
        .map_err(|x| e(&x))?;
    let cursor = npz.finish().map_err(|x| e(&x))?;
    Ok(cursor.into_inner())
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
        };
        let bytes = encode(&arrays).unwrap();
        // A zip (local file header) holding the seven .npy files.
        assert_eq!(&bytes[..4], b"PK\x03\x04");
        for name in ["a", "b", "family", "strength", "visible", "faces", "chain"] {
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
        let _ = std::fs::remove_dir_all(&dir);
    }
}
