//! Headless OpenGL renderer: shaded meshes, and the projection-space quads and
//! triangles that the edge stage writes (House & Li's edge-out and cap-out
//! buffers), read back as an RGBA8 + depth [`Frame`] or saved as PNG.
//!
//! GL, not a CPU rasteriser: the edge-out buffers are drawn as they are (the
//! vertex shader applies no transform), with coverage, depth test and MSAA;
//! without a GPU, Mesa's llvmpipe does it through EGL (`context.rs`).
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
//! Clip space is OpenGL's (z in [−w, w], [`Camera::view_proj`]); drawing goes
//! to the renderer's own framebuffers (multisampled when `msaa > 0`).
//!
//! Threads: a `Renderer` is not `Send` (its GL context is current on the
//! thread that made it); make one per thread. Any number may exist at once or
//! one after another; each public call makes its own context current first.
//!
//! Files: `context.rs` (EGL), `programs.rs` (GLSL sources, compiling, GL
//! errors), `targets.rs` (framebuffers and the driver's limits), `state.rs`
//! (making, reconfiguring, starting a frame), `draw_mesh.rs` (uploads and
//! shaded meshes), `draw_clip.rs` (clip-space quads, triangles and lines),
//! `readback.rs` (resolve and read-back into a [`Frame`]); `edges.rs` and
//! `strokes.rs` draw those cues; `camera.rs`, `lines.rs`, `colormap.rs` and
//! `depth_visibility.rs` (which parts of a line the depth buffer shows) are plain
//! arithmetic on the CPU.

mod camera;
pub mod colormap;
mod context;
pub mod depth_visibility;
mod draw_clip;
mod draw_mesh;
pub mod edges;
pub mod external;
mod frame;
mod lines;
mod programs;
mod readback;
mod state;
pub mod strokes;
mod targets;

pub use camera::{Camera, Placement, fit_sphere, framed};
pub use frame::Frame;
pub use lines::{clip_segment, segments_to_clip_quads};

use glam::Vec3;

use crate::spec::view::View;
use context::GlContext;
use programs::MeshUniforms;
use targets::Target;

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
