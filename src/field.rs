//! Per-vertex curvature outputs and options, now defined in
//! [`crate::spec::curvature`]; this module keeps the old paths working.

pub use crate::spec::curvature::*; // compat re-export
