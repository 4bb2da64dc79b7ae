//! Headless OpenGL renderer: shaded meshes, and the projection-space quads and
//! triangles that the edge stage writes (House & Li's edge-out and cap-out
//! buffers), read back as an RGBA8 + depth [`Frame`] or saved as PNG.
//!
//! Why GL and not a CPU rasteriser: the edge-out buffers are meant to be drawn
//! by the GPU as they are (the vertex shader applies no transform), with
//! coverage, depth test and MSAA from the rasteriser; on a machine without a
//! GPU, Mesa's llvmpipe does the same through EGL's surfaceless platform (see
//! `context.rs`). Nothing here needs a window or a display server.
//!
//! A frame is `begin(&camera)` → any number of `draw_*` → `finish()`:
//! - [`Renderer::draw_mesh`]: Lambert shading × per-vertex colour, two-sided,
//!   pushed back by a polygon offset (factor 1, units 1) so that lines and
//!   edge quads drawn at the same depth win the depth test.
//! - [`Renderer::draw_clip_quads`] / [`Renderer::draw_clip_triangles`]: vertices
//!   already in clip space, flat colour, depth-tested (≤) against the mesh.
//! - [`Renderer::draw_lines`]: world-space segments as screen-aligned quads.
//!
//! A mesh drawn in many views is uploaded once: [`Renderer::upload_topology`]
//! (faces, once per topology) and [`Renderer::upload_pose`] (positions,
//! normals, colours, once per pose), outside any frame, then
//! [`Renderer::draw_uploaded`] in each frame; [`Renderer::uploads`] counts
//! the uploads. [`Renderer::reconfigure`] changes the image size and
//! antialiasing while keeping the context, its programs and the mesh.
//!
//! Clip space is OpenGL's (z in [−w, w]), as produced by
//! [`Camera::view_proj`]. All drawing goes to the renderer's own framebuffer
//! objects (multisampled when `msaa > 0`, resolved in `finish`).
//!
//! Threads: a `Renderer` is not `Send` (its GL context is current on the
//! thread that made it); make one per thread. Any number may exist at once or
//! one after another; each public call makes its own context current first.

mod camera;
pub mod colormap;
mod context;
pub mod edges;
mod frame;
mod lines;
pub mod strokes;

pub use camera::{Camera, Placement, fit_sphere, framed};
pub use frame::Frame;
pub use lines::{clip_segment, segments_to_clip_quads};

use glam::Vec3;
use glow::HasContext;

use crate::error::{Error, Result};
use crate::spec::view::View;
use context::GlContext;

/// Size, antialiasing and background of the images a [`Renderer`] produces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Width in pixels (> 0).
    pub width: u32,
    /// Height in pixels (> 0).
    pub height: u32,
    /// Samples per pixel: 0 (no multisampling), 2, 4 or 8; at most the
    /// driver's `GL_MAX_SAMPLES` (llvmpipe: 4 in Mesa 22).
    pub msaa: u32,
    /// Clear colour, RGBA in [0, 1].
    pub background: [f32; 4],
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 512,
            height: 512,
            msaa: 4,
            background: [1.0, 1.0, 1.0, 1.0],
        }
    }
}

/// Where the light of [`Renderer::draw_mesh`] comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// From the eye: a surface facing the camera is brightest.
    Headlight,
    /// A directional light; the vector points from the surface towards the light (world space).
    Directional(Vec3),
}

/// How [`Renderer::draw_mesh`] shades a mesh: colour × (ambient + (1 − ambient) · max(n·l, 0)),
/// with normals flipped towards the eye (two-sided lighting).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshStyle {
    /// The light.
    pub light: Light,
    /// Ambient term in [0, 1].
    pub ambient: f32,
    /// Colour used when no per-vertex colours are given.
    pub color: [f32; 3],
}

impl Default for MeshStyle {
    fn default() -> Self {
        MeshStyle {
            light: Light::Headlight,
            ambient: 0.15,
            color: [0.8, 0.8, 0.8],
        }
    }
}

const MESH_VS: &str = r"#version 330 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_color;
uniform mat4 u_view_proj;
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_color;
void main() {
    v_pos = a_pos;
    v_normal = a_normal;
    v_color = a_color;
    gl_Position = u_view_proj * vec4(a_pos, 1.0);
}
";

const MESH_FS: &str = r"#version 330 core
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_color;
uniform vec3 u_eye;
uniform vec3 u_view_dir;    // eye towards target, unit
uniform int u_ortho;
uniform int u_headlight;
uniform vec3 u_light_dir;   // towards the light, unit
uniform float u_ambient;
uniform int u_vertex_color;
uniform vec3 u_color;
out vec4 o_color;
void main() {
    vec3 to_eye = u_ortho != 0 ? -u_view_dir : normalize(u_eye - v_pos);
    float len = length(v_normal);
    // A zero (or NaN) normal is shaded as if facing the eye rather than black.
    vec3 n = len > 0.0 ? v_normal / len : to_eye;
    // Two-sided: meshes with inconsistent orientation still shade correctly.
    if (dot(n, to_eye) < 0.0) n = -n;
    vec3 l = u_headlight != 0 ? to_eye : u_light_dir;
    float lambert = max(dot(n, l), 0.0);
    vec3 base = u_vertex_color != 0 ? v_color : u_color;
    o_color = vec4(base * (u_ambient + (1.0 - u_ambient) * lambert), 1.0);
}
";

const CLIP_VS: &str = r"#version 330 core
layout(location = 0) in vec4 a_clip;
void main() { gl_Position = a_clip; }   // already projected: no transform (House & Li)
";

const CLIP_FS: &str = r"#version 330 core
uniform vec4 u_color;
out vec4 o_color;
void main() { o_color = u_color; }
";

/// A framebuffer object with a colour and a depth renderbuffer.
struct Target {
    fbo: glow::NativeFramebuffer,
    renderbuffers: [glow::NativeRenderbuffer; 2],
}

impl Target {
    /// Frees the framebuffer and its renderbuffers.
    ///
    /// # Safety
    /// The context of `gl` (the one that made the target) must be current.
    unsafe fn delete(self, gl: &glow::Context) {
        unsafe {
            gl.delete_framebuffer(self.fbo);
            for rb in self.renderbuffers {
                gl.delete_renderbuffer(rb);
            }
        }
    }
}

/// What the mesh buffers of a [`Renderer`] hold (see
/// [`Renderer::upload_topology`] and [`Renderer::upload_pose`]).
#[derive(Clone, Copy, Debug, Default)]
struct HeldMesh {
    /// Faces in the index buffer, and the largest index they use.
    faces: Option<(usize, Option<u32>)>,
    /// Vertices in the position and normal buffers, and whether the colour
    /// buffer holds one colour per vertex.
    pose: Option<(usize, bool)>,
}

/// How often a [`Renderer`] has uploaded mesh data to GL since it was made:
/// a caller that draws many views of one mesh uploads its faces once per
/// topology and its positions once per pose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Uploads {
    /// Index-buffer uploads ([`Renderer::upload_topology`]).
    pub topology: u64,
    /// Position, normal and colour uploads ([`Renderer::upload_pose`]).
    pub pose: u64,
}

/// Uniform locations of the mesh program.
struct MeshUniforms {
    view_proj: Option<glow::NativeUniformLocation>,
    eye: Option<glow::NativeUniformLocation>,
    view_dir: Option<glow::NativeUniformLocation>,
    ortho: Option<glow::NativeUniformLocation>,
    headlight: Option<glow::NativeUniformLocation>,
    light_dir: Option<glow::NativeUniformLocation>,
    ambient: Option<glow::NativeUniformLocation>,
    vertex_color: Option<glow::NativeUniformLocation>,
    color: Option<glow::NativeUniformLocation>,
}

/// The camera state of the frame being drawn.
struct FrameState {
    view: View,
}

/// A headless OpenGL renderer with its own EGL context and framebuffers.
/// See the [module documentation](self) for the frame protocol.
pub struct Renderer {
    gl: glow::Context,
    opts: RenderOptions,
    mesh_prog: glow::NativeProgram,
    mesh_u: MeshUniforms,
    clip_prog: glow::NativeProgram,
    clip_color: Option<glow::NativeUniformLocation>,
    mesh_vao: glow::NativeVertexArray,
    /// Positions, normals, colours, indices.
    mesh_bufs: [glow::NativeBuffer; 4],
    clip_vao: glow::NativeVertexArray,
    /// Vertices, and the quad index pattern (0 1 2 0 2 3 per quad).
    clip_bufs: [glow::NativeBuffer; 2],
    /// Quads the pattern in `clip_bufs[1]` covers.
    quad_pattern: usize,
    /// Multisampled target, when `msaa > 0`.
    ms: Option<Target>,
    /// Single-sampled target that `finish` reads (the draw target when `msaa == 0`).
    resolve: Target,
    frame: Option<FrameState>,
    /// `GL_RENDERER`, and the driver's `GL_MAX_SAMPLES` and
    /// `GL_MAX_RENDERBUFFER_SIZE` (the limits of [`Renderer::reconfigure`]).
    driver: String,
    max_samples: i32,
    max_size: i32,
    /// `GL_RENDERER`, `GL_VERSION` and the EGL platform; the MSAA part of
    /// [`Renderer::gl_info`] is added from the current targets.
    info: String,
    /// Samples per pixel the driver gave the multisampled target.
    samples: i32,
    held: HeldMesh,
    uploads: Uploads,
    // Dropped last: destroying the context frees every GL object above, so
    // Renderer needs no Drop of its own (and a failed `new` leaks nothing).
    ctx: GlContext,
}

fn gl_error_name(e: u32) -> String {
    match e {
        glow::INVALID_ENUM => "GL_INVALID_ENUM".into(),
        glow::INVALID_VALUE => "GL_INVALID_VALUE".into(),
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION".into(),
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION".into(),
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY".into(),
        other => format!("GL error 0x{other:04X}"),
    }
}

/// Returns the first pending GL error (and clears the rest) as an [`Error::Render`].
fn check(gl: &glow::Context, what: &str) -> Result<()> {
    // SAFETY: glGetError only needs a current context, which every caller has made.
    let first = unsafe { gl.get_error() };
    if first == glow::NO_ERROR {
        return Ok(());
    }
    for _ in 0..16 {
        // SAFETY: as above.
        if unsafe { gl.get_error() } == glow::NO_ERROR {
            break;
        }
    }
    Err(Error::render(what, gl_error_name(first)))
}

/// Compiles and links a vertex + fragment program; the error carries the info log.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn program(
    gl: &glow::Context,
    name: &str,
    vs: &str,
    fs: &str,
) -> Result<glow::NativeProgram> {
    unsafe {
        let prog = gl
            .create_program()
            .map_err(|e| Error::render(format!("glCreateProgram ({name})"), e))?;
        let mut shaders = Vec::new();
        for (kind, src, label) in [
            (glow::VERTEX_SHADER, vs, "vertex"),
            (glow::FRAGMENT_SHADER, fs, "fragment"),
        ] {
            let sh = gl
                .create_shader(kind)
                .map_err(|e| Error::render(format!("glCreateShader ({name} {label})"), e))?;
            gl.shader_source(sh, src);
            gl.compile_shader(sh);
            if !gl.get_shader_compile_status(sh) {
                return Err(Error::render(
                    format!("compiling the {name} {label} shader"),
                    gl.get_shader_info_log(sh),
                ));
            }
            gl.attach_shader(prog, sh);
            shaders.push(sh);
        }
        gl.link_program(prog);
        if !gl.get_program_link_status(prog) {
            return Err(Error::render(
                format!("linking the {name} program"),
                gl.get_program_info_log(prog),
            ));
        }
        for sh in shaders {
            gl.detach_shader(prog, sh);
            gl.delete_shader(sh);
        }
        Ok(prog)
    }
}

/// Creates a framebuffer with RGBA8 colour and 32-bit float depth
/// renderbuffers (`samples == 0`: single-sampled) and checks completeness.
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn target(gl: &glow::Context, w: i32, h: i32, samples: i32) -> Result<Target> {
    unsafe {
        let fbo = gl
            .create_framebuffer()
            .map_err(|e| Error::render("glGenFramebuffers", e))?;
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        let mut renderbuffers = Vec::with_capacity(2);
        for (format, attachment) in [
            (glow::RGBA8, glow::COLOR_ATTACHMENT0),
            (glow::DEPTH_COMPONENT32F, glow::DEPTH_ATTACHMENT),
        ] {
            let rb = gl
                .create_renderbuffer()
                .map_err(|e| Error::render("glGenRenderbuffers", e))?;
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            if samples > 0 {
                gl.renderbuffer_storage_multisample(glow::RENDERBUFFER, samples, format, w, h);
            } else {
                gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
            }
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                attachment,
                glow::RENDERBUFFER,
                Some(rb),
            );
            renderbuffers.push(rb);
        }
        let renderbuffers = [renderbuffers[0], renderbuffers[1]];
        let made = Target { fbo, renderbuffers };
        if let Err(e) = check(
            gl,
            &format!("allocating a {w}x{h} framebuffer with {samples} samples"),
        ) {
            made.delete(gl);
            return Err(e);
        }
        let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
        if status != glow::FRAMEBUFFER_COMPLETE {
            made.delete(gl);
            return Err(Error::render(
                format!("framebuffer {w}x{h}, {samples} samples"),
                format!("incomplete (status 0x{status:04X})"),
            ));
        }
        Ok(made)
    }
}

/// Checks `opts` against the driver's sample and size limits.
fn check_limits(opts: &RenderOptions, driver: &str, max_samples: i32, max_size: i32) -> Result<()> {
    if opts.msaa as i32 > max_samples {
        return Err(Error::InvalidArgument(format!(
            "msaa {} exceeds the {max_samples} samples '{driver}' supports",
            opts.msaa
        )));
    }
    if opts.width as i64 > max_size as i64 || opts.height as i64 > max_size as i64 {
        return Err(Error::InvalidArgument(format!(
            "render size {}x{} exceeds the {max_size}x{max_size} '{driver}' supports",
            opts.width, opts.height
        )));
    }
    Ok(())
}

/// Checks what [`Renderer::new`] and [`Renderer::reconfigure`] can check
/// before touching GL.
fn check_options(opts: &RenderOptions) -> Result<()> {
    if opts.width == 0 || opts.height == 0 {
        return Err(Error::InvalidArgument(format!(
            "render size {}x{} must be at least 1x1",
            opts.width, opts.height
        )));
    }
    if ![0, 2, 4, 8].contains(&opts.msaa) {
        return Err(Error::InvalidArgument(format!(
            "msaa {} must be 0, 2, 4 or 8",
            opts.msaa
        )));
    }
    Ok(())
}

/// The multisampled (when `msaa > 0`) and resolve targets of `opts`, and the
/// samples the driver gave the first (drivers may round up: llvmpipe 2 → 4).
///
/// # Safety
/// The context of `gl` must be current.
unsafe fn targets(
    gl: &glow::Context,
    opts: &RenderOptions,
) -> Result<(Option<Target>, Target, i32)> {
    let (w, h) = (opts.width as i32, opts.height as i32);
    unsafe {
        let ms = if opts.msaa > 0 {
            Some(target(gl, w, h, opts.msaa as i32)?)
        } else {
            None
        };
        let resolve = match target(gl, w, h, 0) {
            Ok(t) => t,
            Err(e) => {
                if let Some(t) = ms {
                    t.delete(gl);
                }
                return Err(e);
            }
        };
        let samples = match &ms {
            Some(t) => {
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(t.fbo));
                gl.get_parameter_i32(glow::SAMPLES)
            }
            None => 0,
        };
        gl.viewport(0, 0, w, h);
        Ok((ms, resolve, samples))
    }
}

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
            let u = |name: &str| gl.get_uniform_location(mesh_prog, name);
            let mesh_u = MeshUniforms {
                view_proj: u("u_view_proj"),
                eye: u("u_eye"),
                view_dir: u("u_view_dir"),
                ortho: u("u_ortho"),
                headlight: u("u_headlight"),
                light_dir: u("u_light_dir"),
                ambient: u("u_ambient"),
                vertex_color: u("u_vertex_color"),
                color: u("u_color"),
            };
            let clip_prog = program(&gl, "clip", CLIP_VS, CLIP_FS)?;
            let clip_color = gl.get_uniform_location(clip_prog, "u_color");

            let buf = || {
                gl.create_buffer()
                    .map_err(|e| Error::render("glGenBuffers", e))
            };
            let vao = || {
                gl.create_vertex_array()
                    .map_err(|e| Error::render("glGenVertexArrays", e))
            };
            let mesh_vao = vao()?;
            let mesh_bufs = [buf()?, buf()?, buf()?, buf()?];
            gl.bind_vertex_array(Some(mesh_vao));
            for (loc, b) in mesh_bufs[..3].iter().enumerate() {
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(*b));
                gl.vertex_attrib_pointer_f32(loc as u32, 3, glow::FLOAT, false, 0, 0);
            }
            gl.enable_vertex_attrib_array(0);
            gl.enable_vertex_attrib_array(1);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(mesh_bufs[3]));
            let clip_vao = vao()?;
            let clip_bufs = [buf()?, buf()?];
            gl.bind_vertex_array(Some(clip_vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(clip_bufs[0]));
            gl.vertex_attrib_pointer_f32(0, 4, glow::FLOAT, false, 0, 0);
            gl.enable_vertex_attrib_array(0);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(clip_bufs[1]));
            gl.bind_vertex_array(None);

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
    fn frame(&self, what: &str) -> Result<&FrameState> {
        let f = self.frame.as_ref().ok_or_else(|| {
            Error::InvalidArgument(format!("Renderer::{what} called outside begin()..finish()"))
        })?;
        self.ctx.make_current()?;
        Ok(f)
    }

    /// Draws a triangle mesh with Lambert shading (see [`MeshStyle`]).
    /// `normals` has one entry per position; `colors` one per position, or is
    /// empty to use `style.color`. Faces may have either orientation (no
    /// culling, two-sided lighting). The mesh is drawn with a polygon offset so
    /// that edges and lines drawn on it afterwards stay visible.
    ///
    /// This uploads the faces and the pose on every call; a caller drawing
    /// one mesh in many views uploads them once ([`upload_topology`],
    /// [`upload_pose`]) and calls [`draw_uploaded`] per view.
    ///
    /// [`upload_topology`]: Self::upload_topology
    /// [`upload_pose`]: Self::upload_pose
    /// [`draw_uploaded`]: Self::draw_uploaded
    pub fn draw_mesh(
        &mut self,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        colors: &[[f32; 3]],
        faces: &[[u32; 3]],
        style: MeshStyle,
    ) -> Result<()> {
        self.frame("draw_mesh")?;
        self.upload_pose(positions, normals, colors)?;
        self.upload_topology(faces)?;
        self.draw_uploaded(style)
    }

    /// Uploads a mesh's faces (the index buffer), kept until the next call:
    /// once per topology. Needs no frame in progress. Indices are checked
    /// against the pose when drawing.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for more faces than one draw can take.
    pub fn upload_topology(&mut self, faces: &[[u32; 3]]) -> Result<()> {
        if i32::try_from(faces.len() * 3).is_err() {
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: {} faces are too many for one draw",
                faces.len()
            )));
        }
        let max_index = faces.iter().flatten().copied().max();
        self.ctx.make_current()?;
        self.held.faces = None;
        let gl = &self.gl;
        // SAFETY: the context is current (above); the index buffer is the
        // mesh VAO's element buffer, bound with the VAO.
        unsafe {
            gl.bind_vertex_array(Some(self.mesh_vao));
            gl.buffer_data_u8_slice(
                glow::ELEMENT_ARRAY_BUFFER,
                bytemuck::cast_slice(faces),
                glow::STATIC_DRAW,
            );
            gl.bind_vertex_array(None);
        }
        check(gl, &format!("uploading {} faces", faces.len()))?;
        self.held.faces = Some((faces.len(), max_index));
        self.uploads.topology += 1;
        Ok(())
    }

    /// Uploads a pose: positions, one normal per position, and one colour
    /// per position or none (the style's flat colour); kept until the next
    /// call: once per pose. Needs no frame in progress.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for mismatched lengths or a non-finite
    /// position (named by its index).
    pub fn upload_pose(
        &mut self,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        colors: &[[f32; 3]],
    ) -> Result<()> {
        let n = positions.len();
        if normals.len() != n || !(colors.is_empty() || colors.len() == n) {
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: {n} positions need {n} normals (got {}) and {n} or 0 colours (got {})",
                normals.len(),
                colors.len()
            )));
        }
        if let Some(i) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            let [x, y, z] = positions[i];
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: vertex {i} has a non-finite position ({x}, {y}, {z})"
            )));
        }
        self.ctx.make_current()?;
        self.held.pose = None;
        let gl = &self.gl;
        let data: [&[u8]; 3] = [
            bytemuck::cast_slice(positions),
            bytemuck::cast_slice(normals),
            bytemuck::cast_slice(colors),
        ];
        // SAFETY: the context is current (above); the buffers are the mesh
        // VAO's attribute buffers.
        unsafe {
            for (b, d) in self.mesh_bufs[..3].iter().zip(data) {
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(*b));
                gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, d, glow::DYNAMIC_DRAW);
            }
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
        }
        check(gl, &format!("uploading a pose of {n} vertices"))?;
        self.held.pose = Some((n, !colors.is_empty()));
        self.uploads.pose += 1;
        Ok(())
    }

    /// Draws the mesh last uploaded ([`upload_topology`](Self::upload_topology),
    /// [`upload_pose`](Self::upload_pose)) into the frame in progress, shaded
    /// as [`draw_mesh`](Self::draw_mesh) describes.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] outside a frame, with nothing uploaded, or
    /// when a face indexes past the uploaded vertices.
    pub fn draw_uploaded(&mut self, style: MeshStyle) -> Result<()> {
        let f = self.frame("draw_mesh")?;
        let (Some((faces, max_index)), Some((n, colored))) = (self.held.faces, self.held.pose)
        else {
            return Err(Error::InvalidArgument(
                "draw_mesh: no mesh uploaded (faces and a pose)".into(),
            ));
        };
        if let Some(m) = max_index.filter(|&m| m as usize >= n) {
            return Err(Error::InvalidArgument(format!(
                "draw_mesh: a face uses vertex {m}, past the {n} vertices"
            )));
        }
        let (light_dir, headlight) = match style.light {
            Light::Headlight => (Vec3::Z, true),
            Light::Directional(d) => (d.try_normalize().unwrap_or(Vec3::Z), false),
        };
        let cam = &f.view;
        let view_dir = cam.unit_dir();
        let gl = &self.gl;
        let u = &self.mesh_u;
        // SAFETY: the context is current (`frame`); the buffers hold `n`
        // vertices and every index is < n (checked above).
        unsafe {
            gl.use_program(Some(self.mesh_prog));
            gl.uniform_matrix_4_f32_slice(
                u.view_proj.as_ref(),
                false,
                &cam.view_proj.to_cols_array(),
            );
            gl.uniform_3_f32(u.eye.as_ref(), cam.eye.x, cam.eye.y, cam.eye.z);
            gl.uniform_3_f32(u.view_dir.as_ref(), view_dir.x, view_dir.y, view_dir.z);
            gl.uniform_1_i32(u.ortho.as_ref(), cam.ortho as i32);
            gl.uniform_1_i32(u.headlight.as_ref(), headlight as i32);
            gl.uniform_3_f32(u.light_dir.as_ref(), light_dir.x, light_dir.y, light_dir.z);
            gl.uniform_1_f32(u.ambient.as_ref(), style.ambient.clamp(0.0, 1.0));
            gl.uniform_1_i32(u.vertex_color.as_ref(), colored as i32);
            let [r, g, b] = style.color;
            gl.uniform_3_f32(u.color.as_ref(), r, g, b);

            gl.bind_vertex_array(Some(self.mesh_vao));
            if colored {
                gl.enable_vertex_attrib_array(2);
            } else {
                gl.disable_vertex_attrib_array(2);
            }
            gl.enable(glow::POLYGON_OFFSET_FILL);
            gl.disable(glow::BLEND);
            gl.depth_func(glow::LESS);
            gl.draw_elements(glow::TRIANGLES, (faces * 3) as i32, glow::UNSIGNED_INT, 0);
            gl.disable(glow::POLYGON_OFFSET_FILL);
            gl.bind_vertex_array(None);
        }
        check(gl, &format!("draw_mesh ({n} vertices, {faces} faces)"))
    }

    /// Draws clip-space quads, 4 vertices each, in House & Li's edge-out order:
    /// `0 = s0 − p, 1 = s1 − p, 2 = s1 + p, 3 = s0 + p` (s0, s1 the edge ends,
    /// p the screen-space perpendicular), i.e. **around the quad's perimeter**,
    /// not in triangle-strip order. Each quad is drawn as the triangles 0-1-2
    /// and 0-2-3, so any convex quad in perimeter order works, and so does the
    /// adjacency cap layout (middle vector, p0, sM, p1). Winding does not matter.
    ///
    /// A quad whose first vertex has a NaN x (House & Li's non-drawable marker
    /// `(NaN, 0, −1, 1)`), or that has any non-finite coordinate, is skipped on
    /// the CPU, so nothing of it reaches the rasteriser. McGuire & Hughes' marker
    /// `(0, 0, −1, 1)` on all four vertices is a zero-area quad and draws nothing.
    ///
    /// Flat `color` (alpha-blended when its alpha is < 1), depth-tested with ≤
    /// and written to depth.
    pub fn draw_clip_quads(&mut self, verts: &[[f32; 4]], color: [f32; 4]) -> Result<()> {
        self.draw_clip(verts, 4, color, "draw_clip_quads")
    }

    /// Draws clip-space triangles, 3 vertices each (McGuire & Hughes half-caps:
    /// `s`, `s + p·sign(m·p)`, `s + m`); skipping, colour and depth as in
    /// [`draw_clip_quads`](Self::draw_clip_quads), with the NaN test on each
    /// triangle's first vertex. Adjacency caps (4 per cap) go to `draw_clip_quads`.
    pub fn draw_clip_triangles(&mut self, verts: &[[f32; 4]], color: [f32; 4]) -> Result<()> {
        self.draw_clip(verts, 3, color, "draw_clip_triangles")
    }

    /// Draws world-space segments (consecutive point pairs) as screen-aligned
    /// quads `width_px` pixels wide with square ends, through
    /// [`segments_to_clip_quads`] and [`draw_clip_quads`](Self::draw_clip_quads).
    pub fn draw_lines(
        &mut self,
        segments: &[[f32; 3]],
        color: [f32; 4],
        width_px: f32,
    ) -> Result<()> {
        let ok = segments.len().is_multiple_of(2) && width_px.is_finite() && width_px > 0.0;
        if !ok {
            return Err(Error::InvalidArgument(format!(
                "draw_lines: needs an even number of points (got {}) and a positive width (got {width_px})",
                segments.len()
            )));
        }
        let view_proj = self.frame("draw_lines")?.view.view_proj;
        let quads = segments_to_clip_quads(
            view_proj,
            [self.opts.width, self.opts.height],
            segments,
            width_px,
        );
        self.draw_clip(&quads, 4, color, "draw_lines")
    }

    fn draw_clip(
        &mut self,
        verts: &[[f32; 4]],
        per: usize,
        color: [f32; 4],
        what: &str,
    ) -> Result<()> {
        if !verts.len().is_multiple_of(per) {
            return Err(Error::InvalidArgument(format!(
                "{what}: {} vertices is not a multiple of {per}",
                verts.len()
            )));
        }
        self.frame(what)?;
        // Compact the drawable primitives so that the marker vertices never
        // reach the GPU: what llvmpipe (or any driver) does with NaN positions
        // is undefined. Buffers that hold only drawable primitives (the edge
        // stage's compacted read-back) go to GL as they are.
        let drawable = |prim: &[[f32; 4]]| {
            !prim[0][0].is_nan() && prim.iter().flatten().all(|c| c.is_finite())
        };
        let compacted: Vec<[f32; 4]>;
        let kept: &[[f32; 4]] = if verts.chunks_exact(per).all(drawable) {
            verts
        } else {
            compacted = verts
                .chunks_exact(per)
                .filter(|p| drawable(p))
                .flatten()
                .copied()
                .collect();
            &compacted
        };
        if kept.is_empty() {
            return Ok(());
        }
        let prims = kept.len() / per;
        // Quads are drawn as two triangles through the shared index pattern
        // 0 1 2 0 2 3 (grown when needed), triangles as they are.
        let index_count = if per == 4 { prims * 6 } else { prims * 3 };
        if u32::try_from(kept.len()).is_err() || i32::try_from(index_count).is_err() {
            return Err(Error::InvalidArgument(format!(
                "{what}: {prims} primitives are too many for one draw"
            )));
        }
        let gl = &self.gl;
        // SAFETY: the context is current (`frame`); every index of the
        // pattern's first `index_count` is < 4 * prims = kept.len().
        unsafe {
            gl.use_program(Some(self.clip_prog));
            let [r, g, b, a] = color;
            gl.uniform_4_f32(self.clip_color.as_ref(), r, g, b, a);
            gl.bind_vertex_array(Some(self.clip_vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.clip_bufs[0]));
            gl.buffer_data_u8_slice(
                glow::ARRAY_BUFFER,
                bytemuck::cast_slice(kept),
                glow::STREAM_DRAW,
            );
            if per == 4 && prims > self.quad_pattern {
                // Doubling keeps the uploads of a growing edge count rare.
                let quads = prims.max(2 * self.quad_pattern).min(u32::MAX as usize / 4);
                let pattern: Vec<u32> = (0..quads as u32)
                    .flat_map(|q| [0, 1, 2, 0, 2, 3].map(|k| 4 * q + k))
                    .collect();
                gl.buffer_data_u8_slice(
                    glow::ELEMENT_ARRAY_BUFFER,
                    bytemuck::cast_slice(&pattern),
                    glow::STATIC_DRAW,
                );
                self.quad_pattern = quads;
            }
            if a < 1.0 {
                gl.enable(glow::BLEND);
            } else {
                gl.disable(glow::BLEND);
            }
            gl.depth_func(glow::LEQUAL);
            if per == 4 {
                gl.draw_elements(glow::TRIANGLES, index_count as i32, glow::UNSIGNED_INT, 0);
            } else {
                gl.draw_arrays(glow::TRIANGLES, 0, index_count as i32);
            }
            gl.bind_vertex_array(None);
        }
        check(gl, &format!("{what} ({prims} primitives)"))
    }

    /// Ends the frame: resolves the multisampled image and reads back colour
    /// (RGBA8) and depth (window depth in [0, 1]), both flipped to top row first.
    pub fn finish(&mut self) -> Result<Frame> {
        self.finish_with(true)
    }

    /// [`finish`](Self::finish) without the depth: resolves and reads back
    /// the colour only, and the [`Frame`]'s `depth` is empty. For pictures
    /// that need no depth test afterwards (no SVG visibility): it saves the
    /// depth resolve, a 4-byte-per-pixel read-back and its flip.
    pub fn finish_color(&mut self) -> Result<Frame> {
        self.finish_with(false)
    }

    fn finish_with(&mut self, with_depth: bool) -> Result<Frame> {
        self.frame("finish")?;
        self.frame = None;
        let gl = &self.gl;
        let (w, h) = (self.opts.width as i32, self.opts.height as i32);
        let (wu, hu) = (self.opts.width as usize, self.opts.height as usize);
        let mut rgba = vec![0u8; wu * hu * 4];
        let mut depth = vec![0f32; if with_depth { wu * hu } else { 0 }];
        let blit = if with_depth {
            glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT
        } else {
            glow::COLOR_BUFFER_BIT
        };
        // SAFETY: the context is current (`frame`); the destination slices hold
        // exactly w*h RGBA8 pixels and w*h floats, with PACK_ALIGNMENT 1.
        unsafe {
            if let Some(ms) = &self.ms {
                gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(ms.fbo));
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(self.resolve.fbo));
                // Colour is averaged over samples; depth (NEAREST is required)
                // takes one sample.
                gl.blit_framebuffer(0, 0, w, h, 0, 0, w, h, blit, glow::NEAREST);
                check(gl, "resolving the multisampled frame")?;
            }
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.resolve.fbo));
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.read_pixels(
                0,
                0,
                w,
                h,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut rgba)),
            );
            if with_depth {
                gl.read_pixels(
                    0,
                    0,
                    w,
                    h,
                    glow::DEPTH_COMPONENT,
                    glow::FLOAT,
                    glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut depth))),
                );
            }
        }
        check(gl, "reading back the frame")?;
        flip_rows(&mut rgba, wu * 4);
        flip_rows(&mut depth, wu);
        Ok(Frame {
            width: self.opts.width,
            height: self.opts.height,
            rgba,
            depth,
        })
    }
}

/// GL rows run bottom-up; images top-down. In place (no second image).
fn flip_rows<T: Copy>(data: &mut [T], row: usize) {
    let n = data.len() / row.max(1);
    for i in 0..n / 2 {
        let (top, bottom) = data.split_at_mut((n - 1 - i) * row);
        top[i * row..(i + 1) * row].swap_with_slice(&mut bottom[..row]);
    }
}
