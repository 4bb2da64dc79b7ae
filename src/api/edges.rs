//! The edges picture front door: a one-view scene of the mesh, shaded, with
//! its feature edges and caps in black (House & Li's edge stage, drawn from
//! its edge-out and cap-out buffers), which the scene executor runs; the
//! route of the buffers to GL is the executor's decision from the mode
//! given ([`EdgePictureOptions::interop`]).

use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;

use crate::error::Result;
use crate::export::svg::SvgLayer;
use crate::gpu::{DeviceInfo, Gpu};
use crate::mesh::Mesh;
use crate::render::{Camera, Frame, MeshStyle, RenderOptions, Uploads};
use crate::scene::exec::{EdgeCounts, ExecOptions, PassRecord, Session};
use crate::scene::file::{HeldMesh, Scene, Shot, Source};
use crate::scene::planner::Cue;
use crate::spec::edges::{
    CapMode, EdgeOutput, InteropDecision, KIND_BOUNDARY, KIND_CONTOUR, KIND_CREASE, KIND_DRAWN,
    MemoryUse, crease_from_degrees, memory_use,
};
use crate::spec::interop::{InteropMode, InteropOffer};
use crate::spec::timing::Timing;
use crate::spec::visibility::VisibilityMethod;

/// What [`feature_edges_picture`] draws and how (the `shapecue edges`
/// options).
#[derive(Clone, Debug, PartialEq)]
pub struct EdgePictureOptions {
    /// The camera and the image size (default: the eye at (5, 5, 5),
    /// looking at the centre of the bounding box, 800 × 600).
    pub shot: Shot,
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
    /// Draw the picture (GL). Off, with `svg` on and exact visibility, no
    /// GL context is opened.
    pub image: bool,
    /// Also find the SVG group of the visible edges.
    pub svg: bool,
    /// How the SVG's hidden edges are found: exactly, over the mesh's BVH
    /// (default), or against the picture's depth (which draws it).
    pub visibility: VisibilityMethod,
    /// How the stage's buffers reach GL: `auto` shares memory (Vulkan
    /// external memory) where the device, GL and Vulkan offer it, else
    /// reads back and uploads; `on` refuses to run without sharing; `off`
    /// always reads back.
    pub interop: InteropMode,
}

impl Default for EdgePictureOptions {
    fn default() -> Self {
        EdgePictureOptions {
            shot: Shot {
                eye: Some(Vec3::splat(5.0)),
                ..Shot::default()
            },
            msaa: RenderOptions::default().msaa,
            caps: CapMode::Adjacency,
            line_width: 4.0,
            crease_deg: 30.0,
            depth_scale: None,
            half_contours: false,
            marked: None,
            image: true,
            svg: false,
            visibility: VisibilityMethod::Exact,
            interop: InteropMode::Off,
        }
    }
}

/// What [`feature_edges_picture`] made.
#[derive(Clone, Debug)]
pub struct EdgePicture {
    /// The picture: the shaded mesh with its edges and caps in black, where
    /// one was drawn (with depth when the SVG's hidden edges came from it).
    pub frame: Option<Frame>,
    /// The stage's outputs as drawn: `kind` per edge, and only the edge
    /// quads and caps that hold geometry, compacted in index order (on the
    /// external-memory route they stay on the device: `kind` only, and the
    /// edge quads when an SVG was asked for).
    pub output: EdgeOutput,
    /// The edge buffer's counts.
    pub counts: EdgeCounts,
    /// The cap variant drawn.
    pub caps: CapMode,
    /// The camera used (world coordinates).
    pub camera: Camera,
    /// Mesh vertices.
    pub vertices: usize,
    /// Mesh faces.
    pub faces: usize,
    /// Kernel time of the edge stage, the wall time of the whole frame
    /// (topology, stage, GL context, drawing and read-backs), and every pass
    /// that ran as a phase named after it (on the pass's own clock: kernel
    /// time for `edges` and `caps`, wall time for the others).
    pub timing: Timing,
    /// The passes that ran, in plan order.
    pub passes: Vec<PassRecord>,
    /// Device memory of the variant.
    pub memory: MemoryUse,
    /// The SVG groups (the visible edges), when asked for.
    pub layers: Option<Vec<SvgLayer>>,
    /// The drawn edges split where their visibility changes and joined into
    /// chains (world coordinates), with exact visibility.
    pub visible: Option<crate::scene::exec::VisibleLines>,
    /// The device that ran the stage.
    pub device: DeviceInfo,
    /// Mesh data uploads to GL (one topology and one pose).
    pub uploads: Uploads,
    /// Adjacency caps drawn.
    pub drawn_caps: usize,
    /// The route the buffers took to GL, and why.
    pub interop: InteropDecision,
    /// What the device, GL and Vulkan offered.
    pub offer: InteropOffer,
}

impl EdgePicture {
    /// Edges whose kind has `bit` set (`KIND_*`).
    pub fn count(&self, bit: u32) -> usize {
        self.output.count(bit)
    }

    /// Drawn edges of each kind: (drawn, contour, crease, boundary or marked).
    pub fn kinds(&self) -> [usize; 4] {
        [KIND_DRAWN, KIND_CONTOUR, KIND_CREASE, KIND_BOUNDARY].map(|b| self.count(b))
    }
}

/// The edges picture of `mesh` in one call on the default device: the
/// scene of [`edges_scene`] (the mesh shaded, its contour, crease, boundary
/// and marked edges with the caps of `opts.caps` in black) run by the scene
/// executor. `name` names the mesh in errors (the marked file names itself).
///
/// ```
/// use shapecue::mesh::Generated;
/// use shapecue::spec::edges::KIND_CONTOUR;
/// let (_, mesh) = Generated::Torus.mesh(2000);
/// let mut opts = shapecue::EdgePictureOptions::default();
/// opts.shot.eye = None;
/// let pic = shapecue::feature_edges_picture(&mesh, "torus", &opts)?;
/// let frame = pic.frame.as_ref().expect("the picture is drawn (`image` is on)");
/// assert_eq!((frame.width, frame.height), (800, 600));
/// assert!(pic.count(KIND_CONTOUR) > 0);
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// No device, bad marked edges, parameters the stage rejects (width,
/// crease, depth scale, camera), `interop` on where sharing is not offered,
/// device and GL failures.
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
    let scene = edges_scene(Arc::new(mesh.clone()), name, opts)?;
    let t0 = std::time::Instant::now();
    let f = Session::on(gpu.clone()).picture(&scene, &ExecOptions::default())?;
    let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    let v = f.out;
    let camera = v.world_camera();
    let info = v.edge_info.expect("feature edges are planned");
    let mut timing = v.timing;
    timing.wall_ms = wall_ms;
    for p in &f.passes {
        timing.phase(p.pass.name(), p.ms());
    }
    let counts = info.counts;
    Ok(EdgePicture {
        memory: memory_use(opts.caps, counts.edges, counts.cap_pairs),
        frame: v.image,
        output: v.edges.unwrap_or_default(),
        counts,
        caps: opts.caps,
        camera,
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        timing,
        passes: f.passes,
        layers: v.layers,
        visible: v.visible,
        device: gpu.info.clone(),
        uploads: v.uploads,
        drawn_caps: info.drawn_caps,
        interop: info.decision,
        offer: info.offer,
    })
}

/// The one-view scene of an edges picture: `mesh` (named `name` in errors)
/// shaded with the renderer's default style, its feature edges in black.
///
/// # Errors
/// A crease angle out of range.
pub fn edges_scene(mesh: Arc<Mesh>, name: &str, opts: &EdgePictureOptions) -> Result<Scene> {
    let mut s = Scene::held(Source::Held(HeldMesh(mesh)), &opts.shot);
    s.path = PathBuf::from(name);
    let [r, g, b, _] = RenderOptions::default().background;
    s.background = [r, g, b];
    s.msaa = opts.msaa;
    s.png = opts.image;
    s.svg = opts.svg;
    s.visibility = opts.visibility;
    s.interop = opts.interop;
    let fx = &mut s.effects;
    fx.cues = vec![Cue::Shading, Cue::FeatureEdges];
    let style = MeshStyle::default();
    (fx.ambient, fx.base_color) = (style.ambient, style.color);
    fx.edge = (opts.line_width, [0.0; 3]);
    fx.crease = crease_from_degrees(opts.crease_deg)?;
    fx.caps = opts.caps;
    fx.edge_contours = true;
    fx.edge_boundaries = true;
    fx.edge_depth_scale = opts.depth_scale;
    fx.edge_half_contours = opts.half_contours;
    fx.edge_marked = opts.marked.clone();
    Ok(s)
}
