//! Writers: PLY (mesh with per-vertex curvature), SVG (visible feature edges), NPZ (line
//! segments) and JSON stats.
//!
//! Files are written whole or not at all through [`crate::output`]
//! (re-exported here as `export::output`), which the renderer's PNG writer
//! shares; this module reads the renderer's frames and cameras, and the
//! renderer imports nothing from it.

pub use crate::output;
pub mod npz;
pub mod ply;
pub mod strokes;
pub mod svg;
