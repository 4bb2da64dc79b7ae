//! Shared types of the `marching_cubes` family (see [`crate::spec`]): the
//! case table ([`table`], derived here, not copied: marching squares on each
//! cube face with the inside corners kept apart, segments chained into loops,
//! loops fan-triangulated, so every shared face is cut the same way from both
//! cells and the surface is closed), the cell-row layout ([`cell_rows`]), the
//! normals choice of isosurface curvature ([`IsoNormals`]) and the bounds
//! that size the soup and the device memory.
//!
//! Mirrors in `kernels/marching_cubes.cl`: the `counts uchar[256]`,
//! `tris uchar[256·16]` and `flat uchar[256]` buffers are [`McTable`]
//! (uploaded as is; `0xFF` = [`END`] ends a row, at most
//! [`MAX_CELL_TRIANGLES`] triangles per case; `flat` marks the triangles
//! lying in a cube face, which direct numbering checks for twins);
//! the corner and edge numbering of [`edge_corners`] is the kernel's
//! (see its header); one work-item per cell row, [`cell_rows`] of them;
//! `mc_triangles`' `mode` is [`crate::spec::vertex_fusion::Fusion::code`].
//! Scalar arguments only: no parameter struct crosses.

use std::sync::OnceLock;

use crate::error::{Error, Result};

/// Most triangles one cell can emit (checked when the table is built).
pub const MAX_CELL_TRIANGLES: usize = 5;
/// Table row terminator.
pub const END: u8 = 0xFF;

/// The 256-case triangle table: `tris[case]` lists edge ids, three per
/// triangle, terminated by [`END`]; `counts[case]` is the triangle count.
#[derive(Clone, Debug)]
pub struct McTable {
    /// Edge ids per case, `END`-terminated, 16 entries.
    pub tris: [[u8; 16]; 256],
    /// Triangles per case.
    pub counts: [u8; 256],
    /// Bit `j` set when triangle `j` of the case lies in a face of the cube
    /// (a fan over a loop through all four edges of an ambiguous face). Such
    /// a triangle can have an opposite twin in the cell across the face: a
    /// fold of zero thickness that fusion cancels.
    pub flat: [u8; 256],
}

/// The two corner ids of edge `e` (lower, upper along the edge's axis).
pub fn edge_corners(e: usize) -> (usize, usize) {
    let axis = e / 4;
    let k = e % 4;
    let others = [(axis + 1) % 3, (axis + 2) % 3];
    let (lo_axis, hi_axis) = (others[0].min(others[1]), others[0].max(others[1]));
    let lo = ((k & 1) << lo_axis) | ((k >> 1) << hi_axis);
    (lo, lo | (1 << axis))
}

/// The edge (table numbering) joining corners `c0` and `c1`, which differ
/// along one axis (the inverse of [`edge_corners`]).
pub fn edge_of(c0: usize, c1: usize) -> usize {
    let d = c0 ^ c1;
    let axis = d.trailing_zeros() as usize;
    let lo = c0 & !d;
    let others = [(axis + 1) % 3, (axis + 2) % 3];
    let (lo_axis, hi_axis) = (others[0].min(others[1]), others[0].max(others[1]));
    axis * 4 + ((lo >> lo_axis) & 1) + 2 * ((lo >> hi_axis) & 1)
}

fn build_table() -> McTable {
    let mut tris = [[END; 16]; 256];
    let mut counts = [0u8; 256];
    let mut flat = [0u8; 256];
    for case in 0..256usize {
        let inside = |c: usize| case >> c & 1 == 1;
        // next[e] = the edge the surface boundary goes to from edge e.
        let mut next = [usize::MAX; 12];
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for side in 0..2 {
                // Corners counter-clockwise seen from outside the cube.
                let mut ring: Vec<usize> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                    .iter()
                    .map(|&(a, b)| (side << axis) | (a << u) | (b << v))
                    .collect();
                if side == 0 {
                    ring.reverse();
                }
                // Crossings in traversal order: (edge, entering the inside?).
                let mut xs = Vec::new();
                for i in 0..4 {
                    let (p, q) = (ring[i], ring[(i + 1) % 4]);
                    if inside(p) != inside(q) {
                        xs.push((edge_of(p, q), inside(q)));
                    }
                }
                // Each entry is joined to the exit that follows it: the inside
                // corners of an ambiguous face are cut off separately.
                for i in 0..xs.len() {
                    let (e, entering) = xs[i];
                    if entering {
                        let (f, _) = xs[(i + 1) % xs.len()];
                        next[e] = f;
                    }
                }
            }
        }
        let mut used = [false; 12];
        let mut out = Vec::new();
        for start in 0..12 {
            if next[start] == usize::MAX || used[start] {
                continue;
            }
            let mut lp = vec![start];
            used[start] = true;
            let mut e = next[start];
            while e != start {
                lp.push(e);
                used[e] = true;
                e = next[e];
            }
            for i in 1..lp.len() - 1 {
                out.extend_from_slice(&[lp[0] as u8, lp[i] as u8, lp[i + 1] as u8]);
            }
        }
        assert!(
            out.len() <= 3 * MAX_CELL_TRIANGLES,
            "case {case}: {} triangles",
            out.len() / 3
        );
        tris[case][..out.len()].copy_from_slice(&out);
        counts[case] = (out.len() / 3) as u8;
        for (j, t) in out.chunks(3).enumerate() {
            if common_face(t[0] as usize, t[1] as usize, t[2] as usize).is_some() {
                flat[case] |= 1 << j;
            }
        }
    }
    McTable { tris, counts, flat }
}

/// The face of the cube, `(axis, side)`, that edges `a`, `b`, `c` all lie on,
/// if any: a triangle on them lies in that face's plane (see
/// [`McTable::flat`]).
pub fn common_face(a: usize, b: usize, c: usize) -> Option<(usize, usize)> {
    let side = |e: usize, f: usize| (edge_corners(e).0 >> f) & 1;
    (0..3)
        .find(|&f| {
            [a, b, c].iter().all(|&e| e / 4 != f)
                && side(a, f) == side(b, f)
                && side(b, f) == side(c, f)
        })
        .map(|f| (f, side(a, f)))
}

/// The case table (built once per process).
pub fn table() -> &'static McTable {
    static T: OnceLock<McTable> = OnceLock::new();
    T.get_or_init(build_table)
}

/// Most grid points along one axis. The kernels (and their CPU twins) place
/// a vertex in grid-index space in `f32`, where integers above 2^24 are not
/// all representable: beyond it an edge's two ends round to one value and a
/// crossing would be counted once but listed as two grid points.
pub const MAX_AXIS_POINTS: usize = 1 << 24;

/// Checks that a volume of `dims` grid points can be extracted: each axis at
/// most [`MAX_AXIS_POINTS`] and fewer than 2^32 voxels in all (the kernels'
/// 32-bit vertex and grid indices). The error names the axis or the count.
pub fn check_dims(dims: [usize; 3]) -> Result<()> {
    for (axis, &d) in ["x", "y", "z"].iter().zip(&dims) {
        if d > MAX_AXIS_POINTS {
            return Err(Error::InvalidArgument(format!(
                "volume of {}×{}×{} voxels: {d} along {axis}; marching cubes places \
                 vertices in single precision and takes at most {MAX_AXIS_POINTS} \
                 (2^24) along an axis",
                dims[0], dims[1], dims[2]
            )));
        }
    }
    let n = dims.iter().map(|&d| d as u64).product::<u64>();
    if n >= 1 << 32 {
        return Err(Error::InvalidArgument(format!(
            "volume of {n} voxels: at most 2^32 − 1 voxels"
        )));
    }
    Ok(())
}

/// Finite sample magnitude from which an edge's value difference can
/// overflow `f32` (2^126, about 8.5e37): volumes with such values build the
/// marching-cubes kernels with `SC_MC_HALVE`, whose lane code takes the
/// halved differences where one overflows, as `mc_edge_t` always does (and
/// the CPU twin's `edge_t`). Below it no difference on a crossing edge
/// overflows, so both give the same bits.
pub const HALVE_FROM: f32 = (1u128 << 126) as f32;

/// Whether a volume whose largest finite magnitude is `max_abs` needs
/// `SC_MC_HALVE` ([`HALVE_FROM`]).
pub fn halves_differences(max_abs: f32) -> bool {
    max_abs >= HALVE_FROM
}

/// Number of cell rows (one row: every cell with the same y and z).
pub fn cell_rows(dims: [usize; 3]) -> usize {
    if dims.iter().any(|&d| d < 2) {
        0
    } else {
        (dims[1] - 1) * (dims[2] - 1)
    }
}

/// Soup vertices of `triangles` soup triangles (the scan total of the
/// `mc_classify` row counts): three per triangle, no sharing. Sizes `pos`
/// (3 floats each), `key`, `idx` and, for [`Fusion::None`], the soup's face
/// indices.
///
/// [`Fusion::None`]: crate::spec::vertex_fusion::Fusion::None
pub fn soup_vertices_bound(triangles: usize) -> usize {
    3 * triangles
}

/// Bits of the exact vertex keys of [`Fusion::Edge`] for a volume of
/// `voxels` voxels (keys `4g + axis` and `4g + 3`, `g` a voxel index), or
/// `None` when they do not fit the device's 32-bit keys (more than 2^30
/// voxels).
///
/// [`Fusion::Edge`]: crate::spec::vertex_fusion::Fusion::Edge
pub fn edge_key_bits(voxels: usize) -> Option<u32> {
    let keys = 4 * voxels as u64;
    (keys <= u32::MAX as u64 + 1).then(|| 64 - keys.saturating_sub(1).leading_zeros())
}

/// Bytes of device memory needed to extract a surface of `soup_vertices`
/// soup vertices from a volume of `voxels` voxels (volume, row buffers, soup,
/// fusion scratch and outputs): the bound the memory check uses.
pub fn device_bytes_bound(voxels: usize, rows: usize, soup_vertices: usize) -> u64 {
    4 * voxels as u64
        + 8 * rows as u64
        + 20 * soup_vertices as u64
        + crate::spec::vertex_fusion::device_bytes_bound(soup_vertices)
}

/// Which vertex normals the curvature of an isosurface uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum IsoNormals {
    /// The volume's gradient at each vertex: far more accurate on
    /// marching-cubes meshes, whose sliver triangles make face normals noisy.
    Gradient,
    /// The estimator's own area-weighted face normals (Rusinkiewicz).
    Mesh,
}

impl IsoNormals {
    /// Both choices, in the order of `--help` (the default first).
    pub const ALL: [IsoNormals; 2] = [IsoNormals::Gradient, IsoNormals::Mesh];

    /// The name used on the command line (`--curvature-normals`) and in stats.
    pub fn name(self) -> &'static str {
        match self {
            IsoNormals::Mesh => "mesh",
            IsoNormals::Gradient => "gradient",
        }
    }
}

super::named_choice!(IsoNormals, "isosurface normals choice");

/// Which side of the iso value is the object. Marching cubes orients its
/// triangles (and gradient normals) out of the region *below* the iso value;
/// for density data (CT, MRI: the object has the high values) the values and
/// the iso value are negated first (exact in f32), so normals point out of
/// the object and its convex parts get positive curvature. The scene file's
/// `inside = "above" | "below"`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Inside {
    /// The object has the values above the iso value (density volumes).
    Above,
    /// The object has the values below it (signed distance fields).
    #[default]
    Below,
}

impl Inside {
    /// Both choices, in the order of `--help`.
    pub const ALL: [Inside; 2] = [Inside::Above, Inside::Below];

    /// The name used on the command line and in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Inside::Above => "above",
            Inside::Below => "below",
        }
    }
}

crate::spec::choice!(Inside);

impl std::str::FromStr for Inside {
    type Err = crate::error::Error;

    /// `above` or `below` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "below" => Ok(Inside::Below),
            "above" => Ok(Inside::Above),
            _ => Err(crate::error::Error::InvalidArgument(format!(
                "inside = '{s}': expected above or below"
            ))),
        }
    }
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/marching_cubes.cl` and `kernels/marching_cubes_direct.cl`.
    pub enum McKernel {
        /// Per-cell case and triangle count (soup variants).
        Classify = "mc_classify",
        /// The soup: three vertices per triangle, each with its key.
        Triangles = "mc_triangles",
        /// Soup indices 0..n for the sort.
        Iota = "mc_iota",
        /// Vertex normals from the volume gradient.
        GradientNormals = "mc_gradient_normals",
        /// Direct numbering: each row trimmed to where the surface is.
        DirectRows = "mc_direct_rows",
        /// Per row: vertices on its edges, triangles and exact hits.
        DirectCount = "mc_direct_count",
        /// The grid points that vertices land on, listed.
        DirectHits = "mc_direct_hits",
        /// Rows with hits recounted for collapsing triangles.
        DirectRecount = "mc_direct_recount",
        /// Triangles with their final indices.
        DirectTriangles = "mc_direct_triangles",
        /// Vertex positions, each made once by its edge.
        DirectPoints = "mc_direct_points",
        /// The cell rows that dropped triangles, listed.
        DirectUnusedRows = "mc_direct_unused_rows",
        /// Near dropped triangles: the marks of the vertices that may be unused.
        DirectUnusedClear = "mc_direct_unused_clear",
        /// Near dropped triangles: the vertices the kept triangles use.
        DirectUnusedMark = "mc_direct_unused_mark",
        /// Near dropped triangles: the vertices left unused, counted.
        DirectUnusedCount = "mc_direct_unused_count",
    }
}

/// Whether direct numbering checks that every vertex is still used only near
/// the cell rows that dropped triangles (`mc_direct_unused_*`: the vertices
/// of their grid rows, marked by the kept triangles of the 3 × 3 cell rows
/// around each) rather than over every triangle (vertex fusion's marks and
/// their sum, which the compaction needs anyway): when the kept triangles of
/// those blocks, at most 9 cell rows per dropped triangle of about
/// `triangles / cell_rows` each, are at most a quarter of the `triangles`.
pub fn unused_check_near(dropped: usize, cell_rows: usize) -> bool {
    36 * dropped as u64 <= cell_rows as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dims_beyond_single_precision_or_32_bit_indices_are_refused() {
        assert!(check_dims([MAX_AXIS_POINTS, 2, 2]).is_ok());
        for (dims, word) in [
            ([MAX_AXIS_POINTS + 1, 2, 2], "along x"),
            ([17, MAX_AXIS_POINTS + 17, 2], "along y"),
            ([2, 2, usize::MAX], "along z"),
            ([65_536, 65_536, 2], "2^32"),
        ] {
            let e = check_dims(dims).unwrap_err().to_string();
            assert!(e.contains(word), "{dims:?}: {e}");
        }
        assert!(check_dims([65_536, 65_535, 1]).is_ok());
    }

    #[test]
    fn below_halve_from_no_difference_overflows() {
        assert_eq!(HALVE_FROM, 2f32.powi(126));
        let below = f32::from_bits(HALVE_FROM.to_bits() - 1);
        assert!((below - -below).is_finite());
        assert!((HALVE_FROM - -HALVE_FROM).is_finite());
        assert!((f32::MAX - -HALVE_FROM).is_infinite());
        assert!(!halves_differences(below) && halves_differences(HALVE_FROM));
    }
}
