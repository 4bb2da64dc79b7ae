//! OpenCL buffers on memory another API allocated and exported as an opaque
//! file descriptor (`cl_khr_external_memory_opaque_fd`): the OpenCL half of
//! the external-memory route, where a Vulkan allocation ([`super::vulkan`])
//! is imported by OpenCL and by GL, so that kernels write what GL draws.
//!
//! Calls: `clCreateBufferWithProperties` with
//! `{CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR, fd, 0}` (OpenCL 3.0, through
//! `cl3`); kernels write the buffer between
//! `clEnqueueAcquireExternalMemObjectsKHR` and
//! `clEnqueueReleaseExternalMemObjectsKHR`, then the queue is finished before
//! GL draws (no external semaphore: a finish is the one wait a frame has
//! anyway). The two extension functions are looked up with
//! `clGetExtensionFunctionAddressForPlatform`, as the extension requires;
//! nothing here is called unless the device reports the extension
//! ([`reports_external_memory`]). PoCL does not, so this half runs on GPUs only.

use std::ffi::{CString, c_void};
use std::os::fd::{IntoRawFd, OwnedFd};

use opencl3::device::Device;
use opencl3::memory::{Buffer, CL_MEM_READ_WRITE, ClMem};
use opencl3::types::{cl_command_queue, cl_event, cl_int, cl_mem, cl_mem_properties, cl_uint};

use super::Gpu;
use crate::error::{Error, Result};

/// `CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR`.
const HANDLE_OPAQUE_FD: cl_mem_properties = 0x2060;
/// `CL_DEVICE_UUID_KHR` (`cl_khr_device_uuid`).
const DEVICE_UUID: u32 = 0x106A;

/// Whether `gpu`'s device reports `cl_khr_external_memory_opaque_fd`.
pub fn reports_external_memory(gpu: &Gpu) -> bool {
    has_extension(gpu, "cl_khr_external_memory_opaque_fd")
}

fn has_extension(gpu: &Gpu, name: &str) -> bool {
    Device::new(gpu.info.id)
        .extensions()
        .is_ok_and(|e| e.split_whitespace().any(|x| x == name))
}

/// The device's UUID (`cl_khr_device_uuid`), which names the same device as
/// Vulkan's `deviceUUID` and GL's `GL_DEVICE_UUID_EXT`.
pub fn device_uuid(gpu: &Gpu) -> Option<[u8; 16]> {
    if !has_extension(gpu, "cl_khr_device_uuid") {
        return None;
    }
    let b = Device::new(gpu.info.id).get_data(DEVICE_UUID).ok()?;
    b.try_into().ok()
}

type AcquireRelease = unsafe extern "system" fn(
    cl_command_queue,
    cl_uint,
    *const cl_mem,
    cl_uint,
    *const cl_event,
    *mut cl_event,
) -> cl_int;

type ExtensionAddress = unsafe extern "system" fn(
    opencl3::types::cl_platform_id,
    *const std::ffi::c_char,
) -> *mut c_void;

/// The extension's acquire and release entry points for `gpu`'s platform.
fn entry_points(gpu: &Gpu) -> Result<(AcquireRelease, AcquireRelease)> {
    let platform = Device::new(gpu.info.id)
        .platform()
        .map_err(|e| Error::cl("clGetDeviceInfo(CL_DEVICE_PLATFORM)", e))?;
    // The ICD loader is already loaded (the device came from it): look up
    // the core 1.2 function that finds extension functions per platform.
    // SAFETY: dlopen with RTLD_NOLOAD only returns a library already mapped;
    // the symbol, when found, has the OpenCL 1.2 signature.
    let lookup: ExtensionAddress = unsafe {
        let lib = libc::dlopen(
            c"libOpenCL.so.1".as_ptr(),
            libc::RTLD_NOW | libc::RTLD_NOLOAD,
        );
        let sym = if lib.is_null() {
            std::ptr::null_mut()
        } else {
            libc::dlsym(lib, c"clGetExtensionFunctionAddressForPlatform".as_ptr())
        };
        if sym.is_null() {
            return Err(Error::cl(
                "clGetExtensionFunctionAddressForPlatform",
                "not found in libOpenCL.so.1",
            ));
        }
        std::mem::transmute::<*mut c_void, ExtensionAddress>(sym)
    };
    let get = |name: &str| -> Result<AcquireRelease> {
        let c = CString::new(name).map_err(|e| Error::cl(name, e))?;
        // SAFETY: a valid platform and a NUL-terminated name.
        let p = unsafe { lookup(platform, c.as_ptr()) };
        if p.is_null() {
            return Err(Error::cl(name, "the platform does not provide it"));
        }
        // SAFETY: the extension defines the function with this signature.
        Ok(unsafe { std::mem::transmute::<*mut c_void, AcquireRelease>(p) })
    };
    Ok((
        get("clEnqueueAcquireExternalMemObjectsKHR")?,
        get("clEnqueueReleaseExternalMemObjectsKHR")?,
    ))
}

/// An OpenCL buffer of floats on imported external memory.
pub struct ExternalBuffer {
    buffer: Buffer<f32>,
    bytes: u64,
    acquire: AcquireRelease,
    release: AcquireRelease,
}

impl ExternalBuffer {
    /// Imports `bytes` bytes of the memory behind `fd` (an opaque fd, e.g.
    /// from [`super::vulkan::ExportedBuffer::fd`]) as a read-write buffer.
    /// On success the implementation owns the fd; on failure it is closed.
    ///
    /// # Errors
    /// [`Error::DeviceUnsupported`] when the device does not report
    /// `cl_khr_external_memory_opaque_fd`; [`Error::Cl`] when the import or
    /// the entry-point look-up fails.
    pub fn import(gpu: &Gpu, fd: OwnedFd, bytes: u64) -> Result<ExternalBuffer> {
        if !reports_external_memory(gpu) {
            return Err(Error::DeviceUnsupported {
                device: gpu.info.name.clone(),
                what: "importing external memory needs cl_khr_external_memory_opaque_fd".into(),
            });
        }
        let (acquire, release) = entry_points(gpu)?;
        if bytes == 0 || !bytes.is_multiple_of(4) {
            return Err(Error::InvalidArgument(format!(
                "an external buffer of floats needs a positive multiple of 4 bytes, got {bytes}"
            )));
        }
        use std::os::fd::AsRawFd;
        let props: [cl_mem_properties; 3] =
            [HANDLE_OPAQUE_FD, fd.as_raw_fd() as cl_mem_properties, 0];
        // SAFETY: a valid context, a zero-terminated property list, no host pointer.
        let mem = unsafe {
            opencl3::memory::create_buffer_with_properties(
                gpu.context().get(),
                props.as_ptr(),
                CL_MEM_READ_WRITE,
                bytes as usize,
                std::ptr::null_mut(),
            )
        }
        .map_err(|e| Error::cl("clCreateBufferWithProperties (opaque fd)", e))?;
        // The import took the fd over.
        let _ = fd.into_raw_fd();
        Ok(ExternalBuffer {
            buffer: Buffer::new(mem),
            bytes,
            acquire,
            release,
        })
    }

    /// The buffer, for kernel arguments (between [`acquire`](Self::acquire)
    /// and [`release`](Self::release)).
    pub fn buffer(&self) -> &Buffer<f32> {
        &self.buffer
    }

    /// The buffer, for copies into it.
    pub fn buffer_mut(&mut self) -> &mut Buffer<f32> {
        &mut self.buffer
    }

    /// Floats the buffer holds.
    pub fn len(&self) -> usize {
        (self.bytes / 4) as usize
    }

    /// Whether the buffer holds nothing (never: imports are at least 4 bytes).
    pub fn is_empty(&self) -> bool {
        self.bytes == 0
    }

    fn enqueue(&self, gpu: &Gpu, f: AcquireRelease, what: &str) -> Result<()> {
        let mem = [self.buffer.get()];
        let mut ev: cl_event = std::ptr::null_mut();
        // SAFETY: a valid queue and one mem object of its context.
        let status = unsafe {
            f(
                gpu.queue().get(),
                1,
                mem.as_ptr(),
                0,
                std::ptr::null(),
                &raw mut ev,
            )
        };
        if !ev.is_null() {
            // SAFETY: the event was returned to us and nobody else holds it.
            let _ = unsafe { opencl3::event::release_event(ev) };
        }
        if status != 0 {
            return Err(Error::cl(what, status));
        }
        Ok(())
    }

    /// Enqueues the acquire: kernels enqueued after it may use the buffer.
    ///
    /// # Errors
    /// [`Error::Cl`] when the driver refuses.
    pub fn acquire(&self, gpu: &Gpu) -> Result<()> {
        self.enqueue(gpu, self.acquire, "clEnqueueAcquireExternalMemObjectsKHR")
    }

    /// Enqueues the release and finishes the queue, so that GL may draw.
    ///
    /// # Errors
    /// [`Error::Cl`] when the driver refuses or the queue fails.
    pub fn release(&self, gpu: &Gpu) -> Result<()> {
        self.enqueue(gpu, self.release, "clEnqueueReleaseExternalMemObjectsKHR")?;
        gpu.finish()
    }
}
