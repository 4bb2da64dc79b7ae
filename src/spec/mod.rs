//! The spec layer: types that the host wiring (`stages`), the CPU twins
//! (`cpu`), the planner and the file formats share, in the role
//! `vello_encoding` plays for vello. Per stage family: constants, option
//! enums, output types, `#[repr(C)]` parameter structs mirrored in
//! `kernels/<family>.cl`, and the `*_bound` functions that size every
//! variable output.
//!
//! This module imports nothing from `gpu`, `stages`, `cpu`, `render` or
//! `scene` (CI checks it), so a CPU twin or the planner can use it without
//! the device.

pub mod ao;
pub mod curvature;
pub mod edges;
pub mod feature_lines;
pub mod marching_cubes;
pub mod mesh_sdf;
pub mod radix_sort;
pub mod scan;
pub mod sdf_lines;
pub mod skinning;
pub mod vertex_fusion;
pub mod view;
