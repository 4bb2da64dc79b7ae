//! Curvature's accumulation schemes and their forms: gather against atomic
//! (bitwise reproducibility), explicit SIMD lanes, pair adds, native float
//! atomics, memory orders (Morton renumbering and order plans) and mapped
//! read-backs.

mod common;
mod curvature_support;

use common::gpu;
use curvature_support::*;

use shapecue::cpu::curvature as cpu;
use shapecue::mesh::{self, Mesh};
use shapecue::report::metrics::{nrmse, rmse};
use shapecue::spec::curvature::{Accumulate, CurvatureOptions, Precision};
use shapecue::stages::curvature::CurvatureEstimator;

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
                lanes: shapecue::spec::curvature::Lanes::Fixed(lanes),
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
        lanes: shapecue::spec::curvature::Lanes::Fixed(3),
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
                lanes: shapecue::spec::curvature::Lanes::Fixed(lanes),
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
            lanes: shapecue::spec::curvature::Lanes::Fixed(lanes),
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

/// `--accumulate atomic-native` (cl_ext_float_atomics, or inline PTX on
/// NVIDIA's CUDA platform) agrees with the compare-and-swap atomics and the
/// CPU reference where the device offers native float atomics (Intel's CPU
/// runtime, NVIDIA GPUs), and is refused with a message naming both routes
/// where it does not (PoCL 3.1), for each precision.
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
                    native[prec as usize] || g.info.ptx,
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
                assert!(!g.info.ptx, "{prec:?}: refused on NVIDIA: {msg}");
                let want = format!(
                    "native {} float atomic adds (cl_ext_float_atomics, or NVIDIA's CUDA \
                     platform for inline PTX)",
                    prec.name()
                );
                assert!(msg.contains(&want), "{prec:?}: {msg}");
            }
        }
    }
}
