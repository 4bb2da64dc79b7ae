//! `shapecue curvature`: per-vertex curvature of a mesh file or a generated
//! mesh ([`shapecue::curvature`] or its CPU twin), written as PLY with JSON
//! stats; `--report` prints the accuracy/time table.

use super::{check_outputs, out, write_json};
use anyhow::{Context, Result, bail};
use clap::Args;
use shapecue::gpu::Gpu;
use shapecue::mesh::{Generated, LoadOptions};
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureOptions, Precision};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// The arguments of `shapecue curvature`.
#[derive(Args)]
pub struct CurvatureArgs {
    /// Input mesh (.obj, .ply, .off).
    #[arg(required_unless_present_any = ["generate", "report"])]
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
    /// One-ring accumulation: float atomics per face, or per-vertex gather (deterministic).
    #[arg(long, value_enum, default_value = "atomic")]
    accumulate: Accumulate,
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
    /// Print the accuracy/time table of every variant instead (no input needed).
    #[arg(long)]
    report: bool,
    /// Runs per variant for the report's median times.
    #[arg(long, default_value_t = 7)]
    runs: usize,
}

/// Runs `shapecue curvature`.
pub fn run(device: Option<&str>, a: CurvatureArgs) -> Result<()> {
    let opts = CurvatureOptions {
        accumulate: a.accumulate,
        precision: a.precision,
        compat: a.compat,
        dcurv: !a.no_dcurv,
    };
    shapecue::spec::limits::check_count("--runs", a.runs, 10_000)?;
    super::report_alone(a.report, a.input.as_deref(), a.output.as_deref())?;
    if a.report {
        let gpu = Arc::new(Gpu::new(device)?);
        let text = super::tables::curvature_report(gpu, a.resolution, a.runs)?;
        super::print_str(&text)?;
        return Ok(());
    }
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
        (None, None) => bail!("give an input mesh, --generate or --report"),
    };
    let load_ms = t_load.elapsed().as_secs_f64() * 1e3;
    check_outputs(
        a.input.as_deref(),
        a.output.iter().chain(a.stats.iter()).map(PathBuf::as_path),
        a.force,
    )?;
    if a.output.is_none() && a.stats.is_none() {
        eprintln!("note: no --output or --stats given; computing and printing a summary only");
    }

    let t_all = Instant::now();
    let (c, mut stats) = if a.cpu {
        // The reference computes in f64, so it judges faces by f64 rounding.
        let opts = CurvatureOptions {
            precision: shapecue::spec::curvature::Precision::F64,
            ..opts
        };
        let c = shapecue::cpu::curvature::curvature(&mesh, opts)?;
        let stats = serde_json::json!({
            "device": "cpu reference (f64, single thread)",
            "wall_ms": c.timing.wall_ms,
        });
        (c, stats)
    } else {
        let gpu = Arc::new(Gpu::new(device)?);
        let c = shapecue::curvature_on(&gpu, &mesh, opts)
            .with_context(|| format!("setting up curvature for {name}"))?;
        let stats = serde_json::json!({
            "device": gpu.info,
            "topology_ms": c.topology_ms,
            "passes": passes(&c.timing),
            "kernel_ms": c.timing.kernel_ms,
            "run_wall_ms": c.timing.wall_ms,
            "device_bytes": c.device_bytes,
            "device_bytes_per_vertex": c.device_bytes as f64 / mesh.n_vertices() as f64,
        });
        (c, stats)
    };
    let total_ms = t_all.elapsed().as_secs_f64() * 1e3;
    let (field, counts) = (&c.field, c.counts);
    if !field.all_finite() {
        bail!("internal error: non-finite output (please report with the input mesh)");
    }
    let (k1min, k1max) = minmax(&field.k1);
    let (k2min, k2max) = minmax(&field.k2);
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
            "warning: {name}: {} of {} faces were skipped as degenerate, so most curvature              values are zero. Faces are judged against the rounding of the precision computed              in: for a mesh far from the origin or finely detailed, try --precision f64",
            counts.degenerate_faces,
            mesh.n_faces()
        );
    }
    if let Some(out) = &a.output {
        let written = shapecue::export::ply::write_ply(out, &mesh, Some(field))?;
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
        write_json(path, &stats)?;
    }
    Ok(())
}

fn minmax(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
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
