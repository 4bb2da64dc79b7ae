//! Shared types of the `scan` family (see [`crate::spec`]).
