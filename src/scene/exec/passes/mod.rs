//! Per-pass execution: the executor's state and one arm per planner pass.
//! [`Executor::pose_pass`] runs a topology or pose pass, [`Executor::view_pass`]
//! a view pass; the caller walks the plan's passes in order, filtered by
//! lifetime, and calls them. Nothing here decides *what* runs: an arm runs
//! because its pass is in the plan.
//!
//! Stages: a skinned input runs skinning, curvature and AO through
//! [`PosePipeline`] (built with only the stages the plan needs); the other
//! inputs hold their curvature estimator per topology (an isosurface's on
//! the device, from the fusion kernels) and one [`AoStage`]. The feature
//! lines and the edge stage are per topology for every input. A volume's
//! curvature-directed strokes ([`SdfLines`]) are traced on the volume
//! itself, uploaded once for the run, and need no mesh pass.

mod stages;
mod state;
mod view;
mod visibility;

use super::draw::{self, ViewLines};
use super::interop::{SharedEdges, interop_offer};
use super::load::Loaded;
use super::report::{Recorder, ms_since};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::mesh::Mesh;
use crate::mesh::edges::{EdgeTopology, read_marked};
use crate::mesh::topology::vertex_normals;
use crate::render::colormap::curvature_scale;
use crate::render::{Camera, Renderer};
use crate::scene::file::Scene;
use crate::scene::planner::{Pass, Plan};
use crate::spec::curvature::CurvatureOptions;
use crate::spec::edges::{EdgeOutput, EdgeParams};
use crate::spec::feature_lines::LineInputs;
use crate::spec::interop::{InteropDecision, InteropOffer, InteropRoute, decide_interop};
use crate::spec::marching_cubes::IsoNormals;
use crate::spec::sdf_lines::Stroke;
use crate::spec::timing::{Step, Timing};
use crate::stages::ao::AoStage;
use crate::stages::bvh::Bvh;
use crate::stages::curvature::{CurvatureEstimator, Pass as CurvPass};
use crate::stages::edges::EdgeStage;
use crate::stages::feature_lines::LineExtractor;
use stages::{isosurfacer, line_options, skinning_pipeline, strokes_stage};
pub(super) use state::Keep;
use state::{PoseState, RunStages, RunState, ViewState};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// Per-topology state.
struct TopologyState {
    mesh: Mesh,
    /// The scale of the line families' thresholds, as the scene asks for it
    /// ([`crate::mesh::feature_size::resolve`]), from the topology's first
    /// pose and its curvature; found by the first view's lines.
    feature_size: Option<f32>,
    /// Which vertices faces use.
    used: Vec<bool>,
    /// The curvature estimator of an unskinned input.
    est: Option<CurvatureEstimator>,
    lines: Option<LineExtractor>,
    edges: Option<EdgeStage>,
    /// The edge buffer's counts.
    edge_counts: Option<draw::EdgeCounts>,
    /// The edges frame's shared buffer (external-memory route), made by the
    /// first view.
    shared: Option<SharedEdges>,
    /// The two vertices of each edge entry (for the SVG's feature edges).
    edge_pairs: Vec<[u32; 2]>,
    /// The BVH of exact visibility and intersection lines (built on the
    /// first pose, refitted to later ones).
    bvh: Option<Bvh>,
    /// The intersection lines' search (made by the first pose).
    isect: Option<crate::stages::intersections::Intersections>,
    /// Whether the renderer holds this topology's faces.
    gl: bool,
}

impl TopologyState {
    fn new(mesh: Mesh) -> Self {
        let used = crate::mesh::referenced(mesh.n_vertices(), &mesh.faces);
        TopologyState {
            feature_size: None,
            used,
            mesh,
            est: None,
            lines: None,
            edges: None,
            edge_counts: None,
            shared: None,
            edge_pairs: Vec::new(),
            bvh: None,
            isect: None,
            gl: false,
        }
    }
}

/// What the first pose fixes for the whole run: the scene origin, the
/// cameras, the AO radius and the curvature colour scale.
struct Framing {
    /// World position of the scene frame's origin (the centre of the first
    /// pose), so that a mesh far from the world origin keeps its f32
    /// precision in the renderer.
    origin: [f64; 3],
    /// Bounds of the first pose's used vertices (scene frame), which fitted
    /// cameras frame.
    bounds: ([f64; 3], [f64; 3]),
    cameras: Vec<Camera>,
    ao_radius: f32,
}

/// The executor's state over a run: what it was given, its recorder and
/// renderer, and one value per lifetime ([`state`]).
pub(super) struct Executor<'s, 'g> {
    scene: &'s Scene,
    plan: &'s Plan,
    loaded: Loaded,
    gpu: &'g Arc<Gpu>,
    pub(super) rec: Recorder,
    /// The renderer, where the plan draws a frame (none for a vector
    /// drawing with exact visibility: no GL context is opened).
    renderer: Option<Renderer>,
    /// The stages and options built for the run.
    stages: RunStages,
    /// What the run fixes on its first pose and counts over all.
    pub(super) run: RunState,
    /// The current topology.
    topo: Option<TopologyState>,
    /// The current pose.
    pose: PoseState,
    /// The current view.
    view: ViewState,
    /// What the caller keeps of each view.
    pub(super) keep: Keep,
    /// The last view's outputs, when kept.
    pub(super) kept: Option<super::draw::ViewOutputs>,
    /// Where the next view's lines keep their hysteresis state (a run over
    /// an animation's frames with coherence on sets it; `None`: none).
    pub(super) hold: Option<crate::stages::feature_lines::HoldAt>,
}

impl<'s, 'g> Executor<'s, 'g> {
    /// Builds the stages whose passes the plan holds that live for the
    /// whole run (skinning pipeline, isosurfacer, AO).
    pub(super) fn new(
        scene: &'s Scene,
        plan: &'s Plan,
        loaded: Loaded,
        gpu: &'g Arc<Gpu>,
        renderer: Option<Renderer>,
    ) -> Result<Self> {
        let fx = &scene.effects;
        let has = |p: Pass| plan.contains(p);
        let curv_opts = CurvatureOptions {
            dcurv: has(Pass::Dcurv),
            ..scene.curvature
        };
        let line_opts = line_options(scene, plan);
        let pipe = skinning_pipeline(&loaded, plan, gpu, scene, curv_opts)?;
        let iso = isosurfacer(&loaded, plan, gpu)?;
        let sdf_lines = strokes_stage(&loaded, plan, gpu, scene)?;
        let interop = match has(Pass::Edges) {
            true => Some(view::decide(gpu, scene, has(Pass::Render))?),
            false => None,
        };
        let ao = match (&pipe, has(Pass::Ao)) {
            (None, true) => Some(AoStage::new(gpu.clone())?),
            _ => None,
        };
        Ok(Executor {
            scene,
            plan,
            loaded,
            gpu,
            rec: Recorder::new(plan.input),
            renderer,
            stages: RunStages {
                curv_opts,
                line_opts,
                pipe,
                iso,
                ao,
                sdf_lines,
                interop,
            },
            run: RunState {
                color_scale: fx.curvature_scale,
                ..Default::default()
            },
            topo: None,
            pose: PoseState::default(),
            view: ViewState::default(),
            keep: Keep::default(),
            kept: None,
            hold: None,
        })
    }

    /// The renderer's GL description (none when no frame is drawn).
    pub(super) fn gl_info(&self) -> String {
        (self.renderer.as_ref()).map_or_else(|| "none (no frame drawn)".into(), |r| r.gl_info())
    }

    /// The renderer's mesh uploads so far.
    pub(super) fn uploads(&self) -> crate::render::Uploads {
        (self.renderer.as_ref()).map_or_else(Default::default, |r| r.uploads())
    }

    /// The renderer, for the next scene of the session (the shared edge
    /// buffer freed first).
    pub(super) fn into_renderer(self) -> Option<Renderer> {
        self.into_parts().1
    }

    /// The loaded input and the renderer, for the next executor of a live
    /// scene whose input stays.
    pub(super) fn into_parts(mut self) -> (Loaded, Option<Renderer>) {
        if let (Some(sh), Some(r)) = (
            self.topo.as_mut().and_then(|t| t.shared.take()),
            self.renderer.as_mut(),
        ) {
            sh.free(r);
        }
        (self.loaded, self.renderer)
    }

    /// Vertices and faces of the current topology.
    pub(super) fn counts(&self) -> (usize, usize) {
        self.topo
            .as_ref()
            .map_or((0, 0), |t| (t.mesh.n_vertices(), t.mesh.n_faces()))
    }

    /// The curvature estimator of the current pose, wherever it lives.
    fn est(&self) -> Option<&CurvatureEstimator> {
        match &self.stages.pipe {
            Some(p) => p.estimator(),
            None => self.topo.as_ref().and_then(|t| t.est.as_ref()),
        }
    }

    /// Starts a pose: nothing of the last one is reused.
    pub(super) fn begin_pose(&mut self) {
        self.pose = PoseState::default();
    }

    /// Ends a pose: host copies made (if no pass needed them), the colour
    /// scale fixed on the first pose.
    pub(super) fn end_pose(&mut self, frame: usize) -> Result<()> {
        self.host_pose(frame)?;
        if self.run.color_scale.is_none() && !self.pose.host.k.is_empty() {
            self.run.color_scale = Some(curvature_scale(&self.pose.host.k));
        }
        Ok(())
    }

    /// The current topology, made from the input on the first pose (an
    /// isosurface's comes from its pass).
    fn topology(&mut self, frame: usize) -> Result<&mut TopologyState> {
        if self.topo.is_none() {
            let mesh = match &self.loaded {
                Loaded::Static(m, _) => m.clone(),
                Loaded::Skinned { mesh, .. } => mesh.rest.clone(),
                Loaded::Flipbook(fb) => {
                    let p = match self.pose.frame_pos.take() {
                        Some(p) => p,
                        None => fb.frame(frame)?,
                    };
                    self.pose.frame_pos = Some(p.clone());
                    let name = fb.frames[frame].display().to_string();
                    Mesh::new(p, fb.faces.clone(), &name)?
                }
                Loaded::Volume(..) => {
                    return Err(Error::InvalidArgument(
                        "internal: an isosurface scene without its isosurface pass".into(),
                    ));
                }
            };
            self.topo = Some(TopologyState::new(mesh));
        }
        Ok(self.topo.as_mut().expect("made above"))
    }

    /// Host copies of the pose's positions for drawing and host passes,
    /// relative to the scene origin; on the first pose, the bounds fix the
    /// origin, the cameras and the AO radius. Normals start at zero: only a
    /// planned normals pass fills them (`edges_detect` and `caps_adjacency`
    /// do not read them, and a lines-only mesh is drawn flat).
    fn host_pose(&mut self, frame: usize) -> Result<()> {
        if self.pose.ready {
            return Ok(());
        }
        self.topology(frame)?;
        let t = self.topo.as_ref().expect("made above");
        let skinned = match &self.stages.pipe {
            Some(p) => Some(p.skinner().read()?),
            None => None,
        };
        let host: Vec<[f64; 3]> = match (&skinned, &self.pose.frame_pos) {
            (Some(p), _) => p.iter().map(|q| q.map(f64::from)).collect(),
            (None, Some(p)) => p.clone(),
            (None, None) => t.mesh.positions.clone(),
        };
        let o = match &self.run.framing {
            Some(f) => f.origin,
            None => draw::centre(draw::bounds_of(host.iter().copied(), &t.used)),
        };
        self.pose.host.pos = match &skinned {
            // f32 positions: subtract in f64 from the f32 values.
            Some(p) => p
                .iter()
                .map(|q| std::array::from_fn(|i| (f64::from(q[i]) - o[i]) as f32))
                .collect(),
            None => host
                .iter()
                .map(|q| std::array::from_fn(|i| (q[i] - o[i]) as f32))
                .collect(),
        };
        self.pose.host.nrm = vec![[0.0; 3]; t.mesh.n_vertices()];
        if self.run.framing.is_none() {
            let b = draw::bounds_of(self.pose.host.pos.iter().map(|q| q.map(f64::from)), &t.used);
            let diag = ((0..3).map(|i| (b.1[i] - b.0[i]).powi(2)).sum::<f64>()).sqrt();
            let [w, h] = self.scene.size;
            let cameras = self
                .scene
                .views
                .iter()
                .map(|v| draw::camera(v, b, w as f32 / h as f32, o))
                .collect::<Result<_>>()?;
            self.run.framing = Some(Framing {
                origin: o,
                bounds: b,
                cameras,
                ao_radius: (self.scene.effects.ao_radius as f64 * diag.max(1e-30)) as f32,
            });
        }
        self.pose.ready = true;
        Ok(())
    }

    /// The curvature run of this pose (normals, curvature, dcurv), run on
    /// first use: from the skinned buffer, or from the host positions.
    fn curvature_run(&mut self, frame: usize) -> Result<Timing> {
        if let Some(t) = &self.pose.curv {
            return Ok(t.clone());
        }
        let t = self.estimator_run(frame, CurvPass::Dcurv)?;
        self.pose.curv = Some(t.clone());
        Ok(t)
    }

    /// This pose's estimator passes up to `last` (the skinned pipeline runs
    /// them all): the host positions set, a static mesh's topology made
    /// here if it is not yet.
    fn estimator_run(&mut self, frame: usize, last: CurvPass) -> Result<Timing> {
        if let Some(p) = self.stages.pipe.as_mut() {
            return p.curvature();
        }
        self.topology(frame)?;
        let fp = self.pose.frame_pos.take();
        let t = self.topo.as_mut().expect("made above");
        let est = t.est.as_mut().expect("planned with the one-rings");
        est.set_positions(fp.as_deref().unwrap_or(&t.mesh.positions))?;
        self.pose.frame_pos = fp;
        est.run_until(last)
    }

    /// Runs one topology or pose pass.
    pub(super) fn pose_pass(&mut self, pass: Pass, frame: usize) -> Result<()> {
        match pass {
            Pass::Isosurface => self.isosurface()?,
            Pass::Skinning => self.skin(frame)?,
            Pass::LoadFrame => {
                let Loaded::Flipbook(fb) = &self.loaded else {
                    unreachable!("planned for a flipbook input")
                };
                let t0 = Instant::now();
                let p = fb.frame(frame)?;
                self.rec.wall(pass, ms_since(t0), "read the frame file");
                self.pose.frame_pos = Some(p);
            }
            Pass::EdgeBuffer => self.edge_buffer(frame)?,
            Pass::OneRings => self.one_rings(frame)?,
            Pass::CapBuffer => self.rec.wall(
                pass,
                0.0,
                "pairs of edges sharing a vertex (built with the edge buffer; time counted there)",
            ),
            Pass::VertexNormals => self.vertex_normals(frame)?,
            Pass::FaceNormals => self.face_normals(frame)?,
            Pass::Curvature => {
                let t = self.curvature_run(frame)?;
                // What ran, as the options chose it.
                let o = self.stages.curv_opts;
                let normals = if self.stages.iso.is_some() {
                    "the volume's gradient"
                } else if self.stored_normals().is_some() {
                    "the file's"
                } else {
                    "computed"
                };
                let how = format!(
                    "tensor + principal (Rusinkiewicz; {} accumulation, {}, {} least squares, \
                     normals {normals})",
                    o.accumulate.name(),
                    o.precision.name(),
                    o.compat.name()
                );
                self.rec.kernels(pass, &t, &how);
            }
            Pass::Dcurv => {
                let t = self.curvature_run(frame)?;
                self.rec.kernels(pass, &t, "dcurv");
            }
            Pass::Ao => self.ao(frame)?,
            Pass::Bvh => self.bvh_pass(frame)?,
            Pass::Intersections => self.intersections_pass()?,
            Pass::SdfLines => self.sdf_lines()?,
            Pass::LinesPose => {
                // The curvature run of this pose makes the extractor's pose
                // terms stale: `lines_pose` runs again in the first view's
                // line launch, and only there (recorded by that view).
                if let Some(lx) = self.topo.as_mut().and_then(|t| t.lines.as_mut()) {
                    lx.pose_changed();
                }
            }
            Pass::Contours
            | Pass::SuggestiveContours
            | Pass::LinesView
            | Pass::LinesDt1q1
            | Pass::LinesCurves
            | Pass::ViewFields
            | Pass::Edges
            | Pass::Caps
            | Pass::Visibility
            | Pass::Render
            | Pass::Svg
            | Pass::Npz => {
                unreachable!("{pass:?} is a view pass")
            }
        }
        Ok(())
    }

    /// Linear blend skinning of this frame's joint matrices.
    fn skin(&mut self, frame: usize) -> Result<()> {
        let Loaded::Skinned { poses, .. } = &self.loaded else {
            unreachable!("planned for a skinned input")
        };
        let mats = poses(frame)?;
        let pipe = self
            .stages
            .pipe
            .as_mut()
            .expect("built for the skinning pass");
        let t = pipe.skin(&mats)?;
        self.rec
            .kernels(Pass::Skinning, &t, "skin_lbs (linear blend, ≤ 4 joints)");
        Ok(())
    }

    /// The edge buffer of this topology: unique edges with their opposite
    /// vertices (and the cap pairs, when planned), found on the host, and
    /// the edge stage built on them.
    fn edge_buffer(&mut self, frame: usize) -> Result<()> {
        let t0 = Instant::now();
        let caps = self.plan.contains(Pass::CapBuffer);
        let (marked, name) = match &self.scene.effects.edge_marked {
            Some(f) => (read_marked(f)?, f.display().to_string()),
            None => (Vec::new(), self.scene.path.display().to_string()),
        };
        let t = self.topology(frame)?;
        let et = if caps {
            EdgeTopology::new(&t.mesh, &marked, &name)?
        } else {
            EdgeTopology::without_caps(&t.mesh, &marked, &name)?
        };
        let t = self.topo.as_mut().expect("made above");
        t.edges = Some(EdgeStage::new(self.gpu.clone(), &t.mesh, &et)?);
        t.edge_pairs = et.edges.iter().map(|e| [e[0], e[1]]).collect();
        self.rec.wall(
            Pass::EdgeBuffer,
            ms_since(t0),
            "unique edges with opposite vertices (host), then the edge stage's buffers \
             (once per topology)",
        );
        t.edge_counts = Some(draw::EdgeCounts {
            edges: et.edges.len(),
            cap_pairs: et.caps.len(),
            boundary: et.boundary,
            non_manifold: et.non_manifold,
            marked: et.marked,
        });
        Ok(())
    }

    /// The pose to the edge stage, which computes face normals inside
    /// `edges_detect`.
    fn face_normals(&mut self, frame: usize) -> Result<()> {
        self.host_pose(frame)?;
        let t0 = Instant::now();
        let t = self.topo.as_mut().expect("made by the host copies");
        let es = t.edges.as_mut().expect("planned with the edge buffer");
        es.set_positions(&self.pose.host.pos, &self.pose.host.nrm)?;
        self.rec.wall(
            Pass::FaceNormals,
            ms_since(t0),
            "upload the pose to the edge stage; face normals are computed inside edges_detect",
        );
        Ok(())
    }

    /// Marching cubes + fusion: a new topology.
    fn isosurface(&mut self) -> Result<()> {
        let Loaded::Volume(v, iso_value, negated) = &self.loaded else {
            unreachable!("planned for a volume input")
        };
        let ex = self
            .stages
            .iso
            .as_mut()
            .expect("built for the isosurface pass");
        let s = ex.extract(*iso_value, crate::spec::vertex_fusion::Fusion::Direct)?;
        self.rec.kernels(
            Pass::Isosurface,
            &s.timing,
            "marching cubes with direct vertex numbering",
        );
        let (ipos, faces) = ex.read_index_space()?;
        let m = ex.world_mesh(&ipos, faces);
        // Shading without curvature: the volume's gradient gives the
        // normals (smoother than the faces' on marching cubes' chords).
        let gradient =
            self.plan.contains(Pass::VertexNormals) && !self.plan.contains(Pass::Curvature);
        self.pose.iso_normals = gradient.then(|| {
            crate::volume::gradient::gradient_normals(v, &ipos)
                .iter()
                .map(|n| n.map(|c| c as f32))
                .collect()
        });
        if m.n_faces() == 0 {
            return Err(Error::input(
                self.scene.path.display().to_string(),
                "[input]",
                {
                    let sign = if *negated { -1.0 } else { 1.0 };
                    let span = v.range().map(|(a, b)| {
                        let (a, b) = (sign * a, sign * b);
                        (a.min(b), a.max(b))
                    });
                    let span = span.map_or("no finite values".to_string(), |(a, b)| {
                        format!("the values span {a} to {b}")
                    });
                    format!(
                        "the isosurface at iso {} is empty ({span})",
                        sign * iso_value
                    )
                },
            ));
        }
        self.topo = Some(TopologyState::new(m));
        Ok(())
    }

    /// The curvature estimator's topology (owning faces), built once per
    /// topology; an isosurface's faces stay on the device and its estimator
    /// runs here, with normals from the volume gradient.
    fn one_rings(&mut self, frame: usize) -> Result<()> {
        // What the pass's wall time holds: the topology, and the program
        // only where it was built or loaded for this estimator.
        let how = |est: &CurvatureEstimator| {
            let build = est.build_ms();
            let program = if build >= 0.05 {
                format!(
                    "; includes {build:.1} ms getting the curvature program (built or from the cache)"
                )
            } else {
                String::new()
            };
            format!("one-ring lists or owning faces (atomic_max){program}")
        };
        if let Some(p) = &self.stages.pipe {
            let est = p.estimator().expect("built for the one-rings pass");
            let ms = est.topology_ms();
            self.rec
                .wall(Pass::OneRings, ms, &format!("upload faces, {}", how(est)));
            return Ok(());
        }
        if let Some(ex) = self.stages.iso.as_ref() {
            let (est, timing) = crate::stages::marching_cubes::curvature(
                ex,
                self.stages.curv_opts,
                IsoNormals::Gradient,
            )?;
            let faces = if self.stages.curv_opts.accumulate.scatters() {
                "faces copied on the device"
            } else {
                "faces read back once for the gather scheme's one-rings"
            };
            let how = format!("{faces}, {}", how(&est));
            self.rec.wall(Pass::OneRings, est.topology_ms(), &how);
            self.pose.curv = Some(timing);
            self.topo.as_mut().expect("made by the isosurface").est = Some(est);
            return Ok(());
        }
        let (gpu, opts) = (self.gpu.clone(), self.stages.curv_opts);
        let t = self.topology(frame)?;
        let mut est = CurvatureEstimator::new(gpu, t.mesh.n_vertices(), &t.mesh.faces, opts)?;
        let mut how = how(&est);
        if t.mesh.normals.is_some() {
            // A static mesh's stored normals (only those keep them): the
            // curvature starts from them, as trimesh2's does.
            est.set_stored_normals(t.mesh.normals.as_deref())?;
            how.push_str(", the normals the file stores uploaded");
        }
        let ms = est.topology_ms();
        t.est = Some(est);
        self.rec
            .wall(Pass::OneRings, ms, &format!("upload faces, {how}"));
        Ok(())
    }

    /// The normals the mesh file stores, where the scene's mesh is a static
    /// one that kept them ([`crate::mesh::NormalsSource::File`]).
    fn stored_normals(&self) -> Option<&[[f32; 3]]> {
        let t = self.topo.as_ref()?;
        match &self.loaded {
            Loaded::Static(..) => t.mesh.normals.as_deref(),
            _ => None,
        }
    }

    /// Vertex normals: from the curvature estimator where there is one,
    /// from the volume's gradient with an isosurface, else on the host.
    fn vertex_normals(&mut self, frame: usize) -> Result<()> {
        self.host_pose(frame)?;
        if self.est().is_some() {
            self.device_normals(frame)
        } else if let Some(n) = &self.pose.iso_normals {
            self.pose.host.nrm = n.clone();
            self.rec.wall(
                Pass::VertexNormals,
                0.0,
                "from the volume's gradient at the isosurface's vertices (with the isosurface)",
            );
            Ok(())
        } else {
            self.host_normals();
            Ok(())
        }
    }

    /// The estimator's normals (and curvature, where it is planned). Line
    /// families without curvature (isophotes, boundaries) run it up to its
    /// frames pass: the curvature's own normals, the same as with any other
    /// family, as rtsc's are.
    fn device_normals(&mut self, frame: usize) -> Result<()> {
        let curvature = self.plan.contains(Pass::Curvature);
        let t = if curvature {
            self.curvature_run(frame)?
        } else {
            self.estimator_run(frame, CurvPass::Frames)?
        };
        let f = self.est().expect("the caller checked it").read()?;
        self.pose.host.nrm = f.normals.iter().map(|p| p.map(|c| c as f32)).collect();
        if curvature {
            self.pose.host.k =
                f.k1.iter()
                    .zip(&f.k2)
                    .map(|(&a, &b)| [a as f32, b as f32])
                    .collect();
        }
        let normals = if self.stages.iso.is_some() {
            "then replaced by the volume's gradient"
        } else if self.stored_normals().is_some() {
            "then replaced by the normals the mesh file stores"
        } else if curvature {
            "curvature normals (area-weighted)"
        } else {
            "the curvature's normals; no curvature planned"
        };
        let how = format!("clear + normals_areas + frames ({normals})");
        self.rec.kernels(Pass::VertexNormals, &t, &how);
        Ok(())
    }

    /// Host normals where no estimator is planned: the file's at unit
    /// length, or area-weighted from the pose.
    fn host_normals(&mut self) {
        let t0 = Instant::now();
        let mesh = &self.topo.as_ref().expect("made by the host pose").mesh;
        let how = if let Some(n) = self.stored_normals() {
            // A stored normal without a direction (copies that cancel where
            // welding summed them) takes the faces' there, as on the device.
            let mut computed: Option<Vec<[f32; 3]>> = None;
            self.pose.host.nrm = (n.iter().enumerate())
                .map(|(i, &v)| match unit(v) {
                    Some(u) => u,
                    None => computed.get_or_insert_with(|| vertex_normals(mesh))[i],
                })
                .collect();
            "the normals the mesh file stores, at unit length (no curvature planned)"
        } else {
            let m = Mesh {
                positions: (self.pose.host.pos.iter())
                    .map(|p| p.map(f64::from))
                    .collect(),
                faces: mesh.faces.clone(),
                normals: None,
            };
            self.pose.host.nrm = vertex_normals(&m);
            "area-weighted, host (no curvature planned)"
        };
        self.rec.wall(Pass::VertexNormals, ms_since(t0), how);
    }

    /// Ambient occlusion from the pose's curvatures.
    fn ao(&mut self, frame: usize) -> Result<()> {
        self.host_pose(frame)?;
        let radius = self
            .run
            .framing
            .as_ref()
            .expect("made by the host copies")
            .ao_radius;
        let mode = self.scene.effects.ao_mode;
        let t = match self.stages.pipe.as_mut() {
            Some(p) => {
                p.set_ao_radius(radius);
                let t = p.run_ao(mode)?;
                self.pose.host.ao = p.read_ao()?;
                t
            }
            None => {
                let est = self.topo.as_ref().and_then(|t| t.est.as_ref());
                let est = est.expect("planned with curvature");
                let ao = self.stages.ao.as_mut().expect("built for the AO pass");
                let t = Timing::of(Step::AoVertex, ao.run_device(est, radius, mode)?);
                self.pose.host.ao = ao.read(self.pose.host.pos.len())?;
                t
            }
        };
        self.rec
            .kernels(Pass::Ao, &t, &format!("ao_vertex, level {mode}"));
        Ok(())
    }

    /// Curvature-directed strokes of this pose, traced on the volume.
    fn sdf_lines(&mut self) -> Result<()> {
        let (stage, _) = self
            .stages
            .sdf_lines
            .as_mut()
            .expect("built for the strokes pass");
        let out = stage.run()?;
        let st = &out.stats;
        let t = st.timing.clone();
        let h = st.params.map_or(0.0, |p| p.sampling);
        let r = st.params.map_or(0.0, |p| p.spacing);
        let how = format!(
            "{} surface samples → {} Poisson-disk seeds (r = {r:.4}), {} strokes, {} segments; \
             Hessian sampling distance {h:.4} ({})",
            st.dense,
            st.seeds,
            st.strokes,
            st.segments,
            if st.sweep.is_empty() {
                "fixed"
            } else {
                "automatic: coefficient of variation of κ1 closest to 1"
            }
        );
        self.rec.kernels(Pass::SdfLines, &t, &how);
        self.run.stroke_count += out.strokes.len();
        self.pose.strokes = out;
        Ok(())
    }
}

/// `v` at unit length, or `None` where it has no direction.
fn unit(v: [f32; 3]) -> Option<[f32; 3]> {
    let l = v.iter().map(|c| c * c).sum::<f32>().sqrt();
    (l.is_finite() && l > 0.0).then(|| v.map(|c| c / l))
}
