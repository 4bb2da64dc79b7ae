//! Writers: PLY (mesh with per-vertex curvature) and JSON stats.

pub mod ply;
