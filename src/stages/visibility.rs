//! The device version of the `visibility` family (exact, object-space
//! visibility of line segments; method in [`crate::spec::visibility`]): the
//! queries of every segment of a view at once, one [`Bvh::occluded`] call
//! per sampling round (the samples, then one call per bisection level for
//! the brackets whose ends differ). The rounds, the queries and the pieces
//! come from the twin's [`classify_by`], so the device's pieces equal
//! [`crate::cpu::visibility::classify_twin`]'s bit for bit. No kernel of
//! its own: the work is the `bvh` family's `bvh_occluded`.

use crate::cpu::visibility::{Plan, classify_by, hidden_from, queries_of};
use crate::error::{Error, Result};
use crate::spec::feature_lines::Segment;
use crate::spec::timing::Timing;
use crate::spec::view::View;
use crate::spec::visibility::{Pieces, VisibilityOptions};
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
    let plan = Plan::new(positions, faces, segments, view, opts)?;
    let c = classify_planned(bvh, &plan)?;
    Ok((c.pieces, c.overflows))
}

/// What [`classify_planned`] found and what it cost.
#[derive(Clone, Debug, Default)]
pub struct Classified {
    /// The pieces of each segment.
    pub pieces: Vec<Pieces>,
    /// Query stack overflows (answered visible; none at the spec's depth).
    pub overflows: u32,
    /// Rounds (one `bvh_occluded` launch each) and queries in all.
    pub rounds: usize,
    /// Queries in all.
    pub queries: usize,
    /// Kernel time of the rounds' launches.
    pub timing: Timing,
}

/// [`classify`] of segments already read into a [`Plan`] (whose faces each
/// segment lies on the caller may want too), over a tree of the plan's mesh.
pub fn classify_planned(bvh: &mut Bvh, plan: &Plan) -> Result<Classified> {
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
