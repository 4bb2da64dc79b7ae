//! The curvature front door for a mesh still to be loaded: the load (and
//! the choice of memory order) on one thread while the device opens and
//! the curvature program is built (or loaded from the kernel cache) on
//! another, then the ordered estimator ([`OrderedEstimator`]) built, run
//! once and read in place ([`CurvatureRun::mapped`]: the device buffers
//! mapped, no copy of the field), with every phase timed (the phases of the
//! run's [`Timing`]). Timed repeats are the caller's: `shapecue curvature
//! --runs` runs the returned estimator again.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use crate::error::Result;
use crate::gpu::Gpu;
use crate::mesh::order::MeshOrder;
use crate::mesh::{Generated, LoadOptions, Mesh};
use crate::spec::curvature::{Accumulate, AccumulateChoice, CurvatureCounts, CurvatureOptions};
use crate::spec::timing::Timing;
use crate::stages::curvature::{CurvatureEstimator, MappedField, OrderPlan, OrderedEstimator};

/// Where a mesh comes from.
#[derive(Clone, Debug)]
pub enum MeshSource {
    /// A mesh file (.obj, .ply, .off), loaded with these options.
    File(PathBuf, LoadOptions),
    /// A generated mesh of about this many vertices.
    Generated(Generated, usize),
}

impl MeshSource {
    /// Loads (or generates) the mesh; returns its name (the path, or the
    /// generated mesh's description) and the mesh.
    ///
    /// # Errors
    /// The file's errors; a generated mesh too large.
    pub fn load(&self) -> Result<(String, Mesh)> {
        Ok(match self {
            MeshSource::Generated(kind, n) => {
                crate::spec::limits::check_mesh_vertices("the generated mesh's vertex count", *n)?;
                kind.mesh(*n)
            }
            MeshSource::File(path, opts) => {
                (path.display().to_string(), crate::mesh::load(path, opts)?)
            }
        })
    }
}

/// What [`curvature_of`] computes and where.
#[derive(Clone, Debug)]
pub struct CurvatureJob {
    /// The mesh.
    pub source: MeshSource,
    /// The device (`SHAPECUE_DEVICE` or the first GPU, else CPU, when `None`).
    pub device: Option<String>,
    /// The options; `accumulate` is replaced by [`CurvatureJob::accumulate`]
    /// resolved.
    pub opts: CurvatureOptions,
    /// The accumulation scheme asked for ([`AccumulateChoice::resolve`]).
    pub accumulate: AccumulateChoice,
    /// The memory order the device computes in.
    pub order: MeshOrder,
}

/// What [`curvature_of`] made: the mesh, the estimator holding the results
/// on the device, and the call's timing.
pub struct CurvatureRun {
    /// The mesh's name (its path, or the generated mesh's description).
    pub name: String,
    /// The mesh, in its input order.
    pub mesh: Mesh,
    /// The device.
    pub gpu: Arc<Gpu>,
    /// The estimator after its run; its results are read with
    /// [`CurvatureRun::mapped`]. A caller timing repeats runs it again
    /// (`estimator.est.run()`: the same values, so the field read
    /// afterwards is the last run's).
    pub estimator: OrderedEstimator,
    /// The options run (the accumulation variant chosen).
    pub opts: CurvatureOptions,
    /// The run's kernel time per pass and wall time (`wall_ms`), and the
    /// wall time of each phase of the call ([`Timing::phase_ms`]): `load`
    /// (parsing and validating, or generating, the mesh), `device` (opening
    /// it, beside the load), `program_prepare` (building the curvature
    /// program or loading it from the kernel cache, beside the load),
    /// `device_wait` (waiting for the device thread after the load),
    /// `reorder` (choosing and applying the memory order, in the load's
    /// thread), `program_build` (getting the programs for the estimator),
    /// `topology` (the index-only structures on the device), `normalise`
    /// (the positions), `upload` (writing them to the device), `first_run`
    /// (the run, with the driver's compilation at first launch),
    /// `cache_write` (saving newly built programs to the kernel cache), and
    /// `compute`: from the end of the load and the device's preparation to
    /// the end of the call (building the estimator, the run, the cache
    /// write).
    pub timing: Timing,
    /// Skip counts of the run.
    pub counts: CurvatureCounts,
}

impl CurvatureRun {
    /// The results in the input's vertex order, read in place (the device
    /// buffers mapped; the same values as a copy, bit for bit).
    ///
    /// # Errors
    /// Mapping failures.
    pub fn mapped(&self) -> Result<MappedField<'_>> {
        self.estimator.mapped()
    }

    /// Whether the run computed in a renumbered memory order.
    pub fn reordered(&self) -> bool {
        self.estimator.order.is_some()
    }
}

/// The device opened and the program built for the options, with the
/// `device` and `program_prepare` phases.
struct Prepared {
    gpu: Arc<Gpu>,
    accumulate: Accumulate,
    timing: Timing,
}

/// Opens the device and gets the curvature program for `opts` built (or
/// loaded from a cache). A program the device refuses is not an error
/// here: building the estimator reports it, with its context.
fn prepare_device(
    device: Option<&str>,
    mut opts: CurvatureOptions,
    accumulate: AccumulateChoice,
) -> Result<Prepared> {
    let mut timing = Timing::default();
    let t = Instant::now();
    let gpu = Arc::new(Gpu::new(device)?);
    timing.phase("device", ms_since(t));
    opts.accumulate = accumulate.resolve();
    let t = Instant::now();
    let _ = CurvatureEstimator::prepare(&gpu, &opts);
    timing.phase("program_prepare", ms_since(t));
    Ok(Prepared {
        gpu,
        accumulate: opts.accumulate,
        timing,
    })
}

/// The mesh loaded and its memory order planned, with the `load` phase.
struct Loaded {
    name: String,
    mesh: Mesh,
    plan: OrderPlan,
    timing: Timing,
}

/// Loads the job's mesh and plans its memory order (this thread's half of
/// [`curvature_of`]).
fn load_and_plan(job: &CurvatureJob) -> Result<Loaded> {
    let mut timing = Timing::default();
    let t = Instant::now();
    let (name, mesh) = job.source.load()?;
    timing.phase("load", ms_since(t));
    let plan = OrderPlan::new(&mesh, job.order);
    Ok(Loaded {
        name,
        mesh,
        plan,
        timing,
    })
}

/// The load and the memory order on this thread while the device opens and
/// the program builds on another; the phases of both, and `device_wait`,
/// in the load's timing.
fn load_beside_device(job: &CurvatureJob) -> Result<(Loaded, Prepared)> {
    let (loaded, prepared) = std::thread::scope(|s| {
        let prepare = s.spawn(|| prepare_device(job.device.as_deref(), job.opts, job.accumulate));
        let loaded = load_and_plan(job);
        let t_wait = Instant::now();
        let prepared = match prepare.join() {
            Ok(p) => p.map(|p| (p, ms_since(t_wait))),
            Err(panic) => std::panic::resume_unwind(panic),
        };
        (loaded, prepared)
    });
    let mut loaded = loaded?;
    let (prepared, wait_ms) = prepared?;
    loaded.timing.extend(&prepared.timing);
    loaded.timing.phase("device_wait", wait_ms);
    Ok((loaded, prepared))
}

/// Curvature of a mesh still to be loaded, as fast as one process can get
/// it (the `shapecue curvature` command): the load and the memory order on
/// this thread while the device opens and the program builds on another
/// (both a single core's work), then the ordered estimator built and run,
/// the programs saved to the kernel cache, and the results left on the
/// device to be read in place ([`CurvatureRun::mapped`]). For a mesh in
/// hand, [`crate::curvature()`] is simpler.
///
/// ```
/// use shapecue::mesh::Generated;
/// let job = shapecue::CurvatureJob {
///     source: shapecue::MeshSource::Generated(Generated::Torus, 2000),
///     device: None,
///     opts: Default::default(),
///     accumulate: Default::default(),
///     order: Default::default(),
/// };
/// let run = shapecue::curvature_of(&job)?;
/// let k = run.mapped()?;
/// assert!((0..run.mesh.n_vertices()).all(|i| k.vertex(i).all_finite()));
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// The mesh's errors, no device, a device without what the variant needs,
/// OpenCL failures.
pub fn curvature_of(job: &CurvatureJob) -> Result<CurvatureRun> {
    let (loaded, prepared) = load_beside_device(job)?;
    let Loaded {
        name,
        mesh,
        plan,
        mut timing,
    } = loaded;
    let t_compute = Instant::now();
    let opts = CurvatureOptions {
        accumulate: prepared.accumulate,
        ..job.opts
    };
    let gpu = prepared.gpu;
    let mut estimator = OrderedEstimator::with_plan(gpu.clone(), &mesh, opts, plan)?;
    let est = &estimator.est;
    timing.phase("reorder", estimator.reorder_ms());
    for p in &est.host_timing().phases {
        timing.phase(p.phase, p.ms);
    }
    // The run's steps, kernel and wall time (the phases' timing has none).
    let run = estimator.est.run()?;
    timing.extend(&run);
    timing.phase("first_run", run.wall_ms);
    let counts = estimator.est.counts()?;
    // After the run, so that code the driver compiled at the first launch
    // is in the saved binaries; a no-op when the cache hit.
    let t = Instant::now();
    gpu.persist_programs();
    timing.phase("cache_write", ms_since(t));
    timing.phase("compute", ms_since(t_compute));
    Ok(CurvatureRun {
        name,
        mesh,
        gpu,
        estimator,
        opts,
        timing,
        counts,
    })
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
