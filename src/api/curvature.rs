//! The curvature front door for a mesh still to be loaded: the load (and
//! the choice of memory order) on one thread while the device opens and
//! the curvature program is built (or loaded from the kernel cache) on
//! another, then the ordered estimator ([`OrderedEstimator`]) built, run
//! once and read in place ([`CurvatureRun::mapped`]: the device buffers
//! mapped, no copy of the field), with every phase timed.

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
                crate::spec::limits::check_mesh_vertices("--resolution", *n)?;
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
    /// Timed runs of the device passes after the first (0: none).
    pub runs: usize,
}

/// Host wall time of each phase of [`curvature_of`], ms.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct CurvaturePhases {
    /// Parsing and validating (or generating) the mesh.
    pub load: f64,
    /// Opening the device (beside the load).
    pub device: f64,
    /// Building the curvature program or loading it from the cache (beside
    /// the load).
    pub program_prepare: f64,
    /// Waiting for the device thread after the load.
    pub device_wait: f64,
    /// Choosing and applying the memory order (in the load's thread).
    pub reorder: f64,
    /// Getting the programs for the estimator.
    pub program_build: f64,
    /// The index-only structures on the device.
    pub topology: f64,
    /// Normalising the positions.
    pub normalise: f64,
    /// Writing them to the device.
    pub upload: f64,
    /// The first run (with the driver's compilation at first launch).
    pub first_run: f64,
    /// Saving newly built programs to the kernel cache.
    pub cache_write: f64,
}

/// What [`curvature_of`] made: the mesh, the estimator holding the results
/// on the device, and the phases.
pub struct CurvatureRun {
    /// The mesh's name (its path, or the generated mesh's description).
    pub name: String,
    /// The mesh, in its input order.
    pub mesh: Mesh,
    /// The device.
    pub gpu: Arc<Gpu>,
    /// The estimator after its runs; its results are read with
    /// [`CurvatureRun::mapped`].
    pub estimator: OrderedEstimator,
    /// The options run (the accumulation variant chosen).
    pub opts: CurvatureOptions,
    /// The first run's kernel time per pass and wall time.
    pub timing: Timing,
    /// The timed runs after it ([`CurvatureJob::runs`]).
    pub runs: Vec<Timing>,
    /// Skip counts of the run.
    pub counts: CurvatureCounts,
    /// Wall time of each phase.
    pub phases: CurvaturePhases,
    /// Wall ms from the end of the load and the device's preparation to
    /// the end of the call: building the estimator, the runs, the cache
    /// write.
    pub compute_ms: f64,
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

/// The device opened and the program built for the options.
struct Prepared {
    gpu: Arc<Gpu>,
    accumulate: Accumulate,
    device_ms: f64,
    prepare_ms: f64,
}

/// Opens the device and gets the curvature program for `opts` built (or
/// loaded from a cache). A program the device refuses is not an error
/// here: building the estimator reports it, with its context.
fn prepare_device(
    device: Option<&str>,
    mut opts: CurvatureOptions,
    accumulate: AccumulateChoice,
) -> Result<Prepared> {
    let t = Instant::now();
    let gpu = Arc::new(Gpu::new(device)?);
    let device_ms = ms_since(t);
    opts.accumulate = accumulate.resolve();
    let t = Instant::now();
    let _ = CurvatureEstimator::prepare(&gpu, &opts);
    Ok(Prepared {
        gpu,
        accumulate: opts.accumulate,
        device_ms,
        prepare_ms: ms_since(t),
    })
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
///     runs: 0,
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
    let mut opts = job.opts;
    let (loaded, prepared) = std::thread::scope(|s| {
        let prepare = s.spawn(|| prepare_device(job.device.as_deref(), opts, job.accumulate));
        let loaded = (|| {
            let t = Instant::now();
            let (name, mesh) = job.source.load()?;
            let load_ms = ms_since(t);
            let plan = OrderPlan::new(&mesh, job.order);
            Ok::<_, crate::error::Error>((name, mesh, load_ms, plan))
        })();
        let t_wait = Instant::now();
        let prepared = match prepare.join() {
            Ok(p) => p.map(|p| (p, ms_since(t_wait))),
            Err(panic) => std::panic::resume_unwind(panic),
        };
        (loaded, prepared)
    });
    let (name, mesh, load_ms, plan) = loaded?;
    let (p, wait_ms) = prepared?;
    let t_compute = Instant::now();
    opts.accumulate = p.accumulate;
    let gpu = p.gpu;
    let mut estimator = OrderedEstimator::with_plan(gpu.clone(), &mesh, opts, plan)?;
    let mut phases = CurvaturePhases {
        load: load_ms,
        device: p.device_ms,
        program_prepare: p.prepare_ms,
        device_wait: wait_ms,
        reorder: estimator.reorder_ms,
        program_build: estimator.est.build_ms(),
        topology: estimator.est.topology_ms() - estimator.est.build_ms(),
        normalise: estimator.est.upload_ms().normalise,
        upload: estimator.est.upload_ms().write,
        ..CurvaturePhases::default()
    };
    let timing = estimator.est.run()?;
    phases.first_run = timing.wall_ms;
    let counts = estimator.est.counts()?;
    // Each run writes the same values (the passes are deterministic for
    // gather; atomic sums may differ in the last bits), so the field read
    // afterwards is the last run's.
    let runs = (0..job.runs)
        .map(|_| estimator.est.run())
        .collect::<Result<Vec<_>>>()?;
    // After the runs, so that code the driver compiled at the first launch
    // is in the saved binaries; a no-op when the cache hit.
    let t = Instant::now();
    gpu.persist_programs();
    phases.cache_write = ms_since(t);
    Ok(CurvatureRun {
        name,
        mesh,
        gpu,
        estimator,
        opts,
        timing,
        runs,
        counts,
        phases,
        compute_ms: ms_since(t_compute),
    })
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
