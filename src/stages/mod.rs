//! Host wiring of each kernel family in `kernels/`, one module per family,
//! and `pipeline`, which chains skinning, curvature, AO and feature lines per
//! pose on the device.

pub mod ao;
pub mod bvh;
pub mod curvature;
pub mod edges;
pub mod feature_lines;
pub mod feature_lines_curves;
pub mod intersections;
pub mod kernel_files;
pub mod marching_cubes;
pub mod mesh_sdf;
pub mod pipeline;
pub mod radix_sort;
pub mod scan;
pub mod sdf_lines;
pub mod skinning;
pub mod vertex_fusion;
pub mod visibility;
