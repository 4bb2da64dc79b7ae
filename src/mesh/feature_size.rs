//! The feature size that scales the line families' thresholds, in the two
//! forms shapecue offers: rtsc's (Rusinkiewicz and DeCarlo's program, its
//! `compute_feature_size`), the default, and the median edge length.
//!
//! rtsc's feature size is fs = min(0.01 / p, 0.05 r): p is the 10th
//! percentile of |k1| and |k2| at 500 vertices drawn (with repeats) by a
//! linear congruential generator (x ← 1664525 x + 1013904223 mod 2³², from
//! 0, vertex x mod n), and r the radius of the smallest sphere enclosing
//! every vertex (trimesh2's `need_bsphere`, an exact miniball). The same
//! sampler and percentile give the same number as rtsc on the same
//! curvature.

use crate::spec::feature_lines::FeatureSize;

/// Vertices rtsc samples for its feature size (at most).
pub const RTSC_SAMPLES: usize = 500;

/// The vertex indices rtsc's generator draws for a mesh of `n` vertices:
/// min(n, 500) of them, with repeats, in draw order.
pub fn rtsc_sample_indices(n: usize) -> Vec<usize> {
    let mut q: u32 = 0;
    (0..n.min(RTSC_SAMPLES))
        .map(|_| {
            q = q.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (u64::from(q) % n as u64) as usize
        })
        .collect()
}

/// rtsc's feature size of a mesh of `n` vertices, from the principal
/// curvatures `k` gives by vertex (asked for the sampled vertices only, so a
/// field that stays on the device is read at 500 vertices, not all) and the
/// radius of the bounding sphere: min(0.01 / p, 0.05 r), p the 10th
/// percentile (index ⌊0.1 · 2m⌋ of the 2m sorted magnitudes) of |k1| and
/// |k2| at the sampled vertices. A non-finite curvature counts as the
/// largest; where p is 0 (a flat sample) the cap 0.05 r is the size, as in
/// rtsc. `None` for a mesh without vertices or a size that is not a finite
/// positive number (a zero radius and no curvature).
pub fn rtsc_feature_size(n: usize, k: &dyn Fn(usize) -> [f64; 2], radius: f64) -> Option<f64> {
    let idx = rtsc_sample_indices(n);
    let mut s: Vec<f32> = idx
        .iter()
        .flat_map(|&i| k(i))
        .map(|x| {
            // rtsc keeps its curvature in single precision.
            let a = (x as f32).abs();
            if a.is_finite() { a } else { f32::INFINITY }
        })
        .collect();
    if s.is_empty() {
        return None;
    }
    let which = (0.1f32 * s.len() as f32) as usize;
    let (_, p, _) = s.select_nth_unstable_by(which, f32::total_cmp);
    let cap = (0.05 * radius) as f32;
    let fs = (0.01f32 / *p).min(cap);
    (fs.is_finite() && fs > 0.0).then_some(f64::from(fs))
}

/// The smallest sphere enclosing the finite points (centre, radius), exact up
/// to rounding: Welzl's algorithm in its iterative form (each point, when
/// outside, is put on the boundary of the ball of the points before it),
/// over the points in a fixed pseudo-random order, so its expected time is
/// linear and its result the same on every run. `None` without a finite
/// point.
pub fn bounding_sphere(points: &[[f64; 3]]) -> Option<([f64; 3], f64)> {
    let mut p: Vec<[f64; 3]> = points
        .iter()
        .copied()
        .filter(|q| q.iter().all(|c| c.is_finite()))
        .collect();
    if p.is_empty() {
        return None;
    }
    // A fixed shuffle (Fisher-Yates on the same generator as rtsc's sampler).
    let mut q: u32 = 12345;
    for i in (1..p.len()).rev() {
        q = q.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        p.swap(i, (u64::from(q) % (i as u64 + 1)) as usize);
    }
    // Relative slack of the containment test, so that rounding does not make
    // a boundary point look outside and loop the algorithm on it.
    let scale = p
        .iter()
        .flat_map(|q| q.iter().map(|c| c.abs()))
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let eps = 1e-12 * scale * scale;
    let inside = |b: &Ball, x: &[f64; 3]| dist2(&b.c, x) <= b.r2 + eps;
    let mut b = Ball::of(&[p[0]]);
    for i in 1..p.len() {
        if inside(&b, &p[i]) {
            continue;
        }
        b = Ball::of(&[p[i]]);
        for j in 0..i {
            if inside(&b, &p[j]) {
                continue;
            }
            b = Ball::of(&[p[i], p[j]]);
            for k in 0..j {
                if inside(&b, &p[k]) {
                    continue;
                }
                b = Ball::of(&[p[i], p[j], p[k]]);
                for l in 0..k {
                    if inside(&b, &p[l]) {
                        continue;
                    }
                    b = Ball::of(&[p[i], p[j], p[k], p[l]]);
                }
            }
        }
    }
    Some((b.c, b.r2.sqrt()))
}

/// The feature size `choice` asks for, in the mesh's units: rtsc's from the
/// principal curvatures `k` gives (k1, k2 of a vertex, asked for the sampled
/// vertices only) and the bounding sphere of every vertex; the median edge
/// length ([`super::feature_size`]); or the value given. Where rtsc's has no curvature to read (a run that computes
/// none: contours from normals alone, isophotes, boundaries, none of which
/// reads a threshold) or gives no positive size, the median edge length;
/// where that is 0 too (no edge), the RMS distance from the centroid, else 1.
pub fn resolve(
    choice: FeatureSize,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    k: Option<&dyn Fn(usize) -> [f64; 2]>,
) -> f64 {
    let edge = || {
        let s = super::feature_size(positions, faces);
        if s > 0.0 && s.is_finite() {
            return s;
        }
        let finite: Vec<&[f64; 3]> = positions
            .iter()
            .filter(|p| p.iter().all(|c| c.is_finite()))
            .collect();
        let n = finite.len().max(1) as f64;
        let c: [f64; 3] = std::array::from_fn(|i| finite.iter().map(|p| p[i]).sum::<f64>() / n);
        let r = (finite.iter().map(|p| dist2(p, &c)).sum::<f64>() / n).sqrt();
        if r > 0.0 && r.is_finite() { r } else { 1.0 }
    };
    match choice {
        FeatureSize::Value(v) => f64::from(v),
        FeatureSize::Edge => edge(),
        FeatureSize::Rtsc => k
            .and_then(|k| {
                let (_, r) = bounding_sphere(positions)?;
                rtsc_feature_size(positions.len(), k, r)
            })
            .unwrap_or_else(edge),
    }
}

/// A ball: centre and squared radius.
struct Ball {
    c: [f64; 3],
    r2: f64,
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(&d, &d)
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl Ball {
    /// The smallest ball with 1 to 4 points on its boundary. Points that do
    /// not span a circle or sphere (collinear three, coplanar four) fall
    /// back to the ball of the pair farthest apart, or of three, which then
    /// contains them all.
    fn of(pts: &[[f64; 3]]) -> Ball {
        match pts.len() {
            1 => Ball { c: pts[0], r2: 0.0 },
            2 => {
                let c = std::array::from_fn(|i| 0.5 * (pts[0][i] + pts[1][i]));
                Ball {
                    r2: dist2(&c, &pts[0]),
                    c,
                }
            }
            3 => {
                // Circumcentre in the plane of the three points.
                let (a, b) = (sub(&pts[1], &pts[0]), sub(&pts[2], &pts[0]));
                let n = cross(&a, &b);
                let nn = dot(&n, &n);
                if nn <= 1e-24 * dot(&a, &a) * dot(&b, &b) || nn == 0.0 {
                    return Ball::widest(pts);
                }
                let t = cross(&n, &a);
                let u = cross(&b, &n);
                let (aa, bb) = (dot(&a, &a), dot(&b, &b));
                let off: [f64; 3] = std::array::from_fn(|i| (bb * t[i] + aa * u[i]) / (2.0 * nn));
                let c = std::array::from_fn(|i| pts[0][i] + off[i]);
                Ball {
                    r2: dot(&off, &off),
                    c,
                }
            }
            _ => {
                let (a, b, d) = (
                    sub(&pts[1], &pts[0]),
                    sub(&pts[2], &pts[0]),
                    sub(&pts[3], &pts[0]),
                );
                let det = dot(&a, &cross(&b, &d));
                let scale = (dot(&a, &a) * dot(&b, &b) * dot(&d, &d)).sqrt();
                if det.abs() <= 1e-12 * scale || det == 0.0 {
                    // Coplanar: the best of the four triangles' balls.
                    let tris = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];
                    return tris
                        .iter()
                        .map(|t| Ball::of(&[pts[t[0]], pts[t[1]], pts[t[2]]]))
                        .filter(|bl| pts.iter().all(|p| dist2(&bl.c, p) <= bl.r2 * (1.0 + 1e-9)))
                        .min_by(|x, y| x.r2.total_cmp(&y.r2))
                        .unwrap_or_else(|| Ball::widest(pts));
                }
                let (aa, bb, dd) = (dot(&a, &a), dot(&b, &b), dot(&d, &d));
                let (bxd, dxa, axb) = (cross(&b, &d), cross(&d, &a), cross(&a, &b));
                let off: [f64; 3] = std::array::from_fn(|i| {
                    (aa * bxd[i] + bb * dxa[i] + dd * axb[i]) / (2.0 * det)
                });
                let c = std::array::from_fn(|i| pts[0][i] + off[i]);
                Ball {
                    r2: dot(&off, &off),
                    c,
                }
            }
        }
    }

    /// The ball on the pair of points farthest apart, grown to hold the rest.
    fn widest(pts: &[[f64; 3]]) -> Ball {
        let mut best = (0, 0, -1.0);
        for i in 0..pts.len() {
            for j in i + 1..pts.len() {
                let d = dist2(&pts[i], &pts[j]);
                if d > best.2 {
                    best = (i, j, d);
                }
            }
        }
        let mut b = Ball::of(&[pts[best.0], pts[best.1]]);
        for p in pts {
            b.r2 = b.r2.max(dist2(&b.c, p));
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rtsc_fs(k: &[[f64; 2]], radius: f64) -> Option<f64> {
        rtsc_feature_size(k.len(), &|i| k[i], radius)
    }

    #[test]
    fn the_sampler_draws_rtsc_s_indices() {
        // x1 = 1013904223, x2 = 1664525 · x1 + 1013904223 mod 2^32.
        let x1: u64 = 1_013_904_223;
        let x2 = (1_664_525 * x1 + 1_013_904_223) % (1 << 32);
        assert_eq!(
            rtsc_sample_indices(1000)[..2],
            [(x1 % 1000) as usize, (x2 % 1000) as usize]
        );
        assert_eq!(rtsc_sample_indices(7).len(), 7);
        assert_eq!(rtsc_sample_indices(100_000).len(), 500);
        assert!(rtsc_sample_indices(0).is_empty());
    }

    #[test]
    fn the_feature_size_is_the_tenth_percentile_by_hand() {
        // 2000 vertices: 500 samples, 1000 magnitudes, index 100 of them.
        // Every vertex has |k1| = 1 + i and |k2| = 0.5 (so the 1000 sampled
        // magnitudes hold 500 halves: the 101st smallest is 0.5).
        let k: Vec<[f64; 2]> = (0..2000).map(|i| [-(1.0 + i as f64), 0.5]).collect();
        let fs = rtsc_fs(&k, 100.0).unwrap();
        assert!((fs - 0.02).abs() < 1e-9, "{fs}");
        // Here the 101st smallest of the sampled |k1| ∪ |k2| is computed by
        // hand from the drawn indices: |k1| = i + 1 at vertex i, |k2| huge.
        let k: Vec<[f64; 2]> = (0..2000).map(|i| [i as f64 + 1.0, 1e9]).collect();
        let mut drawn: Vec<f64> = rtsc_sample_indices(2000)
            .iter()
            .map(|&i| i as f64 + 1.0)
            .collect();
        drawn.sort_by(f64::total_cmp);
        let expect = (0.01f32 / drawn[100] as f32) as f64;
        assert_eq!(rtsc_fs(&k, 1e6).unwrap(), expect);
        // Capped at 0.05 r: flat samples (p = 0), and small radii.
        let flat = vec![[0.0, 0.0]; 10];
        assert!((rtsc_fs(&flat, 2.0).unwrap() - 0.1).abs() < 1e-7);
        assert!((rtsc_fs(&k, 1e-4).unwrap() - 5e-6).abs() < 1e-12);
        // Nothing to size.
        assert_eq!(rtsc_fs(&[], 1.0), None);
        assert_eq!(rtsc_fs(&flat, 0.0), None);
        // Non-finite curvature counts as the largest.
        let mut k = vec![[1.0, 1.0]; 20];
        k[3] = [f64::NAN, f64::INFINITY];
        assert!((rtsc_fs(&k, 1e3).unwrap() - 0.01).abs() < 1e-9);
    }

    #[test]
    fn the_bounding_sphere_is_the_smallest() {
        // The vertices of a cube: the sphere through its corners.
        let mut cube = Vec::new();
        for i in 0..8 {
            cube.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
        }
        let (c, r) = bounding_sphere(&cube).unwrap();
        assert!(c.iter().all(|x| (x - 0.5).abs() < 1e-12), "{c:?}");
        assert!((r - 0.75f64.sqrt()).abs() < 1e-12);
        // Points on a unit sphere and inside it, shifted and scaled.
        let mut pts = Vec::new();
        let mut q = 7u32;
        let mut rnd = || {
            q = q.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            q as f64 / 4294967296.0
        };
        for _ in 0..5000 {
            let (z, a) = (2.0 * rnd() - 1.0, std::f64::consts::TAU * rnd());
            let s = (1.0 - z * z).sqrt();
            let r = if rnd() < 0.3 { 1.0 } else { rnd() };
            pts.push([
                1e3 + 5.0 * r * s * a.cos(),
                -2.0 + 5.0 * r * s * a.sin(),
                5.0 * r * z,
            ]);
        }
        let (c, r) = bounding_sphere(&pts).unwrap();
        assert!(r <= 5.0 + 1e-9 && r > 4.99, "{r}");
        assert!((c[0] - 1e3).abs() < 0.01 && (c[1] + 2.0).abs() < 0.01 && c[2].abs() < 0.01);
        for p in &pts {
            assert!(dist2(&c, p).sqrt() <= r * (1.0 + 1e-9));
        }
        // Two points; collinear and coplanar sets; one point; none.
        let (c, r) = bounding_sphere(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]).unwrap();
        assert_eq!((c, r), ([1.0, 0.0, 0.0], 1.0));
        let line: Vec<[f64; 3]> = (0..50).map(|i| [i as f64, 0.0, 0.0]).collect();
        let (c, r) = bounding_sphere(&line).unwrap();
        assert!((c[0] - 24.5).abs() < 1e-9 && (r - 24.5).abs() < 1e-9);
        let grid: Vec<[f64; 3]> = (0..100)
            .map(|i| [(i % 10) as f64, (i / 10) as f64, 0.0])
            .collect();
        let (_, r) = bounding_sphere(&grid).unwrap();
        assert!((r - (2.0f64 * 4.5 * 4.5).sqrt()).abs() < 1e-9, "{r}");
        assert_eq!(
            bounding_sphere(&[[3.0, 4.0, 5.0]]),
            Some(([3.0, 4.0, 5.0], 0.0))
        );
        assert_eq!(bounding_sphere(&[[f64::NAN, 0.0, 0.0]]), None);
    }

    #[test]
    fn a_choice_resolves_to_its_size_or_falls_back() {
        let pos = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let faces = [[0, 1, 2]];
        let k: Option<&dyn Fn(usize) -> [f64; 2]> = Some(&|_| [1.0, 0.5]);
        assert_eq!(resolve(FeatureSize::Value(0.25), &pos, &faces, k), 0.25);
        assert_eq!(resolve(FeatureSize::Edge, &pos, &faces, k), 2.0);
        // 6 magnitudes, index 0: 0.5; min(0.01 / 0.5, 0.05 · √2).
        assert!((resolve(FeatureSize::Rtsc, &pos, &faces, k) - 0.02).abs() < 1e-7);
        // No curvature: the median edge; no edge either: the RMS radius.
        assert_eq!(resolve(FeatureSize::Rtsc, &pos, &faces, None), 2.0);
        let r = resolve(FeatureSize::Edge, &pos, &[], None);
        // Squared distances from the centroid (2/3, 2/3, 0): 8/9, 20/9, 20/9.
        assert!((r - 4.0 / 3.0).abs() < 1e-12, "{r}");
        assert_eq!(
            resolve(FeatureSize::Edge, &[[1.0, 1.0, 1.0]], &[], None),
            1.0
        );
    }
}
