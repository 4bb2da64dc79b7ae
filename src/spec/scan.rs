//! Shared types of the `scan` family (see [`crate::spec`]): how the device
//! splits `n` values into contiguous chunks ([`chunking`], built on
//! [`split`], which the radix sort's blocks use too) and the size of its
//! scratch ([`partials_len_bound`]).
//!
//! Mirrors in `kernels/scan.cl`: the `n`, `chunk`, `chunks` scalar arguments
//! of `scan_block_sums` and `scan_apply` are [`chunking`]`(n)`, and the
//! kernels' `CHUNK_RANGE` macro is the same split (the last chunk shorter);
//! `partials` is `ulong[C]`, C ≤ [`MAX_CHUNKS`], and `total` `ulong[1]`.
//! Scalar arguments only: no parameter struct crosses. The CPU twin
//! (`cpu::scan`) is one serial loop: chunking does not change the result.

/// Largest number of chunks (work-items) of one scan. A few thousand keeps
/// every core busy on any device while the serial scan of the partials stays
/// in the microseconds, so no second level is needed.
pub const MAX_CHUNKS: usize = 4096;

/// Smallest chunk: below this, per-work-item overhead dominates the loop.
pub const MIN_CHUNK: usize = 256;

/// Splits `n` items into at most `max_parts` contiguous parts of at least
/// `min_len` items (the last one shorter): `(len, parts)` with
/// `parts = ceil(n / len)`, `(0, 0)` for `n = 0`. The one split of the
/// scan's chunks and the radix sort's blocks.
pub fn split(n: usize, max_parts: usize, min_len: usize) -> (usize, usize) {
    if n == 0 {
        return (0, 0);
    }
    let len = n.div_ceil(max_parts).max(min_len);
    (len, n.div_ceil(len))
}

/// The chunk length and chunk count the device uses for `n` values
/// (`chunks = ceil(n / chunk) <= MAX_CHUNKS`; `(0, 0)` for `n = 0`).
pub fn chunking(n: usize) -> (usize, usize) {
    split(n, MAX_CHUNKS, MIN_CHUNK)
}

/// Entries of the `partials` buffer (`ulong`), enough for any `n`: one per
/// chunk, at most [`MAX_CHUNKS`]. With the `total` it is the scan's whole
/// scratch, allocated once.
pub fn partials_len_bound() -> usize {
    MAX_CHUNKS
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/scan.cl`.
    pub enum ScanKernel {
        /// Sum of each block.
        BlockSums = "scan_block_sums",
        /// Exclusive scan of the block sums.
        Partials = "scan_partials",
        /// Each block scanned, offset by its partial.
        Apply = "scan_apply",
    }
}
