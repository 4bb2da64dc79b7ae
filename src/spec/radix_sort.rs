//! Shared types of the `radix_sort` family (see [`crate::spec`]).
