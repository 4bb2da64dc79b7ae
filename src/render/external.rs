//! The GL half of the external-memory route: memory another API allocated
//! and exported as an opaque file descriptor (a Vulkan allocation that
//! OpenCL kernels write) imported as a GL buffer (`GL_EXT_memory_object`,
//! `GL_EXT_memory_object_fd`), and the clip-space primitives in it drawn
//! as [`Renderer::draw_clip_quads`] draws uploaded ones, with no copy
//! through the host.
//!
//! Calls: `glCreateMemoryObjectsEXT`, `glImportMemoryFdEXT(mem, size,
//! GL_HANDLE_TYPE_OPAQUE_FD_EXT, fd)` (GL owns the fd once it succeeds),
//! then a buffer whose storage is that memory (`glBufferStorageMemEXT`).
//! glow does not load these entry points; they come from
//! `eglGetProcAddress`, as glow's own do, and only once the context
//! reports the extensions ([`Renderer::memory_object_fd`]).
//!
//! An [`ImportedBuffer`] is a handle: [`Renderer::free_imported`] deletes
//! its buffer, vertex array and memory object; on an early exit they go
//! with the renderer's context. The screen only draws: what writes the
//! memory, and when it is done writing, is the caller's business (the
//! OpenCL side finishes its queue before a draw).

use std::ffi::c_void;
use std::os::fd::{IntoRawFd, OwnedFd};

use glow::HasContext;

use super::Renderer;
use super::programs::check;
use crate::error::{Error, Result};

/// `GL_HANDLE_TYPE_OPAQUE_FD_EXT`.
const HANDLE_TYPE_OPAQUE_FD: u32 = 0x9586;
/// `GL_NUM_DEVICE_UUIDS_EXT`.
const NUM_DEVICE_UUIDS: u32 = 0x9596;
/// `GL_DEVICE_UUID_EXT`.
const DEVICE_UUID: u32 = 0x9597;

type CreateMemoryObjects = unsafe extern "system" fn(i32, *mut u32);
type DeleteMemoryObjects = unsafe extern "system" fn(i32, *const u32);
type ImportMemoryFd = unsafe extern "system" fn(u32, u64, u32, i32);
type BufferStorageMem = unsafe extern "system" fn(u32, isize, u32, u64);
type GetUnsignedBytei = unsafe extern "system" fn(u32, u32, *mut u8);

/// The `GL_EXT_memory_object(_fd)` entry points.
#[derive(Clone, Copy)]
struct MemoryObjectFns {
    create: CreateMemoryObjects,
    delete: DeleteMemoryObjects,
    import_fd: ImportMemoryFd,
    storage: BufferStorageMem,
    get_ubyte_i: GetUnsignedBytei,
}

/// A GL buffer on imported memory, and the vertex array that reads it as
/// clip-space `vec4`s ([`Renderer::draw_imported`]).
#[derive(Debug)]
pub struct ImportedBuffer {
    memory: u32,
    buffer: glow::NativeBuffer,
    vao: glow::NativeVertexArray,
    /// Bytes the buffer holds.
    bytes: u64,
}

impl ImportedBuffer {
    /// Bytes the buffer holds.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// `vec4` vertices the buffer holds.
    pub fn vertices(&self) -> usize {
        (self.bytes / 16) as usize
    }
}

impl Renderer {
    /// Whether this context reports `GL_EXT_memory_object` and
    /// `GL_EXT_memory_object_fd`, the GL half of the external-memory route.
    pub fn memory_object_fd(&self) -> bool {
        let ext = self.gl.supported_extensions();
        ext.contains("GL_EXT_memory_object") && ext.contains("GL_EXT_memory_object_fd")
    }

    fn memory_object_fns(&self) -> Result<MemoryObjectFns> {
        if !self.memory_object_fd() {
            return Err(Error::render(
                "importing external memory",
                "the GL context does not report GL_EXT_memory_object_fd",
            ));
        }
        let load = |name: &str| -> Result<*const c_void> {
            let p = self.ctx.proc_address(name);
            if p.is_null() {
                Err(Error::render(
                    name,
                    "eglGetProcAddress found no such entry point",
                ))
            } else {
                Ok(p)
            }
        };
        // SAFETY: each pointer is the named GL_EXT_memory_object(_fd) entry
        // point, whose C signature the type spells out.
        unsafe {
            Ok(MemoryObjectFns {
                create: std::mem::transmute::<*const c_void, CreateMemoryObjects>(load(
                    "glCreateMemoryObjectsEXT",
                )?),
                delete: std::mem::transmute::<*const c_void, DeleteMemoryObjects>(load(
                    "glDeleteMemoryObjectsEXT",
                )?),
                import_fd: std::mem::transmute::<*const c_void, ImportMemoryFd>(load(
                    "glImportMemoryFdEXT",
                )?),
                storage: std::mem::transmute::<*const c_void, BufferStorageMem>(load(
                    "glBufferStorageMemEXT",
                )?),
                get_ubyte_i: std::mem::transmute::<*const c_void, GetUnsignedBytei>(load(
                    "glGetUnsignedBytei_vEXT",
                )?),
            })
        }
    }

    /// The UUIDs of the devices this context runs on (`GL_DEVICE_UUID_EXT`),
    /// to pick the Vulkan device that exports the memory GL imports; empty
    /// without `GL_EXT_memory_object_fd`.
    pub fn device_uuids(&self) -> Vec<[u8; 16]> {
        let Ok(f) = self.memory_object_fns() else {
            return Vec::new();
        };
        if self.ctx.make_current().is_err() {
            return Vec::new();
        }
        // SAFETY: the context is current; each query writes GL_UUID_SIZE_EXT
        // (16) bytes into a 16-byte array.
        unsafe {
            let n = self.gl.get_parameter_i32(NUM_DEVICE_UUIDS).max(0) as u32;
            let mut out = Vec::new();
            for i in 0..n {
                let mut uuid = [0u8; 16];
                (f.get_ubyte_i)(DEVICE_UUID, i, uuid.as_mut_ptr());
                out.push(uuid);
            }
            // A failed query leaves an error that a later check would blame
            // on something else.
            while self.gl.get_error() != glow::NO_ERROR {}
            out
        }
    }

    /// Imports the memory behind `fd` (`allocation` bytes, as the exporter
    /// allocated them) as a GL buffer of its first `bytes` bytes, to draw
    /// from with [`draw_imported`](Self::draw_imported). GL owns the fd once
    /// the import succeeds; on failure it is closed.
    ///
    /// # Errors
    /// [`Error::Render`] without `GL_EXT_memory_object_fd`, when `bytes` is
    /// 0, not a whole number of vertices or larger than `allocation`, or
    /// when GL reports an error.
    pub fn import_buffer(
        &mut self,
        fd: OwnedFd,
        allocation: u64,
        bytes: u64,
    ) -> Result<ImportedBuffer> {
        let f = self.memory_object_fns()?;
        if bytes == 0
            || !bytes.is_multiple_of(16)
            || bytes > allocation
            || isize::try_from(bytes).is_err()
        {
            return Err(Error::render(
                "importing external memory",
                format!(
                    "{bytes} bytes of a {allocation}-byte allocation: needs a positive whole \
                     number of 16-byte vertices within the allocation"
                ),
            ));
        }
        self.ctx.make_current()?;
        let gl = &self.gl;
        // SAFETY: the context is current; the memory object, buffer and
        // vertex array are made here and deleted on every failure below.
        unsafe {
            while gl.get_error() != glow::NO_ERROR {}
            let mut memory = 0u32;
            (f.create)(1, &raw mut memory);
            use std::os::fd::AsRawFd;
            (f.import_fd)(memory, allocation, HANDLE_TYPE_OPAQUE_FD, fd.as_raw_fd());
            let e = gl.get_error();
            if e != glow::NO_ERROR {
                (f.delete)(1, &raw const memory);
                // `fd` is still ours and closes on drop.
                return Err(Error::render(
                    "glImportMemoryFdEXT",
                    format!("GL error 0x{e:04X}"),
                ));
            }
            let _ = fd.into_raw_fd();
            let made = (|| -> std::result::Result<(glow::NativeBuffer, glow::NativeVertexArray), String> {
                let buffer = gl.create_buffer()?;
                let vao = match gl.create_vertex_array() {
                    Ok(v) => v,
                    Err(e) => {
                        gl.delete_buffer(buffer);
                        return Err(e);
                    }
                };
                Ok((buffer, vao))
            })();
            let (buffer, vao) = match made {
                Ok(x) => x,
                Err(e) => {
                    (f.delete)(1, &raw const memory);
                    return Err(Error::render("creating the imported buffer", e));
                }
            };
            gl.bind_vertex_array(Some(vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(buffer));
            (f.storage)(glow::ARRAY_BUFFER, bytes as isize, memory, 0);
            gl.enable_vertex_attrib_array(0);
            gl.vertex_attrib_pointer_f32(0, 4, glow::FLOAT, false, 16, 0);
            // Quads are drawn through the shared index pattern.
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(self.clip_bufs[1]));
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            let out = ImportedBuffer {
                memory,
                buffer,
                vao,
                bytes,
            };
            if let Err(e) = check(gl, "glBufferStorageMemEXT (imported buffer)") {
                self.free_imported(out);
                return Err(e);
            }
            Ok(out)
        }
    }

    /// Deletes an imported buffer's vertex array, buffer and memory object.
    pub fn free_imported(&mut self, b: ImportedBuffer) {
        let Ok(f) = self.memory_object_fns() else {
            return;
        };
        if self.ctx.make_current().is_err() {
            // The objects go with the context.
            return;
        }
        let gl = &self.gl;
        // SAFETY: the objects were made on this context by `import_buffer`.
        unsafe {
            gl.delete_vertex_array(b.vao);
            gl.delete_buffer(b.buffer);
            (f.delete)(1, &raw const b.memory);
        }
    }

    /// Draws `count` clip-space vertices of `b` from vertex `first`, as
    /// quads (`per` = 4, perimeter order, as
    /// [`draw_clip_quads`](Self::draw_clip_quads)) or triangles (`per` = 3),
    /// flat `color`, depth-tested with ≤, into the frame in progress. The
    /// range must hold drawable primitives only (the edges stage's
    /// compaction writes no markers), since GL reads them as they are.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] outside a frame, for `per` other than 3
    /// or 4, or a range that is not whole primitives inside the buffer.
    pub fn draw_imported(
        &mut self,
        b: &ImportedBuffer,
        first: usize,
        count: usize,
        per: usize,
        color: [f32; 4],
    ) -> Result<()> {
        let what = "draw_imported";
        let fits = first.checked_add(count).is_some_and(|e| e <= b.vertices());
        if !(per == 3 || per == 4) || !count.is_multiple_of(per) || !fits {
            return Err(Error::InvalidArgument(format!(
                "{what}: {count} vertices from {first} as {per}-vertex primitives in a buffer \
                 of {} vertices",
                b.vertices()
            )));
        }
        self.frame(what)?;
        if count == 0 {
            return Ok(());
        }
        let prims = count / per;
        let index_count = if per == 4 { prims * 6 } else { count };
        let (Ok(first_i), Ok(n)) = (i32::try_from(first), i32::try_from(index_count)) else {
            return Err(Error::InvalidArgument(format!(
                "{what}: {prims} primitives are too many for one draw"
            )));
        };
        let quads = if per == 4 { prims } else { 0 };
        // SAFETY: the context is current (`frame`); an imported buffer's
        // vertex array is a clip-vertex array of this renderer.
        unsafe { self.clip_state(b.vao, color, quads) };
        let gl = &self.gl;
        // SAFETY: the context is current (`frame`); the pattern covers
        // `prims` quads (clip_state) and every index it yields, offset by
        // `first`, is < first + count ≤ the buffer's vertices.
        unsafe {
            if per == 4 {
                gl.draw_elements_base_vertex(glow::TRIANGLES, n, glow::UNSIGNED_INT, 0, first_i);
            } else {
                gl.draw_arrays(glow::TRIANGLES, first_i, n);
            }
            self.clip_done();
        }
        check(gl, &format!("{what} ({prims} primitives)"))
    }
}
