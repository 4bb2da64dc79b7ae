//! Shared types of the `radix_sort` family (see [`crate::spec`]): the digit
//! width ([`DIGIT_BITS`], [`RADIX`], [`digits`]), the blocks of the MSD pass
//! ([`blocking`]), the histogram size ([`histogram_len_bound`]) and the
//! strategy a sort ran with ([`Strategy`], chosen by [`SKEW_LIMIT`]).
//!
//! Mirrors in `kernels/radix_sort.cl`: `RADIX_BITS` (the host passes
//! `-DRADIX_BITS=`[`DIGIT_BITS`]) and `RADIX` (= [`RADIX`]); the `n`,
//! `block`, `blocks` scalar arguments of `radix_histogram` and
//! `radix_scatter` are [`blocking`]`(n)`, and the kernels' `BLOCK_RANGE`
//! macro is the same split; `hist` is `uint[RADIX·G]`, digit-major
//! (`hist[d × G + b]`). Scalar arguments only: no parameter struct crosses.
//! The CPU twin (`cpu::radix_sort`) takes the block length as a parameter
//! and reproduces the device's histogram with [`blocking`]'s.

/// Bits per digit, for the MSD pass (256 buckets) and each pass inside a bucket.
pub const DIGIT_BITS: u32 = 8;

/// Number of buckets per digit.
pub const RADIX: usize = 1 << DIGIT_BITS;

/// Most blocks (work-items) of the MSD pass; the histogram has
/// `RADIX × blocks` entries.
pub const MAX_BLOCKS: usize = 2048;

/// Fewest pairs per block of the MSD pass: smaller blocks make the histogram
/// and its scan (`RADIX` counters per block) cost more than the block itself.
pub const MIN_BLOCK: usize = 1024;

/// Block length and block count of the MSD pass for `n` pairs
/// (`blocks = ceil(n / block) <= MAX_BLOCKS`; `(0, 0)` for `n = 0`): the same
/// split as the scan's chunks ([`crate::spec::scan::split`]).
pub fn blocking(n: usize) -> (usize, usize) {
    crate::spec::scan::split(n, MAX_BLOCKS, MIN_BLOCK)
}

/// How a key width is split: `(top, low)`, the bits of the MSD digit
/// (`min(key_bits, DIGIT_BITS)`) and the bits sorted inside each bucket below it.
pub fn digits(key_bits: u32) -> (u32, u32) {
    let top = key_bits.min(DIGIT_BITS);
    (top, key_bits - top)
}

/// Entries of the histogram (`hist`, `u32`) of a sort of `n` pairs: `RADIX`
/// counters per block of [`blocking`].
pub fn histogram_len_bound(n: usize) -> usize {
    RADIX * blocking(n).1
}

/// How a sort ran (chosen per call from the sizes of the top-digit buckets).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// MSD pass, then each bucket sorted by one work-item (the usual case).
    Buckets,
    /// A bucket held more than `1/SKEW_LIMIT` of the pairs: plain LSD passes
    /// over the whole data set instead, so that all work-items share the work.
    Lsd,
    /// GPUs: LSD passes of [`WG_BITS`]-bit digits, each tile of [`WG_TILE`]
    /// pairs counted and ranked by one work-group in local memory, with a
    /// device-wide scan between (Satish, Harris & Garland 2009).
    WorkGroups,
}

impl Strategy {
    /// The name in stats and bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Buckets => "buckets",
            Strategy::Lsd => "lsd",
            Strategy::WorkGroups => "work-groups",
        }
    }
}

/// Work-items per work-group of [`Strategy::WorkGroups`] (`WG_SIZE` in the
/// kernel; the same as [`crate::gpu::LOCAL_SIZE`]'s value).
pub const WG_SIZE: usize = 64;
/// Consecutive pairs each work-item ranks (`WG_ITEMS`).
pub const WG_ITEMS: usize = 16;
/// Pairs per tile (`WG_TILE`).
pub const WG_TILE: usize = WG_SIZE * WG_ITEMS;
/// Bits per digit of [`Strategy::WorkGroups`] (`WG_BITS`): 16 counters per
/// work-item fit local memory.
pub const WG_BITS: u32 = 4;
/// Digits per pass of [`Strategy::WorkGroups`].
pub const WG_RADIX: usize = 1 << WG_BITS;

/// Tiles (work-groups) of a [`Strategy::WorkGroups`] pass over `n` pairs,
/// and the entries of its histogram (`WG_RADIX` per tile).
pub fn wg_tiles(n: usize) -> (usize, usize) {
    let tiles = n.div_ceil(WG_TILE);
    (tiles, WG_RADIX * tiles)
}

/// A sort whose largest top-digit bucket holds more than `n / SKEW_LIMIT`
/// pairs runs [`Strategy::Lsd`]: one work-item sorting that bucket would
/// leave the other cores idle (all keys below 2^24 with `key_bits = 32`;
/// docs/performance.md has the figures).
pub const SKEW_LIMIT: usize = 8;

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/radix_sort.cl`.
    pub enum RadixKernel {
        /// Digit counts per work-group.
        Histogram = "radix_histogram",
        /// Stable scatter by the scanned counts.
        Scatter = "radix_scatter",
        /// Sorting of small buckets in local memory.
        BucketSort = "radix_bucket_sort",
        /// Digit counts of a tile, in a work-group (GPUs).
        WgHistogram = "radix_wg_histogram",
        /// Stable local ranks and scatter of a tile (GPUs).
        WgScatter = "radix_wg_scatter",
    }
}
