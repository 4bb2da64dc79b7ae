//! Feature lines: occluding contours of a torus against the analytic
//! silhouettes (orthographic views along and across its axis), the device
//! against the CPU twin (torus and bunny, both kinds of line), and nasty
//! views (eye on the surface, inside the mesh) giving finite segments.

mod common;

use common::{LineArrays, gpu, to_f32};

use shapecue::cpu::feature_lines::{Hold, lines_face, lines_vertex};
use shapecue::mesh::{self, Mesh};
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureField, CurvatureOptions, Precision};
use shapecue::spec::feature_lines::{LineInputs, Segment};
use shapecue::spec::view::View;
use shapecue::stages::curvature::estimate;
use shapecue::stages::feature_lines::{LineExtractor, LineOptions};

fn inputs(m: &Mesh) -> LineArrays {
    let opts = CurvatureOptions {
        accumulate: Accumulate::Gather,
        precision: Precision::F64,
        compat: Compat::Exact,
        dcurv: true,
        lanes: shapecue::spec::curvature::Lanes::Auto,
    };
    let f: CurvatureField = estimate(gpu(), m, opts).unwrap().field;
    LineArrays::new(to_f32(&m.positions), &f)
}

fn li(x: &LineArrays) -> LineInputs<'_> {
    x.inputs()
}

fn device(m: &Mesh, x: &LineArrays, view: View, opts: LineOptions) -> Vec<Segment> {
    let mut ex = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    ex.extract(&li(x), view, 1.0, opts).unwrap().0
}

/// Every device segment has a CPU segment of the same kind with the same
/// endpoints (1e-5), and vice versa; f32 rounding differences (fused
/// multiply-adds on the device) may flip a face whose n·v is within rounding
/// of 0, so up to 0.5 % may be unmatched.
fn same(dev: Vec<Segment>, cpu: Vec<Segment>, what: &str) {
    let close = |a: &Segment, b: &Segment| {
        let d = |p: [f32; 3], q: [f32; 3]| (0..3).all(|k| (p[k] - q[k]).abs() < 1e-5);
        // Endpoints and the mesh edges they lie on, in the same order.
        a.family == b.family
            && (d(a.a, b.a) && d(a.b, b.b) && a.ends == b.ends
                || d(a.a, b.b) && d(a.b, b.a) && a.ends == [b.ends[1], b.ends[0]])
            && (a.strength - b.strength).abs() < 1e-4
    };
    let key = |s: &Segment| (s.a[0] + s.b[0]) * 0.5;
    let mut c = cpu.clone();
    c.sort_by(|a, b| key(a).total_cmp(&key(b)));
    let mut used = vec![false; c.len()];
    let mut unmatched = 0;
    for d in &dev {
        let k = key(d);
        let start = c.partition_point(|s| key(s) < k - 1e-4);
        let hit = (start..c.len())
            .take_while(|&i| key(&c[i]) <= k + 1e-4)
            .find(|&i| !used[i] && close(d, &c[i]));
        match hit {
            Some(i) => used[i] = true,
            None => unmatched += 1,
        }
    }
    let allowed = (cpu.len() / 200).max(1);
    assert!(
        unmatched <= allowed,
        "{what}: {unmatched} of {} device segments unmatched",
        dev.len()
    );
    assert!(
        dev.len().abs_diff(cpu.len()) <= allowed,
        "{what}: {} vs {} segments",
        dev.len(),
        cpu.len()
    );
}

#[test]
fn torus_contours_lie_on_the_analytic_silhouettes() {
    let m = mesh::torus(1.0, 0.4, 160, 80);
    let x = inputs(&m);
    let contours = LineOptions {
        contours: true,
        suggestive: false,
        ..Default::default()
    };
    // Along the axis: the outer and inner equators (radius 1.4 and 0.6, z = 0).
    let s = device(&m, &x, View::from_eye([0.0, 0.0, 1.0], true), contours);
    assert!(s.len() > 300, "{}", s.len());
    for Segment {
        a, b, family: kind, ..
    } in &s
    {
        assert_eq!(*kind, 0);
        for p in [a, b] {
            let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
            assert!(p[2].abs() < 0.01, "{p:?}");
            assert!(
                (rho - 1.4).abs() < 0.01 || (rho - 0.6).abs() < 0.01,
                "{p:?}"
            );
        }
    }
    // Across the axis (view along x): n·x = cos v cos u = 0, the circles in
    // the plane x = 0 and the top and bottom circles z = ±0.4.
    let s = device(&m, &x, View::from_eye([1.0, 0.0, 0.0], true), contours);
    assert!(s.len() > 300);
    for Segment { a, b, .. } in &s {
        for p in [a, b] {
            assert!(
                p[0].abs() < 0.01 || (p[2].abs() - 0.4).abs() < 0.01,
                "{p:?}"
            );
        }
    }
}

#[test]
fn each_segment_end_lies_on_its_mesh_edge_and_closed_contours_meet_in_pairs() {
    // On a closed mesh an occluding contour is a set of closed loops: every
    // mesh edge a contour crosses is shared by exactly two contour segments
    // (the faces on either side), which is what joins them into polylines.
    let m = mesh::torus(1.0, 0.4, 120, 60);
    let x = inputs(&m);
    let contours = LineOptions {
        contours: true,
        suggestive: false,
        ..Default::default()
    };
    let s = device(&m, &x, View::from_eye([0.3, 0.2, 1.0], true), contours);
    assert!(s.len() > 300, "{}", s.len());
    let mut count: std::collections::HashMap<[u32; 2], usize> = Default::default();
    for Segment { a, b, ends, .. } in &s {
        for (p, e) in [(a, ends[0]), (b, ends[1])] {
            assert!(e[0] < e[1], "{e:?} is a sorted vertex pair");
            // p = v0 + t (v1 − v0) for some t in [0, 1].
            let (v0, v1) = (x.pos[e[0] as usize], x.pos[e[1] as usize]);
            let d: [f32; 3] = std::array::from_fn(|i| v1[i] - v0[i]);
            let len2: f32 = d.iter().map(|c| c * c).sum();
            let t = (0..3).map(|i| (p[i] - v0[i]) * d[i]).sum::<f32>() / len2;
            let off: f32 = (0..3)
                .map(|i| (p[i] - v0[i] - t * d[i]).powi(2))
                .sum::<f32>()
                .sqrt();
            assert!(
                (-1e-4..=1.0 + 1e-4).contains(&t) && off < 1e-5,
                "{p:?} off {e:?}"
            );
            *count.entry(e).or_default() += 1;
        }
    }
    let odd: Vec<_> = count.iter().filter(|(_, n)| **n != 2).collect();
    assert!(odd.is_empty(), "edges not shared by two segments: {odd:?}");
}

#[test]
fn device_matches_cpu_twin() {
    let torus = mesh::torus(1.0, 0.4, 120, 60);
    let mut meshes = vec![("torus", torus)];
    // The bunny is added where the shared data sets are (else a message).
    if let Some(bunny) = common::shared_mesh("stanford-bunny.obj") {
        meshes.push(("bunny", bunny));
    }
    for (name, m) in meshes {
        let x = inputs(&m);
        let (lo, hi) = m.bounds();
        let c: [f32; 3] = std::array::from_fn(|i| (0.5 * (lo[i] + hi[i])) as f32);
        let d = (0..3).map(|i| (hi[i] - lo[i]) as f32).fold(0.0, f32::max);
        for (view, hermite) in [
            (
                View::from_eye([c[0] + 2.0 * d, c[1] + 0.7 * d, c[2] + 1.3 * d], false),
                false,
            ),
            (View::from_eye([0.3, 1.0, 0.2], true), false),
            (
                View::from_eye([c[0] - 1.5 * d, c[1] + 0.4 * d, c[2] + 2.0 * d], false),
                true,
            ),
            (View::from_eye([0.3, 1.0, 0.2], true), true),
        ] {
            let mut opts = LineOptions {
                threshold: 0.0,
                ..Default::default()
            };
            opts.curves.hermite = hermite;
            let dev = device(&m, &x, view, opts);
            let t = lines_vertex(&li(&x), view);
            let cpu = lines_face(
                &m.faces,
                &x.pos,
                &t,
                [true, true],
                true,
                hermite,
                0.0,
                opts.scaled_fade(1.0),
                &mut Hold::none(),
            );
            assert!(
                cpu.iter().any(|s| s.family == 0) && cpu.iter().any(|s| s.family == 1),
                "{name}: both kinds"
            );
            same(dev, cpu, name);
        }
    }
}

fn length(s: &[Segment]) -> f32 {
    s.iter()
        .map(|s| {
            (0..3)
                .map(|i| (s.b[i] - s.a[i]).powi(2))
                .sum::<f32>()
                .sqrt()
        })
        .sum()
}

#[test]
fn suggestive_contours_respect_the_threshold_and_facing() {
    let m = mesh::torus(1.0, 0.4, 120, 60);
    let x = inputs(&m);
    let view = View::from_eye([3.0, 0.5, 1.5], false);
    let only_sc = |t: f32| LineOptions {
        contours: false,
        suggestive: true,
        threshold: t,
        ..Default::default()
    };
    let loose = device(&m, &x, view, only_sc(0.0));
    let strict = device(&m, &x, view, only_sc(0.5));
    assert!(!loose.is_empty());
    // A higher threshold cuts the lines shorter (rtsc cuts, not drops).
    assert!(
        length(&strict) < 0.95 * length(&loose),
        "{} vs {}",
        length(&strict),
        length(&loose)
    );
    assert!(
        loose
            .iter()
            .all(|s| s.family == 1 && (0.0..=1.0).contains(&s.strength))
    );
    // A sphere is convex everywhere: radial curvature never crosses zero.
    let sphere = mesh::icosphere(1.0, 4);
    let xs = inputs(&sphere);
    assert!(device(&sphere, &xs, view, only_sc(0.0)).is_empty());
}

/// A flat grid over [-1, 1]² with curvature inputs made up so that, seen
/// along (1, 0, 1) (orthographic): κr sin²θ = x / 2 (zero on x = 0) and
/// sinθ D_w κr = y / √2, so rtsc's test D_w κr tanθ ≥ t holds for y ≥ t.
fn made_up_grid(n: usize) -> (Vec<[u32; 3]>, LineArrays) {
    let mut pos = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            // Columns off x = 0, so that the zero set crosses faces.
            let xx = -1.0 + 2.0 * (i as f32 + 0.37) / (n as f32 + 1.0);
            pos.push([xx, -1.0 + 2.0 * j as f32 / n as f32, 0.0]);
        }
    }
    let mut faces = Vec::new();
    let w = (n + 1) as u32;
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = j * w + i;
            faces.push([a, a + 1, a + w + 1]);
            faces.push([a, a + w + 1, a + w]);
        }
    }
    let nv = pos.len();
    let x = LineArrays {
        nrm: vec![[0.0, 0.0, 1.0]; nv],
        d1: vec![[1.0, 0.0, 0.0]; nv],
        d2: vec![[0.0, 1.0, 0.0]; nv],
        k: pos.iter().map(|p| [p[0], 0.0]).collect(),
        dk: pos.iter().map(|p| [p[1], 0.0, 0.0, 0.0]).collect(),
        pos,
    };
    (faces, x)
}

#[test]
fn suggestive_contours_are_cut_where_the_test_crosses_its_threshold() {
    let (faces, x) = made_up_grid(40);
    let mut ex = LineExtractor::new(gpu(), x.pos.len(), &faces).unwrap();
    let view = View::from_eye([1.0, 0.0, 1.0], true);
    for t in [0.3f32, 0.05] {
        let opts = LineOptions {
            contours: false,
            suggestive: true,
            threshold: t,
            ..Default::default()
        };
        let (s, _) = ex.extract(&li(&x), view, 1.0, opts).unwrap();
        assert!(!s.is_empty());
        let ys: Vec<f32> = s.iter().flat_map(|s| [s.a[1], s.b[1]]).collect();
        let lo = ys.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = ys.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        // On x = 0, from y = t (the cut, exact: the test is linear) to 1.
        assert!(s.iter().all(|s| s.a[0].abs() < 1e-5 && s.b[0].abs() < 1e-5));
        assert!(
            (lo - t).abs() < 1e-5 && (hi - 1.0).abs() < 1e-5,
            "{lo} {hi}"
        );
        assert!((length(&s) - (1.0 - t)).abs() < 1e-4, "{}", length(&s));
        // One end is cut inside a face; every other end lies on an edge.
        let free: Vec<_> = s
            .iter()
            .flat_map(|s| [(s.a, s.ends[0]), (s.b, s.ends[1])])
            .filter(|(_, e)| e[0] == shapecue::spec::feature_lines::LINE_FREE)
            .collect();
        assert_eq!(free.len(), 1, "{free:?}");
        assert!((free[0].0[1] - t).abs() < 1e-5);
        // rtsc's fade r / (r + 0.03) with r = y − t: 0 at the cut, rising.
        let mut by_y: Vec<&Segment> = s.iter().collect();
        by_y.sort_by(|a, b| (a.a[1] + a.b[1]).total_cmp(&(b.a[1] + b.b[1])));
        for seg in &by_y {
            let r0 = (seg.a[1] - t).max(0.0);
            let r1 = (seg.b[1] - t).max(0.0);
            let want = 0.5 * (r0 / (r0 + 0.03) + r1 / (r1 + 0.03));
            assert!(
                (seg.strength - want).abs() < 1e-4,
                "{} vs {want}",
                seg.strength
            );
        }
        // The twin cuts at the same place.
        let terms = lines_vertex(&li(&x), view);
        let cpu = lines_face(
            &faces,
            &x.pos,
            &terms,
            [false, true],
            true,
            false,
            t,
            0.03,
            &mut Hold::none(),
        );
        same(s.clone(), cpu, "made-up grid");
        // Without the test: the whole zero set of κr (rtsc's κr = 0 loops).
        let (all, _) = ex
            .extract(
                &li(&x),
                view,
                1.0,
                LineOptions {
                    curves: shapecue::spec::feature_lines::CurveOptions {
                        test: false,
                        ..Default::default()
                    },
                    ..opts
                },
            )
            .unwrap();
        assert!((length(&all) - 2.0).abs() < 1e-4, "{}", length(&all));
        assert!(all.iter().all(|s| s.strength == 1.0));
    }
}

#[test]
fn contours_keep_their_parts_with_positive_radial_curvature() {
    // A torus seen obliquely: its contour crosses the saddle-shaped inside,
    // where κr < 0 on parts that a closed surface hides; rtsc's test drops
    // them, cutting the contour where κr = 0.
    let m = mesh::torus(1.0, 0.4, 160, 80);
    let x = inputs(&m);
    let view = View::from_eye([3.0, 0.4, 2.0], false);
    let tested = device(
        &m,
        &x,
        view,
        LineOptions {
            suggestive: false,
            ..Default::default()
        },
    );
    let all = device(
        &m,
        &x,
        view,
        LineOptions {
            suggestive: false,
            curves: shapecue::spec::feature_lines::CurveOptions {
                test: false,
                ..Default::default()
            },
            ..Default::default()
        },
    );
    assert!(
        length(&tested) < 0.98 * length(&all),
        "{} {}",
        length(&tested),
        length(&all)
    );
    assert!(length(&tested) > 0.3 * length(&all));
    // Every kept end has κr ≥ 0 (barycentric in its face, or on its edge).
    let t = lines_vertex(&li(&x), view);
    let kr_at = |p: [f32; 3], e: [u32; 2]| -> f32 {
        if e[0] == shapecue::spec::feature_lines::LINE_FREE {
            let f = m.faces[e[1] as usize].map(|i| i as usize);
            let q = f.map(|i| x.pos[i]);
            let area = |a: [f32; 3], b: [f32; 3], c: [f32; 3]| {
                let (u, v) = (
                    [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                    [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
                );
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
            };
            let w = [
                area(p, q[1], q[2]),
                area(q[0], p, q[2]),
                area(q[0], q[1], p),
            ];
            let sw: f32 = w.iter().sum();
            (0..3).map(|k| w[k] / sw * t.kr[f[k]]).sum()
        } else {
            let (a, b) = (x.pos[e[0] as usize], x.pos[e[1] as usize]);
            let d: f32 = (0..3).map(|i| (b[i] - a[i]).powi(2)).sum::<f32>().sqrt();
            let s: f32 = (0..3).map(|i| (p[i] - a[i]).powi(2)).sum::<f32>().sqrt() / d;
            t.kr[e[0] as usize] + s * (t.kr[e[1] as usize] - t.kr[e[0] as usize])
        }
    };
    let scale = t.kr.iter().map(|k| k.abs()).fold(0.0, f32::max);
    let mut cut = 0;
    for s in &tested {
        for (p, e) in [(s.a, s.ends[0]), (s.b, s.ends[1])] {
            assert!(kr_at(p, e) >= -1e-4 * scale, "κr {} at {p:?}", kr_at(p, e));
            cut += usize::from(e[0] == shapecue::spec::feature_lines::LINE_FREE);
        }
    }
    assert!(cut >= 2, "{cut} cut ends");
}

#[test]
fn nasty_views_give_finite_segments_or_clear_errors() {
    let m = mesh::icosphere(1.0, 3);
    let x = inputs(&m);
    let mut ex = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    let opts = LineOptions::default();
    // Eye exactly on a vertex, and inside the sphere.
    for eye in [x.pos[0], [0.1, 0.0, 0.0]] {
        let (s, _) = ex
            .extract(&li(&x), View::from_eye(eye, false), 1.0, opts)
            .unwrap();
        assert!(
            s.iter()
                .all(|s| s.a.iter().chain(&s.b).all(|c| c.is_finite()))
        );
    }
    assert!(
        ex.extract(
            &li(&x),
            View::from_eye([f32::NAN, 0.0, 0.0], false),
            1.0,
            opts
        )
        .is_err()
    );
    assert!(
        ex.extract(&li(&x), View::from_eye([0.0; 3], true), 1.0, opts)
            .is_err()
    );
    assert!(
        ex.extract(&li(&x), View::from_eye([0.0, 0.0, 5.0], false), 0.0, opts)
            .is_err()
    );
    let short = LineArrays {
        pos: x.pos[..3].to_vec(),
        ..inputs(&m)
    };
    assert!(
        ex.extract(
            &li(&short),
            View::from_eye([0.0, 0.0, 5.0], false),
            1.0,
            opts
        )
        .is_err()
    );
}

#[test]
fn a_face_with_more_pieces_than_the_first_buffer_holds_grows_it() {
    // One face seen along z (orthographic), with made-up inputs: n·v =
    // (1, -1, -3), κr sin²θ = 0.64 k1 = (-1, 3, 1), sinθ D_w κr = 0.8 C111 =
    // (0, 4, -1). Its suggestive contour's test changes sign twice along it
    // (den at 1/3, num at 2/3): two pieces, beside one contour piece, three
    // segments for one face where the buffer starts with two.
    let faces = vec![[0u32, 1, 2]];
    let x = LineArrays {
        pos: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        nrm: vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, -3.0]],
        d1: vec![[0.6, 0.0, 0.8]; 3],
        d2: vec![[0.0, 1.0, 0.0]; 3],
        k: vec![[-1.0 / 0.64, 0.0], [3.0 / 0.64, 0.0], [1.0 / 0.64, 0.0]],
        dk: vec![[0.0; 4], [5.0, 0.0, 0.0, 0.0], [-1.25, 0.0, 0.0, 0.0]],
    };
    let opts = LineOptions {
        threshold: 0.0,
        ..Default::default()
    };
    let view = View::from_eye([0.0, 0.0, 1.0], true);
    let mut ex = LineExtractor::new(gpu(), 3, &faces).unwrap();
    let (s, _) = ex.extract(&li(&x), view, 1.0, opts).unwrap();
    let sc: Vec<&Segment> = s.iter().filter(|s| s.family == 1).collect();
    assert_eq!((s.len(), sc.len()), (3, 2), "{s:?}");
    let t = lines_vertex(&li(&x), view);
    let cpu = lines_face(
        &faces,
        &x.pos,
        &t,
        [true, true],
        true,
        false,
        0.0,
        opts.scaled_fade(1.0),
        &mut Hold::none(),
    );
    same(s.clone(), cpu, "one face, three pieces");
    // A second extraction reuses the grown buffer.
    let (again, _) = ex.extract(&li(&x), view, 1.0, opts).unwrap();
    assert_eq!(again.len(), 3);
}

/// A lines picture of no family, and a held scene of no cue, are refused
/// with a clear error (nothing to draw), never a panic.
#[test]
fn a_picture_of_nothing_is_an_error() {
    let (_, mesh) = mesh::Generated::Torus.mesh(500);
    let opts = shapecue::LinesPictureOptions {
        lines: LineOptions {
            contours: false,
            suggestive: false,
            curves: Default::default(),
            ..Default::default()
        },
        ..Default::default()
    };
    let e = shapecue::lines_picture_on(&gpu(), &mesh, &opts)
        .err()
        .expect("refused");
    assert!(e.to_string().contains("no line family"), "{e}");
    let held = shapecue::api::Source::Held(shapecue::api::HeldMesh(std::sync::Arc::new(mesh)));
    let scene = shapecue::api::Scene::held(held, &shapecue::Shot::default());
    match shapecue::api::Session::on(gpu()).picture(&scene, &Default::default()) {
        Err(e) => {
            let m = e.to_string();
            // Without GL the renderer's error comes first; with it, the plan's.
            assert!(
                m.contains("nothing to draw") || m.contains("OpenGL") || m.contains("EGL"),
                "{m}"
            );
        }
        Ok(_) => panic!("a scene of no cue drew something"),
    }
}

/// The bits of `segs`.
fn bits(segs: &[Segment]) -> &[u32] {
    bytemuck::cast_slice(segs)
}

/// Hysteresis over frames (two thresholds): a sequence whose suggestive
/// contours' test hovers at its threshold (the threshold alternates 30 %
/// above and below a middle value, which moves the test's margin as a
/// deforming surface would). Without hysteresis every other frame loses a
/// part of the lines; with it (held faces tested at half the threshold)
/// they stay. The first frame is today's lines bit for bit, a slot whose
/// last frame is not the one before starts afresh, and the device equals
/// its twin frame by frame, marks included.
#[test]
fn hysteresis_holds_lines_whose_test_hovers_at_its_threshold() {
    use shapecue::stages::feature_lines::HoldAt;
    let m = mesh::torus(1.0, 0.4, 120, 60);
    let x = inputs(&m);
    let view = View::from_eye([2.2, 0.9, 1.6], false);
    let opts_at = |k: usize| LineOptions {
        contours: false,
        suggestive: true,
        threshold: 10.0 * if k.is_multiple_of(2) { 0.7 } else { 1.3 },
        ..Default::default()
    };
    let low = 0.5;
    let mut plain = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    let mut held = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    let mut twin_held = vec![0u32; m.faces.len()];
    let mut twin_near = vec![0u32; m.n_vertices()];
    let t = lines_vertex(&li(&x), view);
    let (mut without, mut with) = (Vec::new(), Vec::new());
    for k in 0..6 {
        let o = opts_at(k);
        let (a, _) = plain.extract(&li(&x), view, 1.0, o).unwrap();
        held.hold_at(Some(HoldAt {
            slot: 0,
            frame: k,
            follows: k.checked_sub(1),
            low,
            birth: 0,
            band: 0.0,
        }))
        .unwrap();
        let (b, _) = held.extract(&li(&x), view, 1.0, o).unwrap();
        if k == 0 {
            assert!(
                bits(&a) == bits(&b),
                "frame 0 with hysteresis is today's lines bit for bit"
            );
        }
        // The twin from its own marks.
        let mut next = vec![0u32; m.faces.len()];
        let mut next_near = vec![0u32; m.n_vertices()];
        let cpu = lines_face(
            &m.faces,
            &x.pos,
            &t,
            [false, true],
            true,
            false,
            o.scaled_threshold(1.0),
            o.scaled_fade(1.0),
            &mut Hold {
                held: &twin_held,
                near: &twin_near,
                next_held: &mut next,
                next_near: &mut next_near,
                low,
                birth: 0,
            },
        );
        same(b.clone(), cpu, &format!("hysteresis frame {k}"));
        let marks = held.read_marks(0).unwrap().expect("the slot ran");
        assert_eq!(marks.frame, Some(k));
        let differ = marks.held.iter().zip(&next).filter(|(a, b)| a != b).count();
        assert!(
            differ <= m.faces.len() / 200,
            "frame {k}: {differ} faces' marks differ from the twin's"
        );
        twin_held = next;
        twin_near = next_near;
        without.push(length(&a));
        with.push(length(&b));
    }
    // Without: the high-threshold frames lose lines; with: they keep them.
    let dip = |l: &[f32]| {
        (1..6)
            .step_by(2)
            .map(|k| l[k] / l[k - 1])
            .fold(1.0, f32::min)
    };
    assert!(dip(&without) < 0.8, "the test hovers: {without:?}");
    assert!(
        dip(&with) > 0.97,
        "held lines stay: {with:?} (without: {without:?})"
    );
    // A slot whose last frame is not the one before starts afresh.
    held.hold_at(Some(HoldAt {
        slot: 0,
        frame: 9,
        follows: Some(8),
        low,
        birth: 0,
        band: 0.0,
    }))
    .unwrap();
    let o = opts_at(1);
    let (b, _) = held.extract(&li(&x), view, 1.0, o).unwrap();
    let (a, _) = plain.extract(&li(&x), view, 1.0, o).unwrap();
    assert!(bits(&a) == bits(&b), "a fresh slot draws today's lines");
    // A fraction outside (0, 1] is refused.
    for bad in [0.0, 1.5, f32::NAN] {
        let at = HoldAt {
            slot: 0,
            frame: 0,
            follows: None,
            low: bad,
            birth: 0,
            band: 0.0,
        };
        assert!(held.hold_at(Some(at)).is_err(), "{bad}");
    }
    let late = HoldAt {
        slot: 0,
        frame: 0,
        follows: None,
        low,
        birth: 3,
        band: 0.0,
    };
    assert!(held.hold_at(Some(late)).is_err(), "a delay of 3 frames");
}
