//! The input of the `mesh_sdf` family, made from a mesh: validation, the
//! sampling grid, vertices snapped to the fixed-point lattice, the faces
//! kept and their edge neighbours ([`PreparedMesh`], whose fields and
//! constants the spec defines: see [`crate::spec::mesh_sdf`]). Both the
//! device stage (`crate::stages::mesh_sdf`) and the CPU twin
//! (`crate::cpu::mesh_sdf`) start from [`prepare`].

use std::collections::HashMap;

use super::Mesh;
use crate::error::{Error, Result};
use crate::spec::mesh_sdf::{
    FIX_ONE, MAX_RESOLUTION, MIN_RESOLUTION, MeshSdfOptions, NO_TRIANGLE, PreparedMesh, SdfGrid,
    padding_voxels,
};

/// Validates `mesh`, chooses the grid and snaps the vertices.
///
/// # Errors
///
/// [`Error::InvalidInput`] (source `source`) for a mesh without faces, an
/// index out of range, a non-finite coordinate, or faces that are all
/// degenerate (zero area); [`Error::InvalidArgument`] for a resolution
/// outside `MIN_RESOLUTION..=MAX_RESOLUTION`.
pub fn prepare(mesh: &Mesh, opts: &MeshSdfOptions, source: &str) -> Result<PreparedMesh> {
    let n = opts.resolution;
    if !(MIN_RESOLUTION..=MAX_RESOLUTION).contains(&n) {
        return Err(Error::InvalidArgument(format!(
            "mesh signed distance resolution {n}: expected {MIN_RESOLUTION} to {MAX_RESOLUTION} \
             samples along the longest axis"
        )));
    }
    mesh.validate(source)?;
    let (lo, hi) = used_box(mesh);
    let grid = choose_grid(lo, hi, n).ok_or_else(|| all_degenerate(mesh, source))?;
    let fixed = snap(mesh, &grid);
    let inv = 1.0 / FIX_ONE as f32;
    let grid_pos = fixed.iter().map(|q| q.map(|c| c as f32 * inv)).collect();
    let triangles: Vec<[u32; 3]> = mesh
        .faces
        .iter()
        .copied()
        .filter(|f| !collinear(&fixed, f))
        .collect();
    let degenerate = mesh.faces.len() - triangles.len();
    if triangles.is_empty() {
        return Err(all_degenerate(mesh, source));
    }
    let adjacent = adjacency(&triangles);
    Ok(PreparedMesh {
        grid,
        fixed,
        grid_pos,
        triangles,
        degenerate,
        adjacent,
    })
}

/// The box of the vertices that faces use (unreferenced vertices, like
/// the Stanford bunny's 1,113, do not widen it): its low and high corners.
fn used_box(mesh: &Mesh) -> ([f64; 3], [f64; 3]) {
    let used = mesh.referenced();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (p, _) in mesh.positions.iter().zip(&used).filter(|(_, u)| **u) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The error for a mesh whose faces are all degenerate.
fn all_degenerate(mesh: &Mesh, source: &str) -> Error {
    Error::input(
        source,
        "faces",
        format!(
            "all {} faces are degenerate (zero area): there is no surface to measure \
             a distance to",
            mesh.faces.len()
        ),
    )
}

/// The grid of `n` samples along the longest axis of the box `lo..hi`,
/// padded and centred on it; `None` for a flat or non-finite box.
fn choose_grid(lo: [f64; 3], hi: [f64; 3], n: usize) -> Option<SdfGrid> {
    let ext: [f64; 3] = std::array::from_fn(|k| hi[k] - lo[k]);
    let longest = ext.iter().copied().fold(0.0, f64::max);
    if longest <= 0.0 || !longest.is_finite() {
        return None;
    }
    let pad = padding_voxels(n);
    let h = longest / (n as f64 - 1.0 - 2.0 * pad);
    let axis = (0..3)
        .max_by(|&a, &b| ext[a].total_cmp(&ext[b]))
        .unwrap_or(0);
    let dims: [usize; 3] = std::array::from_fn(|k| {
        if k == axis {
            n
        } else {
            (((ext[k] / h + 2.0 * pad) - 1e-9).ceil() as usize + 1).clamp(2, n)
        }
    });
    let origin: [f64; 3] =
        std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]) - 0.5 * (dims[k] as f64 - 1.0) * h);
    Some(SdfGrid {
        dims,
        spacing: h,
        origin,
    })
}

/// The vertices snapped to the grid's fixed-point lattice, clamped to it.
fn snap(mesh: &Mesh, grid: &SdfGrid) -> Vec<[i32; 3]> {
    let (dims, origin) = (grid.dims, grid.origin);
    let scale = FIX_ONE as f64 / grid.spacing;
    mesh.positions
        .iter()
        .map(|p| {
            std::array::from_fn(|k| {
                let max = ((dims[k] - 1) as i64 * FIX_ONE) as f64;
                ((p[k] - origin[k]) * scale).round().clamp(0.0, max) as i32
            })
        })
        .collect()
}

/// Edge neighbours of each triangle (see [`PreparedMesh::adjacent`]).
fn adjacency(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(3 * tris.len() / 2);
    for (t, f) in tris.iter().enumerate() {
        for k in 0..3 {
            by_edge
                .entry(key(f[k], f[(k + 1) % 3]))
                .or_default()
                .push(t as u32);
        }
    }
    tris.iter()
        .enumerate()
        .map(|(t, f)| {
            std::array::from_fn(|k| {
                by_edge[&key(f[k], f[(k + 1) % 3])]
                    .iter()
                    .copied()
                    .filter(|&o| o != t as u32)
                    .min()
                    .unwrap_or(NO_TRIANGLE)
            })
        })
        .collect()
}

/// Whether the snapped corners of `f` are collinear (exact, in `i64`).
fn collinear(q: &[[i32; 3]], f: &[u32; 3]) -> bool {
    let [a, b, c] = f.map(|v| q[v as usize].map(i64::from));
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    u[1] * v[2] - u[2] * v[1] == 0
        && u[2] * v[0] - u[0] * v[2] == 0
        && u[0] * v[1] - u[1] * v[0] == 0
}
