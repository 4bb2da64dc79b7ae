//! Shared types of the `ao` family (see [`crate::spec`]): the accuracy level
//! ([`AoMode`]), the table of the `lut` level ([`LUT_N`], [`build_lut`],
//! [`lut`]) with the f64 integral it tabulates ([`ao_reference`]), and the
//! directions of the `exact` level ([`AO_SAMPLES`], [`dirs`]). The host
//! builds the table and the directions once and uploads them; the CPU twin
//! (`cpu::ao`) reads the same ones, so both sides interpolate the same values.
//!
//! Mirrors in `kernels/ao.cl`: `ao_vertex`'s `mode` argument is
//! [`AoMode::code`] (0 poly, 1 lut, 2 exact); `#define AO_SAMPLES 256` is
//! [`AO_SAMPLES`]; the `lut` buffer is `float[n·n]` with `n` = [`LUT_N`]
//! (a kernel argument), `dirs` is `float[2·AO_SAMPLES]`. Scalar arguments
//! only: no parameter struct crosses.

use std::sync::OnceLock;

/// Accuracy level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AoMode {
    /// Griffin et al.'s polynomial along the table's diagonal.
    Poly,
    /// Bilinear lookup in a precomputed table.
    Lut,
    /// The integral evaluated per vertex (256 directions).
    Exact,
}

impl AoMode {
    /// All levels, fastest first.
    pub const ALL: [AoMode; 3] = [AoMode::Poly, AoMode::Lut, AoMode::Exact];

    /// Kernel mode number (`ao_vertex`'s `mode`).
    pub fn code(self) -> u32 {
        match self {
            AoMode::Poly => 0,
            AoMode::Lut => 1,
            AoMode::Exact => 2,
        }
    }

    /// The name used in scene files (`ao_mode`), stats and bench ids.
    pub fn name(self) -> &'static str {
        match self {
            AoMode::Poly => "poly",
            AoMode::Lut => "lut",
            AoMode::Exact => "exact",
        }
    }
}

super::named_choice!(AoMode, "AO mode");

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

/// The `lut` level's table of side [`LUT_N`] (built on first use, once per
/// process).
pub fn lut() -> &'static [f32] {
    static L: OnceLock<Vec<f32>> = OnceLock::new();
    L.get_or_init(|| build_lut(LUT_N))
}

/// Directions of the `exact` level's midpoint rule on [0, π/2]
/// (`AO_SAMPLES` in the kernel).
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

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/ao.cl`.
    pub enum AoKernel {
        /// Ambient occlusion of each vertex from (k1, k2).
        Vertex = "ao_vertex",
    }
}
