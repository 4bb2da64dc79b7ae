//! Curvature: device vs CPU reference (pass by pass and end to end), analytic
//! oracles with convergence, output conventions, determinism, deforming
//! meshes, and the hard cases (degenerate, non-manifold, flat, umbilic,
//! slivers, far from the origin, extreme scales).

mod common;

use common::{gpu, shared_mesh};

use shapecue::cpu::curvature as cpu;
use shapecue::mesh::{self, Mesh};
use shapecue::report::metrics::{analytic_rms, nrmse, rmse};
use shapecue::spec::curvature::{
    Accumulate, Compat, CurvatureField, CurvatureOptions, Normalization, Precision,
};
use shapecue::stages::curvature::{self as stage, CurvatureEstimator, Pass};

const F64: CurvatureOptions = CurvatureOptions {
    accumulate: Accumulate::Atomic,
    precision: Precision::F64,
    compat: Compat::Exact,
    dcurv: true,
    lanes: 0,
};

fn with(o: CurvatureOptions, acc: Accumulate, prec: Precision) -> CurvatureOptions {
    CurvatureOptions {
        accumulate: acc,
        precision: prec,
        ..o
    }
}

fn device(m: &Mesh, o: CurvatureOptions) -> shapecue::Curvature {
    stage::estimate(gpu(), m, o).expect("device estimate")
}

/// The mesh as the f32 device sees it: normalized, rounded to f32, mapped back.
fn quantized(m: &Mesh) -> Mesh {
    let n = Normalization::of(&m.positions);
    m.map_positions(|p| {
        let a = n.apply(p);
        std::array::from_fn(|k| (a[k] as f32) as f64 * n.scale + n.center[k])
    })
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Output conventions: unit n, d1, d2; d1, d2 tangent; d2 = n × d1; all finite.
fn assert_frames(f: &CurvatureField, tol: f64) {
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

fn assert_fields_close(a: &CurvatureField, b: &CurvatureField, tol: f64, what: &str) {
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

#[test]
fn gather_is_bitwise_reproducible_and_agrees_with_atomic() {
    let m = mesh::jittered_sphere(1.0, 4, 0.3, 3);
    let o = with(
        CurvatureOptions::default(),
        Accumulate::Gather,
        Precision::F32,
    );
    // One-shot runs (which compute this mesh in a Morton order) and runs
    // of one estimator (in the input order) are each reproducible.
    let a = device(&m, o).field;
    assert_eq!(a, device(&m, o).field, "one-shot gather results differ");
    let mut est = CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o).unwrap();
    est.set_positions(&m.positions).unwrap();
    est.run().unwrap();
    let first = est.read().unwrap();
    for _ in 0..3 {
        est.run().unwrap();
        let b = est.read().unwrap();
        assert_eq!(first, b, "gather results differ between runs");
    }
    assert_fields_close(&a, &first, 1e-6, "Morton vs input order");
    let at = device(&m, CurvatureOptions::default()).field;
    assert_fields_close(&at, &a, 1e-6, "atomic vs gather");
}

/// A 96 × 48 torus with its vertices and faces in a fixed pseudo-random
/// order (as in scanned meshes).
fn shuffled_torus() -> Mesh {
    let t = mesh::torus(1.0, 0.4, 96, 48);
    let nv = t.n_vertices();
    // A fixed pseudo-random permutation of the vertices and of the faces.
    let shuffle = |n: usize, seed: u64| {
        let mut p: Vec<u32> = (0..n as u32).collect();
        let mut x = seed;
        for i in (1..n).rev() {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            p.swap(i, (x >> 33) as usize % (i + 1));
        }
        p
    };
    let (pv, pf) = (shuffle(nv, 7), shuffle(t.n_faces(), 11));
    let mut positions = vec![[0.0; 3]; nv];
    for (old, &new) in pv.iter().enumerate() {
        positions[new as usize] = t.positions[old];
    }
    let faces = pf
        .iter()
        .map(|&f| t.faces[f as usize].map(|v| pv[v as usize]))
        .collect();
    Mesh::new(positions, faces, "shuffled torus").unwrap()
}

/// A mesh in scattered order (its vertices and faces shuffled, as in scanned
/// meshes) is computed in a Morton order by the one-shot estimate and the
/// CLI, and gives the input-order results to rounding: the same curvatures
/// and, since the frames are seeded from the input's owning faces, the same
/// principal directions with the same signs, and the same derivative.
#[test]
fn scattered_meshes_are_reordered_and_give_the_input_order_results() {
    use shapecue::mesh::order::{LocalityOrder, MeshOrder};
    let t = mesh::torus(1.0, 0.4, 96, 48);
    let nv = t.n_vertices();
    let m = shuffled_torus();
    assert!(LocalityOrder::scattered(nv, &m.faces));
    assert!(
        LocalityOrder::choose(&t, MeshOrder::Auto).is_none(),
        "the grid is local"
    );
    for acc in [Accumulate::Gather, Accumulate::Atomic] {
        let o = with(CurvatureOptions::default(), acc, Precision::F32);
        let reordered = device(&m, o).field;
        let mut est = CurvatureEstimator::new(gpu(), nv, &m.faces, o).unwrap();
        est.set_positions(&m.positions).unwrap();
        est.run().unwrap();
        let input = est.read().unwrap();
        assert_fields_close(&reordered, &input, 1e-6, "Morton vs input order");
        for i in 0..nv {
            for (a, b, what) in [
                (reordered.d1[i], input.d1[i], "d1"),
                (reordered.d2[i], input.d2[i], "d2"),
            ] {
                assert!(dot(a, b) > 1.0 - 1e-6, "vertex {i}: {what} {a:?} vs {b:?}");
            }
        }
        // The derivative, against its RMS over all four components (some
        // components are ~0 on a torus, so a per-component NRMSE would
        // divide rounding by rounding).
        let (a, b): (Vec<f64>, Vec<f64>) = (0..nv)
            .flat_map(|i| (0..4).map(move |c| (i, c)))
            .map(|(i, c)| (reordered.dk[i][c], input.dk[i][c]))
            .unzip();
        let e = rmse(&a, &b) / rmse(&a, &vec![0.0; a.len()]);
        eprintln!("{acc:?}: dk relative RMS difference {e:.2e}");
        assert!(e < 1e-4, "{acc:?}: dk relative RMS difference {e:.2e}");
    }
}

/// A memory order planned on the host before the device opens
/// (`OrderPlan`, as the CLI does beside the load) gives the bits of the
/// one-call estimator; a plan made for another mesh is refused by name,
/// not applied.
#[test]
fn an_order_plan_gives_the_bits_of_the_one_call_estimator() {
    use shapecue::mesh::order::MeshOrder;
    use shapecue::stages::curvature::{OrderPlan, OrderedEstimator};
    let m = shuffled_torus();
    let o = with(
        CurvatureOptions::default(),
        Accumulate::Gather,
        Precision::F32,
    );
    let mut direct = OrderedEstimator::new(gpu(), &m, o, MeshOrder::Auto).unwrap();
    let plan = OrderPlan::new(&m, MeshOrder::Auto);
    let mut planned = OrderedEstimator::with_plan(gpu(), &m, o, plan).unwrap();
    assert!(planned.order.is_some(), "the shuffled torus is reordered");
    direct.est.run().unwrap();
    planned.est.run().unwrap();
    let (a, b) = (direct.read().unwrap(), planned.read().unwrap());
    for i in 0..m.n_vertices() {
        let (x, y) = (a.vertex(i), b.vertex(i));
        assert_eq!(
            (x.k1.to_bits(), x.k2.to_bits(), x.d1.map(f64::to_bits)),
            (y.k1.to_bits(), y.k2.to_bits(), y.d1.map(f64::to_bits)),
            "vertex {i}"
        );
    }
    let other = mesh::icosphere(1.0, 2);
    let plan = OrderPlan::new(&m, MeshOrder::Spatial);
    let err = OrderedEstimator::with_plan(gpu(), &other, o, plan)
        .err()
        .expect("a plan for another mesh is refused")
        .to_string();
    assert!(err.contains("memory order made for a mesh of"), "{err}");
}

/// The device buffers read in place (mapped, converted vertex by vertex,
/// as the CLI writes its PLY file) give the bits of the copying read, in
/// the input's order after a Morton reordering, in both precisions, with
/// and without the derivative (zeros without it, as the copy has).
#[test]
fn mapped_reads_give_the_bits_of_copied_reads() {
    use shapecue::mesh::order::MeshOrder;
    use shapecue::stages::curvature::OrderedEstimator;
    let m = shuffled_torus();
    for (precision, dcurv) in [
        (Precision::F32, true),
        (Precision::F64, true),
        (Precision::F32, false),
    ] {
        let o = CurvatureOptions {
            dcurv,
            ..with(CurvatureOptions::default(), Accumulate::Gather, precision)
        };
        let mut est = OrderedEstimator::new(gpu(), &m, o, MeshOrder::Auto).unwrap();
        assert!(est.order.is_some(), "the shuffled torus is reordered");
        est.est.run().unwrap();
        let copied = est.read().unwrap();
        let mapped = est.mapped().unwrap();
        assert_eq!(mapped.len(), m.n_vertices());
        for i in 0..m.n_vertices() {
            let (a, b) = (copied.vertex(i), mapped.vertex(i));
            let bits = |v: &shapecue::spec::curvature::VertexCurvature| {
                let mut x: Vec<u64> = v.normal.iter().map(|x| x.to_bits()).collect();
                x.extend([v.area, v.k1, v.k2].map(f64::to_bits));
                x.extend(v.d1.iter().chain(&v.d2).chain(&v.dk).map(|x| x.to_bits()));
                x
            };
            assert_eq!(
                bits(&a),
                bits(&b),
                "{precision:?} dcurv {dcurv}: vertex {i}"
            );
        }
        if !dcurv {
            assert!((0..m.n_vertices()).all(|i| mapped.vertex(i).dk == [0.0; 4]));
        }
    }
}

/// Meshes for the lane tests: face and vertex counts that are not multiples
/// of 16 (lanes past the last face or vertex), degenerate faces and skipped
/// solves (masked lanes).
fn lane_test_meshes() -> Vec<(&'static str, Mesh)> {
    let mut sliver = mesh::jittered_sphere(1.0, 3, 0.2, 5);
    // a zero-area face and a repeated vertex: degenerate lanes in a block
    let v = sliver.faces[7];
    sliver.faces.push([v[0], v[0], v[1]]);
    let p = sliver.positions[v[0] as usize];
    sliver.positions.push(p);
    let n = sliver.positions.len() as u32 - 1;
    sliver.faces.push([v[0], n, v[1]]);
    let mut open_sphere = mesh::jittered_sphere(1.0, 4, 0.3, 3);
    open_sphere.faces.truncate(open_sphere.faces.len() - 5);
    let lone = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let meshes = vec![
        ("jittered sphere with a hole", open_sphere),
        (
            "lone triangle",
            Mesh::new(lone, vec![[0, 1, 2]], "test").unwrap(),
        ),
        ("sphere with degenerate faces", sliver),
        ("torus", mesh::torus(1.0, 0.4, 37, 19)),
    ];
    for (what, m) in &meshes {
        assert_ne!(
            m.n_faces() % 16,
            0,
            "{what}: want a partial last face block"
        );
        assert_ne!(
            m.n_vertices() % 16,
            0,
            "{what}: want a partial last vertex block"
        );
    }
    meshes
}

/// The gather variant's lane kernels (the per-face kernels, and curv_frames
/// and curv_principal with their vertex records) give the same bits for
/// every lane count: on meshes whose face and vertex counts are not
/// multiples of 16 (lanes past the last face or vertex), with degenerate
/// faces and skipped solves (masked lanes), in both precisions. Counts agree
/// too.
#[test]
fn face_lanes_give_bitwise_identical_results() {
    let meshes = lane_test_meshes();
    for (what, m) in &meshes {
        for prec in [Precision::F32, Precision::F64] {
            let o = |lanes| CurvatureOptions {
                lanes,
                ..with(CurvatureOptions::default(), Accumulate::Gather, prec)
            };
            let mut est = CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o(1)).unwrap();
            assert_eq!(est.face_lanes(), 1);
            est.set_positions(&m.positions).unwrap();
            est.run().unwrap();
            let (one, one_counts) = (est.read().unwrap(), est.counts().unwrap());
            for lanes in [2, 4, 8, 16] {
                let mut est =
                    CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o(lanes)).unwrap();
                assert_eq!(est.face_lanes(), lanes);
                est.set_positions(&m.positions).unwrap();
                est.run().unwrap();
                assert_eq!(
                    est.read().unwrap(),
                    one,
                    "{what} {prec:?}: {lanes} lanes differ from 1"
                );
                assert_eq!(
                    est.counts().unwrap(),
                    one_counts,
                    "{what} {prec:?}: {lanes} lanes' counts"
                );
            }
        }
    }
    let bad = CurvatureOptions {
        lanes: 3,
        ..with(
            CurvatureOptions::default(),
            Accumulate::Gather,
            Precision::F32,
        )
    };
    let m = &meshes[0].1;
    let err = CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, bad)
        .err()
        .unwrap();
    assert!(err.to_string().contains("1, 2, 4, 8 or 16"), "{err}");
}

/// The atomic scheme with face lanes (SIMD arithmetic, then float atomic
/// adds, lane after lane) agrees with its one-lane form on the meshes of
/// [`lane_test_meshes`], in both precisions: the counts exactly, the
/// normals, areas and principal curvatures up to the rounding of sums taken
/// in another order (atomic sums have no fixed order in either form). Directions are left out:
/// on these near-umbilic spheres they turn with any rounding.
#[test]
fn atomic_scheme_with_lanes_matches_one_lane() {
    for (what, m) in &lane_test_meshes() {
        for (prec, tol) in [(Precision::F32, 1e-5), (Precision::F64, 1e-12)] {
            let o = |lanes| CurvatureOptions {
                lanes,
                ..with(CurvatureOptions::default(), Accumulate::Atomic, prec)
            };
            let run = |lanes| {
                let mut est =
                    CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o(lanes)).unwrap();
                assert_eq!(est.face_lanes(), lanes);
                est.set_positions(&m.positions).unwrap();
                est.run().unwrap();
                (est.read().unwrap(), est.counts().unwrap())
            };
            let (one, one_counts) = run(1);
            for lanes in [4, 16] {
                let (f, counts) = run(lanes);
                assert_eq!(counts, one_counts, "{what} {prec:?}: {lanes} lanes' counts");
                let flat = |v: &[[f64; 3]]| v.iter().flatten().copied().collect::<Vec<_>>();
                for (name, a, b) in [
                    ("normals", flat(&f.normals), flat(&one.normals)),
                    ("areas", f.areas.clone(), one.areas.clone()),
                    ("k1", f.k1.clone(), one.k1.clone()),
                    ("k2", f.k2.clone(), one.k2.clone()),
                ] {
                    assert!(a.iter().all(|x| x.is_finite()), "{what} {prec:?}: {name}");
                    let e = nrmse(&a, &b);
                    assert!(
                        e <= tol,
                        "{what} {prec:?}, {lanes} lanes: {name} NRMSE {e:e}"
                    );
                }
            }
        }
    }
}

/// The compare-and-swap scheme in f32 adds two adjacent floats in one 64-bit
/// compare-and-swap on a device with cl_khr_int64_base_atomics (both CPU
/// runtimes here). The same device told it has no 64-bit atomics builds the
/// one-float form: both agree, counts exactly and values up to the rounding
/// of the sums' order, with lanes and without, and the option is named in
/// the program's build options only where it applies.
#[test]
fn pair_adds_match_single_adds() {
    let paired = gpu();
    if !paired.info.int64_atomics {
        eprintln!("skipping: the device has no cl_khr_int64_base_atomics");
        return;
    }
    let mut single = shapecue::gpu::Gpu::new(None).unwrap();
    single.info.int64_atomics = false;
    let single = std::sync::Arc::new(single);
    let m = mesh::jittered_sphere(1.0, 4, 0.3, 3);
    for lanes in [1, 16] {
        let o = CurvatureOptions {
            lanes,
            ..with(
                CurvatureOptions::default(),
                Accumulate::Atomic,
                Precision::F32,
            )
        };
        let run = |g: &std::sync::Arc<shapecue::gpu::Gpu>| {
            let mut est = CurvatureEstimator::new(g.clone(), m.n_vertices(), &m.faces, o).unwrap();
            est.set_positions(&m.positions).unwrap();
            est.run().unwrap();
            (est.read().unwrap(), est.counts().unwrap())
        };
        let ((a, ca), (b, cb)) = (run(&paired), run(&single));
        assert_eq!(ca, cb, "{lanes} lanes: counts");
        for (name, x, y) in [
            ("areas", &a.areas, &b.areas),
            ("k1", &a.k1, &b.k1),
            ("k2", &a.k2, &b.k2),
        ] {
            let e = nrmse(x, y);
            assert!(e <= 1e-5, "{lanes} lanes: {name} NRMSE {e:e}");
        }
        let opts = |g: &shapecue::gpu::Gpu| {
            g.program_builds()
                .iter()
                .map(|b| b.options.clone())
                .collect::<Vec<_>>()
        };
        assert!(opts(&paired).iter().any(|o| o.contains("-DSC_PAIR_ADDS")));
        assert!(opts(&single).iter().all(|o| !o.contains("-DSC_PAIR_ADDS")));
    }
}

/// `--accumulate atomic-native` (cl_ext_float_atomics) agrees with the
/// compare-and-swap atomics and the CPU reference where the device offers
/// native float atomics (Intel's CPU runtime), and is refused with a message
/// naming the extension where it does not (PoCL 3.1), for each precision.
#[test]
fn native_float_atomics_match_compare_and_swap_or_are_refused() {
    let m = mesh::jittered_sphere(1.0, 4, 0.3, 3);
    let g = gpu();
    for prec in [Precision::F32, Precision::F64] {
        let o = with(CurvatureOptions::default(), Accumulate::AtomicNative, prec);
        let est = CurvatureEstimator::new(g.clone(), m.n_vertices(), &m.faces, o);
        match est {
            Ok(_) => {
                let native = [g.info.float_atomics, g.info.double_atomics];
                assert!(
                    native[prec as usize],
                    "{prec:?}: ran without native atomics"
                );
                let native = device(&m, o);
                let cas = device(&m, with(o, Accumulate::Atomic, prec));
                assert_eq!(native.counts, cas.counts);
                assert_fields_close(&native.field, &cas.field, 1e-6, "native vs CAS atomics");
                let (r, _) = cpu::estimate(&m, &o);
                assert_fields_close(&native.field, &r, 2e-4, "native atomics vs CPU reference");
            }
            Err(e) => {
                let msg = e.to_string();
                let want = format!(
                    "native {} float atomic adds (cl_ext_float_atomics)",
                    prec.name()
                );
                assert!(msg.contains(&want), "{prec:?}: {msg}");
            }
        }
    }
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
            lanes,
            ..with(CurvatureOptions::default(), acc, Precision::F32)
        };
        let e = CurvatureEstimator::new(gpu(), m.n_vertices(), &m.faces, o).unwrap();
        assert_eq!(e.face_lanes(), lanes);
        let bound =
            shapecue::spec::curvature::device_bytes_bound(m.n_vertices(), m.n_faces(), &o, lanes);
        assert_eq!(e.device_bytes(), bound, "{acc:?}, {lanes} lanes");
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
