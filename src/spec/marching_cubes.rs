//! Shared types of the `marching_cubes` family (see [`crate::spec`]).
