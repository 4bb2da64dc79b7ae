//! Shared types of the `sdf_lines` family (see [`crate::spec`]):
//! curvature-directed strokes on a signed distance field (or any scalar
//! volume), after Interrante's curvature-directed strokes as run on the GPU
//! by the *Curvature-Directed Rendering* write-up: dense surface samples →
//! Poisson-disk thinning → gradient → principal curvature and direction
//! (Kindlmann et al. 2003) → RK4 tracing along d1 → tapered strips.
//!
//! Here: the options ([`SdfLineOptions`]) and the parameters they resolve to
//! ([`Resolved`], [`resolve`]), the `#[repr(C)]` parameter block the kernels
//! read ([`SdflParams`], mirrored in `kernels/sdf_lines.cl`), the output types
//! ([`SdfLinesOutput`]), and the bound functions that size every variable
//! output.
//!
//! Units: every length in the options and the outputs is in world units
//! (the volume's spacing and origin applied). The kernels work in *local*
//! world coordinates (world − origin) so that a volume far from the origin
//! keeps its float precision; the host adds the origin back in f64.

use crate::error::{Error, Result};
use bytemuck::{Pod, Zeroable};

/// Hessian sampling distances tried by the automatic choice, in voxels (the
/// smallest spacing of the volume): the candidates of [`Sampling::Auto`].
pub const AUTO_SAMPLING_VOXELS: [f64; 7] = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0];
/// Default seed spacing r as a multiple of the sampling distance h.
pub const SPACING_PER_SAMPLING: f64 = 1.5;
/// Default stroke length (end to end, at the largest κ1) per sampling distance.
pub const LENGTH_PER_SAMPLING: f64 = 6.0;
/// Default stroke width (at the seed, at the largest κ1) per sampling distance.
pub const WIDTH_PER_SAMPLING: f64 = 0.4;
/// Default RK4 step in voxels.
pub const STEP_VOXELS: f64 = 0.5;
/// Seed spacing of the provisional thinning whose seeds the automatic
/// sampling distance is measured on, in voxels (when no spacing is given).
pub const PROVISIONAL_SPACING_VOXELS: f64 = 4.0;
/// Newton projections onto the surface after each RK4 step.
pub const NEWTON_STEPS: u32 = 2;
/// Marker of an empty Poisson cell / an unset index.
pub const NONE: u32 = u32::MAX;

/// Which side of the iso value is inside the object: the marching-cubes
/// choice, shared so that the surface and its strokes agree.
pub use super::marching_cubes::Inside;

/// How the Hessian sampling distance h is chosen.
#[derive(Clone, Debug, PartialEq)]
pub enum Sampling {
    /// The candidate (world units) whose coefficient of variation of κ1
    /// over the seeds is closest to 1 (the write-up's rule). Empty: the
    /// candidates [`AUTO_SAMPLING_VOXELS`] × the voxel size.
    Auto(Vec<f64>),
    /// A fixed distance in world units.
    Fixed(f64),
}

/// Options of the `sdf_lines` family. Lengths are world units; `None` means
/// the documented default (a multiple of the sampling distance h).
#[derive(Clone, Debug, PartialEq)]
pub struct SdfLineOptions {
    /// The iso value of the surface.
    pub iso: f32,
    /// Which side is inside.
    pub inside: Inside,
    /// Hessian sampling distance h.
    pub sampling: Sampling,
    /// Poisson-disk seed spacing r (default [`SPACING_PER_SAMPLING`] × h).
    pub spacing: Option<f64>,
    /// Stroke length at the largest κ1 (default [`LENGTH_PER_SAMPLING`] × h).
    pub length: Option<f64>,
    /// Stroke width at the largest κ1 (default [`WIDTH_PER_SAMPLING`] × h).
    pub width: Option<f64>,
    /// RK4 step (default [`STEP_VOXELS`] voxels).
    pub step: Option<f64>,
    /// Length factor at the smallest κ1 over the seeds (1 at the largest;
    /// linear in between).
    pub length_low: f64,
    /// Width factor at the smallest κ1 over the seeds (1 at the largest).
    pub width_low: f64,
    /// Tracing stops where |κ1 − κ2| < `umbilic_rel` · (|κ1| + |κ2|) + `umbilic_abs`.
    pub umbilic_rel: f64,
    /// Absolute part of the umbilic test, in 1/world units; `None`: 10⁻³ / voxel.
    pub umbilic_abs: Option<f64>,
    /// Seed of the per-sample random priority of the thinning.
    pub seed: u32,
    /// Bound on the dense surface samples (caller-sized; more is an error
    /// naming the count). `None`: [`dense_bound`] of the volume.
    pub max_dense: Option<usize>,
    /// Bound on the Poisson background-grid cells.
    pub max_cells: usize,
    /// Bound on the traced points (seeds × points per stroke).
    pub max_points: usize,
}

impl Default for SdfLineOptions {
    fn default() -> Self {
        SdfLineOptions {
            iso: 0.0,
            inside: Inside::Below,
            sampling: Sampling::Auto(Vec::new()),
            spacing: None,
            length: None,
            width: None,
            step: None,
            length_low: 0.5,
            width_low: 0.5,
            umbilic_rel: 0.05,
            umbilic_abs: None,
            seed: 1,
            max_dense: None,
            max_cells: 1 << 26,
            max_points: 1 << 22,
        }
    }
}

/// Everything derived from the options and the volume's geometry that the
/// steps need, in world units.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Resolved {
    /// Hessian sampling distance h.
    pub sampling: f64,
    /// Seed spacing r.
    pub spacing: f64,
    /// Stroke length at the largest κ1.
    pub length: f64,
    /// Stroke width at the largest κ1.
    pub width: f64,
    /// RK4 step.
    pub step: f64,
    /// Absolute umbilic threshold.
    pub umbilic_abs: f64,
    /// Most RK4 steps each way from a seed (`ceil(length / 2 / step)`).
    pub max_steps: u32,
}

impl Resolved {
    /// Points per stroke slot: `2 · max_steps + 1`.
    pub fn points_per_stroke(&self) -> usize {
        2 * self.max_steps as usize + 1
    }
}

/// The smallest voxel spacing (world units per voxel step).
pub fn voxel_size(spacing: [f64; 3]) -> f64 {
    spacing.iter().copied().fold(f64::INFINITY, f64::min)
}

/// The automatic candidates of `sampling` for a volume with `spacing`.
pub fn sampling_candidates(sampling: &Sampling, spacing: [f64; 3]) -> Vec<f64> {
    match sampling {
        Sampling::Fixed(h) => vec![*h],
        Sampling::Auto(c) if !c.is_empty() => c.clone(),
        Sampling::Auto(_) => {
            let v = voxel_size(spacing);
            AUTO_SAMPLING_VOXELS.iter().map(|k| k * v).collect()
        }
    }
}

/// Resolves the defaults for sampling distance `h` on a volume with `spacing`.
///
/// # Errors
///
/// [`crate::error::Error::InvalidArgument`] for a non-positive or non-finite
/// length, or a stroke needing more than 2²⁰ steps.
pub fn resolve(opts: &SdfLineOptions, spacing: [f64; 3], h: f64) -> crate::error::Result<Resolved> {
    let voxel = voxel_size(spacing);
    let r = Resolved {
        sampling: h,
        spacing: opts.spacing.unwrap_or(SPACING_PER_SAMPLING * h),
        length: opts.length.unwrap_or(LENGTH_PER_SAMPLING * h),
        width: opts.width.unwrap_or(WIDTH_PER_SAMPLING * h),
        step: opts.step.unwrap_or(STEP_VOXELS * voxel),
        umbilic_abs: opts.umbilic_abs.unwrap_or(1e-3 / voxel),
        max_steps: 0,
    };
    for (what, v) in [
        ("sampling distance", r.sampling),
        ("seed spacing", r.spacing),
        ("stroke length", r.length),
        ("stroke width", r.width),
        ("step", r.step),
        ("voxel size", voxel),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(crate::error::Error::InvalidArgument(format!(
                "curvature-directed strokes: the {what} must be positive and finite, got {v}"
            )));
        }
    }
    for (what, v) in [
        ("length factor", opts.length_low),
        ("width factor", opts.width_low),
        ("umbilic threshold", opts.umbilic_rel),
        ("umbilic threshold", r.umbilic_abs),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(crate::error::Error::InvalidArgument(format!(
                "curvature-directed strokes: the {what} must be ≥ 0 and finite, got {v}"
            )));
        }
    }
    let steps = (r.length / 2.0 / r.step).ceil();
    if steps > (1u64 << 20) as f64 {
        return Err(crate::error::Error::InvalidArgument(format!(
            "curvature-directed strokes: a stroke of length {} with steps of {} needs {steps} \
             steps each way (at most 2^20)",
            r.length, r.step
        )));
    }
    Ok(Resolved {
        max_steps: steps.max(1.0) as u32,
        ..r
    })
}

/// Worst case of dense samples: one per grid edge (`3N`).
pub fn dense_bound(dims: [usize; 3]) -> usize {
    let [x, y, z] = dims;
    x.saturating_sub(1) * y * z + x * y.saturating_sub(1) * z + x * y * z.saturating_sub(1)
}

/// Cells per axis of the Poisson background grid of cell size `cell` over a
/// box of `extent` world units (at least one).
pub fn poisson_cells(extent: [f64; 3], cell: f32) -> [usize; 3] {
    extent.map(|e| {
        ((e as f32 / cell).floor() as usize)
            .saturating_add(1)
            .max(1)
    })
}

/// Poisson grid cell size `r/√3` (so a cell's diagonal is r: one seed per cell).
pub fn poisson_cell(r: f64) -> f32 {
    (r / 3f64.sqrt()) as f32
}

/// Traced-point slots for `seeds` seeds: `seeds · points_per_stroke`.
pub fn stroke_points_bound(seeds: usize, points_per_stroke: usize) -> usize {
    seeds.saturating_mul(points_per_stroke)
}

/// Strip vertices for `seeds` strokes: two per traced point.
pub fn strip_vertices_bound(seeds: usize, points_per_stroke: usize) -> usize {
    2 * stroke_points_bound(seeds, points_per_stroke)
}

/// The parameter block of every `sdf_lines` kernel (a `__constant` buffer
/// of one element), mirrored as `SdflParams` in `kernels/sdf_lines.cl`;
/// the layout is checked by a probe kernel test.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SdflParams {
    /// Voxels per axis (x, y, z, 0).
    pub dims: [u32; 4],
    /// World units per voxel step (x, y, z, 0).
    pub spacing: [f32; 4],
    /// Poisson grid cells per axis (x, y, z, 0).
    pub cells: [u32; 4],
    /// Iso value.
    pub iso: f32,
    /// +1 when inside is below iso, −1 when above: the field is sign · (v − iso).
    pub sign: f32,
    /// Hessian sampling distance h (world).
    pub h: f32,
    /// RK4 step (world).
    pub step: f32,
    /// Poisson cell size r/√3 (world).
    pub cell: f32,
    /// r² (world²).
    pub r2: f32,
    /// Relative umbilic threshold.
    pub umbilic_rel: f32,
    /// Absolute umbilic threshold (1/world).
    pub umbilic_abs: f32,
    /// Stroke length at the largest κ1.
    pub length: f32,
    /// Stroke width at the largest κ1.
    pub width: f32,
    /// Length factor at the smallest κ1.
    pub length_low: f32,
    /// Width factor at the smallest κ1.
    pub width_low: f32,
    /// Thinning priority seed.
    pub seed: u32,
    /// Most steps each way.
    pub max_steps: u32,
    /// Newton projections per step.
    pub newton: u32,
    /// Padding (0).
    pub pad: u32,
}

const _: () = assert!(std::mem::size_of::<SdflParams>() == 112);

/// One seed: a kept Poisson sample with its curvature.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Seed {
    /// World position (on the interpolated surface).
    pub p: [f64; 3],
    /// Outward unit normal.
    pub n: [f64; 3],
    /// First (larger, signed) principal curvature.
    pub k1: f64,
    /// Second principal curvature.
    pub k2: f64,
    /// Unit first principal direction (tangent).
    pub d1: [f64; 3],
    /// False where the curvature is undefined (zero or non-finite gradient).
    pub valid: bool,
}

/// One traced stroke, in order from one end to the other through its seed.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Stroke {
    /// Index of its seed in [`SdfLinesOutput::seeds`].
    pub seed: usize,
    /// Index of the seed's point in `points`.
    pub centre: usize,
    /// World positions on the surface.
    pub points: Vec<[f64; 3]>,
    /// Outward unit normals at the points.
    pub normals: Vec<[f64; 3]>,
    /// Strip width at each point (tapered; 0 at both ends).
    pub widths: Vec<f64>,
    /// Triangle-strip vertices, two per point (left, right of the tangent
    /// seen from outside), world positions on the surface.
    pub strip: Vec<[f64; 3]>,
}

/// One candidate of the automatic sampling distance.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct CvPoint {
    /// Sampling distance h (world units).
    pub distance: f64,
    /// Coefficient of variation of κ1 over the seeds (std / |mean|).
    pub cv: f64,
    /// Seeds with a defined curvature that it was measured on.
    pub seeds: usize,
}

/// Kernel milliseconds per step (profiling events; 0 on the CPU twin).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct StepMs {
    /// `sdfl_dense`.
    pub dense: f64,
    /// Poisson-disk thinning (cell count, scan, fill, 27 phases, compaction).
    pub thin: f64,
    /// `sdfl_gradient`.
    pub gradient: f64,
    /// `sdfl_curvature` at the seeds.
    pub curvature: f64,
    /// `sdfl_range` (κ1 min/max with atomics).
    pub range: f64,
    /// `sdfl_trace`.
    pub trace: f64,
    /// Vertex-count scan and `sdfl_strips`.
    pub strips: f64,
    /// The automatic sampling sweep (provisional thinning + one curvature
    /// pass per candidate).
    pub sweep: f64,
    /// Sum of the above.
    pub total: f64,
}

impl StepMs {
    /// The steps as the one timing type ([`crate::spec::timing::Timing`]),
    /// in execution order (the sweep, when it ran, after the gradient), one
    /// launch each; `wall_ms` the run's wall time.
    pub fn timing(&self, wall_ms: f64) -> crate::spec::timing::Timing {
        use crate::spec::timing::{Step, Timing};
        let mut t = Timing::default();
        for (step, ms) in [
            (Step::SdflDense, self.dense),
            (Step::SdflGradient, self.gradient),
            (Step::SdflSweep, self.sweep),
            (Step::SdflThin, self.thin),
            (Step::SdflCurvature, self.curvature),
            (Step::SdflRange, self.range),
            (Step::SdflTrace, self.trace),
            (Step::SdflStrips, self.strips),
        ] {
            if step != Step::SdflSweep || ms > 0.0 {
                t.add(step, ms);
            }
        }
        t.wall_ms = wall_ms;
        t
    }
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SdfLineStats {
    /// Dense surface samples (before thinning).
    pub dense: usize,
    /// Seeds after thinning.
    pub seeds: usize,
    /// Strokes with at least one segment.
    pub strokes: usize,
    /// Segments over all strokes.
    pub segments: usize,
    /// Strip vertices.
    pub strip_vertices: usize,
    /// The resolved parameters (the chosen sampling distance among them).
    pub params: Option<Resolved>,
    /// The automatic sweep (empty for a fixed distance).
    pub sweep: Vec<CvPoint>,
    /// Smallest κ1 over the seeds.
    pub k1_min: f64,
    /// Largest κ1 over the seeds.
    pub k1_max: f64,
    /// Kernel ms per step and the wall time of the run (volume already on
    /// the device).
    pub timing: crate::spec::timing::Timing,
}

/// The result of one run: seeds, strokes and stats.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SdfLinesOutput {
    /// The thinned seeds, in Poisson-cell order (x fastest).
    pub seeds: Vec<Seed>,
    /// Strokes of at least two points, in seed order.
    pub strokes: Vec<Stroke>,
    /// Counts, parameters and timings.
    pub stats: SdfLineStats,
}

/// The automatic rule: the candidate whose CV is closest to 1 (the first
/// such on ties; the first candidate when none has a finite CV).
pub fn pick_sampling(sweep: &[CvPoint]) -> Option<f64> {
    let mut best: Option<(f64, f64)> = None;
    for c in sweep {
        if !c.cv.is_finite() {
            continue;
        }
        let d = (c.cv - 1.0).abs();
        if best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c.distance));
        }
    }
    best.map(|b| b.1)
        .or_else(|| sweep.first().map(|c| c.distance))
}

/// Coefficient of variation (population std / |mean|) of the finite values;
/// NaN for fewer than two or a zero mean.
pub fn coefficient_of_variation(values: impl Iterator<Item = f64>) -> (f64, usize) {
    let v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    if v.len() < 2 {
        return (f64::NAN, v.len());
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / v.len() as f64;
    if mean == 0.0 {
        return (f64::NAN, v.len());
    }
    (var.sqrt() / mean.abs(), v.len())
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/sdf_lines.cl`.
    pub enum SdflKernel {
        /// Field samples and gradients at given points (tests).
        Probe = "sdfl_probe",
        /// Sign changes between neighbouring voxels, appended.
        Dense = "sdfl_dense",
        /// Samples per Poisson-disk grid cell.
        CellCount = "sdfl_cell_count",
        /// Samples sorted into their cells.
        CellFill = "sdfl_cell_fill",
        /// One of the 27 conflict-free thinning phases.
        ThinPhase = "sdfl_thin_phase",
        /// Which samples survived thinning.
        ThinFlags = "sdfl_thin_flags",
        /// The seeds, compacted.
        ThinCompact = "sdfl_thin_compact",
        /// Central differences per voxel.
        Gradient = "sdfl_gradient",
        /// Principal curvatures and direction at given points (tests).
        PrincipalProbe = "sdfl_principal_probe",
        /// Principal curvatures and direction at the seeds.
        Curvature = "sdfl_curvature",
        /// κ1 minimum and maximum over the seeds.
        Range = "sdfl_range",
        /// RK4 along d1 both ways, projected onto the surface.
        Trace = "sdfl_trace",
        /// Tapered triangle strips.
        Strips = "sdfl_strips",
    }
}

// ---- Host steps the device stage and its twin share ----

/// The kernels' parameter block for a volume of `dims` samples `spacing`
/// apart with the resolved parameters.
pub fn params_for(
    dims: [usize; 3],
    spacing: [f64; 3],
    opts: &SdfLineOptions,
    r: &Resolved,
) -> SdflParams {
    let cell = poisson_cell(r.spacing);
    let cells = poisson_cells(extent_of(dims, spacing), cell);
    SdflParams {
        dims: [dims[0] as u32, dims[1] as u32, dims[2] as u32, 0],
        spacing: [spacing[0] as f32, spacing[1] as f32, spacing[2] as f32, 0.0],
        cells: [cells[0] as u32, cells[1] as u32, cells[2] as u32, 0],
        iso: opts.iso,
        sign: match opts.inside {
            Inside::Below => 1.0,
            Inside::Above => -1.0,
        },
        h: r.sampling as f32,
        step: r.step as f32,
        cell,
        r2: (r.spacing * r.spacing) as f32,
        umbilic_rel: opts.umbilic_rel as f32,
        umbilic_abs: r.umbilic_abs as f32,
        length: r.length as f32,
        width: r.width as f32,
        length_low: opts.length_low as f32,
        width_low: opts.width_low as f32,
        seed: opts.seed,
        max_steps: r.max_steps,
        newton: NEWTON_STEPS,
        pad: 0,
    }
}

/// A volume's extent in world units from voxel 0 (`(n − 1) · spacing`).
pub fn extent_of(dims: [usize; 3], spacing: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|a| dims[a].saturating_sub(1) as f64 * spacing[a])
}

/// One dense surface sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DenseSample {
    /// Local world position (world − origin), f32 as on the device.
    pub p: [f32; 3],
    /// Edge key `3 · g + axis` (g: linear index of the edge's lower grid point).
    pub key: u32,
}

/// The error for `count` dense samples over `bound`.
pub fn dense_overflow(count: usize, bound: usize) -> Error {
    Error::InvalidArgument(format!(
        "curvature-directed strokes: the surface has {count} dense samples, more than the \
         bound of {bound}; raise the bound or lower the resolution"
    ))
}

/// Refuses a volume too large for the edge keys (`3 · voxel + axis` in u32).
pub fn check_dims(dims: [usize; 3]) -> Result<()> {
    let n = dims.iter().map(|&d| d as u64).product::<u64>();
    if n.saturating_mul(3) >= u32::MAX as u64 {
        return Err(Error::InvalidArgument(format!(
            "curvature-directed strokes: volume of {n} voxels; at most (2^32 − 1)/3 voxels"
        )));
    }
    Ok(())
}

/// The error for a Poisson grid of `count` cells over `bound`.
pub fn cells_overflow(count: u128, bound: usize, r: f64) -> Error {
    Error::InvalidArgument(format!(
        "curvature-directed strokes: a seed spacing of {r} needs a Poisson grid of {count} \
         cells, more than the bound of {bound}; raise the spacing"
    ))
}

/// Total cells of the parameter block's grid, checked against `bound`.
pub fn cell_count(p: &SdflParams, bound: usize, r: f64) -> Result<usize> {
    let n = p.cells[..3].iter().map(|&c| c as u128).product::<u128>();
    if n > bound as u128 {
        return Err(cells_overflow(n, bound, r));
    }
    Ok(n as usize)
}

/// Principal curvatures and the first principal direction at a point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Principal {
    /// Outward unit normal ∇f/|∇f|.
    pub n: [f64; 3],
    /// Larger (signed) principal curvature.
    pub k1: f64,
    /// Smaller principal curvature.
    pub k2: f64,
    /// Unit tangent direction of κ1.
    pub d1: [f64; 3],
    /// False when |∇f| is zero or anything is not finite (then all zero).
    pub valid: bool,
}

/// Validates a volume of `dims` samples and the options; returns the
/// dense bound.
pub fn check_for(dims: [usize; 3], opts: &SdfLineOptions) -> Result<usize> {
    check_dims(dims)?;
    if !opts.iso.is_finite() {
        return Err(Error::InvalidArgument(format!(
            "curvature-directed strokes: the iso value must be finite, got {}",
            opts.iso
        )));
    }
    Ok(opts.max_dense.unwrap_or_else(|| dense_bound(dims)))
}

/// Checks the traced-point bound for `seeds` seeds.
///
/// # Errors
///
/// [`Error::InvalidArgument`] naming the seed count when
/// [`stroke_points_bound`] exceeds `max_points`.
pub fn check_points(seeds: usize, res: &Resolved, max_points: usize) -> Result<()> {
    let need = stroke_points_bound(seeds, res.points_per_stroke());
    if need > max_points {
        return Err(Error::InvalidArgument(format!(
            "curvature-directed strokes: {seeds} seeds × {} points per stroke = {need} traced \
             points, more than the bound of {max_points}; raise the seed spacing (now {})",
            res.points_per_stroke(),
            res.spacing
        )));
    }
    Ok(())
}

/// The stats of an output (counts from its strokes).
pub fn stats(
    dense: usize,
    out: &SdfLinesOutput,
    res: Resolved,
    sweep: Vec<CvPoint>,
    lo: f64,
    hi: f64,
) -> SdfLineStats {
    SdfLineStats {
        dense,
        seeds: out.seeds.len(),
        strokes: out.strokes.len(),
        segments: out.strokes.iter().map(|s| s.points.len() - 1).sum(),
        strip_vertices: out.strokes.iter().map(|s| s.strip.len()).sum(),
        params: Some(res),
        sweep,
        k1_min: lo,
        k1_max: hi,
        ..Default::default()
    }
}
