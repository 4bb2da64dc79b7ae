//! The edges picture front door: the edges stage ([`EdgeStage`], House &
//! Li) composed with the renderer, which draws the edge-out and cap-out
//! buffers the stage made ([`draw_edges`]) over the shaded mesh; the
//! visible polylines for SVG and the phases of the call, timed. The
//! renderer runs no compute: the stage runs here.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;

use crate::error::Result;
use crate::gpu::{DeviceInfo, Gpu};
use crate::mesh::Mesh;
use crate::mesh::edges::{EdgeTopology, read_marked};
use crate::mesh::topology::vertex_normals;
use crate::render::edges::draw_edges;
use crate::render::visibility::{DEFAULT_BIAS, visible_polylines};
use crate::render::{
    Camera, Frame, MeshStyle, Placement, RenderOptions, Renderer, Uploads, framed,
};
use crate::spec::edges::{
    CapMode, EdgeOutput, EdgeParams, InteropDecision, KIND_BOUNDARY, KIND_CONTOUR, KIND_CREASE,
    KIND_DRAWN, MemoryUse, crease_from_degrees, memory_use,
};
use crate::spec::interop::InteropRoute;
use crate::spec::timing::Timing;
use crate::stages::edges::{EdgeStage, SharedDrawn};

use super::interop::SharedEdges;

/// What [`feature_edges_picture`] draws and how (the `shapecue edges`
/// options).
#[derive(Clone, Debug, PartialEq)]
pub struct EdgePictureOptions {
    /// Eye position (world space); `None`: framed, from direction (1, 1, 1)
    /// off the centre of the mesh's bounding box, far enough that the
    /// bounding sphere fills the view with a 5 % margin ([`Placement::Fit`]).
    pub eye: Option<Vec3>,
    /// Point looked at; `None`: the centre of the mesh's bounding box.
    pub target: Option<Vec3>,
    /// Up direction; `None`: +Y, or +Z when looking along Y.
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    /// Orthographic projection (showing the height the perspective view shows at the target).
    pub ortho: bool,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel (0, 2, 4 or 8; see [`RenderOptions::msaa`]).
    pub msaa: u32,
    /// Cap variant.
    pub caps: CapMode,
    /// Edge width in pixels.
    pub line_width: f32,
    /// Crease angle in degrees; 180 or more finds none
    /// ([`crease_from_degrees`]).
    pub crease_deg: f32,
    /// Depth scale k of the width factor max(1, k/w).
    pub depth_scale: Option<f32>,
    /// Contour-only edges as half quads, outward from the silhouette.
    pub half_contours: bool,
    /// Marked edges: a text file of vertex-index pairs
    /// ([`crate::mesh::edges::read_marked`]).
    pub marked: Option<PathBuf>,
    /// Also find the visible edges as polylines (for SVG).
    pub polylines: bool,
    /// Timed frames after the first (0: none): each reruns the stage, its
    /// read-back and the GL frame with the topology, the device buffers, the
    /// renderer and the uploaded mesh kept, as a batch of views does
    /// ([`EdgePicture::runs`]).
    pub timed_runs: usize,
    /// How the stage's buffers reach GL: [`InteropRoute::ExternalMemory`]
    /// compacts what is drawn into memory GL draws from
    /// ([`super::interop::SharedEdges`]); any other route reads it back and
    /// uploads it (CL-GL sharing is not carried out by this build, see
    /// [`crate::spec::interop::GL_SHARING_BUILT`]).
    pub interop: InteropRoute,
}

impl Default for EdgePictureOptions {
    fn default() -> Self {
        EdgePictureOptions {
            eye: Some(Vec3::splat(5.0)),
            target: None,
            up: None,
            fov_deg: 40.0,
            ortho: false,
            width: 800,
            height: 600,
            msaa: RenderOptions::default().msaa,
            caps: CapMode::Adjacency,
            line_width: 4.0,
            crease_deg: 30.0,
            depth_scale: None,
            half_contours: false,
            marked: None,
            polylines: false,
            timed_runs: 0,
            interop: InteropRoute::Host,
        }
    }
}

/// Host wall time of each phase of [`feature_edges_picture`], ms: where a frame's time goes.
/// The CLI adds loading, PNG encoding and the SVG file; the rest is measured
/// here. `frame_ms` of [`EdgePicture`] is the sum of `stage_setup` through
/// `image_readback`.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct EdgePhases {
    /// The edge buffer (unique edges, their faces, marked edges).
    pub edge_buffer: f64,
    /// The adjacency cap pairs (0 without adjacency caps).
    pub cap_pairs: f64,
    /// Building the program, allocating and filling the device buffers
    /// (topology, markers, positions, vertex normals).
    pub stage_setup: f64,
    /// The stage's run: parameter upload, kernels, waiting for them.
    pub kernels: f64,
    /// Reading back edge-out, kinds and the caps of the variant; on the
    /// external-memory route, compacting them into the shared buffer and
    /// reading back the kinds only.
    pub readback: f64,
    /// Creating (or reusing) the renderer: GL context, programs,
    /// framebuffers, and on the external-memory route the shared buffer.
    pub gl_context: f64,
    /// Drawing the shaded mesh (uploads included).
    pub draw_mesh: f64,
    /// Drawing the edge and cap quads (compaction and uploads included).
    pub draw_edges: f64,
    /// Resolving and reading back the image (and depth when an SVG is asked for).
    pub image_readback: f64,
    /// The visible polylines for SVG (0 without).
    pub svg_visibility: f64,
}

/// Medians over the timed frames of [`EdgePictureOptions::timed_runs`], ms.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct EdgeRuns {
    /// Timed frames.
    pub runs: usize,
    /// Median of the whole frame: kernels, read-back, drawing, image read-back.
    pub frame_median_ms: f64,
    /// Median kernel time of the stage (OpenCL profiling events).
    pub kernel_median_ms: f64,
    /// Median of each phase a frame has (the topology, stage setup and GL
    /// context phases are 0: a frame reuses them).
    pub phases_median: EdgePhases,
}

/// What [`feature_edges_picture`] made.
#[derive(Clone, Debug)]
pub struct EdgePicture {
    /// The picture: the shaded mesh with its edges and caps in black (its
    /// depth only when [`EdgePictureOptions::polylines`] asked for it, else empty).
    pub frame: Frame,
    /// The stage's outputs as drawn: `kind` per edge, and only the edge
    /// quads and caps that hold geometry, compacted in index order
    /// ([`EdgeStage::read_drawn`]).
    pub output: EdgeOutput,
    /// The edge and cap buffers (and their counts).
    pub topology: EdgeTopology,
    /// The cap variant drawn.
    pub caps: CapMode,
    /// The camera used.
    pub camera: Camera,
    /// Mesh vertices and faces.
    pub vertices: usize,
    /// Mesh faces.
    pub faces: usize,
    /// Kernel and wall times of the stage's run.
    pub timing: Timing,
    /// Building the topology, ms.
    pub topology_ms: f64,
    /// Wall time of each phase of the call, ms ([`EdgePhases`]).
    pub phases: EdgePhases,
    /// The stage, its run and read-back, and the whole GL frame, ms.
    pub frame_ms: f64,
    /// Device memory of the variant.
    pub memory: MemoryUse,
    /// The visible parts of the drawn edges, joined into polylines (pixels),
    /// when [`EdgePictureOptions::polylines`] asked for them.
    pub polylines: Option<Vec<Vec<[f32; 2]>>>,
    /// The device that ran the stage.
    pub device: DeviceInfo,
    /// Medians of the timed frames after the first, when asked for.
    pub runs: Option<EdgeRuns>,
    /// Mesh data uploads to GL over all frames (one topology and one pose).
    pub uploads: Uploads,
    /// Adjacency caps drawn in the first frame (on the external-memory
    /// route they stay on the device, so `output.cap_adj` is empty).
    pub drawn_caps: usize,
    /// The route the buffers took to GL.
    pub interop: InteropRoute,
}

impl EdgePicture {
    /// Edges whose kind has `bit` set (`KIND_*`).
    pub fn count(&self, bit: u32) -> usize {
        self.output.count(bit)
    }

    /// The statistics document of `shapecue edges --stats`: counts, timings,
    /// memory, the interop path; `input` names the mesh.
    pub fn stats(&self, input: &str, interop: &InteropDecision) -> serde_json::Value {
        let t = &self.topology;
        serde_json::json!({
            "input": input,
            "device": self.device,
            "vertices": self.vertices,
            "faces": self.faces,
            "edges": t.edges.len(),
            "cap_pairs": t.caps.len(),
            "boundary": t.boundary,
            "non_manifold": t.non_manifold,
            "marked": t.marked,
            "drawn": self.count(KIND_DRAWN),
            "contour": self.count(KIND_CONTOUR),
            "crease": self.count(KIND_CREASE),
            "boundary_or_marked": self.count(KIND_BOUNDARY),
            "caps": self.caps,
            // Adjacency caps drawn (the device holds only these).
            "drawn_caps": self.drawn_caps,
            "interop": interop,
            "timing": self.timing,
            "topology_ms": self.topology_ms,
            "frame_ms": self.frame_ms,
            "phases_ms": self.phases,
            "memory_bits": self.memory,
            "svg_polylines": self.polylines.as_ref().map_or(0, Vec::len),
            "runs": self.runs.map(|r| r.runs),
            "frame_median_ms": self.runs.map(|r| r.frame_median_ms),
            "kernel_median_ms": self.runs.map(|r| r.kernel_median_ms),
            "phases_median_ms": self.runs.map(|r| r.phases_median),
            "gl_uploads": self.uploads,
        })
    }
}

/// The edges picture of `mesh` in one call on the default device: reads
/// the marked edges, builds the topology (with the cap buffer only for
/// adjacency caps), frames the camera ([`framed`]; the default target is the
/// bounding-box centre, computed in f64; without an eye the view fits the
/// mesh), runs the edges stage once, renders the shaded mesh and the edges
/// and caps in black ([`draw_edges`]), and finds the visible polylines when
/// asked. `name` names the mesh in errors (the marked file names itself).
/// The phases of the call are timed ([`EdgePhases`]).
///
/// ```
/// use shapecue::mesh::Generated;
/// use shapecue::spec::edges::KIND_CONTOUR;
/// let (_, mesh) = Generated::Torus.mesh(2000);
/// let opts = shapecue::EdgePictureOptions { eye: None, ..Default::default() };
/// let pic = shapecue::feature_edges_picture(&mesh, "torus", &opts)?;
/// assert_eq!((pic.frame.width, pic.frame.height), (800, 600));
/// assert!(pic.count(KIND_CONTOUR) > 0);
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// No device, bad marked edges, parameters the stage rejects (width,
/// crease, depth scale, camera), device and GL failures.
pub fn feature_edges_picture(
    mesh: &Mesh,
    name: &str,
    opts: &EdgePictureOptions,
) -> Result<EdgePicture> {
    feature_edges_picture_on(&super::default_gpu()?, mesh, name, opts)
}

/// [`feature_edges_picture`] on a given device.
pub fn feature_edges_picture_on(
    gpu: &Arc<Gpu>,
    mesh: &Mesh,
    name: &str,
    opts: &EdgePictureOptions,
) -> Result<EdgePicture> {
    let crease = crease_from_degrees(opts.crease_deg)?;
    let (w, h) = (opts.width, opts.height);
    let marked = match &opts.marked {
        Some(f) => read_marked(f)?,
        None => Vec::new(),
    };
    let source = opts
        .marked
        .as_ref()
        .map_or_else(|| name.to_string(), |m| m.display().to_string());
    let mut ph = EdgePhases::default();
    let mut clock = Instant::now();
    let mut lap = || {
        let now = Instant::now();
        let ms = (now - clock).as_secs_f64() * 1e3;
        clock = now;
        ms
    };
    let mut topo = EdgeTopology::without_caps(mesh, &marked, &source)?;
    ph.edge_buffer = lap();
    if opts.caps == CapMode::Adjacency {
        topo.add_caps(mesh.n_vertices(), &source)?;
    }
    ph.cap_pairs = lap();
    let topology_ms = ph.edge_buffer + ph.cap_pairs;
    let (lo, hi) = mesh.bounds();
    let centre = Vec3::new(
        (0.5 * (lo[0] + hi[0])) as f32,
        (0.5 * (lo[1] + hi[1])) as f32,
        (0.5 * (lo[2] + hi[2])) as f32,
    );
    let target = opts.target.unwrap_or(centre);
    let placement = match opts.eye {
        Some(eye) => Placement::At(eye),
        None => Placement::Fit(Vec3::ONE),
    };
    let cam = framed(
        placement,
        Some(target),
        opts.up,
        opts.fov_deg,
        opts.ortho,
        (lo, hi),
        w as f32 / h as f32,
    )?;
    let mut p = EdgeParams::new(cam.view(w, h));
    p.line_width = opts.line_width;
    p.crease_deg = crease;
    p.depth_scale = opts.depth_scale;
    p.half_contours = opts.half_contours;
    p.pack()?;

    lap();
    // One f32 copy of the positions and one set of normals, for the stage
    // and the renderer both.
    let pos: Vec<[f32; 3]> = mesh.positions.iter().map(|q| q.map(|c| c as f32)).collect();
    let nrm = vertex_normals(mesh);
    let mut stage = EdgeStage::with_pose(gpu.clone(), &topo, &pos, &nrm)?;
    ph.stage_setup = lap();
    let timing = stage.run(&p, opts.caps)?;
    ph.kernels = lap();
    let mut r = Renderer::new(RenderOptions {
        width: w,
        height: h,
        msaa: opts.msaa,
        ..Default::default()
    })?;
    // The shared buffer, once per topology: GL's context must exist first.
    let mut shared = match opts.interop {
        InteropRoute::ExternalMemory => Some(SharedEdges::new(gpu, &mut r, &stage, opts.caps)?),
        _ => None,
    };
    let gl_ms = lap();
    // What the frame draws: read back (host) or compacted in place (shared).
    let fetch = |stage: &mut EdgeStage,
                 shared: &mut Option<SharedEdges>|
     -> Result<(EdgeOutput, Option<SharedDrawn>)> {
        match shared {
            Some(sh) => {
                let d = sh.compact(gpu, stage)?;
                let mut out = EdgeOutput {
                    kind: d.kind.clone(),
                    ..EdgeOutput::default()
                };
                if opts.polylines {
                    out.edge_out = sh.read_edges(gpu, &d)?;
                }
                Ok((out, Some(d)))
            }
            None => Ok((stage.read_drawn()?, None)),
        }
    };
    let (output, drawn) = fetch(&mut stage, &mut shared)?;
    ph.readback = lap();
    ph.gl_context = gl_ms;
    r.upload_topology(&mesh.faces)?;
    r.upload_pose(&pos, &nrm, &[])?;
    let black = [0.0, 0.0, 0.0, 1.0];
    let mut frame_run = |ph: &mut EdgePhases,
                         lap: &mut dyn FnMut() -> f64,
                         output: &EdgeOutput,
                         drawn: Option<&SharedDrawn>,
                         shared: &Option<SharedEdges>| {
        r.begin(&cam)?;
        r.draw_uploaded(MeshStyle::default())?;
        ph.draw_mesh = lap();
        match (shared, drawn) {
            (Some(sh), Some(d)) => sh.draw(&mut r, d, black)?,
            _ => draw_edges(&mut r, output, black)?,
        }
        ph.draw_edges = lap();
        // Depth only for the SVG's visibility test.
        let frame = if opts.polylines {
            r.finish()?
        } else {
            r.finish_color()?
        };
        ph.image_readback = lap();
        Ok::<_, crate::error::Error>(frame)
    };
    let frame = frame_run(&mut ph, &mut lap, &output, drawn.as_ref(), &shared)?;
    let frame_ms = frame_sum(&ph);
    let polylines = opts
        .polylines
        .then(|| visible_polylines(&output.edge_out, &frame, DEFAULT_BIAS));
    ph.svg_visibility = lap();

    let runs = if opts.timed_runs > 0 {
        let mut each: Vec<(EdgePhases, f64)> = Vec::with_capacity(opts.timed_runs);
        for _ in 0..opts.timed_runs {
            let mut q = EdgePhases::default();
            lap();
            let t = stage.run(&p, opts.caps)?;
            q.kernels = lap();
            let (out, d) = fetch(&mut stage, &mut shared)?;
            q.readback = lap();
            let f = frame_run(&mut q, &mut lap, &out, d.as_ref(), &shared)?;
            if opts.polylines {
                std::hint::black_box(visible_polylines(&out.edge_out, &f, DEFAULT_BIAS));
                q.svg_visibility = lap();
            }
            each.push((q, t.kernel_ms));
        }
        Some(runs_summary(&each))
    } else {
        None
    };
    if let Some(sh) = shared.take() {
        sh.free(&mut r);
    }
    let uploads = r.uploads();
    let drawn_caps = drawn
        .as_ref()
        .map_or(output.cap_adj.len() / 4, |d| d.adjacency_caps);
    Ok(EdgePicture {
        memory: memory_use(opts.caps, topo.edges.len(), topo.caps.len()),
        frame,
        output,
        topology: topo,
        caps: opts.caps,
        camera: cam,
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        timing,
        topology_ms,
        phases: ph,
        frame_ms,
        polylines,
        device: gpu.info.clone(),
        runs,
        uploads,
        drawn_caps,
        interop: opts.interop,
    })
}

/// The whole frame of `ph`: everything after the topology but the SVG.
fn frame_sum(ph: &EdgePhases) -> f64 {
    ph.stage_setup
        + ph.kernels
        + ph.readback
        + ph.gl_context
        + ph.draw_mesh
        + ph.draw_edges
        + ph.image_readback
}

/// Medians of timed frames (their phases and kernel times).
fn runs_summary(each: &[(EdgePhases, f64)]) -> EdgeRuns {
    use crate::spec::timing::median;
    let of = |f: &dyn Fn(&EdgePhases) -> f64| {
        median(&mut each.iter().map(|e| f(&e.0)).collect::<Vec<_>>())
    };
    EdgeRuns {
        runs: each.len(),
        frame_median_ms: of(&frame_sum),
        kernel_median_ms: median(&mut each.iter().map(|e| e.1).collect::<Vec<_>>()),
        phases_median: EdgePhases {
            kernels: of(&|p| p.kernels),
            readback: of(&|p| p.readback),
            draw_mesh: of(&|p| p.draw_mesh),
            draw_edges: of(&|p| p.draw_edges),
            image_readback: of(&|p| p.image_readback),
            svg_visibility: of(&|p| p.svg_visibility),
            ..EdgePhases::default()
        },
    }
}
