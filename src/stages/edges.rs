//! Host wiring of `kernels/edges.cl`: object-space feature edges with caps
//! (House & Li, "Real-Time Object-Space Edge Detection using OpenCL", seed
//! 002, after McGuire & Hughes 2004).
//!
//! Buffers (E edge entries, C cap pairs, V vertices), owned by [`EdgeStage`]:
//! `edges uint[4E]` and `caps uint[2C]` (topology, uploaded once, see
//! [`crate::mesh::edges`]); `pos`, `nrm float[3V]` (per pose,
//! [`EdgeStage::set_positions`]); `params float[32]` (per frame,
//! [`EdgeParams::pack`]); outputs `edge_out float4[4E]`, `kind uint[E]`,
//! `cap_mh0`, `cap_mh1 float4[3E]` and `cap_adj float4[4C]`. One work-item
//! handles one edge (`edges_detect`, `caps_mh`) or one cap pair
//! (`caps_adjacency`). Outputs are indexed by edge or cap, never appended, so
//! device and CPU ([`crate::cpu::edges`]) results compare element by element.
//! Outputs persist between runs: a primitive undrawn in this run and the last
//! one keeps its marker and is not rewritten (`kind` and `cap_drawn uchar[C]`
//! remember what the last run drew), which removes most of the output traffic.
//!
//! Conventions:
//! - **Contour**: the two face normals face opposite ways seen from the eye
//!   (per-edge eye vector `eye − p0` in perspective, the view direction in
//!   orthographic views). Faces must be consistently oriented.
//! - **Crease**: the angle between the two face normals is larger than the
//!   user angle θ (degrees, in (0, 180]): `na·nb < cos θ |na||nb|`. A flat
//!   region has 0°, a cube's edges 90°: θ = 30 finds the cube's 12 edges and
//!   none of its face diagonals. (The seed writes `na·nb < −cos θ'`, i.e.
//!   θ' = 180° − θ is the dihedral angle between the faces.)
//! - **Boundary and marked**: `i3 == i0`.
//! - **Half quads** (`half_contours`): contour-only edges extend from the edge
//!   outward by the full width; their quad-end midpoints lie on the stroke's
//!   centre line, so adjacency caps join them (McGuire-Hughes caps stay
//!   centred on the edge).
//! - **Width**: `line_width` pixels across, times max(1, k/w) with depth scale
//!   k (the seed's appendix; k = 0 or `None`: constant screen width).
//! - **Near plane**: an edge with an end at clip w ≤ near (perspective) is not
//!   drawn, so an eye inside the mesh gives no screen-spanning quads.
//! - **Degenerate output** is the seed's marker `(NaN, 0, −1, 1)` on every
//!   vertex of the quad, triangle or cap.

use crate::error::{Error, Result};
use crate::gpu::{Arg, Gpu, buf, event_ms, kernel_file, launch};
use crate::mesh::Mesh;
use crate::mesh::edges::{EdgeTopology, vertex_normals};
use crate::render::Camera;
use crate::spec::timing::{Step, Timing};
use opencl3::kernel::Kernel;
use opencl3::memory::Buffer;
use serde::Serialize;
use std::time::Instant;

/// Kind bit: contour edge.
pub const KIND_CONTOUR: u32 = 1;
/// Kind bit: crease edge.
pub const KIND_CREASE: u32 = 2;
/// Kind bit: boundary or marked edge.
pub const KIND_BOUNDARY: u32 = 4;
/// Kind bit: the edge was detected and written as a quad.
pub const KIND_DRAWN: u32 = 8;

/// Number of floats in the per-frame parameter block.
pub const PARAMS_LEN: usize = 32;

/// How the gaps between thick edges are filled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CapMode {
    /// No caps.
    None,
    /// McGuire-Hughes half-caps from the projected vertex normals.
    Mh,
    /// House & Li adjacency caps from the middle vector of connected edges.
    Adjacency,
}

impl CapMode {
    /// All variants, in the order of tables and benches.
    pub const ALL: [CapMode; 3] = [CapMode::None, CapMode::Mh, CapMode::Adjacency];

    /// The name used on the command line, in stats and bench groups.
    pub fn name(self) -> &'static str {
        match self {
            CapMode::None => "none",
            CapMode::Mh => "mh",
            CapMode::Adjacency => "adjacency",
        }
    }
}

impl std::str::FromStr for CapMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<CapMode> {
        match s {
            "none" => Ok(CapMode::None),
            "mh" => Ok(CapMode::Mh),
            "adjacency" => Ok(CapMode::Adjacency),
            _ => Err(Error::InvalidArgument(format!(
                "unknown cap mode {s:?}: expected none, mh or adjacency"
            ))),
        }
    }
}

/// What to detect and how to draw it, for one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeParams {
    /// The camera (world space).
    pub camera: Camera,
    /// Viewport width in pixels.
    pub width: u32,
    /// Viewport height in pixels.
    pub height: u32,
    /// Line width in pixels (> 0).
    pub line_width: f32,
    /// Crease angle θ in degrees, in (0, 180]; `None`: no crease edges.
    pub crease_deg: Option<f32>,
    /// Detect contour edges.
    pub contours: bool,
    /// Draw boundary and marked edges.
    pub boundaries: bool,
    /// Depth scale k of the width factor max(1, k/w); `None`: constant width.
    pub depth_scale: Option<f32>,
    /// Draw contour-only edges as half quads, from the edge outward by the
    /// full width (outward: the side of the projected vertex normal).
    pub half_contours: bool,
}

impl EdgeParams {
    /// Defaults for a camera and viewport: width 4, crease 30°, contours and boundaries on.
    pub fn new(camera: Camera, width: u32, height: u32) -> EdgeParams {
        EdgeParams {
            camera,
            width,
            height,
            line_width: 4.0,
            crease_deg: Some(30.0),
            contours: true,
            boundaries: true,
            depth_scale: None,
            half_contours: false,
        }
    }

    /// Checks the parameters and packs the kernel's `params` block: the
    /// view-projection matrix (column-major), eye, view direction, ortho flag,
    /// half viewport, half line width, cos θ, depth scale, near w, flags.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a bad camera (NaN, eye == target, ...),
    /// an empty viewport, a width that is not a positive finite number, a
    /// crease angle outside (0, 180] or a negative or non-finite depth scale.
    pub fn pack(&self) -> Result<[f32; PARAMS_LEN]> {
        self.camera.validate()?;
        if self.width == 0 || self.height == 0 {
            return Err(Error::InvalidArgument(format!(
                "edges: viewport {}x{} is empty",
                self.width, self.height
            )));
        }
        if !(self.line_width.is_finite() && self.line_width > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "edges: line width {} must be a positive number of pixels",
                self.line_width
            )));
        }
        let cos_crease = match self.crease_deg {
            None => -2.0, // never: na·nb ≥ −|na||nb|
            Some(d) if d > 0.0 && d <= 180.0 => d.to_radians().cos(),
            Some(d) => {
                return Err(Error::InvalidArgument(format!(
                    "edges: crease angle {d}° must be in (0, 180]"
                )));
            }
        };
        let k = match self.depth_scale {
            None => 0.0,
            Some(k) if k >= 0.0 && k.is_finite() => k,
            Some(k) => {
                return Err(Error::InvalidArgument(format!(
                    "edges: depth scale {k} must be a finite number ≥ 0"
                )));
            }
        };
        let cam = &self.camera;
        let aspect = self.width as f32 / self.height as f32;
        let m = cam.view_proj(aspect).to_cols_array();
        let view = (cam.target - cam.eye).normalize();
        let mut p = [0f32; PARAMS_LEN];
        p[..16].copy_from_slice(&m);
        p[16..19].copy_from_slice(&cam.eye.to_array());
        p[19..22].copy_from_slice(&view.to_array());
        p[22] = cam.ortho_height.is_some() as u32 as f32;
        p[23] = 0.5 * self.width as f32;
        p[24] = 0.5 * self.height as f32;
        p[25] = 0.5 * self.line_width;
        p[26] = cos_crease;
        p[27] = k;
        p[28] = if cam.ortho_height.is_some() {
            0.0
        } else {
            cam.near
        };
        p[29] = self.contours as u32 as f32;
        p[30] = self.boundaries as u32 as f32;
        p[31] = self.half_contours as u32 as f32;
        if p.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidArgument(
                "edges: the camera gives a non-finite view-projection matrix".into(),
            ));
        }
        Ok(p)
    }
}

/// What `--interop` asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InteropMode {
    /// Use CL-GL sharing when the device offers it, the host path otherwise.
    Auto,
    /// Require CL-GL sharing.
    On,
    /// Always copy through the host.
    Off,
}

/// The interop path chosen and why.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct InteropDecision {
    /// `true`: share GL buffers; `false`: read outputs back and upload to GL.
    pub shared: bool,
    /// Why, in words (for stats).
    pub reason: String,
}

/// Decides the interop path from the mode and the device's extension string
/// alone (`DeviceInfo::gl_sharing`): nothing is probed, because calling
/// `clCreateFromGLBuffer` on a device without `cl_khr_gl_sharing` (PoCL)
/// terminates the process.
///
/// This build has no shared-buffer path yet, so `auto` and `on` with the
/// extension also use the host path, and say so.
///
/// # Errors
/// [`Error::DeviceUnsupported`] for `on` when the device lacks `cl_khr_gl_sharing`.
pub fn decide_interop(
    mode: InteropMode,
    gl_sharing: bool,
    device: &str,
) -> Result<InteropDecision> {
    let host = |reason: String| {
        Ok(InteropDecision {
            shared: false,
            reason,
        })
    };
    match (mode, gl_sharing) {
        (InteropMode::Off, _) => host("host path: --interop off".into()),
        (InteropMode::On, false) => Err(Error::DeviceUnsupported {
            device: device.to_string(),
            what: "--interop on needs cl_khr_gl_sharing, which the device does not report".into(),
        }),
        (InteropMode::Auto, false) => host(format!(
            "host path: device '{device}' does not report cl_khr_gl_sharing"
        )),
        (_, true) => host(
            "host path: the device reports cl_khr_gl_sharing, but this build has no shared-buffer \
             path (the renderer's EGL surfaceless context is not shareable with OpenCL)"
                .into(),
        ),
    }
}

/// Kernel and wall times of one [`EdgeStage::run`]: steps `edges_detect`
/// and `caps_mh` or `caps_adjacency`.
pub type RunTiming = Timing; // compat re-export

/// The stage's outputs read back to the host.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EdgeOutput {
    /// 4 vertices per edge (House & Li's edge-out buffer).
    pub edge_out: Vec<[f32; 4]>,
    /// Kind bits per edge (`KIND_*`).
    pub kind: Vec<u32>,
    /// McGuire-Hughes half-caps at the i0 end (3 vertices per edge); empty unless `Mh`.
    pub cap_mh0: Vec<[f32; 4]>,
    /// McGuire-Hughes half-caps at the i1 end; empty unless `Mh`.
    pub cap_mh1: Vec<[f32; 4]>,
    /// Adjacency caps (4 vertices per cap pair); empty unless `Adjacency`.
    pub cap_adj: Vec<[f32; 4]>,
}

/// Bits of device memory the edges stage uses for one mesh, from the actual
/// buffer sizes (seed 002's memory table; inputs already on the GPU for
/// rendering, positions and normals, are not counted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct MemoryUse {
    /// Edge entries.
    pub edges: usize,
    /// Cap pairs.
    pub caps: usize,
    /// Edge buffer + edge-out + kind bits.
    pub edge_bits: u64,
    /// Cap-related bits of the variant (cap buffer + cap-out, and the
    /// adjacency variant's one byte of state per cap pair).
    pub cap_bits: u64,
}

/// Memory of the variant `mode` for `edges` edge entries and `caps` cap pairs.
pub fn memory_use(mode: CapMode, edges: usize, caps: usize) -> MemoryUse {
    let (e, c) = (edges as u64, caps as u64);
    // edges uint[4E], edge_out float[16E], kind uint[E]
    let edge_bits = 32 * (4 * e + 16 * e + e);
    let cap_bits = match mode {
        CapMode::None => 0,
        CapMode::Mh => 32 * (2 * 12 * e),
        CapMode::Adjacency => 32 * (2 * c + 16 * c) + 8 * c,
    };
    MemoryUse {
        edges,
        caps,
        edge_bits,
        cap_bits,
    }
}

/// Device buffers and kernels of the edges stage for one mesh topology.
pub struct EdgeStage<'g> {
    gpu: &'g Gpu,
    n_vertices: usize,
    n_edges: usize,
    n_caps: usize,
    k_detect: Kernel,
    k_mh: Kernel,
    k_adj: Kernel,
    params: Buffer<f32>,
    pos: Buffer<f32>,
    nrm: Buffer<f32>,
    edges: Buffer<u32>,
    caps: Buffer<u32>,
    edge_out: Buffer<f32>,
    kind: Buffer<u32>,
    cap_mh0: Buffer<f32>,
    cap_mh1: Buffer<f32>,
    cap_adj: Buffer<f32>,
    cap_drawn: Buffer<u8>,
    last_mode: CapMode,
}

impl<'g> EdgeStage<'g> {
    /// Builds the program, uploads the topology and the mesh's positions and
    /// vertex normals, and allocates every output buffer of every cap variant.
    pub fn new(gpu: &'g Gpu, mesh: &Mesh, topo: &EdgeTopology) -> Result<EdgeStage<'g>> {
        let file = kernel_file("edges").expect("kernels/edges.cl is registered");
        let prog = gpu.program(&file, "")?;
        let (nv, ne, nc) = (mesh.n_vertices(), topo.edges.len(), topo.caps.len());
        if ne >= (u32::MAX / 16) as usize || nc >= (u32::MAX / 16) as usize {
            return Err(Error::input(
                "mesh",
                "edges",
                format!("{ne} edges / {nc} cap pairs exceed the 32-bit output index range"),
            ));
        }
        let mut s = EdgeStage {
            gpu,
            n_vertices: nv,
            n_edges: ne,
            n_caps: nc,
            k_detect: gpu.kernel(&prog, "edges_detect")?,
            k_mh: gpu.kernel(&prog, "caps_mh")?,
            k_adj: gpu.kernel(&prog, "caps_adjacency")?,
            params: gpu.buffer(PARAMS_LEN)?,
            pos: gpu.buffer(3 * nv)?,
            nrm: gpu.buffer(3 * nv)?,
            edges: gpu.buffer(4 * ne)?,
            caps: gpu.buffer(2 * nc)?,
            edge_out: gpu.buffer(16 * ne)?,
            kind: gpu.buffer(ne)?,
            cap_mh0: gpu.buffer(12 * ne)?,
            cap_mh1: gpu.buffer(12 * ne)?,
            cap_adj: gpu.buffer(16 * nc)?,
            cap_drawn: gpu.buffer(nc)?,
            last_mode: CapMode::None,
        };
        // Outputs persist between runs (undrawn-then-undrawn primitives are not
        // rewritten): start from markers everywhere.
        let marker = [f32::NAN, 0.0, -1.0, 1.0];
        gpu.write(&mut s.edge_out, bytemuck::cast_slice(&vec![marker; 4 * ne]))?;
        gpu.write(&mut s.cap_mh0, bytemuck::cast_slice(&vec![marker; 3 * ne]))?;
        gpu.write(&mut s.cap_mh1, bytemuck::cast_slice(&vec![marker; 3 * ne]))?;
        gpu.write(&mut s.cap_adj, bytemuck::cast_slice(&vec![marker; 4 * nc]))?;
        gpu.write(&mut s.kind, &vec![0u32; ne])?;
        gpu.write(&mut s.cap_drawn, &vec![0u8; nc])?;
        gpu.write(&mut s.edges, bytemuck::cast_slice(&topo.edges))?;
        gpu.write(&mut s.caps, bytemuck::cast_slice(&topo.caps))?;
        let pos: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.map(|c| c as f32)).collect();
        s.set_positions(&pos, &vertex_normals(mesh))?;
        Ok(s)
    }

    /// Number of edge entries.
    pub fn n_edges(&self) -> usize {
        self.n_edges
    }

    /// Number of cap pairs.
    pub fn n_caps(&self) -> usize {
        self.n_caps
    }

    /// Uploads a new pose (world-space positions and unit vertex normals)
    /// into the existing buffers.
    pub fn set_positions(&mut self, pos: &[[f32; 3]], nrm: &[[f32; 3]]) -> Result<()> {
        if pos.len() != self.n_vertices || nrm.len() != self.n_vertices {
            return Err(Error::InvalidArgument(format!(
                "edges: {} positions and {} normals for a mesh of {} vertices",
                pos.len(),
                nrm.len(),
                self.n_vertices
            )));
        }
        if let Some(i) = pos.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::input(
                "positions",
                format!("vertex {i}"),
                "non-finite coordinate",
            ));
        }
        self.gpu.write(&mut self.pos, bytemuck::cast_slice(pos))?;
        self.gpu.write(&mut self.nrm, bytemuck::cast_slice(nrm))
    }

    /// Runs detection and the caps of `mode` for one frame and waits for it.
    pub fn run(&mut self, params: &EdgeParams, mode: CapMode) -> Result<Timing> {
        let packed = params.pack()?;
        let t0 = Instant::now();
        let g = self.gpu;
        g.write(&mut self.params, &packed)?;
        let ne = self.n_edges as u32;
        let ev_d = launch(
            g,
            &self.k_detect,
            self.n_edges,
            &[
                Arg::U32(ne),
                buf(&self.params),
                buf(&self.pos),
                buf(&self.nrm),
                buf(&self.edges),
                buf(&self.edge_out),
                buf(&self.kind),
            ],
        )?;
        let ev_c = match mode {
            CapMode::None => None,
            CapMode::Mh => launch(
                g,
                &self.k_mh,
                self.n_edges,
                &[
                    Arg::U32(ne),
                    buf(&self.params),
                    buf(&self.pos),
                    buf(&self.nrm),
                    buf(&self.edges),
                    buf(&self.kind),
                    buf(&self.cap_mh0),
                    buf(&self.cap_mh1),
                ],
            )?,
            CapMode::Adjacency => launch(
                g,
                &self.k_adj,
                self.n_caps,
                &[
                    Arg::U32(self.n_caps as u32),
                    buf(&self.params),
                    buf(&self.edges),
                    buf(&self.caps),
                    buf(&self.kind),
                    buf(&self.edge_out),
                    buf(&self.cap_adj),
                    buf(&self.cap_drawn),
                ],
            )?,
        };
        g.finish()?;
        self.last_mode = mode;
        let mut t = Timing::default();
        if let Some(e) = &ev_d {
            t.add(Step::EdgesDetect, event_ms(e));
        }
        if let Some(e) = &ev_c {
            let step = match mode {
                CapMode::Mh => Step::CapsMh,
                _ => Step::CapsAdjacency,
            };
            t.add(step, event_ms(e));
        }
        t.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(t)
    }

    /// Reads back the outputs of the last run (caps of the last run's mode only).
    pub fn read(&self) -> Result<EdgeOutput> {
        let g = self.gpu;
        let read4 = |b: &Buffer<f32>, n: usize| -> Result<Vec<[f32; 4]>> {
            let mut v = vec![[0f32; 4]; n];
            g.read(b, bytemuck::cast_slice_mut(&mut v))?;
            Ok(v)
        };
        let mut kind = vec![0u32; self.n_edges];
        g.read(&self.kind, &mut kind)?;
        let mut out = EdgeOutput {
            edge_out: read4(&self.edge_out, 4 * self.n_edges)?,
            kind,
            ..Default::default()
        };
        match self.last_mode {
            CapMode::None => {}
            CapMode::Mh => {
                out.cap_mh0 = read4(&self.cap_mh0, 3 * self.n_edges)?;
                out.cap_mh1 = read4(&self.cap_mh1, 3 * self.n_edges)?;
            }
            CapMode::Adjacency => out.cap_adj = read4(&self.cap_adj, 4 * self.n_caps)?,
        }
        Ok(out)
    }
}

/// A camera for the edges CLI and tables: perspective with vertical field of
/// view `fov_deg`, or orthographic showing the height the perspective view
/// would show at the target; near and far hug the bounding sphere of
/// `bounds` (near = 1/1000 of the radius when the eye is inside it).
pub fn camera_for(
    eye: glam::Vec3,
    target: glam::Vec3,
    up: Option<glam::Vec3>,
    fov_deg: f32,
    ortho: bool,
    bounds: ([f64; 3], [f64; 3]),
) -> Result<Camera> {
    let (lo, hi) = bounds;
    let lo = glam::DVec3::from(lo).as_vec3();
    let hi = glam::DVec3::from(hi).as_vec3();
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let mut cam = Camera::look_at(eye, target);
    if let Some(u) = up {
        cam.up = u;
    }
    cam.fov_y_deg = fov_deg;
    let d = eye.distance(centre);
    cam.near = ((d - radius) * 0.9).max(1e-3 * radius);
    cam.far = (d + radius) * 1.1 + cam.near;
    if ortho {
        let dist = eye.distance(target);
        cam.ortho_height = Some(2.0 * dist * (0.5 * fov_deg.to_radians()).tan());
        // Orthographic: nothing is behind the eye, so near can sit at the sphere.
        cam.near = (d - radius).max(1e-3 * radius) * 0.9;
    }
    cam.validate()?;
    Ok(cam)
}

/// Draws the edge quads of `out` and the caps it holds (those of the last
/// run's mode) with flat `color` into the frame in progress.
pub fn draw(r: &mut crate::render::Renderer, out: &EdgeOutput, color: [f32; 4]) -> Result<()> {
    r.draw_clip_quads(&out.edge_out, color)?;
    r.draw_clip_triangles(&out.cap_mh0, color)?;
    r.draw_clip_triangles(&out.cap_mh1, color)?;
    r.draw_clip_quads(&out.cap_adj, color)
}

/// How closely one cap variant's stroke matches the ideal round-joined stroke.
#[derive(Clone, Debug, Serialize)]
pub struct CapQuality {
    /// The cap variant.
    pub mode: CapMode,
    /// Pixels of the ideal stroke.
    pub ideal: usize,
    /// Pixels the renderer covered (edges and caps, no mesh, no MSAA).
    pub rendered: usize,
    /// Ideal covered, rendered not.
    pub gap: usize,
    /// Rendered, ideal not.
    pub extra: usize,
}

/// The ideal stroke of the drawn edges of `edge_out`: pixels whose centre is
/// within `half_width` pixels of a projected edge (the union of discs along
/// every edge), `width × height`, row 0 at the top.
pub fn ideal_coverage(
    edge_out: &[[f32; 4]],
    width: u32,
    height: u32,
    half_width: f32,
) -> Vec<bool> {
    let (w, h) = (width as usize, height as usize);
    let mut cov = vec![false; w * h];
    let px = |a: [f32; 4], b: [f32; 4]| {
        let (x, y, cw) = (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), a[3]);
        [
            (x / cw * 0.5 + 0.5) * w as f32,
            (0.5 - y / cw * 0.5) * h as f32,
        ]
    };
    for q in edge_out.chunks_exact(4) {
        if q[0][0].is_nan() || !q.iter().flatten().all(|c| c.is_finite()) {
            continue;
        }
        let (a, b) = (px(q[0], q[3]), px(q[1], q[2]));
        let r = half_width;
        let x0 = (a[0].min(b[0]) - r).floor().max(0.0) as usize;
        let x1 = ((a[0].max(b[0]) + r).ceil().max(0.0) as usize).min(w);
        let y0 = (a[1].min(b[1]) - r).floor().max(0.0) as usize;
        let y1 = ((a[1].max(b[1]) + r).ceil().max(0.0) as usize).min(h);
        let d = [b[0] - a[0], b[1] - a[1]];
        let dd = d[0] * d[0] + d[1] * d[1];
        for y in y0..y1 {
            for x in x0..x1 {
                let p = [x as f32 + 0.5 - a[0], y as f32 + 0.5 - a[1]];
                let t = if dd > 0.0 {
                    ((p[0] * d[0] + p[1] * d[1]) / dd).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (p[0] - t * d[0], p[1] - t * d[1]);
                if ex * ex + ey * ey <= r * r {
                    cov[y * w + x] = true;
                }
            }
        }
    }
    cov
}

/// Cap quality of every variant for one mesh and view: runs the stage,
/// renders only the edges and caps (black on white, no MSAA) and compares the
/// covered pixels with [`ideal_coverage`] (constant width: `depth_scale` is ignored).
pub fn cap_quality(
    gpu: &Gpu,
    mesh: &Mesh,
    topo: &EdgeTopology,
    params: &EdgeParams,
) -> Result<Vec<CapQuality>> {
    use crate::render::{RenderOptions, Renderer};
    let mut p = *params;
    p.depth_scale = None;
    let mut stage = EdgeStage::new(gpu, mesh, topo)?;
    let mut r = Renderer::new(RenderOptions {
        width: p.width,
        height: p.height,
        msaa: 0,
        background: [1.0; 4],
    })?;
    let mut rows = Vec::new();
    for mode in CapMode::ALL {
        stage.run(&p, mode)?;
        let out = stage.read()?;
        r.begin(&p.camera)?;
        draw(&mut r, &out, [0.0, 0.0, 0.0, 1.0])?;
        let frame = r.finish()?;
        let ideal = ideal_coverage(&out.edge_out, p.width, p.height, 0.5 * p.line_width);
        let mut q = CapQuality {
            mode,
            ideal: 0,
            rendered: 0,
            gap: 0,
            extra: 0,
        };
        for (i, &want) in ideal.iter().enumerate() {
            let got = frame.rgba[4 * i] < 128;
            q.ideal += want as usize;
            q.rendered += got as usize;
            q.gap += (want && !got) as usize;
            q.extra += (got && !want) as usize;
        }
        rows.push(q);
    }
    Ok(rows)
}
