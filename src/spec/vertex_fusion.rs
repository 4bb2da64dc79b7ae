//! Shared types of the `vertex_fusion` family (see [`crate::spec`]).
