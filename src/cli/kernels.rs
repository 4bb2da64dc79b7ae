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
use shapecue::api::Gpu;
use shapecue::api::build_kernels;
use shapecue::spec::curvature::{
    Accumulate, AccumulateChoice, Compat, CurvatureOptions, Lanes, Precision,
};
use std::sync::Arc;

/// The arguments of `shapecue build-kernels`.
#[derive(Args)]
pub struct KernelsArgs {
    /// One-ring accumulation variants to build (comma-separated), as in
    /// `shapecue curvature --accumulate`. Default: the device type's default
    /// (gather, the faster exact scheme on CPU devices and GPUs).
    #[arg(long, value_parser = super::choice::<AccumulateChoice>(), value_delimiter = ',', default_value = "auto")]
    accumulate: Vec<AccumulateChoice>,
    /// SIMD lanes of the gather variant, as in `shapecue curvature
    /// --lanes`. Default: the device's native vector width on CPU devices.
    #[arg(long, value_parser = super::choice::<Lanes>(), default_value = "auto")]
    lanes: Lanes,
    /// Device precisions to build (comma-separated).
    #[arg(long, value_parser = super::choice::<Precision>(), value_delimiter = ',', default_value = "f32")]
    precision: Vec<Precision>,
    /// Least-squares variants to build (comma-separated).
    #[arg(long, value_parser = super::choice::<Compat>(), value_delimiter = ',', default_value = "exact")]
    compat: Vec<Compat>,
}

/// Runs `shapecue build-kernels`.
pub fn run(device: Option<&str>, a: KernelsArgs) -> Result<()> {
    let gpu = Arc::new(Gpu::new(device)?);
    let lanes = a.lanes;
    let accumulate: Vec<Accumulate> = a.accumulate.iter().map(|c| c.resolve()).collect();
    let variants = CurvatureOptions::combinations(&accumulate, &a.precision, &a.compat, lanes);
    if let Some(dir) = gpu.cache_folder() {
        out!(
            "building curvature kernels for {} ({}) into {}",
            gpu.info.name,
            gpu.info.platform,
            dir.display()
        );
    }
    let report = |b: &shapecue::api::KernelBuild| -> std::io::Result<()> {
        let how = match (b.program.cache.as_str(), b.program.saved) {
            ("hit", _) => "already built (loaded from the cache)".to_string(),
            (_, true) => format!("built in {:.1} s, saved in {:.1} s", b.build_s, b.save_s),
            (_, false) => format!(
                "built in {:.1} s, but not saved: the driver gave no binary or the \
                 cache folder could not be written",
                b.build_s
            ),
        };
        let options = if b.program.options.is_empty() {
            String::new()
        } else {
            format!(" ({})", b.program.options)
        };
        super::print(format_args!("  {}{options}: {how}", b.variant))
    };
    // Each line as its program is done; a closed standard output stops the
    // lines, not the builds, and is reported at the end.
    let mut printed = Ok(());
    build_kernels(&gpu, &variants, |b| {
        if printed.is_ok() {
            printed = report(b);
        }
    })
    .context("building the curvature kernels")?;
    printed?;
    Ok(())
}
