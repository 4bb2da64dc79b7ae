//! Shared types of the `sdf_lines` family (see [`crate::spec`]).
