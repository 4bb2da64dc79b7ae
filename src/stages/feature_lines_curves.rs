//! Host wiring of `kernels/feature_lines_curves.cl`: the curvature line
//! families of rtsc (ridges, valleys, apparent ridges, principal and
//! suggestive highlights, isophotes, K = 0, H = 0, D_w κr = 0, boundaries)
//! beside the contours, in the feature-lines family. Built by
//! [`super::feature_lines::LineExtractor`] the first time a curve family is
//! asked for: the faces around each vertex and the boundary mask are
//! uploaded once per topology; `lines_pose` runs once per pose (until
//! [`CurveStage::pose_changed`]), `lines_view` and `lines_dt1q1` once per
//! view and only for the families that read them. CPU twin:
//! [`crate::cpu::feature_lines_curves`].

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::feature_lines::{
    CurveOptions, FamilySet, LineFamily, LinesCurvesKernel, Segment, curve_segments_estimate,
};
use crate::spec::feature_lines::{ScaledThresholds, boundary_mask};
use crate::spec::timing::{Step, Timing};
use crate::stages::kernel_files;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;

/// The per-vertex inputs of the stage as kernel arguments, in one
/// coordinate system: pos, nrm, d1, d2, k, dk; then lines_vertex's ndv, kr,
/// sc, gkr; then the faces.
pub struct CurveArgs {
    /// pos, nrm, d1, d2, k, dk.
    pub inputs: [Arg; 6],
    /// ndv, kr, sc, and the gradient of κr sin²θ.
    pub terms: [Arg; 4],
    /// The faces (uint[3F]).
    pub faces: Arg,
    /// The coherence (kernels/common/isoline.h): held, near, next_held,
    /// next_near; low; birth.
    pub hold: HoldArgs,
    /// Coherence's Schmitt trigger on the signs of K and H and the side of
    /// emax dmax (`lines_pose`): mode (0 off, 1 record, 2 hold) and the
    /// bands of K, H and emax, in the inputs' coordinates.
    pub signs: (u32, [f32; 3]),
}

/// The coherence arguments of the line kernels (kernels/common/isoline.h):
/// held, near, next_held, next_near; low; birth.
pub type HoldArgs = ([Arg; 4], f32, u32);

/// The curve families' kernels and buffers for one topology.
pub struct CurveStage {
    gpu: Arc<Gpu>,
    nv: usize,
    nf: usize,
    kernels: [Kernel; 4],
    off: Buffer<u32>,
    ring: Buffer<u32>,
    bnd: Buffer<u32>,
    pose: Buffer<f32>,
    grad: Buffer<f32>,
    view: Buffer<f32>,
    dt: Buffer<f32>,
    /// The signs of K and H, and emax dmax, of the last pose (coherence's
    /// Schmitt trigger).
    signs: Buffer<u32>,
    evec: Buffer<f32>,
    seg: Buffer<f32>,
    ends: Buffer<u32>,
    cap: usize,
    counter: Buffer<u32>,
    /// Whether `pose` holds this pose's terms (and with gradients).
    pose_done: Option<bool>,
    /// Whether `view` holds the last run's view terms.
    view_done: bool,
}

impl CurveStage {
    /// Builds the program and uploads the topology of `faces`.
    pub fn new(gpu: Arc<Gpu>, nv: usize, faces: &[[u32; 3]]) -> Result<Self> {
        let p = gpu.program(&kernel_files::FEATURE_LINES_CURVES, "")?;
        let kernels = [
            LinesCurvesKernel::Pose,
            LinesCurvesKernel::View,
            LinesCurvesKernel::Dt1q1,
            LinesCurvesKernel::Curves,
        ]
        .map(|k| gpu.entry(&p, k));
        let [a, b, c, d] = kernels;
        let (off_h, ring_h) = crate::mesh::topology::one_rings(nv, faces);
        let mut off = gpu.buffer::<u32>(off_h.len())?;
        gpu.write(&mut off, &off_h)?;
        let mut ring = gpu.buffer::<u32>(ring_h.len().max(1))?;
        if !ring_h.is_empty() {
            gpu.write(&mut ring, &ring_h)?;
        }
        let nf = faces.len();
        let mut bnd = gpu.buffer::<u32>(nf.max(1))?;
        if nf > 0 {
            gpu.write(&mut bnd, &boundary_mask(faces))?;
        }
        let n = nv.max(1);
        // The coherence's signs start cleared (a sequence's first frame
        // records them before any frame reads them).
        let (mut signs, mut evec) = (gpu.buffer(n)?, gpu.buffer(3 * n)?);
        gpu.zero(&mut signs, n)?;
        gpu.zero(&mut evec, 3 * n)?;
        Ok(CurveStage {
            kernels: [a?, b?, c?, d?],
            off,
            ring,
            bnd,
            pose: gpu.buffer(8 * n)?,
            grad: gpu.buffer(6 * n)?,
            view: gpu.buffer(8 * n)?,
            dt: gpu.buffer(n)?,
            signs,
            evec,
            seg: gpu.buffer(8)?,
            ends: gpu.buffer(4)?,
            cap: 1,
            counter: gpu.buffer(1)?,
            pose_done: None,
            view_done: false,
            gpu,
            nv,
            nf,
        })
    }

    /// Marks the per-pose terms stale: the next run recomputes them.
    pub fn pose_changed(&mut self) {
        self.pose_done = None;
    }

    /// Marks the view terms stale (a new view starts).
    pub fn view_changed(&mut self) {
        self.view_done = false;
    }

    fn grow(&mut self, cap: usize) -> Result<()> {
        if cap > self.cap {
            self.seg = self.gpu.buffer(8 * cap)?;
            self.ends = self.gpu.buffer(4 * cap)?;
            self.cap = cap;
        }
        Ok(())
    }

    /// Runs the passes `opts.families` need and reads their segments back.
    /// `view` is the eye (or direction, `ortho`) and `feature_size` the
    /// thresholds' scale, both in the inputs' coordinates; `sc` the
    /// suggestive-contour threshold and fade, already scaled (D_w κr = 0 and
    /// the suggestive highlights' fade use them).
    pub fn run(
        &mut self,
        a: &CurveArgs,
        view: ([f32; 3], bool),
        feature_size: f32,
        sc_scaled: (f32, f32),
        opts: &CurveOptions,
    ) -> Result<(Vec<Segment>, Timing)> {
        opts.check()?;
        let fams = opts.families.curves();
        // Profiling times are read once the blocking read of the counter
        // has finished every launch before it.
        let mut events = Vec::new();
        let grads = opts.hermite_kh;
        // The view pass reads dmax from the pose terms, used only by the
        // principal highlights, which need the pose pass anyway.
        let pose_ok = match self.pose_done {
            Some(g) => g || !grads,
            None => false,
        };
        if needs_pose(fams) && !pose_ok {
            self.lines_pose(a, grads, &mut events)?;
        }
        self.view_done = needs_view(fams);
        if self.view_done {
            self.lines_view(a, view, opts, &mut events)?;
        }
        if fams.has(LineFamily::ApparentRidges) {
            self.lines_dt1q1(a, &mut events)?;
        }
        let thr = ScaledThresholds::of(opts, feature_size, sc_scaled);
        self.grow(curve_segments_estimate(self.nf, fams))?;
        // Twice at most: a first pass that overflows reports the count it
        // needs, and the second has room for it.
        for _ in 0..2 {
            let found = self.lines_curves(a, opts, &thr, &mut events)?;
            if found <= self.cap {
                let segs = self.read(found)?;
                let mut timing = Timing::default();
                for (step, e) in &events {
                    timing.add(*step, event_ms(e));
                }
                return Ok((segs, timing));
            }
            self.grow(found)?;
        }
        Err(Error::InvalidArgument(
            "internal: the curve line pass overflowed twice; nothing was written past the buffer"
                .into(),
        ))
    }

    /// `lines_pose`: the per-pose terms (with their gradients if `grads`).
    fn lines_pose(&mut self, a: &CurveArgs, grads: bool, events: &mut Events) -> Result<()> {
        let [_, _, d1, d2, k, dk] = a.inputs;
        let e = launch(
            &self.gpu,
            &self.kernels[0],
            self.nv,
            &[
                Arg::U32(self.nv as u32),
                d1,
                d2,
                k,
                dk,
                Arg::U32(u32::from(grads)),
                buf(&self.pose),
                buf(&self.grad),
                buf(&self.signs),
                buf(&self.evec),
                Arg::U32(a.signs.0),
                Arg::F32(a.signs.1[0]),
                Arg::F32(a.signs.1[1]),
                Arg::F32(a.signs.1[2]),
            ],
        )?;
        time(events, Step::LinesPose, e);
        self.pose_done = Some(grads);
        Ok(())
    }

    /// The view terms of the last [`CurveStage::run`]: `lines_view` runs
    /// now for `view` where that run's families did not need it (a caller
    /// that keeps q1 beside the lines). Returns the launch's timing.
    pub fn view_terms(
        &mut self,
        a: &CurveArgs,
        view: ([f32; 3], bool),
        opts: &CurveOptions,
    ) -> Result<Timing> {
        let mut events = Vec::new();
        if !self.view_done {
            self.lines_view(a, view, opts, &mut events)?;
            self.view_done = true;
        }
        let mut timing = Timing::default();
        for (step, e) in &events {
            e.wait().map_err(|e| Error::cl("clWaitForEvents", e))?;
            timing.add(*step, event_ms(e));
        }
        Ok(timing)
    }

    /// q1 per vertex from the view terms (after [`CurveStage::view_terms`]),
    /// in the coordinates of the inputs.
    pub fn read_q1(&self) -> Result<Vec<f32>> {
        let mut v = vec![0f32; 8 * self.nv];
        if self.nv > 0 {
            self.gpu.read(&self.view, &mut v)?;
        }
        Ok(v.chunks_exact(8).map(|c| c[0]).collect())
    }

    /// `lines_view`: the per-view terms for the eye (or direction) `view`
    /// and the options' light.
    fn lines_view(
        &mut self,
        a: &CurveArgs,
        view: ([f32; 3], bool),
        opts: &CurveOptions,
        events: &mut Events,
    ) -> Result<()> {
        let [pos, nrm, d1, d2, k, _] = a.inputs;
        let ndv = a.terms[0];
        let ([ex, ey, ez], ortho) = view;
        let [lx, ly, lz] = opts.unit_light();
        let e = launch(
            &self.gpu,
            &self.kernels[1],
            self.nv,
            &[
                Arg::U32(self.nv as u32),
                pos,
                nrm,
                d1,
                d2,
                k,
                buf(&self.pose),
                ndv,
                Arg::F32(ex),
                Arg::F32(ey),
                Arg::F32(ez),
                Arg::U32(u32::from(ortho)),
                Arg::F32(lx),
                Arg::F32(ly),
                Arg::F32(lz),
                buf(&self.view),
            ],
        )?;
        time(events, Step::LinesView, e);
        Ok(())
    }

    /// `lines_dt1q1`: D_t1 q1 per vertex (the apparent ridges).
    fn lines_dt1q1(&mut self, a: &CurveArgs, events: &mut Events) -> Result<()> {
        let [pos, nrm, ..] = a.inputs;
        let e = launch(
            &self.gpu,
            &self.kernels[2],
            self.nv,
            &[
                Arg::U32(self.nv as u32),
                a.faces,
                pos,
                nrm,
                buf(&self.off),
                buf(&self.ring),
                buf(&self.view),
                a.terms[0],
                buf(&self.dt),
            ],
        )?;
        time(events, Step::LinesDt1q1, e);
        Ok(())
    }

    /// `lines_curves`: the segments of the options' families, with the
    /// scaled thresholds `thr`, appended with the counter; returns the count
    /// found (past `cap` when they did not fit).
    fn lines_curves(
        &mut self,
        a: &CurveArgs,
        opts: &CurveOptions,
        thr: &ScaledThresholds,
        events: &mut Events,
    ) -> Result<usize> {
        let g = self.gpu.clone();
        let pos = a.inputs[0];
        let [ndv, kr, sc, gkr] = a.terms;
        g.zero(&mut self.counter, 1)?;
        let e = launch(
            &g,
            &self.kernels[3],
            self.nf,
            &[
                Arg::U32(self.nf as u32),
                a.faces,
                pos,
                ndv,
                kr,
                sc,
                gkr,
                buf(&self.pose),
                buf(&self.grad),
                buf(&self.view),
                buf(&self.dt),
                buf(&self.bnd),
                Arg::U32(opts.families.curves().0),
                Arg::U32(opts.flags()),
                Arg::F32(thr.rv),
                Arg::F32(thr.ar),
                Arg::F32(thr.ph),
                Arg::F32(thr.sh),
                Arg::F32(thr.sc),
                Arg::F32(thr.sh_fade),
                Arg::U32(opts.isophotes),
                Arg::U32(self.cap as u32),
                buf(&self.seg),
                buf(&self.ends),
                buf(&self.counter),
                a.hold.0[0],
                a.hold.0[1],
                a.hold.0[2],
                a.hold.0[3],
                Arg::F32(a.hold.1),
                Arg::U32(a.hold.2),
            ],
        )?;
        time(events, Step::LinesCurves, e);
        let mut c = [0u32];
        g.read(&self.counter, &mut c)?;
        Ok(c[0] as usize)
    }

    /// The device's per-vertex terms of the last run, for step-by-step
    /// comparison with the twin: pose (8 per vertex), gradients (6), view
    /// (8) and D_t1 q1 (1). Entries of passes that did not run are stale.
    pub fn read_terms(&self) -> Result<[Vec<f32>; 4]> {
        let n = self.nv;
        let mut out = [
            vec![0f32; 8 * n],
            vec![0f32; 6 * n],
            vec![0f32; 8 * n],
            vec![0f32; n],
        ];
        if n > 0 {
            self.gpu.read(&self.pose, &mut out[0])?;
            self.gpu.read(&self.grad, &mut out[1])?;
            self.gpu.read(&self.view, &mut out[2])?;
            self.gpu.read(&self.dt, &mut out[3])?;
        }
        Ok(out)
    }

    fn read(&self, found: usize) -> Result<Vec<Segment>> {
        let mut raw = vec![0f32; 8 * found];
        let mut ends = vec![0u32; 4 * found];
        if found > 0 {
            self.gpu.read(&self.seg, &mut raw)?;
            self.gpu.read(&self.ends, &mut ends)?;
        }
        Ok(raw
            .chunks_exact(8)
            .zip(ends.chunks_exact(4))
            .map(|(s, e)| {
                Segment::new(
                    [s[0], s[1], s[2]],
                    [s[3], s[4], s[5]],
                    s[6] as u32,
                    s[7],
                    [[e[0], e[1]], [e[2], e[3]]],
                )
            })
            .collect())
    }
}

/// The launches of one run with their steps, timed once the run has read
/// its count back.
type Events = Vec<(Step, opencl3::event::Event)>;

/// Keeps the event of a launch of `step` (none when nothing launched).
fn time(events: &mut Events, step: Step, e: Option<opencl3::event::Event>) {
    if let Some(e) = e {
        events.push((step, e));
    }
}

/// Whether one of `fams` reads the per-pose terms.
fn needs_pose(fams: FamilySet) -> bool {
    fams.iter().any(|f| {
        matches!(
            f,
            LineFamily::Ridges
                | LineFamily::Valleys
                | LineFamily::PrincipalHighlights
                | LineFamily::KZero
                | LineFamily::HZero
        )
    })
}

/// Whether one of `fams` reads the per-view terms.
fn needs_view(fams: FamilySet) -> bool {
    fams.iter().any(|f| {
        matches!(
            f,
            LineFamily::ApparentRidges | LineFamily::PrincipalHighlights | LineFamily::Isophotes
        )
    })
}
