//! Helpers the curvature test files share (`tests/curvature*.rs`, each with
//! `mod curvature_support;`): the variants, the one-call device estimate, the
//! f32 view of a mesh, and the output-convention and field comparisons.

#![allow(dead_code)]

use crate::common::gpu;
use shapecue::mesh::Mesh;
use shapecue::report::metrics::nrmse;
use shapecue::spec::curvature::{
    Accumulate, Compat, CurvatureField, CurvatureOptions, Normalization, Precision,
};
use shapecue::stages::curvature as stage;

pub const F64: CurvatureOptions = CurvatureOptions {
    accumulate: Accumulate::Atomic,
    precision: Precision::F64,
    compat: Compat::Exact,
    dcurv: true,
    lanes: shapecue::spec::curvature::Lanes::Auto,
};

pub fn with(o: CurvatureOptions, acc: Accumulate, prec: Precision) -> CurvatureOptions {
    CurvatureOptions {
        accumulate: acc,
        precision: prec,
        ..o
    }
}

pub fn device(m: &Mesh, o: CurvatureOptions) -> shapecue::Curvature {
    stage::estimate(gpu(), m, o).expect("device estimate")
}

/// The mesh as the f32 device sees it: normalized, rounded to f32, mapped back.
pub fn quantized(m: &Mesh) -> Mesh {
    let n = Normalization::of(&m.positions);
    m.map_positions(|p| {
        let a = n.apply(p);
        std::array::from_fn(|k| (a[k] as f32) as f64 * n.scale + n.center[k])
    })
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Output conventions: unit n, d1, d2; d1, d2 tangent; d2 = n × d1; all finite.
pub fn assert_frames(f: &CurvatureField, tol: f64) {
    assert!(f.all_finite(), "non-finite output");
    for i in 0..f.len() {
        let (n, d1, d2) = (f.normals[i], f.d1[i], f.d2[i]);
        for (what, v) in [("n", n), ("d1", d1), ("d2", d2)] {
            assert!(
                (dot(v, v).sqrt() - 1.0).abs() < tol,
                "vertex {i}: |{what}| = {}",
                dot(v, v).sqrt()
            );
        }
        assert!(dot(n, d1).abs() < tol, "vertex {i}: d1 not tangent");
        assert!(dot(n, d2).abs() < tol, "vertex {i}: d2 not tangent");
        let c = cross(n, d1);
        assert!(
            (0..3).all(|k| (c[k] - d2[k]).abs() < tol),
            "vertex {i}: d2 != n × d1"
        );
    }
}

pub fn assert_fields_close(a: &CurvatureField, b: &CurvatureField, tol: f64, what: &str) {
    let cmp = |x: &[f64], y: &[f64], name: &str| {
        let e = nrmse(x, y);
        assert!(e <= tol, "{what}: {name} NRMSE {e:.3e} > {tol:.1e}");
    };
    cmp(&a.k1, &b.k1, "k1");
    cmp(&a.k2, &b.k2, "k2");
    cmp(&a.mean(), &b.mean(), "H");
    cmp(&a.gaussian(), &b.gaussian(), "K");
    cmp(&a.areas, &b.areas, "area");
}
