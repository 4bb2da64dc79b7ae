//! The gradient of a volume at its grid points and the unit normals it
//! gives at points inside the grid: what the isosurface's host steps, the
//! marching-cubes twin and the `sdf_lines` twin share.

use super::Volume;

/// The gradient at grid point `g` in world units: central differences,
/// one-sided at the border, 0 along an axis of one sample.
pub fn grid_gradient(vol: &Volume, g: [usize; 3]) -> [f64; 3] {
    let d = vol.dims;
    let val = |x: usize, y: usize, z: usize| vol.value(x, y, z) as f64;
    std::array::from_fn(|a| {
        let mut lo = g;
        let mut hi = g;
        if g[a] > 0 {
            lo[a] -= 1;
        }
        if g[a] + 1 < d[a] {
            hi[a] += 1;
        }
        let span = (hi[a] - lo[a]) as f64;
        if span == 0.0 {
            return 0.0;
        }
        (val(hi[0], hi[1], hi[2]) - val(lo[0], lo[1], lo[2])) / (span * vol.spacing[a])
    })
}

/// Unit normals at index-space positions from the volume's gradient
/// (central differences at the grid points, trilinearly interpolated, scaled
/// by the spacing into world units), pointing towards increasing values like
/// the triangles' winding. Where the gradient vanishes or a needed voxel is
/// not finite the normal is (0, 0, 0).
pub fn gradient_normals(vol: &Volume, positions: &[[f32; 3]]) -> Vec<[f64; 3]> {
    let d = vol.dims;
    positions
        .iter()
        .map(|p| {
            let base: [usize; 3] =
                std::array::from_fn(|a| (p[a].max(0.0) as usize).min(d[a].saturating_sub(2)));
            let f: [f64; 3] =
                std::array::from_fn(|a| (p[a] as f64 - base[a] as f64).clamp(0.0, 1.0));
            let mut n = [0.0; 3];
            for c in 0..8 {
                let o = [c & 1, (c >> 1) & 1, c >> 2];
                let g: [usize; 3] = std::array::from_fn(|a| (base[a] + o[a]).min(d[a] - 1));
                let w: f64 = (0..3)
                    .map(|a| if o[a] == 1 { f[a] } else { 1.0 - f[a] })
                    .product();
                let gr = grid_gradient(vol, g);
                for a in 0..3 {
                    n[a] += w * gr[a];
                }
            }
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len.is_finite() && len > 0.0 {
                n.map(|c| c / len)
            } else {
                [0.0; 3]
            }
        })
        .collect()
}
