//! CPU reference of `kernels/ao.cl`: ambient occlusion from curvature, three
//! accuracy levels (see the kernel file for the derivation), plus the f64
//! reference integral the levels are measured against and the table the
//! `lut` level interpolates (both in [`crate::spec::ao`], shared with the
//! host wiring).

use crate::spec::ao::{AO_SAMPLES, dirs};

use crate::spec::ao::AoMode;

fn lut_coord(x: f32, n: usize) -> f32 {
    let t = x / (1.0 + x.abs());
    ((t + 1.0) * 0.5 * (n - 1) as f32).clamp(0.0, (n - 1) as f32)
}

/// `ao_vertex` for one vertex (same f32 steps as the kernel).
pub fn ao_vertex(k1: f32, k2: f32, radius: f32, mode: AoMode, lut: &[f32], n: usize) -> f32 {
    let (a, b) = (k1 * radius, k2 * radius);
    let r = if !a.is_finite() || !b.is_finite() {
        1.0
    } else {
        match mode {
            AoMode::Poly => {
                let s = a + b;
                1.0 - 0.0022 * s * s + 0.0776 * s + 0.7369
            }
            AoMode::Lut => {
                let (u, v) = (lut_coord(a, n), lut_coord(b, n));
                let (i, j) = ((u as usize).min(n - 2), (v as usize).min(n - 2));
                let (fu, fv) = (u - i as f32, v - j as f32);
                let l = |i: usize, j: usize| lut[i * n + j];
                (1.0 - fu) * ((1.0 - fv) * l(i, j) + fv * l(i, j + 1))
                    + fu * ((1.0 - fv) * l(i + 1, j) + fv * l(i + 1, j + 1))
            }
            AoMode::Exact => {
                static D: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
                let d = D.get_or_init(dirs);
                (0..AO_SAMPLES)
                    .map(|i| {
                        let q = -(a * d[2 * i] + b * d[2 * i + 1]);
                        if q.is_nan() || q <= 0.0 {
                            1.0
                        } else {
                            let c = if q < 1e18 {
                                q / (1.0 + (1.0 + q * q).sqrt())
                            } else {
                                1.0
                            };
                            1.0 - c * c
                        }
                    })
                    .sum::<f32>()
                    / AO_SAMPLES as f32
            }
        }
    };
    r.clamp(0.0, 1.0)
}
