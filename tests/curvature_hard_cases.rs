//! Curvature's hard cases: degenerate faces, duplicates and unreferenced
//! vertices, non-manifold meshes and boundaries, slivers, translations and
//! extreme scales, and f64 judging faces by f64 rounding.

mod common;
mod curvature_support;

use common::shared_mesh;
use curvature_support::*;

use shapecue::cpu::curvature as cpu;
use shapecue::mesh::{self, Mesh};
use shapecue::report::metrics::nrmse;
use shapecue::spec::curvature::{Accumulate, CurvatureField, CurvatureOptions, Precision};

// ---------------------------------------------------------------- hard cases

fn check_hard(m: &Mesh, what: &str) -> (shapecue::Curvature, CurvatureField) {
    let (r, _) = cpu::estimate(m, &CurvatureOptions::default());
    assert!(r.all_finite(), "{what}: CPU reference not finite");
    for acc in [Accumulate::Atomic, Accumulate::Gather] {
        for prec in [Precision::F32, Precision::F64] {
            let o = with(CurvatureOptions::default(), acc, prec);
            let g = device(m, o);
            // The reference judges faces by the rounding of the precision
            // the device computes in.
            let (_, rc) = cpu::estimate(m, &o);
            assert_frames(&g.field, 1e-4);
            assert_eq!(
                (
                    g.counts.degenerate_faces,
                    g.counts.vertices_without_curvature
                ),
                (rc.degenerate_faces, rc.vertices_without_curvature),
                "{what} {acc:?} {prec:?}: counts differ from the reference"
            );
        }
    }
    (device(m, CurvatureOptions::default()), r)
}

#[test]
fn degenerate_faces_are_skipped_counted_and_do_not_poison_neighbours() {
    let base = mesh::icosphere(1.0, 3);
    let clean = device(&base, F64).field;
    let mut m = base.clone();
    let n0 = m.positions.len() as u32;
    // zero-area (collinear) face: midpoint of an existing edge
    let [a, b, _] = m.faces[0];
    let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
    m.positions
        .push(std::array::from_fn(|k| 0.5 * (pa[k] + pb[k])));
    m.faces.push([a, b, n0]);
    // zero-length edge: a face using the same vertex twice, and one with a coincident copy
    m.faces.push([a, a, b]);
    m.positions.push(pa);
    m.faces.push([a, n0 + 1, b]);
    let (g, _) = check_hard(&m, "degenerate");
    assert_eq!(g.counts.degenerate_faces, 3);
    assert_eq!(g.counts.vertices_without_curvature, 2);
    // every original vertex is exactly as without the degenerate faces
    let g64 = device(&m, F64).field;
    for i in 0..base.n_vertices() {
        assert!(
            (g64.k1[i] - clean.k1[i]).abs() < 1e-9,
            "vertex {i} poisoned"
        );
        assert!(
            (g64.k2[i] - clean.k2[i]).abs() < 1e-9,
            "vertex {i} poisoned"
        );
    }
}

#[test]
fn duplicate_faces_unreferenced_vertices_and_a_lone_triangle() {
    let mut m = mesh::icosphere(1.0, 2);
    let f0 = m.faces[0];
    m.faces.push(f0);
    m.positions.push([5.0, 5.0, 5.0]);
    m.positions.push([f64::MAX.sqrt(), 0.0, 0.0]); // far away, unreferenced
    let (g, _) = check_hard(&m, "duplicates + unreferenced");
    assert_eq!(g.counts.vertices_without_curvature, 2);
    let n = m.n_vertices();
    assert_eq!(g.field.normals[n - 1], [0.0, 0.0, 1.0]);
    assert_eq!((g.field.k1[n - 1], g.field.k2[n - 1]), (0.0, 0.0));

    let lone = Mesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
        "lone",
    )
    .unwrap();
    let (g, _) = check_hard(&lone, "lone triangle");
    assert!(g.field.k1.iter().all(|k| k.abs() < 1e-6));
    assert!(g.field.normals.iter().all(|n| (n[2] - 1.0).abs() < 1e-6));
}

#[test]
fn non_manifold_edges_and_vertices_and_boundaries() {
    // three fins sharing one edge
    let p = vec![
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.5],
        [-0.5, 0.8, 0.5],
        [-0.5, -0.8, 0.5],
    ];
    let fins = Mesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]], "fins").unwrap();
    check_hard(&fins, "non-manifold edge");
    // two cones touching at their apex (non-manifold vertex)
    let mut cones = Mesh::default();
    cones.positions.push([0.0, 0.0, 0.0]);
    for s in [1.0, -1.0] {
        let base = cones.positions.len() as u32;
        for i in 0..8 {
            let a = i as f64 * std::f64::consts::TAU / 8.0;
            cones.positions.push([a.cos(), a.sin(), s]);
        }
        for i in 0..8u32 {
            let (u, v) = (base + i, base + (i + 1) % 8);
            cones
                .faces
                .push(if s > 0.0 { [0, u, v] } else { [0, v, u] });
        }
    }
    check_hard(&cones, "non-manifold vertex");
    // open cylinder: boundary rows
    check_hard(&mesh::cylinder(1.0, 1.0, 16, 4), "boundary");
    if let Some(m) = shared_mesh("beetle.obj") {
        check_hard(&m, "beetle (47 non-manifold edges)");
    }
}

#[test]
fn slivers_with_aspect_ratio_1e6_stay_finite() {
    let mut m = mesh::plane(6, 1.0);
    let n = m.positions.len() as u32;
    // needles: a long edge and an apex 1e-6 of its length off the line, bent out of plane
    m.positions.push([0.0, 2.0, 0.0]);
    m.positions.push([1.0, 2.0, 1e-6]);
    m.positions.push([0.5, 2.0 + 1e-6, 0.0]);
    m.faces.push([n, n + 1, n + 2]);
    // a cap: nearly 180° angle
    m.positions.push([0.0, 3.0, 0.0]);
    m.positions.push([1.0, 3.0, 0.0]);
    m.positions.push([0.5, 3.0 + 1e-6, 0.0]);
    m.faces.push([n + 3, n + 4, n + 5]);
    // slivers inside a curved mesh
    let mut s = mesh::torus(1.0, 0.4, 24, 12);
    let k = s.positions.len() as u32;
    let [a, b, _] = s.faces[5];
    let (pa, pb) = (s.positions[a as usize], s.positions[b as usize]);
    s.positions.push(std::array::from_fn(|i| {
        0.5 * (pa[i] + pb[i]) + if i == 2 { 1e-6 } else { 0.0 }
    }));
    s.faces.push([a, b, k]);
    check_hard(&m, "needles and caps");
    check_hard(&s, "sliver in a torus");
}

#[test]
fn translation_by_1e6_and_scales_1e_minus6_and_1e6() {
    let m = mesh::torus(1.0, 0.4, 64, 32);
    let base = device(&m, CurvatureOptions::default()).field;
    for (what, s, t) in [
        ("translated by 1e6", 1.0, 1e6),
        ("scaled by 1e-6", 1e-6, 0.0),
        ("scaled by 1e6", 1e6, 0.0),
        ("scaled by 1e-6 at 1e-3", 1e-6, 1e-3),
    ] {
        let mm = m.map_positions(|p| p.map(|c| c * s + t));
        let (g, _) = check_hard(&mm, what);
        let f = g.field;
        let k1: Vec<f64> = f.k1.iter().map(|k| k * s).collect();
        let k2: Vec<f64> = f.k2.iter().map(|k| k * s).collect();
        let e = nrmse(&k1, &base.k1).max(nrmse(&k2, &base.k2));
        assert!(
            e < 1e-5,
            "{what}: curvature × scale differs by NRMSE {e:.2e}"
        );
        let a: Vec<f64> = f.areas.iter().map(|x| x / (s * s)).collect();
        assert!(nrmse(&a, &base.areas) < 1e-5, "{what}: areas");
    }
}

/// Two unit spheres 10⁶ apart: well resolved in f64, so the f64 device and the
/// CPU reference keep every face and find k = 1; f32 cannot resolve them
/// (its rounding at 10⁶ is ~0.06, the edges ~0.1) and skips faces, but
/// never more than f64 does.
#[test]
fn f64_judges_faces_by_f64_rounding() {
    let one = mesh::icosphere(1.0, 3);
    let n = one.n_vertices() as u32;
    let mut m = one.clone();
    for p in &one.positions {
        m.positions.push([p[0] + 1e6, p[1], p[2]]);
    }
    for f in &one.faces {
        m.faces.push(f.map(|v| v + n));
    }
    for acc in [Accumulate::Atomic, Accumulate::Gather] {
        let e = device(&m, with(F64, acc, Precision::F64));
        assert_eq!(e.counts.degenerate_faces, 0, "{acc:?} f64 device");
        let worst = e
            .field
            .k1
            .iter()
            .chain(&e.field.k2)
            .map(|k| (k - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.1, "{acc:?}: |k - 1| up to {worst}");
        let f32run = device(&m, with(F64, acc, Precision::F32));
        assert!(f32run.counts.degenerate_faces >= e.counts.degenerate_faces);
    }
    let (f, c) = cpu::estimate(&m, &F64);
    assert_eq!(c.degenerate_faces, 0, "CPU reference at f64");
    assert!(f.k1.iter().all(|k| (k - 1.0).abs() < 0.1));
    let (_, c32) = cpu::estimate(&m, &with(F64, Accumulate::Atomic, Precision::F32));
    let d32 = device(&m, with(F64, Accumulate::Atomic, Precision::F32));
    assert_eq!(
        c32.degenerate_faces, d32.counts.degenerate_faces,
        "f32 twin and device agree"
    );
}
