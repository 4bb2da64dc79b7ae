//! Host wiring of each kernel family in `kernels/`, one module per family.

pub mod curvature;
