//! `shapecue curvature`: per-vertex curvature of a mesh file or a generated
//! mesh ([`shapecue::curvature`] or its CPU twin), written as PLY with JSON
//! stats (`shapecue report curvature` prints the accuracy/time table).
//!
//! The stats time every phase of the command (`phases_ms`: load = parse and
//! validation, device, reorder (the memory order of `--order`), program
//! build, topology, normalisation, upload, the first run with the driver's
//! compilation at first launch, program-cache write, read-back (the device
//! buffers mapped, not copied: CPU runtimes hand over their own memory), PLY
//! write (with each value's conversion, scaling back and mapping back to
//! the input's order, done as it is written)), and `--runs N` adds N
//! timed runs of the device passes after the one whose results are written,
//! with medians.

use super::{check_outputs, out, write_json};
use anyhow::{Context, Result, bail};
use clap::Args;
use shapecue::gpu::Gpu;
use shapecue::mesh::order::MeshOrder;
use shapecue::mesh::{Generated, LoadOptions};
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureOptions, Precision};
use shapecue::stages::curvature::{CurvatureEstimator, OrderPlan, OrderedEstimator};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// The arguments of `shapecue curvature`.
#[derive(Args)]
pub struct CurvatureArgs {
    /// Input mesh (.obj, .ply, .off).
    #[arg(required_unless_present = "generate")]
    input: Option<PathBuf>,
    /// Use a generated mesh instead of a file.
    #[arg(long, value_enum, conflicts_with = "input")]
    generate: Option<Generated>,
    /// Approximate vertex count of a generated mesh.
    #[arg(long, default_value_t = 40_000)]
    resolution: usize,
    /// Output PLY (binary little-endian). Never the input file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Merge vertices with bit-identical positions before computing.
    #[arg(long)]
    weld: bool,
    /// One-ring accumulation: float atomics per face (Griffin et al.; as
    /// compare-and-swap loops, or atomic-native: the device's own float
    /// atomic add, cl_ext_float_atomics), or per-vertex gather (bitwise
    /// reproducible). Default: gather on CPU devices, atomic on GPUs (the
    /// faster exact scheme of each).
    #[arg(long, value_enum)]
    accumulate: Option<Accumulate>,
    /// Faces per work-item of the per-face kernels (and vertices per
    /// work-item of the frame and principal passes), computed as SIMD
    /// lanes: 1, 2, 4, 8 or 16. Default: the device's native vector width on
    /// CPU devices, 1 on GPUs. The gather scheme gives the same bits for
    /// every count, the atomic schemes the same values up to the rounding
    /// of their sums; more than one lane adds 64 bytes of device memory per
    /// vertex (f32).
    #[arg(long, value_parser = ["1", "2", "4", "8", "16"])]
    lanes: Option<String>,
    /// Order of the vertices and faces in device memory: auto renumbers
    /// them along a Morton curve when the input's order is scattered (as in
    /// scanned meshes), for cache locality; spatial always does, input never.
    /// Results are written in the input's order and differ only by the
    /// rounding of sums taken in another order.
    #[arg(long, value_enum, default_value = "auto")]
    order: MeshOrder,
    /// Device precision.
    #[arg(long, value_enum, default_value = "f32")]
    precision: Precision,
    /// Exact least squares, or trimesh2 2.16 compatibility (its pivot quirk, |k1| ≥ |k2|).
    #[arg(long, value_enum, default_value = "exact")]
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

/// The device opened and the curvature program built for the options, with
/// the variant chosen for the device.
struct Prepared {
    gpu: Arc<Gpu>,
    accumulate: Accumulate,
    device_ms: f64,
    prepare_ms: f64,
}

/// Opens the device and gets the curvature program for `opts` built (or
/// loaded from a cache), the accumulation variant being `accumulate` or the
/// device type's default. A program the device refuses is not an error
/// here: building the estimator reports it, with its context.
fn prepare_device(
    device: Option<&str>,
    mut opts: CurvatureOptions,
    accumulate: Option<Accumulate>,
) -> Result<Prepared> {
    let t = Instant::now();
    let gpu = Arc::new(Gpu::new(device)?);
    let device_ms = ms_since(t);
    opts.accumulate = accumulate.unwrap_or_else(|| Accumulate::default_for(&gpu.info.kind));
    let t = Instant::now();
    let _ = CurvatureEstimator::prepare(&gpu, &opts);
    Ok(Prepared {
        gpu,
        accumulate: opts.accumulate,
        device_ms,
        prepare_ms: ms_since(t),
    })
}

/// Runs `shapecue curvature`.
pub fn run(device: Option<&str>, a: CurvatureArgs) -> Result<()> {
    let mut opts = CurvatureOptions {
        accumulate: a.accumulate.unwrap_or(Accumulate::Gather),
        precision: a.precision,
        compat: a.compat,
        dcurv: !a.no_dcurv,
        lanes: a.lanes.as_deref().map_or(Ok(0), str::parse)?,
    };
    let t_start = Instant::now();
    if let Some(n) = a.runs {
        shapecue::spec::limits::check_count("--runs", n, 10_000)?;
    }
    // Before the load: a refused output should not wait for a large mesh.
    check_outputs(
        a.input.as_deref(),
        a.output.iter().chain(a.stats.iter()).map(PathBuf::as_path),
        a.force,
    )?;
    // Opening the device and building the curvature program need no mesh:
    // they run on a thread of their own beside the load (both are a single
    // core's work; on a CPU device the other core is otherwise idle).
    // The memory order is chosen and applied here too (host work that needs
    // no device), unless the CPU reference computes.
    let load = || -> Result<(String, shapecue::Mesh, f64, Option<OrderPlan>)> {
        let t_load = Instant::now();
        let (name, mesh) = match (&a.input, a.generate) {
            (_, Some(kind)) => {
                shapecue::spec::limits::check_mesh_vertices("--resolution", a.resolution)?;
                kind.mesh(a.resolution)
            }
            (Some(path), None) => {
                let m = shapecue::mesh::load(path, &LoadOptions { weld: a.weld })?;
                (path.display().to_string(), m)
            }
            (None, None) => bail!("give an input mesh or --generate"),
        };
        let load_ms = t_load.elapsed().as_secs_f64() * 1e3;
        let plan = (!a.cpu).then(|| OrderPlan::new(&mesh, a.order));
        Ok((name, mesh, load_ms, plan))
    };
    let (loaded, prepared) = std::thread::scope(|s| {
        let prepare = (!a.cpu).then(|| s.spawn(|| prepare_device(device, opts, a.accumulate)));
        let loaded = load();
        let t_wait = Instant::now();
        let prepared = prepare.map(|h| match h.join() {
            Ok(p) => p.map(|p| (p, ms_since(t_wait))),
            Err(panic) => std::panic::resume_unwind(panic),
        });
        (loaded, prepared)
    });
    let (name, mesh, load_ms, plan) = loaded?;
    let prepared = prepared.transpose()?;
    if a.output.is_none() && a.stats.is_none() {
        eprintln!("note: no --output or --stats given; computing and printing a summary only");
    }

    let t_all = Instant::now();
    let mut phases = serde_json::Map::new();
    let mut phase = |name: &str, ms: f64| {
        phases.insert(name.to_string(), serde_json::json!(ms));
    };
    phase("load", load_ms);
    // The results: the CPU twin's field, or the device's buffers, read in
    // place below (no copy of the field: on a 2M-vertex mesh a copy is
    // 256 MB of fresh pages, whose first touch costs more than the rest).
    let (field, estimator, counts, mut stats) = if a.cpu {
        // The reference computes in f64, so it judges faces by f64 rounding.
        let opts = CurvatureOptions {
            precision: shapecue::spec::curvature::Precision::F64,
            ..opts
        };
        let c = shapecue::cpu::curvature::curvature(&mesh, opts)?;
        let mut stats = serde_json::json!({
            "device": "cpu reference (f64, single thread)",
            "wall_ms": c.timing.wall_ms,
        });
        if let Some(n) = a.runs {
            let mut walls = Vec::with_capacity(n);
            for _ in 0..n {
                walls.push(
                    shapecue::cpu::curvature::curvature(&mesh, opts)?
                        .timing
                        .wall_ms,
                );
            }
            stats["runs"] = serde_json::json!(n);
            stats["wall_median_ms"] =
                serde_json::json!(shapecue::report::metrics::median(&mut walls));
        }
        phase("first_run", c.timing.wall_ms);
        (Some(c.field), None, c.counts, stats)
    } else {
        let (p, wait_ms) = prepared.expect("prepared when not on the CPU reference");
        phase("device", p.device_ms);
        phase("program_prepare", p.prepare_ms);
        let prepare_ms = p.prepare_ms;
        phase("device_wait", wait_ms);
        let gpu = p.gpu;
        opts.accumulate = p.accumulate;
        let setup = || format!("setting up curvature for {name}");
        let plan = plan.expect("an order plan when not on the CPU reference");
        let mut o =
            OrderedEstimator::with_plan(gpu.clone(), &mesh, opts, plan).with_context(setup)?;
        phase("reorder", o.reorder_ms);
        phase("program_build", o.est.build_ms());
        phase("topology", o.est.topology_ms() - o.est.build_ms());
        phase("normalise", o.est.upload_ms().normalise);
        phase("upload", o.est.upload_ms().write);
        let timing = o.est.run().with_context(setup)?;
        phase("first_run", timing.wall_ms);
        let counts = o.est.counts()?;
        let device_bytes = o.est.device_bytes();
        let mut stats = serde_json::json!({
            "device": gpu.info,
            "accumulate": opts.accumulate.name(),
            "face_lanes": o.est.face_lanes(),
            "order": if o.order.is_some() { "spatial" } else { "input" },
            "topology_ms": o.est.topology_ms(),
            "passes": passes(&timing),
            "kernel_ms": timing.kernel_ms,
            "run_wall_ms": timing.wall_ms,
            "device_bytes": device_bytes,
            "device_bytes_per_vertex": device_bytes as f64 / mesh.n_vertices() as f64,
        });
        if let Some(n) = a.runs {
            // Each run writes the same values (the passes are deterministic
            // for gather; atomic sums may differ in the last bits), so the
            // field read below is the last run's.
            let mut timed = Vec::with_capacity(n);
            for _ in 0..n {
                timed.push(o.est.run()?);
            }
            shapecue::report::metrics::runs_stats(&mut stats, &timed, timing.wall_ms);
        }
        // After the runs, so that code the driver compiled at the first
        // launch is in the saved binaries; a no-op when the cache hit.
        let t = Instant::now();
        gpu.persist_programs();
        phase("cache_write", ms_since(t));
        // PoCL compiles at the first build and launch when its own cache is
        // empty (seconds), and shapecue saves nothing there on its own.
        let compile_ms = prepare_ms + timing.wall_ms;
        if compile_ms > 1000.0
            && gpu
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
        stats["programs"] = serde_json::to_value(gpu.program_builds())?;
        (None, Some(o), counts, stats)
    };
    let t = Instant::now();
    let mapped = estimator
        .as_ref()
        .map(OrderedEstimator::mapped)
        .transpose()?;
    if mapped.is_some() {
        phases.insert("read_back".into(), serde_json::json!(ms_since(t)));
    }
    let vertex = |i: usize| match (&field, &mapped) {
        (Some(f), _) => f.vertex(i),
        (None, Some(m)) => m.vertex(i),
        (None, None) => unreachable!("a field or a device"),
    };
    let n = mesh.n_vertices();
    let mut finite = true;
    let (mut k1min, mut k1max, mut k2min, mut k2max) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for v in (0..n).map(vertex) {
        finite &= v.all_finite();
        (k1min, k1max) = (k1min.min(v.k1), k1max.max(v.k1));
        (k2min, k2max) = (k2min.min(v.k2), k2max.max(v.k2));
    }
    if !finite {
        bail!("internal error: non-finite output (please report with the input mesh)");
    }
    let total_ms = t_all.elapsed().as_secs_f64() * 1e3;
    out!(
        "{name}: {} vertices, {} faces; k1 in [{k1min:.4}, {k1max:.4}], k2 in [{k2min:.4}, {k2max:.4}]; \
         {} degenerate faces skipped, {} vertices without curvature; {total_ms:.1} ms",
        mesh.n_vertices(),
        mesh.n_faces(),
        counts.degenerate_faces,
        counts.vertices_without_curvature
    );
    let mostly_degenerate = counts.mostly_degenerate(mesh.n_faces());
    if mostly_degenerate {
        eprintln!(
            "warning: {name}: {} of {} faces were skipped as degenerate, so most curvature \
                 values are zero. Faces are judged against the rounding of the precision computed \
                 in: for a mesh far from the origin or finely detailed, try --precision f64",
            counts.degenerate_faces,
            mesh.n_faces()
        );
    }
    if let Some(out) = &a.output {
        let t = Instant::now();
        let written = shapecue::export::ply::write_ply_vertices(out, &mesh, n, vertex)?;
        phases.insert("ply_write".into(), serde_json::json!(ms_since(t)));
        super::note_double(out, &written);
        out!("wrote {}", out.display());
    }
    if let Some(path) = &a.stats {
        stats["input"] = serde_json::json!(name);
        stats["vertices"] = serde_json::json!(mesh.n_vertices());
        stats["faces"] = serde_json::json!(mesh.n_faces());
        stats["options"] = serde_json::to_value(opts)?;
        stats["counts"] = serde_json::to_value(counts)?;
        stats["mostly_degenerate"] = serde_json::json!(mostly_degenerate);
        stats["load_ms"] = serde_json::json!(load_ms);
        stats["total_wall_ms"] = serde_json::json!(total_ms);
        stats["phases_ms"] = serde_json::Value::Object(phases);
        // From the start of the command (after argument parsing) to here:
        // everything but the process start and this file.
        stats["command_ms"] = serde_json::json!(ms_since(t_start));
        write_json(path, &stats)?;
    }
    // The process ends with this command, and everything is written: the
    // OS takes back the device buffers, the context and the mesh at once,
    // about 5 ms sooner on the bunny than releasing them one by one.
    std::mem::forget(mapped);
    std::mem::forget(estimator);
    std::mem::forget(mesh);
    Ok(())
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
