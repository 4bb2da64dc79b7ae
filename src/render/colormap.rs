//! Per-vertex colours for the scene renderer: the curvature colour map of
//! Griffin et al. 2012 (Fig. 1 and 7: blue concave, red convex, green saddle) and AO
//! baked into vertex colours, so that the mesh shader's Lambert term times
//! the colour gives Lambert × AO.
//!
//! Sign convention: k1, k2 > 0 where the surface bends away from its
//! (outward) normal, i.e. convex, as the curvature stage returns them.

/// Convex (both principal curvatures positive).
pub const CONVEX: [f32; 3] = [0.85, 0.12, 0.1];
/// Concave (both negative).
pub const CONCAVE: [f32; 3] = [0.1, 0.25, 0.9];
/// Saddle (opposite signs).
pub const SADDLE: [f32; 3] = [0.1, 0.75, 0.2];

/// The colour of a vertex with principal curvatures `k1`, `k2`, blended from
/// `base` (flat or parabolic) towards red, blue or green:
/// - elliptic or parabolic (K = k1·k2 ≥ 0): towards red (H > 0) or blue
///   (H < 0) by tanh(|H| / scale), H the mean curvature;
/// - hyperbolic (K < 0): towards green by tanh(√−K / scale).
///
/// `scale` (> 0, world units⁻¹) sets where colours saturate. Non-finite
/// curvatures give `base`; the result is always in [0, 1].
pub fn curvature_color(k1: f32, k2: f32, scale: f32, base: [f32; 3]) -> [f32; 3] {
    if !(k1.is_finite() && k2.is_finite() && scale.is_finite() && scale > 0.0) {
        return base;
    }
    // In f64 so that huge curvatures (1e30) do not overflow the product.
    let (a, b, s) = (k1 as f64, k2 as f64, scale as f64);
    let k = a * b;
    let (target, t) = if k >= 0.0 {
        let h = 0.5 * (a + b);
        (
            if h >= 0.0 { CONVEX } else { CONCAVE },
            (h.abs() / s).tanh(),
        )
    } else {
        (SADDLE, ((-k).sqrt() / s).tanh())
    };
    let t = t as f32;
    std::array::from_fn(|i| (base[i] + (target[i] - base[i]) * t).clamp(0.0, 1.0))
}

/// A colour scale for a curvature field: the 90th percentile of
/// √((k1² + k2²)/2) over the finite vertices (1 when there are none or it is 0).
pub fn curvature_scale(k: &[[f32; 2]]) -> f32 {
    let mut m: Vec<f32> = k
        .iter()
        .map(|&[a, b]| ((a as f64 * a as f64 + b as f64 * b as f64) / 2.0).sqrt() as f32)
        .filter(|v| v.is_finite())
        .collect();
    if m.is_empty() {
        return 1.0;
    }
    let i = ((m.len() - 1) as f64 * 0.9).round() as usize;
    let (_, v, _) = m.select_nth_unstable_by(i, f32::total_cmp);
    if *v > 0.0 { *v } else { 1.0 }
}

/// `color` × `ao` (AO clamped to [0, 1]; a non-finite AO counts as 1).
pub fn with_ao(color: [f32; 3], ao: f32) -> [f32; 3] {
    let a = if ao.is_finite() {
        ao.clamp(0.0, 1.0)
    } else {
        1.0
    };
    color.map(|c| c * a)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: [f32; 3] = [0.8, 0.8, 0.8];

    fn dominant(c: [f32; 3]) -> usize {
        (0..3).max_by(|&i, &j| c[i].total_cmp(&c[j])).unwrap()
    }

    #[test]
    fn convex_is_red_concave_blue_saddle_green_flat_base() {
        assert_eq!(dominant(curvature_color(2.0, 1.0, 1.0, BASE)), 0);
        assert_eq!(dominant(curvature_color(-1.0, -2.0, 1.0, BASE)), 2);
        assert_eq!(dominant(curvature_color(1.5, -1.5, 1.0, BASE)), 1);
        assert_eq!(curvature_color(0.0, 0.0, 1.0, BASE), BASE);
        // A cylinder (parabolic) is convex-ish: towards red, by |H|.
        let c = curvature_color(2.0, 0.0, 1.0, BASE);
        assert!(c[0] > c[1] && c[0] > c[2]);
    }

    #[test]
    fn stronger_curvature_is_more_saturated_and_everything_stays_in_range() {
        let weak = curvature_color(0.2, 0.1, 1.0, BASE);
        let strong = curvature_color(4.0, 2.0, 1.0, BASE);
        assert!(strong[1] < weak[1]);
        let nasty = [
            0.0,
            1e-30,
            -1e-30,
            1e30,
            -1e30,
            f32::MAX,
            f32::MIN,
            f32::NAN,
            f32::INFINITY,
        ];
        for &a in &nasty {
            for &b in &nasty {
                for s in [1e-30, 1.0, 1e30, 0.0, f32::NAN] {
                    let c = curvature_color(a, b, s, BASE);
                    assert!(
                        c.iter().all(|x| (0.0..=1.0).contains(x)),
                        "{a} {b} {s}: {c:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn scale_is_the_90th_percentile_and_ao_darkens() {
        let k: Vec<[f32; 2]> = (1..=100).map(|i| [i as f32, i as f32]).collect();
        assert_eq!(curvature_scale(&k), 90.0);
        assert_eq!(curvature_scale(&[]), 1.0);
        assert_eq!(curvature_scale(&[[0.0, 0.0], [f32::NAN, 1.0]]), 1.0);
        assert_eq!(with_ao([1.0, 0.5, 0.0], 0.5), [0.5, 0.25, 0.0]);
        assert_eq!(with_ao([1.0; 3], f32::NAN), [1.0; 3]);
        assert_eq!(with_ao([1.0; 3], 2.0), [1.0; 3]);
    }
}
