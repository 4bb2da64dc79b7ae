//! The front door: one call per task, re-exported at the crate root
//! (`shapecue::curvature`, `shapecue::isosurface`, `shapecue::feature_edges`
//! and `shapecue::feature_edges_picture`, `shapecue::strokes`,
//! `shapecue::render_scene`), beside the stateful per-topology types that a
//! deforming mesh reuses frame after frame
//! ([`crate::stages::curvature::CurvatureEstimator`],
//! [`crate::stages::marching_cubes::Isosurfacer`],
//! [`crate::stages::edges::EdgeStage`],
//! [`crate::stages::pipeline::PosePipeline`]).
//!
//! Each call runs on the default device (`Gpu::new(None)`: `SHAPECUE_DEVICE`
//! if set, else the first GPU, else the first CPU device); its `_on` form
//! takes a device the caller already holds, so programs are built once.
//! The CPU twins have the same signatures where a twin exists:
//! [`crate::cpu::curvature::curvature`], [`crate::cpu::edges::feature_edges`].
//! The `shapecue` command line calls these and only these, then writes and
//! prints what they return; `shapecue report` ([`crate::report`]) times
//! them from above.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::edges::EdgeTopology;
use crate::spec::curvature::{Curvature, CurvatureOptions};
use crate::spec::edges::{CapMode, EdgeOptions, EdgeOutput};
use crate::spec::marching_cubes::{Inside, IsoNormals};
use crate::spec::vertex_fusion::Fusion;
use crate::spec::view::View;
use crate::stages::edges::EdgeStage;
use crate::stages::marching_cubes::{self as mcs, IsoStats, Isosurfacer};
use crate::volume::Volume;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

mod curvature;
mod edges;
pub mod interop;
mod lines;
mod strokes;

pub use curvature::{CurvatureJob, CurvatureRun, MeshSource, curvature_of};

pub use edges::{
    EdgePicture, EdgePictureOptions, edges_scene, feature_edges_picture, feature_edges_picture_on,
};

pub use crate::scene::file::Shot;

// The stateful types, the device and the scene runner the command line and
// Python use beside the one-call tasks: the front door names them, so that
// nothing above it reaches into the layers below.
pub use crate::cpu::curvature::curvature as curvature_reference;
pub use crate::gpu::{DeviceInfo, Gpu, list_devices};
pub use crate::render::{Camera, Placement, framed};
pub use crate::scene::exec::{
    Checked, ExecOptions, LAYER_FEATURE_EDGES, LAYER_INTERSECTIONS, LAYER_STROKES, RunReport,
    Session, VisibleLines, check_scenes, explain, output_paths, run as run_scene,
    run_on as run_scene_on,
};
pub use crate::scene::file::{
    CameraDefaults, CameraKind, HeldMesh, HeldVolume, Scene, Source, ViewSpec, check_fov,
    fibonacci_views, load_camera_file, parse_camera_file,
};
pub use crate::spec::cameras::{MAX_VIEWS, fibonacci_directions};
pub use crate::spec::feature_lines::ViewFields;
pub use crate::spec::visibility::VisibilityMethod;
pub use crate::stages::curvature::{
    CurvatureEstimator, KernelBuild, OrderedEstimator, build_kernels,
};
pub use crate::stages::feature_lines::LineOptions;
pub use lines::{
    Hidden, LineFiles, LineSegments, LineSetup, LineView, LinesPicture, LinesPictureOptions,
    family_style, hidden_id, line_segments_on, lines_on, lines_picture, lines_picture_on,
    lines_scene, lines_views_scene, segment_arrays, wanted, with_consumer,
};

pub use strokes::{
    FIT_DIRECTION, MeshField, Picture, PictureOptions, Strokes, StrokesInput, StrokesOptions,
    strokes, strokes_on,
};

fn default_gpu() -> Result<Arc<Gpu>> {
    Ok(Arc::new(Gpu::new(None)?))
}

/// Curvature of a triangle mesh on the default device: normals, point areas,
/// principal curvatures and directions and (with `opts.dcurv`) the
/// derivative tensor, with skip counts and timing (Griffin et al. 2012,
/// after Rusinkiewicz 2004). For many poses of one topology, build a
/// [`crate::stages::curvature::CurvatureEstimator`] once instead.
///
/// ```
/// use shapecue::{mesh::Generated, spec::curvature::CurvatureOptions};
/// let (_, mesh) = Generated::Torus.mesh(2000);
/// let c = shapecue::curvature(&mesh, CurvatureOptions::default())?;
/// assert_eq!(c.field.len(), mesh.n_vertices());
/// assert!(c.field.all_finite());
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// No device, a device without what the variant needs (f64, 64-bit
/// atomics), OpenCL failures.
pub fn curvature(mesh: &Mesh, opts: CurvatureOptions) -> Result<Curvature> {
    curvature_on(&default_gpu()?, mesh, opts)
}

/// [`curvature`] on a given device.
pub fn curvature_on(gpu: &Arc<Gpu>, mesh: &Mesh, opts: CurvatureOptions) -> Result<Curvature> {
    crate::stages::curvature::estimate(gpu.clone(), mesh, opts)
}

/// How [`isosurface`] extracts and what it computes on the result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoOptions {
    /// Vertex fusion variant.
    pub fusion: Fusion,
    /// Which side of the iso value is the object (default: below, as for a
    /// signed distance field; density volumes want [`Inside::Above`]).
    pub inside: Inside,
    /// Curvature of the fused mesh, computed on the device right after
    /// extraction (atomic accumulation, exact solve; `accumulate` and
    /// `compat` are ignored).
    pub curvature: Option<CurvatureOptions>,
    /// Vertex normals of the curvature passes.
    pub curvature_normals: IsoNormals,
    /// Also compute per-vertex normals from the volume gradient
    /// ([`Isosurface::normals`]).
    pub gradient_normals: bool,
}

impl Default for IsoOptions {
    fn default() -> Self {
        IsoOptions {
            fusion: Fusion::Direct,
            inside: Inside::Below,
            curvature: None,
            curvature_normals: IsoNormals::Gradient,
            gradient_normals: false,
        }
    }
}

/// What [`isosurface`] made.
#[derive(Clone, Debug)]
pub struct Isosurface {
    /// The fused mesh in world coordinates (spacing and origin applied).
    pub mesh: Mesh,
    /// Unit normals from the volume gradient, when asked for.
    pub normals: Option<Vec<[f64; 3]>>,
    /// The curvature of the mesh, when asked for.
    pub curvature: Option<Curvature>,
    /// Counts and timing of the extraction; its timing has the phase
    /// `upload` (uploading the volume and building the programs).
    pub stats: IsoStats,
}

/// The isosurface of `volume` at `iso` on the default device: marching
/// cubes with vertex fusion on the device (Griffin et al. 2012, §3.4), and
/// optionally its curvature with no host round trip. For many iso values of
/// one volume, build an [`Isosurfacer`] once instead.
///
/// ```
/// use shapecue::volume::sdf::{Sdf, sdf};
/// use shapecue::spec::curvature::CurvatureOptions;
/// let vol = sdf(Sdf::Sphere, 32);
/// let opts = shapecue::IsoOptions {
///     curvature: Some(CurvatureOptions::default()),
///     ..Default::default()
/// };
/// let s = shapecue::isosurface(&vol, 0.0, &opts)?;
/// assert!(s.mesh.n_faces() > 0);
/// let k = &s.curvature.expect("asked for").field;
/// assert!(k.mean().iter().sum::<f64>() > 0.0); // a sphere is convex
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// No device, a volume too large for it, OpenCL failures.
pub fn isosurface(volume: &Volume, iso: f32, opts: &IsoOptions) -> Result<Isosurface> {
    isosurface_on(&default_gpu()?, volume, iso, opts)
}

/// [`isosurface`] on a given device.
pub fn isosurface_on(
    gpu: &Arc<Gpu>,
    volume: &Volume,
    iso: f32,
    opts: &IsoOptions,
) -> Result<Isosurface> {
    let (vol, iso) = volume.oriented(iso, opts.inside);
    let t_up = Instant::now();
    let mut ex = Isosurfacer::new(gpu.clone(), &vol)?;
    let upload_ms = t_up.elapsed().as_secs_f64() * 1e3;
    let mut stats = ex.extract(iso, opts.fusion)?;
    stats.timing.phase("upload", upload_ms);
    let curvature = match opts.curvature {
        Some(o) => {
            let (est, timing) = mcs::curvature(&ex, o, opts.curvature_normals)?;
            let field = est.read()?;
            if !field.all_finite() {
                return Err(Error::InvalidArgument(
                    "internal error: non-finite curvature (please report with the input)".into(),
                ));
            }
            Some(Curvature {
                field,
                counts: est.counts()?,
                timing: {
                    let mut t = timing;
                    t.phase("topology", est.topology_ms());
                    t
                },
                device_bytes: est.device_bytes(),
            })
        }
        None => None,
    };
    let (ipos, faces) = ex.read_index_space()?;
    let normals = opts
        .gradient_normals
        .then(|| crate::volume::gradient::gradient_normals(&vol, &ipos));
    Ok(Isosurface {
        mesh: ex.world_mesh(&ipos, faces),
        normals,
        curvature,
        stats,
    })
}

/// Object-space feature edges of `mesh` seen through `view` on the default
/// device (House & Li, after McGuire & Hughes 2004): contour, crease,
/// boundary and marked edges as clip-space quads with the caps of
/// `opts.caps`; nothing is drawn ([`feature_edges_picture`] draws them). For
/// many frames of one topology, build an [`EdgeStage`] once instead.
///
/// ```
/// use shapecue::mesh::Generated;
/// use shapecue::render::{Placement, framed};
/// use shapecue::spec::edges::{EdgeOptions, KIND_CONTOUR};
/// let (_, mesh) = Generated::Torus.mesh(2000);
/// let eye = Placement::At(glam::Vec3::splat(5.0));
/// let view = framed(eye, None, None, 40.0, false, mesh.bounds(), 4.0 / 3.0)?.view(400, 300);
/// let out = shapecue::feature_edges(&mesh, &view, &EdgeOptions::default())?;
/// assert!(out.count(KIND_CONTOUR) > 0);
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// Bad parameters (width, crease, depth scale, view), a marked edge out of
/// range, device failures.
pub fn feature_edges(mesh: &Mesh, view: &View, opts: &EdgeOptions) -> Result<EdgeOutput> {
    feature_edges_on(&default_gpu()?, mesh, view, opts)
}

/// [`feature_edges`] on a given device.
pub fn feature_edges_on(
    gpu: &Arc<Gpu>,
    mesh: &Mesh,
    view: &View,
    opts: &EdgeOptions,
) -> Result<EdgeOutput> {
    let params = opts.params(*view)?;
    params.pack()?;
    let topo = if opts.caps == CapMode::Adjacency {
        EdgeTopology::new(mesh, &opts.marked, "mesh")?
    } else {
        EdgeTopology::without_caps(mesh, &opts.marked, "mesh")?
    };
    let mut stage = EdgeStage::new(gpu.clone(), mesh, &topo)?;
    stage.run(&params, opts.caps)?;
    stage.read()
}

/// Renders the scene file at `path` on the device `opts.device` names (the
/// default device when `None`): checks the scene, plans the passes its cues
/// need, runs exactly those and writes the images and the report (see
/// [`crate::scene::exec::run`]).
///
/// ```
/// let opts = shapecue::scene::exec::ExecOptions {
///     out_dir: Some(std::env::temp_dir().join("shapecue-doc-render-scene")),
///     force: true,
///     ..Default::default()
/// };
/// let report = shapecue::render_scene("scenes/torus.toml".as_ref(), &opts)?;
/// println!("{} passes ran", report.passes.len());
/// # std::fs::remove_dir_all(opts.out_dir.unwrap()).ok();
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// The scene file's errors (file, line, column), existing outputs without
/// `force`, device and GL failures.
pub fn render_scene(path: &Path, opts: &ExecOptions) -> Result<RunReport> {
    let scene = crate::scene::file::Scene::load(path)?;
    crate::scene::exec::run(&scene, opts, &mut |_, _| {})
}

/// [`render_scene`] on a given device (`opts.device` is ignored).
pub fn render_scene_on(gpu: &Arc<Gpu>, path: &Path, opts: &ExecOptions) -> Result<RunReport> {
    let scene = crate::scene::file::Scene::load(path)?;
    crate::scene::exec::run_on(gpu, &scene, opts, &mut |_, _| {})
}
