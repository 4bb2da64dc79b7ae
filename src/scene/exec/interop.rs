//! The executor's side of `--interop`: what the device, a GL context and
//! Vulkan offer ([`interop_offer`], for [`decide_interop`]), and the
//! external-memory route of the edges frame ([`SharedEdges`]): one Vulkan
//! allocation per topology, exported twice as an opaque fd, imported by
//! OpenCL (the edges stage compacts what it draws into it) and by GL (the
//! renderer draws from it), so that nothing drawn passes through the host.
//!
//! [`decide_interop`]: crate::spec::interop::decide_interop

use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu::external::{ExternalBuffer, reports_external_memory};
use crate::gpu::vulkan::{ExportedBuffer, VulkanExporter};
use crate::render::external::ImportedBuffer;
use crate::render::{RenderOptions, Renderer};
use crate::spec::interop::{InteropMode, InteropOffer};
use crate::stages::edges::{EdgeStage, SharedDrawn};

/// What `gpu`, a GL context and Vulkan offer for `mode`. The device's
/// extensions are always read; a GL context and a Vulkan instance are made
/// only when the device can import external memory (and `mode` is not
/// `off`), since no answer of theirs could change the route otherwise.
pub fn interop_offer(gpu: &Gpu, mode: InteropMode) -> InteropOffer {
    let mut o = InteropOffer {
        device: gpu.info.name.clone(),
        cl_gl_sharing: gpu.info.gl_sharing,
        cl_external_memory: reports_external_memory(gpu),
        ..InteropOffer::default()
    };
    if mode == InteropMode::Off || !o.wants_probe() {
        return o;
    }
    let tiny = RenderOptions {
        width: 1,
        height: 1,
        msaa: 0,
        ..RenderOptions::default()
    };
    o.gl_memory_object_fd = Some(Renderer::new(tiny).is_ok_and(|r| r.memory_object_fd()));
    match crate::gpu::vulkan::probe() {
        Ok(_) => o.vk_external_memory_fd = Some(true),
        Err(d) => {
            o.vk_external_memory_fd = Some(false);
            o.vk_detail = Some(d);
        }
    }
    o
}

/// The edges frame's shared buffer on the external-memory route, sized once
/// per topology and cap mode. Freed in order by [`SharedEdges::free`] (GL's
/// import, then OpenCL's, then the Vulkan allocation and device); on an
/// early exit the fields drop in that order too, and GL's objects go with
/// the renderer's context.
pub struct SharedEdges {
    gl: Option<ImportedBuffer>,
    cl: ExternalBuffer,
    _memory: ExportedBuffer,
    _vulkan: VulkanExporter,
    vertices: usize,
}

impl SharedEdges {
    /// Exports one buffer large enough for everything `stage` may draw
    /// with `mode` and imports it into OpenCL and into `r`'s GL context.
    ///
    /// # Errors
    /// Vulkan, OpenCL or GL failures (the caller's decision said all three
    /// offer the route, so a failure here is reported, not hidden).
    pub fn new(
        gpu: &Gpu,
        r: &mut Renderer,
        stage: &EdgeStage,
        mode: crate::spec::edges::CapMode,
    ) -> Result<SharedEdges> {
        let vertices = stage.shared_vertices(mode).max(1);
        let bytes = 16 * vertices as u64;
        // The Vulkan device GL runs on, when GL names it.
        let uuid = r.device_uuids().first().copied();
        let vulkan = VulkanExporter::new(uuid)?;
        let memory = vulkan.export(bytes, false)?;
        let cl = ExternalBuffer::import(gpu, memory.fd()?, bytes)?;
        let gl = r.import_buffer(memory.fd()?, memory.allocation_size(), bytes)?;
        Ok(SharedEdges {
            gl: Some(gl),
            cl,
            _memory: memory,
            _vulkan: vulkan,
            vertices,
        })
    }

    /// Compacts what the stage's last run drew into the shared buffer
    /// (between OpenCL's acquire and release; the release finishes the
    /// queue, so GL may draw after it).
    ///
    /// # Errors
    /// Device failures.
    pub fn compact(&mut self, gpu: &Gpu, stage: &mut EdgeStage) -> Result<SharedDrawn> {
        self.cl.acquire(gpu)?;
        let out = stage.compact_into(self.cl.buffer_mut(), self.vertices);
        let released = self.cl.release(gpu);
        let out = out?;
        released?;
        Ok(out)
    }

    /// Reads the compacted edge quads back (for the SVG's visibility test only).
    ///
    /// # Errors
    /// Device failures.
    pub fn read_edges(&self, gpu: &Gpu, d: &SharedDrawn) -> Result<Vec<[f32; 4]>> {
        let mut v = vec![[0f32; 4]; 4 * d.edges];
        if d.edges > 0 {
            self.cl.acquire(gpu)?;
            // SAFETY: `v` is untouched until the release below finishes the
            // queue (also when the read fails); 4e vertices lie inside the
            // shared buffer.
            let read =
                unsafe { gpu.read_at_async(self.cl.buffer(), 0, bytemuck::cast_slice_mut(&mut v)) };
            let released = self.cl.release(gpu);
            read?;
            released?;
        }
        Ok(v)
    }

    /// Draws what [`compact`](Self::compact) wrote, flat `color`, into the
    /// frame in progress.
    ///
    /// # Errors
    /// GL failures.
    pub fn draw(&self, r: &mut Renderer, d: &SharedDrawn, color: [f32; 4]) -> Result<()> {
        let Some(gl) = &self.gl else { return Ok(()) };
        let e = d.edges;
        r.draw_imported(gl, 0, 4 * e, 4, color)?;
        if d.mh {
            r.draw_imported(gl, 4 * e, 3 * e, 3, color)?;
            r.draw_imported(gl, 7 * e, 3 * e, 3, color)?;
        }
        r.draw_imported(gl, d.caps_at, 4 * d.adjacency_caps, 4, color)
    }

    /// Frees GL's import, then OpenCL's, then the Vulkan memory and device.
    pub fn free(mut self, r: &mut Renderer) {
        if let Some(gl) = self.gl.take() {
            r.free_imported(gl);
        }
    }
}
