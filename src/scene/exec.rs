//! The scene executor: runs exactly the passes of a
//! [`Plan`](crate::scene::planner::Plan) over a scene's frames and views,
//! renders, writes the images, and reports which passes ran, how often and
//! for how long.
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
//! A run of several scenes checks them all first ([`check_scenes`]: output
//! collisions, frame ranges, a flipbook's topology), loading the animated
//! inputs once for [`run_checked`]: a bad last scene fails the run before
//! the first writes anything.
//!
//! One process, one device and one GL context: a [`Session`] holds both
//! across the scenes it runs. Within a scene the mesh goes to GL once per
//! topology and once per pose, not once per view.
//!
//! A front end that draws one camera and frame at a time holds a scene
//! live ([`Session::live`], in `live`): a camera move reruns only the view
//! passes, a new frame only the pose passes and the view passes.
//!
//! The plan is the program: [`run`] walks the plan's passes in order,
//! filtered by lifetime, one arm per pass ([`passes`](self) has them).
//! Split by concern: loading inputs (`load`), per-pass execution
//! (`passes`), drawing and outputs (`draw`), the report (`report`).

mod draw;
pub mod interop;
mod live;
mod load;
mod passes;
mod report;
mod vector;
mod walk;

pub use draw::{EdgeCounts, EdgeInfo, PosedPieces, ViewDone, ViewOutputs};
pub use live::{LiveFrame, LiveRequest};
pub use load::{frame_indices, output_paths};
pub use report::{PassRecord, RunReport};
pub use vector::{LAYER_FEATURE_EDGES, LAYER_INTERSECTIONS, LAYER_STROKES, VisibleLines};
pub use walk::Change;

use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::render::{RenderOptions, Renderer};
use crate::scene::file::{Scene, Source};
use crate::scene::planner::{Outputs, Pass, Plan, plan_for};
use load::load;
use passes::Executor;
use report::ms_since;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use walk::Walker;

/// Command-line overrides of a scene.
#[derive(Clone, Debug, Default)]
pub struct ExecOptions {
    /// Output folder instead of the scene's.
    pub out_dir: Option<PathBuf>,
    /// Overwrite existing outputs.
    pub force: bool,
    /// OpenCL device selector.
    pub device: Option<String>,
    /// Only these views (indices into the scene's views; `None`: all). The
    /// files of a view keep its number, so that a run continued after an
    /// interruption writes the views it lacks under their own names.
    pub views: Option<Vec<usize>>,
    /// On failure, keep the views finished before it (their files are
    /// whole), so that the caller can continue the run; by default a
    /// failed run removes what it created.
    pub keep_done: bool,
}

/// Whether view `v` runs, of the `views` asked for (`None`: all).
fn runs_view(views: Option<&[usize]>, v: usize) -> bool {
    views.is_none_or(|set| set.contains(&v))
}

/// What the scene runs of one process share: the OpenCL device (its
/// programs built once) and one renderer (one GL context with its
/// programs), made by the first scene that needs them and reconfigured for
/// each scene's image size and antialiasing (its framebuffers made anew
/// when the size differs).
/// A renderer is tied to its thread: so is a `Session`.
#[derive(Default)]
pub struct Session {
    gpu: Option<Arc<Gpu>>,
    renderer: Option<Renderer>,
}

impl Session {
    /// A session that opens the device of the first scene's options.
    pub fn new() -> Session {
        Session::default()
    }

    /// A session on a device the caller holds (`ExecOptions::device` is
    /// then ignored).
    pub fn on(gpu: Arc<Gpu>) -> Session {
        Session {
            gpu: Some(gpu),
            renderer: None,
        }
    }

    /// [`run`] in this session.
    pub fn run(
        &mut self,
        scene: &Scene,
        opts: &ExecOptions,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<RunReport> {
        run_loaded(self, scene, None, opts, progress, None)
    }

    /// [`run`] in this session, handing each view's lines to `each` as soon
    /// as the view is done ([`ViewDone`]: the camera as resolved, the
    /// segments and, with exact visibility, their visible pieces and
    /// chains, all in world coordinates), so that a caller writes per-view
    /// outputs of its own without holding every view. An error from `each`
    /// stops the run, which then removes what it created, as any failed
    /// run does (what `each` wrote is the caller's to remove).
    pub fn run_each(
        &mut self,
        scene: &Scene,
        opts: &ExecOptions,
        progress: &mut dyn FnMut(usize, usize),
        each: &mut dyn FnMut(ViewDone) -> Result<()>,
    ) -> Result<RunReport> {
        run_loaded(self, scene, None, opts, progress, Some(each))
    }

    /// A scene run that writes nothing (no image, no SVG, no report): each
    /// view goes to `each` as soon as it is done, with the image where the
    /// scene's `png` asks for one and the SVG groups where its `svg` does
    /// ([`ViewDone::out`]). The same walk as [`Session::run_each`]: the
    /// pose passes once per pose, the view passes once per camera, the
    /// views `opts` names. The report comes back; the output folder and
    /// `force` are not read.
    pub fn run_in_memory(
        &mut self,
        scene: &Scene,
        opts: &ExecOptions,
        each: &mut dyn FnMut(ViewDone) -> Result<()>,
    ) -> Result<RunReport> {
        self.in_memory(scene, opts, (false, false), each)
    }

    /// Draws the first view of the first frame of `scene` into memory (a
    /// picture of the front door): [`Session::run_in_memory`] of that view
    /// and frame, with the surface drawn ([`ViewOutputs::mesh`]).
    pub fn picture(&mut self, scene: &Scene, opts: &ExecOptions) -> Result<ViewDone> {
        let mut one = scene.clone();
        one.views.truncate(1);
        let plan = plan_of(&one, false);
        let nothing = if one.views.is_empty() {
            Some("no camera")
        } else if !plan.contains(Pass::Render) && !plan.contains(Pass::Svg) {
            Some("no cue is asked for, so there is nothing to draw")
        } else {
            None
        };
        if let Some(why) = nothing {
            return Err(Error::InvalidArgument(format!(
                "{}: {why}",
                scene.path.display()
            )));
        }
        let mut done = None;
        self.in_memory(&one, opts, (true, true), &mut |v| {
            done = Some(v);
            Ok(())
        })?;
        Ok(done.expect("a run of one view and one frame hands one view"))
    }

    /// A run in memory ([`Session::run_in_memory`]); `(first, mesh)`: of
    /// the first frame only, and with each view's surface.
    fn in_memory(
        &mut self,
        scene: &Scene,
        opts: &ExecOptions,
        (first, mesh): (bool, bool),
        each: &mut dyn FnMut(ViewDone) -> Result<()>,
    ) -> Result<RunReport> {
        let mut notes = Vec::new();
        let loaded = load(scene, &mut notes)?;
        let mut frames = frame_indices(scene, loaded.frames())?;
        if first {
            frames.truncate(1);
        }
        if frames.is_empty() {
            return Err(Error::InvalidArgument(format!(
                "{}: the frame range is empty",
                scene.path.display()
            )));
        }
        let input = RunInput {
            loaded,
            frames,
            notes,
            t_all: Instant::now(),
        };
        let calls = Calls {
            progress: &mut |_, _| {},
            each: Some(each),
        };
        render_all(self, scene, opts, calls, input, Kept::Memory { mesh })
    }

    /// [`run_checked`] in this session.
    pub fn run_checked(
        &mut self,
        scene: &Scene,
        checked: Checked,
        opts: &ExecOptions,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<RunReport> {
        let pre = checked.input.filter(|_| checked.scene == scene.path);
        run_loaded(self, scene, pre, opts, progress, None)
    }

    /// The session's device, opened on first use.
    fn gpu(&mut self, opts: &ExecOptions) -> Result<Arc<Gpu>> {
        if let Some(g) = &self.gpu {
            return Ok(g.clone());
        }
        let g = Arc::new(Gpu::new(opts.device.as_deref())?);
        self.gpu = Some(g.clone());
        Ok(g)
    }

    /// The session's renderer set to `scene`'s image size, antialiasing
    /// and background: made on first use, its framebuffers made anew when
    /// the size or antialiasing changes.
    /// None where `plan` draws no frame (no GL context is opened).
    fn renderer(&mut self, scene: &Scene, plan: &Plan) -> Result<Option<Renderer>> {
        if !plan.contains(Pass::Render) {
            return Ok(None);
        }
        let [br, bg, bb] = scene.background;
        let opts = RenderOptions {
            width: scene.size[0],
            height: scene.size[1],
            msaa: scene.msaa,
            background: [br, bg, bb, 1.0],
        };
        match self.renderer.take() {
            Some(mut r) => {
                r.reconfigure(opts)?;
                Ok(Some(r))
            }
            None => Renderer::new(opts).map(Some),
        }
    }
}

/// The plan of a scene's cues for its input and outputs; `image`: a frame
/// is wanted besides the scene's PNG (a live view).
fn plan_of(scene: &Scene, image: bool) -> crate::scene::planner::Plan {
    let fx = &scene.effects;
    let outputs = Outputs {
        raster: scene.png || image,
        vector: scene.svg,
        visibility: scene.visibility,
        pieces: scene.pieces,
        fields: scene.fields,
        npz: scene.npz,
    };
    plan_for(&fx.cues, scene.source.input(), fx.caps, outputs)
}

/// Runs a scene: loads the input, plans, refuses to overwrite outputs
/// (unless `force`), then walks the plan frame by frame and view by view,
/// calling `progress(done, total)` after each view. Returns the report,
/// which is also written next to the images. Several scenes in a row share
/// a device and a GL context through a [`Session`].
pub fn run(
    scene: &Scene,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport> {
    Session::new().run(scene, opts, progress)
}

/// [`run`] on a device the caller holds (`opts.device` is ignored).
pub fn run_on(
    gpu: &Arc<Gpu>,
    scene: &Scene,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport> {
    Session::on(gpu.clone()).run(scene, opts, progress)
}

/// [`run`] with the input that [`check_scenes`] loaded for `scene` (see
/// [`Checked`]), so that it is not loaded twice. A `checked` of another
/// scene is ignored and the input loaded again.
pub fn run_checked(
    scene: &Scene,
    checked: Checked,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport> {
    Session::new().run_checked(scene, checked, opts, progress)
}

/// What a run hands its caller after each view, where asked.
type EachView<'a> = Option<&'a mut dyn FnMut(ViewDone) -> Result<()>>;

/// A scene run in `session` on an input already loaded (`pre`: the input and what
/// loading it said), or loading it when `pre` is `None`; `each` is handed
/// every view when done.
fn run_loaded(
    session: &mut Session,
    scene: &Scene,
    pre: Option<(load::Loaded, Vec<String>)>,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
    each: EachView<'_>,
) -> Result<RunReport> {
    let t_all = Instant::now();
    let (loaded, notes) = match pre {
        Some(p) => p,
        None => {
            let mut notes = Vec::new();
            (load(scene, &mut notes)?, notes)
        }
    };
    let frames = frame_indices(scene, loaded.frames())?;
    let out_dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| scene.out_dir.clone());
    let outputs = RunOutputs::new(scene, &frames, &out_dir, opts.views.as_deref());
    let input = RunInput {
        loaded,
        frames,
        notes,
        t_all,
    };
    let result = refuse_overwrite(scene, &outputs.images, &outputs.report, opts.force)
        .and_then(|()| {
            std::fs::create_dir_all(&out_dir).map_err(|source| Error::Write {
                path: out_dir.clone(),
                source,
            })
        })
        .and_then(|()| {
            let calls = Calls { progress, each };
            render_all(session, scene, opts, calls, input, Kept::Files(&outputs))
        });
    if result.is_err() && !opts.keep_done {
        outputs.remove_created();
    }
    result
}

/// The files a run writes, and what of them it creates (folders, and
/// files that did not exist), to remove again if it fails: a failed run
/// leaves what it found.
struct RunOutputs {
    /// The images: frame, view and path, frame-major ([`output_paths`]).
    images: Vec<(usize, usize, PathBuf)>,
    /// The report's path.
    report: PathBuf,
    /// Folders of the output folder's path that do not exist yet, deepest
    /// first.
    new_dirs: Vec<PathBuf>,
    /// Images and report that do not exist yet.
    new_files: Vec<PathBuf>,
}

impl RunOutputs {
    /// The outputs of `scene`'s `frames` and `views` (`None`: all) in
    /// `out_dir`, before the run.
    fn new(
        scene: &Scene,
        frames: &[usize],
        out_dir: &std::path::Path,
        views: Option<&[usize]>,
    ) -> RunOutputs {
        let (mut images, report) = output_paths(scene, frames, out_dir);
        images.retain(|i| runs_view(views, i.1));
        let new_dirs: Vec<PathBuf> = out_dir
            .ancestors()
            .filter(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(PathBuf::from)
            .collect();
        let new_files: Vec<PathBuf> = images
            .iter()
            .map(|i| &i.2)
            .chain([&report])
            .filter(|p| !p.exists())
            .cloned()
            .collect();
        RunOutputs {
            images,
            report,
            new_dirs,
            new_files,
        }
    }

    /// Removes what the failed run created: its files, then its folders
    /// where they are left empty.
    fn remove_created(&self) {
        for f in &self.new_files {
            let _ = std::fs::remove_file(f);
        }
        // Deepest first; only folders left empty go.
        for d in &self.new_dirs {
            let _ = std::fs::remove_dir(d);
        }
    }
}

/// What a run renders from: the loaded input, the frames it renders, what
/// loading the input said, and when the run started.
struct RunInput {
    loaded: load::Loaded,
    frames: Vec<usize>,
    notes: Vec<String>,
    t_all: Instant,
}

/// What a run calls back: `progress(done, total)` after each view, and
/// `each` with the view's lines where asked.
struct Calls<'a, 'b> {
    progress: &'a mut dyn FnMut(usize, usize),
    each: EachView<'b>,
}

/// Where a run's views go besides the caller's `each`.
enum Kept<'a> {
    /// The files of a run (images and report), checked and their folder made.
    Files(&'a RunOutputs),
    /// Nowhere: each view's image and SVG groups (and with `mesh` its
    /// surface) go to `each` in memory.
    Memory { mesh: bool },
}

/// The rendering of [`run_loaded`] after the outputs are checked and the
/// folder exists: builds the executor, runs the frames ([`run_frames`]) and
/// writes the report last. A run in memory writes nothing: each view's image
/// and SVG groups go to the caller's `each`.
fn render_all(
    session: &mut Session,
    scene: &Scene,
    opts: &ExecOptions,
    calls: Calls<'_, '_>,
    input: RunInput,
    kept: Kept<'_>,
) -> Result<RunReport> {
    let outputs = match kept {
        Kept::Files(o) => Some(o),
        Kept::Memory { .. } => None,
    };
    let RunInput {
        loaded,
        frames,
        notes,
        t_all,
    } = input;
    let plan = plan_of(scene, false);
    let gpu = session.gpu(opts)?;
    let renderer = session.renderer(scene, &plan)?;
    let uploads_before = renderer.as_ref().map(|r| r.uploads()).unwrap_or_default();
    let mut ex = Executor::new(scene, &plan, loaded, &gpu, renderer)?;
    if let Kept::Memory { mesh } = kept {
        ex.keep.layers = scene.svg;
        ex.keep.mesh = mesh;
    }
    let laps = Laps {
        frames: &frames,
        images: outputs.map_or(&[], |o| &o.images),
        views: opts.views.as_deref(),
    };
    let timing = run_frames(&mut ex, scene, &plan, laps, calls)?;
    let run = RunDone {
        frames,
        notes,
        t_all,
        timing,
        uploads_before,
    };
    let report = run_report(&mut ex, scene, &plan, &gpu, run);
    // The next scene of the session draws with the same GL context.
    if let Some(r) = ex.into_renderer() {
        session.renderer = Some(r);
    }
    if let Some(o) = outputs {
        let json = serde_json::to_string_pretty(&report).expect("the report serializes") + "\n";
        crate::export::output::write_bytes_atomic(&o.report, json.as_bytes())?;
    }
    Ok(report)
}

/// What a run's report takes from its walk besides the executor: the
/// frames run, what loading said, when the run started, the walk's laps,
/// and the GL uploads before it.
struct RunDone {
    frames: Vec<usize>,
    notes: Vec<String>,
    t_all: Instant,
    timing: crate::spec::timing::Timing,
    uploads_before: crate::render::Uploads,
}

/// The report of a run walked by `ex`: the passes in plan order with their
/// kernel time summed, the counts, the notes and outputs, the timing.
fn run_report(
    ex: &mut Executor<'_, '_>,
    scene: &Scene,
    plan: &Plan,
    gpu: &Gpu,
    run: RunDone,
) -> RunReport {
    let RunDone {
        frames,
        notes,
        t_all,
        timing,
        uploads_before,
    } = run;
    let (vertices, faces) = ex.counts();
    let passes = ex.rec.in_plan_order(plan);
    // The run's kernel time: its kernel passes' (the laps are wall time).
    let kernel_ms = (passes.iter())
        .filter(|p| p.is_kernel())
        .map(|p| p.ms())
        .sum();
    RunReport {
        scene: scene.path.display().to_string(),
        device: gpu.info.name.clone(),
        renderer: ex.gl_info(),
        plan: plan.clone(),
        frames,
        views: scene.views.len(),
        vertices,
        faces,
        passes,
        gl_uploads: {
            let now = ex.uploads();
            crate::render::Uploads {
                topology: now.topology - uploads_before.topology,
                pose: now.pose - uploads_before.pose,
            }
        },
        segments: ex.run.segments,
        chains: report::Chains::new(ex.run.chains),
        lines: std::mem::take(&mut ex.run.line_segments),
        strokes: ex.run.stroke_count,
        notes: notes
            .into_iter()
            .chain(ex.run.feature_size_note.take())
            .chain(ex.run.held_low.map(|low| {
                format!(
                    "lines held over the frames (coherence): a face that drew a thresholded \
                     family in its view's previous frame tests it at {low} of its threshold"
                )
            }))
            .collect(),
        outputs: std::mem::take(&mut ex.run.outputs),
        timing: crate::spec::timing::Timing {
            wall_ms: ms_since(t_all),
            kernel_ms,
            ..timing
        },
    }
}

/// What the frame loop walks: the frames, each view's images, and the
/// views it runs (`None`: all).
struct Laps<'a> {
    frames: &'a [usize],
    images: &'a [(usize, usize, PathBuf)],
    views: Option<&'a [usize]>,
}

/// The frame loop: the plan's passes frame by frame and view by view, by
/// lifetime (topology passes on a new topology, pose passes per pose, view
/// passes per camera), each view writing its `images`; calls
/// `progress(done, total)` after each view, and hands `each` the view
/// where asked. Returns the pose, view and render laps (the passes'
/// clocks), and the wall-clock laps `pose_wall` (a pose's passes, topology
/// passes with the first) and `view_wall` (a view's passes, drawing and
/// writing included; not what `each` does with it).
fn run_frames(
    ex: &mut Executor<'_, '_>,
    scene: &Scene,
    plan: &Plan,
    laps: Laps<'_>,
    calls: Calls<'_, '_>,
) -> Result<crate::spec::timing::Timing> {
    let Calls { progress, mut each } = calls;
    let Laps {
        frames,
        images,
        views,
    } = laps;
    let runs = |v: usize| runs_view(views, v);
    let mut walker = Walker::new(plan, scene.source.input());
    let total_views = frames.len() * (0..scene.views.len()).filter(|&v| runs(v)).count();
    let mut done = 0;
    for (i, &frame) in frames.iter().enumerate() {
        walker.pose(ex, frame)?;
        for (vi, cam) in ex.cameras().iter().enumerate() {
            if !runs(vi) {
                continue;
            }
            ex.hold = walk::hold_at(scene, frames, i, vi);
            let paths: Vec<&PathBuf> = (images.iter())
                .filter(|i| i.0 == frame && i.1 == vi)
                .map(|i| &i.2)
                .collect();
            walker.view(ex, cam, &paths)?;
            if let Some(each) = each.as_deref_mut() {
                let files = paths.into_iter().cloned().collect();
                each(ex.view_done((frame, vi), cam, files))?;
            }
            done += 1;
            progress(done, total_views);
        }
    }
    Ok(walker.timing)
}

/// What [`check_scenes`] learnt of one scene: the input it loaded to check
/// the scene's frames (animated inputs only), for [`run_checked`] to use
/// instead of loading it again.
pub struct Checked {
    /// The scene file it belongs to.
    scene: PathBuf,
    /// The loaded input and what loading it said.
    input: Option<(load::Loaded, Vec<String>)>,
}

/// Checks, before any scene of a run starts, everything that can be
/// checked before rendering, so that a run fails at once (writing nothing)
/// rather than after its first scenes have rendered:
///
/// - no two scenes write the same report and images (same output folder
///   and name), and without `force` no scene's report exists already;
/// - every scene's `[frames]` range lies within its input's frames: one
///   frame for a static mesh, a volume or an SDF (nothing is loaded); the
///   clip's sampled frames of a glTF model, the animation's frames of an
///   LBS set, the files of a flipbook;
/// - a flipbook's frames in that range have its first frame's topology
///   ([`Flipbook::check_frames`](crate::mesh::flipbook::Flipbook::check_frames):
///   in full for small sequences, from the file headers for large ones).
///
/// Counting an animated input's frames needs the input (a glTF clip's
/// duration comes from its keyframes, an LBS set's frame count from its
/// animation file, a flipbook's topology from its first frame), so those
/// inputs are loaded here, once: the returned [`Checked`] (one per scene,
/// in order) hands each to [`run_checked`]. They are held until their
/// scene runs, one mesh (and its animation) per animated scene.
///
/// # Errors
///
/// [`Error::InvalidArgument`] naming both scene files for a collision and
/// the scene file for an existing report; the errors of loading an
/// animated input; [`Error::InvalidInput`] naming the scene file and its
/// `[frames]` for a range outside the input; for a flipbook frame of
/// another topology, an error naming the scene file, the frame and the
/// frame's file with the difference.
pub fn check_scenes(scenes: &[Scene], opts: &ExecOptions) -> Result<Vec<Checked>> {
    check_outputs_across(scenes, opts)?;
    scenes.iter().map(check_input).collect()
}

/// The frames check of [`check_scenes`] for one scene.
fn check_input(scene: &Scene) -> Result<Checked> {
    let animated = matches!(
        scene.source,
        Source::Gltf(..) | Source::Lbs(_) | Source::Flipbook(_)
    );
    if !animated {
        frame_indices(scene, 1)?;
        return Ok(Checked {
            scene: scene.path.clone(),
            input: None,
        });
    }
    let mut notes = Vec::new();
    let loaded = load(scene, &mut notes)?;
    let frames = frame_indices(scene, loaded.frames())?;
    if let load::Loaded::Flipbook(book) = &loaded {
        book.check_frames(&frames).map_err(|(i, e)| {
            Error::input(
                scene.path.display().to_string(),
                format!("flipbook frame {i}"),
                e.to_string(),
            )
        })?;
    }
    Ok(Checked {
        scene: scene.path.clone(),
        input: Some((loaded, notes)),
    })
}

/// The output check of [`check_scenes`]: no collisions across scenes, no
/// existing report without `force`. A collision used to surface only
/// after the first scene had rendered.
fn check_outputs_across(scenes: &[Scene], opts: &ExecOptions) -> Result<()> {
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
                "{}: {} exists (from an earlier run); pass force = true to overwrite it",
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
    let plan = plan_of(scene, false);
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
