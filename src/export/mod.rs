//! Writers: PLY (mesh with per-vertex curvature), SVG (visible feature edges) and JSON stats.

pub mod output;
pub mod ply;
pub mod strokes;
pub mod svg;
