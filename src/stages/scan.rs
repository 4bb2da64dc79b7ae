//! Host wiring of `kernels/scan.cl`: exclusive prefix sum of `n` `u32` values
//! on the device, in place or out of place, with the total checked against
//! `u32::MAX` (callers size buffers from totals, so a wrapped sum would be a
//! silent out-of-bounds write later). The CPU twin is [`crate::cpu::scan`];
//! the chunking and scratch size are in [`crate::spec::scan`].
//!
//! Buffers: `input`, `output` `u32[n]` (caller's, may be the same buffer);
//! internal `partials` `u64[C]` and `total` `u64[1]`, allocated once in
//! [`Scan::new`] for the largest chunk count
//! ([`crate::spec::scan::partials_len_bound`]).
//!
//! Three launches, reduce-then-scan: `scan_block_sums` (one work-item sums
//! one contiguous chunk of [`crate::spec::scan::chunking`]), `scan_partials` (one work-item scans
//! the chunk sums serially), `scan_apply` (one work-item rescans its chunk from
//! its offset). `scan_apply` skips every write when the total exceeds
//! `u32::MAX`, so on overflow the output is left unchanged.

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, launch};
use crate::spec::scan::ScanKernel;
use crate::spec::scan::partials_len_bound;
use crate::stages::kernel_files;
use opencl3::event::Event;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, ClMem};
use std::sync::Arc;

/// Number of `u32` elements a device buffer holds.
pub(crate) fn len_u32(b: &Buffer<u32>) -> Result<usize> {
    b.size()
        .map(|bytes| bytes / 4)
        .map_err(|e| Error::cl("clGetMemObjectInfo(CL_MEM_SIZE)", e))
}

/// Checks that `n` fits the kernels' `uint` indices and each buffer holds `n` elements.
pub(crate) fn check_len(what: &str, n: usize, buffers: &[(&str, &Buffer<u32>)]) -> Result<()> {
    if n > u32::MAX as usize {
        return Err(Error::InvalidArgument(format!(
            "{what}: n = {n} exceeds the u32 index range"
        )));
    }
    for (name, b) in buffers {
        let len = len_u32(b)?;
        if len < n {
            return Err(Error::InvalidArgument(format!(
                "{what}: n = {n} but the {name} buffer holds {len} elements"
            )));
        }
    }
    Ok(())
}

/// Exclusive prefix sum on one device; kernels and scratch built once.
pub struct Scan {
    gpu: Arc<Gpu>,
    block_sums: Kernel,
    partials_kernel: Kernel,
    apply: Kernel,
    partials: Buffer<u64>,
    total: Buffer<u64>,
    last_ms: f64,
}

impl Scan {
    /// Builds `kernels/scan.cl` (cached per device) and allocates the scratch
    /// (`8 × (MAX_CHUNKS + 1)` bytes).
    pub fn new(gpu: Arc<Gpu>) -> Result<Scan> {
        let file = kernel_files::SCAN;
        let program = gpu.program(&file, "")?;
        Ok(Scan {
            block_sums: gpu.entry(&program, ScanKernel::BlockSums)?,
            partials_kernel: gpu.entry(&program, ScanKernel::Partials)?,
            apply: gpu.entry(&program, ScanKernel::Apply)?,
            partials: gpu.buffer::<u64>(partials_len_bound())?,
            total: gpu.buffer::<u64>(1)?,
            gpu,
            last_ms: 0.0,
        })
    }

    /// Exclusive scan of the first `n` values of `input` into `output`
    /// (`output[i] = input[0] + … + input[i-1]`); `input` and `output` may be
    /// the same buffer. Returns the sum of all `n` values (0 for `n = 0`).
    ///
    /// Blocks until the device is done. Errors with [`Error::InvalidInput`]
    /// when the sum exceeds `u32::MAX`, in which case `output` is left
    /// unchanged; with [`Error::InvalidArgument`] when a buffer holds fewer
    /// than `n` values.
    pub fn exclusive(
        &mut self,
        input: &Buffer<u32>,
        output: &Buffer<u32>,
        n: usize,
    ) -> Result<u64> {
        self.exclusive_at(input, output, n, &[])
            .map(|(total, _)| total)
    }

    /// Like [`Scan::exclusive`], also returning `output[i]` for each `i` of
    /// `at` (each below `n`), read with the total in one wait: a caller that
    /// scans several counts laid end to end gets every partial total with
    /// one round trip.
    pub fn exclusive_at(
        &mut self,
        input: &Buffer<u32>,
        output: &Buffer<u32>,
        n: usize,
        at: &[usize],
    ) -> Result<(u64, Vec<u32>)> {
        self.last_ms = 0.0;
        check_len("exclusive scan", n, &[("input", input), ("output", output)])?;
        if let Some(&i) = at.iter().find(|&&i| i >= n) {
            return Err(Error::InvalidArgument(format!(
                "exclusive scan: element {i} asked of {n}"
            )));
        }
        if n == 0 {
            return Ok((0, Vec::new()));
        }
        let events = self.enqueue(input, output, n)?;
        let mut total = [0u64; 1];
        let mut vals = vec![0u32; at.len()];
        for (&i, v) in at.iter().zip(vals.iter_mut()) {
            // SAFETY: `vals` lives until the blocking read below has drained
            // the in-order queue; `i < n` is inside the buffer (checked above).
            if let Err(e) = unsafe { self.gpu.read_at_async(output, i, std::slice::from_mut(v)) } {
                // Do not return while earlier reads may still write into `vals`.
                let _ = self.gpu.finish();
                return Err(e);
            }
        }
        // Blocking read on the in-order queue: the three kernels (and the
        // reads of `at`) are done after it.
        self.gpu.read(&self.total, &mut total)?;
        self.last_ms = events.iter().map(event_ms).sum();
        if total[0] > u64::from(u32::MAX) {
            return Err(Error::input(
                "exclusive scan",
                format!("sum of {n} values"),
                format!(
                    "{} exceeds u32::MAX ({}); the output was left unchanged",
                    total[0],
                    u32::MAX
                ),
            ));
        }
        Ok((total[0], vals))
    }

    /// The sum of `input[0..n]` alone (the scan's first two kernels, no
    /// output written), waiting for it; [`Scan::last_ms`] gives their time.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when `input` holds fewer than `n` values.
    pub fn sum(&mut self, input: &Buffer<u32>, n: usize) -> Result<u64> {
        self.last_ms = 0.0;
        check_len("sum", n, &[("input", input)])?;
        let events = self.enqueue_sums(input, n)?;
        if events.is_empty() {
            return Ok(0);
        }
        let mut t = [0u64; 1];
        self.gpu.read(&self.total, &mut t)?;
        self.last_ms = events.iter().map(event_ms).sum();
        Ok(t[0])
    }

    /// Enqueues the three kernels without waiting and without reading the
    /// total back (for callers that know the total cannot overflow, like the
    /// radix sort's histogram of `n` keys). `n` must be checked by the caller.
    pub(crate) fn enqueue(
        &self,
        input: &Buffer<u32>,
        output: &Buffer<u32>,
        n: usize,
    ) -> Result<Vec<Event>> {
        let mut events = self.enqueue_sums(input, n)?;
        if events.is_empty() {
            return Ok(events);
        }
        let (chunk, chunks) = crate::spec::scan::chunking(n);
        let (n32, chunk32, chunks32) = (n as u32, chunk as u32, chunks as u32);
        let (partials, total) = (buf(&self.partials), buf(&self.total));
        let args = [
            Arg::U32(n32),
            Arg::U32(chunk32),
            Arg::U32(chunks32),
            buf(input),
            buf(output),
            partials,
            total,
        ];
        events.extend(launch(&self.gpu, &self.apply, chunks, &args)?);
        Ok(events)
    }

    /// The first two kernels (each chunk's sum, then the partials' scan and
    /// the total), not waited for; none for `n = 0`.
    fn enqueue_sums(&self, input: &Buffer<u32>, n: usize) -> Result<Vec<Event>> {
        let (chunk, chunks) = crate::spec::scan::chunking(n);
        if chunks == 0 {
            return Ok(Vec::new());
        }
        let g = &*self.gpu;
        let (n32, chunk32, chunks32) = (n as u32, chunk as u32, chunks as u32);
        let (partials, total) = (buf(&self.partials), buf(&self.total));
        let mut events = Vec::with_capacity(3);
        let args = [
            Arg::U32(n32),
            Arg::U32(chunk32),
            Arg::U32(chunks32),
            buf(input),
            partials,
        ];
        events.extend(launch(g, &self.block_sums, chunks, &args)?);
        let args = [Arg::U32(chunks32), partials, total];
        events.extend(launch(g, &self.partials_kernel, 1, &args)?);
        Ok(events)
    }

    /// Summed kernel time of the last [`Scan::exclusive`] call, in
    /// milliseconds (from OpenCL profiling events).
    pub fn last_ms(&self) -> f64 {
        self.last_ms
    }

    /// Device bytes of the internal scratch (chunk partials and total).
    pub fn scratch_bytes(&self) -> u64 {
        8 * (partials_len_bound() as u64 + 1)
    }
}
