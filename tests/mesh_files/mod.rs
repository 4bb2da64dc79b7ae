//! The mesh tests' own helpers, included by `tests/mesh.rs` and
//! `tests/mesh_ply.rs` with `mod mesh_files;`: loading with the expected
//! outcome, and a small mesh with a curvature field for the PLY writer.

// Each test binary uses only part of these.
#![allow(dead_code)]

use std::path::Path;

use shapecue::Error;
use shapecue::mesh::{LoadOptions, Mesh, load};
use shapecue::spec::curvature::CurvatureField;

pub fn plain() -> LoadOptions {
    LoadOptions::default()
}

/// Loads and expects an `InvalidInput` error; returns its message.
pub fn load_err(path: &Path) -> String {
    match load(path, &plain()) {
        Ok(m) => panic!(
            "{}: expected an error, loaded {} vertices / {} faces",
            path.display(),
            m.n_vertices(),
            m.n_faces()
        ),
        Err(e @ Error::InvalidInput { .. }) => {
            let msg = e.to_string();
            assert!(
                msg.contains(&path.display().to_string()),
                "message does not name the file: {msg}"
            );
            msg
        }
        Err(e) => panic!("{}: expected InvalidInput, got {e:?}", path.display()),
    }
}

pub fn square() -> Mesh {
    Mesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.25],
            [1.0, 1.0, -0.5],
            [0.0, 1.0, 1e-3],
        ],
        faces: vec![[0, 1, 2], [0, 2, 3]],
        normals: None,
    }
}

/// A field with a distinct, exactly representable value in every slot.
pub fn field_for(m: &Mesh) -> CurvatureField {
    let n = m.n_vertices();
    let v = |i: usize, k: usize| (i * 100 + k) as f64 * 0.5;
    CurvatureField {
        normals: (0..n).map(|i| [v(i, 0), v(i, 1), v(i, 2)]).collect(),
        areas: (0..n).map(|i| v(i, 3)).collect(),
        k1: (0..n).map(|i| v(i, 4)).collect(),
        k2: (0..n).map(|i| -v(i, 5)).collect(),
        d1: (0..n).map(|i| [v(i, 6), v(i, 7), v(i, 8)]).collect(),
        d2: (0..n).map(|i| [v(i, 9), v(i, 10), v(i, 11)]).collect(),
        dk: (0..n)
            .map(|i| [v(i, 12), v(i, 13), v(i, 14), v(i, 15)])
            .collect(),
    }
}
