//! The one frame walker: the plan's passes for one view of one frame, by
//! lifetime. The pose passes run when the frame is not the one whose pose
//! ran last (all but the view passes on the first pose: the topology passes
//! with it), then the view passes. Scene runs, pictures, many views, the
//! viewer's live loop and Python all draw through it: a run walks its frames
//! and views with it ([`super::run_frames`]), a live scene one request at a
//! time (`live`).

use super::passes::Executor;
use super::report::ms_since;
use crate::error::Result;
use crate::render::Camera;
use crate::scene::planner::{Input, Lifetime, Pass, Plan};
use crate::spec::timing::Timing;
use std::path::PathBuf;
use std::time::Instant;

/// What a request changed, and so what ran for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Change {
    /// A new plan or input: every pass of the plan ran.
    Scene,
    /// Another frame of the animation: its pose passes and the view passes.
    Pose,
    /// Only the camera (or nothing): the view passes.
    View,
}

/// The plan's passes by lifetime and the pose that ran last.
pub(super) struct Walker {
    input: Input,
    /// The topology and pose passes (the first pose).
    first_pose: Vec<Pass>,
    /// The pose passes (later poses).
    later_poses: Vec<Pass>,
    /// The view passes.
    view_passes: Vec<Pass>,
    /// The frame whose pose passes ran last.
    pose: Option<usize>,
    /// The laps: `pose`, `view`, `render` (the passes' clocks) and the wall
    /// clock of a pose's passes (`pose_wall`) and of a view's (`view_wall`:
    /// its passes, drawing and writing).
    pub(super) timing: Timing,
}

impl Walker {
    /// A walker of `plan` for an input of kind `input`.
    pub(super) fn new(plan: &Plan, input: Input) -> Walker {
        let of = |keep: &dyn Fn(Lifetime) -> bool| -> Vec<Pass> {
            (plan.passes.iter().copied())
                .filter(|p| keep(p.lifetime(input)))
                .collect()
        };
        Walker {
            input,
            first_pose: of(&|l| l != Lifetime::View),
            later_poses: of(&|l| l == Lifetime::Pose),
            view_passes: of(&|l| l == Lifetime::View),
            pose: None,
            timing: Timing::default(),
        }
    }

    /// Runs the pose passes `frame` needs: every one but the view passes
    /// on the first pose, the pose passes on another frame of an animated
    /// input, none where its pose is the one that ran last. Says what
    /// changed.
    pub(super) fn pose(&mut self, ex: &mut Executor<'_, '_>, frame: usize) -> Result<Change> {
        let change = match self.pose {
            None => Change::Scene,
            Some(f) if f != frame && self.input != Input::Static => Change::Pose,
            Some(_) => return Ok(Change::View),
        };
        let t = Instant::now();
        // A failure leaves the last pose as it was: the next walk of this
        // frame runs the same passes again.
        ex.begin_pose();
        let passes = match change {
            Change::Scene => &self.first_pose,
            _ => &self.later_poses,
        };
        for &p in passes {
            ex.pose_pass(p, frame)?;
        }
        ex.end_pose(frame)?;
        self.pose = Some(frame);
        self.timing.lap("pose", ex.rec.lap());
        self.timing.lap("pose_wall", ms_since(t));
        Ok(change)
    }

    /// Runs the view passes from `cam`; the drawing passes write `paths`.
    pub(super) fn view(
        &mut self,
        ex: &mut Executor<'_, '_>,
        cam: &Camera,
        paths: &[&PathBuf],
    ) -> Result<()> {
        let t = Instant::now();
        ex.begin_view();
        let mut drawing = false;
        for &p in &self.view_passes {
            if matches!(p, Pass::Render | Pass::Svg) && !drawing {
                self.timing.lap("view", ex.rec.lap());
                drawing = true;
            }
            ex.view_pass(p, cam, paths)?;
        }
        ex.end_view(cam);
        self.timing.lap("render", ex.rec.lap());
        self.timing.lap("view_wall", ms_since(t));
        Ok(())
    }
}

/// Where view `view` of the `i`-th of `frames` keeps its lines' hysteresis
/// state: its own slot, following the frame before it in the run, where
/// the scene's coherence holds over that many frames; `None` otherwise.
pub(super) fn hold_at(
    scene: &crate::scene::file::Scene,
    frames: &[usize],
    i: usize,
    view: usize,
) -> Option<crate::stages::feature_lines::HoldAt> {
    let lines = &scene.effects.lines;
    (lines.coherence.holds(frames.len())).then(|| crate::stages::feature_lines::HoldAt {
        slot: view,
        frame: frames[i],
        follows: i.checked_sub(1).map(|p| frames[p]),
        low: lines.coherence_low,
        birth: lines.coherence_birth,
        band: lines.coherence_band,
    })
}
