//! The run report: which passes ran, how often, for how long and by which
//! clock. Device passes take their kernel ms from their stage's
//! [`Timing`], joined to the plan by [`Pass::kernels`]; host passes report
//! wall time.

use crate::scene::planner::{Input, Lifetime, Pass, Plan};
use crate::spec::timing::{Step, Timing};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

/// What ran of one pass.
#[derive(Clone, Debug, Serialize)]
pub struct PassRecord {
    /// The pass.
    pub pass: Pass,
    /// Its lifetime for this input.
    pub lifetime: Lifetime,
    /// How many times it ran.
    pub runs: usize,
    /// Its time over all runs: a device pass's kernel steps (OpenCL
    /// profiling time, each step's launches summed) and, for one with a
    /// host step beside them (visibility), that step's wall time; a host
    /// pass's wall time.
    pub timing: Timing,
    /// `kernel` (OpenCL profiling time) or `wall` (host time).
    pub clock: &'static str,
    /// What the pass did here.
    pub how: String,
}

impl PassRecord {
    /// Whether its ms are OpenCL kernel time (else host wall time).
    pub fn is_kernel(&self) -> bool {
        self.clock == "kernel"
    }

    /// Its milliseconds over all runs, on its own clock (kernel or wall).
    pub fn ms(&self) -> f64 {
        if self.is_kernel() {
            self.timing.kernel_ms
        } else {
            self.timing.wall_ms
        }
    }
}

/// The report of one scene run.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// The scene file.
    pub scene: String,
    /// The OpenCL device.
    pub device: String,
    /// The GL renderer.
    pub renderer: String,
    /// The plan: input kind, cues, passes in order.
    pub plan: Plan,
    /// Frame indices rendered.
    pub frames: Vec<usize>,
    /// Cameras per frame.
    pub views: usize,
    /// Vertices and faces of the (last) pose.
    pub vertices: usize,
    /// Faces.
    pub faces: usize,
    /// The passes that ran, in plan order, with counts and times.
    pub passes: Vec<PassRecord>,
    /// Mesh uploads to GL in this run: one per topology (faces) and one per
    /// pose (positions, normals, colours), however many views.
    pub gl_uploads: crate::render::Uploads,
    /// Contour and suggestive-contour segments over all views.
    pub segments: [usize; 2],
    /// The visible chains of exact visibility over all views.
    pub chains: Chains,
    /// Segments of each curvature line cue's family over all views, by
    /// family name.
    pub lines: BTreeMap<&'static str, usize>,
    /// Curvature-directed strokes over all poses (traced once per pose).
    pub strokes: usize,
    /// Notes (e.g. what skinning weights were dropped).
    pub notes: Vec<String>,
    /// Files written (images; the report itself is written last).
    pub outputs: Vec<PathBuf>,
    /// The wall time of the whole run, and one phase entry per pose
    /// (`pose`: its passes, their own clocks), per view (`view`: the view
    /// passes other than rendering) and per render (`render`: draw + read
    /// back), in order; medians are the reader's ([`Timing::laps`]). Those
    /// sum what the passes recorded, each on its own clock (topology passes
    /// left out); `pose_wall` (per pose, topology passes with the first) and
    /// `view_wall` (per view, drawing and writing included) are wall-clock
    /// laps of the same loop.
    pub timing: Timing,
}

/// The visible chains of a run's views (exact visibility: each an SVG
/// polyline across faces).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Chains {
    /// Chains over all views.
    pub chains: usize,
    /// Their pieces (a segment's visible part each).
    pub pieces: usize,
    /// Mean pieces per chain (0 without chains).
    pub mean_length: f64,
}

impl Chains {
    /// From `[chains, pieces]`.
    pub fn new([chains, pieces]: [usize; 2]) -> Chains {
        Chains {
            chains,
            pieces,
            mean_length: if chains == 0 {
                0.0
            } else {
                pieces as f64 / chains as f64
            },
        }
    }
}

/// Accumulates what each pass did, and the time of the current pose or
/// view (the sum of what its passes recorded).
pub(super) struct Recorder {
    input: Input,
    map: BTreeMap<Pass, PassRecord>,
    /// What ran since the last [`Recorder::take_recent`] (one view's
    /// passes, and its pose's where they ran for it).
    recent: BTreeMap<Pass, PassRecord>,
    /// Milliseconds recorded since the last [`Recorder::lap`] (topology
    /// passes left out).
    current: f64,
}

impl Recorder {
    pub(super) fn new(input: Input) -> Recorder {
        Recorder {
            input,
            map: BTreeMap::new(),
            recent: BTreeMap::new(),
            current: 0.0,
        }
    }

    fn add(&mut self, pass: Pass, t: Timing, clock: &'static str, how: &str) {
        let lifetime = pass.lifetime(self.input);
        // On the pass's own clock (a device pass's host time is beside it).
        let ms = if clock == "kernel" {
            t.kernel_ms
        } else {
            t.wall_ms
        };
        for map in [&mut self.map, &mut self.recent] {
            let r = map.entry(pass).or_insert_with(|| PassRecord {
                pass,
                lifetime,
                runs: 0,
                timing: Timing::default(),
                clock,
                how: how.to_string(),
            });
            r.runs += 1;
            // Each step once, its launches summed over the runs.
            for s in &t.steps {
                match r.timing.steps.iter_mut().find(|x| x.step == s.step) {
                    Some(x) => {
                        x.kernel_ms += s.kernel_ms;
                        x.launches += s.launches;
                    }
                    None => r.timing.steps.push(*s),
                }
            }
            r.timing.kernel_ms += t.kernel_ms;
            r.timing.wall_ms += t.wall_ms;
        }
        // The pose time is that of the passes run per pose.
        if lifetime != Lifetime::Topology {
            self.current += ms;
        }
    }

    /// One run of a host pass taking `ms` of wall time.
    pub(super) fn wall(&mut self, pass: Pass, ms: f64, how: &str) {
        let t = Timing {
            wall_ms: ms,
            ..Timing::default()
        };
        self.add(pass, t, "wall", how);
    }

    /// One run of a device pass: the kernel ms of its steps in `t`.
    pub(super) fn kernels(&mut self, pass: Pass, t: &Timing, how: &str) {
        self.kernels_of(pass, t, pass.kernels(), how);
    }

    /// One run of a device pass with a host step beside its kernels (the
    /// visibility's plan, rounds and chains): its kernel ms, and `host_ms`
    /// of host wall time as the record's `wall_ms`.
    pub(super) fn kernels_and_host(&mut self, pass: Pass, t: &Timing, host_ms: f64, how: &str) {
        let mut mine = Timing::default();
        for s in t.steps.iter().filter(|s| pass.kernels().contains(&s.step)) {
            mine.kernel_ms += s.kernel_ms;
            mine.steps.push(*s);
        }
        mine.wall_ms = host_ms;
        self.add(pass, mine, "kernel", how);
    }

    /// One run of a device pass counting only `steps` of `t` (the rest of
    /// its launch is counted by another pass).
    pub(super) fn kernels_of(&mut self, pass: Pass, t: &Timing, steps: &[Step], how: &str) {
        let mut mine = Timing::default();
        for s in t.steps.iter().filter(|s| steps.contains(&s.step)) {
            mine.kernel_ms += s.kernel_ms;
            mine.steps.push(*s);
        }
        self.add(pass, mine, "kernel", how);
    }

    /// One run of a device pass whose kernels ran in another pass's launch
    /// (time counted there).
    pub(super) fn shared(&mut self, pass: Pass, how: &str) {
        self.add(pass, Timing::default(), "kernel", how);
    }

    /// The milliseconds recorded since the last call.
    pub(super) fn lap(&mut self) -> f64 {
        std::mem::take(&mut self.current)
    }

    /// The records of the passes that ran, in plan order.
    pub(super) fn in_plan_order(&self, plan: &Plan) -> Vec<PassRecord> {
        plan.passes
            .iter()
            .filter_map(|p| self.map.get(p).cloned())
            .collect()
    }

    /// The records of the passes that ran since the last call (one view's,
    /// with its pose's where they ran for it), in plan order.
    pub(super) fn take_recent(&mut self, plan: &Plan) -> Vec<PassRecord> {
        let mut recent = std::mem::take(&mut self.recent);
        plan.passes
            .iter()
            .filter_map(|p| recent.remove(p))
            .collect()
    }
}

/// Milliseconds since `t`.
pub(super) fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
