//! Shared types of the `feature_lines` family (see [`crate::spec`]).
