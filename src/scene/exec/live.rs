//! A scene held live for an interactive front end (`shapecue view`): one
//! request after another, each the scene of one camera and one frame, drawn
//! into memory. What a request changes decides what runs again:
//!
//! - only the camera: the plan's *view* passes;
//! - the frame of an animation: its *pose* passes, then the view passes;
//! - anything else (cues, sliders, the image size, the iso value): a new
//!   plan and new stages, every pass of the plan. The loaded input is kept
//!   when the input itself (file, isovalue, weld, glTF rate) stays.
//!
//! Nothing is written but the SVG a request asks for: no report, no PNG
//! (the image comes back in the [`LiveFrame`]). A live view's SVG takes its
//! hidden lines from the frame's depth, which it draws anyway, unless the
//! scene asks for its SVG groups ([`LiveRequest`]). Each frame reports the
//! passes that ran for it, as the run report does for a whole run.

use super::draw::ViewOutputs;
use super::load::{Loaded, load};
use super::passes::Executor;
use super::report::{PassRecord, Recorder};
use super::walk::{Change, Walker};
use super::{ExecOptions, Session, frame_indices, plan_of};
use crate::error::{Error, Result};
use crate::scene::file::Scene;
use crate::scene::planner::{Input, Plan};
use std::path::PathBuf;

/// One frame to draw: the scene with the camera (its first view) and the
/// frame (the first of its `frames`) of the moment. The scene's `svg`
/// switch asks for the SVG groups in the frame ([`ViewOutputs::layers`]),
/// found as its `visibility` says, and then the image comes back where its
/// `png` is on; without `svg` the image always comes back. Changing these
/// sets the scene up anew.
#[derive(Clone, Debug)]
pub struct LiveRequest {
    /// The scene of this frame.
    pub scene: Scene,
    /// Also write the lines of the frame as SVG here.
    pub svg: Option<PathBuf>,
}

/// A drawn frame.
pub struct LiveFrame {
    /// The view's image and what was found for it.
    pub view: ViewOutputs,
    /// The passes that ran for this frame, in plan order, with their ms.
    pub passes: Vec<PassRecord>,
    /// What the request changed.
    pub change: Change,
    /// The SVG written, when the request asked for one.
    pub svg: Option<PathBuf>,
}

/// The scene with what a frame may change without new stages (camera,
/// frame, outputs) set aside: two requests of equal setups share stages.
fn setup(s: &Scene) -> Scene {
    let mut k = s.clone();
    k.views.clear();
    k.frames = (0, None, 1);
    k.prefix.clear();
    k.out_dir = PathBuf::new();
    k
}

/// The plan of a live setup: a scene that asks for its SVG groups plans as
/// its outputs say (a frame where `png` is on; exact visibility needs
/// none); any other draws its frame, and the SVG a request asks for takes
/// its hidden lines from the frame's depth.
fn live_plan(scene: &Scene) -> Plan {
    if scene.svg {
        return plan_of(scene, false);
    }
    let mut s = scene.clone();
    s.svg = true;
    s.visibility = crate::spec::visibility::VisibilityMethod::Depth;
    plan_of(&s, true)
}

/// Whether two scenes load the same input.
fn same_input(a: &Scene, b: &Scene) -> bool {
    a.source == b.source && a.weld == b.weld && a.fps == b.fps
}

impl Session {
    /// Draws `first`, hands the frame to `next`, and draws what `next`
    /// returns, until it returns `None`. A failed request is handed to
    /// `next` as its error; the scene is set up anew for the request after
    /// it. The device and the renderer stay with the session.
    pub fn live(
        &mut self,
        opts: &ExecOptions,
        first: LiveRequest,
        next: &mut dyn FnMut(Result<LiveFrame>) -> Option<LiveRequest>,
    ) {
        let mut req = first;
        let mut held: Option<(Scene, Loaded)> = None;
        loop {
            let scene = setup(&req.scene);
            let outcome = self.live_setup(opts, &scene, &mut held, req, next);
            req = match outcome {
                Ok(Some(r)) => r,
                Ok(None) => return,
                Err(e) => match next(Err(e)) {
                    Some(r) => r,
                    None => return,
                },
            };
        }
    }

    /// The requests of one setup (`scene`): stages built once, then pose
    /// and view passes as requests change the frame and the camera. Returns
    /// the first request of another setup, keeping the input in `held`
    /// for it.
    fn live_setup(
        &mut self,
        opts: &ExecOptions,
        scene: &Scene,
        held: &mut Option<(Scene, Loaded)>,
        first: LiveRequest,
        next: &mut dyn FnMut(Result<LiveFrame>) -> Option<LiveRequest>,
    ) -> Result<Option<LiveRequest>> {
        let loaded = match held.take() {
            Some((s, l)) if same_input(&s, scene) => l,
            _ => load(scene, &mut Vec::new())?,
        };
        let input = scene.source.input();
        let plan = live_plan(scene);
        let gpu = self.gpu(opts)?;
        let renderer = self.renderer(scene, &plan)?;
        let n_frames = loaded.frames();
        let mut ex = Executor::new(scene, &plan, loaded, &gpu, renderer)?;
        ex.keep.image = true;
        let mut live = Live {
            plan: &plan,
            input,
            n_frames,
            walker: Walker::new(&plan, input),
        };
        let mut req = first;
        loop {
            let frame = live.frame(&mut ex, &req)?;
            match next(Ok(frame)) {
                None => {
                    if let Some(r) = ex.into_renderer() {
                        self.renderer = Some(r);
                    }
                    return Ok(None);
                }
                Some(r) if setup(&r.scene) == *scene => req = r,
                Some(r) => {
                    let (loaded, renderer) = ex.into_parts();
                    if renderer.is_some() {
                        self.renderer = renderer;
                    }
                    *held = Some((scene.clone(), loaded));
                    return Ok(Some(r));
                }
            }
        }
    }
}

/// The state of one setup across its requests.
struct Live<'p> {
    plan: &'p Plan,
    input: Input,
    n_frames: usize,
    /// The plan's walker (it knows the pose that ran last).
    walker: Walker,
}

impl Live<'_> {
    /// Draws one request: pose passes when its frame is not the last one
    /// drawn (all but the view passes on the first), then the view passes.
    fn frame(&mut self, ex: &mut Executor<'_, '_>, req: &LiveRequest) -> Result<LiveFrame> {
        let frame = *frame_indices(&req.scene, self.n_frames)?
            .first()
            .ok_or_else(|| {
                Error::InvalidArgument(format!(
                    "{}: the frame range is empty",
                    req.scene.path.display()
                ))
            })?;
        let view = req.scene.views.first().ok_or_else(|| {
            Error::InvalidArgument(format!("{}: no camera", req.scene.path.display()))
        })?;
        ex.rec = Recorder::new(self.input);
        let change = self.walker.pose(ex, frame)?;
        let cam = ex.camera_of(view)?;
        let paths: Vec<&PathBuf> = req.svg.iter().collect();
        ex.keep.layers = req.scene.svg;
        self.walker.view(ex, &cam, &paths)?;
        let view = ex.kept.take().ok_or_else(|| {
            Error::InvalidArgument(format!(
                "{}: no cue is asked for, so there is nothing to draw",
                req.scene.path.display()
            ))
        })?;
        Ok(LiveFrame {
            view,
            passes: ex.rec.in_plan_order(self.plan),
            change,
            svg: req.svg.clone(),
        })
    }
}
