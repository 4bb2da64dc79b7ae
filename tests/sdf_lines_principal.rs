//! Curvature-directed strokes (`sdf_lines`): principal curvatures and
//! directions of the field (the CPU twin and the device probe) at umbilic
//! and flat points, and regression tests for the defects of the published
//! Unity implementation (a zero eigenvector, an unnormalised basis, a
//! difference divided by e instead of 2e, the last RK4 stage).

mod common;

use common::gpu;
use common::sdf_fields::*;
use shapecue::cpu::sdf_lines::{self as twin, Field, Principal};
use shapecue::spec::sdf_lines::*;
use shapecue::stages::sdf_lines::{SdfLines, principal_probe};

/// Principal curvature checks shared by the twin and the device probe.
fn principal_both(g: [f64; 3], h: [[f64; 3]; 3]) -> (Principal, Principal) {
    let cpu = twin::principal(g, h);
    let gf = g.map(|c| c as f32);
    let hf: [f32; 9] = std::array::from_fn(|i| h[i / 3][i % 3] as f32);
    let dev = principal_probe(&gpu(), &[gf], &[hf]).unwrap()[0];
    (cpu, dev)
}

#[test]
fn unity_defect_zero_eigenvector_when_fxy_is_zero() {
    // Tangent-plane Hessian diag(a, c) with a > c and b = 0: the form
    // (2 fxy, fyy − fxx + D) of the Unity code is (0, 0) here.
    let g = [0.0, 0.0, 1.0];
    let (u, v) = twin::tangent_basis(g);
    let (a, c) = (3.0, 1.0);
    let h: [[f64; 3]; 3] =
        std::array::from_fn(|r| std::array::from_fn(|s| a * u[r] * u[s] + c * v[r] * v[s]));
    for p in [principal_both(g, h).0, principal_both(g, h).1] {
        assert!(p.valid);
        assert!(
            (p.k1 - 3.0).abs() < 1e-5 && (p.k2 - 1.0).abs() < 1e-5,
            "{p:?}"
        );
        assert!(p.d1.iter().all(|x| x.is_finite()));
        assert!(dot(p.d1, u).abs() > 0.9999, "d1 {:?} is not u {u:?}", p.d1);
    }
}

#[test]
fn umbilic_and_flat_points_have_a_defined_direction() {
    let g = [0.3, -0.2, 0.9];
    let n = {
        let l = dot(g, g).sqrt();
        g.map(|c| c / l)
    };
    let sphere: [[f64; 3]; 3] =
        std::array::from_fn(|r| std::array::from_fn(|s| (r == s) as u8 as f64 - n[r] * n[s]));
    for h in [sphere, [[0.0; 3]; 3]] {
        let (c, d) = principal_both(g, h);
        for p in [c, d] {
            assert!(p.valid && p.d1.iter().all(|x| x.is_finite()));
            assert!((dot(p.d1, p.d1) - 1.0).abs() < 1e-5 && dot(p.d1, n).abs() < 1e-5);
        }
    }
    // Zero or NaN gradient: invalid, all zero, no NaN.
    for g in [[0.0; 3], [f64::NAN, 0.0, 1.0]] {
        let (c, d) = principal_both(g, sphere);
        for p in [c, d] {
            assert!(!p.valid && p.k1 == 0.0 && p.d1 == [0.0; 3]);
        }
    }
}

#[test]
fn unity_defect_unnormalised_basis_and_gradient_scale() {
    // Sphere of radius 2 seen with a normal at 45° to the axes (|n × e| ≠ 1)
    // and a field whose gradient has length 3 (not a distance).
    let n = [1.0f64, 1.0, 0.3];
    let l = dot(n, n).sqrt();
    let n = n.map(|c| c / l);
    for scale in [1.0, 3.0] {
        let g = n.map(|c| c * scale);
        let h: [[f64; 3]; 3] = std::array::from_fn(|r| {
            std::array::from_fn(|s| scale * ((r == s) as u8 as f64 - n[r] * n[s]) / 2.0)
        });
        let (c, d) = principal_both(g, h);
        for p in [c, d] {
            assert!(
                (p.k1 - 0.5).abs() < 1e-5 && (p.k2 - 0.5).abs() < 1e-5,
                "{p:?}"
            );
        }
    }
}

/// Paraboloid z = ½(ka x² + kb y²) as f = ½(ka x² + kb y²) − z (scaled by
/// `s`): central differences of a quadratic are exact, so the curvature at
/// the origin is (ka, kb) up to rounding: a gradient difference divided by
/// e instead of 2e would double it.
#[test]
fn unity_defect_difference_divided_by_2e_and_world_offsets() {
    let (ka, kb) = (1.5, -0.5);
    for (scale, res) in [(1.0, 33), (3.0, 33), (1.0, 65)] {
        let mut vol = field(res, |p| {
            scale * (0.5 * (ka * p[0] * p[0] + kb * p[1] * p[1]) - p[2])
        });
        // Stretch the box: the sampling distance is in world units, so the
        // same world h gives the same curvature whatever the box size.
        for box_scale in [1.0, 4.0] {
            let ka_w = ka / box_scale;
            vol.spacing = [2.0 / (res - 1) as f64 * box_scale; 3];
            vol.origin = [-box_scale; 3];
            vol.values = field(res, |p| {
                let q = p.map(|c| c * box_scale);
                scale * (0.5 * (ka_w * q[0] * q[0] + kb / box_scale * q[1] * q[1]) - q[2])
            })
            .values;
            let grad = twin::gradient(&vol);
            let f = Field::new(&vol, &grad, 0.0, Inside::Below);
            let o = local(&vol, [0.0; 3]);
            // Outward normal is −z (inside is above the paraboloid): convex along x.
            let h = 0.1 * box_scale;
            let c = f.curvature(o, h);
            assert!((c.k1 - ka_w).abs() < 1e-4, "k1 {} vs {ka_w}", c.k1);
            assert!((c.k2 - kb / box_scale).abs() < 1e-4, "k2 {}", c.k2);
            let mut s = SdfLines::new(gpu(), &vol, &SdfLineOptions::default()).unwrap();
            let d = s.curvature_at(&[o.map(|c| c as f32)], h).unwrap()[0];
            assert!(
                (d.k1 - ka_w).abs() < 1e-3 && (d.k2 - kb / box_scale).abs() < 1e-3,
                "{d:?}"
            );
        }
    }
}

#[test]
fn unity_defect_rk4_last_stage_from_the_start_point() {
    // Unit circle field d(p) = (−y, x)/|p|: one RK4 step from (1, 0) of dt.
    let dir = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1]).sqrt();
        Some([-p[1] / l, p[0] / l, 0.0])
    };
    let dt = 0.2;
    let q = twin::rk4_step([1.0, 0.0, 0.0], dt, [0.0, 1.0, 0.0], dir).unwrap();
    // Exact: rotating along the unit circle by arc dt, for a unit-speed
    // field the radius grows by O(dt²) for any one-step method; compare with
    // the exact integral curve of this (radius-preserving direction) field:
    // the point at arclength dt on the spiral r' = 0, i.e. the circle.
    let exact = [dt.cos(), dt.sin(), 0.0];
    let err = ((q[0] - exact[0]).powi(2) + (q[1] - exact[1]).powi(2)).sqrt();
    // The defective variant: k4 sampled at (p + dt k3) + dt k3.
    let p = [1.0, 0.0, 0.0];
    let ad = |a: [f64; 3], b: [f64; 3], s: f64| [a[0] + s * b[0], a[1] + s * b[1], 0.0];
    let k1 = dir(p).unwrap();
    let k2 = dir(ad(p, k1, dt / 2.0)).unwrap();
    let k3 = dir(ad(p, k2, dt / 2.0)).unwrap();
    let k4 = dir(ad(ad(p, k3, dt), k3, dt)).unwrap();
    let bad: [f64; 3] =
        std::array::from_fn(|a| p[a] + dt / 6.0 * (k1[a] + 2.0 * k2[a] + 2.0 * k3[a] + k4[a]));
    let bad_err = ((bad[0] - exact[0]).powi(2) + (bad[1] - exact[1]).powi(2)).sqrt();
    eprintln!("rk4 step error {err:e}, with the advanced last stage {bad_err:e}");
    assert!(err < 1e-5, "{err}");
    assert!(bad_err > 100.0 * err);
    // The sign of every stage follows the previous direction.
    let q2 = twin::rk4_step([1.0, 0.0, 0.0], dt, [0.0, -1.0, 0.0], dir).unwrap();
    assert!(q2[1] < 0.0);
}
