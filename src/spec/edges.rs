//! Shared types of the `edges` family (see [`crate::spec`]).
