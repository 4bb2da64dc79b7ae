//! The curvature line families (`kernels/feature_lines_curves.cl`): the
//! device against the CPU twin step by step, analytic oracles (ellipsoid
//! ridges in its principal planes, none on a sphere or a plane, sphere
//! isophotes at their latitudes, torus parabolic circles, apparent ridges of
//! an obliquely seen cylinder at its contour, cylinder boundaries), the
//! Hermite placement's error and time beside the linear one, and hard cases
//! giving finite segments.

mod common;

use common::{LineArrays, gpu, only, to_f32};

use shapecue::cpu::feature_lines::{Hold, lines_vertex};
use shapecue::cpu::feature_lines_curves::{
    CurveTerms, ScaledThresholds, boundary_mask, lines_curves, lines_dt1q1, lines_pose, lines_view,
};
use shapecue::mesh::{self, Mesh};
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureField, CurvatureOptions, Precision};
use shapecue::spec::feature_lines::{FamilySet, LineFamily, Segment};
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

fn device(m: &Mesh, x: &LineArrays, view: View, fs: f32, opts: LineOptions) -> Vec<Segment> {
    let mut ex = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    let (s, st) = ex.extract(&x.inputs(), view, fs, opts).unwrap();
    assert_eq!(st.segments, s.len());
    s
}

fn finite(s: &[Segment]) -> bool {
    s.iter()
        .all(|s| s.a.iter().chain(&s.b).all(|c| c.is_finite()) && s.strength.is_finite())
}

/// Both lists match segment for segment (endpoints within `tol`, same
/// family and edges), but for `slack` (a fraction) of either: decisions
/// on values within f32 rounding of a test may differ.
fn same(dev: &[Segment], cpu: &[Segment], tol: f32, slack: f64, what: &str) {
    let close = |a: &Segment, b: &Segment| {
        let d = |p: [f32; 3], q: [f32; 3]| (0..3).all(|k| (p[k] - q[k]).abs() < tol);
        a.family == b.family
            && (d(a.a, b.a) && d(a.b, b.b) && a.ends == b.ends
                || d(a.a, b.b) && d(a.b, b.a) && a.ends == [b.ends[1], b.ends[0]])
            && (a.strength - b.strength).abs() < 1e-3
    };
    let mut used = vec![false; cpu.len()];
    let mut unmatched = 0;
    let mut by_edge: std::collections::HashMap<[[u32; 2]; 2], Vec<usize>> = Default::default();
    for (i, c) in cpu.iter().enumerate() {
        let mut k = c.ends;
        k.sort();
        by_edge.entry(k).or_default().push(i);
    }
    for d in dev {
        let mut k = d.ends;
        k.sort();
        let hit = by_edge
            .get(&k)
            .and_then(|v| v.iter().copied().find(|&i| !used[i] && close(d, &cpu[i])));
        match hit {
            Some(i) => used[i] = true,
            None => unmatched += 1,
        }
    }
    let allowed = ((cpu.len() as f64 * slack) as usize).max(1);
    assert!(
        unmatched <= allowed && dev.len().abs_diff(cpu.len()) <= allowed,
        "{what}: {unmatched} of {} device segments unmatched, {} on the CPU",
        dev.len(),
        cpu.len()
    );
}

fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

#[test]
fn device_matches_cpu_twin_step_by_step() {
    let mut meshes = vec![
        ("torus", mesh::torus(1.0, 0.4, 90, 45)),
        ("ellipsoid", mesh::ellipsoid(1.5, 1.0, 0.6, 4)),
        ("cylinder", mesh::cylinder(0.5, 2.0, 48, 20)),
    ];
    if let Some(bunny) = common::shared_mesh("stanford-bunny.obj") {
        meshes.push(("bunny", bunny));
    }
    let all: Vec<LineFamily> = LineFamily::ALL[2..].to_vec();
    for (name, m) in meshes {
        let x = inputs(&m);
        let fs = mesh::feature_size(&m.positions, &m.faces) as f32;
        let (lo, hi) = m.bounds();
        let c: [f32; 3] = std::array::from_fn(|i| (0.5 * (lo[i] + hi[i])) as f32);
        let d = (0..3).map(|i| (hi[i] - lo[i]) as f32).fold(0.0, f32::max);
        for (view, hermite) in [
            (
                View::from_eye([c[0] + 2.0 * d, c[1] + 0.7 * d, c[2] + 1.3 * d], false),
                false,
            ),
            (View::from_eye([0.3, 1.0, 0.2], true), true),
        ] {
            let opts = only(&all, |o| {
                o.hermite = hermite;
                o.hermite_kh = hermite;
                o.light = [0.2, 0.5, 1.0];
                o.isophotes = 6;
            });
            let mut ex = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
            let (dev, _) = ex.extract(&x.inputs(), view, fs, opts).unwrap();
            let [pose, grad, viewt, dt] = ex.curve_stage().unwrap().read_terms().unwrap();
            let li = x.inputs();
            // lines_pose
            let p = lines_pose(&li, hermite);
            let col = |a: &[f32], stride: usize, k: usize| -> Vec<f32> {
                a.chunks_exact(stride).map(|c| c[k]).collect()
            };
            assert!(max_diff(&col(&pose, 8, 0), &p.kmax) < 1e-5, "{name}: kmax");
            assert!(max_diff(&col(&pose, 8, 1), &p.emax) < 1e-4, "{name}: emax");
            assert!(max_diff(&col(&pose, 8, 5), &p.gauss) < 1e-4, "{name}: K");
            assert!(max_diff(&col(&pose, 8, 6), &p.mean) < 1e-5, "{name}: H");
            if hermite {
                let g: Vec<f32> = p.grad.iter().flatten().flatten().copied().collect();
                let scale = g.iter().map(|v| v.abs()).fold(1.0, f32::max);
                assert!(max_diff(&grad, &g) < 1e-4 * scale, "{name}: gradients");
            }
            // lines_view, from the same n·v
            let t = lines_vertex(&li, view);
            let light = opts.curves.unit_light();
            let w = lines_view(&li, &p, &t, view, light);
            let q1 = col(&viewt, 8, 0);
            let rel = q1
                .iter()
                .zip(&w.q1)
                .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
                .fold(0.0, f32::max);
            assert!(rel < 1e-3, "{name}: q1 {rel}");
            assert!(max_diff(&col(&viewt, 8, 6), &w.ndl) < 1e-5, "{name}: n·l");
            assert!(
                max_diff(&col(&viewt, 8, 4), &w.phdot) < 1e-5,
                "{name}: v·dmax"
            );
            // lines_dt1q1 from the device's q1 and t1 (t1's sign is free,
            // and D_t1 q1 flips with it; the product does not).
            let mut wd = w.clone();
            wd.q1 = q1.clone();
            wd.t1 = viewt.chunks_exact(8).map(|c| [c[1], c[2], c[3]]).collect();
            let (off, ring) = mesh::topology::one_rings(m.n_vertices(), &m.faces);
            let dcpu = lines_dt1q1(&m.faces, &li, &off, &ring, &wd, &t);
            let scale = dcpu.iter().map(|v| v.abs()).fold(1.0, f32::max);
            assert!(max_diff(&dt, &dcpu) < 1e-3 * scale, "{name}: Dt1q1");
            // lines_curves from the device's terms
            let devpose = shapecue::cpu::feature_lines_curves::PoseTerms {
                kmax: col(&pose, 8, 0),
                emax: col(&pose, 8, 1),
                dmax: pose.chunks_exact(8).map(|c| [c[2], c[3], c[4]]).collect(),
                gauss: col(&pose, 8, 5),
                mean: col(&pose, 8, 6),
                grad: grad
                    .chunks_exact(6)
                    .map(|c| [[c[0], c[1], c[2]], [c[3], c[4], c[5]]])
                    .collect(),
            };
            let mut devview = wd.clone();
            devview.phdot = col(&viewt, 8, 4);
            devview.phtest = col(&viewt, 8, 5);
            devview.ndl = col(&viewt, 8, 6);
            let bnd = boundary_mask(&m.faces);
            let terms = CurveTerms {
                vertex: &t,
                pose: &devpose,
                view: &devview,
                dt: &dt,
                bnd: &bnd,
            };
            let cpu = lines_curves(
                &m.faces,
                &x.pos,
                &terms,
                &opts.curves,
                ScaledThresholds::of(
                    &opts.curves,
                    fs,
                    (opts.scaled_threshold(fs), opts.scaled_fade(fs)),
                ),
                &mut Hold::none(),
            );
            assert!(finite(&dev), "{name}: finite");
            for f in LineFamily::ALL[2..].iter().copied() {
                let pick = |s: &[Segment]| -> Vec<Segment> {
                    s.iter().filter(|s| s.family == f as u32).copied().collect()
                };
                let (a, b) = (pick(&dev), pick(&cpu));
                same(&a, &b, 1e-4, 0.01, &format!("{name} {}", f.name()));
            }
            assert!(
                cpu.iter().any(|s| s.family == LineFamily::Isophotes as u32),
                "{name}: isophotes drawn"
            );
        }
    }
}

#[test]
fn ellipsoid_ridges_lie_in_its_principal_planes() {
    let (a, b, c) = (1.5, 1.0, 0.6);
    let m = mesh::uv_ellipsoid(a, b, c, 160, 80);
    let x = inputs(&m);
    let fs = mesh::feature_size(&m.positions, &m.faces) as f32;
    let opts = only(&[LineFamily::Ridges, LineFamily::Valleys], |o| {
        o.cull = false;
        o.ridge_threshold = 0.0;
    });
    let s = device(&m, &x, View::from_eye([0.0, 0.0, 1.0], true), fs, opts);
    assert!(
        s.iter().all(|s| s.family == LineFamily::Ridges as u32),
        "no valleys"
    );
    assert!(s.len() > 200, "{} ridge segments", s.len());
    let tol = 3.0 * fs;
    let near = s
        .iter()
        .filter(|s| {
            let p: [f32; 3] = std::array::from_fn(|i| 0.5 * (s.a[i] + s.b[i]));
            p.iter().any(|c| c.abs() < tol)
        })
        .count();
    let frac = near as f64 / s.len() as f64;
    assert!(
        frac > 0.9,
        "{near} of {} ridge segments in a principal plane",
        s.len()
    );
}

#[test]
fn a_sphere_and_a_plane_have_no_ridges_or_valleys() {
    for (name, m) in [
        ("sphere", mesh::icosphere(1.0, 4)),
        ("plane", mesh::plane(40, 2.0)),
    ] {
        let x = inputs(&m);
        let fs = mesh::feature_size(&m.positions, &m.faces) as f32;
        let opts = only(&[LineFamily::Ridges, LineFamily::Valleys], |_| {});
        let s = device(&m, &x, View::from_eye([0.3, 0.2, 3.0], false), fs, opts);
        assert!(s.is_empty(), "{name}: {} segments", s.len());
    }
}

#[test]
fn sphere_isophotes_lie_at_the_latitudes_n_dot_l_gives() {
    let m = mesh::icosphere(1.0, 4);
    let x = inputs(&m);
    let n = 8;
    let opts = only(&[LineFamily::Isophotes], |o| {
        o.isophotes = n;
        o.cull = false;
        o.light = [0.0, 0.0, 2.0];
    });
    let s = device(&m, &x, View::from_eye([0.0, 0.0, 5.0], false), 0.05, opts);
    let mut levels = std::collections::BTreeSet::new();
    for seg in &s {
        for p in [seg.a, seg.b] {
            // On the unit sphere n·l = z: the nearest level is j / N.
            let j = (p[2] * n as f32).round();
            assert!((p[2] - j / n as f32).abs() < 0.01, "{p:?}");
            levels.insert(j as i32);
        }
    }
    assert_eq!(levels.len(), 2 * n as usize - 1, "{levels:?}");
}

/// Mean distance of K = 0 segment ends from the torus's top and bottom
/// circles (ρ = R, z = ±r), and the kernel ms of the face pass.
fn torus_parabolic_error(hermite: bool) -> (f64, f64, usize) {
    let (big, r) = (1.0, 0.4);
    let m = mesh::torus(big, r, 90, 36);
    let x = inputs(&m);
    let opts = only(&[LineFamily::KZero], |o| {
        o.cull = false;
        o.hermite_kh = hermite;
    });
    let mut ex = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    let view = View::from_eye([0.0, 0.0, 4.0], false);
    let (s, st) = ex.extract(&x.inputs(), view, 0.05, opts).unwrap();
    let mut err = 0.0;
    for seg in &s {
        for p in [seg.a, seg.b] {
            let rho = (p[0] as f64).hypot(p[1] as f64);
            err += ((rho - big).powi(2) + (p[2].abs() as f64 - r).powi(2)).sqrt();
        }
    }
    let ms = st
        .timing
        .family_ms(shapecue::spec::timing::Family::FeatureLines);
    (err / (2 * s.len()).max(1) as f64, ms, s.len())
}

#[test]
fn torus_parabolic_lines_are_its_top_and_bottom_circles() {
    let (lin, lin_ms, n) = torus_parabolic_error(false);
    let (her, her_ms, nh) = torus_parabolic_error(true);
    println!("K = 0 placement | mean error | kernel ms | segments");
    println!("linear | {lin:.5} | {lin_ms:.3} | {n}");
    println!("hermite | {her:.5} | {her_ms:.3} | {nh}");
    // Tube circumference 2.5 over 36 rings: 0.07 per ring.
    assert!(
        n >= 2 * 90 && lin < 0.02,
        "linear: {n} segments, error {lin}"
    );
    assert!(
        nh >= 2 * 90 && her < 0.02,
        "hermite: {nh} segments, error {her}"
    );
}

#[test]
fn apparent_ridges_of_an_obliquely_seen_cylinder_lie_at_its_contours() {
    let m = mesh::cylinder(0.5, 3.0, 96, 30);
    let x = inputs(&m);
    let fs = mesh::feature_size(&m.positions, &m.faces) as f32;
    // Seen from the side of φ = 0.3 rad, between two vertex columns (a
    // vertex exactly on the minimum of q1 has D_t1 q1 = 0 and passes the
    // zero-crossing test from either side, as in rtsc).
    let (c, sn) = (0.3f32.cos(), 0.3f32.sin());
    let dir = [c, sn, 1.0];
    let opts = only(&[LineFamily::ApparentRidges], |o| {
        o.apparent_threshold = 0.0
    });
    let s = device(&m, &x, View::from_eye(dir, true), fs, opts);
    assert!(s.len() > 20, "{}", s.len());
    // q1 grows towards the contour (n·v = 0: x cos 0.3 + y sin 0.3 = 0) on
    // both sides, so its maxima along t1 are there.
    let at = s
        .iter()
        .filter(|s| {
            let (x, y) = (0.5 * (s.a[0] + s.b[0]), 0.5 * (s.a[1] + s.b[1]));
            (x * c + y * sn).abs() < 0.1
        })
        .count();
    assert!(
        at as f64 > 0.9 * s.len() as f64,
        "{at} of {} at the contours",
        s.len()
    );
}

#[test]
fn cylinder_boundaries_are_its_two_rims() {
    let m = mesh::cylinder(0.5, 2.0, 40, 10);
    let x = inputs(&m);
    let opts = only(&[LineFamily::Boundaries], |_| {});
    let s = device(&m, &x, View::from_eye([3.0, 0.0, 0.5], false), 0.05, opts);
    assert_eq!(s.len(), 80);
    for seg in &s {
        assert!((seg.a[2].abs() - 1.0).abs() < 1e-6 && (seg.b[2] - seg.a[2]).abs() < 1e-6);
        assert_eq!(seg.ends[0][0], seg.ends[0][1], "ends keyed by their vertex");
    }
}

#[test]
fn hard_cases_give_finite_segments() {
    // A plane (flat: no curvature), a sphere (umbilic everywhere), a mesh
    // with a zero-area face and a repeated vertex, and an open cylinder.
    let mut degenerate = mesh::icosphere(1.0, 2);
    let p0 = degenerate.positions[0];
    degenerate.positions.push(p0);
    let nv = degenerate.positions.len() as u32;
    degenerate.faces.push([0, 1, nv - 1]);
    degenerate.faces.push([1, 1, 2]);
    let all: Vec<LineFamily> = LineFamily::ALL[2..].to_vec();
    for (name, m) in [
        ("plane", mesh::plane(20, 1.0)),
        ("sphere", mesh::icosphere(1.0, 3)),
        ("degenerate", degenerate),
        ("cylinder", mesh::cylinder(0.5, 1.0, 24, 6)),
    ] {
        let x = inputs(&m);
        for hermite in [false, true] {
            for view in [
                View::from_eye([0.0, 0.0, 3.0], false),
                View::from_eye(x.pos[0], false),
                View::from_eye([0.0, 0.0, 1.0], true),
            ] {
                let opts = only(&all, |o| {
                    o.hermite = hermite;
                    o.hermite_kh = hermite;
                    o.cull = false;
                    o.test = false;
                });
                let s = device(&m, &x, view, 0.1, opts);
                assert!(finite(&s), "{name}: non-finite segment");
            }
        }
    }
    let m = mesh::icosphere(1.0, 2);
    let x = inputs(&m);
    let mut ex = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    let bad = only(&[LineFamily::Ridges], |o| o.ridge_threshold = f32::NAN);
    let v = View::from_eye([0.0, 0.0, 3.0], false);
    assert!(ex.extract(&x.inputs(), v, 1.0, bad).is_err());
    let dark = only(&[LineFamily::Isophotes], |o| o.light = [0.0; 3]);
    assert!(ex.extract(&x.inputs(), v, 1.0, dark).is_err());
}

#[test]
fn family_names_round_trip_and_lists_parse() {
    for f in LineFamily::ALL {
        assert_eq!(f.name().parse::<LineFamily>().unwrap(), f);
        assert_eq!(LineFamily::from_kind(f as u32), Some(f));
    }
    let s = FamilySet::parse("ridges, valleys,apparent-ridges").unwrap();
    assert_eq!(
        s.iter().collect::<Vec<_>>(),
        [
            LineFamily::Ridges,
            LineFamily::Valleys,
            LineFamily::ApparentRidges
        ]
    );
    let e = FamilySet::parse("ridges,creases").unwrap_err().to_string();
    assert!(
        e.contains("creases") && e.contains("apparent-ridges"),
        "{e}"
    );
}

#[test]
fn each_family_runs_only_its_passes_and_reports_its_kernel_time() {
    use shapecue::spec::timing::Step;
    let m = common::shared_mesh("stanford-bunny.obj")
        .unwrap_or_else(|| mesh::torus(1.0, 0.4, 200, 100));
    let x = inputs(&m);
    let fs = mesh::feature_size(&m.positions, &m.faces) as f32;
    let view = View::from_eye([0.3, 0.2, 1.0], true);
    let mut ex = LineExtractor::new(gpu(), m.n_vertices(), &m.faces).unwrap();
    println!("family | steps | kernel ms | segments");
    for f in LineFamily::ALL[2..].iter().copied() {
        ex.pose_changed();
        let (s, st) = ex
            .extract(&x.inputs(), view, fs, only(&[f], |_| {}))
            .unwrap();
        let t = &st.timing;
        let pose = [
            LineFamily::Ridges,
            LineFamily::Valleys,
            LineFamily::PrincipalHighlights,
            LineFamily::KZero,
            LineFamily::HZero,
        ]
        .contains(&f);
        let view_pass = [
            LineFamily::ApparentRidges,
            LineFamily::PrincipalHighlights,
            LineFamily::Isophotes,
        ]
        .contains(&f);
        assert_eq!(t.ran(&[Step::LinesPose]), pose, "{}: pose pass", f.name());
        assert_eq!(
            t.ran(&[Step::LinesView]),
            view_pass,
            "{}: view pass",
            f.name()
        );
        assert_eq!(
            t.ran(&[Step::LinesDt1q1]),
            f == LineFamily::ApparentRidges,
            "{}",
            f.name()
        );
        assert!(
            t.ran(&[Step::LinesCurves]) && !t.ran(&[Step::LinesFace]),
            "{}",
            f.name()
        );
        let steps = [
            Step::LinesVertex,
            Step::LinesPose,
            Step::LinesView,
            Step::LinesDt1q1,
            Step::LinesCurves,
        ];
        println!(
            "{} | {} | {:.3} | {}",
            f.name(),
            steps
                .iter()
                .filter(|s| t.ran(&[**s]))
                .map(|s| s.kernel())
                .collect::<Vec<_>>()
                .join(" "),
            t.ms(&steps),
            s.len()
        );
    }
    // A second view of the same pose reuses the pose terms; a new pose
    // (after pose_changed) recomputes them.
    let copts = CurvatureOptions {
        accumulate: Accumulate::Atomic,
        precision: Precision::F32,
        compat: Compat::Exact,
        dcurv: true,
        lanes: shapecue::spec::curvature::Lanes::Auto,
    };
    let mut est = shapecue::stages::curvature::CurvatureEstimator::new(
        gpu(),
        m.n_vertices(),
        &m.faces,
        copts,
    )
    .unwrap();
    est.set_positions(&m.positions).unwrap();
    est.run().unwrap();
    ex.pose_changed();
    let opts = only(&[LineFamily::Ridges], |_| {});
    let side = View::from_eye([1.0, 0.2, 0.3], true);
    let ran = |ex: &mut LineExtractor, v: View| {
        let (s, st) = ex.extract_device(&est, v, fs, opts).unwrap();
        assert!(finite(&s));
        st.timing.ran(&[Step::LinesPose])
    };
    assert!(ran(&mut ex, view), "first view of a pose");
    assert!(!ran(&mut ex, side), "second view of the same pose");
    ex.pose_changed();
    assert!(ran(&mut ex, side), "after a new pose");
}

#[test]
fn the_command_writes_a_group_per_family_and_the_segments() {
    let d = common::scratch("lines-cli");
    let svg = d.join("t.svg");
    let json = d.join("t.json");
    let out = common::run_cli([
        "lines",
        "torus",
        "--vertices",
        "4000",
        "--lines",
        "contours,ridges,isophotes,k-zero",
        "--hidden",
        "dashed",
        "-o",
        svg.to_str().unwrap(),
        "--segments",
        json.to_str().unwrap(),
    ]);
    if common::cli_gl_missing(&out) {
        return;
    }
    common::assert_succeeded(&out);
    let t = std::fs::read_to_string(&svg).unwrap();
    for id in ["contours", "ridges", "isophotes", "k-zero", "k-zero-hidden"] {
        assert!(t.contains(&format!("<g id=\"{id}\"")), "{id}");
    }
    assert!(t.contains("stroke-dasharray"));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let segs = j["segments"].as_array().unwrap();
    assert!(segs.iter().any(|s| s["family"] == "k-zero"));
    assert!(segs.iter().all(|s| s["strength"].as_f64().is_some()));
    let bad = common::run_cli([
        "lines",
        "torus",
        "--lines",
        "ridges,creases",
        "-o",
        svg.to_str().unwrap(),
        "--force",
    ]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("creases"), "{err}");
}

#[test]
fn a_skinned_frame_gives_the_lines_of_the_static_mesh_in_the_same_pose() {
    use shapecue::mesh::skinned::{SkinnedMesh, load_gltf};
    use shapecue::stages::pipeline::{PipelineOptions, PosePipeline};
    // BrainStem (a shared data set; skipped with a message where absent):
    // the bundled Fox is a triangle soup, with no shared vertices to carry
    // curvature lines.
    let Some(path) = common::model_path("BrainStem.glb") else {
        return;
    };
    let m = load_gltf(&path).unwrap();
    let clip = &m.clips[0];
    let mats = SkinnedMesh::flatten(&m.joint_matrices(Some(0), 0.4 * clip.duration).unwrap());
    let mut p = PosePipeline::new(gpu(), &m, PipelineOptions::default()).unwrap();
    p.skin(&mats).unwrap();
    p.curvature().unwrap();
    let fs = p.feature_size();
    let fams: Vec<LineFamily> = LineFamily::ALL[2..].to_vec();
    let opts = only(&fams, |o| o.isophotes = 6);
    // The same pose as a static mesh: skinned by the CPU twin, curvature
    // (f32, on the device) of that mesh, lines from host arrays.
    let rest = to_f32(&m.rest.positions);
    let posed = shapecue::cpu::skinning::skin_lbs(&rest, &m.joints, &m.weights, &mats);
    let mesh = Mesh {
        positions: posed.iter().map(|q| q.map(f64::from)).collect(),
        faces: m.rest.faces.clone(),
        normals: None,
    };
    let copts = CurvatureOptions {
        accumulate: Accumulate::Atomic,
        precision: Precision::F32,
        compat: Compat::Exact,
        dcurv: true,
        lanes: shapecue::spec::curvature::Lanes::Auto,
    };
    let f = estimate(gpu(), &mesh, copts).unwrap().field;
    let x = LineArrays::new(posed, &f);
    let (lo, hi) = mesh.bounds();
    let d = (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max) as f32;
    assert!(fs > 0.0 && fs < d);
    let eye: [f32; 3] =
        std::array::from_fn(|i| (0.5 * (lo[i] + hi[i])) as f32 + 2.0 * d * [0.6, 0.5, 1.0][i]);
    let view = View::from_eye(eye, false);
    let (chained, _) = p.lines(view, fs, opts).unwrap();
    let stat = device(&mesh, &x, view, fs, opts);
    for fam in fams {
        let pick = |s: &[Segment]| -> Vec<Segment> {
            s.iter()
                .filter(|s| s.family == fam as u32)
                .copied()
                .collect()
        };
        let (a, b) = (pick(&chained), pick(&stat));
        eprintln!("{}: {} chained, {} static", fam.name(), a.len(), b.len());
        // Two f32 curvature runs (rest-pose vs own normalization) differ by
        // rounding, which the derivative tests (ridges, apparent ridges)
        // amplify: ends within a tenth of an edge, 5 % may differ; H = 0
        // crosses where k1 ≈ −k2 and its gradient is small, so its ends move
        // further: 10 %. The counts agree within 1 %.
        assert!(
            a.len().abs_diff(b.len()) * 100 <= b.len().max(100),
            "{}",
            fam.name()
        );
        let slack = if fam == LineFamily::HZero { 0.1 } else { 0.05 };
        same(&a, &b, 0.1 * fs, slack, fam.name());
    }
}

#[test]
fn the_default_solve_draws_analytic_lines_at_least_as_well_as_rtsc_s() {
    use shapecue::report::lines::analytic_errors;
    use shapecue::spec::curvature::Compat;
    let exact = analytic_errors(&gpu(), Compat::Exact).unwrap();
    let rtsc = analytic_errors(&gpu(), Compat::Trimesh2).unwrap();
    println!("solve | torus K = 0 error | ellipsoid ridge error");
    println!(
        "exact | {:.3e} | {:.3e}",
        exact.torus_k_zero, exact.ellipsoid_ridges
    );
    println!(
        "trimesh2 | {:.3e} | {:.3e}",
        rtsc.torus_k_zero, rtsc.ellipsoid_ridges
    );
    assert!(exact.torus_k_zero < 0.02 && exact.ellipsoid_ridges < 0.05);
    assert!(exact.torus_k_zero <= rtsc.torus_k_zero * 1.001);
    assert!(exact.ellipsoid_ridges <= rtsc.ellipsoid_ridges * 1.001);
}

/// rtsc's draw_isolines draws in a face only where some corner is above
/// zero and some below: a face whose corners are 0, 0 and negative crosses
/// nothing (it drew a segment along its zero edge, as on fandisk, whose
/// flat patches have K exactly 0 at 1,471 vertices).
#[test]
fn faces_touching_zero_without_crossing_it_draw_nothing() {
    let n = 9;
    let m = mesh::plane(n, 2.0);
    let nv = m.n_vertices();
    // K = k1 k2 is 0 on the first rows, negative on the others; H = (k1 +
    // k2) / 2 is 0 on the last rows, positive on the others.
    let k: Vec<[f32; 2]> = (0..nv)
        .map(|v| {
            if v / n < n / 2 {
                [1.0, 0.0]
            } else {
                [1.0, -1.0]
            }
        })
        .collect();
    let x = LineArrays {
        pos: to_f32(&m.positions),
        nrm: vec![[0.0, 0.0, 1.0]; nv],
        d1: vec![[1.0, 0.0, 0.0]; nv],
        d2: vec![[0.0, 1.0, 0.0]; nv],
        k,
        dk: vec![[0.0; 4]; nv],
    };
    let view = View::from_eye([0.3, 0.2, 5.0], false);
    for fam in [LineFamily::KZero, LineFamily::HZero] {
        let s = device(&m, &x, view, 1.0, only(&[fam], |_| {}));
        assert!(
            s.is_empty(),
            "{fam:?}: {} segments on faces that cross no zero",
            s.len()
        );
    }
    // A real crossing still draws: K from −1 to +1 across the rows.
    let mut y = x;
    y.k = (0..nv)
        .map(|v| {
            if v / n < n / 2 {
                [1.0, 1.0]
            } else {
                [1.0, -1.0]
            }
        })
        .collect();
    let s = device(&m, &y, view, 1.0, only(&[LineFamily::KZero], |_| {}));
    assert!(!s.is_empty());
}
