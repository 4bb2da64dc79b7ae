//! Host wiring of `kernels/radix_sort.cl`: stable least-significant-digit
//! radix sort of `n` (`u32` key, `u32` value) pairs on the device, in place in
//! the caller's buffers, by the low `key_bits` bits of the keys. Marching
//! cubes vertex fusion sorts (hash, vertex) pairs with it. The CPU twin with
//! the same steps is [`crate::cpu::radix_sort`].
//!
//! Buffers: `keys`, `values` `u32[n]` (caller's); scratch `keys_tmp`,
//! `values_tmp` `u32[n]` (ping-pong targets) and `hist` `u32[RADIX × G]`,
//! grown on demand and kept between calls.
//!
//! The pairs are split into G contiguous blocks ([`blocking`]), one per
//! work-item. Each pass over one [`DIGIT_BITS`]-bit digit runs
//! `radix_histogram` (per-block digit counts, digit-major), an exclusive
//! [`Scan`] of the counts (global offsets of each (digit, block)), and
//! `radix_scatter` (each work-item walks its block in order and writes each
//! pair at its digit's next offset; in-order walking makes it stable). Passes
//! alternate between the caller's buffers and the scratch; an odd pass count
//! ends with a device copy back into the caller's buffers.

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, kernel_file, launch};
use crate::stages::scan::{Scan, check_len};
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use std::sync::Arc;

/// Bits of key sorted per pass (256 buckets): 32-bit keys take 4 passes.
/// Measured on PoCL 3.1 (2 cores, AVX-512), 8M random pairs: 4-bit digits
/// (8 passes) take about twice as long; wider digits spill the per-work-item
/// counters and scatter streams out of L1.
pub const DIGIT_BITS: u32 = 8;

/// Number of buckets per pass.
pub const RADIX: usize = 1 << DIGIT_BITS;

/// Most blocks (work-items) per pass; the histogram has `RADIX × blocks` entries.
pub const MAX_BLOCKS: usize = 2048;

/// Fewest pairs per block: smaller blocks make the histogram and its scan
/// (`RADIX` counters per block) cost more than the block itself.
pub const MIN_BLOCK: usize = 1024;

/// Block length and block count used for `n` pairs
/// (`blocks = ceil(n / block) <= MAX_BLOCKS`; `(0, 0)` for `n = 0`).
pub fn blocking(n: usize) -> (usize, usize) {
    blocking_with(
        n,
        env("MINB", MIN_BLOCK as u32) as usize,
        env("MAXB", MAX_BLOCKS as u32) as usize,
    )
}

fn blocking_with(n: usize, min_block: usize, max_blocks: usize) -> (usize, usize) {
    if n == 0 {
        return (0, 0);
    }
    let block = n.div_ceil(max_blocks).max(min_block);
    (block, n.div_ceil(block))
}

fn env(k: &str, d: u32) -> u32 {
    std::env::var(k)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(d)
}
fn db() -> u32 {
    env("DB", DIGIT_BITS)
}
/// Number of passes for a key width: `ceil(key_bits / DIGIT_BITS)`.
pub fn passes(key_bits: u32) -> u32 {
    key_bits.div_ceil(db())
}

/// Stable device radix sort of (key, value) pairs; kernels built once,
/// scratch kept between calls.
pub struct RadixSort {
    gpu: Arc<Gpu>,
    scan: Scan,
    histogram: Kernel,
    scatter: Kernel,
    keys_tmp: Buffer<u32>,
    values_tmp: Buffer<u32>,
    tmp_len: usize,
    hist: Buffer<u32>,
    hist_len: usize,
    last_ms: f64,
}

impl RadixSort {
    /// Builds `kernels/radix_sort.cl` and `kernels/scan.cl` (cached per
    /// device). Scratch is allocated by the first sort that needs it.
    pub fn new(gpu: Arc<Gpu>) -> Result<RadixSort> {
        let file = kernel_file("radix_sort").expect("radix_sort kernels are embedded");
        let program = gpu.program(&file, &format!("-DRADIX_BITS={}", db()))?;
        Ok(RadixSort {
            scan: Scan::new(gpu.clone())?,
            histogram: gpu.kernel(&program, "radix_histogram")?,
            scatter: gpu.kernel(&program, "radix_scatter")?,
            keys_tmp: gpu.buffer::<u32>(1)?,
            values_tmp: gpu.buffer::<u32>(1)?,
            tmp_len: 0,
            hist: gpu.buffer::<u32>(1)?,
            hist_len: 0,
            gpu,
            last_ms: 0.0,
        })
    }

    /// Sorts the first `n` (key, value) pairs of `keys`/`values` by key,
    /// stably (equal keys keep their order), in place.
    ///
    /// Only the low `key_bits` bits of each key are compared: pairs are
    /// ordered by `key & (2^key_bits − 1)`, and keys keep their high bits
    /// (they travel with the pair but do not affect the order). `key_bits = 0`
    /// leaves the pairs as they are. Runs `ceil(key_bits / 8)` passes.
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
        if key_bits > 32 {
            return Err(Error::InvalidArgument(format!(
                "radix sort: key_bits = {key_bits}, at most 32"
            )));
        }
        check_len("radix sort", n, &[("keys", keys), ("values", values)])?;
        let passes = passes(key_bits);
        if n < 2 || passes == 0 {
            return Ok(());
        }
        let (block, blocks) = blocking(n);
        self.reserve(n, (1 << db()) * blocks)?;

        let g = &*self.gpu;
        let (n32, block32, blocks32) = (n as u32, block as u32, blocks as u32);
        let hist = buf(&self.hist);
        let mut events: Vec<Event> = Vec::with_capacity(5 * passes as usize + 2);
        for pass in 0..passes {
            let shift = pass * db();
            let bits = (key_bits - shift).min(db());
            let mask = (1u32 << bits) - 1;
            // Even passes read the caller's buffers, odd passes the scratch.
            let (kin, vin, kout, vout) = if pass % 2 == 0 {
                (&*keys, &*values, &self.keys_tmp, &self.values_tmp)
            } else {
                (&self.keys_tmp, &self.values_tmp, &*keys, &*values)
            };
            let common = [
                Arg::U32(n32),
                Arg::U32(block32),
                Arg::U32(blocks32),
                Arg::U32(shift),
                Arg::U32(mask),
            ];
            let mut args = common.to_vec();
            args.extend([buf(kin), hist]);
            events.extend(launch(g, &self.histogram, blocks, &args)?);
            // The counts add up to n <= u32::MAX: no overflow check needed.
            events.extend(
                self.scan
                    .enqueue(&self.hist, &self.hist, (1 << db()) * blocks)?,
            );
            let mut args = common.to_vec();
            args.extend([buf(kin), buf(vin), hist, buf(kout), buf(vout)]);
            events.extend(launch(g, &self.scatter, blocks, &args)?);
        }
        if passes % 2 == 1 {
            let bytes = n * 4;
            // SAFETY: both buffers hold at least n elements (checked above and
            // by `reserve`); the in-order queue orders the copies after the last pass.
            unsafe {
                let q = g.queue();
                events.push(
                    q.enqueue_copy_buffer(&self.keys_tmp, keys, 0, 0, bytes, &[])
                        .map_err(|e| Error::cl("clEnqueueCopyBuffer(keys)", e))?,
                );
                events.push(
                    q.enqueue_copy_buffer(&self.values_tmp, values, 0, 0, bytes, &[])
                        .map_err(|e| Error::cl("clEnqueueCopyBuffer(values)", e))?,
                );
            }
        }
        g.finish()?;
        self.last_ms = events.iter().map(event_ms).sum();
        if std::env::var("DEBUG").is_ok() {
            eprintln!(
                "{:?}",
                events
                    .iter()
                    .map(|e| (event_ms(e) * 100.0).round() / 100.0)
                    .collect::<Vec<_>>()
            );
        }
        Ok(())
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

    /// Summed kernel (and copy) time of the last [`RadixSort::sort_pairs`]
    /// call, in milliseconds (from OpenCL profiling events).
    pub fn last_ms(&self) -> f64 {
        self.last_ms
    }

    /// Device bytes of the scratch held now: two `u32[n]` ping-pong buffers
    /// for the largest `n` sorted so far, the histogram and the scan's partials.
    pub fn scratch_bytes(&self) -> u64 {
        8 * self.tmp_len as u64 + 4 * self.hist_len as u64 + self.scan.scratch_bytes()
    }
}
