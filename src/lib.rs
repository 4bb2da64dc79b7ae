//! shapecue: shape cues (curvature, isosurfaces, feature edges, curvature-based
//! lines and ambient occlusion) computed by OpenCL kernels, each with a plain
//! Rust reference implementation.
//!
//! Data flow (one name per stage, used for the kernel file, the host module,
//! the CPU reference, the test and the bench):
//!
//! ```text
//! mesh ─► positions ─► [curvature] ─► normals, areas, k1 k2 d1 d2 dk ─► export (PLY, JSON)
//! mesh ─► [edges] ─► edge-out + cap-out (House & Li) ─► render, SVG
//! all outputs ─► render (headless OpenGL: shaded mesh, clip-space edge quads ─► PNG)
//! ```
#![warn(missing_docs)]

pub mod cpu;
pub mod error;
pub mod export;
pub mod field;
pub mod gpu;
pub mod mesh;
pub mod render;
pub mod report;
pub mod scene;
pub mod spec;
pub mod stages;
pub mod volume;

pub use error::{Error, Result};
pub use mesh::Mesh;
