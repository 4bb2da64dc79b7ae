//! Shared types of the `skinning` family (see [`crate::spec`]): the layout of
//! the joint influences and matrices that the host uploads, the kernel reads
//! and the CPU twin (`cpu::skinning`) takes.
//!
//! Mirrors in `kernels/skinning.cl`: `joints uint[4V]` and `weights
//! float[4V]` hold [`INFLUENCES`] per vertex (the kernel's `k < 4` loop);
//! `mats float[16J]` holds [`MATRIX_FLOATS`] column-major floats per joint
//! (the kernel's `16 * j` stride), [`matrices_len`] in all. Scalar arguments
//! only: no parameter struct crosses.

/// Joint influences per vertex (joint ids and weights, 0-weight slots unused).
pub const INFLUENCES: usize = 4;

/// Floats of one joint matrix (4×4, column-major: translation in 12..15).
pub const MATRIX_FLOATS: usize = 16;

/// Floats of the matrices of one pose with `joints` joints.
pub fn matrices_len(joints: usize) -> usize {
    MATRIX_FLOATS * joints
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/skinning.cl`.
    pub enum SkinKernel {
        /// Linear blend skinning of each vertex.
        Lbs = "skin_lbs",
    }
}
