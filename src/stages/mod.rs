//! Host wiring of each kernel family in `kernels/`, one module per family.

pub mod curvature;
pub mod radix_sort;
pub mod scan;
