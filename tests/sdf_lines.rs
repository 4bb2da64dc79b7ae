//! Curvature-directed strokes (`sdf_lines`): the device against the CPU twin
//! step by step (dense samples, thinning, gradient, curvature, strokes),
//! analytic oracles (torus, cylinder, ellipsoid), and hard cases (never NaN,
//! never a hang). Principal directions at umbilic and flat points and the
//! published Unity implementation's defects: `sdf_lines_principal.rs`.

mod common;

use common::gpu;
use common::sdf_fields::*;
use shapecue::cpu::sdf_lines::{self as twin, DenseSample, Field};
use shapecue::spec::sdf_lines::*;
use shapecue::stages::sdf_lines::{SdfLines, layout_probe};
use shapecue::volume::Volume;
use shapecue::volume::sdf::{Sdf, TORUS_R, TORUS_TUBE, sdf};

#[test]
fn params_layout_matches_the_kernel() {
    let v = layout_probe(&gpu()).expect("probe");
    assert_eq!(v[0] as usize, std::mem::size_of::<SdflParams>());
    assert_eq!(v[1] as usize, std::mem::offset_of!(SdflParams, iso));
    assert_eq!(v[2] as usize, std::mem::offset_of!(SdflParams, length));
    assert_eq!(v[3] as usize, std::mem::offset_of!(SdflParams, seed));
}

fn sorted(mut d: Vec<DenseSample>) -> Vec<DenseSample> {
    d.sort_by_key(|s| s.key);
    d
}

#[test]
fn dense_samples_match_the_twin_bit_for_bit() {
    for (vol, iso) in [(sdf(Sdf::Torus, 48), 0.0), (sdf(Sdf::Gyroid, 40), 0.3)] {
        let opts = SdfLineOptions {
            iso,
            ..Default::default()
        };
        let cpu = twin::dense(&vol, iso, usize::MAX).unwrap();
        let mut s = SdfLines::new(gpu(), &vol, &opts).unwrap();
        let dev = sorted(s.dense().unwrap());
        assert!(!cpu.is_empty());
        assert_eq!(dev.len(), cpu.len());
        if gpu().bitwise_twins() {
            assert!(dev == cpu, "dense samples differ");
        } else {
            // A device without correctly rounded division (or a relaxed
            // build): the same crossings, each within 4 ulps of the twin's.
            for (d, c) in dev.iter().zip(&cpu) {
                assert_eq!(d.key, c.key, "dense samples on other grid edges");
                for a in 0..3 {
                    let ulps = (d.p[a].to_bits() as i64 - c.p[a].to_bits() as i64).abs();
                    assert!(ulps <= 4, "dense sample {:?} vs {:?}", d.p, c.p);
                }
            }
        }
        // On the marching-cubes vertices: every sample is a soup vertex position.
        let soup = shapecue::cpu::marching_cubes::mc_triangles(&vol, iso);
        let sp = vol.spacing.map(|s| s as f32);
        let set: std::collections::HashSet<[u32; 3]> = soup
            .iter()
            .map(|v| std::array::from_fn(|a| (v.p[a] * sp[a]).to_bits()))
            .collect();
        assert!(cpu.iter().all(|d| set.contains(&d.p.map(f32::to_bits))));
    }
}

#[test]
fn dense_bound_overflow_is_reported() {
    let vol = sdf(Sdf::Torus, 32);
    let opts = SdfLineOptions {
        max_dense: Some(100),
        ..Default::default()
    };
    let n = twin::dense(&vol, 0.0, usize::MAX).unwrap().len();
    let e = SdfLines::new(gpu(), &vol, &opts)
        .unwrap()
        .dense()
        .unwrap_err();
    assert!(e.to_string().contains(&n.to_string()), "{e}");
    let e = twin::run(&vol, &opts).unwrap_err();
    assert!(e.to_string().contains(&n.to_string()), "{e}");
}

#[test]
fn thinning_is_deterministic_valid_and_maximal() {
    let vol = sdf(Sdf::Torus, 64);
    let opts = SdfLineOptions::default();
    let r = 0.08;
    let samples = twin::dense(&vol, 0.0, usize::MAX).unwrap();
    let res = resolve(
        &SdfLineOptions {
            spacing: Some(r),
            ..opts.clone()
        },
        vol.spacing,
        0.03,
    )
    .unwrap();
    let p = twin::params(&vol, &opts, &res);
    let kept = twin::thin(&samples, &p, usize::MAX, r).unwrap();
    let cpu: Vec<[f32; 3]> = kept.iter().map(|&i| samples[i as usize].p).collect();
    // Order independence of the twin: reversed input, same seeds.
    let rev: Vec<DenseSample> = samples.iter().rev().copied().collect();
    let kept2 = twin::thin(&rev, &p, usize::MAX, r).unwrap();
    let cpu2: Vec<[f32; 3]> = kept2.iter().map(|&i| rev[i as usize].p).collect();
    assert_eq!(cpu, cpu2);
    let mut s = SdfLines::new(gpu(), &vol, &opts).unwrap();
    let a = s.thin(r).unwrap();
    let b = SdfLines::new(gpu(), &vol, &opts).unwrap().thin(r).unwrap();
    assert_eq!(a, b, "two device runs differ");
    // Bit for bit where divisions round as the twin's; elsewhere a sample
    // a few ulps away may win a tie, and validity and maximality (below)
    // are the promise.
    if gpu().bitwise_twins() {
        assert_eq!(a, cpu, "device differs from the twin");
    }
    // Valid: no two seeds closer than r (in f32, as the test is made).
    let r2 = p.r2;
    for i in 0..a.len() {
        for j in i + 1..a.len() {
            assert!(
                twin::dist2(a[i], a[j]) >= r2,
                "seeds {i} and {j} closer than r"
            );
        }
    }
    // Maximal: every dense sample within 2r of a seed (here: within r).
    let worst = samples
        .iter()
        .map(|s| {
            a.iter()
                .map(|q| twin::dist2(*q, s.p))
                .fold(f32::INFINITY, f32::min)
        })
        .fold(0.0f32, f32::max)
        .sqrt();
    assert!(
        worst <= 2.0 * r as f32,
        "a dense sample is {worst} from every seed"
    );
    assert!(worst <= r as f32 * 1.0001, "worst {worst} > r");
    eprintln!(
        "thinning r = {r}: {} seeds of {} samples, farthest sample {worst}",
        a.len(),
        samples.len()
    );
    // Another priority seed gives another (still valid) set.
    let other = SdfLines::new(
        gpu(),
        &vol,
        &SdfLineOptions {
            seed: 7,
            ..opts.clone()
        },
    )
    .unwrap()
    .thin(r)
    .unwrap();
    assert_ne!(other, a);
}

#[test]
fn gradient_matches_the_twin() {
    let mut vol = sdf(Sdf::Torus, 24);
    vol.spacing = [0.05, 0.07, 0.09];
    let cpu = twin::gradient(&vol);
    let dev = SdfLines::new(gpu(), &vol, &SdfLineOptions::default())
        .unwrap()
        .gradient()
        .unwrap();
    for (d, c) in dev.iter().zip(&cpu) {
        for a in 0..3 {
            assert!(
                (d[a] as f64 - c[a]).abs() <= 1e-5 * (1.0 + c[a].abs()),
                "{d:?} {c:?}"
            );
        }
    }
}

/// Tube direction on the torus at a point: the unit tangent of the tube's
/// cross-section circle.
fn tube_dir(p: [f64; 3]) -> [f64; 3] {
    let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
    let e = [p[0] / rho, p[1] / rho, 0.0];
    let q = rho - TORUS_R;
    // Normal in the (e, z) plane is (q, z)/r; the tangent is (−z, q)/r.
    let l = (q * q + p[2] * p[2]).sqrt();
    [-p[2] / l * e[0], -p[2] / l * e[1], q / l]
}

#[test]
fn torus_oracle_converges() {
    let mut prev: Option<f64> = None;
    for res in [48usize, 96, 192] {
        let vol = sdf(Sdf::Torus, res);
        let h = 2.0 * 2.0 / (res - 1) as f64;
        let opts = SdfLineOptions {
            sampling: Sampling::Fixed(h),
            spacing: Some(0.1),
            ..Default::default()
        };
        let mut s = SdfLines::new(gpu(), &vol, &opts).unwrap();
        let out = s.run().unwrap();
        let mut e2 = 0.0;
        let mut worst_dir = 1.0f64;
        for sd in &out.seeds {
            let err = sd.k1 - 1.0 / TORUS_TUBE;
            e2 += err * err;
            worst_dir = worst_dir.min(dot(sd.d1, tube_dir(sd.p)).abs());
        }
        let rms = (e2 / out.seeds.len() as f64).sqrt();
        eprintln!(
            "torus {res}³ h = 2 voxels: {} seeds, k1 RMS error {rms:.3e} (1/r = 4), worst |d1·tube| {worst_dir:.5}",
            out.seeds.len()
        );
        assert!(worst_dir > 0.99, "{worst_dir}");
        assert!(rms < 0.1 * 4.0);
        if let Some(p) = prev {
            eprintln!("  order {:.2}", (p / rms).log2());
            assert!(rms < 0.6 * p, "error does not shrink: {p} → {rms}");
        }
        prev = Some(rms);
    }
}

#[test]
fn strokes_stay_on_the_surface_along_d1_and_match_the_twin() {
    let res = 64;
    let vol = sdf(Sdf::Torus, res);
    let opts = SdfLineOptions {
        spacing: Some(0.15),
        ..fixed(3.0, res)
    };
    let dev = SdfLines::new(gpu(), &vol, &opts).unwrap().run().unwrap();
    let cpu = twin::run(&vol, &opts).unwrap();
    assert!(all_finite(&dev) && all_finite(&cpu));
    assert!(dev.stats.strokes > 20, "{:?}", dev.stats);
    let grad = twin::gradient(&vol);
    let f = Field::new(&vol, &grad, 0.0, Inside::Below);
    let h = dev.stats.params.unwrap().sampling;
    let voxel = vol.spacing[0];
    let (mut worst_f, mut worst_t) = (0.0f64, 1.0f64);
    for st in &dev.strokes {
        for w in st.points.windows(2) {
            let q = local(&vol, w[0]);
            worst_f = worst_f.max(f.value(q).abs());
            let t: [f64; 3] = std::array::from_fn(|a| w[1][a] - w[0][a]);
            let l = dot(t, t).sqrt();
            let d1 = f.curvature(q, h).d1;
            worst_t = worst_t.min(dot(t.map(|c| c / l), d1).abs());
        }
        assert!(st.widths[0] == 0.0 && *st.widths.last().unwrap() == 0.0);
        assert_eq!(st.strip.len(), 2 * st.points.len());
    }
    eprintln!("torus 64³: worst |f| {worst_f:.2e} (voxel {voxel:.3}), worst |t·d1| {worst_t:.5}");
    assert!(worst_f < 1e-3 * voxel, "{worst_f}");
    assert!(worst_t >= 0.99, "{worst_t}");
    // Seed spacing ≥ r.
    let r = 0.15;
    for i in 0..dev.seeds.len() {
        for j in i + 1..dev.seeds.len() {
            let d: [f64; 3] = std::array::from_fn(|a| dev.seeds[i].p[a] - dev.seeds[j].p[a]);
            assert!(dot(d, d).sqrt() >= r * (1.0 - 1e-5));
        }
    }
    // Device vs twin: same seeds, same curvature, same strokes.
    assert_eq!(dev.seeds.len(), cpu.seeds.len());
    for (a, b) in dev.seeds.iter().zip(&cpu.seeds) {
        assert!(a.p.iter().zip(&b.p).all(|(x, y)| (x - y).abs() < 1e-6));
        assert!(
            (a.k1 - b.k1).abs() < 1e-3 * (1.0 + b.k1.abs()),
            "{} {}",
            a.k1,
            b.k1
        );
        assert!(dot(a.d1, b.d1).abs() > 0.9999);
    }
    assert_eq!(dev.strokes.len(), cpu.strokes.len());
    let mut max_d = 0.0f64;
    let mut same_len = 0;
    for (a, b) in dev.strokes.iter().zip(&cpu.strokes) {
        assert_eq!(a.seed, b.seed);
        if a.points.len() == b.points.len() {
            same_len += 1;
            // d1's sign is free: the twin may trace the stroke the other way.
            let dist = |rev: bool| {
                let mut m = 0.0f64;
                for (i, p) in a.points.iter().enumerate() {
                    let q = if rev {
                        b.points[b.points.len() - 1 - i]
                    } else {
                        b.points[i]
                    };
                    let d: [f64; 3] = std::array::from_fn(|i| p[i] - q[i]);
                    m = m.max(dot(d, d).sqrt());
                }
                m
            };
            let dd = dist(false).min(dist(true));
            max_d = max_d.max(dd);
        }
    }
    eprintln!(
        "device vs twin: {same_len}/{} strokes of equal length, max point distance {max_d:.2e}",
        dev.strokes.len()
    );
    assert!(same_len * 10 >= dev.strokes.len() * 9);
    assert!(max_d < 0.05 * voxel, "{max_d}");
}

#[test]
fn sphere_signs_and_umbilic() {
    let vol = sdf(Sdf::Sphere, 48);
    let out = SdfLines::new(gpu(), &vol, &fixed(2.0, 48))
        .unwrap()
        .run()
        .unwrap();
    assert!(all_finite(&out));
    assert!(!out.seeds.is_empty());
    for s in &out.seeds {
        assert!(
            (s.k1 - 1.25).abs() < 0.05 && (s.k2 - 1.25).abs() < 0.05,
            "{s:?}"
        );
        assert!(dot(s.n, s.p) > 0.0, "normal not outward");
    }
    eprintln!(
        "sphere 48³: {} seeds, {} strokes (umbilic everywhere)",
        out.seeds.len(),
        out.stats.strokes
    );
    // inside = above on the negated field: same curvatures.
    let mut neg = vol.clone();
    neg.values.iter_mut().for_each(|v| *v = -*v);
    let o2 = SdfLines::new(
        gpu(),
        &neg,
        &SdfLineOptions {
            inside: Inside::Above,
            ..Default::default()
        },
    )
    .unwrap()
    .run()
    .unwrap();
    assert!(o2.seeds.iter().all(|s| s.k1 > 1.0 && dot(s.n, s.p) > 0.0));
}

#[test]
fn cylinder_and_ellipsoid_oracles() {
    let res = 96;
    let voxel = 2.0 / (res - 1) as f64;
    // Cylinder of radius 0.5 along z: k1 = 2, k2 = 0, d1 around the axis.
    let cyl = field(res, |p| (p[0] * p[0] + p[1] * p[1]).sqrt() - 0.5);
    let grad = twin::gradient(&cyl);
    let f = Field::new(&cyl, &grad, 0.0, Inside::Below);
    let h = 2.0 * voxel;
    let mut s = SdfLines::new(gpu(), &cyl, &SdfLineOptions::default()).unwrap();
    let pts: Vec<[f32; 3]> = (0..16)
        .map(|i| {
            let a = i as f64 * 0.39 + 0.1;
            local(&cyl, [0.5 * a.cos(), 0.5 * a.sin(), -0.5 + i as f64 / 16.0]).map(|c| c as f32)
        })
        .collect();
    let dev = s.curvature_at(&pts, h).unwrap();
    let mut worst = 0.0f64;
    for (q, d) in pts.iter().zip(&dev) {
        let q = q.map(|c| c as f64);
        let c = f.curvature(q, h);
        let w = [q[0] - 1.0, q[1] - 1.0, 0.0];
        let around = [-w[1], w[0], 0.0].map(|c| c / (w[0] * w[0] + w[1] * w[1]).sqrt());
        for p in [c, *d] {
            worst = worst.max((p.k1 - 2.0).abs()).max(p.k2.abs());
            assert!(dot(p.d1, around).abs() > 0.999, "{:?}", p.d1);
        }
    }
    eprintln!("cylinder r = 0.5 at 96³, h = 2 voxels: worst |k - analytic| {worst:.3e}");
    assert!(worst < 0.05);
    // Ellipsoid (a, b, c) = (0.8, 0.5, 0.4) as sqrt(x²/a² + y²/b² + z²/c²) − 1
    // (not a distance: |∇f| ≠ 1): at (a, 0, 0) the curvatures are a/b², a/c².
    let (a, b, c) = (0.8, 0.5, 0.4);
    let ell = field(res, |p| {
        (p[0] * p[0] / (a * a) + p[1] * p[1] / (b * b) + p[2] * p[2] / (c * c)).sqrt() - 1.0
    });
    let grad = twin::gradient(&ell);
    let f = Field::new(&ell, &grad, 0.0, Inside::Below);
    let q = local(&ell, [a, 0.0, 0.0]);
    let mut s = SdfLines::new(gpu(), &ell, &SdfLineOptions::default()).unwrap();
    let d = s.curvature_at(&[q.map(|c| c as f32)], h).unwrap()[0];
    let cc = f.curvature(q, h);
    let (k1, k2) = (a / (c * c), a / (b * b));
    eprintln!(
        "ellipsoid at (a,0,0), 96³, h = 2 voxels: k1 {:.4} / {k1:.4}, k2 {:.4} / {k2:.4} (device {:.4}, {:.4})",
        cc.k1, cc.k2, d.k1, d.k2
    );
    for p in [cc, d] {
        assert!(
            (p.k1 - k1).abs() < 0.03 * k1 && (p.k2 - k2).abs() < 0.03 * k2,
            "{p:?}"
        );
        assert!(p.d1[2].abs() > 0.999, "d1 along z: {:?}", p.d1);
    }
}

fn run_both(vol: &Volume, opts: &SdfLineOptions) -> (SdfLinesOutput, SdfLinesOutput) {
    let d = SdfLines::new(gpu(), vol, opts).unwrap().run().unwrap();
    let c = twin::run(vol, opts).unwrap();
    assert!(all_finite(&d) && all_finite(&c));
    assert_eq!(
        d.stats.seeds, c.stats.seeds,
        "{:?} {:?} / {:?} {:?}",
        d.stats.params, d.stats.sweep, c.stats.params, c.stats.sweep
    );
    (d, c)
}

#[test]
fn hard_cases_constant_empty_border_nan_plane() {
    let opts = SdfLineOptions::default();
    // Constant field and a field with no surface: nothing, no error.
    for v in [0.0f32, 1.0] {
        let vol = field(16, |_| v as f64);
        let (d, _) = run_both(&vol, &opts);
        assert_eq!((d.stats.dense, d.stats.seeds, d.stats.strokes), (0, 0, 0));
    }
    // A sphere cut by the border of the box.
    let vol = field(40, |p| {
        (p[0] * p[0] + p[1] * p[1] + (p[2] - 0.7).powi(2)).sqrt() - 0.8
    });
    let (d, _) = run_both(&vol, &opts);
    assert!(d.stats.seeds > 0);
    // NaN voxels in a slab through the torus.
    let mut vol = sdf(Sdf::Torus, 40);
    for z in 18..21 {
        for i in 0..40 * 40 {
            vol.values[z * 1600 + i] = f32::NAN;
        }
    }
    let (d, _) = run_both(&vol, &fixed(2.0, 40));
    assert!(d.stats.seeds > 0 && d.stats.strokes > 0);
    // A plane: κ = 0 everywhere, seeds but no strokes (umbilic/flat).
    // (Fixed sampling: on a plane κ1 is rounding noise around 0, so its
    // coefficient of variation, and the automatic choice, mean nothing.)
    let vol = field(32, |p| p[2] - 0.1 + 0.05 * p[0]);
    let (d, _) = run_both(&vol, &fixed(2.0, 32));
    eprintln!(
        "plane: {} seeds, {} strokes",
        d.stats.seeds, d.stats.strokes
    );
    assert!(d.stats.seeds > 0);
    assert_eq!(d.stats.strokes, 0);
    assert!(d.seeds.iter().all(|s| s.k1.abs() < 1e-3));
}

#[test]
fn hard_cases_tiny_and_huge_spacing() {
    let vol = sdf(Sdf::Torus, 48);
    let tiny = SdfLineOptions {
        spacing: Some(1e-4),
        ..fixed(2.0, 48)
    };
    let e = SdfLines::new(gpu(), &vol, &tiny)
        .unwrap()
        .run()
        .unwrap_err();
    assert!(e.to_string().contains("cells"), "{e}");
    let e2 = twin::run(&vol, &tiny).unwrap_err();
    assert_eq!(e.to_string(), e2.to_string());
    // Small but allowed by the grid: the traced-point bound names the seeds.
    let small = SdfLineOptions {
        spacing: Some(0.01),
        max_points: 100_000,
        ..fixed(2.0, 48)
    };
    let e = SdfLines::new(gpu(), &vol, &small)
        .unwrap()
        .run()
        .unwrap_err();
    eprintln!("tiny r: {e}");
    assert!(e.to_string().contains("seeds"), "{e}");
    let huge = SdfLineOptions {
        spacing: Some(100.0),
        ..fixed(2.0, 48)
    };
    let (d, _) = run_both(&vol, &huge);
    assert_eq!(d.stats.seeds, 1);
}

#[test]
fn automatic_sampling_follows_the_cv_rule() {
    let vol = sdf(Sdf::Gyroid, 48);
    let (d, c) = run_both(&vol, &SdfLineOptions::default());
    assert_eq!(d.stats.sweep.len(), AUTO_SAMPLING_VOXELS.len());
    let h = d.stats.params.unwrap().sampling;
    assert_eq!(Some(h), pick_sampling(&d.stats.sweep));
    assert_eq!(h, c.stats.params.unwrap().sampling);
    for (a, b) in d.stats.sweep.iter().zip(&c.stats.sweep) {
        assert!((a.cv - b.cv).abs() < 1e-3, "{a:?} {b:?}");
    }
    let best = d
        .stats
        .sweep
        .iter()
        .map(|c| (c.cv - 1.0).abs())
        .fold(f64::INFINITY, f64::min);
    assert!(
        d.stats
            .sweep
            .iter()
            .any(|c| c.distance == h && (c.cv - 1.0).abs() == best)
    );
}

/// Renders a field's isosurface with its strokes (and the strokes alone)
/// to `/tmp/sdf-<name>*.png`, plus SVG and PLY; skipped without headless GL.
fn picture(name: &str, vol: &Volume, opts: &SdfLineOptions, eye: [f32; 3]) {
    use shapecue::cpu::marching_cubes::{gradient_normals, mc_triangles};
    use shapecue::cpu::vertex_fusion::fuse;
    use shapecue::render::strokes::{StrokeStyle, draw};
    use shapecue::render::{Camera, MeshStyle, RenderOptions, Renderer};
    use shapecue::spec::vertex_fusion::Fusion;
    let out = SdfLines::new(gpu(), vol, opts).unwrap().run().unwrap();
    eprintln!("{name}: {:?}", out.stats);
    let mesh = fuse(&mc_triangles(vol, opts.iso), Fusion::Edge);
    let normals: Vec<[f32; 3]> = gradient_normals(vol, &mesh.positions)
        .iter()
        .map(|n| n.map(|c| c as f32))
        .collect();
    let pos: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| std::array::from_fn(|a| (vol.origin[a] + vol.spacing[a] * p[a] as f64) as f32))
        .collect();
    let mut r = match Renderer::new(RenderOptions {
        width: 800,
        height: 800,
        ..Default::default()
    }) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("skipping the pictures: {e}");
            return;
        }
    };
    let lo = glam::Vec3::from_array(vol.origin.map(|c| c as f32));
    let ext = twin::extent(vol).map(|c| c as f32);
    let cam = Camera::fit(
        lo,
        lo + glam::Vec3::from_array(ext),
        glam::Vec3::from_array(eye),
        1.0,
    )
    .unwrap();
    let style = StrokeStyle {
        lift: 0.5 * vol.spacing[0] as f32,
        ..Default::default()
    };
    r.begin(&cam).unwrap();
    r.draw_mesh(&pos, &normals, &[], &mesh.faces, MeshStyle::default())
        .unwrap();
    draw(&mut r, &cam, &out.strokes, &style).unwrap();
    let f = r.finish().unwrap();
    f.save_png(std::path::Path::new(&format!("/tmp/sdf-{name}.png")))
        .unwrap();
    r.begin(&cam).unwrap();
    draw(&mut r, &cam, &out.strokes, &style).unwrap();
    let f = r.finish().unwrap();
    f.save_png(std::path::Path::new(&format!("/tmp/sdf-{name}-alone.png")))
        .unwrap();
    let dir = std::env::temp_dir();
    shapecue::export::strokes::write_svg(
        &dir.join(format!("sdf-{name}.svg")),
        &out.strokes,
        &cam,
        [800, 800],
    )
    .unwrap();
    shapecue::export::strokes::write_ply(&dir.join(format!("sdf-{name}.ply")), &out.strokes)
        .unwrap();
}

#[test]
fn pictures_torus_and_gyroid() {
    picture(
        "torus",
        &sdf(Sdf::Torus, 128),
        &SdfLineOptions::default(),
        [0.3, -1.0, 0.9],
    );
    let gyroid = SdfLineOptions {
        sampling: Sampling::Fixed(0.04),
        spacing: Some(0.06),
        length: Some(0.3),
        width: Some(0.025),
        length_low: 1.0,
        ..Default::default()
    };
    let mut vol = sdf(Sdf::Gyroid, 96);
    // A quarter of the gyroid's cube, for a readable picture.
    vol = shapecue::volume::Volume {
        dims: [48; 3],
        spacing: vol.spacing,
        origin: vol.origin,
        values: (0..48 * 48 * 48)
            .map(|i| vol.value(i % 48, i / 48 % 48, i / 2304))
            .collect(),
    };
    picture("gyroid", &vol, &gyroid, [1.0, 0.8, 0.6]);
}
