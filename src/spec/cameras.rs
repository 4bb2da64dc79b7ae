//! Camera sets for many views of one mesh (line-drawing datasets): view
//! directions spread evenly over the sphere. Pure math, no device.

/// The most views one camera set may hold (a `--views` count or a camera
/// file's list): a run keeps one report entry per view and writes a file
/// or more per view, so a set beyond this is more likely a mistake than a
/// dataset.
pub const MAX_VIEWS: usize = 10_000;

/// `n` unit directions spread evenly over the sphere by the Fibonacci
/// (golden-angle) lattice: point `i` lies at height
/// `z = 1 − (2i + 1) / n` (equal-area bands, so every point stands for the
/// same area `4π / n`) and longitude `i · π (3 − √5)` (the golden angle,
/// which never lines consecutive points up in meridians). Deterministic:
/// the same `n` gives the same directions. Neighbours are about
/// `√(4π / n)` radians apart; no point lies on a pole (`n = 1` gives
/// (1, 0, 0), on the equator).
///
/// Computed in f64 and rounded to unit f32 vectors. An empty list for
/// `n = 0`.
///
/// ```
/// let d = shapecue::spec::cameras::fibonacci_directions(64);
/// assert_eq!(d.len(), 64);
/// for v in &d {
///     let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
///     assert!((len - 1.0).abs() < 1e-6);
/// }
/// ```
pub fn fibonacci_directions(n: usize) -> Vec<[f32; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f64 / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            let v = [r * phi.cos(), r * phi.sin(), z];
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|x| (x / len) as f32)
        })
        .collect()
}

/// The angle in radians that `n` evenly spread directions would leave
/// between neighbours, each standing for a spherical cap of area `4π / n`
/// of equal-area hexagonal cells: `√(8π / (√3 n))` (the distance between
/// the centres of a hexagonal tiling's cells of that area).
pub fn ideal_spacing(n: usize) -> f64 {
    (8.0 * std::f64::consts::PI / (3f64.sqrt() * n.max(1) as f64)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn angle(a: [f32; 3], b: [f32; 3]) -> f64 {
        let d: f64 = (0..3).map(|i| f64::from(a[i]) * f64::from(b[i])).sum();
        d.clamp(-1.0, 1.0).acos()
    }

    #[test]
    fn directions_are_deterministic_and_spread() {
        assert!(fibonacci_directions(0).is_empty());
        assert_eq!(fibonacci_directions(1), vec![[1.0, 0.0, 0.0]]);
        assert_eq!(fibonacci_directions(50), fibonacci_directions(50));
        let d = fibonacci_directions(200);
        // The mean direction of an even spread is near zero.
        let mean: Vec<f64> = (0..3)
            .map(|k| d.iter().map(|v| f64::from(v[k])).sum::<f64>() / 200.0)
            .collect();
        assert!(mean.iter().all(|m| m.abs() < 0.02), "{mean:?}");
        let min = (0..d.len())
            .flat_map(|i| (0..i).map(move |j| (i, j)))
            .map(|(i, j)| angle(d[i], d[j]))
            .fold(f64::INFINITY, f64::min);
        assert!(min > 0.5 * ideal_spacing(200), "{min}");
    }
}
