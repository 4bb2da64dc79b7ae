//! Shared types of the `skinning` family (see [`crate::spec`]).
