//! Host wiring of `kernels/radix_sort.cl`: stable radix sort of `n` (`u32`
//! key, `u32` value) pairs on the device, in place in the caller's buffers,
//! by the low `key_bits` bits of the keys. Marching cubes vertex fusion sorts
//! (hash, vertex) pairs with it. The CPU twin with the same steps is
//! [`crate::cpu::radix_sort`]; digit width, blocks and strategy are in
//! [`crate::spec::radix_sort`].
//!
//! Buffers: `keys`, `values` `u32[n]` (caller's); scratch `keys_tmp`,
//! `values_tmp` `u32[n]` and `hist` `u32[RADIX × G]`, grown on demand and
//! kept between calls.
//!
//! One most-significant-digit pass over the top [`DIGIT_BITS`] bits of the
//! key, then an LSD sort of each bucket by the bits below
//! ([`Strategy::Buckets`]):
//! - `radix_histogram`: one work-item per block of [`blocking`] counts the top
//!   digits of its block (digit-major: `hist[d × G + b]`);
//! - exclusive [`Scan`] of the counts: where each (digit, block) goes;
//! - `radix_scatter`: each work-item walks its block in order and moves each
//!   pair to its digit's next slot in the scratch (stable);
//! - `radix_bucket_sort`: one work-item per bucket (contiguous now) sorts it
//!   by the low bits with serial LSD passes, ending in the caller's buffers.
//!
//! Only the MSD pass streams the whole data set through DRAM; the buckets are
//! sorted in cache: on a CPU device, about half the time of four LSD passes
//! (docs/performance.md). The price is load balance: when one bucket holds most of the pairs,
//! one work-item sorts them while the other cores idle. So the host reads the
//! 256 bucket sizes back after the scan (one strided read, the only sync
//! point) and, when the largest exceeds `n / SKEW_LIMIT`, runs plain LSD
//! passes (histogram, scan, scatter per digit) over the whole data set instead
//! ([`Strategy::Lsd`]).
//!
//! That shape suits CPU devices, whose work-items are cores; on a GPU 256
//! serial work-items leave the card idle. GPUs run [`Strategy::WorkGroups`] instead: LSD passes of
//! [`WG_BITS`]-bit digits, `radix_wg_histogram` and `radix_wg_scatter` per
//! tile of [`WG_TILE`] pairs with their counts and stable ranks in local
//! memory, and the device-wide [`Scan`] between (Satish, Harris & Garland
//! 2009). [`RadixSort::set_strategy`] picks one for every device.

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::radix_sort::RadixKernel;
use crate::spec::radix_sort::histogram_len_bound;
use crate::stages::kernel_files;
use crate::stages::scan::{Scan, check_len};
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use opencl3::types::CL_BLOCKING;
use std::ffi::c_void;
use std::sync::Arc;

use crate::spec::radix_sort::{
    DIGIT_BITS, RADIX, SKEW_LIMIT, Strategy, WG_BITS, blocking, digits, wg_tiles,
};

// The work-group kernels are launched through `launch`, whose work-groups
// are LOCAL_SIZE work-items: the kernels' WG_SIZE must be the same.
const _: () = assert!(crate::gpu::LOCAL_SIZE == crate::spec::radix_sort::WG_SIZE);

/// Stable device radix sort of (key, value) pairs; kernels built once,
/// scratch kept between calls.
pub struct RadixSort {
    gpu: Arc<Gpu>,
    scan: Scan,
    histogram: Kernel,
    scatter: Kernel,
    bucket_sort: Kernel,
    wg_histogram: Kernel,
    wg_scatter: Kernel,
    /// `Some(Strategy::WorkGroups)` on GPUs (or as set), `None`: buckets or
    /// LSD per call.
    forced: Option<Strategy>,
    keys_tmp: Buffer<u32>,
    values_tmp: Buffer<u32>,
    tmp_len: usize,
    hist: Buffer<u32>,
    hist_len: usize,
    last_ms: f64,
    last_strategy: Option<Strategy>,
}

impl RadixSort {
    /// Builds `kernels/radix_sort.cl` and `kernels/scan.cl` (cached per
    /// device). Scratch is allocated by the first sort that needs it.
    pub fn new(gpu: Arc<Gpu>) -> Result<RadixSort> {
        let file = kernel_files::RADIX_SORT;
        let program = gpu.program(&file, &format!("-DRADIX_BITS={DIGIT_BITS}"))?;
        Ok(RadixSort {
            scan: Scan::new(gpu.clone())?,
            histogram: gpu.entry(&program, RadixKernel::Histogram)?,
            scatter: gpu.entry(&program, RadixKernel::Scatter)?,
            bucket_sort: gpu.entry(&program, RadixKernel::BucketSort)?,
            wg_histogram: gpu.entry(&program, RadixKernel::WgHistogram)?,
            wg_scatter: gpu.entry(&program, RadixKernel::WgScatter)?,
            forced: (!gpu.info.kind.eq_ignore_ascii_case("CPU")).then_some(Strategy::WorkGroups),
            keys_tmp: gpu.buffer::<u32>(1)?,
            values_tmp: gpu.buffer::<u32>(1)?,
            tmp_len: 0,
            hist: gpu.buffer::<u32>(1)?,
            hist_len: 0,
            gpu,
            last_ms: 0.0,
            last_strategy: None,
        })
    }

    /// Sorts the first `n` (key, value) pairs of `keys`/`values` by key,
    /// stably (equal keys keep their order), in place.
    ///
    /// Only the low `key_bits` bits of each key are compared: pairs are
    /// ordered by `key & (2^key_bits − 1)`, and keys keep their high bits
    /// (they travel with the pair but do not affect the order). `key_bits = 0`
    /// leaves the pairs as they are.
    ///
    /// Blocks until the device is done. Errors with
    /// [`Error::InvalidArgument`] when `key_bits > 32` or a buffer holds fewer
    /// than `n` elements.
    pub fn sort_pairs(
        &mut self,
        keys: &mut Buffer<u32>,
        values: &mut Buffer<u32>,
        n: usize,
        key_bits: u32,
    ) -> Result<()> {
        self.last_ms = 0.0;
        self.last_strategy = None;
        if key_bits > 32 {
            return Err(Error::InvalidArgument(format!(
                "radix sort: key_bits = {key_bits}, at most 32"
            )));
        }
        check_len("radix sort", n, &[("keys", keys), ("values", values)])?;
        if n < 2 || key_bits == 0 {
            return Ok(());
        }
        let mut events: Vec<Event> = Vec::with_capacity(8);
        if self.forced == Some(Strategy::WorkGroups) {
            self.reserve(n, wg_tiles(n).1)?;
            self.last_strategy = Some(Strategy::WorkGroups);
            self.work_groups(keys, values, n, key_bits, &mut events)?;
            self.gpu.finish()?;
            self.last_ms = events.iter().map(event_ms).sum();
            return Ok(());
        }
        let blocks = blocking(n).1;
        self.reserve(n, histogram_len_bound(n))?;
        let (top, low) = digits(key_bits);

        // Top-digit histogram and its scan, then the bucket sizes to the host.
        let msd = Self::pass_args(n, top, low);
        let mut args = msd.to_vec();
        args.extend([buf(&*keys), buf(&self.hist)]);
        events.extend(launch(&self.gpu, &self.histogram, blocks, &args)?);
        // The counts add up to n <= u32::MAX: no overflow check needed.
        events.extend(self.scan.enqueue(&self.hist, &self.hist, RADIX * blocks)?);
        let largest = self.largest_bucket(n, blocks)?;

        if largest <= n / SKEW_LIMIT && self.forced != Some(Strategy::Lsd) {
            self.last_strategy = Some(Strategy::Buckets);
            let (keys_tmp, values_tmp) = (buf(&self.keys_tmp), buf(&self.values_tmp));
            let mut args = msd.to_vec();
            args.extend([
                buf(&*keys),
                buf(&*values),
                buf(&self.hist),
                keys_tmp,
                values_tmp,
            ]);
            events.extend(launch(&self.gpu, &self.scatter, blocks, &args)?);
            let args = [
                Arg::U32(n as u32),
                Arg::U32(blocks as u32),
                Arg::U32(low),
                buf(&self.hist),
                keys_tmp,
                values_tmp,
                buf(&*keys),
                buf(&*values),
            ];
            events.extend(launch(&self.gpu, &self.bucket_sort, RADIX, &args)?);
        } else {
            self.last_strategy = Some(Strategy::Lsd);
            self.lsd(keys, values, n, key_bits, &mut events)?;
        }
        self.gpu.finish()?;
        self.last_ms = events.iter().map(event_ms).sum();
        Ok(())
    }

    /// The first five kernel arguments of `radix_histogram`/`radix_scatter`
    /// for a digit of `bits` bits at bit `shift`.
    fn pass_args(n: usize, bits: u32, shift: u32) -> [Arg; 5] {
        let (block, blocks) = blocking(n);
        [
            Arg::U32(n as u32),
            Arg::U32(block as u32),
            Arg::U32(blocks as u32),
            Arg::U32(shift),
            Arg::U32((1u32 << bits) - 1),
        ]
    }

    /// Size of the largest top-digit bucket, from the scanned histogram: bucket
    /// d starts at `hist[d × blocks]`, one strided read of `RADIX` values
    /// (blocking, so the queue is drained here).
    fn largest_bucket(&self, n: usize, blocks: usize) -> Result<usize> {
        let mut starts = [0u32; RADIX];
        let (origin, region) = ([0usize; 3], [4usize, RADIX, 1]);
        // SAFETY: the region is RADIX rows of 4 bytes, `blocks × 4` bytes
        // apart, all inside `hist` (RADIX × blocks entries, reserved above);
        // `starts` holds RADIX × 4 bytes; the read is blocking.
        unsafe {
            self.gpu.queue().enqueue_read_buffer_rect(
                &self.hist,
                CL_BLOCKING,
                origin.as_ptr(),
                origin.as_ptr(),
                region.as_ptr(),
                blocks * 4,
                0,
                4,
                0,
                starts.as_mut_ptr().cast::<c_void>(),
                &[],
            )
        }
        .map_err(|e| Error::cl("clEnqueueReadBufferRect(radix sort buckets)", e))?;
        Ok((0..RADIX)
            .map(|d| starts.get(d + 1).map_or(n, |&s| s as usize) - starts[d] as usize)
            .max()
            .unwrap_or(0))
    }

    /// Plain LSD sort for skewed keys: one histogram/scan/scatter pass per
    /// digit over the whole data set, ping-ponging with the scratch; an odd
    /// number of passes ends with a copy back.
    fn lsd(
        &mut self,
        keys: &mut Buffer<u32>,
        values: &mut Buffer<u32>,
        n: usize,
        key_bits: u32,
        events: &mut Vec<Event>,
    ) -> Result<()> {
        let blocks = blocking(n).1;
        let passes = key_bits.div_ceil(DIGIT_BITS);
        let (hist, keys_tmp, values_tmp) =
            (buf(&self.hist), buf(&self.keys_tmp), buf(&self.values_tmp));
        let (user_keys, user_values) = (buf(&*keys), buf(&*values));
        for pass in 0..passes {
            let shift = pass * DIGIT_BITS;
            let common = Self::pass_args(n, (key_bits - shift).min(DIGIT_BITS), shift);
            // Even passes read the caller's buffers, odd passes the scratch.
            let (kin, vin, kout, vout) = if pass % 2 == 0 {
                (user_keys, user_values, keys_tmp, values_tmp)
            } else {
                (keys_tmp, values_tmp, user_keys, user_values)
            };
            let mut args = common.to_vec();
            args.extend([kin, hist]);
            events.extend(launch(&self.gpu, &self.histogram, blocks, &args)?);
            events.extend(self.scan.enqueue(&self.hist, &self.hist, RADIX * blocks)?);
            let mut args = common.to_vec();
            args.extend([kin, vin, hist, kout, vout]);
            events.extend(launch(&self.gpu, &self.scatter, blocks, &args)?);
        }
        if passes % 2 == 1 {
            self.copy_back(keys, values, n, events)?;
        }
        Ok(())
    }

    /// [`Strategy::WorkGroups`]: one histogram, scan and scatter per digit
    /// of [`WG_BITS`] bits, ping-ponging with the scratch; an odd number of
    /// passes ends with a copy back.
    fn work_groups(
        &mut self,
        keys: &mut Buffer<u32>,
        values: &mut Buffer<u32>,
        n: usize,
        key_bits: u32,
        events: &mut Vec<Event>,
    ) -> Result<()> {
        let (tiles, hist_len) = wg_tiles(n);
        let items = tiles * crate::spec::radix_sort::WG_SIZE;
        let passes = key_bits.div_ceil(WG_BITS);
        let (hist, keys_tmp, values_tmp) =
            (buf(&self.hist), buf(&self.keys_tmp), buf(&self.values_tmp));
        let (user_keys, user_values) = (buf(&*keys), buf(&*values));
        for pass in 0..passes {
            let shift = pass * WG_BITS;
            let mask = (1u32 << (key_bits - shift).min(WG_BITS)) - 1;
            let (kin, vin, kout, vout) = if pass % 2 == 0 {
                (user_keys, user_values, keys_tmp, values_tmp)
            } else {
                (keys_tmp, values_tmp, user_keys, user_values)
            };
            let common = [Arg::U32(n as u32), Arg::U32(shift), Arg::U32(mask)];
            let mut args = common.to_vec();
            args.extend([kin, hist]);
            events.extend(launch(&self.gpu, &self.wg_histogram, items, &args)?);
            events.extend(self.scan.enqueue(&self.hist, &self.hist, hist_len)?);
            let mut args = common.to_vec();
            args.extend([kin, vin, hist, kout, vout]);
            events.extend(launch(&self.gpu, &self.wg_scatter, items, &args)?);
        }
        if passes % 2 == 1 {
            self.copy_back(keys, values, n, events)?;
        }
        Ok(())
    }

    /// Copies the first `n` pairs of the scratch into the caller's buffers.
    fn copy_back(
        &self,
        keys: &mut Buffer<u32>,
        values: &mut Buffer<u32>,
        n: usize,
        events: &mut Vec<Event>,
    ) -> Result<()> {
        let bytes = n * 4;
        let q = self.gpu.queue();
        // SAFETY: both buffers hold at least n elements (checked by the
        // caller and by `reserve`); the in-order queue orders the copies
        // after the last pass.
        unsafe {
            events.push(
                q.enqueue_copy_buffer(&self.keys_tmp, keys, 0, 0, bytes, &[])
                    .map_err(|e| Error::cl("clEnqueueCopyBuffer(keys)", e))?,
            );
            events.push(
                q.enqueue_copy_buffer(&self.values_tmp, values, 0, 0, bytes, &[])
                    .map_err(|e| Error::cl("clEnqueueCopyBuffer(values)", e))?,
            );
        }
        Ok(())
    }

    /// Sets the strategy of every later sort: `Some(WorkGroups)` or
    /// `Some(Lsd)` always, `Some(Buckets)` or `None` as chosen per call
    /// (buckets, LSD for skewed keys). The default is `WorkGroups` on GPUs
    /// and `None` on CPU devices.
    pub fn set_strategy(&mut self, s: Option<Strategy>) {
        self.forced = s.filter(|s| *s != Strategy::Buckets);
    }

    /// Grows the scratch to `n` pairs and `hist_len` counters.
    fn reserve(&mut self, n: usize, hist_len: usize) -> Result<()> {
        if self.tmp_len < n {
            // Release the old scratch before allocating the new one.
            self.keys_tmp = self.gpu.buffer::<u32>(1)?;
            self.values_tmp = self.gpu.buffer::<u32>(1)?;
            self.tmp_len = 0;
            self.keys_tmp = self.gpu.buffer::<u32>(n)?;
            self.values_tmp = self.gpu.buffer::<u32>(n)?;
            self.tmp_len = n;
        }
        if self.hist_len < hist_len {
            self.hist = self.gpu.buffer::<u32>(hist_len)?;
            self.hist_len = hist_len;
        }
        Ok(())
    }

    /// Summed kernel time of the last [`RadixSort::sort_pairs`] call, in
    /// milliseconds (from OpenCL profiling events).
    pub fn last_ms(&self) -> f64 {
        self.last_ms
    }

    /// The strategy of the last [`RadixSort::sort_pairs`] call (`None` when it
    /// had nothing to do: fewer than two pairs, `key_bits = 0`, or an error).
    pub fn last_strategy(&self) -> Option<Strategy> {
        self.last_strategy
    }

    /// Device bytes of the scratch held now: two `u32[n]` buffers for the
    /// largest `n` sorted so far, the histogram and the scan's partials.
    pub fn scratch_bytes(&self) -> u64 {
        8 * self.tmp_len as u64 + 4 * self.hist_len as u64 + self.scan.scratch_bytes()
    }
}
