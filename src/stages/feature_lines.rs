//! Host wiring of `kernels/feature_lines.cl`: occluding and suggestive
//! contours of a mesh with curvature, per view. The faces are uploaded once;
//! each call uploads the per-vertex inputs ([`LineExtractor::extract`]) or
//! reads them from a curvature estimator's device buffers
//! ([`LineExtractor::extract_device`]) and runs `lines_vertex` and
//! `lines_face`. The segment buffer starts with two segments per face
//! ([`segments_estimate`]); a pass that counts more (rtsc's test cuts a
//! suggestive contour into up to two pieces: three per face at most,
//! [`segments_bound`]) writes none past it, and runs again into a buffer
//! grown to its count. CPU twin:
//! [`crate::cpu::feature_lines`]. Views are [`crate::spec::view::View`]s
//! (made by the renderer's camera, or [`View::from_eye`] for lines alone).

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::feature_lines::LinesKernel;
use crate::spec::feature_lines::{
    CurveOptions, LineInputs, Segment, canonical, segments_bound, segments_estimate,
};
use crate::spec::feature_lines::{FamilySet, LineFamily, ViewFields};
use crate::spec::timing::{Step, Timing};
use crate::spec::view::View;
use crate::stages::curvature::CurvatureEstimator;
use crate::stages::feature_lines_curves::{CurveArgs, CurveStage, HoldArgs};
use crate::stages::kernel_files;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;

/// Which lines to extract and their thresholds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LineOptions {
    /// Occluding contours.
    pub contours: bool,
    /// Suggestive contours.
    pub suggestive: bool,
    /// Suggestive-contour threshold, dimensionless (rtsc's `sug_thresh`,
    /// default 0.01): segments are kept, and cut, where
    /// D_w κr · tanθ · s² ≥ `threshold`, with s the feature size.
    pub threshold: f32,
    /// rtsc's fade of suggestive contours and highlights, dimensionless
    /// (default 0.03): a point with r = D_w κr · tanθ − threshold / s² above
    /// the threshold has strength r / (r + fade / s²). Applied where
    /// [`CurveOptions::fade`] is on (rtsc's "draw faded"); 0: no fade.
    pub fade: f32,
    /// The curvature line families beside the contours (none by default)
    /// and their controls.
    pub curves: CurveOptions,
}

impl Default for LineOptions {
    fn default() -> Self {
        LineOptions {
            contours: true,
            suggestive: true,
            threshold: 0.01,
            fade: 0.03,
            curves: CurveOptions::default(),
        }
    }
}

impl LineOptions {
    /// These options drawing exactly the families of `set`: the contours
    /// and suggestive contours where it holds them, and its curvature line
    /// families; the thresholds and switches stay.
    pub fn with_families(mut self, set: FamilySet) -> LineOptions {
        self.contours = set.has(LineFamily::Contours);
        self.suggestive = set.has(LineFamily::Suggestive);
        self.curves.families = set.curves();
        self
    }

    /// The suggestive-contour threshold for a feature size `s`: threshold / s².
    pub fn scaled_threshold(&self, s: f32) -> f32 {
        self.threshold / (s * s)
    }

    /// The fade of suggestive contours and highlights for a feature size `s`:
    /// fade / s², or 0 where fading is off.
    pub fn scaled_fade(&self, s: f32) -> f32 {
        if self.curves.fade {
            self.fade / (s * s)
        } else {
            0.0
        }
    }

    /// Checks the suggestive-contour threshold and fade (finite, at least 0),
    /// then the curvature families' controls.
    pub fn check(&self) -> Result<()> {
        if !(self.threshold.is_finite() && self.threshold >= 0.0) {
            return Err(Error::InvalidArgument(format!(
                "the suggestive-contour threshold must be finite and at least 0, got {}",
                self.threshold
            )));
        }
        if !(self.fade.is_finite() && self.fade >= 0.0) {
            return Err(Error::InvalidArgument(format!(
                "the suggestive-contour fade must be finite and at least 0, got {}",
                self.fade
            )));
        }
        self.curves.check()
    }
}

/// Kernel times and counts of one extraction.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct LineStats {
    /// Segments found.
    pub segments: usize,
    /// Kernel ms of `lines_vertex`, `lines_face` and the curve families'
    /// steps (`lines_pose`, `lines_view`, `lines_dt1q1`, `lines_curves`).
    pub timing: Timing,
}

/// Extracts lines of one mesh topology.
pub struct LineExtractor {
    gpu: Arc<Gpu>,
    nv: usize,
    nf: usize,
    vertex: Kernel,
    face: Kernel,
    faces: Buffer<u32>,
    inputs: [Buffer<f32>; 6],
    /// n·v, κr sin²θ, sinθ D_w κr (one per vertex) and the gradient of
    /// κr sin²θ (three per vertex, written for Hermite placement only).
    terms: [Buffer<f32>; 4],
    seg: Buffer<f32>,
    ends: Buffer<u32>,
    /// Segments `seg` and `ends` hold.
    cap: usize,
    counter: Buffer<u32>,
    /// The faces, kept to build the curve stage when first asked for.
    host_faces: Vec<[u32; 3]>,
    curves: Option<CurveStage>,
    /// Keep the view fields of each run ([`LineExtractor::keep_view_fields`]).
    view_fields: bool,
    /// The world length of one unit of the last run's coordinates.
    scale: f64,
    /// The coherence over the frames of a pose sequence.
    hold: HoldState,
}

/// The coherence marks of a slot's last frame ([`LineExtractor::read_marks`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Marks {
    /// Per face, the families drawn.
    pub held: Vec<u32>,
    /// Per vertex, the families found around it (low 16 bits) and
    /// established (high 16 bits).
    pub near: Vec<u32>,
    /// The frame they are of.
    pub frame: Option<usize>,
}

/// Where the next extraction keeps its hysteresis state
/// ([`LineExtractor::hold_at`]): a slot (one per view of a pose sequence)
/// and the frame it runs, with the frame before it in the sequence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldAt {
    /// The state's slot (the view's index in its scene).
    pub slot: usize,
    /// The frame this extraction runs.
    pub frame: usize,
    /// The frame before it in the sequence (`None`: the first): the slot's
    /// marks hold only where they are that frame's.
    pub follows: Option<usize>,
    /// The fraction of its threshold a face that drew a family in the
    /// previous frame tests that family against (in (0, 1]).
    pub low: f32,
    /// The delay of births in frames (0, 1 or 2): a line found away from
    /// every line of its family in the frames before is drawn from its
    /// second (third) frame on.
    pub birth: u32,
    /// The band of the Schmitt trigger on the signs of K and H and the
    /// side of emax dmax (ridges and valleys), in units of the feature size
    /// s (|K| < band / s², |H| < band / s, |emax| < band / s² keep the
    /// previous frame's; 0: none).
    pub band: f32,
}

/// The coherence buffers of one extractor (kernels/common/isoline.h): per
/// face (`held`) and per vertex (`near`), the marks of each slot's last
/// frame, the marks being made, and all-zero marks (and scratch ones to
/// write) for extractions without coherence.
struct HoldState {
    zeros: [Buffer<u32>; 2],
    scratch: [Buffer<u32>; 2],
    /// Per slot: the last frame's marks, the frame they are of.
    slots: std::collections::HashMap<usize, ([Buffer<u32>; 2], Option<usize>)>,
    /// This frame's marks (swapped into the slot after the run).
    next: [Buffer<u32>; 2],
    /// The next run's place, where set.
    at: Option<HoldAt>,
    /// Whether the last run started its slot's sequence afresh.
    fresh: bool,
}

impl LineExtractor {
    /// Uploads the faces and allocates the buffers.
    pub fn new(gpu: Arc<Gpu>, n_vertices: usize, faces: &[[u32; 3]]) -> Result<Self> {
        crate::mesh::check_faces(n_vertices, faces, "feature lines")?;
        let file = kernel_files::FEATURE_LINES;
        let p = gpu.program(&file, "")?;
        let mut fb = gpu.buffer::<u32>(3 * faces.len())?;
        gpu.write(&mut fb, faces.as_flattened())?;
        let nv = n_vertices;
        Ok(LineExtractor {
            vertex: gpu.entry(&p, LinesKernel::Vertex)?,
            face: gpu.entry(&p, LinesKernel::Face)?,
            faces: fb,
            inputs: [
                gpu.buffer(3 * nv)?,
                gpu.buffer(3 * nv)?,
                gpu.buffer(3 * nv)?,
                gpu.buffer(3 * nv)?,
                gpu.buffer(2 * nv)?,
                gpu.buffer(4 * nv)?,
            ],
            terms: [
                gpu.buffer(nv.max(1))?,
                gpu.buffer(nv.max(1))?,
                gpu.buffer(nv.max(1))?,
                gpu.buffer(3 * nv.max(1))?,
            ],
            seg: gpu.buffer(8 * segments_estimate(faces.len()))?,
            ends: gpu.buffer(4 * segments_estimate(faces.len()))?,
            cap: segments_estimate(faces.len()),
            counter: gpu.buffer(1)?,
            host_faces: faces.to_vec(),
            curves: None,
            view_fields: false,
            scale: 1.0,
            hold: HoldState {
                zeros: {
                    let (mut a, mut b) = (gpu.buffer(faces.len().max(1))?, gpu.buffer(nv.max(1))?);
                    gpu.zero(&mut a, faces.len().max(1))?;
                    gpu.zero(&mut b, nv.max(1))?;
                    [a, b]
                },
                scratch: [gpu.buffer(faces.len().max(1))?, gpu.buffer(nv.max(1))?],
                slots: Default::default(),
                next: [gpu.buffer(faces.len().max(1))?, gpu.buffer(nv.max(1))?],
                at: None,
                fresh: true,
            },
            gpu,
            nv,
            nf: faces.len(),
        })
    }

    /// Extracts the lines of `x` seen from `view`. `feature_size` (world
    /// units, > 0) scales the suggestive threshold.
    pub fn extract(
        &mut self,
        x: &LineInputs,
        view: View,
        feature_size: f32,
        opts: LineOptions,
    ) -> Result<(Vec<Segment>, LineStats)> {
        let n = self.nv;
        if [
            x.pos.len(),
            x.nrm.len(),
            x.d1.len(),
            x.d2.len(),
            x.k.len(),
            x.dk.len(),
        ]
        .iter()
        .any(|&l| l != n)
        {
            return Err(Error::InvalidArgument(format!(
                "feature lines: every per-vertex input needs {n} entries"
            )));
        }
        let view = (view.line_eye(), view.ortho);
        check_view(view, feature_size)?;
        let g = self.gpu.clone();
        g.write(&mut self.inputs[0], x.pos.as_flattened())?;
        g.write(&mut self.inputs[1], x.nrm.as_flattened())?;
        g.write(&mut self.inputs[2], x.d1.as_flattened())?;
        g.write(&mut self.inputs[3], x.d2.as_flattened())?;
        g.write(&mut self.inputs[4], x.k.as_flattened())?;
        g.write(&mut self.inputs[5], x.dk.as_flattened())?;
        self.pose_changed();
        self.scale = 1.0;
        let inputs = self.inputs.each_ref().map(buf);
        self.run(inputs, view, feature_size, opts)
    }

    /// Whether each run also computes the view fields that
    /// [`LineExtractor::read_view_fields`] reads (q1 needs `lines_view`,
    /// which otherwise runs only for the families that read it).
    pub fn keep_view_fields(&mut self, on: bool) {
        self.view_fields = on;
    }

    /// The per-vertex fields of the last run's view (n·v, κr sin²θ, D_w κr,
    /// q1), in world units; the run must have kept them
    /// ([`LineExtractor::keep_view_fields`]).
    pub fn read_view_fields(&self) -> Result<ViewFields> {
        let stage = match (&self.curves, self.view_fields) {
            (Some(c), true) => c,
            _ => {
                return Err(Error::InvalidArgument(
                    "feature lines: the view fields were not kept by the last run".into(),
                ));
            }
        };
        let n = self.nv;
        let mut f = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
        if n > 0 {
            for (out, b) in f.iter_mut().zip(&self.terms) {
                self.gpu.read(b, out)?;
            }
        }
        let [ndotv, kr, dwkr] = f;
        let fields = ViewFields {
            ndotv,
            kr,
            dwkr,
            q1: stage.read_q1()?,
        };
        Ok(fields.from_local(self.scale))
    }

    /// Where the next extraction keeps its coherence state (`None`: none,
    /// today's lines). Over the frames of one pose sequence (one slot per
    /// camera), as kernels/common/isoline.h does it: a face that drew a
    /// thresholded family (suggestive contours, ridges, valleys, apparent
    /// ridges, principal and suggestive highlights) in the slot's previous
    /// frame tests it against its threshold times `low` (Canny's two
    /// thresholds); a line found away from every line of its family is
    /// drawn after `birth` frames (contours, isophotes and boundaries at
    /// once); K, H and emax dmax keep their previous sign within `band`
    /// (`lines_pose`). A slot whose last frame is not `follows` starts
    /// afresh: the first frame of a sequence draws today's lines exactly.
    pub fn hold_at(&mut self, at: Option<HoldAt>) -> Result<()> {
        if let Some(h) = at {
            crate::spec::coherence::check(h.low, h.birth, h.band)
                .map_err(Error::InvalidArgument)?;
        }
        self.hold.at = at;
        Ok(())
    }

    /// The coherence marks of `slot`'s last frame (bit = family code):
    /// per face the families drawn, per vertex those found around it (low
    /// 16 bits) and established (high 16 bits); with that frame; `None`
    /// where the slot never ran.
    pub fn read_marks(&self, slot: usize) -> Result<Option<Marks>> {
        let Some(([held, near], frame)) = self.hold.slots.get(&slot) else {
            return Ok(None);
        };
        let mut m = Marks {
            held: vec![0u32; self.nf],
            near: vec![0u32; self.nv],
            frame: *frame,
        };
        if self.nf > 0 {
            self.gpu.read(held, &mut m.held)?;
        }
        if self.nv > 0 {
            self.gpu.read(near, &mut m.near)?;
        }
        Ok(Some(m))
    }

    /// The coherence arguments of the next run (held, near, next_held,
    /// next_near; low; birth), with the slot's marks cleared where they are
    /// not of the frame before (no birth is delayed then).
    fn hold_args(&mut self) -> Result<HoldArgs> {
        let g = self.gpu.clone();
        let n = [self.nf.max(1), self.nv.max(1)];
        let Some(h) = self.hold.at else {
            let [z0, z1] = &self.hold.zeros;
            let [s0, s1] = &self.hold.scratch;
            return Ok(([buf(z0), buf(z1), buf(s0), buf(s1)], 1.0, 0));
        };
        let (marks, last) = match self.hold.slots.entry(h.slot) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(([g.buffer(n[0])?, g.buffer(n[1])?], None))
            }
        };
        // A sequence's first frame: nothing held, no birth delayed.
        let fresh = h.follows.is_none() || *last != h.follows;
        if fresh {
            for (b, n) in marks.iter_mut().zip(n) {
                g.zero(b, n)?;
            }
        }
        for (b, n) in self.hold.next.iter_mut().zip(n) {
            g.zero(b, n)?;
        }
        let ([held, near], _) = &self.hold.slots[&h.slot];
        let [n0, n1] = &self.hold.next;
        let birth = if fresh { 0 } else { h.birth };
        self.hold.fresh = fresh;
        Ok(([buf(held), buf(near), buf(n0), buf(n1)], h.low, birth))
    }

    /// After a run with hysteresis: this frame's marks become the slot's.
    fn hold_done(&mut self) {
        if let Some(h) = self.hold.at
            && let Some((marks, last)) = self.hold.slots.get_mut(&h.slot)
        {
            std::mem::swap(marks, &mut self.hold.next);
            *last = Some(h.frame);
        }
    }

    /// The curve families' stage, once a run has asked for one of them.
    pub fn curve_stage(&self) -> Option<&CurveStage> {
        self.curves.as_ref()
    }

    /// Marks the per-pose terms of the curve families stale. Host inputs
    /// ([`LineExtractor::extract`]) do it themselves; a caller that reruns
    /// the curvature estimator between [`LineExtractor::extract_device`]
    /// calls does it after each run (the pose pipeline and the scene
    /// executor do), so that many views of one pose compute them once.
    pub fn pose_changed(&mut self) {
        if let Some(c) = self.curves.as_mut() {
            c.pose_changed();
        }
    }

    /// Extracts the lines of the estimator's last run seen from `view`,
    /// reading its device buffers (no upload; only the segments come back).
    /// `view` and `feature_size` are in world units like in
    /// [`LineExtractor::extract`]: the eye of a perspective view is mapped
    /// into the estimator's normalized coordinates (an orthographic direction
    /// is unchanged), the feature size is divided by the scale, and the
    /// segments are mapped back to world coordinates (`p·scale + center`).
    /// Contours without rtsc's test need only the normals: a run up to
    /// [`crate::stages::curvature::Pass::Frames`] is enough for them (the
    /// zeroed curvature reads as κr = 0, which the test keeps); the test
    /// reads κr, so tested contours need the principal curvatures and
    /// directions. Needs an f32 estimator of this topology's vertex count.
    pub fn extract_device(
        &mut self,
        est: &CurvatureEstimator,
        view: View,
        feature_size: f32,
        opts: LineOptions,
    ) -> Result<(Vec<Segment>, LineStats)> {
        self.extract_device_at(est, view, feature_size, opts, [0.0; 3])
    }

    /// [`extract_device`](Self::extract_device) with the eye and the
    /// segments relative to `origin` (world = local + origin, mapped in f64):
    /// a renderer that draws a mesh far from the world origin relative to a
    /// point near it keeps f32 precision that world coordinates would lose.
    pub fn extract_device_at(
        &mut self,
        est: &CurvatureEstimator,
        view: View,
        feature_size: f32,
        opts: LineOptions,
        origin: [f64; 3],
    ) -> Result<(Vec<Segment>, LineStats)> {
        let (view_eye, ortho) = (view.line_eye(), view.ortho);
        check_view((view_eye, ortho), feature_size)?;
        let d = est.device_outputs()?;
        if d.nv != self.nv {
            return Err(Error::InvalidArgument(format!(
                "feature lines: the curvature estimator has {} vertices, the extractor was built for {}",
                d.nv, self.nv
            )));
        }
        let norm = d.norm;
        let eye = if ortho {
            view_eye
        } else {
            let e: [f64; 3] = std::array::from_fn(|i| f64::from(view_eye[i]) + origin[i]);
            norm.apply(e).map(|c| c as f32)
        };
        let local = (eye, ortho);
        let size = (f64::from(feature_size) / norm.scale) as f32;
        // Huge world values may not survive the mapping into f32.
        check_view(local, size)?;
        let inputs = [d.pos, d.nrm, d.d1, d.d2, d.k, d.dk].map(buf);
        self.scale = norm.scale;
        let (mut segs, stats) = self.run(inputs, local, size, opts)?;
        let world = |p: [f32; 3]| -> [f32; 3] {
            std::array::from_fn(|i| {
                (f64::from(p[i]) * norm.scale + (norm.center[i] - origin[i])) as f32
            })
        };
        for s in &mut segs {
            s.a = world(s.a);
            s.b = world(s.b);
        }
        Ok((segs, stats))
    }

    /// Runs `lines_vertex` and `lines_face` on the per-vertex float buffers
    /// `inputs` (pos, nrm, d1, d2, k, dk) in one coordinate system, with
    /// `view` (eye or direction towards the viewer, ortho flag) and
    /// `feature_size` in that system, and reads the segments back.
    fn run(
        &mut self,
        inputs: [Arg; 6],
        view: ([f32; 3], bool),
        feature_size: f32,
        opts: LineOptions,
    ) -> Result<(Vec<Segment>, LineStats)> {
        opts.check()?;
        if let Some(c) = self.curves.as_mut() {
            c.view_changed();
        }
        self.gpu.zero(&mut self.counter, 1)?;
        let hold = self.hold_args()?;
        let e1 = self.lines_vertex(inputs, view, &opts)?;
        let curve_fams = opts.curves.families.curves();
        let contours = opts.contours || opts.suggestive || curve_fams == Default::default();
        let (e2, found) = self.lines_face(inputs[0], feature_size, &opts, contours, hold)?;
        let mut segs = self.read_segments(found)?;
        let mut timing = Timing::default();
        if let Some(e) = &e1 {
            timing.add(Step::LinesVertex, event_ms(e));
        }
        for e in &e2 {
            timing.add(Step::LinesFace, event_ms(e));
        }
        if curve_fams != Default::default() {
            let (more, t) = self.curve_lines(inputs, view, feature_size, &opts, hold)?;
            timing.extend(&t);
            segs.extend(more);
        }
        self.hold_done();
        // Found but not drawn: a birth the coherence delays.
        segs.retain(|s| s.family & crate::spec::coherence::LINE_UNBORN == 0);
        if self.view_fields {
            timing.extend(&self.view_terms(inputs, view, &opts)?);
        }
        // The appends' order is the device's; the rows' order is documented.
        canonical(&mut segs);
        let stats = LineStats {
            segments: segs.len(),
            timing,
        };
        Ok((segs, stats))
    }

    /// `lines_vertex`: the per-vertex terms (ndv, kr, sc, the gradient of
    /// κr sin²θ) of `inputs` for `view`.
    fn lines_vertex(
        &mut self,
        inputs: [Arg; 6],
        view: ([f32; 3], bool),
        opts: &LineOptions,
    ) -> Result<Option<Event>> {
        let n = self.nv;
        let ([ex, ey, ez], ortho) = view;
        let mut args: Vec<Arg> = vec![Arg::U32(n as u32)];
        args.extend(inputs);
        args.extend([
            Arg::F32(ex),
            Arg::F32(ey),
            Arg::F32(ez),
            Arg::U32(u32::from(ortho)),
        ]);
        args.extend(self.terms[..3].iter().map(buf));
        args.extend([
            Arg::U32(u32::from(opts.curves.hermite)),
            buf(&self.terms[3]),
        ]);
        launch(&self.gpu, &self.vertex, n, &args)
    }

    /// `lines_face` (when `contours`): the contour and suggestive-contour
    /// segments at positions `pos`, appended with the counter; returns the
    /// launches and the segments found.
    fn lines_face(
        &mut self,
        pos: Arg,
        feature_size: f32,
        opts: &LineOptions,
        contours: bool,
        hold: HoldArgs,
    ) -> Result<(Vec<Event>, usize)> {
        let g = self.gpu.clone();
        // Twice at most: a pass that counts more segments than the buffer
        // holds writes none past it, and the second has room for them.
        let mut e2 = Vec::new();
        let mut found = 0;
        for _ in 0..2 {
            g.zero(&mut self.counter, 1)?;
            if !contours {
                break;
            }
            let cap = self.cap;
            let e = launch(
                &g,
                &self.face,
                self.nf,
                &[
                    Arg::U32(self.nf as u32),
                    buf(&self.faces),
                    pos,
                    buf(&self.terms[0]),
                    buf(&self.terms[1]),
                    buf(&self.terms[2]),
                    buf(&self.terms[3]),
                    Arg::U32(u32::from(opts.contours)),
                    Arg::U32(u32::from(opts.suggestive)),
                    Arg::U32(u32::from(opts.curves.test)),
                    Arg::U32(u32::from(opts.curves.hermite)),
                    Arg::F32(opts.scaled_threshold(feature_size)),
                    Arg::F32(opts.scaled_fade(feature_size)),
                    Arg::U32(cap as u32),
                    buf(&self.seg),
                    buf(&self.ends),
                    buf(&self.counter),
                    hold.0[0],
                    hold.0[1],
                    hold.0[2],
                    hold.0[3],
                    Arg::F32(hold.1),
                    Arg::U32(hold.2),
                ],
            )?;
            e2.extend(e);
            let mut c = [0u32];
            g.read(&self.counter, &mut c)?;
            found = c[0] as usize;
            if found <= cap {
                break;
            }
            if found > segments_bound(self.nf) {
                return Err(Error::InvalidArgument(format!(
                    "internal: {found} segments counted for {} faces; nothing was written past the buffer",
                    self.nf
                )));
            }
            self.seg = g.buffer(8 * found)?;
            self.ends = g.buffer(4 * found)?;
            self.cap = found;
        }
        Ok((e2, found))
    }

    /// Reads the first `found` segments of `lines_face` back.
    fn read_segments(&self, found: usize) -> Result<Vec<Segment>> {
        let g = &self.gpu;
        let mut raw = vec![0f32; 8 * found];
        g.read(&self.seg, &mut raw)?;
        let mut ends = vec![0u32; 4 * found];
        g.read(&self.ends, &mut ends)?;
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

    /// The curve stage's arguments: `inputs`, this extractor's per-vertex
    /// terms and its faces.
    fn curve_args(&self, inputs: [Arg; 6], hold: HoldArgs, feature_size: f32) -> CurveArgs {
        // The signs of K and H follow the hysteresis' slot: recorded on a
        // sequence's first frame, held on the next ones.
        let signs = match self.hold.at {
            Some(h) if h.band > 0.0 => {
                let mode = if self.hold.fresh { 1 } else { 2 };
                let s = feature_size;
                (mode, [h.band / (s * s), h.band / s, h.band / (s * s)])
            }
            _ => (0, [0.0; 3]),
        };
        CurveArgs {
            inputs,
            terms: self.terms.each_ref().map(buf),
            faces: buf(&self.faces),
            hold,
            signs,
        }
    }

    /// The curve stage, built the first time it is asked for.
    fn curve_stage_mut(&mut self) -> Result<&mut CurveStage> {
        if self.curves.is_none() {
            let stage = CurveStage::new(self.gpu.clone(), self.nv, &self.host_faces)?;
            self.curves = Some(stage);
        }
        Ok(self.curves.as_mut().expect("built above"))
    }

    /// The view terms of this run (q1 for the view fields), where its
    /// families did not compute them.
    fn view_terms(
        &mut self,
        inputs: [Arg; 6],
        view: ([f32; 3], bool),
        opts: &LineOptions,
    ) -> Result<Timing> {
        let [z0, z1] = &self.hold.zeros;
        let [s0, s1] = &self.hold.scratch;
        let hold = ([buf(z0), buf(z1), buf(s0), buf(s1)], 1.0, 0);
        let mut args = self.curve_args(inputs, hold, 1.0);
        args.signs = (0, [0.0; 3]);
        let stage = self.curve_stage_mut()?;
        stage.view_terms(&args, view, &opts.curves)
    }

    /// The curvature line families' segments, by the curve stage (built the
    /// first time one is asked for) on the same inputs and terms.
    fn curve_lines(
        &mut self,
        inputs: [Arg; 6],
        view: ([f32; 3], bool),
        feature_size: f32,
        opts: &LineOptions,
        hold: HoldArgs,
    ) -> Result<(Vec<Segment>, Timing)> {
        let args = self.curve_args(inputs, hold, feature_size);
        let stage = self.curve_stage_mut()?;
        let sc = (
            opts.scaled_threshold(feature_size),
            opts.scaled_fade(feature_size),
        );
        stage.run(&args, view, feature_size, sc, &opts.curves)
    }
}

/// A finite eye (a non-zero direction when orthographic) and a finite,
/// positive feature size.
fn check_view((eye, ortho): ([f32; 3], bool), feature_size: f32) -> Result<()> {
    if eye.iter().any(|c| !c.is_finite()) || (ortho && eye == [0.0; 3]) {
        return Err(Error::InvalidArgument(format!(
            "feature lines: invalid view ({}) (finite eye; a non-zero direction when orthographic)",
            crate::error::values(eye, ", ")
        )));
    }
    if !(feature_size.is_finite() && feature_size > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "feature size must be finite and positive, got {feature_size}"
        )));
    }
    Ok(())
}
