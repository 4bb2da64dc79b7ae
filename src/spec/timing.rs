//! One timing type for every stage: which steps ran (typed [`Step`] ids, one
//! per kernel entry point of `kernels/<family>.cl`), their kernel time from
//! OpenCL profiling events, how many launches each took, and the host wall
//! time of the call.
//!
//! The scene planner's passes name the steps they run
//! (`scene::planner::Pass::kernels`), so the executor joins a stage's
//! [`Timing`] to the planned passes by these ids, never by kernel-name
//! strings. Pure data: no device, no clock.

use serde::Serialize;

/// The stage family a [`Step`] belongs to (one name per family across
/// kernel file, host module, CPU twin, tests and benches).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// `kernels/curvature.cl` (Rusinkiewicz 2004).
    Curvature,
    /// `kernels/marching_cubes.cl`.
    MarchingCubes,
    /// `kernels/vertex_fusion.cl`.
    VertexFusion,
    /// `kernels/scan.cl`.
    Scan,
    /// `kernels/radix_sort.cl`.
    RadixSort,
    /// `kernels/edges.cl` (House & Li).
    Edges,
    /// `kernels/skinning.cl`.
    Skinning,
    /// `kernels/feature_lines.cl`.
    FeatureLines,
    /// `kernels/ao.cl`.
    Ao,
    /// `kernels/sdf_lines.cl` (curvature-directed strokes on a field).
    SdfLines,
    /// `kernels/mesh_sdf.cl` (a mesh's signed distance field).
    MeshSdf,
    /// `kernels/bvh.cl` (a linear BVH over a mesh's faces, Karras 2012).
    Bvh,
    /// `kernels/intersections.cl` (where faces cross, over the bvh tree).
    Intersections,
}

/// A step of a stage: a kernel entry point `<prefix>_<step>` of
/// `kernels/<family>.cl`. Serialized as the entry point's name.
///
/// Where a step launches helper kernels they are counted in it: the gather
/// variant's `curv_*_corners` + `curv_*_sum` in the curvature step they
/// serve, `curv_count_empty` in [`Step::CurvFrames`],
/// `curv_override_normals` in [`Step::CurvNormalsAreas`], `fuse_clear` in
/// [`Step::FuseTriangles`]. A call of the scan or the radix sort from
/// another stage is one step ([`Step::ScanExclusive`],
/// [`Step::RadixSortPairs`]) holding the kernel time of all its launches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Step {
    /// `curv_max_face`: owning face per vertex (topology).
    CurvMaxFace,
    /// `curv_clear`: zero the accumulators (atomic variant).
    CurvClear,
    /// `curv_normals_areas`: corner-weighted normals and Voronoi areas.
    CurvNormalsAreas,
    /// `curv_frames` (+ `curv_count_empty`): unit normals, initial frames.
    CurvFrames,
    /// `curv_tensor`: per-face curvature tensors over the one-ring.
    CurvTensor,
    /// `curv_principal`: k1, k2, d1, d2.
    CurvPrincipal,
    /// `curv_dcurv`: the curvature derivative.
    CurvDcurv,
    /// `mc_classify`: triangles per cell row.
    McClassify,
    /// `mc_triangles`: the soup, one key per vertex.
    McTriangles,
    /// `mc_iota`: identity faces of an unfused soup.
    McIota,
    /// `mc_direct_rows`: each grid row read once, where it crosses.
    McDirectRows,
    /// `mc_direct_count`: per-row vertex, triangle and hit counts, trimming.
    McDirectCount,
    /// `mc_direct_hits`: the grid points that vertices round onto.
    McDirectHits,
    /// `mc_direct_triangles`: positions and triangles with final indices.
    McDirectTriangles,
    /// `mc_direct_points`: positions of the grid-point vertices.
    McDirectPoints,
    /// `mc_direct_recount`: kept triangles of the rows with hits.
    McDirectRecount,
    /// `mc_direct_unused_mark` (with `mc_direct_unused_rows`,
    /// `mc_direct_unused_clear` and `mc_direct_unused_count`): the check,
    /// near the dropped triangles, that every vertex is still used.
    McDirectUnused,
    /// `mc_gradient_normals`: normals from the volume gradient.
    McGradientNormals,
    /// `fuse_index`: representative per sorted key.
    FuseIndex,
    /// `fuse_triangles` (+ `fuse_clear`): triangles kept, twin candidates.
    FuseTriangles,
    /// `fuse_candidates`: keys of the twin candidates.
    FuseCandidates,
    /// `fuse_cancel`: cancel opposite twins.
    FuseCancel,
    /// `fuse_mark`: referenced vertices.
    FuseMark,
    /// `fuse_compact_vertices`.
    FuseCompactVertices,
    /// `fuse_compact_faces`.
    FuseCompactFaces,
    /// One exclusive scan (`scan_block_sums`, `scan_partials`, `scan_apply`).
    ScanExclusive,
    /// One radix sort of (key, value) pairs (`radix_histogram`,
    /// `radix_scatter`, `radix_bucket_sort` and their scans).
    RadixSortPairs,
    /// `edges_detect`: contour, crease, boundary tests into edge-out.
    EdgesDetect,
    /// `caps_mh`: McGuire-Hughes half-caps.
    CapsMh,
    /// `caps_adjacency`: House & Li adjacency caps.
    CapsAdjacency,
    /// The drawn primitives compacted for read-back (`drawn_flags`, one
    /// exclusive scan, `compact_edges`, `compact_caps`).
    EdgesCompact,
    /// `skin_lbs`: linear blend skinning.
    SkinLbs,
    /// `lines_vertex`: per-vertex n·v and radial curvature.
    LinesVertex,
    /// `lines_face`: one contour / suggestive-contour segment per face.
    LinesFace,
    /// `lines_pose`: per-pose terms of the curvature line families.
    LinesPose,
    /// `lines_view`: view-dependent curvature and highlight terms.
    LinesView,
    /// `lines_dt1q1`: the derivative of the view-dependent curvature.
    LinesDt1q1,
    /// `lines_curves`: segments of the curvature line families.
    LinesCurves,
    /// `ao_vertex`: ambient occlusion from (k1, k2).
    AoVertex,
    /// `sdfl_dense`: sign changes between neighbouring voxels (the
    /// marching-cubes edge rule), appended with a counter.
    SdflDense,
    /// `sdfl_thin_phase`: Poisson-disk thinning in 27 conflict-free phases
    /// (`sdfl_cell_count`, `sdfl_cell_fill`, `sdfl_thin_flags`,
    /// `sdfl_thin_compact` and their scans counted in it).
    SdflThin,
    /// `sdfl_gradient`: central differences per voxel.
    SdflGradient,
    /// `sdfl_curvature`: principal curvatures and direction at the seeds
    /// (Kindlmann et al. 2003).
    SdflCurvature,
    /// `sdfl_range`: κ1 min and max over the seeds (atomics).
    SdflRange,
    /// `sdfl_trace`: RK4 along d1 both ways, projected onto the surface.
    SdflTrace,
    /// `sdfl_strips` (+ the vertex-count scan): tapered triangle strips.
    SdflStrips,
    /// The automatic sampling sweep (host entry `sdfl_sweep`): a
    /// provisional thinning and one `sdfl_curvature` per candidate distance.
    SdflSweep,
    /// `msdf_band_min` (with `msdf_clear` and `msdf_band_id`): exact
    /// distances in the narrow band.
    MsdfBand,
    /// `msdf_jfa` (with `msdf_seed`): every jump-flooding pass.
    MsdfJfa,
    /// `msdf_refine`: exact distance to the flooded nearest triangle.
    MsdfRefine,
    /// `msdf_wind` (with `msdf_cross`, over the three axes): the sign.
    MsdfSign,
    /// `msdf_finish`: the signed field.
    MsdfFinish,
    /// `bvh_morton`: Morton codes of the face centroids.
    BvhMorton,
    /// `bvh_build`: Karras's internal nodes from the sorted codes.
    BvhBuild,
    /// `bvh_refit`: leaf boxes, then internal boxes bottom-up.
    BvhRefit,
    /// `bvh_occluded`: segment occlusion queries.
    BvhOccluded,
    /// `isect_find`: face pairs from the tree, their crossing segments.
    IsectFind,
}

impl Step {
    /// The step's name within its family: the entry point without the
    /// family prefix (`tensor` for `curv_tensor`), as the curvature stats
    /// list their passes.
    pub fn name(self) -> &'static str {
        let k = self.kernel();
        match self.family() {
            Family::Curvature => &k["curv_".len()..],
            Family::MarchingCubes => &k["mc_".len()..],
            Family::VertexFusion => &k["fuse_".len()..],
            Family::Skinning => &k["skin_".len()..],
            Family::FeatureLines => &k["lines_".len()..],
            Family::Ao => &k["ao_".len()..],
            Family::SdfLines => &k["sdfl_".len()..],
            Family::MeshSdf => &k["msdf_".len()..],
            Family::Bvh => &k["bvh_".len()..],
            Family::Intersections => &k["isect_".len()..],
            Family::Scan | Family::RadixSort | Family::Edges => k,
        }
    }

    /// The family whose kernel file holds the step.
    pub fn family(self) -> Family {
        use Step::*;
        match self {
            CurvMaxFace | CurvClear | CurvNormalsAreas | CurvFrames | CurvTensor
            | CurvPrincipal | CurvDcurv => Family::Curvature,
            McClassify | McTriangles | McIota | McGradientNormals | McDirectRows
            | McDirectCount | McDirectHits | McDirectTriangles | McDirectPoints
            | McDirectRecount | McDirectUnused => Family::MarchingCubes,
            FuseIndex | FuseTriangles | FuseCandidates | FuseCancel | FuseMark
            | FuseCompactVertices | FuseCompactFaces => Family::VertexFusion,
            ScanExclusive => Family::Scan,
            RadixSortPairs => Family::RadixSort,
            EdgesDetect | CapsMh | CapsAdjacency | EdgesCompact => Family::Edges,
            SkinLbs => Family::Skinning,
            LinesVertex | LinesFace | LinesPose | LinesView | LinesDt1q1 | LinesCurves => {
                Family::FeatureLines
            }
            AoVertex => Family::Ao,
            SdflDense | SdflThin | SdflGradient | SdflCurvature | SdflRange | SdflTrace
            | SdflStrips | SdflSweep => Family::SdfLines,
            MsdfBand | MsdfJfa | MsdfRefine | MsdfSign | MsdfFinish => Family::MeshSdf,
            BvhMorton | BvhBuild | BvhRefit | BvhOccluded => Family::Bvh,
            IsectFind => Family::Intersections,
        }
    }
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.kernel())
    }
}

impl Serialize for Step {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.kernel())
    }
}

/// Kernel time of one step in one call.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StepTime {
    /// The step.
    pub step: Step,
    /// Kernel time from OpenCL profiling events, in milliseconds.
    pub kernel_ms: f64,
    /// Kernel launches counted in it.
    pub launches: u32,
}

/// The time of one phase of a call: a part that is not one kernel step
/// (loading, building a topology, uploading, drawing, reading back; a scene
/// pass on its own clock), in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PhaseTime {
    /// The phase's name (`load`, `topology`, `upload`, ...), as reports
    /// and `--stats` print it.
    pub phase: &'static str,
    /// Wall time in milliseconds.
    pub ms: f64,
}

/// Timing of one stage call (or of a chain of them): kernel ms per step in
/// execution order, their sum, the host wall time, and the wall time of the
/// call's phases. The one type of time a library result carries: repeats,
/// medians and tables live in `shapecue report` and the command line.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Timing {
    /// Kernel time per step, in execution order; a step launched again
    /// right after itself is one entry.
    pub steps: Vec<StepTime>,
    /// Sum of the step kernel times.
    pub kernel_ms: f64,
    /// Host wall time of the call, uploads and waits included (0 where the
    /// caller measures it).
    pub wall_ms: f64,
    /// The call's phases in order: one entry per phase ([`Timing::phase`]
    /// adds to it), or one per run of a phase that repeats ([`Timing::lap`]);
    /// [`Timing::extend`] adds another's entries by name.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<PhaseTime>,
}

impl Timing {
    /// One step of `ms` kernel time (one launch).
    pub fn of(step: Step, ms: f64) -> Timing {
        let mut t = Timing::default();
        t.add(step, ms);
        t
    }

    /// Adds one launch of `step` taking `ms`: merged into the last entry
    /// when it is the same step, a new entry otherwise.
    pub fn add(&mut self, step: Step, ms: f64) {
        self.kernel_ms += ms;
        match self.steps.last_mut() {
            Some(last) if last.step == step => {
                last.kernel_ms += ms;
                last.launches += 1;
            }
            _ => self.steps.push(StepTime {
                step,
                kernel_ms: ms,
                launches: 1,
            }),
        }
    }

    /// Adds `ms` to the phase `phase` (a new phase at the end, or the one of
    /// that name).
    pub fn phase(&mut self, phase: &'static str, ms: f64) {
        match self.phases.iter_mut().find(|p| p.phase == phase) {
            Some(p) => p.ms += ms,
            None => self.phases.push(PhaseTime { phase, ms }),
        }
    }

    /// Sets the phase `phase` to `ms` (a phase that holds the last run's
    /// time: a new phase at the end, or the one of that name replaced).
    pub fn set_phase(&mut self, phase: &'static str, ms: f64) {
        match self.phases.iter_mut().find(|p| p.phase == phase) {
            Some(p) => p.ms = ms,
            None => self.phases.push(PhaseTime { phase, ms }),
        }
    }

    /// Appends one more run of `phase` (a phase that runs once per pose or
    /// per view keeps one entry per run: [`laps`](Self::laps)).
    pub fn lap(&mut self, phase: &'static str, ms: f64) {
        self.phases.push(PhaseTime { phase, ms });
    }

    /// The wall ms of a phase, over all its entries (0 when it did not run).
    pub fn phase_ms(&self, phase: &str) -> f64 {
        self.laps(phase).iter().sum()
    }

    /// The wall ms of each entry of a phase, in order.
    pub fn laps(&self, phase: &str) -> Vec<f64> {
        (self.phases.iter())
            .filter(|p| p.phase == phase)
            .map(|p| p.ms)
            .collect()
    }

    /// Appends another call's steps (its wall time and phases added too).
    pub fn extend(&mut self, other: &Timing) {
        for s in &other.steps {
            self.kernel_ms += s.kernel_ms;
            match self.steps.last_mut() {
                Some(last) if last.step == s.step => {
                    last.kernel_ms += s.kernel_ms;
                    last.launches += s.launches;
                }
                _ => self.steps.push(*s),
            }
        }
        self.wall_ms += other.wall_ms;
        for p in &other.phases {
            self.phase(p.phase, p.ms);
        }
    }

    /// Summed kernel ms of the entries whose step is in `steps`.
    pub fn ms(&self, steps: &[Step]) -> f64 {
        self.steps
            .iter()
            .filter(|s| steps.contains(&s.step))
            .map(|s| s.kernel_ms)
            .sum()
    }

    /// Summed kernel ms of one family's steps.
    pub fn family_ms(&self, family: Family) -> f64 {
        self.steps
            .iter()
            .filter(|s| s.step.family() == family)
            .map(|s| s.kernel_ms)
            .sum()
    }

    /// Whether any entry's step is in `steps`.
    pub fn ran(&self, steps: &[Step]) -> bool {
        self.steps.iter().any(|s| steps.contains(&s.step))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn consecutive_launches_of_a_step_merge() {
        let mut t = Timing::of(Step::CurvTensor, 1.0);
        t.add(Step::CurvTensor, 0.5);
        t.add(Step::CurvPrincipal, 0.25);
        assert_eq!(t.steps.len(), 2);
        assert_eq!(t.steps[0].launches, 2);
        assert_eq!(t.kernel_ms, 1.75);
        assert_eq!(t.ms(&[Step::CurvPrincipal]), 0.25);
        assert_eq!(t.family_ms(Family::Curvature), 1.75);
        assert_eq!(Step::CurvTensor.name(), "tensor");
        assert_eq!(Step::CapsMh.name(), "caps_mh");
    }
}
