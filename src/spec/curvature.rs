//! Shared types of the `curvature` family (see [`crate::spec`]).
