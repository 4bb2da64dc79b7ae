//! The OpenCL layer: platform and device discovery, device selection, program
//! building (kernel sources embedded with `include_str!`, shared headers
//! prepended with `#line` markers so build logs name the real file), typed
//! buffers and kernel launches timed with profiling events; built programs
//! are kept in shapecue's own binary cache ([`cache`]) across processes.

pub mod cache;
mod device;
pub mod external;
mod launch;
#[cfg(test)]
mod probe;
#[cfg(test)]
pub(crate) use probe::{check_layout, probe_layout};
mod program;
pub mod vulkan;

pub use device::{DeviceInfo, list_devices};
pub use launch::{Arg, buf, event_ms, launch, wait_ms};
pub use program::{COMMON_HEADERS, FpMode, KernelFile, STRICT_HEADER, assemble_as};

use crate::error::{Error, Result};
use opencl3::command_queue::{CL_QUEUE_PROFILING_ENABLE, CommandQueue};
use opencl3::context::Context;
use opencl3::device::Device;
use opencl3::kernel::Kernel;
use opencl3::memory::{Buffer, CL_MEM_READ_WRITE};
use opencl3::program::Program;
use opencl3::types::{CL_BLOCKING, cl_mem_flags};
use serde::Serialize;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Writes of at least this many bytes go through pinned staging on devices
/// with their own memory ([`Gpu::write`]).
pub const STAGED_MIN_BYTES: usize = 4 << 20;

/// Bytes of the pinned staging buffer of a staged write: larger writes go
/// through it in chunks.
pub const STAGING_BYTES: usize = 64 << 20;

/// Work-group size used for every 1-D launch. PoCL compiles a new kernel
/// variant for every distinct local size, so a fixed size (with the global
/// size padded up to a multiple) keeps JIT compilation to once per kernel.
pub const LOCAL_SIZE: usize = 64;

/// An OpenCL device with its context, in-order profiling queue and a cache of
/// built programs (each (file, options) pair is compiled once per `Gpu`, and
/// across processes through [`cache`]).
pub struct Gpu {
    /// What the device is.
    pub info: DeviceInfo,
    context: Context,
    queue: CommandQueue,
    programs: Mutex<HashMap<(String, String), Arc<Program>>>,
    /// The binary cache's folder (`None`: off), read once in [`Gpu::new`].
    cache_dir: Option<PathBuf>,
    /// Platform, device and driver, as they enter every cache key.
    cache_tag: String,
    /// Programs built from source in this `Gpu`, not yet saved: (key, program).
    unsaved: Mutex<Vec<(u128, Arc<Program>)>>,
    /// Set by [`Gpu::save_every_build`]: programs built from source are
    /// saved on every runtime, PoCL included.
    save_all: std::sync::atomic::AtomicBool,
    builds: Mutex<Vec<ProgramBuild>>,
    /// `SHAPECUE_DEVICE_MEMORY`: a simulated device memory in bytes, and the
    /// bytes allocated so far against it (see [`Gpu::buffer_flags`]).
    budget: Option<(u64, std::sync::atomic::AtomicU64)>,
    /// How floating-point arithmetic is built ([`FpMode`]).
    fp: FpMode,
    /// Large writes go through pinned staging ([`Gpu::write`]).
    staged_uploads: bool,
    /// `SHAPECUE_CL_OPTIONS`: options added to every build (CI builds with
    /// `-cl-mad-enable` there, as a GPU compiler's liberty to fuse).
    extra_options: String,
}

/// Parses a byte count with an optional binary suffix (`512M`, `2G`, `64KiB`).
pub fn parse_bytes(s: &str) -> Option<u64> {
    let s = s.trim();
    let digits = s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
    let n: u64 = s[..digits].parse().ok()?;
    let shift = match s[digits..].trim().to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kib" | "kb" => 10,
        "m" | "mib" | "mb" => 20,
        "g" | "gib" | "gb" => 30,
        _ => return None,
    };
    n.checked_mul(1u64 << shift)
}

/// How one program of a [`Gpu`] was obtained (for stats).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProgramBuild {
    /// Kernel file (`kernels/curvature.cl`).
    pub file: String,
    /// Build options given (without `-cl-std`).
    pub options: String,
    /// `"hit"` (built from the cached binary), `"miss"` (from source, to be
    /// saved), `"off"` (cache disabled or no folder) or `"rejected: why"`
    /// (a damaged, foreign or refused cache file; built from source and
    /// saved again).
    pub cache: String,
    /// Whether [`Gpu::persist_programs`] saved it into the cache (a miss is
    /// saved where [`cache::saves`] says so, or after
    /// [`Gpu::save_every_build`]).
    pub saved: bool,
    /// Getting the program (read + build, or build from source): its wall
    /// time.
    pub timing: crate::spec::timing::Timing,
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu").field("info", &self.info).finish()
    }
}

impl Gpu {
    /// Opens the device chosen by `selector` (an index from `shapecue devices`
    /// or a substring of the device or platform name); `None` falls back to the
    /// `SHAPECUE_DEVICE` environment variable, then to the first GPU, then to
    /// the first CPU device.
    pub fn new(selector: Option<&str>) -> Result<Gpu> {
        let fp = match std::env::var("SHAPECUE_FP").ok().as_deref().map(str::trim) {
            None | Some("") | Some("strict") => FpMode::Strict,
            Some("relaxed") => FpMode::Relaxed,
            Some(v) => {
                return Err(Error::InvalidArgument(format!(
                    "SHAPECUE_FP={v}: expected strict or relaxed"
                )));
            }
        };
        Self::with_fp(selector, fp)
    }

    /// As [`Gpu::new`], building every program in the floating-point mode
    /// `fp` (whatever `SHAPECUE_FP` says).
    pub fn with_fp(selector: Option<&str>, fp: FpMode) -> Result<Gpu> {
        let info = device::select(selector)?;
        let cpu_device = info.kind.eq_ignore_ascii_case("CPU");
        let _guard = program::driver_lock();
        let device = Device::new(info.id);
        let context = Context::from_device(&device).map_err(|e| Error::cl("clCreateContext", e))?;
        #[allow(deprecated)]
        let queue = CommandQueue::create_default(&context, CL_QUEUE_PROFILING_ENABLE)
            .map_err(|e| Error::cl("clCreateCommandQueue", e))?;
        let platform_version = device
            .platform()
            .ok()
            .and_then(|p| opencl3::platform::Platform::new(p).version().ok())
            .unwrap_or_default();
        let cache_tag = format!(
            "platform={}\nplatform_version={}\ndevice={}\ndevice_version={}\ndriver={}\n",
            info.platform,
            platform_version.trim(),
            info.name,
            info.version,
            device.driver_version().unwrap_or_default().trim()
        );
        Ok(Gpu {
            info,
            context,
            queue,
            programs: Mutex::new(HashMap::new()),
            cache_dir: cache::cache_dir(),
            budget: std::env::var("SHAPECUE_DEVICE_MEMORY")
                .ok()
                .filter(|v| !v.is_empty())
                .map(|v| {
                    parse_bytes(&v).map(|b| (b, 0.into())).ok_or_else(|| {
                        Error::InvalidArgument(format!(
                            "SHAPECUE_DEVICE_MEMORY={v:?}: expected a byte count such as \
                             268435456, 256M or 2G"
                        ))
                    })
                })
                .transpose()?,
            cache_tag,
            unsaved: Mutex::new(Vec::new()),
            save_all: false.into(),
            builds: Mutex::new(Vec::new()),
            staged_uploads: match std::env::var("SHAPECUE_STAGED_UPLOADS").as_deref() {
                Ok("1") => true,
                Ok("0") => false,
                _ => !cpu_device,
            },
            fp,
            extra_options: std::env::var("SHAPECUE_CL_OPTIONS").unwrap_or_default(),
        })
    }

    /// How this `Gpu` builds floating-point arithmetic.
    pub fn fp_mode(&self) -> FpMode {
        self.fp
    }

    /// Whether the kernels compute what their CPU twins compute bit for bit
    /// on this device: the strict mode on a device with correctly rounded
    /// f32 divide and square root. Elsewhere the promises of bits hold
    /// within a tolerance (docs/accuracy.md).
    pub fn bitwise_twins(&self) -> bool {
        self.fp == FpMode::Strict && self.info.correctly_rounded_div_sqrt
    }

    /// The OpenCL context.
    pub fn context(&self) -> &Context {
        &self.context
    }

    /// The in-order command queue (profiling enabled).
    pub fn queue(&self) -> &CommandQueue {
        &self.queue
    }

    /// Builds `file` with `options` (e.g. `-DREAL=double`), or returns the
    /// program built earlier in this process with the same pair. The build
    /// starts from shapecue's binary cache where it holds this program for
    /// this device and driver ([`cache`]), else from source (then saved by
    /// [`Gpu::persist_programs`]); a cache problem is never an error.
    pub fn program(&self, file: &KernelFile, options: &str) -> Result<Arc<Program>> {
        let map_key = (file.name.to_string(), options.to_string());
        let mut programs = self.programs.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(p) = programs.get(&map_key) {
            return Ok(p.clone());
        }
        let t0 = Instant::now();
        let src = program::assemble_as(file, self.fp);
        let opts = program::full_options(
            options,
            self.fp,
            self.info.correctly_rounded_div_sqrt,
            &self.extra_options,
        );
        let key = cache::key(&[src.as_bytes(), opts.as_bytes(), self.cache_tag.as_bytes()]);
        let from_cache = self.cache_dir.as_deref().map(|dir| {
            cache::load(dir, key)
                .map_err(|r| r.to_string())
                .and_then(|bin| {
                    program::build_binary(&self.context, self.info.id, &bin, &opts)
                        .map_err(|e| format!("the driver refused the cached binary ({e})"))
                })
        });
        let (p, outcome) = match from_cache {
            Some(Ok(p)) => (Arc::new(p), "hit".to_string()),
            other => {
                let p = Arc::new(program::build_source(&self.context, file, &src, &opts)?);
                let saves = cache::saves(&self.info.platform)
                    || self.save_all.load(std::sync::atomic::Ordering::Relaxed);
                let (outcome, save) = match (other, &self.cache_dir) {
                    (Some(Err(why)), Some(_)) if why == cache::Reject::Missing.to_string() => {
                        ("miss".to_string(), saves)
                    }
                    (Some(Err(why)), _) => (format!("rejected: {why}"), saves),
                    _ => ("off".to_string(), false),
                };
                if save {
                    lock(&self.unsaved).push((key, p.clone()));
                }
                (p, outcome)
            }
        };
        lock(&self.builds).push(ProgramBuild {
            file: file.name.to_string(),
            options: options.to_string(),
            cache: outcome,
            saved: false,
            timing: crate::spec::timing::Timing {
                wall_ms: t0.elapsed().as_secs_f64() * 1e3,
                ..Default::default()
            },
        });
        programs.insert(map_key, p.clone());
        Ok(p)
    }

    /// From now on, programs this `Gpu` builds from source are saved into
    /// the binary cache on every runtime, PoCL included (see
    /// [`cache::saves`]: there the save compiles every kernel of the program
    /// for any work-group size, seconds that `shapecue build-kernels` spends
    /// once so that no later command does). No effect with the cache off.
    pub fn save_every_build(&self) {
        self.save_all
            .store(true, std::sync::atomic::Ordering::Relaxed);
    }

    /// The binary cache's folder, or `None` when the cache is off.
    pub fn cache_folder(&self) -> Option<&std::path::Path> {
        self.cache_dir.as_deref()
    }

    /// How each program of this `Gpu` was obtained, in build order.
    pub fn program_builds(&self) -> Vec<ProgramBuild> {
        lock(&self.builds).clone()
    }

    /// Saves the programs built from source so far that are due (see
    /// [`cache::saves`])
    /// into the binary cache (best effort: a folder that cannot be written
    /// is skipped silently).
    /// Called when the `Gpu` is dropped; call it earlier to time it, or
    /// after the kernels have run once so that code the driver compiles at
    /// the first launch is in the saved binary. Returns how many were saved.
    pub fn persist_programs(&self) -> usize {
        let Some(dir) = &self.cache_dir else {
            return 0;
        };
        let pending = std::mem::take(&mut *lock(&self.unsaved));
        let mut saved = 0;
        for (key, p) in &pending {
            if program::binary_of(p).is_some_and(|bin| cache::store(dir, *key, &bin).is_ok()) {
                saved += 1;
                let programs = lock(&self.programs);
                let mut builds = lock(&self.builds);
                // The build record of this program: same (file, options) entry.
                if let Some(((file, options), _)) = programs.iter().find(|(_, q)| Arc::ptr_eq(q, p))
                {
                    for b in builds.iter_mut() {
                        if &b.file == file && &b.options == options {
                            b.saved = true;
                        }
                    }
                }
            }
        }
        saved
    }

    /// Creates the kernel of entry point `k` (a family's kernel enum,
    /// [`crate::spec::kernels::KernelEntry`]) from `program`.
    pub fn entry(
        &self,
        program: &Program,
        k: impl crate::spec::kernels::KernelEntry,
    ) -> Result<Kernel> {
        self.kernel(program, k.entry())
    }

    /// Creates the kernel `name` from `program`; the stages use [`Gpu::entry`].
    pub fn kernel(&self, program: &Program, name: &str) -> Result<Kernel> {
        Kernel::create(program, name).map_err(|e| Error::cl(format!("clCreateKernel({name})"), e))
    }

    /// Allocates an uninitialised read-write buffer of `len` elements (at
    /// least one: OpenCL rejects empty buffers).
    pub fn buffer<T>(&self, len: usize) -> Result<Buffer<T>> {
        self.buffer_flags(len, CL_MEM_READ_WRITE)
    }

    /// Allocates a buffer with explicit memory flags. A buffer larger than the
    /// device's largest allocation is refused with the bytes named. With
    /// `SHAPECUE_DEVICE_MEMORY` set (bytes, or with a K/M/G suffix), the
    /// device is taken to have that much memory: an allocation that would
    /// bring the bytes allocated through this `Gpu` past it is refused, with
    /// the bytes named (counted without frees, so an upper bound of what is
    /// live: meant to test what a run does on a small device).
    pub fn buffer_flags<T>(&self, len: usize, flags: cl_mem_flags) -> Result<Buffer<T>> {
        let bytes = len.max(1) * std::mem::size_of::<T>();
        if bytes as u64 > self.info.max_alloc {
            return Err(Error::DeviceUnsupported {
                device: self.info.name.clone(),
                what: format!(
                    "a buffer of {bytes} bytes exceeds the device's largest allocation ({} bytes)",
                    self.info.max_alloc
                ),
            });
        }
        if let Some((limit, used)) = &self.budget {
            use std::sync::atomic::Ordering;
            let before = used.fetch_add(bytes as u64, Ordering::Relaxed);
            if before + bytes as u64 > *limit {
                return Err(Error::DeviceUnsupported {
                    device: self.info.name.clone(),
                    what: format!(
                        "a buffer of {bytes} bytes does not fit: {before} bytes are allocated \
                         already and the device has {limit} bytes (SHAPECUE_DEVICE_MEMORY)"
                    ),
                });
            }
        }
        // SAFETY: no host pointer is passed; the buffer is written before it is read.
        unsafe { Buffer::<T>::create(&self.context, flags, len.max(1), std::ptr::null_mut()) }
            .map_err(|e| Error::cl(format!("clCreateBuffer({bytes} bytes)"), e))
    }

    /// Blocking write of `data` to the start of `buf`. On devices with
    /// their own memory (not CPU devices), a write of at least
    /// [`STAGED_MIN_BYTES`] goes through pinned staging
    /// ([`Gpu::write_staged`]); `SHAPECUE_STAGED_UPLOADS=1` or `0` forces it
    /// on or off.
    pub fn write<T>(&self, buf: &mut Buffer<T>, data: &[T]) -> Result<()> {
        if data.is_empty() {
            return Ok(());
        }
        if self.staged_uploads && std::mem::size_of_val(data) >= STAGED_MIN_BYTES {
            return self.write_staged(buf, data);
        }
        // SAFETY: blocking write of a live slice into a buffer at least as long
        // (callers size buffers from the same lengths).
        unsafe {
            self.queue
                .enqueue_write_buffer(buf, CL_BLOCKING, 0, data, &[])
        }
        .map(|_| ())
        .map_err(|e| Error::cl("clEnqueueWriteBuffer", e))
    }

    /// Blocking read of `out.len()` elements from the start of `buf`.
    pub fn read<T>(&self, buf: &Buffer<T>, out: &mut [T]) -> Result<()> {
        if out.is_empty() {
            return Ok(());
        }
        // SAFETY: blocking read into a live slice no longer than the buffer.
        unsafe {
            self.queue
                .enqueue_read_buffer(buf, CL_BLOCKING, 0, out, &[])
        }
        .map(|_| ())
        .map_err(|e| Error::cl("clEnqueueReadBuffer", e))
    }

    /// Writes `data` to the start of `buf` through a staging buffer the
    /// driver allocates in pinned host memory (`CL_MEM_ALLOC_HOST_PTR`),
    /// [`STAGING_BYTES`] at a time: map, copy, unmap, then a device copy
    /// into `buf`. A plain write from pageable memory makes the driver pin
    /// or bounce every page itself, far below the bus's speed on an NVIDIA
    /// GPU (docs/performance.md); from pinned memory the copy runs at the
    /// bus's speed. Blocking.
    pub fn write_staged<T>(&self, buf: &mut Buffer<T>, data: &[T]) -> Result<()> {
        let bytes: &[u8] = unsafe {
            // SAFETY: a live slice of `T` viewed as its bytes (read only).
            std::slice::from_raw_parts(data.as_ptr().cast::<u8>(), std::mem::size_of_val(data))
        };
        let chunk = bytes.len().min(STAGING_BYTES);
        let staging = self.buffer_flags::<u8>(
            chunk,
            CL_MEM_READ_WRITE | opencl3::memory::CL_MEM_ALLOC_HOST_PTR,
        )?;
        let target = opencl3::memory::ClMem::get(buf);
        for (i, part) in bytes.chunks(chunk).enumerate() {
            // The map waits for the previous chunk's device copy (in order).
            let view = self.map(
                &staging,
                opencl3::memory::CL_MAP_WRITE_INVALIDATE_REGION,
                part.len(),
            )?;
            // SAFETY: the map made `part.len()` bytes writable at this pointer
            // until the unmap; `part` does not overlap them.
            unsafe {
                std::ptr::copy_nonoverlapping(part.as_ptr(), view.ptr.cast_mut(), part.len());
            }
            view.unmap()?;
            // SAFETY: both memory objects are alive; the region lies inside
            // `staging` (chunk bytes) and inside `buf` (the caller's buffer
            // holds `data`, checked by the driver: CL_INVALID_VALUE otherwise).
            unsafe {
                opencl3::command_queue::enqueue_copy_buffer(
                    self.queue.get(),
                    opencl3::memory::ClMem::get(&staging),
                    target,
                    0,
                    i * chunk,
                    part.len(),
                    0,
                    std::ptr::null(),
                )
            }
            .map_err(|e| Error::cl("clEnqueueCopyBuffer(staged upload)", e))?;
        }
        self.finish()
    }

    /// Whether large writes go through pinned staging ([`Gpu::write`]).
    pub fn staged_uploads(&self) -> bool {
        self.staged_uploads
    }

    /// Reads several buffers with one wait: every read is enqueued without
    /// blocking, then the queue is finished once (a blocking read per
    /// buffer waits for the device's worker each time). Each `out` is filled
    /// from the start of its buffer.
    pub fn read_many<T>(&self, reads: &mut [(&Buffer<T>, &mut [T])]) -> Result<()> {
        for (buf, out) in reads.iter_mut() {
            if out.is_empty() {
                continue;
            }
            // SAFETY: a non-blocking read into a live slice no longer than the
            // buffer; the slices stay borrowed until `finish` below returns,
            // and an error from it leaves them borrowed only to this call.
            unsafe {
                self.queue
                    .enqueue_read_buffer(buf, opencl3::types::CL_NON_BLOCKING, 0, out, &[])
            }
            .map_err(|e| {
                // Do not return while earlier reads may still write into `reads`.
                let _ = self.queue.finish();
                Error::cl("clEnqueueReadBuffer", e)
            })?;
        }
        self.finish()
    }

    /// Maps the first `len` elements of `buf` for reading (blocking): the
    /// device's own memory where it is the host's (CPU runtimes: no copy and
    /// no fresh pages), a copy the driver makes otherwise. Unmapped when the
    /// returned view is dropped. The view borrows `buf` shared, so nothing
    /// can launch a kernel that writes it through `&mut` while it lives.
    pub fn map_read<'b, T: Copy>(
        &'b self,
        buf: &'b Buffer<T>,
        len: usize,
    ) -> Result<Mapped<'b, T>> {
        self.map(buf, opencl3::memory::CL_MAP_READ, len)
    }

    /// Maps the first `len` elements of `buf` (blocking) with `flags`, as a
    /// view that unmaps when dropped; a pointer the map returns null or not
    /// aligned for `T` is an error (and unmapped).
    fn map<'b, T>(
        &'b self,
        buf: &'b Buffer<T>,
        flags: opencl3::types::cl_map_flags,
        len: usize,
    ) -> Result<Mapped<'b, T>> {
        let mem = opencl3::memory::ClMem::get(buf);
        if len == 0 {
            let ptr = std::ptr::NonNull::<T>::dangling().as_ptr();
            return Ok(Mapped {
                queue: &self.queue,
                mem,
                ptr,
                len,
            });
        }
        let mut ptr: opencl3::types::cl_mem = std::ptr::null_mut();
        // SAFETY: a blocking map of a range inside the buffer; the pointer is
        // only used through `Mapped` and unmapped in its `Drop` or `unmap`.
        unsafe {
            self.queue.enqueue_map_buffer(
                buf,
                CL_BLOCKING,
                flags,
                0,
                len * std::mem::size_of::<T>(),
                &mut ptr,
                &[],
            )
        }
        .map_err(|e| Error::cl("clEnqueueMapBuffer", e))?;
        let view = Mapped {
            queue: &self.queue,
            mem,
            ptr: ptr.cast::<T>(),
            len,
        };
        if ptr.is_null() || !(ptr as usize).is_multiple_of(std::mem::align_of::<T>()) {
            // Dropping the view unmaps it.
            return Err(Error::cl(
                "clEnqueueMapBuffer",
                format!("a pointer ({ptr:p}) not aligned for the buffer's elements"),
            ));
        }
        Ok(view)
    }

    /// Maps the first `len` elements of `buf` for writing, with their old
    /// contents discarded (`CL_MAP_WRITE_INVALIDATE_REGION`), lets `fill`
    /// write them in place, then unmaps and waits. On CPU runtimes that is
    /// the device's own memory: a buffer built on the host this way costs no
    /// host copy and no second set of fresh pages. `fill` must write every
    /// element (what it leaves is unspecified). Waits for the queue first.
    pub fn write_with<T: bytemuck::Pod, R>(
        &self,
        buf: &mut Buffer<T>,
        len: usize,
        fill: impl FnOnce(&mut [T]) -> R,
    ) -> Result<R> {
        let view = self.map(buf, opencl3::memory::CL_MAP_WRITE_INVALIDATE_REGION, len)?;
        // SAFETY: the map made `len` elements of a plain-old-data type
        // writable at this pointer (non-null and aligned, or dangling for
        // none) until the unmap, and no other slice of them exists.
        let out = fill(unsafe { std::slice::from_raw_parts_mut(view.ptr.cast_mut(), len) });
        view.unmap()?;
        Ok(out)
    }

    /// Reads `out.len()` elements of `buf` from element `offset` on. Only
    /// enqueued: the data is there after [`Gpu::finish`] (or any blocking
    /// call on the queue), so many small reads cost one wait.
    ///
    /// # Safety
    /// `out` must stay alive and untouched until the queue has finished, and
    /// `offset + out.len()` must not pass the end of `buf`.
    pub unsafe fn read_at_async<T>(
        &self,
        buf: &Buffer<T>,
        offset: usize,
        out: &mut [T],
    ) -> Result<()> {
        if out.is_empty() {
            return Ok(());
        }
        // SAFETY: the caller keeps `out` alive until the queue finishes and
        // keeps the range inside the buffer.
        unsafe {
            self.queue.enqueue_read_buffer(
                buf,
                opencl3::types::CL_NON_BLOCKING,
                offset * std::mem::size_of::<T>(),
                out,
                &[],
            )
        }
        .map(|_| ())
        .map_err(|e| Error::cl("clEnqueueReadBuffer", e))
    }

    /// Enqueues filling the first `len` elements of `buf` with `pattern`
    /// repeated (`len` a multiple of `pattern.len()`), without waiting: the
    /// device writes the buffer, no host copy of it is made.
    pub fn fill<T>(&self, buf: &mut Buffer<T>, pattern: &[T], len: usize) -> Result<()> {
        if len == 0 {
            return Ok(());
        }
        debug_assert!(len.is_multiple_of(pattern.len()));
        // SAFETY: the pattern is copied at enqueue time (OpenCL 1.2
        // clEnqueueFillBuffer); callers size `len` within the buffer.
        unsafe {
            self.queue
                .enqueue_fill_buffer(buf, pattern, 0, len * std::mem::size_of::<T>(), &[])
        }
        .map(|_| ())
        .map_err(|e| Error::cl("clEnqueueFillBuffer", e))
    }

    /// Enqueues zeroing the first `len` elements of `buf` without waiting
    /// (the in-order queue runs it before later commands): resetting a
    /// counter this way does not stall the host between passes.
    pub fn zero<T: bytemuck::Zeroable>(&self, buf: &mut Buffer<T>, len: usize) -> Result<()> {
        if len == 0 {
            return Ok(());
        }
        let bytes = len * std::mem::size_of::<T>();
        let pattern = [0u8; 128];
        let size = zero_pattern_bytes(bytes);
        // SAFETY: `pattern` holds `size` bytes and is copied at enqueue time
        // (OpenCL 1.2 clEnqueueFillBuffer); callers size `len` within the
        // buffer, and `bytes` is a multiple of `size`. The returned event is
        // released at once (the in-order queue still orders the fill).
        let ev = unsafe {
            opencl3::command_queue::enqueue_fill_buffer(
                self.queue.get(),
                opencl3::memory::ClMem::get(buf),
                pattern.as_ptr().cast(),
                size,
                0,
                bytes,
                0,
                std::ptr::null(),
            )
        }
        .map_err(|e| Error::cl("clEnqueueFillBuffer", opencl3::error_codes::ClError(e)))?;
        drop(opencl3::event::Event::new(ev));
        Ok(())
    }

    /// Submits every queued command to the device without waiting.
    pub fn flush(&self) -> Result<()> {
        self.queue.flush().map_err(|e| Error::cl("clFlush", e))
    }

    /// Waits for every queued command.
    pub fn finish(&self) -> Result<()> {
        self.queue.finish().map_err(|e| Error::cl("clFinish", e))
    }
}

/// Bytes in the zero pattern of [`Gpu::zero`]: the largest pattern OpenCL
/// allows (a power of two up to 128 bytes) that divides `bytes`. Runtimes
/// fill a pattern at a time (PoCL 3.1's CPU devices copy one pattern per
/// step), so a pattern of one element fills hundreds of megabytes slowly
/// (docs/performance.md).
fn zero_pattern_bytes(bytes: usize) -> usize {
    let mut p = 128;
    while p > 1 && !bytes.is_multiple_of(p) {
        p /= 2;
    }
    p
}

/// A device buffer mapped for reading ([`Gpu::map_read`]), read as a slice;
/// unmapped (and the unmap waited for) when dropped.
pub struct Mapped<'b, T> {
    queue: &'b CommandQueue,
    mem: opencl3::types::cl_mem,
    ptr: *const T,
    /// Elements; 0 for a view of nothing, which was never mapped.
    len: usize,
}

impl<T> std::ops::Deref for Mapped<'_, T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        // SAFETY: the blocking map made `len` elements readable at `ptr`
        // (checked non-null and aligned), and they stay mapped until drop.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

impl<T> Mapped<'_, T> {
    /// Unmaps now and waits, reporting a failure (a drop unmaps silently).
    fn unmap(self) -> Result<()> {
        let view = std::mem::ManuallyDrop::new(self);
        if view.len == 0 {
            return Ok(());
        }
        // SAFETY: `ptr` is the pointer the map returned for `mem`; `view` is
        // not dropped, so it is unmapped once, and no slice of it is alive.
        unsafe {
            view.queue
                .enqueue_unmap_mem_object(view.mem, view.ptr as *mut _, &[])
        }
        .map_err(|e| Error::cl("clEnqueueUnmapMemObject", e))?;
        view.queue.finish().map_err(|e| Error::cl("clFinish", e))
    }
}

impl<T> Drop for Mapped<'_, T> {
    fn drop(&mut self) {
        if self.len > 0 {
            // SAFETY: `ptr` is the pointer the map returned for `mem`, and
            // no slice of it outlives `self`.
            let unmapped = unsafe {
                self.queue
                    .enqueue_unmap_mem_object(self.mem, self.ptr as *mut _, &[])
            };
            if unmapped.is_ok() {
                let _ = self.queue.finish();
            }
        }
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        self.persist_programs();
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// The device the library's unit tests run on (the default pick, as for the
/// integration tests), or a panic saying that they need one.
#[cfg(test)]
pub(crate) fn test_gpu() -> Arc<Gpu> {
    match Gpu::new(None) {
        Ok(g) => Arc::new(g),
        Err(e) => panic!("this test needs an OpenCL device (PoCL on CPU is enough): {e}"),
    }
}
