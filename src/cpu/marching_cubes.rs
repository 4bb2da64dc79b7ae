//! CPU reference of `kernels/marching_cubes.cl`: the case table, and the
//! `mc_classify` and `mc_triangles` steps, in the same f32 arithmetic as the
//! kernels so that soup positions agree bit for bit.
//!
//! Conventions shared with the kernels (see the kernel file's header):
//! - corner `c` of a cell is at offset `(c & 1, (c >> 1) & 1, c >> 2)`;
//!   bit `c` of the case is set when the corner is *inside* (`value < iso`);
//! - edge `e` runs along axis `e / 4`; `e % 4` picks the other two offsets
//!   (low bit: the first other axis in x, y, z order, high bit: the second);
//! - triangles are wound so that normals point towards values ≥ iso
//!   (outward for signed distance fields, negative inside);
//! - a cell with a non-finite corner emits nothing (the surface gets a
//!   boundary there): NaN and ±inf voxels never make NaN vertices;
//! - a vertex whose interpolated coordinate rounds onto an edge endpoint *is*
//!   that grid point: its key is the point's, so vertex fusion merges it with
//!   every other vertex there (this is what makes iso values equal to voxel
//!   values safe: the triangles that collapse are dropped after fusion).
//!
//! The case table, derived rather than copied, is shared with the host
//! wiring: [`crate::spec::marching_cubes::table`].

use crate::spec::marching_cubes::cell_rows;
use crate::volume::Volume;

use crate::spec::marching_cubes::{END, edge_corners, table};

/// One vertex of the triangle soup: its position in index space (voxel
/// units; world = origin + spacing × p) and its exact key: `4g + axis` for a
/// vertex inside the edge of axis `axis` starting at grid point `g`, `4g + 3`
/// for a vertex at grid point `g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoupVertex {
    /// Index-space position.
    pub p: [f32; 3],
    /// Exact key (u64; the device uses u32 and checks that it fits).
    pub key: u64,
}

/// The case of the cell at `(x, y, z)`, or `None` when a corner is not finite.
pub fn cell_case(vol: &Volume, iso: f32, x: usize, y: usize, z: usize) -> Option<usize> {
    let mut case = 0;
    for c in 0..8 {
        let v = vol.value(x + (c & 1), y + (c >> 1 & 1), z + (c >> 2));
        if !v.is_finite() {
            return None;
        }
        if v < iso {
            case |= 1 << c;
        }
    }
    Some(case)
}

/// `mc_classify`: triangles emitted by each cell row `y + (ny-1) z`.
pub fn mc_classify(vol: &Volume, iso: f32) -> Vec<u32> {
    let [nx, ny, _] = vol.dims;
    let t = table();
    (0..cell_rows(vol.dims))
        .map(|r| {
            let (y, z) = (r % (ny - 1), r / (ny - 1));
            (0..nx - 1)
                .filter_map(|x| cell_case(vol, iso, x, y, z))
                .map(|c| t.counts[c] as u32)
                .sum()
        })
        .collect()
}

/// Interpolates the vertex on edge `e` of cell `(x, y, z)` (the same f32
/// operations as the kernel's `mc_vertex`).
pub fn mc_vertex(vol: &Volume, iso: f32, cell: [usize; 3], e: usize) -> SoupVertex {
    let axis = e / 4;
    let (c0, _) = edge_corners(e);
    let lo = [
        cell[0] + (c0 & 1),
        cell[1] + (c0 >> 1 & 1),
        cell[2] + (c0 >> 2),
    ];
    let mut hi = lo;
    hi[axis] += 1;
    let v0 = vol.value(lo[0], lo[1], lo[2]);
    let v1 = vol.value(hi[0], hi[1], hi[2]);
    let mut t = (iso - v0) / (v1 - v0);
    // NaN (from ±inf voxels) fails the test too: the vertex goes to the lower end.
    if t.is_nan() || t < 0.0 {
        t = 0.0;
    }
    if t > 1.0 {
        t = 1.0;
    }
    let a = lo[axis] as f32;
    let c = a + t;
    let g = |p: [usize; 3]| (p[0] + vol.dims[0] * (p[1] + vol.dims[1] * p[2])) as u64;
    let mut p = [lo[0] as f32, lo[1] as f32, lo[2] as f32];
    let key = if c == a {
        4 * g(lo) + 3
    } else if c == (lo[axis] + 1) as f32 {
        p[axis] = c;
        4 * g(hi) + 3
    } else {
        p[axis] = c;
        4 * g(lo) + axis as u64
    };
    SoupVertex { p, key }
}

/// `mc_triangles`: the triangle soup, row by row in increasing x, triangles
/// in table order, three vertices each.
pub fn mc_triangles(vol: &Volume, iso: f32) -> Vec<SoupVertex> {
    let [nx, ny, _] = vol.dims;
    let t = table();
    let mut out = Vec::new();
    for r in 0..cell_rows(vol.dims) {
        let (y, z) = (r % (ny - 1), r / (ny - 1));
        for x in 0..nx - 1 {
            let Some(case) = cell_case(vol, iso, x, y, z) else {
                continue;
            };
            for &e in t.tris[case].iter().take_while(|&&e| e != END) {
                out.push(mc_vertex(vol, iso, [x, y, z], e as usize));
            }
        }
    }
    out
}

/// The gradient at grid point `g` in world units: central differences,
/// one-sided at the border, 0 along an axis of one sample. Shared by the
/// marching-cubes normals and the `sdf_lines` twin.
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
