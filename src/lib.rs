//! shapecue: shape cues (curvature, isosurfaces, feature edges, curvature-based
//! lines and ambient occlusion) computed by OpenCL kernels, each with a plain
//! Rust reference implementation (its CPU twin).
//!
//! Data flow (one name per stage family, used for the kernel file, the host
//! module, the CPU twin, the test, the bench group, the planner pass and the
//! stats keys; see `ARCHITECTURE.md`):
//!
//! ```text
//! mesh file ─► mesh::load ─┐                     (topology once: mesh::topology, mesh::edges)
//! glTF / libigl / frames ──┴─► [skinning] ─► positions ─┬─► [curvature] ─► k1 k2 d1 d2 dk ─┬─► [feature_lines]
//!                                                       │                                  └─► [ao]
//!                                                       └─► [edges] ─► edge-out + cap-out
//! volume file / SDF ─► volume::load ─► [marching_cubes] ─► [vertex_fusion: radix_sort, scan] ─► mesh ─► (above)
//!                                   └─► [sdf_lines] ─► strokes
//! mesh ─► [mesh_sdf] ─► volume ─► (above)
//! all outputs ─► render/ (headless GL, PNG)   export/ (PLY, SVG, JSON; written whole or not at all)
//! scene file ─► scene::planner (cues → passes, pure data) ─► scene::exec (runs exactly those passes)
//! ```
//!
//! The front door is one call per task ([`curvature()`], [`isosurface()`],
//! [`feature_edges()`] and [`feature_edges_picture()`], [`strokes()`], [`render_scene()`], each with an `_on` form taking a
//! device; defined in [`api`]), beside the stateful per-topology types for
//! deforming meshes ([`stages::curvature::CurvatureEstimator`],
//! [`stages::marching_cubes::Isosurfacer`], [`stages::edges::EdgeStage`],
//! [`stages::pipeline::PosePipeline`], ...). The CPU twins of the calls have
//! the same signatures ([`cpu::curvature::curvature`],
//! [`cpu::edges::feature_edges`]).
#![warn(missing_docs)]

pub mod api;
pub mod cpu;
pub mod error;
pub mod export;
pub mod gpu;
pub mod mesh;
pub mod output;
pub mod render;
pub mod report;
pub mod scene;
pub mod spec;
pub mod stages;
pub mod volume;

/// The Rust example of README.md, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

pub use api::{
    CurvatureJob, CurvatureRun, EdgePicture, EdgePictureOptions, IsoOptions, Isosurface,
    LinesPicture, LinesPictureOptions, MeshSource, PictureOptions, Shot, Strokes, StrokesInput,
    StrokesOptions, curvature, curvature_of, curvature_on, feature_edges, feature_edges_on,
    feature_edges_picture, feature_edges_picture_on, isosurface, isosurface_on, lines_picture,
    lines_picture_on, render_scene, render_scene_on, strokes, strokes_on,
};
pub use error::{Error, Result};
pub use mesh::Mesh;
pub use spec::curvature::{Curvature, CurvatureOptions};
pub use spec::edges::{EdgeOptions, EdgeOutput};
pub use spec::marching_cubes::Inside;
