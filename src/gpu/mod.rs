//! The OpenCL layer: platform and device discovery, device selection, program
//! building (kernel sources embedded with `include_str!`, shared headers
//! prepended with `#line` markers so build logs name the real file), typed
//! buffers and kernel launches timed with profiling events.

mod device;
mod program;

pub use device::{DeviceInfo, list_devices};
pub use program::{COMMON_HEADERS, KernelFile, kernel_file};

use crate::error::{Error, Result};
use opencl3::command_queue::{CL_QUEUE_PROFILING_ENABLE, CommandQueue};
use opencl3::context::Context;
use opencl3::device::Device;
use opencl3::event::Event;
use opencl3::kernel::{ExecuteKernel, Kernel};
use opencl3::memory::{Buffer, CL_MEM_READ_WRITE};
use opencl3::program::Program;
use opencl3::types::{CL_BLOCKING, cl_mem_flags};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Work-group size used for every 1-D launch. PoCL compiles a new kernel
/// variant for every distinct local size, so a fixed size (with the global
/// size padded up to a multiple) keeps JIT compilation to once per kernel.
pub const LOCAL_SIZE: usize = 64;

/// An OpenCL device with its context, in-order profiling queue and a cache of
/// built programs (each (file, options) pair is compiled once per `Gpu`).
pub struct Gpu {
    /// What the device is.
    pub info: DeviceInfo,
    context: Context,
    queue: CommandQueue,
    programs: Mutex<HashMap<(String, String), Arc<Program>>>,
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
        let info = device::select(selector)?;
        let _guard = program::driver_lock();
        let device = Device::new(info.id);
        let context = Context::from_device(&device).map_err(|e| Error::cl("clCreateContext", e))?;
        #[allow(deprecated)]
        let queue = CommandQueue::create_default(&context, CL_QUEUE_PROFILING_ENABLE)
            .map_err(|e| Error::cl("clCreateCommandQueue", e))?;
        Ok(Gpu {
            info,
            context,
            queue,
            programs: Mutex::new(HashMap::new()),
        })
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
    /// program built earlier in this process with the same pair.
    pub fn program(&self, file: &KernelFile, options: &str) -> Result<Arc<Program>> {
        let key = (file.name.to_string(), options.to_string());
        let mut cache = self.programs.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(p) = cache.get(&key) {
            return Ok(p.clone());
        }
        let p = Arc::new(program::build(&self.context, file, options)?);
        cache.insert(key, p.clone());
        Ok(p)
    }

    /// Creates the kernel `name` from `program`.
    pub fn kernel(&self, program: &Program, name: &str) -> Result<Kernel> {
        Kernel::create(program, name).map_err(|e| Error::cl(format!("clCreateKernel({name})"), e))
    }

    /// Allocates an uninitialised read-write buffer of `len` elements (at
    /// least one: OpenCL rejects empty buffers).
    pub fn buffer<T>(&self, len: usize) -> Result<Buffer<T>> {
        self.buffer_flags(len, CL_MEM_READ_WRITE)
    }

    /// Allocates a buffer with explicit memory flags.
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
        // SAFETY: no host pointer is passed; the buffer is written before it is read.
        unsafe { Buffer::<T>::create(&self.context, flags, len.max(1), std::ptr::null_mut()) }
            .map_err(|e| Error::cl(format!("clCreateBuffer({bytes} bytes)"), e))
    }

    /// Blocking write of `data` to the start of `buf`.
    pub fn write<T>(&self, buf: &mut Buffer<T>, data: &[T]) -> Result<()> {
        if data.is_empty() {
            return Ok(());
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
        let pattern = [T::zeroed()];
        // SAFETY: the pattern is copied at enqueue time (OpenCL 1.2
        // clEnqueueFillBuffer); callers size `len` within the buffer.
        unsafe {
            self.queue
                .enqueue_fill_buffer(buf, &pattern, 0, len * std::mem::size_of::<T>(), &[])
        }
        .map(|_| ())
        .map_err(|e| Error::cl("clEnqueueFillBuffer", e))
    }

    /// Waits for every queued command.
    pub fn finish(&self) -> Result<()> {
        self.queue.finish().map_err(|e| Error::cl("clFinish", e))
    }
}

/// A kernel argument: a buffer or a plain scalar value.
#[derive(Clone, Copy)]
pub enum Arg {
    /// A device buffer (any element type), as its handle.
    Buf(opencl3::types::cl_mem),
    /// A 32-bit unsigned scalar.
    U32(u32),
    /// A 32-bit integer scalar.
    I32(i32),
    /// A 32-bit float scalar.
    F32(f32),
    /// A 64-bit float scalar (kernels built with double precision).
    F64(f64),
}

/// Wraps a buffer as a kernel argument.
pub fn buf<T>(b: &Buffer<T>) -> Arg {
    use opencl3::memory::ClMem;
    Arg::Buf(b.get())
}

/// Enqueues `kernel` over `n` work-items (global size padded to
/// [`LOCAL_SIZE`]; kernels guard `gid < n`). Returns the profiling event, or
/// `None` when `n == 0` (nothing to launch).
pub fn launch(gpu: &Gpu, kernel: &Kernel, n: usize, args: &[Arg]) -> Result<Option<Event>> {
    if n == 0 {
        return Ok(None);
    }
    let global = n.div_ceil(LOCAL_SIZE) * LOCAL_SIZE;
    let mut exec = ExecuteKernel::new(kernel);
    // SAFETY: argument types match the kernel signatures, which are checked by
    // the tests that run every kernel against its CPU reference.
    unsafe {
        for a in args {
            match a {
                Arg::Buf(m) => exec.set_arg(m),
                Arg::U32(v) => exec.set_arg(v),
                Arg::I32(v) => exec.set_arg(v),
                Arg::F32(v) => exec.set_arg(v),
                Arg::F64(v) => exec.set_arg(v),
            };
        }
        exec.set_global_work_size(global)
            .set_local_work_size(LOCAL_SIZE)
            .enqueue_nd_range(gpu.queue())
    }
    .map(Some)
    .map_err(|e| {
        let name = kernel.function_name().unwrap_or_default();
        Error::cl(format!("clEnqueueNDRangeKernel({name})"), e)
    })
}

/// Waits for a launched kernel and returns its kernel ms (0 when nothing was
/// launched, see [`launch`]).
pub fn wait_ms(ev: Option<Event>) -> Result<f64> {
    match ev {
        Some(e) => {
            e.wait().map_err(|e| Error::cl("clWaitForEvents", e))?;
            Ok(event_ms(&e))
        }
        None => Ok(0.0),
    }
}

/// Kernel time of a finished event in milliseconds (from profiling counters).
pub fn event_ms(ev: &Event) -> f64 {
    match (ev.profiling_command_start(), ev.profiling_command_end()) {
        (Ok(s), Ok(e)) if e >= s => (e - s) as f64 * 1e-6,
        _ => 0.0,
    }
}
