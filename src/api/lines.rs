//! [`lines_picture`]: every line family of rtsc (occluding and suggestive
//! contours, ridges, valleys, apparent ridges, highlights, isophotes,
//! K = 0, H = 0, D_w κr = 0, boundaries) of one mesh seen from one camera,
//! as a one-view scene that the scene executor runs (curvature on the
//! device, the feature-line stage, the lines over the mesh drawn flat in
//! white, which hides what is behind it, and the SVG groups per family);
//! and [`line_segments_on`], the segments alone, with no picture and no GL.

use crate::error::Result;
use crate::export::svg::SvgLayer;
use crate::gpu::Gpu;
use crate::mesh::Mesh;
use crate::render::{Camera, Frame, RenderOptions};
use crate::scene::exec::{ExecOptions, PassRecord, RunReport, Session, ViewDone, VisibleLines};
use crate::scene::file::{HeldMesh, LineStyle, Scene, Shot, Source, ViewSpec};
use crate::scene::planner::Cue;
use crate::spec::curvature::{Compat, CurvatureOptions};
use crate::spec::feature_lines::{FeatureSize, LineFamily, Segment};
pub use crate::spec::feature_lines::{Hidden, family_style, hidden_id};
use crate::spec::timing::Timing;
use crate::spec::view::View;
pub use crate::spec::visibility::VisibilityMethod;
use crate::stages::curvature::CurvatureEstimator;
use crate::stages::feature_lines::{LineExtractor, LineOptions};
use std::sync::Arc;

/// What [`lines_picture`] draws and how (the `shapecue lines` options).
#[derive(Clone, Debug, PartialEq)]
pub struct LinesPictureOptions {
    /// The camera and the image size (fitted from (1, 1, 1) by default).
    pub shot: Shot,
    /// The families and their controls.
    pub lines: LineOptions,
    /// Line width in pixels (contours 1.25 times as wide, as
    /// [`family_style`] gives each family's factor).
    pub line_width: f32,
    /// Hidden parts in the SVG.
    pub hidden: Hidden,
    /// Draw the picture (GL). Off, with `svg` on and exact visibility, no
    /// GL context is opened.
    pub image: bool,
    /// Also find the SVG groups.
    pub svg: bool,
    /// Also split the lines where their visibility changes and chain them
    /// ([`LineView::visible`]), with or without the SVG groups (exact
    /// visibility only: the depth-buffer method finds no pieces).
    pub pieces: bool,
    /// How the SVG's hidden lines are found: exactly, over the mesh's BVH
    /// (default), or against the picture's depth (which draws it).
    pub visibility: VisibilityMethod,
    /// The curvature and the feature size the lines are found with.
    pub setup: LineSetup,
}

/// What the line families are computed from besides the view: the
/// curvature estimator's options (the derivative is on where a family
/// needs it) and the feature size the thresholds are scaled by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineSetup {
    /// Scheme, precision and least squares of the curvature (default:
    /// gather, f32, trimesh2's least squares, the curvature rtsc computes its
    /// lines from: [`Compat::default_for`]; `Compat::Exact` is the exact
    /// solve).
    pub curvature: CurvatureOptions,
    /// The thresholds' scale (default: rtsc's).
    pub feature_size: FeatureSize,
}

impl Default for LineSetup {
    fn default() -> Self {
        LineSetup {
            curvature: CurvatureOptions {
                compat: Compat::default_for(true),
                ..CurvatureOptions::default()
            },
            feature_size: FeatureSize::default(),
        }
    }
}

impl Default for LinesPictureOptions {
    fn default() -> Self {
        LinesPictureOptions {
            shot: Shot::default(),
            lines: LineOptions::default(),
            line_width: 2.0,
            hidden: Hidden::Remove,
            image: true,
            svg: false,
            pieces: false,
            visibility: VisibilityMethod::Exact,
            setup: LineSetup::default(),
        }
    }
}

/// The result of [`lines_picture`].
pub struct LinesPicture {
    /// The picture (lines over the mesh in white), where one was drawn.
    pub frame: Option<Frame>,
    /// Every segment found, world coordinates, with its family (`kind`) and
    /// strength (the picture leaves out those of no strength).
    pub segments: Vec<Segment>,
    /// The SVG groups, one per family (and one per family's hidden parts).
    pub layers: Option<Vec<SvgLayer>>,
    /// The drawn segments split where their visibility changes and joined
    /// into chains (world coordinates), with exact visibility.
    pub visible: Option<VisibleLines>,
    /// Kernel ms of curvature and line steps.
    pub timing: Timing,
    /// The passes that ran, in plan order, with their ms.
    pub passes: Vec<PassRecord>,
    /// The camera (world coordinates).
    pub camera: Camera,
    /// The feature size the thresholds were scaled by.
    pub feature_size: f32,
}

/// [`lines_picture_on`] on the default device.
pub fn lines_picture(mesh: &Mesh, opts: &LinesPictureOptions) -> Result<LinesPicture> {
    lines_picture_on(&super::default_gpu()?, mesh, opts)
}

/// Every requested line family of `mesh` from the options' camera: the
/// scene of [`lines_scene`] run in memory by [`lines_on`], a single view
/// being many views of one.
pub fn lines_picture_on(
    gpu: &Arc<Gpu>,
    mesh: &Mesh,
    opts: &LinesPictureOptions,
) -> Result<LinesPicture> {
    let scene = lines_scene(Arc::new(mesh.clone()), opts);
    let mut one = None;
    lines_on(gpu, &scene, LineFiles::Memory, &mut |v| {
        one = Some(v);
        Ok(())
    })?;
    let v = one.expect("a one-view scene hands one view");
    Ok(LinesPicture {
        frame: v.image,
        segments: v.segments,
        layers: v.layers,
        visible: v.visible,
        timing: v.timing,
        passes: v.passes,
        camera: v.camera,
        feature_size: v.feature_size,
    })
}

/// The one-view scene of a lines picture: the families as cues, each in
/// its [`family_style`] at `line_width` times its factor, the mesh drawn
/// flat in white.
pub fn lines_scene(mesh: Arc<Mesh>, opts: &LinesPictureOptions) -> Scene {
    let mut s = Scene::held(Source::Held(HeldMesh(mesh)), &opts.shot);
    let [r, g, b, _] = RenderOptions::default().background;
    s.background = [r, g, b];
    s.msaa = RenderOptions::default().msaa;
    s.png = opts.image;
    s.svg = opts.svg;
    s.pieces = opts.pieces;
    s.visibility = opts.visibility;
    s.curvature = opts.setup.curvature;
    let fx = &mut s.effects;
    fx.feature_size = opts.setup.feature_size;
    fx.suggestive_threshold = opts.lines.threshold;
    fx.suggestive_fade = opts.lines.fade;
    fx.lines.curves = opts.lines.curves;
    fx.lines.styles.clear();
    for family in wanted(&opts.lines) {
        let (color, factor) = family_style(family);
        let width = opts.line_width * factor;
        let cue = match family {
            LineFamily::Contours => {
                fx.contour = (width, color);
                Cue::Contours
            }
            LineFamily::Suggestive => {
                fx.suggestive = (width, color);
                Cue::SuggestiveContours
            }
            f => *Cue::ALL
                .iter()
                .find(|c| c.family() == Some(f))
                .expect("every curvature line family has its cue"),
        };
        fx.cues.push(cue);
        fx.lines.styles.push(LineStyle {
            family,
            width,
            color,
            hidden: opts.hidden,
        });
    }
    s
}

/// The scene of a lines drawing from many views in one run: the scene of
/// [`lines_scene`] (its shot gives the image size) with `views` instead of
/// the shot's camera, for [`lines_on`]. Set the scene's `out_dir` and
/// `prefix` for its files, `fields` for each view's per-vertex fields.
pub fn lines_views_scene(
    mesh: Arc<Mesh>,
    opts: &LinesPictureOptions,
    views: Vec<ViewSpec>,
) -> Scene {
    let mut s = lines_scene(mesh, opts);
    s.views = views;
    s
}

/// One view of [`lines_on`], world coordinates.
pub struct LineView {
    /// The frame (its index in the input's frames; 0 for a static mesh).
    pub frame: usize,
    /// The view's index in the scene's views.
    pub view: usize,
    /// The camera as resolved (a fitted view's eye placed).
    pub camera: Camera,
    /// The line segments found for this view.
    pub segments: Vec<Segment>,
    /// The segments split where their visibility changes and chained, by
    /// exact visibility (where the scene asks for its SVG or its pieces).
    pub visible: Option<VisibleLines>,
    /// The per-vertex fields of the view, where asked.
    pub fields: Option<crate::spec::feature_lines::ViewFields>,
    /// The pieces as NPZ arrays, with the face and barycentric coordinates
    /// each lies at on this frame's pose (the same point of the rest mesh
    /// on every frame), and that pose, where the scene writes NPZ
    /// (`scene.npz`).
    pub npz: Option<crate::scene::exec::PosedPieces>,
    /// The picture (lines over the mesh in white), in memory where the
    /// scene asks for a PNG.
    pub image: Option<Frame>,
    /// The SVG groups, one per family (and one per family's hidden parts),
    /// in memory where the scene asks for its SVG.
    pub layers: Option<Vec<SvgLayer>>,
    /// The files the view wrote (into a folder: its SVG and PNG).
    pub files: Vec<std::path::PathBuf>,
    /// The passes that ran for this view (the first view also runs the
    /// pose's), in plan order, with their ms and clocks.
    pub passes: Vec<PassRecord>,
    /// Kernel ms of the pose's curvature and of this view's line steps.
    pub timing: Timing,
    /// The feature size the thresholds were scaled by.
    pub feature_size: f32,
}

/// Where the views of [`lines_on`] go besides its caller.
#[derive(Clone, Copy, Debug)]
pub enum LineFiles<'a> {
    /// Nowhere: each view's image and SVG groups, where the scene asks
    /// for them, come back in its [`LineView`]; nothing is written.
    Memory,
    /// Into the scene's `out_dir`, named by its `prefix`
    /// ([`crate::scene::exec::output_paths`]), with the run's report, as a
    /// scene run writes them; the options say which views run, whether
    /// existing files are replaced and what a failed run keeps.
    Folder(&'a ExecOptions),
}

/// The one route of every line drawing (`shapecue lines -o`, `--views`
/// and `--cameras`, Python's `lines` with one camera or many, the batch
/// task): runs `scene` (of [`lines_scene`] or [`lines_views_scene`]) in
/// the scene executor, the pose passes (curvature, the feature size, the
/// BVH) once and the view passes (the lines, their visibility, the
/// drawing) once per view, and hands each view to `each` as it is done.
/// An error of a view, or of `each`, ends the run with it (a run into a
/// folder then removes what it created, unless its options keep the views
/// done). Returns the run's report.
pub fn lines_on(
    gpu: &Arc<Gpu>,
    scene: &Scene,
    files: LineFiles<'_>,
    each: &mut dyn FnMut(LineView) -> Result<()>,
) -> Result<RunReport> {
    if scene.effects.cues.is_empty() {
        return Err(crate::error::Error::InvalidArgument(
            "no line family is asked for, so there is nothing to draw".into(),
        ));
    }
    let mut hand = |d: ViewDone| {
        let o = d.out;
        each(LineView {
            frame: d.frame,
            view: d.view,
            camera: o.world_camera(),
            segments: o.segments,
            visible: o.visible,
            fields: o.fields,
            npz: o.npz,
            image: o.image,
            layers: o.layers,
            files: d.files,
            passes: d.passes,
            timing: o.timing,
            feature_size: o.feature_size.unwrap_or(0.0),
        })
    };
    let mut session = Session::on(gpu.clone());
    match files {
        LineFiles::Memory => session.run_in_memory(scene, &ExecOptions::default(), &mut hand),
        LineFiles::Folder(opts) => session.run_each(scene, opts, &mut |_, _| {}, &mut hand),
    }
}

/// Runs `produce` with a consumer thread beside it: each item `produce`
/// hands over goes to `consume(&mut state, item)` on that thread, in order,
/// with at most one item waiting, so that one view's files are written while
/// the next view is computed (`shapecue lines --views`, `report
/// lines-batch`). The first error stops both: the consumer's, when it
/// failed (`produce` then sees a closed channel), else `produce`'s. Returns
/// the state once every item handed over is consumed, or the consumer has
/// stopped.
pub fn with_consumer<T: Send, S: Send, R>(
    state: S,
    mut consume: impl FnMut(&mut S, T) -> Result<()> + Send,
    produce: impl FnOnce(&mut dyn FnMut(T) -> Result<()>) -> Result<R>,
) -> (Result<R>, S) {
    let (tx, rx) = std::sync::mpsc::sync_channel::<T>(1);
    std::thread::scope(|scope| {
        let consumer = scope.spawn(move || {
            let mut state = state;
            let mut failed = None;
            for item in rx {
                if let Err(e) = consume(&mut state, item) {
                    failed = Some(e);
                    break;
                }
            }
            (state, failed)
        });
        let produced = produce(&mut |item| {
            // A closed channel means the consumer stopped on an error, which
            // is the one reported.
            tx.send(item).map_err(|_| crate::error::Error::Interrupted)
        });
        drop(tx);
        let (state, failed) = consumer
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        match failed {
            Some(e) => (Err(e), state),
            None => (produced, state),
        }
    })
}

/// The segments of [`line_segments_on`].
pub struct LineSegments {
    /// Every segment, world coordinates, with its family (`kind`) and strength.
    pub segments: Vec<Segment>,
    /// Kernel ms of curvature and line steps.
    pub timing: Timing,
    /// The feature size the thresholds were scaled by.
    pub feature_size: f32,
}

/// The line segments of `mesh` seen from `view` (no picture, no GL):
/// curvature with its derivative on the device, as `setup` asks, then
/// every family `opts` asks for, from the curvature buffers where they lie,
/// thresholds scaled by `setup`'s feature size.
pub fn line_segments_on(
    gpu: &Arc<Gpu>,
    mesh: &Mesh,
    view: View,
    opts: &LineOptions,
    setup: &LineSetup,
) -> Result<LineSegments> {
    let copts = CurvatureOptions {
        dcurv: true,
        ..setup.curvature
    };
    let mut est = CurvatureEstimator::new(gpu.clone(), mesh.n_vertices(), &mesh.faces, copts)?;
    est.set_stored_normals(mesh.normals.as_deref())?;
    est.set_positions(&mesh.positions)?;
    let mut timing = est.run()?;
    let fs = est.feature_size(setup.feature_size, &mesh.positions, &mesh.faces)? as f32;
    let mut ex = LineExtractor::new(gpu.clone(), mesh.n_vertices(), &mesh.faces)?;
    let (segments, st) = ex.extract_device(&est, view, fs, *opts)?;
    timing.extend(&st.timing);
    Ok(LineSegments {
        segments,
        timing,
        feature_size: fs,
    })
}

/// The families the options ask for, by index.
pub fn wanted(o: &LineOptions) -> Vec<LineFamily> {
    let mut v = Vec::new();
    if o.contours {
        v.push(LineFamily::Contours);
    }
    if o.suggestive {
        v.push(LineFamily::Suggestive);
    }
    v.extend(o.curves.families.curves().iter());
    v
}

/// The pieces of a view's classified lines as NPZ-ready arrays
/// ([`VisibleLines::arrays`] on `mesh`'s positions).
pub fn segment_arrays(v: &VisibleLines, mesh: &Mesh) -> crate::export::npz::SegmentArrays {
    v.arrays(&mesh.positions, &mesh.faces)
}
