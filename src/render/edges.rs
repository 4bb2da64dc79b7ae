//! Drawing the edges stage's output (House & Li): the edge-out and
//! cap-out buffers as projection-space quads and triangles
//! ([`draw_edges`]), flat-coloured, into the frame in progress.
//!
//! The screen only draws what it is given: the stage
//! ([`crate::stages::edges`]) runs in the caller, which composes the two
//! (the front door's `shapecue::feature_edges_picture`, the scene executor,
//! the report's cap-quality measurement).

use super::Renderer;
use crate::error::Result;
use crate::spec::edges::EdgeOutput;

/// Draws the edge quads of `out` and the caps it holds (those of the last
/// run's mode) with flat `color` into the frame in progress.
pub fn draw_edges(r: &mut Renderer, out: &EdgeOutput, color: [f32; 4]) -> Result<()> {
    r.draw_clip_quads(&out.edge_out, color)?;
    r.draw_clip_triangles(&out.cap_mh0, color)?;
    r.draw_clip_triangles(&out.cap_mh1, color)?;
    r.draw_clip_quads(&out.cap_adj, color)
}
