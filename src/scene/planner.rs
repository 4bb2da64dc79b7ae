//! The planner: from the cues a scene asks for to exactly the passes they
//! need, each with its lifetime (geometry-central's require/ensure, applied
//! to a frame loop). Pure data: no device, no files.
//!
//! Lifetimes: *topology* passes (edge buffer, one-rings and owning faces,
//! adjacency cap buffer) run once per mesh topology; *pose* passes (skin or
//! load the frame, normals, curvature, dcurv, AO) once per pose; *view*
//! passes (contours, suggestive contours, the curvature line families' view
//! terms and segments, edge detection, caps, render) once per camera and
//! frame. Across the cameras of one frame the pose passes run
//! once; across the frames of a static mesh they run once in all. An
//! isosurface changes topology with every pose, so its topology passes are
//! pose passes.

mod outputs;
use crate::spec::edges::CapMode;
use crate::spec::feature_lines::LineFamily;
use crate::spec::timing::Step;
use crate::spec::visibility::VisibilityMethod;
pub use outputs::Outputs;
use serde::Serialize;

/// A shape cue a scene can ask for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Cue {
    /// Plain Lambert shading.
    Shading,
    /// Curvature colour map (blue concave, red convex, green saddle).
    CurvatureColors,
    /// Curvature-based ambient occlusion (Lambert × AO).
    AmbientOcclusion,
    /// Occluding contours.
    Contours,
    /// Suggestive contours.
    SuggestiveContours,
    /// Feature edges (contour, crease, boundary, marked) with caps.
    FeatureEdges,
    /// Curvature-directed strokes on a signed distance field (Interrante's
    /// strokes, curvature from the Hessian after Kindlmann et al. 2003):
    /// volume inputs only ([`Cue::accepts`]).
    CurvatureStrokes,
    /// Ridges (Ohtake, Belyaev and Seidel 2004, as rtsc draws them).
    Ridges,
    /// Valleys.
    Valleys,
    /// Apparent ridges (Judd, Durand and Adelson 2007).
    ApparentRidges,
    /// Suggestive highlights (DeCarlo and Rusinkiewicz 2007).
    SuggestiveHighlights,
    /// Principal highlights (DeCarlo and Rusinkiewicz 2007).
    PrincipalHighlights,
    /// Isophotes: n·l at evenly spaced levels.
    Isophotes,
    /// Parabolic lines, K = 0.
    KZero,
    /// Lines of zero mean curvature, H = 0.
    HZero,
    /// D_w κr = 0.
    DwkrZero,
    /// Mesh boundaries (edges with one face), as a line family.
    Boundaries,
    /// Intersection lines: where faces of the mesh cross (Blender Line
    /// Art's "intersection" lines), from the BVH (family `intersections`).
    IntersectionLines,
}

impl Cue {
    /// Every cue.
    pub const ALL: [Cue; 18] = [
        Cue::Shading,
        Cue::CurvatureColors,
        Cue::AmbientOcclusion,
        Cue::Contours,
        Cue::SuggestiveContours,
        Cue::FeatureEdges,
        Cue::CurvatureStrokes,
        Cue::Ridges,
        Cue::Valleys,
        Cue::ApparentRidges,
        Cue::SuggestiveHighlights,
        Cue::PrincipalHighlights,
        Cue::Isophotes,
        Cue::KZero,
        Cue::HZero,
        Cue::DwkrZero,
        Cue::Boundaries,
        Cue::IntersectionLines,
    ];

    /// The curvature line families (`kernels/feature_lines_curves.cl`),
    /// one cue each.
    pub const LINE_FAMILIES: [Cue; 10] = [
        Cue::Ridges,
        Cue::Valleys,
        Cue::ApparentRidges,
        Cue::SuggestiveHighlights,
        Cue::PrincipalHighlights,
        Cue::Isophotes,
        Cue::KZero,
        Cue::HZero,
        Cue::DwkrZero,
        Cue::Boundaries,
    ];

    /// The line family this cue draws, for the curvature line cues.
    pub fn family(self) -> Option<LineFamily> {
        Some(match self {
            Cue::Ridges => LineFamily::Ridges,
            Cue::Valleys => LineFamily::Valleys,
            Cue::ApparentRidges => LineFamily::ApparentRidges,
            Cue::SuggestiveHighlights => LineFamily::SuggestiveHighlights,
            Cue::PrincipalHighlights => LineFamily::PrincipalHighlights,
            Cue::Isophotes => LineFamily::Isophotes,
            Cue::KZero => LineFamily::KZero,
            Cue::HZero => LineFamily::HZero,
            Cue::DwkrZero => LineFamily::DwkrZero,
            Cue::Boundaries => LineFamily::Boundaries,
            _ => return None,
        })
    }

    /// Whether the cue can be drawn on an input kind: curvature-directed
    /// strokes are traced on a scalar field, so they need a volume input
    /// (a volume file or a procedural SDF); every other cue works on any.
    /// The scene file refuses a cue on an input it does not accept before
    /// anything runs.
    pub fn accepts(self, input: Input) -> bool {
        match self {
            Cue::CurvatureStrokes => input == Input::Volume,
            _ => true,
        }
    }

    /// The cue's name in scene files (`[effects]` keys).
    pub fn key(self) -> &'static str {
        match self {
            Cue::Shading => "shading",
            Cue::CurvatureColors => "curvature_colors",
            Cue::AmbientOcclusion => "ao",
            Cue::Contours => "contours",
            Cue::SuggestiveContours => "suggestive_contours",
            Cue::FeatureEdges => "feature_edges",
            Cue::CurvatureStrokes => "curvature_strokes",
            Cue::Ridges => "ridges",
            Cue::Valleys => "valleys",
            Cue::ApparentRidges => "apparent_ridges",
            Cue::SuggestiveHighlights => "suggestive_highlights",
            Cue::PrincipalHighlights => "principal_highlights",
            Cue::Isophotes => "isophotes",
            Cue::KZero => "k_zero",
            Cue::HZero => "h_zero",
            Cue::DwkrZero => "dwkr_zero",
            Cue::Boundaries => "boundaries",
            Cue::IntersectionLines => "intersection_lines",
        }
    }

    /// The passes this cue reads directly. The curvature line cues all end
    /// in the per-view segment pass (`lines_curves`); before it, ridges,
    /// valleys, K = 0, H = 0 and principal highlights read the per-pose
    /// terms (`lines_pose`, from curvature and dcurv); apparent ridges the
    /// view-dependent curvature and its derivative (`lines_view`,
    /// `lines_dt1q1`); principal highlights and isophotes the per-view
    /// terms (`lines_view`; isophotes need only normals there); suggestive
    /// highlights and D_w κr = 0 the radial curvature and its derivative
    /// (dcurv); boundaries only the boundary edges, listed once per
    /// topology, and the normals the segment pass culls with. `Render`
    /// here stands for the view's drawing: the plan puts in its place the
    /// passes the outputs need ([`Outputs`]).
    pub fn needs(self) -> &'static [Pass] {
        use Pass::{Curvature, Dcurv, LinesCurves, LinesDt1q1, LinesPose, LinesView, Render};
        match self {
            Cue::Shading => &[Pass::VertexNormals, Pass::Render],
            Cue::CurvatureColors => &[Pass::Curvature, Pass::Render],
            Cue::AmbientOcclusion => &[Pass::Ao, Pass::VertexNormals, Pass::Render],
            Cue::Contours => &[Pass::Contours, Pass::Render],
            Cue::SuggestiveContours => &[Pass::SuggestiveContours, Pass::Render],
            Cue::FeatureEdges => &[Pass::Edges, Pass::Caps, Pass::Render],
            Cue::CurvatureStrokes => &[Pass::SdfLines, Pass::Render],
            Cue::Ridges | Cue::Valleys | Cue::KZero | Cue::HZero => {
                &[LinesPose, LinesCurves, Render]
            }
            Cue::ApparentRidges => &[Curvature, LinesView, LinesDt1q1, LinesCurves, Render],
            Cue::PrincipalHighlights => &[LinesPose, LinesView, LinesCurves, Render],
            Cue::SuggestiveHighlights | Cue::DwkrZero => &[Dcurv, LinesCurves, Render],
            Cue::Isophotes => &[LinesView, LinesCurves, Render],
            Cue::Boundaries => &[LinesCurves, Render],
            Cue::IntersectionLines => &[Pass::Intersections, Render],
        }
    }
}

/// Where a scene's geometry comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Input {
    /// One mesh, the same in every frame.
    Static,
    /// A skinned mesh (glTF skin + animation): topology fixed, poses by skinning.
    Skinned,
    /// A sequence of meshes with one topology (OBJ/PLY frames).
    Flipbook,
    /// An isosurface of a volume: new topology every pose.
    Volume,
}

/// How often a pass runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Lifetime {
    /// Once per mesh topology.
    Topology,
    /// Once per pose (frame).
    Pose,
    /// Once per camera and frame.
    View,
}

/// A pass of the frame loop. Declaration order is a valid execution order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Pass {
    /// Marching cubes + vertex fusion (volume input).
    Isosurface,
    /// Linear blend skinning (skinned input; family `skinning`).
    Skinning,
    /// Upload the frame's positions (flipbook input).
    LoadFrame,
    /// Unique edges with their opposite vertices (House & Li's edge buffer).
    EdgeBuffer,
    /// One-rings / owning faces of the curvature passes.
    OneRings,
    /// Pairs of edges sharing a vertex (adjacency caps).
    CapBuffer,
    /// Area-weighted vertex normals.
    VertexNormals,
    /// Face normals (crease and contour tests of edge detection).
    FaceNormals,
    /// Principal curvatures and directions (k1, k2, d1, d2).
    Curvature,
    /// Curvature derivative (dk).
    Dcurv,
    /// Ambient occlusion from curvature.
    Ao,
    /// Per-pose terms of the curvature line families (`lines_pose`: the
    /// larger principal curvature, its derivative along its direction, K,
    /// H), once per pose however many views.
    LinesPose,
    /// The mesh's BVH for exact visibility (family `bvh`): built when a
    /// topology first appears, refitted to every later pose.
    Bvh,
    /// Intersection lines of this pose (family `intersections`): faces that
    /// cross, found over the BVH.
    Intersections,
    /// Curvature-directed strokes traced on the volume itself (family
    /// `sdf_lines`): dense samples, Poisson-disk seeds, curvature from the
    /// Hessian, RK4 tracing along d1, tapered strips. Reads no mesh pass.
    SdfLines,
    /// Occluding contours (zero crossings of n·v).
    Contours,
    /// Suggestive contours (zero crossings of radial curvature, with dk).
    SuggestiveContours,
    /// Per-view terms of the curvature line families (`lines_view`: the
    /// view-dependent curvature q1 and its direction t1, the
    /// principal-highlight terms, n·l).
    LinesView,
    /// The derivative of the view-dependent curvature along t1
    /// (`lines_dt1q1`, apparent ridges).
    LinesDt1q1,
    /// The segments of every requested curvature line family
    /// (`lines_curves`, with the `lines_vertex` terms n·v, κr and D_w κr).
    LinesCurves,
    /// The view's per-vertex fields beside its lines (n·v, κr, D_w κr and
    /// q1, read back from the line passes' terms), where the outputs ask
    /// for them.
    ViewFields,
    /// Feature-edge detection into the edge-out buffer (family `edges`).
    Edges,
    /// Cap geometry into the cap-out buffers.
    Caps,
    /// Exact visibility of the view's lines (family `visibility`): every
    /// segment split where its visibility changes, by occlusion queries
    /// towards the eye over the BVH, then joined into chains.
    Visibility,
    /// Draw the frame (GL).
    Render,
    /// Write the view's vector drawing (SVG groups of chains), its hidden
    /// lines from the visibility pass or from the frame's depth.
    Svg,
    /// Write the view's lines as NPZ: every piece of the visibility pass
    /// with its family, strength, visibility, chain, and the face and
    /// barycentric coordinates it lies at (which name the same point of
    /// the rest mesh on every frame of an animation).
    Npz,
}

impl std::fmt::Display for Cue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.key())
    }
}

impl Input {
    /// The input kind in words (`--explain`).
    pub fn name(self) -> &'static str {
        match self {
            Input::Static => "static mesh",
            Input::Skinned => "skinned mesh (glTF)",
            Input::Flipbook => "mesh sequence",
            Input::Volume => "volume isosurface",
        }
    }
}

impl std::fmt::Display for Input {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Lifetime {
    /// How often, in words (`--explain`, the report table).
    pub fn name(self) -> &'static str {
        match self {
            Lifetime::Topology => "topology",
            Lifetime::Pose => "pose",
            Lifetime::View => "view",
        }
    }
}

impl std::fmt::Display for Lifetime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Display for Pass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Pass {
    /// The pass's name as the report JSON and `--explain` write it (the
    /// kernel family's name where the pass is one family).
    pub fn name(self) -> &'static str {
        match self {
            Pass::Isosurface => "isosurface",
            Pass::Skinning => "skinning",
            Pass::LoadFrame => "load_frame",
            Pass::EdgeBuffer => "edge_buffer",
            Pass::OneRings => "one_rings",
            Pass::CapBuffer => "cap_buffer",
            Pass::VertexNormals => "vertex_normals",
            Pass::FaceNormals => "face_normals",
            Pass::Curvature => "curvature",
            Pass::Dcurv => "dcurv",
            Pass::Ao => "ao",
            Pass::LinesPose => "lines_pose",
            Pass::Bvh => "bvh",
            Pass::Intersections => "intersections",
            Pass::Visibility => "visibility",
            Pass::Svg => "svg",
            Pass::Npz => "npz",
            Pass::LinesView => "lines_view",
            Pass::LinesDt1q1 => "lines_dt1q1",
            Pass::LinesCurves => "lines_curves",
            Pass::ViewFields => "view_fields",
            Pass::SdfLines => "sdf_lines",
            Pass::Contours => "contours",
            Pass::SuggestiveContours => "suggestive_contours",
            Pass::Edges => "edges",
            Pass::Caps => "caps",
            Pass::Render => "render",
        }
    }

    /// Where the pass's work runs (`--explain`): `device` (kernels only),
    /// `host` (the CPU: building lists, reading back, writing), `device +
    /// host` (kernels, and a host step of the product beside them: the
    /// line passes' canonical order of the segments read back; the
    /// visibility's plan, rounds and chains), or `GL` (the renderer).
    pub fn runs_on(self) -> &'static str {
        match self {
            Pass::LoadFrame
            | Pass::EdgeBuffer
            | Pass::OneRings
            | Pass::CapBuffer
            | Pass::ViewFields
            | Pass::Svg
            | Pass::Npz => "host",
            Pass::Contours | Pass::SuggestiveContours | Pass::LinesCurves | Pass::Visibility => {
                "device + host"
            }
            Pass::Render => "GL",
            Pass::Isosurface
            | Pass::Skinning
            | Pass::VertexNormals
            | Pass::FaceNormals
            | Pass::Curvature
            | Pass::Dcurv
            | Pass::Ao
            | Pass::LinesPose
            | Pass::Bvh
            | Pass::Intersections
            | Pass::SdfLines
            | Pass::LinesView
            | Pass::LinesDt1q1
            | Pass::Edges
            | Pass::Caps => "device",
        }
    }

    /// The device steps this pass launches (empty for host passes), by
    /// which the executor joins a stage's [`crate::spec::timing::Timing`]
    /// to the plan. Contours and suggestive contours share one
    /// `lines_vertex` + `lines_face` launch; the curvature line families'
    /// segment pass runs `lines_vertex` too, whose time the contours count
    /// when they are planned.
    pub fn kernels(self) -> &'static [Step] {
        use Step::*;
        match self {
            // Every step of an extraction, by either numbering (scenes use
            // direct numbering; the soup's steps for the other fusions).
            Pass::Isosurface => &[
                McDirectRows,
                McDirectCount,
                McDirectHits,
                McDirectTriangles,
                McDirectPoints,
                McDirectRecount,
                McDirectUnused,
                McClassify,
                ScanExclusive,
                McTriangles,
                McIota,
                FuseIndex,
                FuseTriangles,
                FuseCandidates,
                RadixSortPairs,
                FuseCancel,
                FuseMark,
                FuseCompactVertices,
                FuseCompactFaces,
            ],
            Pass::Skinning => &[SkinLbs],
            Pass::OneRings => &[CurvMaxFace],
            Pass::VertexNormals => &[CurvClear, CurvNormalsAreas, CurvFrames],
            Pass::Curvature => &[CurvTensor, CurvPrincipal],
            Pass::Dcurv => &[CurvDcurv],
            Pass::Ao => &[AoVertex],
            Pass::SdfLines => &[
                SdflDense,
                SdflGradient,
                SdflSweep,
                SdflThin,
                SdflCurvature,
                SdflRange,
                SdflTrace,
                SdflStrips,
            ],
            Pass::Contours | Pass::SuggestiveContours => &[LinesVertex, LinesFace],
            Pass::LinesPose => &[LinesPose],
            Pass::LinesView => &[LinesView],
            Pass::LinesDt1q1 => &[LinesDt1q1],
            Pass::LinesCurves => &[LinesVertex, LinesCurves],
            Pass::Edges => &[EdgesDetect],
            Pass::Caps => &[CapsMh, CapsAdjacency],
            Pass::Bvh => &[BvhMorton, RadixSortPairs, BvhBuild, BvhRefit],
            Pass::Visibility => &[BvhOccluded],
            Pass::Intersections => &[IsectFind],
            Pass::LoadFrame
            | Pass::EdgeBuffer
            | Pass::CapBuffer
            | Pass::FaceNormals
            | Pass::Render
            | Pass::ViewFields
            | Pass::Svg
            | Pass::Npz => &[],
        }
    }

    /// The pass that makes this input's positions, if any.
    pub fn source(input: Input) -> Option<Pass> {
        match input {
            Input::Static => None,
            Input::Skinned => Some(Pass::Skinning),
            Input::Flipbook => Some(Pass::LoadFrame),
            Input::Volume => Some(Pass::Isosurface),
        }
    }

    /// The passes this one reads directly, for an input kind.
    pub fn needs(self, input: Input) -> Vec<Pass> {
        let src = Pass::source(input);
        let mut v: Vec<Pass> = match self {
            Pass::Isosurface | Pass::Skinning | Pass::LoadFrame => vec![],
            // An isosurface brings a new topology with every pose.
            Pass::EdgeBuffer | Pass::OneRings | Pass::CapBuffer if input == Input::Volume => {
                vec![Pass::Isosurface]
            }
            Pass::EdgeBuffer | Pass::OneRings | Pass::CapBuffer => vec![],
            Pass::VertexNormals | Pass::FaceNormals | Pass::Bvh => src.into_iter().collect(),
            Pass::Curvature => vec![Pass::OneRings, Pass::VertexNormals],
            Pass::Dcurv => vec![Pass::Curvature],
            Pass::Ao => vec![Pass::Curvature],
            // rtsc's contour test keeps the parts with κr > 0.
            Pass::Contours => vec![Pass::Curvature, Pass::VertexNormals],
            Pass::SuggestiveContours => vec![Pass::Dcurv, Pass::VertexNormals],
            Pass::LinesPose => vec![Pass::Dcurv],
            Pass::LinesView => vec![Pass::VertexNormals],
            Pass::LinesDt1q1 => vec![Pass::LinesView],
            // n·v per vertex, for back-face culling and fading, from the
            // curvature's normals (so the same with every family).
            Pass::LinesCurves => vec![Pass::VertexNormals, Pass::OneRings],
            // κr needs the curvature, D_w κr its derivative, q1 the view terms.
            Pass::ViewFields => vec![Pass::Dcurv, Pass::LinesView, Pass::VertexNormals],
            Pass::Edges => vec![Pass::EdgeBuffer, Pass::FaceNormals],
            Pass::Caps => vec![Pass::Edges, Pass::CapBuffer],
            // The strokes are traced on the field, not on the isosurface.
            Pass::SdfLines => vec![],
            // A volume's frame draws its isosurface (shaded, or flat in the
            // background colour to hide the strokes and lines behind it).
            Pass::Render if input == Input::Volume => vec![Pass::Isosurface],
            Pass::Render => vec![],
            // What else these read depends on the plan ([`Plan::reads`]).
            Pass::Visibility => vec![Pass::Bvh],
            Pass::Intersections => vec![Pass::Bvh],
            Pass::Svg => vec![],
            Pass::Npz => vec![Pass::Visibility],
        };
        v.sort();
        v
    }

    /// How often this pass runs for an input kind.
    pub fn lifetime(self, input: Input) -> Lifetime {
        match self {
            Pass::EdgeBuffer | Pass::OneRings | Pass::CapBuffer if input != Input::Volume => {
                Lifetime::Topology
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
            | Pass::Npz => Lifetime::View,
            _ => Lifetime::Pose,
        }
    }
}

impl Cue {
    /// Whether the cue is one of rtsc's line families (occluding and
    /// suggestive contours and the curvature families), which are computed
    /// from trimesh2's curvature by default ([`Compat::default_for`]).
    ///
    /// [`Compat::default_for`]: crate::spec::curvature::Compat::default_for
    pub fn is_rtsc_family(self) -> bool {
        self.family().is_some() || matches!(self, Cue::Contours | Cue::SuggestiveContours)
    }

    /// Whether the cue draws lines (whose hidden parts a vector drawing
    /// must find).
    pub fn draws_lines(self) -> bool {
        !matches!(
            self,
            Cue::Shading | Cue::CurvatureColors | Cue::AmbientOcclusion
        )
    }
}

/// The passes a set of cues needs, in execution order, with lifetimes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Plan {
    /// The input kind planned for.
    pub input: Input,
    /// The cues asked for.
    pub cues: Vec<Cue>,
    /// What the views are written as.
    pub outputs: Outputs,
    /// The closure of what the cues need, in execution order.
    pub passes: Vec<Pass>,
}

/// Plans exactly the passes `cues` need for `input`: the closure of their
/// needs, nothing else, in an order where every pass follows what it reads.
pub fn plan(cues: &[Cue], input: Input) -> Plan {
    plan_with(cues, input, CapMode::Adjacency)
}

/// [`plan`] for feature edges drawn with `caps`: adjacency caps need the cap
/// buffer and the cap pass; McGuire-Hughes half-caps need the cap pass and
/// the vertex normals (they are built per edge, along the projected normals)
/// but no cap buffer; no caps need neither. A raster image is drawn.
pub fn plan_with(cues: &[Cue], input: Input, caps: CapMode) -> Plan {
    plan_for(cues, input, caps, Outputs::RASTER)
}

/// [`plan_with`] for views written as `outputs`: the cues' drawing ends in
/// the render pass only where a raster image is drawn or the depth decides
/// the hidden lines, so a vector drawing with exact visibility opens no GL
/// context (and draws no caps).
pub fn plan_for(cues: &[Cue], input: Input, caps: CapMode, outputs: Outputs) -> Plan {
    let mut set = std::collections::BTreeSet::new();
    let terminals = outputs.terminals(cues);
    // Caps fill the gaps between thick edge quads in a drawn frame; an
    // SVG's polylines join round and need none.
    let caps = match terminals.contains(&Pass::Render) {
        true => caps,
        false => CapMode::None,
    };
    // Shading, curvature colours and AO colour a drawn frame only.
    let mut stack: Vec<Pass> = cues
        .iter()
        .filter(|c| outputs.raster || c.draws_lines())
        .flat_map(|c| c.needs().iter().copied())
        .flat_map(|p| match p {
            Pass::Render => terminals.clone(),
            p => vec![p],
        })
        .collect();
    // An SVG is written whatever it holds (its groups may be empty).
    if outputs.vector && !cues.is_empty() {
        stack.push(Pass::Svg);
    }
    while let Some(p) = stack.pop() {
        let dropped = match caps {
            CapMode::Adjacency => false,
            CapMode::Mh => p == Pass::CapBuffer,
            CapMode::None => matches!(p, Pass::CapBuffer | Pass::Caps),
        };
        if !dropped && set.insert(p) {
            stack.extend(p.needs(input));
            // McGuire-Hughes half-caps point along the projected vertex normals.
            if p == Pass::Caps && caps == CapMode::Mh {
                stack.push(Pass::VertexNormals);
            }
        }
    }
    let mut cues = cues.to_vec();
    cues.sort();
    cues.dedup();
    Plan {
        input,
        cues,
        outputs,
        // BTreeSet order is declaration order, which respects every need.
        passes: set.into_iter().collect(),
    }
}

impl Plan {
    /// Whether the plan runs `pass`.
    pub fn contains(&self, pass: Pass) -> bool {
        self.passes.contains(&pass)
    }

    /// The passes `pass` reads in this plan: its needs
    /// ([`Pass::needs`]), and for the visibility pass the planned passes
    /// whose lines it classifies, for the SVG pass the pass its hidden
    /// lines come from.
    pub fn reads(&self, pass: Pass) -> Vec<Pass> {
        let mut v = pass.needs(self.input);
        let extra: &[Pass] = match pass {
            Pass::Visibility => &[
                Pass::Intersections,
                Pass::SdfLines,
                Pass::Contours,
                Pass::SuggestiveContours,
                Pass::LinesCurves,
                Pass::Edges,
            ],
            Pass::Svg => &[Pass::Visibility, Pass::Render],
            _ => &[],
        };
        v.extend(extra.iter().copied().filter(|p| self.contains(*p)));
        if pass == Pass::Svg && self.outputs.visibility == VisibilityMethod::Exact {
            v.retain(|p| *p != Pass::Render);
        }
        v.sort();
        v
    }

    /// How many times `pass` runs over `frames` frames seen by `views`
    /// cameras: topology passes once, pose passes once per frame (once in
    /// all for a static mesh), view passes once per frame and camera.
    pub fn runs(&self, pass: Pass, frames: usize, views: usize) -> usize {
        if !self.contains(pass) {
            return 0;
        }
        let poses = if self.input == Input::Static {
            frames.min(1)
        } else {
            frames
        };
        match pass.lifetime(self.input) {
            Lifetime::Topology => frames.min(1),
            Lifetime::Pose => poses,
            Lifetime::View => frames * views,
        }
    }

    /// Human-readable plan (`--explain`).
    pub fn explain(&self, frames: usize, views: usize) -> String {
        let list = |v: &mut dyn Iterator<Item = String>| {
            let v: Vec<String> = v.collect();
            if v.is_empty() {
                "nothing".to_string()
            } else {
                v.join(", ")
            }
        };
        let mut s = format!(
            "input: {}; cues: {}; {frames} frame(s) × {views} view(s)\n",
            self.input,
            list(&mut self.cues.iter().map(|c| c.to_string()))
        );
        s.push_str(&format!(
            "  {:<20} {:<9} {:>5}  {:<13}  reads\n",
            "pass", "once per", "runs", "runs on"
        ));
        for &p in &self.passes {
            s.push_str(&format!(
                "  {:<20} {:<9} {:>5}  {:<13}  {}\n",
                p.name(),
                p.lifetime(self.input).name(),
                self.runs(p, frames, views),
                p.runs_on(),
                list(&mut self.reads(p).iter().map(|n| n.to_string()))
            ));
        }
        s
    }
}
