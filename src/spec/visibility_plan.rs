//! The host half of the `visibility` family's method (exact, object-space
//! visibility of line segments; options and output in
//! [`crate::spec::visibility`]), shared by the device stage
//! (`stages::visibility`), its twin and the f64 reference
//! (`cpu::visibility`): the plan of the queries and the rounds that turn
//! their answers into pieces.
//!
//! [`RayPlan::new`] reads the segments once: the faces each one lies on (left
//! out of its queries, at most four), its number of sampling intervals, the
//! local edge length that scales the contour offset, and the bounding sphere
//! that orthographic queries cross. [`classify_by`] runs the rounds (the
//! samples, then one round per bisection level over the brackets whose ends
//! differ) through a caller's cast function, one call per round, and turns
//! the answers into pieces. The queries are built here, in the same f32
//! operations for the device and the twin, so that their answers agree bit
//! for bit.
//!
//! Which faces a segment lies on, from its ends' edges ([`Segment`]): an
//! end on a mesh edge names the edge's faces, an end at a face centre or
//! cut by a test (`[u32::MAX or LINE_FREE, face]`) its face, an end at a
//! vertex (`[v, v]`) the faces around the vertex, an end on no face
//! ([`NO_FACE`]: a stroke on a distance field) none. The segment lies on the
//! faces both ends name (normally one); where they share none (an edge
//! unknown to the mesh), on the union. The first four are kept.

use crate::error::{Error, Result};
use crate::spec::bvh::{BvhQuery, OCCLUDED};
use crate::spec::feature_lines::{LINE_FREE, Segment};
use crate::spec::view::View;
use crate::spec::visibility::{Faces, MAX_INTERVALS, NO_FACE, Pieces, Spacing, VisibilityOptions};

mod ends;
use ends::shared_ends;

/// One sample of one segment: `(segment index, t)`.
pub type Cast = (u32, f32);

/// What one segment needs for its queries.
#[derive(Clone, Debug, PartialEq)]
pub struct SegPlan {
    /// First end.
    pub a: [f32; 3],
    /// Second end.
    pub b: [f32; 3],
    /// Faces left out of its queries (at most four).
    pub exclude: Faces,
    /// Sampling intervals (1 to [`MAX_INTERVALS`]).
    pub intervals: usize,
    /// Start of each query along the ray (world units).
    pub offset: f32,
    /// Its ends' samples ([`RayPlan::ends`]).
    pub end_ids: [u32; 2],
}

/// The sample at a segment end, shared by the segments that end there: the
/// ends on one mesh edge (where a line crosses it into the next face), or
/// at one mesh vertex, are sampled once. Its point is the least of their
/// points (by the bits of their coordinates: they differ by rounding, and the choice
/// does not depend on the segments' order), it leaves out the faces they
/// lie on and starts at the largest of their offsets. Where they lie on
/// more than four faces (more than a query leaves out), each keeps its own.
#[derive(Clone, Debug, PartialEq)]
pub struct EndPlan {
    /// The point sampled.
    pub p: [f32; 3],
    /// Faces left out of its query.
    pub exclude: Faces,
    /// Start of its query along the ray (world units).
    pub offset: f32,
}

/// The segments of one view, ready to classify.
#[derive(Clone, Debug, PartialEq)]
pub struct RayPlan {
    /// Per segment.
    pub segs: Vec<SegPlan>,
    /// The segments' end samples, shared where ends meet.
    pub ends: Vec<EndPlan>,
    /// The view's eye, unit view direction, near plane and projection kind.
    pub view: View,
    /// Centre and radius of the mesh's bounding sphere (orthographic casts).
    pub sphere: ([f32; 3], f32),
    /// Bisection levels.
    pub bisect: u32,
}

/// Faces around each vertex, in compressed rows: `around[start[v]..start[v
/// + 1]]`, in face order, a face once per corner at the vertex.
struct VertexFaces<'a> {
    faces: &'a [[u32; 3]],
    start: Vec<usize>,
    around: Vec<u32>,
}

impl<'a> VertexFaces<'a> {
    fn new(n_vertices: usize, faces: &'a [[u32; 3]]) -> VertexFaces<'a> {
        let mut start = vec![0usize; n_vertices + 1];
        for &v in faces.iter().flatten() {
            start[v as usize + 1] += 1;
        }
        for v in 0..n_vertices {
            start[v + 1] += start[v];
        }
        let mut next = start.clone();
        let mut around = vec![0u32; 3 * faces.len()];
        for (f, t) in faces.iter().enumerate() {
            for &v in t {
                around[next[v as usize]] = f as u32;
                next[v as usize] += 1;
            }
        }
        VertexFaces {
            faces,
            start,
            around,
        }
    }

    fn around(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.around[self.start[v]..self.start[v + 1]]
    }

    /// Appends the faces on the edge `(u, v)` (`u ≠ v`) to `out`, in face
    /// order, a face once per side it has on the edge.
    fn edge_faces(&self, u: u32, v: u32, out: &mut Vec<u32>) {
        let key = (u.min(v), u.max(v));
        let mut last = None;
        for &f in self.around(u) {
            if last.replace(f) == Some(f) {
                continue;
            }
            let t = self.faces[f as usize];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if (a.min(b), a.max(b)) == key {
                    out.push(f);
                }
            }
        }
    }

    /// The faces an end names (see the module note) into `out` (cleared
    /// first), or a plain-words error naming segment `i`'s `which` end.
    fn end_faces(&self, e: [u32; 2], i: usize, which: &str, out: &mut Vec<u32>) -> Result<()> {
        out.clear();
        let n_faces = self.faces.len();
        if e == NO_FACE {
            return Ok(());
        }
        if e[0] == u32::MAX || e[0] == LINE_FREE {
            if e[1] as usize >= n_faces {
                return Err(Error::InvalidArgument(format!(
                    "segment {i}, {which} end: names face {} of a mesh of {n_faces} faces",
                    e[1]
                )));
            }
            out.push(e[1]);
            return Ok(());
        }
        let n_vertices = self.start.len() - 1;
        if e.iter().any(|&v| v as usize >= n_vertices) {
            return Err(Error::InvalidArgument(format!(
                "segment {i}, {which} end: names vertex {} of a mesh of {n_vertices} vertices",
                e[0].max(e[1]),
            )));
        }
        if e[0] == e[1] {
            out.extend_from_slice(self.around(e[0]));
        } else {
            self.edge_faces(e[0], e[1], out);
        }
        Ok(())
    }
}

/// The faces segment `s` (index `i`) lies on (at most four); `f0` and `f1`
/// are scratch space for its ends' faces.
fn lies_on(
    topo: &VertexFaces,
    s: &Segment,
    i: usize,
    [f0, f1]: [&mut Vec<u32>; 2],
) -> Result<Faces> {
    topo.end_faces(s.ends[0], i, "first", f0)?;
    topo.end_faces(s.ends[1], i, "second", f1)?;
    let mut both = Faces::default();
    for &f in f0.iter().filter(|f| f1.contains(f)) {
        if !both.push(f) {
            break;
        }
    }
    if !both.is_empty() {
        return Ok(both);
    }
    let mut all = Faces::default();
    let rest = f1.iter().filter(|f| !f0.contains(f));
    for &f in f0.iter().chain(rest) {
        if !all.push(f) {
            break;
        }
    }
    Ok(all)
}

fn sub(x: [f32; 3], y: [f32; 3]) -> [f32; 3] {
    [x[0] - y[0], x[1] - y[1], x[2] - y[2]]
}

fn norm(x: [f32; 3]) -> f32 {
    (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
}

/// Box centre and half diagonal of `positions`.
fn bounding_sphere(positions: &[[f32; 3]]) -> ([f32; 3], f32) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if positions.is_empty() {
        return ([0.0; 3], 0.0);
    }
    let c = [
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    ];
    (c, 0.5 * norm(sub(hi, lo)))
}

/// Sampling intervals of the segment `a..b`.
fn intervals(view: &View, spacing: Spacing, diag: f32, a: [f32; 3], b: [f32; 3]) -> usize {
    let n = match spacing {
        Spacing::Diagonal(f) => norm(sub(b, a)) / (f * diag),
        Spacing::View(f) => {
            let pa = view.view_proj * glam::Vec4::new(a[0], a[1], a[2], 1.0);
            let pb = view.view_proj * glam::Vec4::new(b[0], b[1], b[2], 1.0);
            if pa.w > 0.0 && pb.w > 0.0 {
                let d = pa.truncate().truncate() / pa.w - pb.truncate().truncate() / pb.w;
                0.5 * d.length() / f
            } else {
                MAX_INTERVALS as f32
            }
        }
    };
    if n.is_finite() {
        (n.ceil() as usize).clamp(1, MAX_INTERVALS)
    } else {
        MAX_INTERVALS
    }
}

/// What each segment's plan reads of the mesh.
struct PlanMesh<'a> {
    positions: &'a [[f32; 3]],
    faces: &'a [[u32; 3]],
    topo: &'a VertexFaces<'a>,
    /// The bounding box's diagonal.
    diag: f32,
}

/// Segments per thread below which the plans are made on one thread.
const SEGMENTS_PER_THREAD: usize = 8192;

/// The threads a plan of `n` segments is made on: the machine's cores (at
/// most 16), at least [`SEGMENTS_PER_THREAD`] segments each.
fn plan_threads(n: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    (n / SEGMENTS_PER_THREAD).clamp(1, cores.min(16))
}

/// The plan of each of `segments` (its end samples not yet shared): made
/// in contiguous runs of segments on the machine's cores, each plan from
/// its own segment alone, so the plans are the same on any number of
/// threads. The error is the first segment's (in segment order) that has
/// one.
fn seg_plans(
    mesh: &PlanMesh,
    segments: &[Segment],
    view: &View,
    opts: &VisibilityOptions,
    threads: usize,
) -> Result<Vec<SegPlan>> {
    if threads <= 1 {
        return seg_plans_of(mesh, segments, 0, view, opts);
    }
    let chunk = segments.len().div_ceil(threads);
    let parts: Vec<Result<Vec<SegPlan>>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (segments.chunks(chunk).enumerate())
            .map(|(k, part)| scope.spawn(move || seg_plans_of(mesh, part, k * chunk, view, opts)))
            .collect();
        (handles.into_iter())
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    let mut segs = Vec::with_capacity(segments.len());
    for part in parts {
        segs.extend(part?);
    }
    Ok(segs)
}

/// The plans of `segments`, the first of which is segment `first`.
fn seg_plans_of(
    mesh: &PlanMesh,
    segments: &[Segment],
    first: usize,
    view: &View,
    opts: &VisibilityOptions,
) -> Result<Vec<SegPlan>> {
    let (positions, faces, diag) = (mesh.positions, mesh.faces, mesh.diag);
    let mut segs = Vec::with_capacity(segments.len());
    let (mut f0, mut f1) = (Vec::new(), Vec::new());
    for (k, s) in segments.iter().enumerate() {
        let i = first + k;
        if !s.a.iter().chain(&s.b).all(|c| c.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "visibility: segment {i} has a non-finite end"
            )));
        }
        let exclude = lies_on(mesh.topo, s, i, [&mut f0, &mut f1])?;
        let edge = match exclude.first() {
            Some(&f) => {
                let p = faces[f as usize].map(|v| positions[v as usize]);
                (norm(sub(p[1], p[0])) + norm(sub(p[2], p[1])) + norm(sub(p[0], p[2]))) / 3.0
            }
            None => norm(sub(s.b, s.a)),
        };
        let edge = if edge > 0.0 { edge } else { 1e-3 * diag };
        segs.push(SegPlan {
            a: s.a,
            b: s.b,
            exclude,
            intervals: intervals(view, opts.spacing, diag, s.a, s.b).max(grazing_intervals(s)),
            offset: opts.contour_offset * edge,
            end_ids: [0; 2],
        });
    }
    Ok(segs)
}

impl RayPlan {
    /// Reads `segments` over the mesh (`positions`, `faces`) seen in
    /// `view`. Errors, in plain words: bad options or view, a non-finite
    /// end, an end naming a vertex or face the mesh lacks.
    pub fn new(
        positions: &[[f32; 3]],
        faces: &[[u32; 3]],
        segments: &[Segment],
        view: &View,
        opts: &VisibilityOptions,
    ) -> Result<RayPlan> {
        let mesh = (positions, faces);
        Self::on_threads(mesh, segments, view, opts, plan_threads(segments.len()))
    }

    /// [`RayPlan::new`] made on `threads` threads (the same plan on any
    /// number).
    fn on_threads(
        (positions, faces): (&[[f32; 3]], &[[u32; 3]]),
        segments: &[Segment],
        view: &View,
        opts: &VisibilityOptions,
        threads: usize,
    ) -> Result<RayPlan> {
        opts.check()?;
        view.check("visibility")?;
        crate::spec::bvh::check_faces("visibility mesh", positions.len(), faces)?;
        crate::spec::bvh::check_positions("visibility mesh", positions.len(), positions)?;
        let topo = VertexFaces::new(positions.len(), faces);
        let sphere = bounding_sphere(positions);
        let diag = (2.0 * sphere.1).max(f32::MIN_POSITIVE);
        let mesh = PlanMesh {
            positions,
            faces,
            topo: &topo,
            diag,
        };
        let mut segs = seg_plans(&mesh, segments, view, opts, threads)?;
        // The two faces of an edge round its crossing apart by a few ulps
        // of the coordinates.
        let reach = positions.iter().flatten().fold(0f32, |m, c| m.max(c.abs()));
        let tol = (1e-6 * diag).max(64.0 * f32::EPSILON * reach);
        let ends = shared_ends(segments, &mut segs, positions.len(), tol, threads);
        Ok(RayPlan {
            segs,
            ends,
            view: *view,
            sphere,
            bisect: opts.bisect,
        })
    }

    /// The plan of the segments `at` only (indices into [`RayPlan::segs`]),
    /// their ends sampled as in the whole view (shared with segments left
    /// out): a reference over a subset answers as over every segment.
    pub fn subset(&self, at: &[usize]) -> RayPlan {
        RayPlan {
            segs: at.iter().map(|&i| self.segs[i].clone()).collect(),
            ends: self.ends.clone(),
            view: self.view,
            sphere: self.sphere,
            bisect: self.bisect,
        }
    }

    /// The f32 query of a cast, or `None` where the point is behind the
    /// eye (hidden without a query). The device and the twin both take
    /// their queries from here.
    pub fn query(&self, cast: Cast) -> Option<BvhQuery> {
        let (p, exclude, offset) = self.sample(cast);
        let eye = self.view.eye.to_array();
        let dir = self.view.unit_dir().to_array();
        let (u, far) = if self.view.ortho {
            let u = dir.map(|c| -c);
            let (c, r) = self.sphere;
            (u, (norm(sub(p, c)) + r) * 1.001 + 1e-6)
        } else {
            let d = sub(p, eye);
            if d[0] * dir[0] + d[1] * dir[1] + d[2] * dir[2] < self.view.near {
                return None;
            }
            let len = norm(d);
            (d.map(|c| -c / len), len)
        };
        let off = offset.min(0.5 * far);
        let origin = std::array::from_fn(|k| p[k] + off * u[k]);
        let target = if self.view.ortho {
            std::array::from_fn(|k| p[k] + far * u[k])
        } else {
            eye
        };
        Some(BvhQuery::new(origin, target, exclude))
    }

    /// The point, left-out faces and offset of a cast: a segment's end
    /// (`t` 0 or 1) is its shared end sample ([`EndPlan`]), any other `t`
    /// its own point.
    fn sample(&self, (seg, t): Cast) -> ([f32; 3], &[u32], f32) {
        let s = &self.segs[seg as usize];
        let end = match t {
            0.0 => Some(s.end_ids[0]),
            1.0 => Some(s.end_ids[1]),
            _ => None,
        };
        match end {
            Some(e) => {
                let e = &self.ends[e as usize];
                (e.p, e.exclude.as_slice(), e.offset)
            }
            None => (
                std::array::from_fn(|k| s.a[k] + t * (s.b[k] - s.a[k])),
                s.exclude.as_slice(),
                s.offset,
            ),
        }
    }

    /// The f64 query of a cast (the reference's): the same construction as
    /// [`RayPlan::query`] in f64, as its origin, target and the faces it
    /// leaves out; `None` behind the eye (hidden).
    pub fn query_f64(&self, cast: Cast) -> Option<([f64; 3], [f64; 3], &[u32])> {
        let s = &self.segs[cast.0 as usize];
        let t = f64::from(cast.1);
        let (a, b) = (s.a.map(f64::from), s.b.map(f64::from));
        let (p, exclude, offset): ([f64; 3], &[u32], f32) = match cast.1 {
            0.0 | 1.0 => {
                let (p, exclude, offset) = self.sample(cast);
                (p.map(f64::from), exclude, offset)
            }
            _ => (
                std::array::from_fn(|k| a[k] + t * (b[k] - a[k])),
                s.exclude.as_slice(),
                s.offset,
            ),
        };
        let eye = self.view.eye.as_dvec3().to_array();
        let dir = self.view.dir.as_dvec3().normalize().to_array();
        let n3 = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        let (u, far) = if self.view.ortho {
            let c = self.sphere.0.map(f64::from);
            let d: [f64; 3] = std::array::from_fn(|k| p[k] - c[k]);
            (
                dir.map(|c| -c),
                (n3(d) + f64::from(self.sphere.1)) * 1.001 + 1e-6,
            )
        } else {
            let d: [f64; 3] = std::array::from_fn(|k| p[k] - eye[k]);
            if d[0] * dir[0] + d[1] * dir[1] + d[2] * dir[2] < f64::from(self.view.near) {
                return None;
            }
            let len = n3(d);
            (d.map(|c| -c / len), len)
        };
        let off = f64::from(offset).min(0.5 * far);
        let origin = std::array::from_fn(|k| p[k] + off * u[k]);
        let target = if self.view.ortho {
            std::array::from_fn(|k| p[k] + far * u[k])
        } else {
            eye
        };
        Some((origin, target, exclude))
    }
}

/// The least intervals of a segment: 2 for the contour families (occluding
/// and suggestive contours, kinds 0 and 1), which lie on the grazing set,
/// where a short segment can be hidden in its middle behind the fold it
/// bounds while both its ends are seen; 1 for the others.
fn grazing_intervals(s: &Segment) -> usize {
    if s.family <= 1 { 2 } else { 1 }
}

/// The queries of `casts` that need one, and for each cast the index of
/// its query (`None`: behind the eye, hidden).
pub fn queries_of(plan: &RayPlan, casts: &[Cast]) -> (Vec<BvhQuery>, Vec<Option<usize>>) {
    let mut qs = Vec::with_capacity(casts.len());
    let at = casts
        .iter()
        .map(|&c| {
            plan.query(c).map(|q| {
                qs.push(q);
                qs.len() - 1
            })
        })
        .collect();
    (qs, at)
}

/// Hidden flags of `casts` from the answers to [`queries_of`]'s queries
/// (only [`OCCLUDED`] hides: a stack overflow, never seen at the spec's
/// depth, counts as visible).
pub fn hidden_from(at: &[Option<usize>], answers: &[u32]) -> Vec<bool> {
    at.iter()
        .map(|a| a.is_none_or(|i| answers[i] == OCCLUDED))
        .collect()
}

/// The first round's casts: every segment's samples `t = k / n`, its ends
/// sampled once per shared end ([`EndPlan`]); for each sample (segments in
/// order, `k` in order) its cast's index; each segment's first sample.
fn sample_casts(plan: &RayPlan) -> (Vec<Cast>, Vec<usize>, Vec<usize>) {
    let mut casts = Vec::new();
    let mut slots = Vec::new();
    let mut first = Vec::with_capacity(plan.segs.len());
    let mut end_cast = vec![usize::MAX; plan.ends.len()];
    for (i, s) in plan.segs.iter().enumerate() {
        first.push(slots.len());
        let n = s.intervals;
        for k in 0..=n {
            let end = match k {
                0 => Some(s.end_ids[0] as usize),
                k if k == n => Some(s.end_ids[1] as usize),
                _ => None,
            };
            let c = match end.map(|e| (e, end_cast[e])) {
                Some((_, c)) if c != usize::MAX => c,
                _ => {
                    casts.push((i as u32, k as f32 / n as f32));
                    if let Some(e) = end {
                        end_cast[e] = casts.len() - 1;
                    }
                    casts.len() - 1
                }
            };
            slots.push(c);
        }
    }
    (casts, slots, first)
}

/// A bracket between two samples whose answers differ.
struct Bracket {
    seg: u32,
    interval: usize,
    lo: f32,
    hi: f32,
    hidden_lo: bool,
}

/// The rounds of a classification through `cast` (one call per round: the
/// samples, then one per bisection level), turned into pieces.
pub fn classify_by(
    plan: &RayPlan,
    mut cast: impl FnMut(&[Cast]) -> Result<Vec<bool>>,
) -> Result<Vec<Pieces>> {
    let (casts, slots, first) = sample_casts(plan);
    let answers = cast(&casts)?;
    let hidden: Vec<bool> = slots.iter().map(|&c| answers[c]).collect();
    let mut brackets = Vec::new();
    for (i, s) in plan.segs.iter().enumerate() {
        for k in 0..s.intervals {
            let (h0, h1) = (hidden[first[i] + k], hidden[first[i] + k + 1]);
            if h0 != h1 {
                let n = s.intervals as f32;
                let (lo, hi) = (k as f32 / n, (k + 1) as f32 / n);
                let (seg, interval, hidden_lo) = (i as u32, k, h0);
                brackets.push(Bracket {
                    seg,
                    interval,
                    lo,
                    hi,
                    hidden_lo,
                });
            }
        }
    }
    for _ in 0..plan.bisect {
        if brackets.is_empty() {
            break;
        }
        let mids: Vec<Cast> = brackets
            .iter()
            .map(|b| (b.seg, 0.5 * (b.lo + b.hi)))
            .collect();
        let h = cast(&mids)?;
        for ((b, m), h) in brackets.iter_mut().zip(&mids).zip(h) {
            if h == b.hidden_lo {
                b.lo = m.1;
            } else {
                b.hi = m.1;
            }
        }
    }
    Ok(pieces(plan, &first, &hidden, &brackets))
}

/// Pieces from the sample answers and the final brackets.
fn pieces(plan: &RayPlan, first: &[usize], hidden: &[bool], brackets: &[Bracket]) -> Vec<Pieces> {
    let mut next = brackets.iter().peekable();
    let mut out = Vec::with_capacity(plan.segs.len());
    for (i, s) in plan.segs.iter().enumerate() {
        let mut ps = Pieces::new();
        let (mut start, mut cur) = (0.0f32, hidden[first[i]]);
        for k in 0..s.intervals {
            if hidden[first[i] + k + 1] == cur {
                continue;
            }
            let b = next.next().filter(|b| b.seg == i as u32 && b.interval == k);
            let split = b.map_or(start, |b| 0.5 * (b.lo + b.hi));
            ps.push((start, split, !cur));
            (start, cur) = (split, !cur);
        }
        ps.push((start, 1.0, !cur));
        out.push(ps);
    }
    out
}

/// Length-weighted share of `[0, 1]` on which two piece lists agree, and
/// the length they cover: `(agreeing length, total length)` in world units
/// of the segment `len`.
pub fn agreement(a: &Pieces, b: &Pieces, len: f64) -> (f64, f64) {
    let at = |ps: &Pieces, t: f32| ps.iter().find(|p| t <= p.1).is_none_or(|p| p.2);
    let mut cuts: Vec<f32> = a.iter().chain(b).flat_map(|p| [p.0, p.1]).collect();
    cuts.push(0.0);
    cuts.push(1.0);
    cuts.sort_by(f32::total_cmp);
    let mut same = 0.0;
    for w in cuts.windows(2) {
        let mid = 0.5 * (w[0] + w[1]);
        if at(a, mid) == at(b, mid) {
            same += f64::from(w[1] - w[0]);
        }
    }
    (same * len, len)
}

#[cfg(test)]
mod tests;
