//! `shapecue render`: scene files through the planner and the executor
//! ([`shapecue::scene::exec`]), with a progress bar on a terminal and each
//! scene's report printed; `--explain` prints the plans (`shapecue report
//! pipeline` prints the per-frame device pipeline table).

use super::out;
use anyhow::Result;
use clap::Args;
use shapecue::api::{self as exec, ExecOptions, RunReport, Scene};
use shapecue::report::metrics::median;
use shapecue::spec::coherence::Coherence;
use std::path::PathBuf;

/// The arguments of `shapecue render`.
#[derive(Args)]
pub struct RenderArgs {
    /// Scene files.
    #[arg(required = true)]
    scenes: Vec<PathBuf>,
    /// Output folder (overrides each scene's `[output] dir`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Overwrite existing images and reports.
    #[arg(long)]
    force: bool,
    /// Print each scene's plan (passes, lifetimes, run counts) and exit
    /// without computing or writing anything.
    #[arg(long)]
    explain: bool,
    /// Hold the lines of an animation from frame to frame (hysteresis,
    /// delayed births, signs held within a band; the first frame is drawn
    /// as without): `off` draws each frame's lines on their own, `on` and
    /// `auto` hold them over more than one frame. Overrides each scene's
    /// `[lines] coherence`.
    #[arg(long, value_name = "MODE", value_parser = super::choice::<Coherence>())]
    coherence: Option<Coherence>,
}

/// Runs `shapecue render`.
pub fn run(device: Option<&str>, a: RenderArgs) -> Result<()> {
    let opts = ExecOptions {
        out_dir: a.out.clone(),
        force: a.force,
        device: device.map(str::to_string),
        ..Default::default()
    };
    // Check every scene before running any, so a typo in the last one does
    // not surface after minutes of rendering.
    let mut scenes: Vec<Scene> = a
        .scenes
        .iter()
        .map(|p| Scene::load(p))
        .collect::<shapecue::Result<_>>()?;
    if let Some(c) = a.coherence {
        for s in &mut scenes {
            s.effects.lines.coherence = c;
        }
    }
    if a.explain {
        for scene in &scenes {
            super::print_str(&exec::explain(scene, &opts)?)?;
        }
        return Ok(());
    }
    // Outputs, frame ranges and flipbook topology of every scene; the
    // animated inputs loaded for it are handed to their runs.
    let checked = exec::check_scenes(&scenes, &opts)?;
    // One device and one GL context for all the scenes.
    let mut session = exec::Session::new();
    for (scene, checked) in scenes.iter().zip(checked) {
        let bar = progress_bar(&scene.name);
        let r = session.run_checked(scene, checked, &opts, &mut |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        })?;
        bar.finish_and_clear();
        print_report(&r)?;
    }
    Ok(())
}

/// A progress bar on stderr, hidden when stderr is not a terminal.
fn progress_bar(name: &str) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    use std::io::IsTerminal;
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if !std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} views {elapsed} ETA {eta}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(name.to_string());
    bar
}

/// A scene's report: counts, one line per pass that ran, medians, notes.
fn print_report(r: &RunReport) -> Result<()> {
    out!(
        "{}: {} frame(s) x {} view(s), {} vertices, {} faces on {}",
        r.scene,
        r.frames.len(),
        r.views,
        r.vertices,
        r.faces,
        r.device
    );
    out!(
        "  {:<20} {:<9} {:>6} {:>10} {:>10}  how",
        "pass",
        "lifetime",
        "runs",
        "total ms",
        "ms/run"
    );
    for p in &r.passes {
        out!(
            "  {:<20} {:<9} {:>6} {:>10.2} {:>10.3}  {} ({})",
            p.pass.name(),
            p.lifetime.name(),
            p.runs,
            p.ms(),
            p.ms() / p.runs.max(1) as f64,
            p.how,
            p.clock
        );
    }
    out!(
        "  per frame: pose passes {:.2} ms (median); per view: lines/edges {:.2} ms, render {:.1} ms; \
         segments: {} contour, {} suggestive; wall {:.0} ms",
        median(&mut r.timing.laps("pose")),
        median(&mut r.timing.laps("view")),
        median(&mut r.timing.laps("render")),
        r.segments[0],
        r.segments[1],
        r.timing.wall_ms
    );
    for n in &r.notes {
        out!("  note: {n}");
    }
    let dir = r
        .outputs
        .first()
        .and_then(|p| p.parent())
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    out!(
        "  wrote {} file(s) to {dir} and the report",
        r.outputs.len()
    );
    Ok(())
}
