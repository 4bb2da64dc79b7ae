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

use crate::spec::marching_cubes::{END, common_face, edge_corners, edge_of, table};

// The soup is what vertex fusion reads, so its vertex type lives there (the
// stages too depend marching cubes -> vertex fusion, never back).
pub use super::vertex_fusion::SoupVertex;

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

/// The interpolation parameter of the crossing of `iso` between values `v0`
/// and `v1`, clamped to [0, 1] (the kernels' `mc_edge_t`). NaN (from ±inf
/// voxels) fails the test too: the vertex goes to the lower end. Where a
/// difference of finite values overflows (beyond ±1.7e38), both differences
/// are taken of the halved values, which halving leaves exact.
pub fn edge_t(v0: f32, v1: f32, iso: f32) -> f32 {
    let (mut n, mut d) = (iso - v0, v1 - v0);
    if n.is_infinite() || d.is_infinite() {
        n = iso * 0.5 - v0 * 0.5;
        d = v1 * 0.5 - v0 * 0.5;
    }
    let mut t = n / d;
    if t.is_nan() || t < 0.0 {
        t = 0.0;
    }
    if t > 1.0 {
        t = 1.0;
    }
    t
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
    let t = edge_t(v0, v1, iso);
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

pub use crate::volume::gradient::{gradient_normals, grid_gradient};

// ---------------------------------------------------------------------------
// Direct numbering (`mc_direct_*`): each vertex created once by the voxel edge
// that owns it and numbered by a scan over per-row counts, as Flying Edges
// (Schroeder, Maynard and Geveci 2015) does; triangles written with final
// indices. Same steps, layout and f32 arithmetic as the kernels.

/// What the voxel edge from value `v0` (coordinate `a` along the edge's axis)
/// to `v1` (coordinate `a + 1`) carries (the kernels' `edge_kind`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EdgeVertex {
    /// No vertex: both ends on one side of iso, or an end not finite.
    None,
    /// A vertex strictly inside the edge, at this coordinate along its axis.
    Inside(f32),
    /// The vertex rounds onto the lower grid point: it *is* that point.
    Lower,
    /// The vertex rounds onto the upper grid point.
    Upper,
}

/// Classifies the vertex of one voxel edge (see [`EdgeVertex`]).
pub fn edge_vertex(v0: f32, v1: f32, iso: f32, a: usize) -> EdgeVertex {
    if !(v0.is_finite() && v1.is_finite()) || (v0 < iso) == (v1 < iso) {
        return EdgeVertex::None;
    }
    let fa = a as f32;
    let c = fa + edge_t(v0, v1, iso);
    if c == fa {
        EdgeVertex::Lower
    } else if c == (a + 1) as f32 {
        EdgeVertex::Upper
    } else {
        EdgeVertex::Inside(c)
    }
}

/// The vertex of the edge along `axis` starting at grid point `g`, or
/// [`EdgeVertex::None`] when the edge leaves the volume.
fn grid_edge(vol: &Volume, iso: f32, g: [usize; 3], axis: usize) -> EdgeVertex {
    let mut h = g;
    h[axis] += 1;
    if h[axis] >= vol.dims[axis] {
        return EdgeVertex::None;
    }
    edge_vertex(
        vol.value(g[0], g[1], g[2]),
        vol.value(h[0], h[1], h[2]),
        iso,
        g[axis],
    )
}

/// True when triangle `j` of cell `cell` (case `case`), which lies in a face
/// of the cube ([`crate::spec::marching_cubes::McTable::flat`]), has an
/// opposite twin in the cell across that face: the same three voxel edges,
/// the other winding. Both are dropped (the kernels' `has_twin`), as vertex
/// fusion's twin cancellation would drop them.
pub fn has_twin(vol: &Volume, iso: f32, cell: [usize; 3], case: usize, j: usize) -> bool {
    let t = table();
    let a = [0, 1, 2].map(|i| t.tris[case][3 * j + i] as usize);
    let Some((f, s)) = common_face(a[0], a[1], a[2]) else {
        return false;
    };
    let side = |e: usize| (edge_corners(e).0 >> f) & 1;
    let mut p = cell;
    if s == 0 {
        if p[f] == 0 {
            return false;
        }
        p[f] -= 1;
    } else {
        if p[f] + 2 >= vol.dims[f] {
            return false;
        }
        p[f] += 1;
    }
    let Some(cb) = cell_case(vol, iso, p[0], p[1], p[2]) else {
        return false;
    };
    t.tris[cb].chunks(3).take(t.counts[cb] as usize).any(|tb| {
        let m: Option<Vec<usize>> = tb
            .iter()
            .map(|&e| {
                let e = e as usize;
                // The same physical edge in this cell's numbering.
                let (c0, c1) = edge_corners(e);
                (e / 4 != f && side(e) == 1 - s).then(|| edge_of(c0 ^ (1 << f), c1 ^ (1 << f)))
            })
            .collect();
        m.is_some_and(|m| {
            let r = [a[0], a[2], a[1]];
            (0..3).any(|k| (0..3).all(|i| m[i] == r[(i + k) % 3]))
        })
    })
}

/// Triangles of a valid cell's case that direct numbering keeps, in table
/// order (those with an opposite twin across a face dropped).
fn kept_triangles(vol: &Volume, iso: f32, cell: [usize; 3], case: usize) -> Vec<usize> {
    let t = table();
    (0..t.counts[case] as usize)
        .filter(|&j| t.flat[case] >> j & 1 == 0 || !has_twin(vol, iso, cell, case, j))
        .collect()
}

/// Per grid row `y + ny z` (every row of grid points along x, `ny · nz` of
/// them), what `mc_direct_count` writes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DirectCounts {
    /// Vertices inside the edges the row owns (its x-edges, and the y- and
    /// z-edges that start on it), triangles of the cell row `(y, z)` (0 on
    /// the last row of y or z) that are kept, vertices of its edges that
    /// round onto a grid point, and triangles dropped with an opposite twin.
    pub rows: Vec<[u32; 4]>,
    /// Within the row: the first y-edge vertex and the first z-edge vertex
    /// (its x-edge vertices come first, then y, then z, each in x order).
    pub split: Vec<[u32; 2]>,
}

/// `mc_direct_count`: the per-row counts.
pub fn mc_direct_count(vol: &Volume, iso: f32) -> DirectCounts {
    let [nx, ny, nz] = vol.dims;
    let t = table();
    let mut out = DirectCounts::default();
    for r in 0..ny * nz {
        let (y, z) = (r % ny, r / ny);
        let mut c = [0u32; 3];
        let mut hits = 0;
        for x in 0..nx {
            for (axis, n) in c.iter_mut().enumerate() {
                match grid_edge(vol, iso, [x, y, z], axis) {
                    EdgeVertex::None => {}
                    EdgeVertex::Inside(_) => *n += 1,
                    _ => hits += 1,
                }
            }
        }
        let (mut tris, mut twins) = (0, 0);
        if y + 1 < ny && z + 1 < nz {
            for x in 0..nx - 1 {
                if let Some(k) = cell_case(vol, iso, x, y, z) {
                    let kept = kept_triangles(vol, iso, [x, y, z], k).len() as u32;
                    tris += kept;
                    twins += t.counts[k] as u32 - kept;
                }
            }
        }
        out.rows.push([c.iter().sum(), tris, hits, twins]);
        out.split.push([c[0], c[0] + c[1]]);
    }
    out
}

/// The result of direct numbering before the clean-up of exact hits.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Direct {
    /// Vertices: the edge vertices in row order, then the grid points that
    /// vertices rounded onto, sorted and unique.
    pub positions: Vec<[f32; 3]>,
    /// Triangles with final indices, cell rows in order, cells in x order,
    /// triangles in table order (those of exact hits may have collapsed).
    pub faces: Vec<[u32; 3]>,
    /// Vertices inside edges (the scan total of the row counts).
    pub edge_vertices: usize,
    /// Edge vertices that rounded onto a grid point.
    pub hits: usize,
    /// Triangles dropped with an opposite twin across a cube face.
    pub twins: usize,
    /// Triangles of each cell row in `faces` (per grid row `y + ny z`, 0
    /// where it is not a cell row), collapsed ones included.
    pub row_faces: Vec<u32>,
}

/// `mc_direct_hits` (the hit points, sorted), `mc_direct_triangles` and
/// `mc_direct_points`: the positions and triangles, indices final.
pub fn mc_direct(vol: &Volume, iso: f32) -> Direct {
    let counts = mc_direct_count(vol, iso);
    let (id, mut positions, mut hit_points) = edge_vertex_ids(vol, iso);
    let edge_vertices = positions.len();
    debug_assert_eq!(
        edge_vertices as u64,
        counts.rows.iter().map(|r| r[0] as u64).sum::<u64>()
    );
    let hits = hit_points.len();
    hit_points.sort_unstable();
    hit_points.dedup();
    let [nx, ny, _] = vol.dims;
    for &g in &hit_points {
        let g = g as usize;
        positions.push([
            (g % nx) as f32,
            (g / nx % ny) as f32,
            (g / (nx * ny)) as f32,
        ]);
    }
    let numbering = Numbering {
        id: &id,
        edge_vertices,
        hit_points: &hit_points,
    };
    let (faces, row_faces) = direct_triangles(vol, iso, &numbering);
    Direct {
        positions,
        faces,
        edge_vertices,
        hits,
        twins: counts.rows.iter().map(|r| r[3] as usize).sum(),
        row_faces,
    }
}

/// The vertices of direct numbering's edges, rows in order (x, y, z edges
/// each): the id of every interior edge vertex (per grid point and axis,
/// `u32::MAX` for none), their positions, and the grid points that
/// vertices round onto (unsorted, repeated).
fn edge_vertex_ids(vol: &Volume, iso: f32) -> (Vec<u32>, Vec<[f32; 3]>, Vec<u32>) {
    let [nx, ny, nz] = vol.dims;
    let lin = |g: [usize; 3]| g[0] + nx * (g[1] + ny * g[2]);
    let mut id = vec![u32::MAX; 3 * nx * ny * nz];
    let mut positions = Vec::new();
    let mut hit_points = Vec::new();
    for r in 0..ny * nz {
        let (y, z) = (r % ny, r / ny);
        for axis in 0..3 {
            for x in 0..nx {
                let g = [x, y, z];
                match grid_edge(vol, iso, g, axis) {
                    EdgeVertex::None => {}
                    EdgeVertex::Inside(c) => {
                        id[3 * lin(g) + axis] = positions.len() as u32;
                        let mut p = g.map(|v| v as f32);
                        p[axis] = c;
                        positions.push(p);
                    }
                    EdgeVertex::Lower => hit_points.push(lin(g) as u32),
                    EdgeVertex::Upper => {
                        let mut h = g;
                        h[axis] += 1;
                        hit_points.push(lin(h) as u32);
                    }
                }
            }
        }
    }
    (id, positions, hit_points)
}

/// How direct numbering names a vertex: the edge vertices' ids, then the
/// sorted, unique hit points after them.
struct Numbering<'a> {
    id: &'a [u32],
    edge_vertices: usize,
    hit_points: &'a [u32],
}

/// The kept triangles of every cell with their final indices, cell rows in
/// order, and the triangles of each cell row (per grid row `y + ny z`).
fn direct_triangles(vol: &Volume, iso: f32, n: &Numbering) -> (Vec<[u32; 3]>, Vec<u32>) {
    let [nx, ny, nz] = vol.dims;
    let lin = |g: [usize; 3]| g[0] + nx * (g[1] + ny * g[2]);
    let t = table();
    let mut faces = Vec::new();
    let mut row_faces = vec![0u32; ny * nz];
    for z in 0..nz.saturating_sub(1) {
        for y in 0..ny.saturating_sub(1) {
            let first = faces.len();
            for x in 0..nx - 1 {
                let Some(case) = cell_case(vol, iso, x, y, z) else {
                    continue;
                };
                let vid = |e: usize| {
                    let (c0, _) = edge_corners(e);
                    let g = [x + (c0 & 1), y + (c0 >> 1 & 1), z + (c0 >> 2)];
                    let axis = e / 4;
                    match grid_edge(vol, iso, g, axis) {
                        EdgeVertex::Inside(_) => n.id[3 * lin(g) + axis],
                        hit => {
                            let mut p = g;
                            if hit == EdgeVertex::Upper {
                                p[axis] += 1;
                            }
                            let k = lin(p) as u32;
                            (n.edge_vertices + n.hit_points.partition_point(|&h| h < k)) as u32
                        }
                    }
                };
                for j in kept_triangles(vol, iso, [x, y, z], case) {
                    let tri = &t.tris[case][3 * j..3 * j + 3];
                    faces.push([
                        vid(tri[0] as usize),
                        vid(tri[1] as usize),
                        vid(tri[2] as usize),
                    ]);
                }
            }
            row_faces[y + ny * z] = (faces.len() - first) as u32;
        }
    }
    (faces, row_faces)
}

/// `mc_direct_unused_rows`, `_clear`, `_mark` and `_count`: how many
/// vertices of `d` (of `vol`'s dims, with the row counts `counts`) no kept
/// triangle uses once collapsed triangles (two corners on one hit point) are
/// dropped, looked for only where triangles were dropped: in the grid rows
/// of the cell rows that dropped some (twins across a face or collapses),
/// marked by the kept triangles of the 3 × 3 cell rows around each. Every
/// other vertex keeps the triangles of the cells it was made for, so this is
/// the count of all unused vertices.
pub fn direct_unused_near(dims: [usize; 3], d: &Direct, counts: &DirectCounts) -> usize {
    let [nx, ny, nz] = dims;
    let g = ny * nz;
    let collapsed = |f: &[u32; 3]| f[0] == f[1] || f[1] == f[2] || f[0] == f[2];
    // Each cell row's faces in `d.faces`, and its dropped triangles.
    let mut first = vec![0usize; g + 1];
    for r in 0..g {
        first[r + 1] = first[r] + d.row_faces[r] as usize;
    }
    let row = |r: usize| &d.faces[first[r]..first[r + 1]];
    let drops =
        |r: usize| counts.rows[r][3] as usize + row(r).iter().filter(|f| collapsed(f)).count();
    let cell_row = |y: isize, z: isize| {
        (y >= 0 && z >= 0 && (y as usize) + 1 < ny && (z as usize) + 1 < nz)
            .then(|| y as usize + ny * z as usize)
    };
    let listed: Vec<usize> = (0..g)
        .filter(|&r| cell_row((r % ny) as isize, (r / ny) as isize).is_some() && drops(r) > 0)
        .collect();
    let mut checked = vec![false; g];
    let mut used = vec![false; d.positions.len()];
    for &r in &listed {
        for j in 0..4 {
            checked[r + (j & 1) + ny * (j >> 1)] = true;
        }
        let (y, z) = ((r % ny) as isize, (r / ny) as isize);
        for (dy, dz) in (-1..=1).flat_map(|dz| (-1..=1).map(move |dy| (dy, dz))) {
            if let Some(c) = cell_row(y + dy, z + dz) {
                for f in row(c).iter().filter(|f| !collapsed(f)) {
                    for &v in f {
                        used[v as usize] = true;
                    }
                }
            }
        }
    }
    // Grid row r owns edge vertices off[r] .. off[r + 1]; the hit points
    // follow all edge vertices, in grid index order.
    let mut unused = 0;
    let mut off = 0;
    for (row, &check) in counts.rows.iter().zip(&checked) {
        let n = row[0] as usize;
        if check {
            unused += (off..off + n).filter(|&v| !used[v]).count();
        }
        off += n;
    }
    for (v, p) in d.positions.iter().enumerate().skip(d.edge_vertices) {
        let r = p[1] as usize + ny * p[2] as usize;
        debug_assert!((p[0] as usize) < nx);
        if checked[r] && !used[v] {
            unused += 1;
        }
    }
    unused
}

/// Direct numbering, whole: [`mc_direct`] (twins across cube faces already
/// dropped), then the clean-up of vertex fusion (which the device runs only
/// where it changes something) ([`crate::cpu::vertex_fusion::fuse_finish`]: collapsed triangles
/// and opposite twins dropped, unused vertex slots removed).
pub fn direct_mesh(vol: &Volume, iso: f32) -> crate::cpu::vertex_fusion::Fused {
    // The device skips the clean-up where it would change nothing.
    let d = mc_direct(vol, iso);
    let mut f = crate::cpu::vertex_fusion::fuse_finish(&d.positions, &d.faces);
    f.dropped += d.twins;
    f
}
