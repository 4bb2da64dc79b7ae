//! The view passes: contours and suggestive contours, feature edges with
//! their caps, and the render pass, run once per frame and camera. Each arm
//! runs because its pass is in the plan.

use super::*;

impl Executor<'_, '_> {
    /// Starts a view.
    pub(in crate::scene::exec) fn begin_view(&mut self) {
        self.segs.clear();
        self.lines_ran = None;
        self.edges_ran = None;
        self.shared_drawn = None;
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
                let shared = self.lines_ran.is_some();
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
            Pass::LinesCurves => {
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
                let contours = self.plan.contains(Pass::Contours)
                    || self.plan.contains(Pass::SuggestiveContours);
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
            }
            Pass::Edges => {
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
                let shared = (self.interop.as_ref()).is_some_and(|(d, _)| d.shared);
                let svg = self.keep_layers
                    || paths
                        .iter()
                        .any(|p| p.extension().is_none_or(|e| e != "png"));
                let t = self.topo.as_mut().expect("a pose ran");
                let es = t.edges.as_mut().expect("planned with the edge buffer");
                let timing = es.run(&p, fx.caps)?;
                let out = if shared {
                    // Compacted into memory GL draws from; only the kinds
                    // (and the quads for an SVG) come back.
                    let sh = match &mut t.shared {
                        Some(sh) => sh,
                        None => t.shared.insert(SharedEdges::new(
                            self.gpu,
                            &mut self.renderer,
                            es,
                            fx.caps,
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
                    self.shared_drawn = Some(d);
                    out
                } else {
                    // Only what was drawn comes back, compacted on the device.
                    es.read_drawn()?
                };
                self.rec.kernels(
                    pass,
                    &timing,
                    "edges_detect (contour, crease, boundary) into edge-out",
                );
                self.edges_ran = Some((timing, out));
            }
            Pass::Caps => {
                let (timing, _) = self.edges_ran.as_ref().expect("planned after the edges");
                let how = format!("caps_{}", self.scene.effects.caps.name());
                self.rec.kernels(pass, timing, &how);
            }
            Pass::Render => {
                let t0 = Instant::now();
                let t = self.topo.as_ref().expect("a pose ran");
                // The mesh goes to GL once per topology (faces) and once per
                // pose (positions, normals, colours), not once per view.
                if !self.gl_topology {
                    self.renderer.upload_topology(&t.mesh.faces)?;
                    self.gl_topology = true;
                }
                if !self.gl_pose {
                    let colors = draw::mesh_colors(
                        self.scene,
                        self.plan,
                        &self.pose,
                        self.color_scale.unwrap_or(1.0),
                    );
                    self.renderer
                        .upload_pose(&self.pose.pos, &self.pose.nrm, &colors)?;
                    self.gl_pose = true;
                }
                let strokes = self.scene_strokes();
                let shared = (t.shared.as_ref()).zip(self.shared_drawn.as_ref());
                let lines = ViewLines {
                    segments: &self.segs,
                    edges: self.edges_ran.as_ref().map(|e| &e.1),
                    shared,
                    strokes: &strokes,
                    // Half a voxel towards the eye: the strokes lie on the
                    // interpolated surface, which marching cubes cuts as chords.
                    stroke_lift: self.sdf_lines.as_ref().map_or(0.0, |s| 0.5 * s.1) as f32,
                };
                let want_layers = self.keep_image && self.keep_layers;
                let d = draw::draw_view(
                    &mut self.renderer,
                    self.scene,
                    self.plan,
                    cam,
                    lines,
                    paths,
                    want_layers,
                )?;
                let drawn = d.segments;
                if self.keep_image {
                    self.kept = Some(self.kept_view(cam, d));
                }
                self.rec.wall(
                    pass,
                    ms_since(t0),
                    "draw mesh, line quads, edge quads and stroke strips; read back",
                );
                self.segments[0] += drawn[0];
                self.segments[1] += drawn[1];
                let fx = &self.scene.effects;
                for st in &fx.lines.styles_for(&fx.cues) {
                    let kind = st.family as u32;
                    let n = self.segs.iter().filter(|s| s.2 == kind).count();
                    *self.line_segments.entry(st.family.name()).or_default() += n;
                }
                self.outputs.extend(paths.iter().map(|p| (*p).clone()));
            }
            _ => unreachable!("{pass:?} is not a view pass"),
        }
        Ok(())
    }

    /// What a view drawn into memory hands its caller: the image, the SVG
    /// groups, the segments (world coordinates), the edge stage's outputs,
    /// the strokes, the camera (world coordinates) and the kernel time of
    /// the pose and the view.
    fn kept_view(&self, cam: &Camera, d: draw::DrawnView) -> draw::ViewOutputs {
        let o = self.framing.as_ref().map_or([0.0; 3], |f| f.origin);
        let world =
            |p: [f32; 3]| -> [f32; 3] { std::array::from_fn(|i| (f64::from(p[i]) + o[i]) as f32) };
        let mut timing = self.curv.clone().unwrap_or_default();
        for t in [
            &self.lines_ran,
            &self.edges_ran.as_ref().map(|e| e.0.clone()),
        ]
        .into_iter()
        .flatten()
        {
            timing.extend(t);
        }
        let topo = self.topo.as_ref();
        draw::ViewOutputs {
            image: d.image,
            layers: d.layers,
            segments: (self.segs.iter())
                .map(|s| (world(s.0), world(s.1), s.2, s.3, s.4))
                .collect(),
            edges: self.edges_ran.as_ref().map(|e| e.1.clone()),
            strokes: self.strokes.clone(),
            camera: *cam,
            origin: o,
            mesh: topo.filter(|_| self.keep_mesh).map(|t| t.mesh.clone()),
            edge_info: self
                .interop
                .as_ref()
                .map(|(decision, offer)| draw::EdgeInfo {
                    counts: topo.and_then(|t| t.edge_counts).unwrap_or_default(),
                    decision: decision.clone(),
                    offer: offer.clone(),
                    drawn_caps: match (&self.shared_drawn, &self.edges_ran) {
                        (Some(d), _) => d.adjacency_caps,
                        (None, Some((_, out))) => out.cap_adj.len() / 4,
                        (None, None) => 0,
                    },
                }),
            uploads: self.renderer.uploads(),
            feature_size: topo.and_then(|t| t.feature_size),
            timing,
        }
    }

    /// Contours, suggestive contours and the curvature line families of
    /// this view, found once per view (one extraction finds them all): on
    /// the device from the curvature buffers, or from host normals when no
    /// curvature is planned (contours, isophotes, boundaries).
    fn lines(&mut self, cam: &Camera) -> Result<Timing> {
        if let Some(t) = &self.lines_ran {
            return Ok(t.clone());
        }
        let [w, h] = self.scene.size;
        let v = cam.view(w, h);
        let origin = self.framing.as_ref().map_or([0.0; 3], |f| f.origin);
        let opts = self.line_opts;
        let Topology {
            mesh,
            feature_size,
            est,
            lines,
            ..
        } = self.topo.as_mut().expect("a pose ran");
        let est = match &self.pipe {
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
        let feature_size = match *feature_size {
            Some(fs) => fs,
            None => {
                // Once per topology: rtsc's size reads the curvature of the
                // first pose (world units) at its 500 sampled vertices, in
                // place on the device; else the median edge length.
                let field = match est {
                    Some(e) if self.plan.contains(Pass::Curvature) => Some(e.mapped(None)?),
                    _ => None,
                };
                let at = |i: usize| {
                    let v = field.as_ref().expect("read only with a field").vertex(i);
                    [v.k1, v.k2]
                };
                let k: Option<&dyn Fn(usize) -> [f64; 2]> = field.as_ref().map(|_| &at as _);
                let fs = crate::mesh::feature_size::resolve(
                    self.scene.effects.feature_size,
                    &mesh.positions,
                    &mesh.faces,
                    k,
                ) as f32;
                let read_curvature = k.is_some();
                drop(field);
                *feature_size = Some(fs);
                if self.feature_size_note.is_none() {
                    use crate::spec::feature_lines::FeatureSize;
                    let how = match self.scene.effects.feature_size {
                        FeatureSize::Rtsc if read_curvature => {
                            "rtsc's, from the first pose's curvature"
                        }
                        FeatureSize::Rtsc => "the median edge length: no curvature is planned",
                        FeatureSize::Edge => "the median edge length",
                        FeatureSize::Value(_) => "as given",
                    };
                    self.feature_size_note = Some(format!(
                        "line thresholds scaled by the feature size {fs:.4e} ({how})"
                    ));
                }
                fs
            }
        };
        let (s, stats) = match est {
            Some(est) => lx.extract_device_at(est, v, feature_size, opts, origin)?,
            None => {
                let n = self.pose.pos.len();
                let z3 = vec![[0f32; 3]; n];
                let x = LineInputs {
                    pos: &self.pose.pos,
                    nrm: &self.pose.nrm,
                    d1: &z3,
                    d2: &z3,
                    k: &vec![[0f32; 2]; n],
                    dk: &vec![[0f32; 4]; n],
                };
                lx.extract(&x, v, feature_size, opts)?
            }
        };
        self.segs = s;
        self.lines_ran = Some(stats.timing.clone());
        Ok(stats.timing)
    }
}
