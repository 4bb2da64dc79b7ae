//! `shapecue curvature`: per-vertex curvature of a mesh file or a generated
//! mesh (one front-door call, [`shapecue::curvature_of`], or the CPU twin
//! [`shapecue::cpu::curvature::curvature`]), written as PLY with JSON stats
//! (`shapecue report curvature` prints the accuracy/time table).
//!
//! The stats time every phase of the command (`phases_ms`): the library
//! call's phases (the phases of [`shapecue::CurvatureRun::timing`]: load =
//! parse and validation, device, reorder (the memory order of `--order`), program
//! build, topology, normalisation, upload, the first run with the driver's
//! compilation at first launch, program-cache write), then read-back (the
//! device buffers mapped, not copied: CPU runtimes hand over their own
//! memory) and PLY write (with each value's conversion, scaling back and
//! mapping back to the input's order, done as it is written); `--runs N`
//! adds N timed runs of the device passes after the library's (the command
//! runs the returned estimator again), with medians.

use super::{check_outputs, out, write_json};
use anyhow::{Result, bail};
use clap::Args;
use shapecue::api::OrderedEstimator;
use shapecue::mesh::order::MeshOrder;
use shapecue::mesh::{Generated, LoadOptions, Mesh, NormalsSource};
use shapecue::spec::curvature::{
    AccumulateChoice, Compat, CurvatureCounts, CurvatureField, CurvatureOptions, Lanes, Precision,
    VertexCurvature,
};
use shapecue::spec::timing::Timing;
use shapecue::{CurvatureJob, MeshSource};
use std::path::PathBuf;
use std::time::Instant;

/// The arguments of `shapecue curvature`.
#[derive(Args)]
pub struct CurvatureArgs {
    /// Input mesh (.obj, .ply, .off), or a generated one: torus, sphere,
    /// ellipsoid, cylinder or plane (with --vertices), as `shapecue lines`
    /// takes it.
    #[arg(required_unless_present = "generate")]
    input: Option<PathBuf>,
    /// A generated mesh instead of a file (the same as giving its name as
    /// the input; kept for older scripts).
    #[arg(long, value_parser = super::choice::<Generated>(), conflicts_with = "input")]
    generate: Option<Generated>,
    /// Vertices of a generated mesh (about; default 40000). `--resolution`
    /// is its older name, kept as an alias.
    #[arg(long, alias = "resolution")]
    vertices: Option<usize>,
    /// Output PLY (binary little-endian). Never the input file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Merge vertices with bit-identical positions before computing.
    #[arg(long)]
    weld: bool,
    /// Vertex normals the curvature starts from: file (those a mesh file
    /// stores, OBJ vn or PLY nx ny nz, as trimesh2 and rtsc use them; the
    /// faces' where it stores none) or computed (always from the faces).
    #[arg(long, value_parser = super::choice::<NormalsSource>(), default_value = "file")]
    normals: NormalsSource,
    /// One-ring accumulation: float atomics per face (Griffin et al.; as
    /// compare-and-swap loops, or atomic-native: the device's own float
    /// atomic add, cl_ext_float_atomics or NVIDIA's PTX red.global.add), or
    /// per-vertex gather (bitwise reproducible). Default: gather, the faster
    /// exact scheme on CPU devices and GPUs measured (--stats says why).
    #[arg(long, value_parser = super::choice::<AccumulateChoice>(), default_value = "auto")]
    accumulate: AccumulateChoice,
    /// Faces per work-item of the per-face kernels (and vertices per
    /// work-item of the frame and principal passes), computed as SIMD
    /// lanes: 1, 2, 4, 8 or 16. Default: the device's native vector width on
    /// CPU devices, 1 on GPUs. The gather scheme gives the same bits for
    /// every count, the atomic schemes the same values up to the rounding
    /// of their sums; more than one lane adds 64 bytes of device memory per
    /// vertex (f32).
    #[arg(long, value_parser = super::choice::<Lanes>(), default_value = "auto")]
    lanes: Lanes,
    /// Order of the vertices and faces in device memory: auto renumbers
    /// them along a Morton curve when the input's order is scattered (as in
    /// scanned meshes), for cache locality; spatial always does, input never.
    /// Results are written in the input's order and differ only by the
    /// rounding of sums taken in another order.
    #[arg(long, value_parser = super::choice::<MeshOrder>(), default_value = "auto")]
    order: MeshOrder,
    /// Device precision.
    #[arg(long, value_parser = super::choice::<Precision>(), default_value = "f32")]
    precision: Precision,
    /// Exact least squares, or trimesh2 2.16 compatibility (its pivot quirk, |k1| ≥ |k2|).
    #[arg(long, value_parser = super::choice::<Compat>(), default_value = "exact")]
    compat: Compat,
    /// Skip the curvature-derivative pass (dk written as zeros).
    #[arg(long)]
    no_dcurv: bool,
    /// Compute with the CPU reference instead of the device.
    #[arg(long)]
    cpu: bool,
    /// Write statistics (device, counts, per-pass ms, bytes) as JSON.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    force: bool,
    /// After the run whose results are written (the warm-up), N more timed
    /// runs of the device passes; --stats gives their medians.
    #[arg(long)]
    runs: Option<usize>,
}

/// Runs `shapecue curvature`: the argument checks, the computation (the
/// CPU twin's or one library call's, with the timed repeats of `--runs`),
/// the read-back and its check, the printed summary, then the PLY and the
/// `--stats` document.
pub fn run(device: Option<&str>, a: CurvatureArgs) -> Result<()> {
    let opts = options(&a)?;
    let t_start = Instant::now();
    let source = check_args(&a)?;
    // The results: the CPU twin's field, or the device's buffers, read in
    // place below (no copy of the field: on a 2M-vertex mesh a copy is
    // 256 MB of fresh pages, whose first touch costs more than the rest).
    let (c, mut record) = if a.cpu {
        on_cpu(&a, &source, opts)?
    } else {
        on_device(device, &a, source, opts)?
    };
    if a.output.is_none() && a.stats.is_none() {
        eprintln!("note: no --output or --stats given; computing and printing a summary only");
    }
    // The time after the load (and the device's preparation): the
    // computation's share, then the read-back and the check below.
    let t_all = Instant::now();
    let t = Instant::now();
    let mapped = match &c.field {
        Field::Device(est) => Some(est.mapped()?),
        Field::Cpu(_) => None,
    };
    if mapped.is_some() {
        record.phase("read_back", ms_since(t));
    }
    let vertex = |i: usize| match (&c.field, &mapped) {
        (Field::Cpu(f), _) => f.vertex(i),
        (Field::Device(_), Some(m)) => m.vertex(i),
        (Field::Device(_), None) => unreachable!("a device field is mapped"),
    };
    let ranges = Ranges::of(c.mesh.n_vertices(), vertex)?;
    let total_ms = c.compute_ms + ms_since(t_all);
    let mostly_degenerate = print_summary(&c, &ranges, total_ms)?;
    if let Some(out) = &a.output {
        let t = Instant::now();
        let written =
            shapecue::export::ply::write_ply_vertices(out, &c.mesh, c.mesh.n_vertices(), vertex)?;
        record.phase("ply_write", ms_since(t));
        super::note_double(out, &written);
        out!("wrote {}", out.display());
    }
    if let Some(path) = &a.stats {
        let doc = record.finish(&c, mostly_degenerate, total_ms, t_start)?;
        write_json(path, &doc)?;
    }
    // The process ends with this command, and everything is written: the
    // OS takes back the device buffers, the context and the mesh at once,
    // sooner than releasing them one by one.
    std::mem::forget(mapped);
    std::mem::forget(c);
    Ok(())
}

/// The options the arguments ask for.
fn options(a: &CurvatureArgs) -> Result<CurvatureOptions> {
    Ok(CurvatureOptions {
        accumulate: a.accumulate.resolve(),
        precision: a.precision,
        compat: a.compat,
        dcurv: !a.no_dcurv,
        lanes: a.lanes,
    })
}

/// The checks made before the load (a refused output should not wait for
/// a large mesh), and where the mesh comes from.
fn check_args(a: &CurvatureArgs) -> Result<MeshSource> {
    if let Some(n) = a.runs {
        shapecue::spec::limits::check_count("--runs", n, 10_000)?;
    }
    // A name that is no file but a generated mesh's is that mesh, as in
    // `shapecue lines`.
    let named = (a.input.as_ref())
        .filter(|p| !p.exists())
        .and_then(|p| p.to_str())
        .and_then(|n| Generated::ALL.into_iter().find(|g| g.name() == n));
    let generate = a.generate.or(named);
    let input = a.input.as_deref().filter(|_| named.is_none());
    check_outputs(
        input,
        a.output.iter().chain(a.stats.iter()).map(PathBuf::as_path),
        a.force,
    )?;
    Ok(match (input, generate) {
        (_, Some(kind)) => {
            let n = a.vertices.unwrap_or(40_000);
            // Checked here first: the message names the flag.
            shapecue::spec::limits::check_mesh_vertices("--vertices", n)?;
            MeshSource::Generated(kind, n)
        }
        (Some(path), None) => {
            if a.vertices.is_some() {
                bail!(
                    "--vertices is for generated meshes (torus, sphere, ellipsoid, cylinder, \
                     plane); {} is a file",
                    path.display()
                );
            }
            MeshSource::File(
                path.to_path_buf(),
                LoadOptions {
                    weld: a.weld,
                    normals: a.normals,
                },
            )
        }
        (None, None) => bail!("give an input mesh or --generate"),
    })
}

/// The results, before the read-back.
enum Field {
    /// The CPU twin's field.
    Cpu(CurvatureField),
    /// The device's buffers, read in place.
    Device(Box<OrderedEstimator>),
}

/// What the computation made.
struct Computed {
    /// The mesh's name (its path, or the generated mesh's description).
    name: String,
    mesh: Mesh,
    field: Field,
    counts: CurvatureCounts,
    /// The options asked for (the accumulation scheme the device ran).
    opts: CurvatureOptions,
    /// Wall ms of the load.
    load_ms: f64,
    /// Wall ms after the load (and the device's preparation) to the end of
    /// the computation and its timed repeats.
    compute_ms: f64,
}

/// The `--stats` document as the computation filled it, and the phases
/// (`phases_ms`) it will hold.
struct Record {
    stats: serde_json::Value,
    phases: serde_json::Map<String, serde_json::Value>,
}

impl Record {
    /// Adds the phase `name` of `ms`.
    fn phase(&mut self, name: &str, ms: f64) {
        self.phases.insert(name.into(), serde_json::json!(ms));
    }

    /// The document with the mesh, the options, the counts and the times
    /// of the whole command (`command_ms`: from the start of the command,
    /// after argument parsing, to here: everything but the process start
    /// and the document's file).
    fn finish(
        self,
        c: &Computed,
        mostly_degenerate: bool,
        total_ms: f64,
        t_start: Instant,
    ) -> Result<serde_json::Value> {
        let mut stats = self.stats;
        stats["input"] = serde_json::json!(c.name);
        stats["vertices"] = serde_json::json!(c.mesh.n_vertices());
        stats["faces"] = serde_json::json!(c.mesh.n_faces());
        stats["normals"] = serde_json::json!(if c.mesh.normals.is_some() {
            "file"
        } else {
            "computed"
        });
        stats["options"] = serde_json::to_value(c.opts)?;
        stats["counts"] = serde_json::to_value(c.counts)?;
        stats["mostly_degenerate"] = serde_json::json!(mostly_degenerate);
        stats["load_ms"] = serde_json::json!(c.load_ms);
        stats["total_wall_ms"] = serde_json::json!(total_ms);
        stats["phases_ms"] = serde_json::Value::Object(self.phases);
        stats["command_ms"] = serde_json::json!(ms_since(t_start));
        Ok(stats)
    }
}

/// The CPU reference: the load, the field (in f64, so it judges faces by
/// f64 rounding), and `--runs` more timed runs with their median wall time.
fn on_cpu(
    a: &CurvatureArgs,
    source: &MeshSource,
    opts: CurvatureOptions,
) -> Result<(Computed, Record)> {
    let t_load = Instant::now();
    let (name, mesh) = source.load()?;
    let load_ms = ms_since(t_load);
    let t_compute = Instant::now();
    let f64_opts = CurvatureOptions {
        precision: Precision::F64,
        ..opts
    };
    let c = shapecue::api::curvature_reference(&mesh, f64_opts)?;
    let mut stats = serde_json::json!({
        "device": "cpu reference (f64, single thread)",
        "wall_ms": c.timing.wall_ms,
    });
    if let Some(n) = a.runs {
        let mut walls = Vec::with_capacity(n);
        for _ in 0..n {
            walls.push(
                shapecue::api::curvature_reference(&mesh, f64_opts)?
                    .timing
                    .wall_ms,
            );
        }
        stats["runs"] = serde_json::json!(n);
        stats["wall_median_ms"] = serde_json::json!(shapecue::report::metrics::median(&mut walls));
    }
    let mut record = Record {
        stats,
        phases: serde_json::Map::new(),
    };
    record.phase("load", load_ms);
    record.phase("first_run", c.timing.wall_ms);
    let computed = Computed {
        name,
        mesh,
        field: Field::Cpu(c.field),
        counts: c.counts,
        opts,
        load_ms,
        compute_ms: ms_since(t_compute),
    };
    Ok((computed, record))
}

/// One library call (the load beside the device's opening and the program
/// build, then the ordered estimator, run once and left on the device,
/// with its phases), then `--runs` more timed runs of the returned
/// estimator with their medians.
fn on_device(
    device: Option<&str>,
    a: &CurvatureArgs,
    source: MeshSource,
    opts: CurvatureOptions,
) -> Result<(Computed, Record)> {
    let mut r = shapecue::curvature_of(&CurvatureJob {
        source,
        device: device.map(str::to_string),
        opts,
        accumulate: a.accumulate,
        order: a.order,
    })?;
    let opts = CurvatureOptions {
        accumulate: r.opts.accumulate,
        ..opts
    };
    let t_runs = Instant::now();
    let runs = timed_runs(&mut r, a.runs.unwrap_or(0))?;
    let runs_ms = ms_since(t_runs);
    let mut stats = device_stats(a, &r, &opts);
    if a.runs.is_some() {
        shapecue::report::metrics::runs_stats(&mut stats, &runs, r.timing.wall_ms);
    }
    note_compilation(&r);
    stats["programs"] = serde_json::to_value(r.gpu.program_builds())?;
    let record = Record {
        stats,
        phases: library_phases(&r.timing),
    };
    let computed = Computed {
        load_ms: r.timing.phase_ms("load"),
        compute_ms: r.timing.phase_ms("compute") + runs_ms,
        name: r.name,
        mesh: r.mesh,
        field: Field::Device(Box::new(r.estimator)),
        counts: r.counts,
        opts,
    };
    Ok((computed, record))
}

/// `n` timed runs of the device passes after the library's. Each writes the
/// same values (the passes are deterministic for gather; atomic sums may
/// differ in the last bits), so the field read afterwards is the last
/// run's.
fn timed_runs(r: &mut shapecue::CurvatureRun, n: usize) -> Result<Vec<Timing>> {
    Ok((0..n)
        .map(|_| r.estimator.est.run())
        .collect::<shapecue::Result<Vec<_>>>()?)
}

/// The device run's stats: device, scheme and lanes with the reasons for
/// them, memory order, topology, per-pass and run times, device memory.
fn device_stats(
    a: &CurvatureArgs,
    r: &shapecue::CurvatureRun,
    opts: &CurvatureOptions,
) -> serde_json::Value {
    let est = &r.estimator.est;
    let device_bytes = est.device_bytes();
    serde_json::json!({
        "device": r.gpu.info,
        "accumulate": opts.accumulate.name(),
        "accumulate_why": a.accumulate.why(),
        "face_lanes": est.face_lanes(),
        "face_lanes_why": match opts.lanes {
            Lanes::Auto => shapecue::spec::curvature::why_face_lanes(&r.gpu.info.kind),
            Lanes::Fixed(_) => "given with --lanes",
        },
        "order": if r.reordered() { "spatial" } else { "input" },
        "topology_ms": est.topology_ms(),
        "passes": passes(&r.timing),
        "kernel_ms": r.timing.kernel_ms,
        "run_wall_ms": r.timing.wall_ms,
        "device_bytes": device_bytes,
        "device_bytes_per_vertex": device_bytes as f64 / r.mesh.n_vertices() as f64,
    })
}

/// PoCL compiles at the first build and launch when its own cache is empty
/// (seconds), and shapecue saves nothing there on its own: a note saying
/// how to build the kernels once.
fn note_compilation(r: &shapecue::CurvatureRun) {
    let compile_ms = r.timing.phase_ms("program_prepare") + r.timing.wall_ms;
    if compile_ms > 1000.0
        && r.gpu
            .program_builds()
            .iter()
            .any(|b| b.cache == "miss" && !b.saved)
    {
        eprintln!(
            "note: the curvature kernels were compiled for this run ({:.1} s); \
             `shapecue build-kernels` builds them once for later runs",
            compile_ms / 1e3
        );
    }
}

/// The library call's phases as `phases_ms` lists them; `compute` (its
/// share after the load) counts in `total_wall_ms` instead.
fn library_phases(t: &Timing) -> serde_json::Map<String, serde_json::Value> {
    t.phases
        .iter()
        .filter(|p| p.phase != "compute")
        .map(|p| (p.phase.to_string(), serde_json::json!(p.ms)))
        .collect()
}

/// The ranges of k1 and k2 over a field whose every value is finite.
#[derive(Clone, Copy)]
struct Ranges {
    k1min: f64,
    k1max: f64,
    k2min: f64,
    k2max: f64,
}

impl Ranges {
    /// The ranges over vertices `0..n`; an error if a value is not finite.
    fn of(n: usize, vertex: impl Fn(usize) -> VertexCurvature) -> Result<Ranges> {
        let mut r = Ranges {
            k1min: f64::INFINITY,
            k1max: f64::NEG_INFINITY,
            k2min: f64::INFINITY,
            k2max: f64::NEG_INFINITY,
        };
        let mut finite = true;
        for v in (0..n).map(vertex) {
            finite &= v.all_finite();
            (r.k1min, r.k1max) = (r.k1min.min(v.k1), r.k1max.max(v.k1));
            (r.k2min, r.k2max) = (r.k2min.min(v.k2), r.k2max.max(v.k2));
        }
        if !finite {
            bail!("internal error: non-finite output (please report with the input mesh)");
        }
        Ok(r)
    }
}

/// Prints the summary line, and a warning when most faces were skipped as
/// degenerate; returns whether they were.
fn print_summary(c: &Computed, k: &Ranges, total_ms: f64) -> Result<bool> {
    let Ranges {
        k1min,
        k1max,
        k2min,
        k2max,
    } = *k;
    let (name, mesh, counts) = (&c.name, &c.mesh, &c.counts);
    out!(
        "{name}: {} vertices, {} faces; k1 in [{k1min:.4}, {k1max:.4}], k2 in [{k2min:.4}, {k2max:.4}]; \
         {} degenerate faces skipped, {} vertices without curvature; normals from the {}; \
         {total_ms:.1} ms",
        mesh.n_vertices(),
        mesh.n_faces(),
        counts.degenerate_faces,
        counts.vertices_without_curvature,
        if mesh.normals.is_some() {
            "file"
        } else {
            "faces"
        }
    );
    let mostly_degenerate = counts.mostly_degenerate(mesh.n_faces());
    if mostly_degenerate {
        // The advice to compute in f64 only where that is not already so.
        let advice = if c.opts.precision == Precision::F64 {
            "the mesh's faces are degenerate even in double precision"
        } else {
            "for a mesh far from the origin or finely detailed, try --precision f64"
        };
        eprintln!(
            "warning: {name}: {} of {} faces were skipped as degenerate, so most curvature \
                 values are zero. Faces are judged against the rounding of the precision computed \
                 in: {advice}",
            counts.degenerate_faces,
            mesh.n_faces()
        );
    }
    Ok(mostly_degenerate)
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// The curvature stats' `passes`: one `{pass, kernel_ms}` per curvature
/// step, named without the `curv_` prefix (`tensor`, `dcurv`).
pub fn passes(t: &shapecue::spec::timing::Timing) -> serde_json::Value {
    t.steps
        .iter()
        .map(|s| serde_json::json!({ "pass": s.step.name(), "kernel_ms": s.kernel_ms }))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_generate_choice_is_a_library_mesh() {
        for k in Generated::ALL {
            let (desc, m) = k.mesh(500);
            assert!(!desc.is_empty() && m.n_faces() > 0);
        }
    }
}
