//! Making a [`Renderer`] (context, programs, buffers, targets), changing its
//! size, and starting a frame.

use glow::HasContext;

use super::context::GlContext;
use super::programs::{CLIP_FS, CLIP_VS, MESH_FS, MESH_VS, MeshUniforms, check, program};
use super::targets::{check_limits, check_options, targets};
use super::{Camera, FrameState, HeldMesh, RenderOptions, Renderer, Uploads};
use crate::error::{Error, Result};
use crate::spec::view::View;

impl Renderer {
    /// Creates a context and framebuffers of the given size. Fails with
    /// [`Error::NoGl`] (naming the apt packages) when libEGL or Mesa is missing,
    /// and with [`Error::InvalidArgument`] for a zero size, an `msaa` other than
    /// 0/2/4/8, or more samples or pixels than the driver supports.
    ///
    /// A context, its programs and its framebuffers cost tens of
    /// milliseconds on llvmpipe: a caller drawing images of several sizes
    /// keeps one renderer and calls [`reconfigure`](Self::reconfigure).
    pub fn new(opts: RenderOptions) -> Result<Renderer> {
        check_options(&opts)?;
        let (ctx, gl) = GlContext::new()?;
        // SAFETY: `GlContext::new` made the context current on this thread.
        unsafe {
            let driver = gl.get_parameter_string(glow::RENDERER);
            let version = gl.get_parameter_string(glow::VERSION);
            let max_samples = gl.get_parameter_i32(glow::MAX_SAMPLES);
            let max_size = gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE);
            check_limits(&opts, &driver, max_samples, max_size)?;
            let (ms, resolve, samples) = targets(&gl, &opts)?;

            let mesh_prog = program(&gl, "mesh", MESH_VS, MESH_FS)?;
            let mesh_u = mesh_uniforms(&gl, mesh_prog);
            let clip_prog = program(&gl, "clip", CLIP_VS, CLIP_FS)?;
            let clip_color = gl.get_uniform_location(clip_prog, "u_color");
            let (mesh_vao, mesh_bufs) = mesh_arrays(&gl)?;
            let (clip_vao, clip_bufs) = clip_arrays(&gl)?;
            gl.bind_vertex_array(None);
            fixed_state(&gl);
            check(&gl, "setting up the renderer")?;

            let info = format!("{driver}; OpenGL {version}; {}", ctx.describe());
            Ok(Renderer {
                gl,
                opts,
                mesh_prog,
                mesh_u,
                clip_prog,
                clip_color,
                mesh_vao,
                mesh_bufs,
                clip_vao,
                clip_bufs,
                quad_pattern: 0,
                ms,
                resolve,
                frame: None,
                driver,
                max_samples,
                max_size,
                info,
                samples,
                held: HeldMesh::default(),
                uploads: Uploads::default(),
                ctx,
            })
        }
    }

    /// Changes the image size, antialiasing and background, keeping the
    /// context, its programs and the uploaded mesh. The framebuffers are
    /// made anew only when the size or `msaa` changes. Errors as for
    /// [`new`](Self::new); after an error the renderer keeps its old options.
    pub fn reconfigure(&mut self, opts: RenderOptions) -> Result<()> {
        check_options(&opts)?;
        check_limits(&opts, &self.driver, self.max_samples, self.max_size)?;
        self.frame = None;
        let same = (opts.width, opts.height, opts.msaa)
            == (self.opts.width, self.opts.height, self.opts.msaa);
        if !same {
            self.ctx.make_current()?;
            // SAFETY: the context is current (above); the old targets were
            // made by it and nothing refers to them once replaced.
            unsafe {
                let (ms, resolve, samples) = targets(&self.gl, &opts)?;
                if let Some(t) = std::mem::replace(&mut self.ms, ms) {
                    t.delete(&self.gl);
                }
                std::mem::replace(&mut self.resolve, resolve).delete(&self.gl);
                self.samples = samples;
            }
        }
        self.opts = opts;
        Ok(())
    }

    /// The options the renderer was created with.
    pub fn options(&self) -> RenderOptions {
        self.opts
    }

    /// `GL_RENDERER`, `GL_VERSION`, the EGL platform and the MSAA setting, for stats.
    pub fn gl_info(&self) -> String {
        format!(
            "{}; MSAA {} ({} samples)",
            self.info, self.opts.msaa, self.samples
        )
    }

    /// How often mesh data went to GL since the renderer was made.
    pub fn uploads(&self) -> Uploads {
        self.uploads
    }

    /// Width / height of the images.
    pub fn aspect(&self) -> f32 {
        self.opts.width as f32 / self.opts.height as f32
    }

    /// Starts a frame: validates the camera, clears colour (to the background)
    /// and depth (to 1), and sets the view-projection used by
    /// [`draw_mesh`](Self::draw_mesh) and [`draw_lines`](Self::draw_lines).
    pub fn begin(&mut self, cam: &Camera) -> Result<()> {
        cam.validate()?;
        self.begin_view(&cam.view(self.opts.width, self.opts.height))
    }

    /// [`begin`](Self::begin) with a [`View`] (the stages' view type) made
    /// for this renderer's image size.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a view of another size or one
    /// [`View::check`] rejects.
    pub fn begin_view(&mut self, view: &View) -> Result<()> {
        if (view.width, view.height) != (self.opts.width, self.opts.height) {
            return Err(Error::InvalidArgument(format!(
                "Renderer::begin_view: a {}x{} view for {}x{} images",
                view.width, view.height, self.opts.width, self.opts.height
            )));
        }
        view.check("render")?;
        self.ctx.make_current()?;
        let gl = &self.gl;
        let target = self.ms.as_ref().unwrap_or(&self.resolve);
        let [r, g, b, a] = self.opts.background;
        // SAFETY: the context is current (above).
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(target.fbo));
            gl.depth_mask(true);
            gl.clear_color(r, g, b, a);
            gl.clear_depth_f32(1.0);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
        check(gl, "clearing the frame")?;
        self.frame = Some(FrameState { view: *view });
        Ok(())
    }

    /// The frame in progress, with the context made current.
    pub(super) fn frame(&self, what: &str) -> Result<&FrameState> {
        let f = self.frame.as_ref().ok_or_else(|| {
            Error::InvalidArgument(format!("Renderer::{what} called outside begin()..finish()"))
        })?;
        self.ctx.make_current()?;
        Ok(f)
    }
}

/// The uniform locations of the mesh program `prog`.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn mesh_uniforms(gl: &glow::Context, prog: glow::NativeProgram) -> MeshUniforms {
    // SAFETY: the caller's contract.
    let u = |name: &str| unsafe { gl.get_uniform_location(prog, name) };
    MeshUniforms {
        view_proj: u("u_view_proj"),
        eye: u("u_eye"),
        view_dir: u("u_view_dir"),
        ortho: u("u_ortho"),
        headlight: u("u_headlight"),
        light_dir: u("u_light_dir"),
        ambient: u("u_ambient"),
        vertex_color: u("u_vertex_color"),
        color: u("u_color"),
    }
}

/// A new buffer.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn new_buffer(gl: &glow::Context) -> Result<glow::NativeBuffer> {
    // SAFETY: the caller's contract.
    unsafe {
        gl.create_buffer()
            .map_err(|e| Error::render("glGenBuffers", e))
    }
}

/// A new vertex array.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn new_vertex_array(gl: &glow::Context) -> Result<glow::NativeVertexArray> {
    // SAFETY: the caller's contract.
    unsafe {
        gl.create_vertex_array()
            .map_err(|e| Error::render("glGenVertexArrays", e))
    }
}

/// The mesh vertex array and its buffers: positions, normals and colours
/// (attributes 0 to 2, 0 and 1 enabled), then the element buffer; left bound.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn mesh_arrays(
    gl: &glow::Context,
) -> Result<(glow::NativeVertexArray, [glow::NativeBuffer; 4])> {
    // SAFETY: the caller's contract.
    unsafe {
        let vao = new_vertex_array(gl)?;
        let bufs = [
            new_buffer(gl)?,
            new_buffer(gl)?,
            new_buffer(gl)?,
            new_buffer(gl)?,
        ];
        gl.bind_vertex_array(Some(vao));
        for (loc, b) in bufs[..3].iter().enumerate() {
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(*b));
            gl.vertex_attrib_pointer_f32(loc as u32, 3, glow::FLOAT, false, 0, 0);
        }
        gl.enable_vertex_attrib_array(0);
        gl.enable_vertex_attrib_array(1);
        gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(bufs[3]));
        Ok((vao, bufs))
    }
}

/// The clip-space vertex array and its buffers: `vec4` positions
/// (attribute 0), then the element buffer; left bound.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn clip_arrays(
    gl: &glow::Context,
) -> Result<(glow::NativeVertexArray, [glow::NativeBuffer; 2])> {
    // SAFETY: the caller's contract.
    unsafe {
        let vao = new_vertex_array(gl)?;
        let bufs = [new_buffer(gl)?, new_buffer(gl)?];
        gl.bind_vertex_array(Some(vao));
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(bufs[0]));
        gl.vertex_attrib_pointer_f32(0, 4, glow::FLOAT, false, 0, 0);
        gl.enable_vertex_attrib_array(0);
        gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(bufs[1]));
        Ok((vao, bufs))
    }
}

/// Sets the state every frame shares: depth test, no culling, polygon
/// offset, blending and tight pixel packing.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn fixed_state(gl: &glow::Context) {
    // SAFETY: the caller's contract.
    unsafe {
        gl.enable(glow::DEPTH_TEST);
        gl.disable(glow::CULL_FACE); // edge quads have either winding
        gl.polygon_offset(1.0, 1.0);
        gl.blend_func_separate(
            glow::SRC_ALPHA,
            glow::ONE_MINUS_SRC_ALPHA,
            glow::ONE,
            glow::ONE_MINUS_SRC_ALPHA,
        );
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
    }
}
