//! CPU reference of `kernels/ao.cl`: ambient occlusion from curvature, three
//! accuracy levels (see the kernel file for the derivation), plus the f64
//! reference integral the levels are measured against and the table the
//! `lut` level interpolates.

use serde::Serialize;

/// Accuracy level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AoMode {
    /// The seed's polynomial along the table's diagonal.
    Poly,
    /// Bilinear lookup in a precomputed table.
    Lut,
    /// The integral evaluated per vertex (256 directions).
    Exact,
}

impl AoMode {
    /// All levels, fastest first.
    pub const ALL: [AoMode; 3] = [AoMode::Poly, AoMode::Lut, AoMode::Exact];

    /// Kernel mode number.
    pub fn code(self) -> u32 {
        match self {
            AoMode::Poly => 0,
            AoMode::Lut => 1,
            AoMode::Exact => 2,
        }
    }
}

/// Table side used by the stage.
pub const LUT_N: usize = 128;

fn visible64(q: f64) -> f64 {
    if q.is_nan() || q <= 0.0 {
        return 1.0;
    }
    let c = q / (1.0 + 1f64.hypot(q));
    1.0 - c * c
}

/// The reference: the integral in f64 with 4096 directions on [0, π/2].
pub fn ao_reference(k1: f64, k2: f64, radius: f64) -> f64 {
    let (a, b) = (k1 * radius, k2 * radius);
    if !a.is_finite() || !b.is_finite() {
        return 1.0;
    }
    let n = 4096;
    (0..n)
        .map(|i| {
            let phi = (i as f64 + 0.5) * std::f64::consts::FRAC_PI_2 / n as f64;
            let (c, s) = (phi.cos(), phi.sin());
            visible64(-(a * c * c + b * s * s))
        })
        .sum::<f64>()
        / n as f64
}

/// The table: AO at (x/(1+|x|), y/(1+|y|)) on an n×n grid over (−1, 1)²,
/// row-major in the first coordinate (the edges map to ±huge curvatures).
pub fn build_lut(n: usize) -> Vec<f32> {
    let inv = |t: f64| {
        let t = t.clamp(-0.999_999, 0.999_999);
        t / (1.0 - t.abs())
    };
    let mut v = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let ti = 2.0 * i as f64 / (n - 1) as f64 - 1.0;
            let tj = 2.0 * j as f64 / (n - 1) as f64 - 1.0;
            v.push(ao_reference(inv(ti), inv(tj), 1.0) as f32);
        }
    }
    v
}

/// Directions of the `exact` level's midpoint rule on [0, π/2].
pub const AO_SAMPLES: usize = 256;

/// (cos²φ, sin²φ) of the `exact` level's directions (f32, uploaded as is).
pub fn dirs() -> Vec<f32> {
    (0..AO_SAMPLES)
        .flat_map(|i| {
            let phi = (i as f32 + 0.5) * (std::f32::consts::FRAC_PI_2 / AO_SAMPLES as f32);
            let (c, s) = (phi.cos(), phi.sin());
            [c * c, s * s]
        })
        .collect()
}

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
