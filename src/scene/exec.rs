//! The scene executor: runs exactly the passes of a [`Plan`] over a scene's
//! frames and views, renders, writes the images, and reports which passes
//! ran, how often and for how long.
//!
//! Lifetimes (see [`crate::scene::planner`]):
//! - *topology* passes run when a topology first appears (once for a static,
//!   skinned or flipbook input; every pose for an isosurface);
//! - *pose* passes run once per frame (once in all for a static mesh);
//! - *view* passes run once per frame and camera.
//!
//! Device residency: a skinned pose stays on the device from `skin_lbs`
//! through the curvature passes, AO and the feature-line kernels; only what
//! the renderer draws is read back (positions, normals, colours, segments).
//! Contours alone need only normals: they are then computed on the host,
//! without building the curvature estimator.
//!
//! Timing: device passes report OpenCL kernel time; host passes (loading a
//! flipbook frame, host normals, building topology, rendering) report wall
//! time. The report says which, per pass.

use crate::cpu::feature_lines::{LineInputs, Segment};
use crate::error::{Error, Result};
use crate::field::{Accumulate, Compat, CurvatureOptions, Normalization, Precision};
use crate::gpu::Gpu;
use crate::mesh::edges::{EdgeTopology, vertex_normals};
use crate::mesh::skinned::SkinnedMesh;
use crate::mesh::{LoadOptions, Mesh};
use crate::render::colormap::{curvature_color, curvature_scale, with_ao};
use crate::render::edges::draw_edges;
use crate::render::{Camera, Frame, MeshStyle, RenderOptions, Renderer};
use crate::render::{Placement, framed};
use crate::scene::file::{CameraKind, ClipRef, Scene, Source, ViewSpec};
use crate::scene::planner::{Lifetime, Pass, Plan, plan_with};
use crate::stages::ao::AoStage;
use crate::stages::curvature::{CurvatureEstimator, Pass as CPass, RunTiming};
use crate::stages::edges::{EdgeOutput, EdgeParams, EdgeStage};
use crate::stages::feature_lines::{LineExtractor, LineOptions};
use crate::stages::skinning::Skinner;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// What ran of one pass.
#[derive(Clone, Debug, Serialize)]
pub struct PassRecord {
    /// The pass.
    pub pass: Pass,
    /// Its lifetime for this input.
    pub lifetime: Lifetime,
    /// How many times it ran.
    pub runs: usize,
    /// Total milliseconds over all runs.
    pub ms: f64,
    /// `kernel` (OpenCL profiling time) or `wall` (host time).
    pub clock: &'static str,
    /// What the pass did here.
    pub how: String,
}

/// The report of one scene run.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// The scene file.
    pub scene: String,
    /// The OpenCL device.
    pub device: String,
    /// The GL renderer.
    pub renderer: String,
    /// The plan: input kind, cues, passes in order.
    pub plan: Plan,
    /// Frame indices rendered.
    pub frames: Vec<usize>,
    /// Cameras per frame.
    pub views: usize,
    /// Vertices and faces of the (last) pose.
    pub vertices: usize,
    /// Faces.
    pub faces: usize,
    /// The passes that ran, in plan order, with counts and times.
    pub passes: Vec<PassRecord>,
    /// Median per-frame time of the pose passes (ms, their own clocks).
    pub pose_ms_median: f64,
    /// Median per-view time of the view passes other than rendering (ms).
    pub view_ms_median: f64,
    /// Median per-view render time (draw + read back), ms.
    pub render_ms_median: f64,
    /// Contour and suggestive-contour segments over all views.
    pub segments: [usize; 2],
    /// Notes (e.g. what skinning weights were dropped).
    pub notes: Vec<String>,
    /// Files written (images; the report itself is written last).
    pub outputs: Vec<PathBuf>,
    /// Wall time of the whole run, ms.
    pub wall_ms: f64,
}

/// Command-line overrides of a scene.
#[derive(Clone, Debug, Default)]
pub struct ExecOptions {
    /// Output folder instead of the scene's.
    pub out_dir: Option<PathBuf>,
    /// Overwrite existing outputs.
    pub force: bool,
    /// OpenCL device selector.
    pub device: Option<String>,
}

/// The geometry of a scene, loaded on the host.
enum Loaded {
    Static(Mesh),
    Skinned {
        mesh: Box<SkinnedMesh>,
        /// Joint matrices per frame index.
        poses: PoseFn,
        frames: usize,
    },
    Flipbook(crate::mesh::flipbook::Flipbook),
    /// The volume, the isovalue used and whether values were negated.
    Volume(Box<crate::volume::Volume>, f32, bool),
}

/// Joint matrices (flattened, device layout) of a frame.
type PoseFn = Box<dyn Fn(usize) -> Result<Vec<f32>>>;

impl Loaded {
    /// Frames available (None: unbounded, a static mesh's one frame repeats).
    fn frames(&self) -> usize {
        match self {
            Loaded::Static(_) | Loaded::Volume(..) => 1,
            Loaded::Skinned { frames, .. } => *frames,
            Loaded::Flipbook(f) => f.frames.len(),
        }
    }
}

fn load(scene: &Scene, notes: &mut Vec<String>) -> Result<Loaded> {
    let opts = LoadOptions { weld: scene.weld };
    Ok(match &scene.source {
        Source::Mesh(p) => Loaded::Static(crate::mesh::load(p, &opts)?),
        Source::Generate(kind, n) => match crate::mesh::generated_by_name(kind, *n) {
            Some((_, m)) => Loaded::Static(m),
            None => {
                return Err(Error::InvalidArgument(format!(
                    "unknown generated mesh {kind:?}"
                )));
            }
        },
        Source::Gltf(p, clip) => {
            let m = crate::mesh::skinned::load_gltf(p)?;
            if m.clips.is_empty() && clip.is_none() {
                notes.push(format!(
                    "{}: no animation; the rest pose is the one frame",
                    p.display()
                ));
                let rest = SkinnedMesh::flatten(&m.joint_matrices(None, 0.0)?);
                return Ok(Loaded::Skinned {
                    mesh: Box::new(m),
                    poses: Box::new(move |_| Ok(rest.clone())),
                    frames: 1,
                });
            }
            let idx = match clip.clone().unwrap_or(ClipRef::Index(0)) {
                ClipRef::Index(i) => i,
                ClipRef::Name(n) => m.clips.iter().position(|c| c.name == n).ok_or_else(|| {
                    Error::input(
                        p.display().to_string(),
                        format!("clip {n:?}"),
                        format!(
                            "no such clip; the file has {:?}",
                            m.clips.iter().map(|c| c.name.as_str()).collect::<Vec<_>>()
                        ),
                    )
                })?,
            };
            if idx >= m.clips.len() {
                return Err(Error::input(
                    p.display().to_string(),
                    format!("clip {idx}"),
                    format!("the file has {} clips", m.clips.len()),
                ));
            }
            let duration = m.clips[idx].duration;
            let fps = scene.fps;
            let frames = (duration * fps).floor() as usize + 1;
            notes.push(format!(
                "clip {idx} {:?}: {duration:.3} s at {fps} fps = {frames} frames",
                m.clips[idx].name
            ));
            let mm = m.clone();
            Loaded::Skinned {
                mesh: Box::new(m),
                poses: Box::new(move |f| {
                    let t = (f as f32 / fps).min(duration);
                    Ok(SkinnedMesh::flatten(&mm.joint_matrices(Some(idx), t)?))
                }),
                frames,
            }
        }
        Source::Lbs(p) => {
            let a = crate::mesh::libigl::load_elephant_set(p)?;
            let (m, trunc) = a.to_skinned();
            notes.push(format!(
                "{}: {} bones, weights cut to the 4 largest per vertex: {trunc:?}",
                p.display(),
                m.joint_nodes.len()
            ));
            let frames = a.frames;
            Loaded::Skinned {
                mesh: Box::new(m),
                poses: Box::new(move |f| Ok(SkinnedMesh::flatten(&a.frame_matrices(f)?))),
                frames,
            }
        }
        Source::Flipbook(pat) => Loaded::Flipbook(crate::mesh::flipbook::Flipbook::open(
            pat,
            Path::new(""),
            &opts,
        )?),
        Source::Volume(p, iso, above) => inside_below(crate::volume::load(p, None)?, *iso, *above),
        Source::Sdf(kind, res, iso, above) => {
            inside_below(crate::volume::sdf::sdf_by_name(kind, *res)?, *iso, *above)
        }
    })
}

/// Marching cubes orients its triangles (and the gradient normals) out of
/// the region *below* the isovalue. When the object is above it (density
/// data), the values and the isovalue are negated (exact in f32), so normals
/// point out of the object and its convex parts get positive curvature.
fn inside_below(mut v: crate::volume::Volume, iso: f32, above: bool) -> Loaded {
    if above {
        v.values.iter_mut().for_each(|x| *x = -*x);
        Loaded::Volume(Box::new(v), -iso, true)
    } else {
        Loaded::Volume(Box::new(v), iso, false)
    }
}

/// The frame indices a scene renders, checked against what the input has.
pub fn frame_indices(scene: &Scene, available: usize) -> Result<Vec<usize>> {
    let (start, end, step) = scene.frames;
    let end = end.unwrap_or(available);
    if end > available || start >= end {
        return Err(Error::input(
            scene.path.display().to_string(),
            "[frames]",
            format!("frames {start}..{end} are outside the input's {available} frame(s)"),
        ));
    }
    Ok((start..end).step_by(step).collect())
}

/// The image files a run writes, in order (frame-major), and the report.
pub fn output_paths(
    scene: &Scene,
    frames: &[usize],
    out_dir: &Path,
) -> (Vec<(usize, usize, PathBuf)>, PathBuf) {
    let mut v = Vec::new();
    for &f in frames {
        for view in 0..scene.views.len() {
            for (on, ext) in [(scene.png, "png"), (scene.svg, "svg")] {
                if on {
                    v.push((
                        f,
                        view,
                        out_dir.join(format!("{}_f{f:04}_v{view:02}.{ext}", scene.prefix)),
                    ));
                }
            }
        }
    }
    (v, out_dir.join(format!("{}_report.json", scene.prefix)))
}

/// Accumulates what each pass did.
struct Recorder {
    input: crate::scene::planner::Input,
    map: BTreeMap<Pass, PassRecord>,
}

impl Recorder {
    fn add(&mut self, pass: Pass, ms: f64, clock: &'static str, how: &str) {
        let r = self.map.entry(pass).or_insert_with(|| PassRecord {
            pass,
            lifetime: pass.lifetime(self.input),
            runs: 0,
            ms: 0.0,
            clock,
            how: how.to_string(),
        });
        r.runs += 1;
        r.ms += ms;
    }
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Kernel ms of the named curvature passes in a run.
fn pass_ms(t: &RunTiming, names: &[&str]) -> f64 {
    t.passes
        .iter()
        .filter(|p| names.contains(&p.pass))
        .map(|p| p.kernel_ms)
        .sum()
}

/// Per-topology device state.
struct Topology {
    mesh: Mesh,
    /// Median edge length ([`crate::mesh::feature_size`]) of the topology's
    /// first pose: the scale of the suggestive-contour threshold.
    feature_size: f32,
    /// Which vertices faces use.
    used: Vec<bool>,
    /// Normalization of the topology's first pose over the used vertices
    /// (fixed for a skinned mesh's poses, as in `PosePipeline`).
    norm: Normalization,
    est: Option<CurvatureEstimator>,
    lines: Option<LineExtractor>,
    edges: Option<EdgeStage>,
}

/// Host copies of the pose that the renderer and the host-side passes use.
#[derive(Default)]
struct PoseData {
    pos: Vec<[f32; 3]>,
    nrm: Vec<[f32; 3]>,
    k: Vec<[f32; 2]>,
    ao: Vec<f32>,
}

fn to_f32(v: &[[f64; 3]]) -> Vec<[f32; 3]> {
    v.iter().map(|p| p.map(|c| c as f32)).collect()
}

/// Resolves a view against the scene bounds (scene frame); explicit eyes and
/// targets are world positions, moved into the scene frame by `origin`.
fn camera(
    v: &ViewSpec,
    bounds: ([f64; 3], [f64; 3]),
    aspect: f32,
    origin: [f64; 3],
) -> Result<Camera> {
    let local = |p: [f32; 3]| -> glam::Vec3 {
        glam::Vec3::from(std::array::from_fn::<f32, 3, _>(|i| {
            (f64::from(p[i]) - origin[i]) as f32
        }))
    };
    let up = v.up.map(glam::Vec3::from);
    let (placement, target) = match &v.kind {
        CameraKind::LookAt { eye, target } => (Placement::At(local(*eye)), target.map(local)),
        CameraKind::Fit(d) => (Placement::Fit(glam::Vec3::from(*d)), None),
    };
    framed(placement, target, up, v.fov, v.ortho, bounds, aspect)
}

/// Runs a scene: loads the input, plans, refuses to overwrite outputs
/// (unless `force`), then runs the planned passes frame by frame and view by
/// view, calling `progress(done, total)` after each view. Returns the report,
/// which is also written next to the images.
pub fn run(
    scene: &Scene,
    opts: &ExecOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport> {
    let t_all = Instant::now();
    let mut notes = Vec::new();
    let loaded = load(scene, &mut notes)?;
    let frames = frame_indices(scene, loaded.frames())?;
    let out_dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| scene.out_dir.clone());
    let (images, report_path) = output_paths(scene, &frames, &out_dir);
    // Refuse before any work: nothing the user has is overwritten.
    if !opts.force {
        for p in images.iter().map(|i| &i.2).chain([&report_path]) {
            if p.exists() {
                return Err(Error::InvalidArgument(format!(
                    "{} exists; pass --force to overwrite it",
                    p.display()
                )));
            }
        }
    }
    std::fs::create_dir_all(&out_dir).map_err(|source| Error::Write {
        path: out_dir.clone(),
        source,
    })?;

    let fx = &scene.effects;
    let input = scene.source.input();
    let plan = plan_with(&fx.cues, input, fx.caps);
    let has = |p: Pass| plan.contains(p);
    let mut rec = Recorder {
        input,
        map: BTreeMap::new(),
    };
    let gpu = Arc::new(Gpu::new(opts.device.as_deref())?);
    let [w, h] = scene.size;
    let [br, bg, bb] = scene.background;
    let mut renderer = Renderer::new(RenderOptions {
        width: w,
        height: h,
        msaa: scene.msaa,
        background: [br, bg, bb, 1.0],
    })?;
    let curv_opts = CurvatureOptions {
        accumulate: Accumulate::Atomic,
        precision: Precision::F32,
        compat: Compat::Exact,
        dcurv: has(Pass::Dcurv),
    };
    let line_opts = LineOptions {
        contours: has(Pass::Contours),
        suggestive: has(Pass::SuggestiveContours),
        threshold: fx.suggestive_threshold,
        fade: fx.suggestive_fade,
    };
    let last_curv = if has(Pass::Dcurv) {
        CPass::Dcurv
    } else {
        CPass::Principal
    };

    let mut skinner = match &loaded {
        Loaded::Skinned { mesh, .. } if has(Pass::Skin) => Some(Skinner::new(gpu.clone(), mesh)?),
        _ => None,
    };
    let mut iso = match &loaded {
        Loaded::Volume(v, ..) if has(Pass::Isosurface) => Some(
            crate::stages::marching_cubes::Isosurfacer::new(gpu.clone(), v)?,
        ),
        _ => None,
    };
    let mut ao_stage = if has(Pass::Ao) {
        Some(AoStage::new(gpu.clone())?)
    } else {
        None
    };

    let mut topo: Option<Topology> = None;
    let mut pose = PoseData::default();
    let mut bounds = None;
    // World position of the scene frame's origin (see the pose block).
    let mut origin: Option<[f64; 3]> = None;
    let mut cameras: Vec<Camera> = Vec::new();
    let mut color_scale = fx.curvature_scale;
    let mut ao_radius = 0.0f32;
    let (mut pose_ms, mut view_ms, mut render_ms) = (Vec::new(), Vec::new(), Vec::new());
    let mut segments = [0usize; 2];
    let mut outputs = Vec::new();
    let total_views = frames.len() * scene.views.len();
    let mut done = 0;
    let static_input = input == crate::scene::planner::Input::Static;

    for (fi, &frame) in frames.iter().enumerate() {
        // ---- Pose passes (once in all for a static mesh). ----
        if fi == 0 || !static_input {
            let mut t_pose = 0.0;
            // Source: new positions (and, for an isosurface, a new topology).
            let mut new_mesh: Option<Mesh> = None;
            let mut host_pos: Option<Vec<[f64; 3]>> = None;
            match &loaded {
                Loaded::Static(m) => {
                    if topo.is_none() {
                        new_mesh = Some(m.clone());
                    }
                }
                Loaded::Skinned { mesh, poses, .. } => {
                    if topo.is_none() {
                        new_mesh = Some(mesh.rest.clone());
                    }
                    if let Some(sk) = skinner.as_mut() {
                        let mats = poses(frame)?;
                        let ms = sk.pose(&mats)?;
                        rec.add(
                            Pass::Skin,
                            ms,
                            "kernel",
                            "skin_lbs (linear blend, ≤ 4 joints)",
                        );
                        t_pose += ms;
                    }
                }
                Loaded::Flipbook(fb) => {
                    let t = Instant::now();
                    let p = fb.frame(frame)?;
                    let ms = ms_since(t);
                    if topo.is_none() {
                        new_mesh = Some(Mesh::new(
                            p.clone(),
                            fb.faces.clone(),
                            &fb.frames[frame].display().to_string(),
                        )?);
                    }
                    if has(Pass::LoadFrame) {
                        rec.add(Pass::LoadFrame, ms, "wall", "read the frame file");
                        t_pose += ms;
                    }
                    host_pos = Some(p);
                }
                Loaded::Volume(v, iso_value, negated) => {
                    let ex = iso.as_mut().expect("planned with the isosurface");
                    let s = ex.extract(*iso_value, crate::cpu::vertex_fusion::Fusion::Edge)?;
                    rec.add(
                        Pass::Isosurface,
                        s.kernel_ms,
                        "kernel",
                        "marching cubes + exact edge-key fusion",
                    );
                    t_pose += s.kernel_ms;
                    let m = ex.read()?;
                    if m.n_faces() == 0 {
                        return Err(Error::input(scene.path.display().to_string(), "[input]", {
                            let sign = if *negated { -1.0 } else { 1.0 };
                            let span = v.range().map(|(a, b)| {
                                let (a, b) = (sign * a, sign * b);
                                (a.min(b), a.max(b))
                            });
                            format!(
                                "the isosurface at iso {} is empty (the values span {span:?})",
                                sign * iso_value
                            )
                        }));
                    }
                    new_mesh = Some(m);
                    topo = None;
                }
            }

            // Topology passes.
            if let Some(m) = new_mesh {
                let used = crate::mesh::referenced(m.n_vertices(), &m.faces);
                let norm = Normalization::of_masked(&m.positions, Some(&used));
                let fs = crate::mesh::feature_size(&m.positions, &m.faces);
                let mut t = Topology {
                    feature_size: if fs > 0.0 { fs } else { norm.scale } as f32,
                    used,
                    norm,
                    mesh: m,
                    est: None,
                    lines: None,
                    edges: None,
                };
                let nv = t.mesh.n_vertices();
                if has(Pass::OneRings) {
                    if let Some(ex) = iso.as_ref() {
                        // The isosurface's faces stay on the device; normals from the gradient.
                        let (est, timing) = crate::stages::marching_cubes::curvature(
                            ex,
                            curv_opts,
                            crate::stages::marching_cubes::IsoNormals::Gradient,
                        )?;
                        rec.add(
                            Pass::OneRings,
                            est.topology_ms(),
                            "wall",
                            "faces copied on the device, owning faces (atomic_max); \
                             includes the first program build",
                        );
                        record_curvature(
                            &mut rec,
                            &timing,
                            &plan,
                            "then replaced by the volume's gradient",
                        );
                        t_pose += est.topology_ms() + timing.kernel_ms;
                        t.est = Some(est);
                    } else {
                        let tt = Instant::now();
                        let est =
                            CurvatureEstimator::new(gpu.clone(), nv, &t.mesh.faces, curv_opts)?;
                        rec.add(
                            Pass::OneRings,
                            ms_since(tt),
                            "wall",
                            "upload faces, owning faces (atomic_max); includes the first program build",
                        );
                        t.est = Some(est);
                    }
                }
                if has(Pass::Contours) || has(Pass::SuggestiveContours) {
                    t.lines = Some(LineExtractor::new(gpu.clone(), nv, &t.mesh.faces)?);
                }
                if has(Pass::EdgeBuffer) {
                    let tt = Instant::now();
                    let name = scene.path.display().to_string();
                    let et = if has(Pass::CapBuffer) {
                        EdgeTopology::new(&t.mesh, &[], &name)?
                    } else {
                        EdgeTopology::without_caps(&t.mesh, &[], &name)?
                    };
                    let both = ms_since(tt);
                    rec.add(
                        Pass::EdgeBuffer,
                        both,
                        "wall",
                        "unique edges with opposite vertices (host, once per topology)",
                    );
                    if has(Pass::CapBuffer) {
                        rec.add(Pass::CapBuffer, 0.0, "wall", "pairs of edges sharing a vertex (built with the edge buffer; time counted there)");
                    }
                    t.edges = Some(EdgeStage::new(gpu.clone(), &t.mesh, &et)?);
                }
                topo = Some(t);
            }
            let t = topo
                .as_mut()
                .expect("a topology exists after the first pose");
            let nv = t.mesh.n_vertices();

            // Curvature (with its normals) on the pose's positions.
            if let (Some(est), None) = (t.est.as_mut(), iso.as_ref()) {
                if let Some(sk) = skinner.as_ref() {
                    est.set_positions_device(&sk.out, [1.0; 3], [0.0; 3], t.norm)?;
                } else {
                    est.set_positions(host_pos.as_deref().unwrap_or(&t.mesh.positions))?;
                }
                let timing = est.run_until(last_curv)?;
                record_curvature(
                    &mut rec,
                    &timing,
                    &plan,
                    "curvature normals (area-weighted)",
                );
                t_pose += timing.kernel_ms;
            }
            // Host copies for drawing and host passes, relative to the scene
            // origin (the centre of the first pose), so that a mesh far from
            // the world origin keeps its f32 precision in the renderer.
            if let Some(sk) = skinner.as_ref() {
                let p = sk.read()?;
                let o = *origin.get_or_insert_with(|| {
                    centre(bounds_of(p.iter().map(|q| q.map(f64::from)), &t.used))
                });
                pose.pos = p
                    .iter()
                    .map(|q| std::array::from_fn(|i| (f64::from(q[i]) - o[i]) as f32))
                    .collect();
            } else {
                let p = host_pos.as_deref().unwrap_or(&t.mesh.positions);
                let o =
                    *origin.get_or_insert_with(|| centre(bounds_of(p.iter().copied(), &t.used)));
                pose.pos = p
                    .iter()
                    .map(|q| std::array::from_fn(|i| (q[i] - o[i]) as f32))
                    .collect();
            }
            if let Some(est) = t.est.as_ref() {
                let f = est.read()?;
                pose.nrm = to_f32(&f.normals);
                pose.k =
                    f.k1.iter()
                        .zip(&f.k2)
                        .map(|(&a, &b)| [a as f32, b as f32])
                        .collect();
            } else if has(Pass::VertexNormals) {
                let tt = Instant::now();
                let m = Mesh {
                    positions: pose.pos.iter().map(|p| p.map(f64::from)).collect(),
                    faces: t.mesh.faces.clone(),
                };
                pose.nrm = vertex_normals(&m);
                let ms = ms_since(tt);
                rec.add(
                    Pass::VertexNormals,
                    ms,
                    "wall",
                    "area-weighted, host (no curvature planned)",
                );
                t_pose += ms;
            } else {
                // Nothing planned reads vertex normals: edges_detect and
                // caps_adjacency do not, and a lines-only mesh is drawn flat.
                pose.nrm = vec![[0.0; 3]; nv];
            }
            if bounds.is_none() {
                let b = bounds_of(pose.pos.iter().map(|q| q.map(f64::from)), &t.used);
                let diag = ((0..3).map(|i| (b.1[i] - b.0[i]).powi(2)).sum::<f64>()).sqrt();
                ao_radius = (fx.ao_radius as f64 * diag.max(1e-30)) as f32;
                cameras = scene
                    .views
                    .iter()
                    .map(|v| camera(v, b, w as f32 / h as f32, origin.unwrap_or_default()))
                    .collect::<Result<_>>()?;
                if color_scale.is_none() && !pose.k.is_empty() {
                    color_scale = Some(curvature_scale(&pose.k));
                }
                bounds = Some(b);
            }
            if let (Some(ao), Some(est)) = (ao_stage.as_mut(), t.est.as_ref()) {
                let ms = ao.run_device(est, ao_radius, fx.ao_mode)?;
                rec.add(
                    Pass::Ao,
                    ms,
                    "kernel",
                    &format!("ao_vertex, level {:?}", fx.ao_mode),
                );
                t_pose += ms;
                pose.ao = ao.read(nv)?;
            }
            if let Some(es) = t.edges.as_mut() {
                let tt = Instant::now();
                es.set_positions(&pose.pos, &pose.nrm)?;
                let ms = ms_since(tt);
                rec.add(Pass::FaceNormals, ms, "wall", "upload the pose to the edge stage; face normals are computed inside edges_detect");
                t_pose += ms;
            }
            pose_ms.push(t_pose);
        }

        // ---- View passes. ----
        let t = topo.as_mut().expect("a topology exists");
        let colors = mesh_colors(scene, &plan, &pose, color_scale.unwrap_or(1.0));
        for (vi, cam) in cameras.iter().enumerate() {
            let mut t_view = 0.0;
            let mut segs: Vec<Segment> = Vec::new();
            if let Some(lx) = t.lines.as_mut() {
                let v = cam.view(w, h);
                let (s, stats) = match t.est.as_ref() {
                    Some(est) => lx.extract_device_at(
                        est,
                        v,
                        t.feature_size,
                        line_opts,
                        origin.unwrap_or_default(),
                    )?,
                    None => {
                        let n = pose.pos.len();
                        let z3 = vec![[0f32; 3]; n];
                        let x = LineInputs {
                            pos: &pose.pos,
                            nrm: &pose.nrm,
                            d1: &z3,
                            d2: &z3,
                            k: &vec![[0f32; 2]; n],
                            dk: &vec![[0f32; 4]; n],
                        };
                        lx.extract(&x, v, t.feature_size, line_opts)?
                    }
                };
                let ms = stats.vertex_ms + stats.face_ms;
                t_view += ms;
                if has(Pass::Contours) {
                    rec.add(
                        Pass::Contours,
                        ms,
                        "kernel",
                        "lines_vertex + lines_face (zero crossings of n·v)",
                    );
                }
                if has(Pass::SuggestiveContours) {
                    let (ms, how) = if has(Pass::Contours) {
                        (
                            0.0,
                            "in the same lines_vertex + lines_face launch as the contours (time counted there)",
                        )
                    } else {
                        (
                            ms,
                            "lines_vertex + lines_face (zero crossings of κr with D_w κr > 0)",
                        )
                    };
                    rec.add(Pass::SuggestiveContours, ms, "kernel", how);
                }
                segs = s;
            }
            let mut edges_out: Option<EdgeOutput> = None;
            if let Some(es) = t.edges.as_mut() {
                let mut p = EdgeParams::new(cam.view(w, h));
                p.line_width = fx.edge.0;
                p.crease_deg = fx.crease;
                p.contours = fx.edge_contours;
                p.boundaries = fx.edge_boundaries;
                let timing = es.run(&p, fx.caps)?;
                rec.add(
                    Pass::EdgeDetect,
                    timing.detect_ms,
                    "kernel",
                    "edges_detect (contour, crease, boundary) into edge-out",
                );
                if has(Pass::Caps) {
                    rec.add(
                        Pass::Caps,
                        timing.caps_ms,
                        "kernel",
                        &format!("caps_{}", fx.caps.name()),
                    );
                }
                t_view += timing.kernel_ms;
                edges_out = Some(es.read()?);
            }
            view_ms.push(t_view);

            // Render.
            let tr = Instant::now();
            renderer.begin(cam)?;
            let lines_only = !(has(Pass::Ao)
                || fx.cues.contains(&crate::scene::planner::Cue::Shading)
                || fx
                    .cues
                    .contains(&crate::scene::planner::Cue::CurvatureColors));
            let style = if lines_only {
                // Lines only: the mesh is drawn flat in the background colour,
                // so that it hides the lines behind it.
                MeshStyle {
                    ambient: 1.0,
                    color: scene.background,
                    ..MeshStyle::default()
                }
            } else {
                MeshStyle {
                    ambient: fx.ambient,
                    color: fx.base_color,
                    ..MeshStyle::default()
                }
            };
            renderer.draw_mesh(&pose.pos, &pose.nrm, &colors, &t.mesh.faces, style)?;
            let mut line_quads: Vec<[f32; 4]> = Vec::new();
            // Contours opaque; suggestive contours in four opacity bins of
            // their n·v fade (DeCarlo et al. fade them out as they approach
            // the contour generator, where they are unstable).
            const BINS: [f32; 4] = [0.25, 0.5, 0.75, 1.0];
            for (kind, (width, color)) in [(0u32, fx.contour), (1u32, fx.suggestive)] {
                let mut n = 0;
                for (bi, &alpha) in BINS.iter().enumerate() {
                    let pts: Vec<[f32; 3]> = segs
                        .iter()
                        .filter(|s| s.2 == kind && (kind == 0 || strength_bin(s.3) == bi))
                        .flat_map(|s| [s.0, s.1])
                        .collect();
                    if pts.is_empty() || (kind == 0 && bi > 0) {
                        continue;
                    }
                    n += pts.len() / 2;
                    let [r, g, b] = color;
                    let a = if kind == 0 { 1.0 } else { alpha };
                    renderer.draw_lines(&pts, [r, g, b, a], width)?;
                    if scene.svg {
                        line_quads.extend(crate::render::segments_to_clip_quads(
                            cam.view_proj(w as f32 / h as f32),
                            [w, h],
                            &pts,
                            width,
                        ));
                    }
                }
                segments[kind as usize] += n;
            }
            if let Some(eo) = &edges_out {
                let [r, g, b] = fx.edge.1;
                draw_edges(&mut renderer, eo, [r, g, b, 1.0])?;
                line_quads.extend_from_slice(&eo.edge_out);
            }
            let image: Frame = renderer.finish()?;
            let ms = ms_since(tr);
            rec.add(
                Pass::Render,
                ms,
                "wall",
                "draw mesh, line quads and edge quads; read back",
            );
            render_ms.push(ms);
            for (_, _, path) in images.iter().filter(|i| i.0 == frame && i.1 == vi) {
                if path.extension().is_some_and(|e| e == "png") {
                    image.save_png(path)?;
                } else {
                    let lines = crate::export::svg::visible_polylines(
                        &line_quads,
                        &image,
                        crate::export::svg::DEFAULT_BIAS,
                    );
                    let width = fx.contour.0.max(fx.edge.0);
                    crate::export::svg::write_svg(path, &lines, w, h, width)?;
                }
                outputs.push(path.clone());
            }
            done += 1;
            progress(done, total_views);
        }
    }

    let t = topo.as_ref().expect("at least one frame ran");
    let passes: Vec<PassRecord> = plan
        .passes
        .iter()
        .filter_map(|p| rec.map.get(p).cloned())
        .collect();
    let report = RunReport {
        scene: scene.path.display().to_string(),
        device: gpu.info.name.clone(),
        renderer: renderer.gl_info(),
        plan: plan.clone(),
        frames,
        views: scene.views.len(),
        vertices: t.mesh.n_vertices(),
        faces: t.mesh.n_faces(),
        passes,
        pose_ms_median: crate::report::median(&mut pose_ms),
        view_ms_median: crate::report::median(&mut view_ms),
        render_ms_median: crate::report::median(&mut render_ms),
        segments,
        notes,
        outputs,
        wall_ms: ms_since(t_all),
    };
    let json = serde_json::to_string_pretty(&report).expect("the report serializes") + "\n";
    std::fs::write(&report_path, json).map_err(|source| Error::Write {
        path: report_path.clone(),
        source,
    })?;
    Ok(report)
}

/// Splits a curvature run's kernel time into the planner's passes.
fn record_curvature(rec: &mut Recorder, t: &RunTiming, plan: &Plan, normals: &str) {
    rec.add(
        Pass::VertexNormals,
        pass_ms(t, &["clear", "normals_areas", "frames"]),
        "kernel",
        &format!("clear + normals_areas + frames ({normals})"),
    );
    rec.add(
        Pass::Curvature,
        pass_ms(t, &["tensor", "principal"]),
        "kernel",
        "tensor + principal (Rusinkiewicz, atomic f32)",
    );
    if plan.contains(Pass::Dcurv) {
        rec.add(Pass::Dcurv, pass_ms(t, &["dcurv"]), "kernel", "dcurv");
    }
}

/// The opacity bin (0..4) of a suggestive-contour segment's strength in [0, 1].
fn strength_bin(strength: f32) -> usize {
    if strength.is_finite() {
        ((strength.clamp(0.0, 1.0) * 4.0).ceil() as usize).clamp(1, 4) - 1
    } else {
        3
    }
}

/// Bounds of the vertices that faces use (a stray unreferenced vertex far
/// away must not shrink the mesh to a dot in a fitted camera).
fn bounds_of(p: impl Iterator<Item = [f64; 3]>, used: &[bool]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (q, _) in p.zip(used).filter(|(_, u)| **u) {
        for i in 0..3 {
            lo[i] = lo[i].min(q[i]);
            hi[i] = hi[i].max(q[i]);
        }
    }
    (lo, hi)
}

/// Centre of bounds (0 on an axis where it is not finite, e.g. no used vertex).
fn centre((lo, hi): ([f64; 3], [f64; 3])) -> [f64; 3] {
    std::array::from_fn(|i| {
        let c = 0.5 * (lo[i] + hi[i]);
        if c.is_finite() { c } else { 0.0 }
    })
}

/// Per-vertex colours: curvature colours and/or AO; empty (the style's flat
/// colour) when neither is asked for.
fn mesh_colors(scene: &Scene, plan: &Plan, pose: &PoseData, scale: f32) -> Vec<[f32; 3]> {
    let fx = &scene.effects;
    let colors = fx
        .cues
        .contains(&crate::scene::planner::Cue::CurvatureColors);
    // The AO pass is planned exactly when the AO cue is asked for.
    let ao = plan.contains(Pass::Ao);
    if !colors && !ao {
        return Vec::new();
    }
    (0..pose.pos.len())
        .map(|i| {
            let c = if colors {
                let [a, b] = pose.k[i];
                curvature_color(a, b, scale, fx.base_color)
            } else {
                fx.base_color
            };
            if ao { with_ao(c, pose.ao[i]) } else { c }
        })
        .collect()
}

/// The plan of a scene and the frames it would render, as `--explain` prints
/// it: loads the input (to count its frames) but touches no device and
/// writes nothing.
pub fn explain(scene: &Scene, opts: &ExecOptions) -> Result<String> {
    let mut notes = Vec::new();
    let loaded = load(scene, &mut notes)?;
    let frames = frame_indices(scene, loaded.frames())?;
    let fx = &scene.effects;
    let plan = plan_with(&fx.cues, scene.source.input(), fx.caps);
    let out_dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| scene.out_dir.clone());
    let (images, report) = output_paths(scene, &frames, &out_dir);
    let mut s = format!(
        "{}: frames {:?}{}\n",
        scene.path.display(),
        &frames[..frames.len().min(8)],
        if frames.len() > 8 { " ..." } else { "" }
    );
    for n in &notes {
        s.push_str(&format!("  note: {n}\n"));
    }
    s.push_str(&plan.explain(frames.len(), scene.views.len()));
    s.push_str(&format!(
        "  writes {} image(s) and {}\n",
        images.len(),
        report.display()
    ));
    Ok(s)
}
