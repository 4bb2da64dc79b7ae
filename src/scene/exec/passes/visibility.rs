//! The passes of a vector drawing: the BVH per pose, exact visibility of
//! the view's lines, and the SVG of the view (its hidden lines from the
//! visibility pass, or from the rendered depth).

use super::super::vector::{classify_view, gather, stroke_segments, svg_layers_exact};
use super::*;
use crate::scene::exec::load::Loaded;
use crate::spec::intersections::IntersectionOptions;

impl Executor<'_, '_> {
    /// The BVH of this pose's mesh: built when its topology first appears,
    /// refitted to later poses (same faces, new positions).
    pub(super) fn bvh_pass(&mut self, frame: usize) -> Result<()> {
        self.host_pose(frame)?;
        let t = self.topo.as_mut().expect("made by the host copies");
        let how = match &mut t.bvh {
            Some(b) => {
                b.refit(&self.pose.host.pos)?;
                "bvh_refit (boxes of the same tree to this pose)"
            }
            None => {
                let mut b = Bvh::new(self.gpu.clone(), t.mesh.n_vertices(), &t.mesh.faces)?;
                b.build(&self.pose.host.pos)?;
                t.bvh = Some(b);
                "bvh_morton, radix sort, bvh_build, bvh_refit (a new topology: Karras's tree)"
            }
        };
        let timing = t.bvh.as_ref().expect("made above").timing().clone();
        self.rec.kernels(Pass::Bvh, &timing, how);
        Ok(())
    }

    /// The intersection lines of this pose: the faces that cross, over the
    /// BVH (scene frame), as segments of the intersection layer whose ends
    /// lie in their two faces.
    pub(super) fn intersections_pass(&mut self) -> Result<()> {
        use crate::spec::feature_lines::LINE_FREE;
        use crate::stages::intersections::Intersections;
        // Several files drawn as one: only faces of different files cross.
        let opts = match &self.loaded {
            Loaded::Static(_, counts) if !counts.is_empty() => {
                IntersectionOptions::by_input(counts)
            }
            _ => IntersectionOptions::default(),
        };
        let t = self.topo.as_mut().expect("a pose ran");
        let bvh = t.bvh.as_ref().expect("planned after the BVH");
        let search = match &mut t.isect {
            Some(s) => s,
            None => t.isect.insert(Intersections::new(
                self.gpu.clone(),
                t.mesh.n_faces(),
                &opts,
            )?),
        };
        let (segs, stats) = search.find(bvh)?;
        let layer = super::super::vector::LAYER_INTERSECTIONS;
        self.pose.isect_segs = (segs.iter())
            .map(|s| {
                let ends = [[LINE_FREE, s.faces[0]], [LINE_FREE, s.faces[1]]];
                crate::spec::feature_lines::Segment::new(s.a, s.b, layer, 1.0, ends)
            })
            .collect();
        let how = format!(
            "isect_find: {} face pairs tested, {} segments (Möller's interval test)",
            stats.pairs_tested, stats.segments
        );
        self.rec
            .kernels(Pass::Intersections, &search.timing().clone(), &how);
        Ok(())
    }

    /// Exact visibility of the lines the SVG draws: split where their
    /// visibility changes, by occlusion queries towards the eye over the
    /// BVH, and chained.
    pub(super) fn visibility_pass(&mut self, cam: &Camera) -> Result<()> {
        let t0 = Instant::now();
        let [w, h] = self.scene.size;
        let view = cam.view(w, h);
        let strokes = match self.plan.contains(Pass::SdfLines) {
            true => stroke_segments(&self.scene_strokes(), &view, self.stroke_lift()),
            false => Vec::new(),
        };
        let t = self.topo.as_mut().expect("a pose ran");
        let edges = (self.view.edges_ran.as_ref()).map(|e| (&e.1, t.edge_pairs.as_slice()));
        let mut segs = gather(
            &self.scene.effects,
            &self.view.segs,
            edges,
            &self.pose.host.pos,
        );
        segs.extend_from_slice(&self.pose.isect_segs);
        segs.extend(strokes);
        let n = segs.len();
        let scale = self.run.framing.as_ref().map_or(1.0, |f| {
            let (lo, hi) = f.bounds;
            (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max) as f32
        });
        let bvh = t.bvh.as_mut().expect("planned with the BVH pass");
        let mesh = (self.pose.host.pos.as_slice(), t.mesh.faces.as_slice());
        let (vis, c) = classify_view(bvh, mesh, segs, &view, scale)?;
        let host = ms_since(t0) - c.timing.kernel_ms;
        let how = format!(
            "bvh_occluded: {n} segments, {} queries in {} rounds, {} chains \
             ({:.1} segments each); {host:.1} ms on the host (plan, rounds, chains)",
            c.queries,
            c.rounds,
            vis.chains.iter().filter(|c| c.visible).count(),
            vis.mean_chain_length(),
        );
        self.rec
            .kernels_and_host(Pass::Visibility, &c.timing, host, &how);
        self.view.vis = Some(vis);
        Ok(())
    }

    /// The SVG of the view: its groups from the chains of the visibility
    /// pass, or from the frame's depth; written to the SVG `paths`, kept
    /// for the caller when asked.
    pub(super) fn svg_pass(&mut self, cam: &Camera, paths: &[&PathBuf]) -> Result<()> {
        let t0 = Instant::now();
        let svgs: Vec<&PathBuf> = (paths.iter().copied())
            .filter(|p| draw::has_ext(p, "svg"))
            .collect();
        if svgs.is_empty() && !self.keep.layers {
            // Nothing asked for in this view (a live view without an SVG
            // request): the pass does not run.
            return Ok(());
        }
        let layers = match (&self.view.vis, &self.view.frame) {
            (Some(vis), _) => svg_layers_exact(self.scene, cam, vis),
            (None, Some(frame)) if self.plan.contains(Pass::Render) => {
                let strokes = self.scene_strokes();
                let lines = self.view_lines(&strokes);
                draw::svg_layers(self.scene, cam, &lines, frame)
            }
            // No line is drawn: empty groups of the families asked for.
            _ => Vec::new(),
        };
        let [w, h] = self.scene.size;
        for p in svgs {
            crate::export::svg::write_svg_layers(p, &layers, w, h)?;
            self.run.outputs.push(p.clone());
        }
        let how = if self.view.vis.is_some() {
            "SVG groups of the visible chains (exact visibility)"
        } else {
            "SVG groups of the lines visible against the frame's depth"
        };
        self.rec.wall(Pass::Svg, ms_since(t0), how);
        if self.keep.layers {
            self.view.layers = Some(layers);
        }
        Ok(())
    }

    /// The NPZ of the view: every piece of the visibility pass with its
    /// family, strength, visibility and chain, world coordinates, and the
    /// face and barycentric coordinates it lies at on this pose (which
    /// name the same point of the rest mesh on every frame), written to
    /// the NPZ `paths`.
    pub(super) fn npz_pass(&mut self, paths: &[&PathBuf]) -> Result<()> {
        let t0 = Instant::now();
        let vis = self
            .view
            .vis
            .as_ref()
            .expect("planned after the visibility");
        let t = self.topo.as_ref().expect("a pose ran");
        let pos: Vec<[f64; 3]> = (self.pose.host.pos.iter())
            .map(|p| p.map(f64::from))
            .collect();
        let mut arrays = vis.arrays(&pos, &t.mesh.faces);
        // Held over the frames: chains keep their ids from frame to frame.
        if let Some(h) = self.hold {
            let pieces: Vec<crate::spec::coherence::ChainPiece> = (0..arrays.a.len())
                .map(|i| crate::spec::coherence::ChainPiece {
                    chain: arrays.chain[i],
                    face: arrays.face[i],
                    family: arrays.family[i],
                    length: (0..3)
                        .map(|k| f64::from(arrays.b[i][k] - arrays.a[i][k]).powi(2))
                        .sum::<f64>()
                        .sqrt(),
                })
                .collect();
            let ids = (self.run.chain_ids.entry(h.slot).or_default()).assign(
                h.frame,
                h.follows,
                vis.chains.len(),
                &pieces,
            );
            arrays.chain_id = Some(arrays.chain.iter().map(|&c| ids[c as usize]).collect());
        }
        // Scene frame to world.
        let origin = self.run.framing.as_ref().map_or([0.0; 3], |f| f.origin);
        for p in arrays.a.iter_mut().chain(arrays.b.iter_mut()) {
            *p = std::array::from_fn(|i| (f64::from(p[i]) + origin[i]) as f32);
        }
        for p in paths.iter().filter(|p| draw::has_ext(p, "npz")) {
            crate::export::npz::write_segments(p, &arrays)?;
            self.run.outputs.push(p.to_path_buf());
        }
        let how = format!(
            "{} pieces with their faces and barycentric coordinates",
            arrays.a.len()
        );
        self.rec.wall(Pass::Npz, ms_since(t0), &how);
        let positions = (pos.into_iter())
            .map(|p| std::array::from_fn(|i| p[i] + origin[i]))
            .collect();
        self.view.npz = Some(draw::PosedPieces { arrays, positions });
        Ok(())
    }
}
