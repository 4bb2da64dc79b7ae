//! The scene executor: runs exactly the passes of a [`Plan`] over a scene's
//! frames and views, renders, writes the images, and reports which passes
//! ran, how often and for how long.
//!
//! Lifetimes (see [`crate::scene::planner`]):
//! - *topology* passes run when a topology first appears (once for a static,
//!   skinned or flipbook input; every pose for an isosurface);
//! - *pose* passes run once per frame (once in all for a static mesh);
//! - *view* passes run once per frame and camera.
//!
//! Device residency: a skinned pose stays on the device from `skin_lbs`
//! through the curvature passes, AO and the feature-line kernels; only what
//! the renderer draws is read back (positions, normals, colours, segments).
//! Contours alone need only normals: they are then computed on the host,
//! without building the curvature estimator.
//!
//! Timing: device passes report OpenCL kernel time; host passes (loading a
//! flipbook frame, host normals, building topology, rendering) report wall
//! time. The report says which, per pass.
//!
//! The plan is the program: [`run`] walks the plan's passes in order,
//! filtered by lifetime (topology passes on a new topology, pose passes per
//! pose, view passes per camera), one arm per pass
//! ([`passes`](self) has them). Split by concern: loading inputs (`load`),
//! per-pass execution (`passes`), drawing and outputs (`draw`), the report
//! (`report`).

mod draw;
mod load;
mod passes;
mod report;

pub use load::{frame_indices, output_paths};
pub use report::{PassRecord, RunReport};

use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::render::{RenderOptions, Renderer};
use crate::scene::file::Scene;
use crate::scene::planner::{Input, Lifetime, Pass, plan_with};
use load::load;
use passes::Executor;
use report::ms_since;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// Command-line overrides of a scene.
#[derive(Clone, Debug, Default)]
pub struct ExecOptions {
    /// Output folder instead of the scene's.
    pub out_dir: Option<PathBuf>,
    /// Overwrite existing outputs.
    pub force: bool,
    /// OpenCL device selector.
    pub device: Option<String>,
}

/// Runs a scene: loads the input, plans, refuses to overwrite outputs
/// (unless `force`), then walks the plan frame by frame and view by view,
/// calling `progress(done, total)` after each view. Returns the report,
/// which is also written next to the images.
pub fn run(
    scene: &Scene,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport> {
    run_with(None, scene, opts, progress)
}

/// [`run`] on a device the caller holds (`opts.device` is ignored).
pub fn run_on(
    gpu: &Arc<Gpu>,
    scene: &Scene,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport> {
    run_with(Some(gpu), scene, opts, progress)
}

fn run_with(
    gpu: Option<&Arc<Gpu>>,
    scene: &Scene,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport> {
    let t_all = Instant::now();
    let mut notes = Vec::new();
    let loaded = load(scene, &mut notes)?;
    let frames = frame_indices(scene, loaded.frames())?;
    let out_dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| scene.out_dir.clone());
    let (images, report_path) = output_paths(scene, &frames, &out_dir);
    // What this run creates (folders, and files that did not exist), to
    // remove again if it fails: a failed run leaves what it found.
    let new_dirs: Vec<PathBuf> = out_dir
        .ancestors()
        .filter(|d| !d.as_os_str().is_empty() && !d.exists())
        .map(PathBuf::from)
        .collect();
    let new_files: Vec<PathBuf> = images
        .iter()
        .map(|i| &i.2)
        .chain([&report_path])
        .filter(|p| !p.exists())
        .cloned()
        .collect();
    let result = refuse_overwrite(scene, &images, &report_path, opts.force)
        .and_then(|()| {
            std::fs::create_dir_all(&out_dir).map_err(|source| Error::Write {
                path: out_dir.clone(),
                source,
            })
        })
        .and_then(|()| {
            render_all(
                gpu,
                scene,
                opts,
                progress,
                loaded,
                frames,
                &images,
                &report_path,
                notes,
                t_all,
            )
        });
    if result.is_err() {
        for f in &new_files {
            let _ = std::fs::remove_file(f);
        }
        // Deepest first; only folders left empty go.
        for d in &new_dirs {
            let _ = std::fs::remove_dir(d);
        }
    }
    result
}

/// The frame loop of [`run_with`] after the outputs are checked and the
/// folder exists (`t_all`: when the run started; `notes`: what loading the
/// input said); writes the report last.
#[allow(clippy::too_many_arguments)]
fn render_all(
    gpu: Option<&Arc<Gpu>>,
    scene: &Scene,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
    loaded: load::Loaded,
    frames: Vec<usize>,
    images: &[(usize, usize, PathBuf)],
    report_path: &std::path::Path,
    notes: Vec<String>,
    t_all: Instant,
) -> Result<RunReport> {
    let fx = &scene.effects;
    let input = scene.source.input();
    let plan = plan_with(&fx.cues, input, fx.caps);
    let gpu = match gpu {
        Some(g) => g.clone(),
        None => Arc::new(Gpu::new(opts.device.as_deref())?),
    };
    let [w, h] = scene.size;
    let [br, bg, bb] = scene.background;
    let renderer = Renderer::new(RenderOptions {
        width: w,
        height: h,
        msaa: scene.msaa,
        background: [br, bg, bb, 1.0],
    })?;
    let mut ex = Executor::new(scene, &plan, loaded, &gpu, renderer)?;

    // The plan's passes by lifetime, each list in plan order.
    let of = |keep: &dyn Fn(Lifetime) -> bool| -> Vec<Pass> {
        plan.passes
            .iter()
            .copied()
            .filter(|p| keep(p.lifetime(input)))
            .collect()
    };
    let first_pose = of(&|l| l != Lifetime::View);
    let later_poses = of(&|l| l == Lifetime::Pose);
    let view_passes = of(&|l| l == Lifetime::View);

    let (mut pose_ms, mut view_ms, mut render_ms) = (Vec::new(), Vec::new(), Vec::new());
    let total_views = frames.len() * scene.views.len();
    let mut done = 0;
    for (fi, &frame) in frames.iter().enumerate() {
        // Pose passes: once in all for a static mesh; topology passes with
        // the first pose (an isosurface's are pose passes).
        if fi == 0 || input != Input::Static {
            ex.begin_pose();
            for &p in if fi == 0 { &first_pose } else { &later_poses } {
                ex.pose_pass(p, frame)?;
            }
            ex.end_pose(frame)?;
            pose_ms.push(ex.rec.lap());
        }
        for (vi, cam) in ex.cameras().iter().enumerate() {
            let paths: Vec<&PathBuf> = images
                .iter()
                .filter(|i| i.0 == frame && i.1 == vi)
                .map(|i| &i.2)
                .collect();
            ex.begin_view();
            for &p in &view_passes {
                if p == Pass::Render {
                    view_ms.push(ex.rec.lap());
                }
                ex.view_pass(p, cam, &paths)?;
            }
            render_ms.push(ex.rec.lap());
            done += 1;
            progress(done, total_views);
        }
    }

    let (vertices, faces) = ex.counts();
    let report = RunReport {
        scene: scene.path.display().to_string(),
        device: gpu.info.name.clone(),
        renderer: ex.gl_info(),
        plan: plan.clone(),
        frames,
        views: scene.views.len(),
        vertices,
        faces,
        passes: ex.rec.in_plan_order(&plan),
        pose_ms_median: crate::metrics::median(&mut pose_ms),
        view_ms_median: crate::metrics::median(&mut view_ms),
        render_ms_median: crate::metrics::median(&mut render_ms),
        segments: ex.segments,
        strokes: ex.stroke_count,
        notes,
        outputs: std::mem::take(&mut ex.outputs),
        wall_ms: ms_since(t_all),
    };
    let json = serde_json::to_string_pretty(&report).expect("the report serializes") + "\n";
    crate::export::output::write_bytes_atomic(report_path, json.as_bytes())?;
    Ok(report)
}

/// Checks, before any scene of a run starts, what can be checked without
/// loading inputs: no two scenes write the same report and images (same
/// output folder and name), and without `force` no scene's report exists
/// already. A collision used to surface only after the first scene had
/// rendered.
pub fn check_scenes(scenes: &[Scene], opts: &ExecOptions) -> Result<()> {
    use crate::export::output::location;
    let reports: Vec<(PathBuf, &Scene)> = scenes
        .iter()
        .map(|s| {
            let dir = opts.out_dir.clone().unwrap_or_else(|| s.out_dir.clone());
            (dir.join(format!("{}_report.json", s.prefix)), s)
        })
        .collect();
    for (i, (a, sa)) in reports.iter().enumerate() {
        for (b, sb) in &reports[..i] {
            if location(a) == location(b) {
                return Err(Error::InvalidArgument(format!(
                    "{} and {} would both write {} and the same image names: give one of them \
                     its own [output] name or dir",
                    sb.path.display(),
                    sa.path.display(),
                    a.display()
                )));
            }
        }
        if !opts.force && a.exists() {
            return Err(Error::InvalidArgument(format!(
                "{}: {} exists (from an earlier run); use --force to overwrite it",
                sa.path.display(),
                a.display()
            )));
        }
    }
    Ok(())
}

/// Refuses outputs that exist (without `force`), that are the scene file,
/// or that name one file twice ([`crate::export::output::check_outputs`]).
fn refuse_overwrite(
    scene: &Scene,
    images: &[(usize, usize, PathBuf)],
    report: &std::path::Path,
    force: bool,
) -> Result<()> {
    let outputs: Vec<&std::path::Path> = images
        .iter()
        .map(|i| i.2.as_path())
        .chain([report])
        .collect();
    crate::export::output::check_outputs(&[scene.path.as_path()], &outputs, force)
}

/// The plan of a scene and the frames it would render, as `--explain` prints
/// it: loads the input (to count its frames) but touches no device and
/// writes nothing.
pub fn explain(scene: &Scene, opts: &ExecOptions) -> Result<String> {
    let mut notes = Vec::new();
    let loaded = load(scene, &mut notes)?;
    let frames = frame_indices(scene, loaded.frames())?;
    let fx = &scene.effects;
    let plan = plan_with(&fx.cues, scene.source.input(), fx.caps);
    let out_dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| scene.out_dir.clone());
    let (images, report) = output_paths(scene, &frames, &out_dir);
    let shown: Vec<String> = frames.iter().take(8).map(|f| f.to_string()).collect();
    let mut s = format!(
        "{}: frames {}{}\n",
        scene.path.display(),
        shown.join(", "),
        if frames.len() > 8 { ", ..." } else { "" }
    );
    for n in &notes {
        s.push_str(&format!("  note: {n}\n"));
    }
    s.push_str(&plan.explain(frames.len(), scene.views.len()));
    s.push_str(&format!(
        "  writes {} image(s) and {}\n",
        images.len(),
        report.display()
    ));
    Ok(s)
}
