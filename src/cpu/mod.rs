//! Plain Rust reference implementations of the device stages, in f64, with
//! the same step names as the kernels. Deliberately simple: they are the
//! oracles the tests compare the device with, and never on the path the
//! product runs (`scripts/check-layers.sh` refuses an import of them from
//! `stages`, `scene` or `api`). Host steps of the product are stages
//! (`spec::chains`); what both sides need is in `spec`.

pub mod ao;
pub mod bvh;
pub mod curvature;
pub mod edges;
pub mod feature_lines;
pub mod feature_lines_curves;
pub mod intersections;
pub mod marching_cubes;
pub mod mesh_sdf;
pub mod radix_sort;
pub mod scan;
pub mod sdf_lines;
pub mod skinning;
mod vec3;
pub mod vertex_fusion;
pub mod visibility;
