//! `shapecue build-kernels`: builds the curvature kernels for the device
//! once, runs each pass once on a small icosphere (so that what the runtime
//! compiles at a kernel's first launch is built too) and saves the programs
//! into shapecue's kernel cache, on every runtime (PoCL included, where an
//! ordinary command does not save: see `shapecue::gpu::cache`). Later
//! `shapecue curvature` processes then load the built kernels instead of
//! compiling them.

use super::out;
use anyhow::{Context, Result};
use clap::Args;
use shapecue::gpu::Gpu;
use shapecue::spec::curvature::{Accumulate, Compat, CurvatureOptions, Precision};
use shapecue::stages::curvature::CurvatureEstimator;
use std::sync::Arc;
use std::time::Instant;

/// The arguments of `shapecue build-kernels`.
#[derive(Args)]
pub struct KernelsArgs {
    /// One-ring accumulation variants to build (comma-separated), as in
    /// `shapecue curvature --accumulate`. Default: the device type's default
    /// (gather on CPU devices, atomic on GPUs).
    #[arg(long, value_enum, value_delimiter = ',')]
    accumulate: Vec<Accumulate>,
    /// Faces per work-item of the gather variant, as in `shapecue curvature
    /// --lanes`. Default: the device's native vector width on CPU devices.
    #[arg(long, value_parser = ["1", "2", "4", "8", "16"])]
    lanes: Option<String>,
    /// Device precisions to build (comma-separated).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "f32")]
    precision: Vec<Precision>,
    /// Least-squares variants to build (comma-separated).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "exact")]
    compat: Vec<Compat>,
}

/// Runs `shapecue build-kernels`.
pub fn run(device: Option<&str>, a: KernelsArgs) -> Result<()> {
    let gpu = Arc::new(Gpu::new(device)?);
    let Some(dir) = gpu.cache_folder().map(std::path::Path::to_path_buf) else {
        anyhow::bail!(
            "the kernel cache is off (SHAPECUE_NO_CACHE is set, or neither \
             SHAPECUE_CACHE_DIR, XDG_CACHE_HOME nor HOME is), so there is \
             nowhere to keep built kernels"
        );
    };
    gpu.save_every_build();
    let lanes = a.lanes.as_deref().map_or(Ok(0), str::parse)?;
    let accumulate = if a.accumulate.is_empty() {
        vec![Accumulate::default_for(&gpu.info.kind)]
    } else {
        a.accumulate.clone()
    };
    out!(
        "building curvature kernels for {} ({}) into {}",
        gpu.info.name,
        gpu.info.platform,
        dir.display()
    );
    let mut variants = Vec::new();
    for &acc in &accumulate {
        for &precision in &a.precision {
            for &compat in &a.compat {
                let v = CurvatureOptions {
                    accumulate: acc,
                    precision,
                    compat,
                    dcurv: true,
                    lanes,
                };
                if !variants.contains(&v) {
                    variants.push(v);
                }
            }
        }
    }
    for opts in &variants {
        let what = format!(
            "{} {} {}",
            opts.accumulate.name(),
            opts.precision.name(),
            opts.compat.name()
        );
        let t = Instant::now();
        CurvatureEstimator::warm_up(&gpu, opts)
            .with_context(|| format!("building the curvature kernels ({what})"))?;
        let build_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        gpu.persist_programs();
        let save_s = t.elapsed().as_secs_f64();
        let Some(b) = gpu.program_builds().pop() else {
            continue;
        };
        let how = match (b.cache.as_str(), b.saved) {
            ("hit", _) => "already built (loaded from the cache)".to_string(),
            (_, true) => format!("built in {build_s:.1} s, saved in {save_s:.1} s"),
            (_, false) => format!(
                "built in {build_s:.1} s, but not saved: the driver gave no binary \
                 or {} could not be written",
                dir.display()
            ),
        };
        let options = if b.options.is_empty() {
            String::new()
        } else {
            format!(" ({})", b.options)
        };
        out!("  {what}{options}: {how}");
    }
    Ok(())
}
