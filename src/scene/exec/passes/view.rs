//! The view passes: contours and suggestive contours, feature edges with
//! their caps, and the render pass, run once per frame and camera. Each arm
//! runs because its pass is in the plan. Also what the views need of the
//! run: their cameras, the edges frame's route to GL and the strokes in the
//! scene frame.

use super::*;

impl Executor<'_, '_> {
    /// The camera of a view resolved as the first pose resolved the
    /// scene's own (same origin, same bounds for a fitted view).
    pub(in crate::scene::exec) fn camera_of(
        &self,
        v: &crate::scene::file::ViewSpec,
    ) -> Result<Camera> {
        let f = self.run.framing.as_ref().expect("a pose ran");
        let [w, h] = self.scene.size;
        draw::camera(v, f.bounds, w as f32 / h as f32, f.origin)
    }

    /// The cameras fixed by the first pose.
    pub(in crate::scene::exec) fn cameras(&self) -> Vec<Camera> {
        self.run
            .framing
            .as_ref()
            .map(|f| f.cameras.clone())
            .unwrap_or_default()
    }

    /// Starts a view.
    pub(in crate::scene::exec) fn begin_view(&mut self) {
        self.view = super::ViewState::default();
    }

    /// Runs one view pass from `cam`; the render pass writes `paths`.
    pub(in crate::scene::exec) fn view_pass(
        &mut self,
        pass: Pass,
        cam: &Camera,
        paths: &[&PathBuf],
    ) -> Result<()> {
        match pass {
            Pass::Contours => {
                let t = self.lines(cam)?;
                self.rec.kernels(
                    pass,
                    &t,
                    "lines_vertex + lines_face (zero crossings of n·v)",
                );
            }
            Pass::SuggestiveContours => {
                let shared = self.view.lines_ran.is_some();
                let t = self.lines(cam)?;
                if shared {
                    self.rec.shared(
                        pass,
                        "in the same lines_vertex + lines_face launch as the contours (time counted there)",
                    );
                } else {
                    self.rec.kernels(
                        pass,
                        &t,
                        "lines_vertex + lines_face (zero crossings of κr with D_w κr > 0)",
                    );
                }
            }
            Pass::LinesView | Pass::LinesDt1q1 => {
                let t = self.lines(cam)?;
                let how = if pass == Pass::LinesView {
                    "lines_view (view-dependent curvature q1 and t1, highlight terms, n·l)"
                } else {
                    "lines_dt1q1 (derivative of q1 along t1)"
                };
                self.rec.kernels(pass, &t, how);
            }
            Pass::LinesCurves => self.line_curves_pass(pass, cam)?,
            Pass::ViewFields => self.view_fields_pass(cam)?,
            Pass::Edges => self.edges_pass(pass, cam, paths)?,
            Pass::Caps => {
                let (timing, _) = self
                    .view
                    .edges_ran
                    .as_ref()
                    .expect("planned after the edges");
                let how = format!("caps_{}", self.scene.effects.caps.name());
                self.rec.kernels(pass, timing, &how);
            }
            Pass::Visibility => self.visibility_pass(cam)?,
            Pass::Render => self.render_pass(pass, cam, paths)?,
            Pass::Svg => self.svg_pass(cam, paths)?,
            Pass::Npz => self.npz_pass(paths)?,
            _ => unreachable!("{pass:?} is not a view pass"),
        }
        Ok(())
    }

    /// The curvature line families of this view (and the pose terms, when
    /// they ran in its launch).
    fn line_curves_pass(&mut self, pass: Pass, cam: &Camera) -> Result<()> {
        let t = self.lines(cam)?;
        // The pose terms run in the first view's launch after a
        // curvature run: recorded where they ran, once per pose.
        if t.ran(Pass::LinesPose.kernels()) {
            self.rec.kernels(
                Pass::LinesPose,
                &t,
                "lines_pose (larger principal curvature, its derivative, K, H), \
                 launched with the pose's first view",
            );
        }
        let fx = &self.scene.effects;
        let families: Vec<&str> = (fx.lines.styles_for(&fx.cues).iter())
            .map(|s| s.family.name())
            .collect();
        let contours =
            self.plan.contains(Pass::Contours) || self.plan.contains(Pass::SuggestiveContours);
        if contours {
            let how = format!(
                "lines_curves ({}); lines_vertex counted with the contours",
                families.join(", ")
            );
            self.rec.kernels_of(pass, &t, &[Step::LinesCurves], &how);
        } else {
            let how = format!("lines_vertex + lines_curves ({})", families.join(", "));
            self.rec.kernels(pass, &t, &how);
        }
        Ok(())
    }

    /// The view's per-vertex fields, read back from the line passes' terms
    /// (which kept them: the extraction of this view ran `lines_view` for
    /// q1 if its families did not).
    fn view_fields_pass(&mut self, cam: &Camera) -> Result<()> {
        self.lines(cam)?;
        let t0 = std::time::Instant::now();
        let lx = (self.topo.as_ref())
            .and_then(|t| t.lines.as_ref())
            .expect("the lines ran");
        self.view.fields = Some(lx.read_view_fields()?);
        self.rec.wall(
            Pass::ViewFields,
            ms_since(t0),
            "n·v, κr, D_w κr and q1 per vertex read back",
        );
        Ok(())
    }

    /// The feature edges of this view: the edge stage runs, then what is
    /// drawn reaches GL through the shared buffer or comes back compacted.
    fn edges_pass(&mut self, pass: Pass, cam: &Camera, paths: &[&PathBuf]) -> Result<()> {
        let p = self.edge_params(cam)?;
        let caps = self.caps();
        // The external-memory route draws from the shared buffer (CL-GL
        // sharing is not built: `GL_SHARING_BUILT`).
        let shared = (self.stages.interop.as_ref())
            .is_some_and(|(d, _)| d.route == InteropRoute::ExternalMemory);
        let svg = self.keep.layers
            || paths
                .iter()
                .any(|p| p.extension().is_none_or(|e| e != "png"));
        let t = self.topo.as_mut().expect("a pose ran");
        let es = t.edges.as_mut().expect("planned with the edge buffer");
        let timing = es.run(&p, caps)?;
        let out = if shared {
            self.compact_shared(svg)?
        } else {
            // Only what was drawn comes back, compacted on the device.
            es.read_drawn()?
        };
        self.rec.kernels(
            pass,
            &timing,
            "edges_detect (contour, crease, boundary) into edge-out",
        );
        self.view.edges_ran = Some((timing, out));
        Ok(())
    }

    /// The cap variant drawn: the scene's, where the plan draws caps (a
    /// frame is drawn; an SVG's polylines need none).
    fn caps(&self) -> crate::spec::edges::CapMode {
        match self.plan.contains(Pass::Caps) {
            true => self.scene.effects.caps,
            false => crate::spec::edges::CapMode::None,
        }
    }

    /// The edge stage's parameters for `cam`, from the scene's effects.
    fn edge_params(&self, cam: &Camera) -> Result<EdgeParams> {
        let fx = &self.scene.effects;
        let [w, h] = self.scene.size;
        let mut p = EdgeParams::new(cam.view(w, h));
        p.line_width = fx.edge.0;
        p.crease_deg = fx.crease;
        p.contours = fx.edge_contours;
        p.boundaries = fx.edge_boundaries;
        p.depth_scale = fx.edge_depth_scale;
        p.half_contours = fx.edge_half_contours;
        p.pack()?;
        Ok(p)
    }

    /// The edges compacted into memory GL draws from (the shared buffer,
    /// made by the first view); only the kinds (and the quads for an SVG)
    /// come back.
    fn compact_shared(&mut self, svg: bool) -> Result<EdgeOutput> {
        let caps = self.caps();
        let t = self.topo.as_mut().expect("a pose ran");
        let es = t.edges.as_mut().expect("planned with the edge buffer");
        let sh = match &mut t.shared {
            Some(sh) => sh,
            None => t.shared.insert(SharedEdges::new(
                self.gpu,
                self.renderer
                    .as_mut()
                    .expect("the external-memory route is taken only where a frame is drawn"),
                es,
                caps,
            )?),
        };
        let d = sh.compact(self.gpu, es)?;
        let mut out = EdgeOutput {
            kind: d.kind.clone(),
            ..EdgeOutput::default()
        };
        if svg {
            out.edge_out = sh.read_edges(self.gpu, &d)?;
        }
        self.view.shared_drawn = Some(d);
        Ok(out)
    }

    /// The render pass: draws the view and writes its PNG `paths`; the
    /// frame is kept (with its depth where the SVG's hidden lines come from
    /// it) for the SVG pass and the caller.
    fn render_pass(&mut self, pass: Pass, cam: &Camera, paths: &[&PathBuf]) -> Result<()> {
        let t0 = Instant::now();
        self.upload_mesh()?;
        let pngs: Vec<&PathBuf> = paths.iter().copied().filter(|p| draw::is_png(p)).collect();
        let depth = self.plan.contains(Pass::Svg)
            && !self.plan.contains(Pass::Visibility)
            && (pngs.len() < paths.len() || self.keep.layers);
        let frame = self.draw(cam, &pngs, depth)?;
        self.rec.wall(
            pass,
            ms_since(t0),
            "draw mesh, line quads, edge quads and stroke strips; read back",
        );
        self.run.outputs.extend(pngs.into_iter().cloned());
        self.view.frame = Some(frame);
        Ok(())
    }

    /// Ends a view: counts its segments, and keeps its outputs when asked.
    pub(in crate::scene::exec) fn end_view(&mut self, cam: &Camera) {
        self.count_segments();
        // A plan with nothing to draw or write keeps nothing: the caller
        // says there is nothing to draw.
        let drawn = self.plan.contains(Pass::Render) || self.plan.contains(Pass::Svg);
        if self.keep.image && drawn {
            self.kept = Some(self.kept_view(cam));
        }
    }

    /// The mesh to GL once per topology (faces) and once per pose
    /// (positions, normals, colours), not once per view.
    fn upload_mesh(&mut self) -> Result<()> {
        let t = self.topo.as_mut().expect("a pose ran");
        let r = self
            .renderer
            .as_mut()
            .expect("a renderer is made where the plan draws a frame");
        if !t.gl {
            r.upload_topology(&t.mesh.faces)?;
            t.gl = true;
        }
        if !self.pose.gl {
            let colors = draw::mesh_colors(
                self.scene,
                self.plan,
                &self.pose.host,
                self.run.color_scale.unwrap_or(1.0),
            );
            r.upload_pose(&self.pose.host.pos, &self.pose.host.nrm, &colors)?;
            self.pose.gl = true;
        }
        Ok(())
    }

    /// Draws the view's mesh, lines, edges and strokes from `cam`, writes
    /// the PNG `paths` ([`draw::draw_view`]) and returns the frame (with its
    /// depth when `depth`).
    fn draw(
        &mut self,
        cam: &Camera,
        paths: &[&PathBuf],
        depth: bool,
    ) -> Result<crate::render::Frame> {
        let strokes = self.scene_strokes();
        let t = self.topo.as_ref().expect("a pose ran");
        let lines = ViewLines {
            segments: &self.view.segs,
            intersections: &self.pose.isect_segs,
            edges: self.view.edges_ran.as_ref().map(|e| &e.1),
            shared: (t.shared.as_ref()).zip(self.view.shared_drawn.as_ref()),
            strokes: &strokes,
            stroke_lift: self.stroke_lift(),
        };
        let r = (self.renderer.as_mut()).expect("a renderer is made where the plan draws a frame");
        draw::draw_view(r, self.scene, self.plan, cam, lines, paths, depth)
    }

    /// What the view draws on top of the mesh, with `strokes` in the scene
    /// frame.
    pub(super) fn view_lines<'a>(&'a self, strokes: &'a [Stroke]) -> ViewLines<'a> {
        let t = self.topo.as_ref().expect("a pose ran");
        ViewLines {
            segments: &self.view.segs,
            intersections: &self.pose.isect_segs,
            edges: self.view.edges_ran.as_ref().map(|e| &e.1),
            shared: (t.shared.as_ref()).zip(self.view.shared_drawn.as_ref()),
            strokes,
            stroke_lift: self.stroke_lift(),
        }
    }

    /// The strokes' lift towards the eye: half a voxel (they lie on the
    /// interpolated surface, which marching cubes cuts as chords).
    pub(super) fn stroke_lift(&self) -> f32 {
        self.stages.sdf_lines.as_ref().map_or(0.0, |s| 0.5 * s.1) as f32
    }

    /// Adds the view's contour and suggestive-contour segments, and its
    /// segments of each curvature line family, to the run's counts (drawn
    /// segments: none of no strength).
    fn count_segments(&mut self) {
        for (k, n) in self.run.segments.iter_mut().enumerate() {
            *n += (self.view.segs.iter())
                .filter(|s| s.family == k as u32 && draw::shown(s))
                .count();
        }
        let fx = &self.scene.effects;
        for st in &fx.lines.styles_for(&fx.cues) {
            let kind = st.family as u32;
            let n = (self.view.segs.iter())
                .filter(|s| s.family == kind && draw::shown(s))
                .count();
            *self.run.line_segments.entry(st.family.name()).or_default() += n;
        }
        if let Some(v) = &self.view.vis {
            let visible = v.chains.iter().filter(|c| c.visible);
            self.run.chains[0] += visible.clone().count();
            self.run.chains[1] += visible.map(|c| c.pieces.len()).sum::<usize>();
        }
    }

    /// The strokes in the scene frame (world minus the scene origin).
    pub(super) fn scene_strokes(&self) -> Vec<Stroke> {
        let o = self.run.framing.as_ref().map_or([0.0; 3], |f| f.origin);
        let local = |p: &[f64; 3]| -> [f64; 3] { std::array::from_fn(|i| p[i] - o[i]) };
        (self.pose.strokes.strokes.iter())
            .map(|s| Stroke {
                points: s.points.iter().map(local).collect(),
                strip: s.strip.iter().map(local).collect(),
                ..s.clone()
            })
            .collect()
    }

    /// What a run hands its caller after the view of `frame` and `view`
    /// from `cam` that wrote `files`: what was found and drawn for it
    /// (world coordinates; the image and SVG groups where the caller keeps
    /// them), and the passes that ran for it.
    pub(in crate::scene::exec) fn view_done(
        &mut self,
        (frame, view): (usize, usize),
        cam: &Camera,
        files: Vec<PathBuf>,
    ) -> draw::ViewDone {
        draw::ViewDone {
            frame,
            view,
            out: self.kept_view(cam),
            passes: self.rec.take_recent(self.plan),
            files,
        }
    }

    /// What a view drawn into memory hands its caller: the image, the SVG
    /// groups, the segments (world coordinates), the edge stage's outputs,
    /// the strokes, the camera (world coordinates) and the kernel time of
    /// the pose and the view.
    fn kept_view(&mut self, cam: &Camera) -> draw::ViewOutputs {
        let o = self.run.framing.as_ref().map_or([0.0; 3], |f| f.origin);
        let world =
            |p: [f32; 3]| -> [f32; 3] { std::array::from_fn(|i| (f64::from(p[i]) + o[i]) as f32) };
        let mut timing = self.pose.curv.clone().unwrap_or_default();
        for t in [
            &self.view.lines_ran,
            &self.view.edges_ran.as_ref().map(|e| e.0.clone()),
        ]
        .into_iter()
        .flatten()
        {
            timing.extend(t);
        }
        let topo = self.topo.as_ref();
        draw::ViewOutputs {
            image: self.view.frame.take(),
            layers: self.view.layers.take(),
            visible: self.view.vis.as_ref().map(|v| v.shifted(o)),
            fields: self.view.fields.take(),
            npz: self.view.npz.take(),
            segments: (self.view.segs.iter())
                .map(|s| crate::spec::feature_lines::Segment {
                    a: world(s.a),
                    b: world(s.b),
                    ..*s
                })
                .collect(),
            edges: self.view.edges_ran.as_ref().map(|e| e.1.clone()),
            strokes: self.pose.strokes.clone(),
            camera: *cam,
            origin: o,
            mesh: topo.filter(|_| self.keep.mesh).map(|t| t.mesh.clone()),
            edge_info: self
                .stages
                .interop
                .as_ref()
                .map(|(decision, offer)| draw::EdgeInfo {
                    counts: topo.and_then(|t| t.edge_counts).unwrap_or_default(),
                    decision: decision.clone(),
                    offer: offer.clone(),
                    drawn_caps: match (&self.view.shared_drawn, &self.view.edges_ran) {
                        (Some(d), _) => d.adjacency_caps,
                        (None, Some((_, out))) => out.cap_adj.len() / 4,
                        (None, None) => 0,
                    },
                }),
            uploads: self.uploads(),
            feature_size: topo.and_then(|t| t.feature_size),
            timing,
        }
    }

    /// Contours, suggestive contours and the curvature line families of
    /// this view, found once per view (one extraction finds them all): on
    /// the device from the curvature buffers, or from host normals when no
    /// curvature is planned (contours, isophotes, boundaries).
    fn lines(&mut self, cam: &Camera) -> Result<Timing> {
        if let Some(t) = &self.view.lines_ran {
            return Ok(t.clone());
        }
        let [w, h] = self.scene.size;
        let v = cam.view(w, h);
        let origin = self.run.framing.as_ref().map_or([0.0; 3], |f| f.origin);
        let opts = self.stages.line_opts;
        let TopologyState {
            mesh,
            feature_size,
            est,
            lines,
            ..
        } = self.topo.as_mut().expect("a pose ran");
        let est = match &self.stages.pipe {
            Some(p) => p.estimator(),
            None => est.as_ref(),
        };
        let lx = match lines {
            Some(lx) => lx,
            None => lines.insert(LineExtractor::new(
                self.gpu.clone(),
                mesh.n_vertices(),
                &mesh.faces,
            )?),
        };
        lx.keep_view_fields(self.plan.contains(Pass::ViewFields));
        lx.hold_at(self.hold)?;
        if let Some(h) = self.hold {
            self.run.held_low = Some(h.low);
        }
        let feature_size = match *feature_size {
            Some(fs) => fs,
            None => {
                let fs = resolve_feature_size(
                    self.scene,
                    self.plan,
                    mesh,
                    est,
                    &mut self.run.feature_size_note,
                )?;
                *feature_size = Some(fs);
                fs
            }
        };
        let (s, stats) = match est {
            Some(est) => lx.extract_device_at(est, v, feature_size, opts, origin)?,
            None => {
                let n = self.pose.host.pos.len();
                let z3 = vec![[0f32; 3]; n];
                let x = LineInputs {
                    pos: &self.pose.host.pos,
                    nrm: &self.pose.host.nrm,
                    d1: &z3,
                    d2: &z3,
                    k: &vec![[0f32; 2]; n],
                    dk: &vec![[0f32; 4]; n],
                };
                lx.extract(&x, v, feature_size, opts)?
            }
        };
        self.view.segs = s;
        self.view.lines_ran = Some(stats.timing.clone());
        Ok(stats.timing)
    }
}

/// The feature size of a topology, found once by its first view: rtsc's
/// size reads the curvature of the first pose (world units) at its 500
/// sampled vertices, in place on the device; else the median edge length.
/// The first topology's also goes to `note`, for the run's notes.
fn resolve_feature_size(
    scene: &Scene,
    plan: &Plan,
    mesh: &Mesh,
    est: Option<&CurvatureEstimator>,
    note: &mut Option<String>,
) -> Result<f32> {
    let size = scene.effects.feature_size;
    let (fs, read_curvature) = match est {
        Some(e) if plan.contains(Pass::Curvature) => {
            (e.feature_size(size, &mesh.positions, &mesh.faces)?, true)
        }
        _ => {
            let fs = crate::mesh::feature_size::resolve(size, &mesh.positions, &mesh.faces, None);
            (fs, false)
        }
    };
    let fs = fs as f32;
    if note.is_none() {
        use crate::spec::feature_lines::FeatureSize;
        let how = match scene.effects.feature_size {
            FeatureSize::Rtsc if read_curvature => "rtsc's, from the first pose's curvature",
            FeatureSize::Rtsc => "the median edge length: no curvature is planned",
            FeatureSize::Edge => "the median edge length",
            FeatureSize::Value(_) => "as given",
        };
        *note = Some(format!(
            "line thresholds scaled by the feature size {fs:.4e} ({how})"
        ));
    }
    Ok(fs)
}

/// The route of the edges frame's buffers to GL, decided once per run from
/// the scene's mode and what the device, GL and Vulkan offer. An
/// isosurface's topology changes every pose, so it always reads back; a
/// plan that draws no frame (`drawn` false: an SVG with exact visibility)
/// has no GL to share with.
pub(super) fn decide(
    gpu: &Gpu,
    scene: &Scene,
    drawn: bool,
) -> Result<(InteropDecision, InteropOffer)> {
    const ISO: &str = "an isosurface's topology changes every pose, so its edges read back";
    const UNDRAWN: &str = "no frame is drawn (an SVG with exact visibility needs no GL), \
                           so the edges read back";
    let why = match (scene.source.input(), drawn) {
        (crate::scene::planner::Input::Volume, _) => Some(ISO),
        (_, false) => Some(UNDRAWN),
        _ => None,
    };
    if let Some(why) = why {
        // Nothing a probe could answer changes the route: no GL context
        // or Vulkan instance is made for it.
        if scene.interop == crate::spec::interop::InteropMode::On {
            return Err(crate::error::Error::gl_sharing_required(
                &gpu.info.name,
                why,
            ));
        }
        let offer = InteropOffer {
            device: gpu.info.name.clone(),
            ..InteropOffer::default()
        };
        let d = InteropDecision {
            route: InteropRoute::Host,
            shared: false,
            reason: format!("host path: {why}"),
            passed_over: Vec::new(),
        };
        return Ok((d, offer));
    }
    let offer = interop_offer(gpu, scene.interop);
    Ok((decide_interop(scene.interop, &offer)?, offer))
}
