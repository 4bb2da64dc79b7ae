//! What a scene's views are written as ([`Outputs`]), and the passes that
//! end a view for it.

use super::{Cue, Pass};
use crate::spec::visibility::VisibilityMethod;
use serde::Serialize;

/// What a scene's views are written as, which decides the passes after
/// the cues' own: a raster image (PNG, or an image held in memory) needs
/// the GL render pass; a vector drawing (SVG, segments) needs the SVG
/// pass, and its hidden lines either the exact visibility pass (over the
/// BVH, no GL) or the rendered depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct Outputs {
    /// A raster image is drawn.
    pub raster: bool,
    /// A vector drawing is written.
    pub vector: bool,
    /// How the vector drawing's hidden lines are found.
    pub visibility: VisibilityMethod,
    /// The lines split where their visibility changes and chained are
    /// kept (segments with visibility, NPZ), with or without a vector
    /// drawing: exact visibility is planned for them on its own.
    pub pieces: bool,
    /// The per-vertex view fields are kept beside the lines.
    pub fields: bool,
    /// The lines' pieces are written as NPZ (exact visibility is planned
    /// for them whatever the vector drawing's method).
    pub npz: bool,
}

impl Outputs {
    /// A raster image only (PNG, or an image held in memory).
    pub const RASTER: Outputs = Outputs {
        raster: true,
        vector: false,
        visibility: VisibilityMethod::Exact,
        pieces: false,
        fields: false,
        npz: false,
    };

    /// The passes that end a view drawn from `cues`.
    pub(super) fn terminals(self, cues: &[Cue]) -> Vec<Pass> {
        let lines = cues.iter().any(|c| c.draws_lines());
        let mut v = Vec::new();
        if self.raster || (self.vector && self.visibility == VisibilityMethod::Depth) {
            v.push(Pass::Render);
        }
        if self.vector {
            v.push(Pass::Svg);
        }
        // Exact visibility serves the vector drawing and the kept pieces
        // alike; it is planned for either, and for neither without lines.
        if (self.vector || self.pieces) && self.visibility == VisibilityMethod::Exact && lines {
            v.push(Pass::Visibility);
        }
        // The fields are those of the line families (not of edges alone).
        let families = (cues.iter())
            .any(|c| c.family().is_some() || matches!(c, Cue::Contours | Cue::SuggestiveContours));
        if self.fields && families {
            v.push(Pass::ViewFields);
        }
        if self.npz && lines {
            v.push(Pass::Npz);
        }
        v
    }
}
