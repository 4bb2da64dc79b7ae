//! Kernel launches: arguments, the 1-D launch every stage uses (global size
//! padded to [`LOCAL_SIZE`]) and kernel times from profiling events.

use super::{Gpu, LOCAL_SIZE};
use crate::error::{Error, Result};
use opencl3::event::Event;
use opencl3::kernel::{ExecuteKernel, Kernel};
use opencl3::memory::Buffer;

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
