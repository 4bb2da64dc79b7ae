//! Host wiring of each kernel family in `kernels/`, one module per family.

pub mod ao;
pub mod curvature;
pub mod edges;
pub mod feature_lines;
pub mod marching_cubes;
pub mod radix_sort;
pub mod scan;
pub mod skinning;
pub mod vertex_fusion;
