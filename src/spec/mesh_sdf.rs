//! Shared types of the `mesh_sdf` family (see [`crate::spec`]): the options,
//! the grid a mesh is sampled on, and the prepared input both the kernels
//! (`kernels/mesh_sdf.cl`) and the CPU twin (`crate::cpu::mesh_sdf`) read;
//! `crate::mesh::mesh_sdf::prepare` makes it from a mesh.
//!
//! The grid: the box is the bounding box of the vertices that faces use,
//! padded on every side by [`padding_voxels`] voxels (at least
//! [`MARGIN_VOXELS`], and [`MARGIN_FRACTION`] of the longest axis), with
//! isotropic spacing chosen so that the longest axis gets exactly
//! `resolution` samples. The box is centred on the mesh's box, so world
//! coordinates of the volume are the mesh's.
//!
//! Distances: exact point-triangle distance in a narrow band of
//! [`BAND_VOXELS`] (each triangle measures the voxels of its grown box),
//! jump flooding of nearest points beyond it, and a last pass that measures
//! each voxel's candidate triangle exactly and descends across
//! edge-adjacent triangles while they are nearer.
//!
//! The prepared input: vertex positions in grid index units, snapped to a
//! fixed-point lattice of [`FIX_ONE`] steps per voxel. The sign pass
//! intersects grid lines with triangles using exact 64-bit integer edge
//! functions on these coordinates (so a grid line through a shared edge or
//! vertex is counted exactly once, and the device and the CPU twin agree
//! bit for bit); the distance passes use the same coordinates as `f32`.
//! Snapping moves a vertex by at most 2⁻¹⁷ voxel.

use crate::error::{Error, Result};

/// Default samples along the longest axis.
pub const DEFAULT_RESOLUTION: usize = 128;
/// Smallest resolution accepted: the padding alone takes 4 samples.
pub const MIN_RESOLUTION: usize = 8;
/// Largest resolution accepted: keeps fixed-point grid coordinates
/// (`resolution × FIX_ONE`) within 2²⁸, so edge functions fit in `i64`.
pub const MAX_RESOLUTION: usize = 4096;
/// Padding of the box around the mesh, as a fraction of the longest axis's
/// sample count (see [`padding_voxels`]).
pub const MARGIN_FRACTION: f64 = 0.05;
/// Smallest padding in voxels: marching cubes needs outside samples all
/// around the surface, and the strokes' central differences one more.
pub const MARGIN_VOXELS: f64 = 2.0;
/// Fixed-point bits per voxel of the snapped vertex coordinates.
pub const FIX_BITS: u32 = 16;
/// Fixed-point units per voxel (`2^FIX_BITS`).
pub const FIX_ONE: i64 = 1 << FIX_BITS;
/// Half-width, in voxels, of the narrow band where distances are exact:
/// each triangle measures every voxel of its bounding box grown by this
/// much, so every voxel within this distance of a triangle has measured it.
pub const BAND_VOXELS: f32 = 1.0;
/// Most voxel visits the band pass may make (the sum over triangles of
/// their grown boxes' voxels): a mesh of many large triangles is an error
/// naming the count rather than a pass that runs for minutes.
pub const MAX_BAND_WORK: u64 = 1 << 32;
/// Most steps of the refinement's descent across neighbouring triangles.
pub const MAX_DESCENT: u32 = 16;
/// Triangle index meaning "no candidate yet".
pub const NO_TRIANGLE: u32 = u32::MAX;

/// Options of the mesh → signed distance conversion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSdfOptions {
    /// Samples along the longest axis of the padded box
    /// ([`MIN_RESOLUTION`]..=[`MAX_RESOLUTION`]).
    pub resolution: usize,
}

impl Default for MeshSdfOptions {
    fn default() -> Self {
        MeshSdfOptions {
            resolution: DEFAULT_RESOLUTION,
        }
    }
}

/// The padding, in voxels, on every side of the box for `resolution`
/// samples along the longest axis: `max(MARGIN_VOXELS, MARGIN_FRACTION ·
/// (resolution − 1))` (6.35 voxels, 5.6 % of the mesh's extent, at 128).
pub fn padding_voxels(resolution: usize) -> f64 {
    MARGIN_VOXELS.max(MARGIN_FRACTION * (resolution as f64 - 1.0))
}

/// The grid a mesh is sampled on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SdfGrid {
    /// Samples along x, y, z.
    pub dims: [usize; 3],
    /// Isotropic spacing (world units per voxel).
    pub spacing: f64,
    /// World position of sample (0, 0, 0).
    pub origin: [f64; 3],
}

impl SdfGrid {
    /// Number of samples.
    pub fn voxels(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// The first jump-flooding step: the smallest power of two at least
    /// half the largest dimension, so the steps sum to at least the largest
    /// dimension − 1 and a candidate reaches every voxel.
    pub fn first_step(&self) -> usize {
        let m = self.dims.iter().copied().max().unwrap_or(1);
        m.div_ceil(2).next_power_of_two()
    }

    /// The jump-flooding steps in order: `first_step`, halving to 1 (the
    /// exact refinement pass after them plays the role of JFA+1's extra
    /// step-1 pass, Rong & Tan 2006).
    pub fn steps(&self) -> Vec<usize> {
        let mut s = Vec::new();
        let mut k = self.first_step();
        while k >= 1 {
            s.push(k);
            k /= 2;
        }
        s
    }
}

/// A mesh ready for the distance and sign passes (see the module header).
#[derive(Clone, Debug)]
pub struct PreparedMesh {
    /// The sampling grid.
    pub grid: SdfGrid,
    /// Vertex positions in fixed-point grid units (`FIX_ONE` per voxel).
    pub fixed: Vec<[i32; 3]>,
    /// The same positions in grid units as `f32` (`fixed / FIX_ONE`).
    pub grid_pos: Vec<[f32; 3]>,
    /// The faces kept: those with nonzero area in fixed-point coordinates.
    pub triangles: Vec<[u32; 3]>,
    /// Faces dropped because their snapped corners are collinear.
    pub degenerate: usize,
    /// For each kept triangle, across each of its edges (`ab`, `bc`, `ca`),
    /// the smallest-index other kept triangle sharing that edge, or
    /// [`NO_TRIANGLE`] on a boundary.
    pub adjacent: Vec<[u32; 3]>,
}

impl PreparedMesh {
    /// The voxel range (inclusive, per axis) of triangle `t`'s bounding box
    /// grown by [`BAND_VOXELS`], in the `f32` arithmetic of the kernel.
    pub fn voxel_range(&self, t: usize) -> ([usize; 3], [usize; 3]) {
        let f = self.triangles[t];
        let mut lo = [0; 3];
        let mut hi = [0; 3];
        for k in 0..3 {
            let [a, b, c] = f.map(|v| self.grid_pos[v as usize][k]);
            let mn = a.min(b).min(c);
            let mx = a.max(b).max(c);
            let top = self.grid.dims[k] as i32 - 1;
            lo[k] = ((mn - BAND_VOXELS).ceil() as i32).clamp(0, top) as usize;
            hi[k] = ((mx + BAND_VOXELS).floor() as i32).clamp(0, top) as usize;
        }
        (lo, hi)
    }

    /// Voxel visits of the band pass (the sum over triangles of their
    /// ranges' voxels).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidInput`] above [`MAX_BAND_WORK`], naming the count.
    pub fn band_work(&self) -> Result<u64> {
        let n: u64 = (0..self.triangles.len())
            .map(|t| {
                let (lo, hi) = self.voxel_range(t);
                (0..3).map(|k| (hi[k] - lo[k] + 1) as u64).product::<u64>()
            })
            .sum();
        if n > MAX_BAND_WORK {
            return Err(Error::input(
                "mesh",
                "triangles",
                format!(
                    "the narrow band of {} triangles would take {n} point-triangle distances \
                     (at most {MAX_BAND_WORK}): the triangles are too large for the grid; \
                     lower the resolution",
                    self.triangles.len()
                ),
            ));
        }
        Ok(n)
    }
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/mesh_sdf.cl`.
    pub enum MsdfKernel {
        /// The grid reset.
        Clear = "msdf_clear",
        /// Exact point-triangle distances in the narrow band (minimum).
        BandMin = "msdf_band_min",
        /// The nearest triangle of each band voxel.
        BandId = "msdf_band_id",
        /// Jump-flooding seeds from the band.
        Seed = "msdf_seed",
        /// One jump-flooding step.
        Jfa = "msdf_jfa",
        /// Exact distance to the flooded nearest triangle.
        Refine = "msdf_refine",
        /// Ray crossings along the six axis directions.
        Cross = "msdf_cross",
        /// The generalized winding number from the crossings.
        Wind = "msdf_wind",
        /// Signed distances.
        Finish = "msdf_finish",
    }
}
