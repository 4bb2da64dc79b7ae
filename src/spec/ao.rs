//! Shared types of the `ao` family (see [`crate::spec`]).
