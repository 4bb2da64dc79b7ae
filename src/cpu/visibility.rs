//! CPU twin and f64 reference of the `visibility` family (exact,
//! object-space visibility of line segments): the plan and rounds of
//! [`crate::spec::visibility_plan`] with the twin's cast
//! ([`classify_twin`]: [`Tree::occluded`] in f32, equal to the device bit
//! for bit) or the reference's ([`classify_reference`]: [`occluded_brute`]
//! in f64 over every face), and the agreement of two classifications.

use crate::cpu::bvh::{Tree, occluded_brute};
use crate::error::{Error, Result};
use crate::spec::visibility::Pieces;
use crate::spec::visibility_plan::{RayPlan, classify_by, hidden_from, queries_of};

/// The twin: [`classify_by`] with [`Tree::occluded`] (f32, the device's
/// arithmetic) over the tree of `positions` (an error where the tree holds
/// another number of faces).
pub fn classify_twin(
    tree: &Tree,
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    plan: &RayPlan,
) -> Result<Vec<Pieces>> {
    if tree.faces_sorted.len() != faces.len() {
        return Err(Error::InvalidArgument(format!(
            "visibility: a tree of {} faces for a mesh of {} faces",
            tree.faces_sorted.len(),
            faces.len()
        )));
    }
    classify_by(plan, |casts| {
        let (qs, at) = queries_of(plan, casts);
        let answers: Vec<u32> = qs
            .iter()
            .map(|q| tree.occluded(positions, faces, q))
            .collect();
        Ok(hidden_from(&at, &answers))
    })
}

/// The reference: [`classify_by`] with [`occluded_brute`] in f64 over every
/// face of the mesh (`positions` in f64, the plan built from their f32
/// rounding).
pub fn classify_reference(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    plan: &RayPlan,
) -> Result<Vec<Pieces>> {
    crate::spec::bvh::check_faces("visibility reference mesh", positions.len(), faces)?;
    classify_by(plan, |casts| {
        Ok(casts
            .iter()
            .map(|&c| {
                plan.query_f64(c)
                    .is_none_or(|(o, t, exclude)| occluded_brute(positions, faces, o, t, exclude))
            })
            .collect())
    })
}
