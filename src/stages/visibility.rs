//! The device version of the `visibility` family (exact, object-space
//! visibility of line segments; method in [`crate::spec::visibility`]): the
//! queries of every segment of a view at once, one [`Bvh::occluded`] call
//! per sampling round (the samples, then one call per bisection level for
//! the brackets whose ends differ). The rounds, the queries and the pieces
//! come from the twin's [`classify_by`], so the device's pieces equal
//! [`crate::cpu::visibility::classify_twin`]'s bit for bit. No kernel of
//! its own: the work is the `bvh` family's `bvh_occluded`.
//!
//! The segments are classified in the Morton order of their midpoints
//! ([`spatial_order`]), so that neighbouring work-items of a round walk the
//! same part of the tree: on the Stanford bunny (PoCL, every line family)
//! the sample round's kernel takes 15–30 % less time than in the
//! extraction's order. The plan is built from the sorted segments, so that
//! its own arrays are read in order too. Each segment's pieces depend only
//! on its own queries: the order changes the time, not the answer.

use crate::error::{Error, Result};
use crate::spec::feature_lines::Segment;
use crate::spec::timing::Timing;
use crate::spec::view::View;
use crate::spec::visibility::{Pieces, VisibilityOptions};
use crate::spec::visibility_plan::{RayPlan, classify_by, hidden_from, queries_of};
use crate::stages::bvh::Bvh;

/// The pieces of `segments` seen in `view` over the mesh (`positions`,
/// `faces`) whose tree `bvh` holds (built or refitted to `positions`), with
/// the number of query stack overflows (answered visible; none at the
/// spec's stack depth). Errors in plain words: a tree of another mesh, bad
/// options, view or segments.
pub fn classify(
    bvh: &mut Bvh,
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    segments: &[Segment],
    view: &View,
    opts: &VisibilityOptions,
) -> Result<(Vec<Pieces>, u32)> {
    if bvh.n_faces() != faces.len() {
        return Err(Error::InvalidArgument(format!(
            "visibility: a tree of {} faces for a mesh of {} faces",
            bvh.n_faces(),
            faces.len()
        )));
    }
    let order = spatial_order(segments);
    let sorted: Vec<Segment> = order.iter().map(|&i| segments[i]).collect();
    let plan = match RayPlan::new(positions, faces, &sorted, view, opts) {
        Ok(plan) => plan,
        // The error names a segment by its place in `sorted`: the caller's
        // order names it by the caller's index.
        Err(e) => {
            return Err(RayPlan::new(positions, faces, segments, view, opts)
                .err()
                .unwrap_or(e));
        }
    };
    let c = classify_planned(bvh, &plan)?;
    Ok((unsort(&order, c.pieces), c.overflows))
}

/// What [`classify_planned`] found and what it cost.
#[derive(Clone, Debug, Default)]
pub struct Classified {
    /// The pieces of each segment.
    pub pieces: Vec<Pieces>,
    /// Query stack overflows (answered visible; none at the spec's depth).
    pub overflows: u32,
    /// Rounds (one `bvh_occluded` launch each).
    pub rounds: usize,
    /// Queries in all.
    pub queries: usize,
    /// Kernel time of the rounds' launches.
    pub timing: Timing,
}

/// [`classify`] of segments already read into a [`RayPlan`] (whose faces each
/// segment lies on the caller may want too), in the plan's order (build it
/// from segments in [`spatial_order`] for speed), over a tree of the plan's
/// mesh.
pub fn classify_planned(bvh: &mut Bvh, plan: &RayPlan) -> Result<Classified> {
    let mut c = Classified::default();
    let pieces = classify_by(plan, |casts| {
        let (qs, at) = queries_of(plan, casts);
        let (answers, o) = bvh.occluded(&qs)?;
        c.overflows += o;
        c.rounds += 1;
        c.queries += qs.len();
        c.timing.extend(bvh.timing());
        Ok(hidden_from(&at, &answers))
    })?;
    c.pieces = pieces;
    Ok(c)
}

/// The order in which [`classify`] takes `segments`: the Morton order of
/// their midpoints (10 bits per axis over the midpoints' box; ties in
/// segment order), as indices into `segments`.
pub fn spatial_order(segments: &[Segment]) -> Vec<usize> {
    if segments.len() > u32::MAX as usize {
        return (0..segments.len()).collect();
    }
    let mid = |s: &Segment| -> [f32; 3] { std::array::from_fn(|k| 0.5 * s.a[k] + 0.5 * s.b[k]) };
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for m in segments.iter().map(mid) {
        for k in 0..3 {
            lo[k] = lo[k].min(m[k]);
            hi[k] = hi[k].max(m[k]);
        }
    }
    let scale: [f32; 3] = std::array::from_fn(|k| {
        let e = hi[k] - lo[k];
        if e > 0.0 && e.is_finite() {
            1023.0 / e
        } else {
            0.0
        }
    });
    // NaN and the infinities land in a cell like any other value (`as`
    // saturates); RayPlan::new rejects them after.
    let spread = |v: u64| (0..10).fold(0, |m, b| m | (((v >> b) & 1) << (3 * b)));
    let cell =
        |m: [f32; 3], k: usize| spread(((m[k] - lo[k]) * scale[k]).clamp(0.0, 1023.0) as u64);
    let mut keyed: Vec<u64> = (segments.iter().enumerate())
        .map(|(i, s)| {
            let m = mid(s);
            let code = (cell(m, 0) << 2) | (cell(m, 1) << 1) | cell(m, 2);
            (code << 32) | i as u64
        })
        .collect();
    keyed.sort_unstable();
    keyed
        .into_iter()
        .map(|k| (k & 0xffff_ffff) as usize)
        .collect()
}

/// Pieces in [`spatial_order`]'s `order`, put back in the segments' own
/// order.
pub fn unsort(order: &[usize], sorted: Vec<Pieces>) -> Vec<Pieces> {
    let mut pieces = vec![Pieces::new(); sorted.len()];
    for (&i, p) in order.iter().zip(sorted) {
        pieces[i] = p;
    }
    pieces
}
