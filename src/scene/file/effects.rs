//! The resolved `[effects]` of a scene: every cue's parameters with their
//! defaults filled in (read by `Scene::from_str`).

use super::LineEffects;
use crate::scene::planner::Cue;
use crate::spec::ao::AoMode;
use crate::spec::edges::CapMode;
use crate::spec::feature_lines::FeatureSize;

/// Curvature colour, AO, line and edge parameters, resolved with defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct Effects {
    /// The cues asked for.
    pub cues: Vec<Cue>,
    /// Shading base colour.
    pub base_color: [f32; 3],
    /// Ambient term.
    pub ambient: f32,
    /// Curvature colour scale (None: from the first pose).
    pub curvature_scale: Option<f32>,
    /// AO level.
    pub ao_mode: AoMode,
    /// AO radius as a fraction of the bounding-box diagonal.
    pub ao_radius: f32,
    /// Contour width and colour.
    pub contour: (f32, [f32; 3]),
    /// Suggestive contour width and colour.
    pub suggestive: (f32, [f32; 3]),
    /// Intersection line width and colour.
    pub intersection: (f32, [f32; 3]),
    /// Suggestive-contour threshold (rtsc's `sug_thresh`, default 0.01).
    pub suggestive_threshold: f32,
    /// rtsc's fade of suggestive contours and highlights (default 0.03; 0:
    /// none).
    pub suggestive_fade: f32,
    /// Edge width, colour.
    pub edge: (f32, [f32; 3]),
    /// Crease angle (None: off).
    pub crease: Option<f32>,
    /// Caps.
    pub caps: CapMode,
    /// Edge contours.
    pub edge_contours: bool,
    /// Edge boundaries.
    pub edge_boundaries: bool,
    /// Depth scale k of the edge width factor max(1, k/w) (`None`: none).
    pub edge_depth_scale: Option<f32>,
    /// Contour-only edges as half quads, outward from the silhouette.
    pub edge_half_contours: bool,
    /// Marked edges: a text file of vertex-index pairs
    /// ([`crate::mesh::edges::read_marked`]).
    pub edge_marked: Option<std::path::PathBuf>,
    /// Curvature-directed strokes.
    pub strokes: StrokeEffect,
    /// The curvature line cues (ridges, valleys, ..., boundaries), with the
    /// tests and Hermite switches of `[lines]` (shared by the contours).
    pub lines: LineEffects,
    /// The length every line family's thresholds are scaled by (`[lines]
    /// feature_size`).
    pub feature_size: FeatureSize,
}

/// The `curvature_strokes` cue's parameters (world units; `None`: the
/// `sdf_lines` default, a multiple of the sampling distance).
#[derive(Debug, Clone, PartialEq)]
pub struct StrokeEffect {
    /// Poisson-disk seed spacing.
    pub spacing: Option<f64>,
    /// Hessian sampling distance: fixed, or chosen among candidates
    /// (`"auto"`: the default candidates).
    pub sampling: crate::spec::sdf_lines::Sampling,
    /// RGB.
    pub color: [f32; 3],
    /// Stroke width at the largest κ1.
    pub width: Option<f64>,
}
