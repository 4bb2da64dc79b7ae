//! Curvature: device vs CPU reference (pass by pass and end to end), analytic
//! oracles with convergence, output conventions and deforming meshes. The
//! accumulation schemes, lanes and memory orders: `tests/curvature_schemes.rs`;
//! the hard cases (degenerate, non-manifold, slivers, far from the origin,
//! extreme scales): `tests/curvature_hard_cases.rs`.

mod common;
mod curvature_support;

use common::{gpu, shared_mesh};
use curvature_support::*;

use shapecue::cpu::curvature as cpu;
use shapecue::mesh::{self, Mesh};
use shapecue::report::metrics::{analytic_rms, nrmse, rmse};
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureOptions, Precision};
use shapecue::stages::curvature::{CurvatureEstimator, Pass};

// ---------------------------------------------------------------- device vs CPU

#[test]
fn every_pass_matches_the_cpu_reference_in_f64() {
    let m = mesh::jittered_sphere(1.0, 3, 0.25, 11);
    for acc in [Accumulate::Atomic, Accumulate::Gather] {
        let o = with(F64, acc, Precision::F64);
        let mut est = CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o).unwrap();
        est.set_positions(&m.positions).unwrap();
        let norm = est.normalization();
        let mut s = cpu::State::new(&m, &norm);
        let close = |a: &[f64], b: &[f64], name: &str| {
            let e = rmse(a, b);
            assert!(e < 1e-11, "{acc:?} {name}: rmse {e:.3e}");
        };
        let flat3 = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<_>>();

        est.run_until(Pass::NormalsAreas).unwrap();
        s.normals_areas();
        let d = est.read_intermediate().unwrap();
        close(&d.areas, &s.areas, "areas");
        // raw normal sums, compared relative to their size
        let scale = s
            .normals
            .iter()
            .map(|n| dot(*n, *n).sqrt())
            .fold(0.0, f64::max);
        close(
            &flat3(&d.normals)
                .iter()
                .map(|x| x / scale)
                .collect::<Vec<_>>(),
            &flat3(&s.normals)
                .iter()
                .map(|x| x / scale)
                .collect::<Vec<_>>(),
            "normal sums",
        );

        est.run_until(Pass::Frames).unwrap();
        s.frames();
        let d = est.read_intermediate().unwrap();
        close(&flat3(&d.normals), &flat3(&s.normals), "normals");
        close(&flat3(&d.pd1), &flat3(&s.pd1), "initial pd1");
        close(&flat3(&d.pd2), &flat3(&s.pd2), "initial pd2");

        est.run_until(Pass::Tensor).unwrap();
        s.tensor(Compat::Exact);
        let d = est.read_intermediate().unwrap();
        close(&flat3(&d.tensor), &flat3(&s.tensor), "tensor");

        est.run_until(Pass::Principal).unwrap();
        s.principal(Compat::Exact);
        let d = est.read_intermediate().unwrap();
        let k = |v: &[[f64; 2]]| v.iter().flatten().copied().collect::<Vec<_>>();
        close(&k(&d.k), &k(&s.k), "k1 k2");
        close(&flat3(&d.pd1), &flat3(&s.pd1), "d1");

        est.run_until(Pass::Dcurv).unwrap();
        s.dcurv();
        let d = est.read_intermediate().unwrap();
        let dk = |v: &[[f64; 4]]| v.iter().flatten().copied().collect::<Vec<_>>();
        let e = nrmse(&dk(&d.dk), &dk(&s.dk));
        assert!(e < 1e-10, "{acc:?} dcurv NRMSE {e:.3e}");
    }
}

#[test]
fn f32_device_matches_reference_at_table_3_level() {
    // Same input for both (the f32 rounding of the positions is the input's,
    // not the estimator's): NRMSE of k1, k2, H, K ≤ 1e-4 % = 1e-6.
    let mut cases = vec![
        ("torus", mesh::torus(1.0, 0.4, 256, 128)),
        ("jittered sphere", mesh::jittered_sphere(1.0, 5, 0.2, 7)),
    ];
    if let Some(b) = shared_mesh("stanford-bunny.obj") {
        cases.push(("bunny", b));
    }
    for (name, m) in cases {
        let q = quantized(&m);
        let (r, _) = cpu::estimate(&q, &CurvatureOptions::default());
        for acc in [Accumulate::Atomic, Accumulate::Gather] {
            let g = device(&m, with(CurvatureOptions::default(), acc, Precision::F32));
            assert_fields_close(&g.field, &r, 1e-6, &format!("{name} {acc:?} f32"));
        }
        // f64 on the raw input agrees to rounding.
        let (r, _) = cpu::estimate(&m, &CurvatureOptions::default());
        let g = device(&m, F64);
        assert_fields_close(&g.field, &r, 1e-10, &format!("{name} f64"));
    }
}

#[test]
fn trimesh2_mode_matches_the_reference_and_orders_by_magnitude() {
    let m = mesh::torus(1.0, 0.4, 64, 32);
    let o = CurvatureOptions {
        compat: Compat::Trimesh2,
        ..F64
    };
    let g = device(&m, o);
    let (r, _) = cpu::estimate(&m, &o);
    assert_fields_close(&g.field, &r, 1e-10, "trimesh2 f64");
    for i in 0..g.field.len() {
        assert!(g.field.k1[i].abs() >= g.field.k2[i].abs());
    }
    // and the quirk really changes the answer
    let (exact, _) = cpu::estimate(&m, &CurvatureOptions::default());
    assert!(rmse(&exact.k1, &r.k1) > 1e-2);
}

// ---------------------------------------------------------------- analytic oracles

/// Mean of the larger and smaller RMS errors against the truth.
fn oracle_error(m: &Mesh, o: CurvatureOptions, truth: &dyn Fn([f64; 3]) -> (f64, f64)) -> f64 {
    let g = device(m, o);
    let t: Vec<(f64, f64)> = m.positions.iter().map(|&p| truth(p)).collect();
    let (e1, e2) = analytic_rms(&g.field, &t);
    0.5 * (e1 + e2)
}

#[test]
fn sphere_cylinder_torus_ellipsoid_converge_like_h_squared() {
    // Each step halves h; an O(h²) estimator cuts the error ~4×. Require ≥ 3×.
    type Case = (
        &'static str,
        Box<dyn Fn(usize) -> Mesh>,
        Box<dyn Fn([f64; 3]) -> (f64, f64)>,
    );
    let cases: Vec<Case> = vec![
        (
            "torus",
            Box::new(|k| mesh::torus(1.0, 0.4, 16 << k, 8 << k)),
            Box::new(|p| mesh::torus_curvature(1.0, 0.4, p)),
        ),
        (
            "cylinder (interior rows)",
            Box::new(|k| mesh::cylinder(1.0, 1.0, 12 << k, (2 << k) + 1)),
            Box::new(|_| (1.0, 0.0)),
        ),
        (
            // regular lat-long grid: on a scaled geodesic sphere (irregular valences)
            // normal-based estimators do not converge, which says nothing about the code
            "ellipsoid",
            Box::new(|k| mesh::uv_ellipsoid(1.5, 1.0, 0.6, 16 << k, 8 << k)),
            Box::new(|p| mesh::ellipsoid_curvature(1.5, 1.0, 0.6, p)),
        ),
    ];
    for (name, make, truth) in &cases {
        let errs: Vec<f64> = (0..3)
            .map(|k| {
                let m = make(k);
                if name.starts_with("cylinder") {
                    // boundary rows of an open cylinder have one-sided rings: test the interior
                    let g = device(&m, F64);
                    let idx: Vec<usize> = (0..m.n_vertices())
                        .filter(|&i| m.positions[i][2].abs() < 0.49)
                        .collect();
                    let e1 = rmse(
                        &idx.iter().map(|&i| g.field.k1[i]).collect::<Vec<_>>(),
                        &vec![1.0; idx.len()],
                    );
                    let e2 = rmse(
                        &idx.iter().map(|&i| g.field.k2[i]).collect::<Vec<_>>(),
                        &vec![0.0; idx.len()],
                    );
                    0.5 * (e1 + e2)
                } else {
                    oracle_error(&m, F64, truth.as_ref())
                }
            })
            .collect();
        eprintln!("{name}: errors {errs:?}");
        if errs[0] < 1e-9 {
            continue; // exact at every resolution (a regular cylinder is)
        }
        for w in errs.windows(2) {
            assert!(
                w[1] < w[0] / 3.0,
                "{name}: error {:.3e} → {:.3e} does not fall like h²",
                w[0],
                w[1]
            );
        }
    }
    // Icospheres are exact up to their irregularity; the error is small at every level.
    for level in 2..5 {
        let e = oracle_error(&mesh::icosphere(2.0, level), F64, &|_| (0.5, 0.5));
        assert!(e < 0.05 * 0.5, "sphere level {level}: {e}");
    }
}

#[test]
fn trimesh2_quirk_error_does_not_vanish_on_the_torus() {
    let o = CurvatureOptions {
        compat: Compat::Trimesh2,
        ..F64
    };
    let errs: Vec<f64> = (0..3)
        .map(|k| {
            let m = mesh::torus(1.0, 0.4, 16 << k, 8 << k);
            let t: Vec<(f64, f64)> = m
                .positions
                .iter()
                .map(|&p| mesh::torus_curvature(1.0, 0.4, p))
                .collect();
            // trimesh2 orders by magnitude; on this torus |k1| ≥ |k2| everywhere, so compare k1
            analytic_rms(&device(&m, o).field, &t).0
        })
        .collect();
    eprintln!("trimesh2 torus k1 errors {errs:?}");
    assert!(errs.iter().all(|&e| e > 0.1), "{errs:?}");
    assert!(errs[2] > errs[0] * 0.8, "quirk error fell: {errs:?}");
}

// ---------------------------------------------------------------- conventions

#[test]
fn sphere_is_convex_positive_and_umbilic_frames_are_orthonormal() {
    let m = mesh::icosphere(2.0, 4);
    let g = device(&m, CurvatureOptions::default());
    assert_frames(&g.field, 1e-5);
    for i in 0..m.n_vertices() {
        assert!(g.field.k1[i] >= g.field.k2[i]);
        assert!((g.field.k1[i] - 0.5).abs() < 0.03, "k1 {}", g.field.k1[i]);
        assert!((g.field.k2[i] - 0.5).abs() < 0.03, "k2 {}", g.field.k2[i]);
        // outward normals
        assert!(dot(g.field.normals[i], m.positions[i]) > 0.0);
    }
    // inverted orientation flips the sign
    let mut inv = m.clone();
    inv.faces.iter_mut().for_each(|f| f.swap(1, 2));
    let g = device(&inv, CurvatureOptions::default());
    assert!(g.field.k1.iter().all(|&k| (k + 0.5).abs() < 0.03));
}

#[test]
fn cylinder_directions_follow_the_circumference() {
    let m = mesh::cylinder(0.5, 1.0, 64, 17);
    let g = device(&m, CurvatureOptions::default());
    assert_frames(&g.field, 1e-5);
    for i in 0..m.n_vertices() {
        if m.positions[i][2].abs() > 0.45 {
            continue;
        }
        assert!((g.field.k1[i] - 2.0).abs() < 0.01, "k1 {}", g.field.k1[i]);
        assert!(g.field.k2[i].abs() < 0.01, "k2 {}", g.field.k2[i]);
        assert!(g.field.d1[i][2].abs() < 1e-3, "d1 not around the axis");
        assert!(g.field.d2[i][2].abs() > 0.999, "d2 not along the axis");
    }
}

#[test]
fn flat_plane_has_zero_curvature_and_orthonormal_frames() {
    let m = mesh::plane(20, 3.0);
    let g = device(&m, CurvatureOptions::default());
    assert_frames(&g.field, 1e-5);
    assert!(g.field.k1.iter().chain(&g.field.k2).all(|k| k.abs() < 1e-5));
    assert!(g.field.dk.iter().flatten().all(|d| d.abs() < 1e-4));
    assert!(g.field.normals.iter().all(|n| (n[2] - 1.0).abs() < 1e-6));
    assert_eq!(g.counts.vertices_without_curvature, 0);
}

// ---------------------------------------------------------------- deforming meshes

#[test]
fn two_poses_through_one_estimator_equal_two_fresh_runs() {
    let rest = mesh::cylinder(0.5, 2.0, 32, 24);
    let bent = rest.map_positions(|p| {
        // bend around the y axis
        let a = p[2] * 0.6;
        [(p[0] + 1.5) * a.cos() - 1.5, p[1], (p[0] + 1.5) * a.sin()]
    });
    for o in [
        with(
            CurvatureOptions::default(),
            Accumulate::Gather,
            Precision::F32,
        ),
        F64,
    ] {
        let mut est = CurvatureEstimator::new(gpu(), rest.n_vertices(), &rest.faces, o).unwrap();
        let bytes = est.device_bytes();
        let mut poses = Vec::new();
        for m in [&rest, &bent, &rest] {
            est.set_positions(&m.positions).unwrap();
            est.run().unwrap();
            poses.push(est.read().unwrap());
        }
        assert_eq!(est.device_bytes(), bytes);
        let fresh_rest = device(&rest, o).field;
        let fresh_bent = device(&bent, o).field;
        if o.accumulate == Accumulate::Gather {
            assert_eq!(poses[0], fresh_rest);
            assert_eq!(poses[1], fresh_bent);
            assert_eq!(poses[2], fresh_rest);
        } else {
            // atomics sum in a varying order: equal to rounding, measured against
            // the curvature scale (k2 of a straight cylinder is ~0, so NRMSE would
            // divide rounding noise by a zero range)
            for (a, b, what) in [
                (&poses[1], &fresh_bent, "bent"),
                (&poses[2], &fresh_rest, "rest"),
            ] {
                let scale = b.k1.iter().map(|k| k.abs()).fold(0.0, f64::max);
                for (x, y) in [(&a.k1, &b.k1), (&a.k2, &b.k2)] {
                    let e = rmse(x, y) / scale;
                    assert!(e < 1e-12, "{what} pose: {e:.2e}");
                }
            }
        }
        assert!(rmse(&poses[0].k2, &poses[1].k2) > 0.01, "the poses differ");
    }
}

#[test]
fn wrong_pose_sizes_and_non_finite_poses_are_errors() {
    let m = mesh::icosphere(1.0, 1);
    let mut est =
        CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, Default::default()).unwrap();
    let e = est
        .set_positions(&m.positions[1..])
        .unwrap_err()
        .to_string();
    assert!(e.contains("vertices"), "{e}");
    let mut bad = m.positions.clone();
    bad[3][1] = f64::NAN;
    let e = est.set_positions(&bad).unwrap_err().to_string();
    assert!(e.contains("vertex 3"), "{e}");
    let e = CurvatureEstimator::new(gpu(), 3, &[[0, 1, 7]], Default::default())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("face 0"), "{e}");
    // Frame faces: one per vertex, each −1 or a face of the mesh.
    let e = est.set_frame_faces(&[0; 3]).unwrap_err().to_string();
    assert!(e.contains("3 frame faces") && e.contains("vertices"), "{e}");
    let mut owner = vec![0i32; m.n_vertices()];
    owner[5] = m.n_faces() as i32;
    let e = est.set_frame_faces(&owner).unwrap_err().to_string();
    assert!(e.contains("vertex 5") && e.contains("not a face"), "{e}");
    owner[5] = -2;
    assert!(est.set_frame_faces(&owner).is_err());
    // A face that does not use its vertex only seeds another frame: the
    // curvature is the same and everything stays finite.
    est.set_positions(&m.positions).unwrap();
    est.run().unwrap();
    let own = est.read().unwrap();
    owner[5] = -1;
    est.set_frame_faces(&owner).unwrap();
    est.run().unwrap();
    let other = est.read().unwrap();
    assert!(other.all_finite());
    assert_fields_close(&own, &other, 1e-5, "other frame faces");
    // Placed reads: a reversal puts vertex v at n − 1 − v; a repeated or
    // missing place is refused.
    let n = m.n_vertices();
    let rev: Vec<u32> = (0..n as u32).rev().collect();
    let placed = est.read_placed(Some(&rev)).unwrap();
    assert_eq!(placed.k1[n - 1 - 7], other.k1[7]);
    assert_eq!(placed.d2[n - 1 - 7], other.d2[7]);
    assert_eq!(placed.dk[0], other.dk[n - 1]);
    let mut twice = rev.clone();
    twice[1] = twice[0];
    let e = est.read_placed(Some(&twice)).unwrap_err().to_string();
    assert!(e.contains("permutation"), "{e}");
    assert!(est.read_placed(Some(&rev[1..])).is_err());
}

#[test]
fn memory_stays_within_budget() {
    // f32: the atomic scheme ≤ 192 bytes per vertex + 32 per face; the
    // gather scheme ≤ 96 + 96 (one-ring lists, corners and corner weights);
    // either 64 more per vertex with SIMD lanes (the vertex records)
    let m = mesh::torus(1.0, 0.4, 200, 100);
    for (acc, lanes, per_vertex, per_face) in [
        (Accumulate::Atomic, 1, 192, 32),
        (Accumulate::Atomic, 16, 256, 32),
        (Accumulate::Gather, 1, 96, 96),
        (Accumulate::Gather, 16, 160, 96),
    ] {
        let o = with(CurvatureOptions::default(), acc, Precision::F32);
        let (nv, nf) = (m.n_vertices(), m.n_faces());
        let b = shapecue::spec::curvature::device_bytes_bound(nv, nf, &o, lanes);
        let budget = per_vertex * nv as u64 + per_face * nf as u64;
        assert!(b <= budget, "{acc:?}, {lanes} lanes: {b} > {budget}");
    }
    // and an estimator reports the bound of its own face lanes
    for (acc, lanes) in [
        (Accumulate::Gather, 1),
        (Accumulate::Gather, 16),
        (Accumulate::Atomic, 1),
        (Accumulate::Atomic, 16),
    ] {
        let o = CurvatureOptions {
            lanes: shapecue::spec::curvature::Lanes::Fixed(lanes),
            ..with(CurvatureOptions::default(), acc, Precision::F32)
        };
        let e = CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o).unwrap();
        assert_eq!(e.face_lanes(), lanes);
        let bound =
            shapecue::spec::curvature::device_bytes_bound(m.n_vertices(), m.n_faces(), &o, lanes);
        assert_eq!(e.device_bytes(), bound, "{acc:?}, {lanes} lanes");
    }
}
