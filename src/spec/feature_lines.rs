//! Shared types of the `feature_lines` family (occluding and suggestive
//! contours, DeCarlo et al. 2003): what the stage reads of a view, the
//! segment type and the bound of the segment buffer. Used by the host wiring
//! (`stages::feature_lines`) and the CPU twin
//! (`cpu::feature_lines`).

/// A segment of a line family: its ends, its family's code, its strength,
/// and the mesh edge each end lies on (sorted vertex pairs). The segments of two
/// faces sharing an edge meet on it, so chaining by these edges is exact
/// (see [`edge_key`]). An end inside a face has no edge: `[LINE_FREE, face]`
/// where a test cut the segment, `[u32::MAX, face]` at a face centre.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Segment {
    /// The first end.
    pub a: [f32; 3],
    /// The second end.
    pub b: [f32; 3],
    /// The family's code ([`LineFamily::kind`]).
    pub family: u32,
    /// The strength (rtsc's fade), in [0, 1].
    pub strength: f32,
    /// What each end lies on: a mesh edge as its sorted vertex pair, or
    /// `[LINE_FREE, face]` / `[u32::MAX, face]` inside a face.
    pub ends: [[u32; 2]; 2],
}

impl Segment {
    /// A segment from its parts.
    pub fn new(a: [f32; 3], b: [f32; 3], family: u32, strength: f32, ends: [[u32; 2]; 2]) -> Self {
        Segment {
            a,
            b,
            family,
            strength,
            ends,
        }
    }
}

/// The per-vertex fields of one view that rtsc's line families are zero
/// crossings of, in world units, one value per vertex: what dataset
/// builders keep beside the lines (`shapecue lines --fields`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewFields {
    /// n·v, the unit normal against the unit direction towards the eye
    /// (the occluding contours are its zeros).
    pub ndotv: Vec<f32>,
    /// κr sin²θ = k1 u² + k2 v² (u, v: the unit view direction along the
    /// principal directions), as rtsc keeps it; its zeros are the
    /// suggestive contours (1 / length).
    pub kr: Vec<f32>,
    /// D_w κr, the radial curvature's derivative along the projected view
    /// direction, as rtsc's suggestive-contour test reads it (1 / length²).
    pub dwkr: Vec<f32>,
    /// q1, the view-dependent curvature of Judd et al.'s apparent ridges
    /// as their code and rtsc keep it: the largest eigenvalue of QᵀQ
    /// (1 / length²).
    pub q1: Vec<f32>,
}

impl ViewFields {
    /// The fields computed in coordinates `scale` times smaller than the
    /// world's (world = local · scale + centre), in world units.
    pub fn from_local(mut self, scale: f64) -> ViewFields {
        let s = scale as f32;
        let s2 = (scale * scale) as f32;
        self.kr.iter_mut().for_each(|x| *x /= s);
        self.dwkr.iter_mut().for_each(|x| *x /= s2);
        self.q1.iter_mut().for_each(|x| *x /= s2);
        self
    }
}

/// One number per mesh edge (a sorted vertex pair), for chaining segments.
pub fn edge_key(e: [u32; 2]) -> u64 {
    (u64::from(e[0]) << 32) | u64::from(e[1])
}

/// Puts the extraction's `segments` in the documented order every output
/// keeps, and leaves out what a face without area or a repeated face
/// makes:
/// - the order: by family, then by the edges (or faces) their two ends lie
///   on, then by the bits of their ends and strength. The extraction
///   appends segments with an atomic counter, so the device hands them back
///   in whatever order its work-items ran; after this sort the same inputs
///   give the same rows, whatever the device, its lane count or the run;
/// - a segment of a face with a repeated vertex (`f 1 1 2`): both its ends
///   lie on one edge (a sign change along the edge from a vertex to itself
///   is impossible, so the face's two crossings are on its one other
///   edge). Such a face has no area, and its piece no place on the
///   surface. A boundary's ends are vertices (`[v, v]`), two of them;
/// - the second of two identical segments: a face given twice (the same
///   corners in the same order) draws its lines twice, which would break
///   every chain through it.
pub fn canonical(segments: &mut Vec<Segment>) {
    let on_edge = |e: [u32; 2]| e[0] != LINE_FREE && e[0] != u32::MAX;
    segments.retain(|s| !(on_edge(s.ends[0]) && s.ends[0] == s.ends[1]));
    let bits = |p: [f32; 3]| p.map(f32::to_bits);
    let key = |s: &Segment| (s.family, s.ends, bits(s.a), bits(s.b), s.strength.to_bits());
    // The family and the ends' edges packed in two integers sort the rows
    // nearly whole, far faster than the whole key; runs of equal packings
    // (segments on the same two edges: isophotes of several levels) are
    // then sorted by the rest. The packing orders as the key does: an edge
    // number is a vertex or face index (below 2^30 - 2 for every mesh the
    // loaders take) or one of the two markers above it, kept in order.
    let squeeze = |x: u32| -> u64 {
        match x {
            u32::MAX => (1 << 30) - 1,
            LINE_FREE => (1 << 30) - 2,
            x => u64::from(x).min((1 << 30) - 3),
        }
    };
    let head = |s: &Segment| -> u64 {
        (u64::from(s.family.min(15)) << 60) | (squeeze(s.ends[0][0]) << 30) | squeeze(s.ends[0][1])
    };
    let second = |s: &Segment| -> u64 { (u64::from(s.ends[1][0]) << 32) | u64::from(s.ends[1][1]) };
    let mut order: Vec<(u64, u64, u32)> = (segments.iter().enumerate())
        .map(|(i, s)| (head(s), second(s), i as u32))
        .collect();
    order.sort_unstable();
    let mut sorted: Vec<Segment> = order
        .iter()
        .map(|&(_, _, i)| segments[i as usize])
        .collect();
    let mut start = 0;
    while start < order.len() {
        let at = (order[start].0, order[start].1);
        let end = start + order[start..].partition_point(|o| (o.0, o.1) == at);
        if end - start > 1 {
            sorted[start..end].sort_unstable_by_key(key);
        }
        start = end;
    }
    sorted.dedup_by_key(|s| key(s));
    *segments = sorted;
}

/// The layer of the feature edges (the line families' layers are their
/// kinds, [`LineFamily`] as `u32`).
pub const LAYER_FEATURE_EDGES: u32 = 1 << 16;
/// The layer of the intersection lines.
pub const LAYER_INTERSECTIONS: u32 = (1 << 16) + 1;
/// The layer of the curvature-directed strokes.
pub const LAYER_STROKES: u32 = (1 << 16) + 2;

/// Every family code a segment or piece may carry, with its name, in
/// code order: the line families' ([`LineFamily`] as `u32`), then the
/// feature edges', intersection lines' and strokes' layers. The one table
/// the NPZ files, the manifests and Python name the codes by.
pub fn family_codes() -> Vec<(u32, &'static str)> {
    let mut v: Vec<(u32, &'static str)> = (LineFamily::ALL.iter())
        .map(|&f| (f as u32, f.name()))
        .collect();
    v.extend([
        (LAYER_FEATURE_EDGES, "feature-edges"),
        (LAYER_INTERSECTIONS, "intersection-lines"),
        (LAYER_STROKES, "curvature-strokes"),
    ]);
    v
}

/// The first entry of a segment end's "edge" where a test cut the segment
/// inside a face (the second is the face): such an end chains with no
/// other by its edge.
pub const LINE_FREE: u32 = 0xffff_fffe;

/// Inputs of the stage, f32 per vertex.
pub struct LineInputs<'a> {
    /// Positions.
    pub pos: &'a [[f32; 3]],
    /// Unit normals.
    pub nrm: &'a [[f32; 3]],
    /// First principal directions.
    pub d1: &'a [[f32; 3]],
    /// Second principal directions.
    pub d2: &'a [[f32; 3]],
    /// (k1, k2).
    pub k: &'a [[f32; 2]],
    /// (C111, C112, C122, C222).
    pub dk: &'a [[f32; 4]],
}

/// Segments the face pass can emit for `faces` faces: three per face (a
/// plane crosses a triangle in at most one segment; rtsc's contour test,
/// linear along it, keeps one piece of a contour, and the suggestive test,
/// a ratio of two linear terms, at most two pieces of a suggestive
/// contour).
pub fn segments_bound(faces: usize) -> usize {
    3 * faces
}

/// The first capacity of the face pass's segment buffer: one segment of
/// each kind per face, which a mesh seen from one view never comes near;
/// where a pass counts more, the buffer grows to what it counted and the
/// pass runs again.
pub fn segments_estimate(faces: usize) -> usize {
    (2 * faces).max(1)
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/feature_lines.cl`.
    pub enum LinesKernel {
        /// Per-vertex n·v and radial curvature.
        Vertex = "lines_vertex",
        /// One contour or suggestive-contour segment per face.
        Face = "lines_face",
    }
}

/// A family of lines: the `kind` of a [`Segment`] is its index. Occluding
/// and suggestive contours come from `kernels/feature_lines.cl`, the others
/// from `kernels/feature_lines_curves.cl`; the set is that of rtsc
/// (Rusinkiewicz and DeCarlo's real-time suggestive contours program).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LineFamily {
    /// Occluding contours, n·v = 0.
    Contours = 0,
    /// Suggestive contours (DeCarlo et al. 2003).
    Suggestive = 1,
    /// Ridges (Ohtake, Belyaev and Seidel 2004): maxima of the larger
    /// principal curvature along its direction, where it is positive.
    Ridges = 2,
    /// Valleys: the same where the curvature of larger magnitude is negative.
    Valleys = 3,
    /// Apparent ridges (Judd, Durand and Adelson 2007): maxima of the
    /// view-dependent curvature.
    ApparentRidges = 4,
    /// Suggestive highlights (DeCarlo and Rusinkiewicz 2007).
    SuggestiveHighlights = 5,
    /// Principal highlights (DeCarlo and Rusinkiewicz 2007).
    PrincipalHighlights = 6,
    /// Isophotes: n·l at evenly spaced levels.
    Isophotes = 7,
    /// Parabolic lines, K = 0.
    KZero = 8,
    /// Lines of zero mean curvature, H = 0.
    HZero = 9,
    /// D_w κr = 0: the zero set of the suggestive-contour test.
    DwkrZero = 10,
    /// Mesh boundaries (edges with one face).
    Boundaries = 11,
}

impl LineFamily {
    /// Every family, by index.
    pub const ALL: [LineFamily; 12] = [
        LineFamily::Contours,
        LineFamily::Suggestive,
        LineFamily::Ridges,
        LineFamily::Valleys,
        LineFamily::ApparentRidges,
        LineFamily::SuggestiveHighlights,
        LineFamily::PrincipalHighlights,
        LineFamily::Isophotes,
        LineFamily::KZero,
        LineFamily::HZero,
        LineFamily::DwkrZero,
        LineFamily::Boundaries,
    ];

    /// The family's name in files, scenes and the command line.
    pub const fn name(self) -> &'static str {
        match self {
            LineFamily::Contours => "contours",
            LineFamily::Suggestive => "suggestive",
            LineFamily::Ridges => "ridges",
            LineFamily::Valleys => "valleys",
            LineFamily::ApparentRidges => "apparent-ridges",
            LineFamily::SuggestiveHighlights => "suggestive-highlights",
            LineFamily::PrincipalHighlights => "principal-highlights",
            LineFamily::Isophotes => "isophotes",
            LineFamily::KZero => "k-zero",
            LineFamily::HZero => "h-zero",
            LineFamily::DwkrZero => "dwkr-zero",
            LineFamily::Boundaries => "boundaries",
        }
    }

    /// The family of a segment kind.
    pub fn from_kind(kind: u32) -> Option<LineFamily> {
        LineFamily::ALL.get(kind as usize).copied()
    }

    /// This family's bit in a [`FamilySet`].
    pub const fn bit(self) -> u32 {
        1 << self as u32
    }

    /// Whether the family reads the view-dependent curvature (q1, t1, D_t1 q1).
    pub fn needs_view_curvature(self) -> bool {
        self == LineFamily::ApparentRidges
    }

    /// Whether the family reads the curvature derivative (dcurv).
    pub fn needs_dcurv(self) -> bool {
        matches!(
            self,
            LineFamily::Suggestive
                | LineFamily::Ridges
                | LineFamily::Valleys
                | LineFamily::SuggestiveHighlights
                | LineFamily::DwkrZero
        )
    }

    /// Whether the family needs only normals (no curvature).
    pub fn needs_only_normals(self) -> bool {
        matches!(
            self,
            LineFamily::Contours | LineFamily::Isophotes | LineFamily::Boundaries
        )
    }
}

crate::spec::named_choice!(LineFamily, "line family");

/// A set of [`LineFamily`]s (a bit per family index).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub struct FamilySet(pub u32);

impl FamilySet {
    /// No family.
    pub const NONE: FamilySet = FamilySet(0);

    /// The set of `families`.
    pub fn of(families: &[LineFamily]) -> FamilySet {
        FamilySet(families.iter().fold(0, |m, f| m | f.bit()))
    }

    /// Whether `f` is in the set.
    pub fn has(self, f: LineFamily) -> bool {
        self.0 & f.bit() != 0
    }

    /// The families in the set, by index.
    pub fn iter(self) -> impl Iterator<Item = LineFamily> {
        LineFamily::ALL.into_iter().filter(move |f| self.has(*f))
    }

    /// Parses a comma-separated list of family names.
    pub fn parse(list: &str) -> crate::error::Result<FamilySet> {
        let mut s = FamilySet::NONE;
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            let f: LineFamily = name.parse()?;
            s.0 |= f.bit();
        }
        Ok(s)
    }

    /// The set with the occluding and suggestive contours removed (the
    /// families of `kernels/feature_lines_curves.cl`).
    pub fn curves(self) -> FamilySet {
        FamilySet(self.0 & !(LineFamily::Contours.bit() | LineFamily::Suggestive.bit()))
    }
}

/// The controls of the curvature line families, with rtsc's defaults and
/// meanings: thresholds are dimensionless and scaled by the feature size s
/// as rtsc scales them: ridges and valleys keep |k| > t / s, apparent
/// ridges q1 > t / s² (q1 a squared curvature), principal highlights
/// (k1² − k2²)(n·v) > t / s², suggestive highlights −D_w κr tanθ > t / s².
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CurveOptions {
    /// The families to draw besides the contours.
    pub families: FamilySet,
    /// Ridge and valley threshold (rtsc's default 0.1).
    pub ridge_threshold: f32,
    /// Apparent-ridge threshold (rtsc's default 0.1).
    pub apparent_threshold: f32,
    /// Principal-highlight threshold (rtsc's default 0.04).
    pub principal_threshold: f32,
    /// Suggestive-highlight threshold (rtsc's default 0.02).
    pub highlight_threshold: f32,
    /// Isophotes: levels n·l = j / N for |j| < N (rtsc's default N = 20).
    pub isophotes: u32,
    /// Unit direction towards the light, world coordinates.
    pub light: [f32; 3],
    /// Back-face culling: no segment on a face whose corners all face away
    /// (apparent ridges are never culled, as in rtsc).
    pub cull: bool,
    /// rtsc's tests (its `test_c`, `test_sc`, `test_sh`, `test_rv`,
    /// `test_ph`, `test_ar`): contours keep κr ≥ 0, suggestive contours and
    /// highlights their threshold, ridge-like families their extremum check.
    /// Off: every zero crossing (suggestive contours become the κr = 0 loops).
    pub test: bool,
    /// Strength fades with the test's margin above the threshold (rtsc's
    /// "draw faded").
    pub fade: bool,
    /// rtsc's `use_hermite`: the κr = 0 crossings of suggestive contours and
    /// highlights placed by a cubic Hermite fit from the gradient of
    /// κr sin²θ instead of linear interpolation.
    pub hermite: bool,
    /// shapecue's addition: the same cubic placement for the K = 0 and
    /// H = 0 crossings, from the curvature gradients.
    pub hermite_kh: bool,
}

impl Default for CurveOptions {
    fn default() -> Self {
        CurveOptions {
            families: FamilySet::NONE,
            ridge_threshold: 0.1,
            apparent_threshold: 0.1,
            principal_threshold: 0.04,
            highlight_threshold: 0.02,
            isophotes: 20,
            light: [0.0, 0.0, 1.0],
            cull: true,
            test: true,
            fade: true,
            hermite: false,
            hermite_kh: false,
        }
    }
}

impl CurveOptions {
    /// The kernel's flag bits: culling, tests, fading, Hermite placement of
    /// K = 0 and H = 0 (bit 3) and of suggestive highlights (bit 4).
    pub fn flags(&self) -> u32 {
        u32::from(self.cull)
            | (u32::from(self.test) << 1)
            | (u32::from(self.fade) << 2)
            | (u32::from(self.hermite_kh) << 3)
            | (u32::from(self.hermite) << 4)
    }

    /// Checks the thresholds and the light.
    pub fn check(&self) -> crate::error::Result<()> {
        for (what, t) in [
            ("ridge", self.ridge_threshold),
            ("apparent-ridge", self.apparent_threshold),
            ("principal-highlight", self.principal_threshold),
            ("suggestive-highlight", self.highlight_threshold),
        ] {
            if !(t.is_finite() && t >= 0.0) {
                return Err(crate::error::Error::InvalidArgument(format!(
                    "the {what} threshold must be finite and at least 0, got {t}"
                )));
            }
        }
        let l = self.light;
        let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        if !(n.is_finite() && n > 0.0) {
            return Err(crate::error::Error::InvalidArgument(
                "the light direction must be finite and non-zero".into(),
            ));
        }
        if self.isophotes == 0 && self.families.has(LineFamily::Isophotes) {
            return Err(crate::error::Error::InvalidArgument(
                "isophotes = 0: isophotes need at least 1 level".into(),
            ));
        }
        if self.isophotes > 1000 {
            return Err(crate::error::Error::InvalidArgument(format!(
                "at most 1000 isophote levels, got {}",
                self.isophotes
            )));
        }
        Ok(())
    }

    /// The light direction, unit.
    pub fn unit_light(&self) -> [f32; 3] {
        let l = self.light;
        let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        l.map(|c| c / n)
    }
}

/// First estimate of the segments the curve pass emits on `faces` faces for
/// `families`: the most a face can emit per family (three for the
/// ridge-like families, whose crossings may meet at the face centre; two
/// isophote levels). The kernel counts everything, and the host grows the
/// buffer and reruns the pass when a mesh needs more (many isophote levels
/// across one face).
pub fn curve_segments_estimate(faces: usize, families: FamilySet) -> usize {
    let per_face: usize = families
        .curves()
        .iter()
        .map(|f| match f {
            LineFamily::Ridges | LineFamily::Valleys | LineFamily::ApparentRidges => 3,
            LineFamily::Boundaries => 3,
            LineFamily::Isophotes => 2,
            _ => 1,
        })
        .sum();
    (per_face * faces).max(1)
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/feature_lines_curves.cl`.
    pub enum LinesCurvesKernel {
        /// Per vertex, per pose: kmax, its derivative and direction, K, H.
        Pose = "lines_pose",
        /// Per vertex, per view: q1, t1, principal-highlight terms, n·l.
        View = "lines_view",
        /// Per vertex, per view: D_t1 q1.
        Dt1q1 = "lines_dt1q1",
        /// Per face: the segments of every requested curve family.
        Curves = "lines_curves",
    }
}

/// The length that scales the line families' thresholds (rtsc's "feature
/// size"): thresholds are dimensionless, divided by it or its square.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FeatureSize {
    /// rtsc's (`compute_feature_size` in rtsc.cc): min(0.01 / p, 0.05 r),
    /// p the 10th percentile of |k1| and |k2| at 500 vertices its generator
    /// draws, r the radius of the smallest sphere around the vertices
    /// (`crate::mesh::feature_size::resolve`).
    #[default]
    Rtsc,
    /// The median edge length.
    Edge,
    /// This length, in the mesh's units.
    Value(f32),
}

impl FeatureSize {
    /// The words a file or the command line may use.
    pub const HELP: &'static str = "rtsc, edge or a length";
}

impl std::fmt::Display for FeatureSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FeatureSize::Rtsc => f.write_str("rtsc"),
            FeatureSize::Edge => f.write_str("edge"),
            FeatureSize::Value(v) => write!(f, "{v}"),
        }
    }
}

impl std::str::FromStr for FeatureSize {
    type Err = crate::error::Error;
    fn from_str(s: &str) -> crate::error::Result<FeatureSize> {
        match s {
            "rtsc" => Ok(FeatureSize::Rtsc),
            "edge" => Ok(FeatureSize::Edge),
            _ => match s.parse::<f32>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(FeatureSize::Value(v)),
                _ => Err(crate::error::Error::InvalidArgument(format!(
                    "feature size {s}: expected rtsc, edge or a positive length"
                ))),
            },
        }
    }
}

/// How the hidden parts of lines appear in the SVG (rtsc's "draw hidden
/// lines"): left out, drawn faded, or drawn dashed, under the visible parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Hidden {
    /// Visible parts only.
    Remove,
    /// Hidden parts at a third of the opacity.
    Faded,
    /// Hidden parts dashed.
    Dashed,
}

impl Hidden {
    /// Every choice.
    pub const ALL: [Hidden; 3] = [Hidden::Remove, Hidden::Faded, Hidden::Dashed];

    /// The choice's name.
    pub const fn name(self) -> &'static str {
        match self {
            Hidden::Remove => "remove",
            Hidden::Faded => "faded",
            Hidden::Dashed => "dashed",
        }
    }
}

crate::spec::named_choice!(Hidden, "hidden-line mode");

/// Each family's stroke colour and width factor in pictures and SVG: rtsc's
/// colours (its `draw_colors` mode) where they tell families apart, and
/// others where rtsc gives two families one colour (it draws K = 0, H = 0
/// and D_w κr = 0 all red, both highlights dark red) or draws boundaries
/// almost as black as contours. No two families share a colour.
pub fn family_style(f: LineFamily) -> ([f32; 3], f32) {
    match f {
        LineFamily::Contours => ([0.0, 0.0, 0.0], 1.25),
        LineFamily::Suggestive => ([0.0, 0.0, 0.8], 1.0),
        LineFamily::Ridges => ([0.3, 0.0, 0.3], 1.0),
        LineFamily::Valleys => ([0.5, 0.3, 0.2], 1.0),
        LineFamily::ApparentRidges => ([0.4, 0.4, 0.0], 1.0),
        LineFamily::SuggestiveHighlights => ([0.5, 0.0, 0.0], 1.0),
        LineFamily::PrincipalHighlights => ([0.9, 0.45, 0.0], 1.0),
        LineFamily::Isophotes => ([0.4, 0.7, 0.4], 0.5),
        LineFamily::KZero => ([0.9, 0.0, 0.0], 0.75),
        LineFamily::HZero => ([0.0, 0.55, 0.7], 0.75),
        LineFamily::DwkrZero => ([0.8, 0.2, 0.7], 0.75),
        LineFamily::Boundaries => ([0.55, 0.55, 0.55], 1.0),
    }
}

/// The id of a family's hidden-parts group.
pub fn hidden_id(f: LineFamily) -> &'static str {
    match f {
        LineFamily::Contours => "contours-hidden",
        LineFamily::Suggestive => "suggestive-hidden",
        LineFamily::Ridges => "ridges-hidden",
        LineFamily::Valleys => "valleys-hidden",
        LineFamily::ApparentRidges => "apparent-ridges-hidden",
        LineFamily::SuggestiveHighlights => "suggestive-highlights-hidden",
        LineFamily::PrincipalHighlights => "principal-highlights-hidden",
        LineFamily::Isophotes => "isophotes-hidden",
        LineFamily::KZero => "k-zero-hidden",
        LineFamily::HZero => "h-zero-hidden",
        LineFamily::DwkrZero => "dwkr-zero-hidden",
        LineFamily::Boundaries => "boundaries-hidden",
    }
}

/// The host helpers of the curve families that the device stage and its
/// twin share.
/// Marks the boundary edges of each face: bit j when edge (v[j], v[j+1])
/// belongs to no other face (computed once per topology).
pub fn boundary_mask(faces: &[[u32; 3]]) -> Vec<u32> {
    let mut count: std::collections::HashMap<(u32, u32), u32> = Default::default();
    for f in faces {
        for j in 0..3 {
            let (a, b) = (f[j], f[(j + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    faces
        .iter()
        .map(|f| {
            (0..3).fold(0, |m, j| {
                let (a, b) = (f[j], f[(j + 1) % 3]);
                if count[&(a.min(b), a.max(b))] == 1 {
                    m | 1 << j
                } else {
                    m
                }
            })
        })
        .collect()
}

/// Thresholds of `lines_curves`, divided by the feature size s as rtsc
/// scales them: ridge/valley (÷ s), apparent ridge, principal and suggestive
/// highlight, suggestive contour (÷ s²), and the fade of suggestive
/// highlights (÷ s², 0 for none).
#[derive(Clone, Copy, Debug)]
pub struct ScaledThresholds {
    /// Ridges and valleys (|k| > rv).
    pub rv: f32,
    /// Apparent ridges (q1 > ar, q1 a squared curvature).
    pub ar: f32,
    /// Principal highlights.
    pub ph: f32,
    /// Suggestive highlights.
    pub sh: f32,
    /// The suggestive-contour threshold (D_w κr = 0 is the zero set of
    /// sinθ D_w κr − sc (n·v)).
    pub sc: f32,
    /// The fade of suggestive highlights.
    pub sh_fade: f32,
}

impl ScaledThresholds {
    /// The options' thresholds for a mesh of feature size `s`, with the
    /// suggestive-contour threshold and fade `sc` already scaled (as
    /// [`crate::stages::feature_lines::LineOptions`] scales them).
    pub fn of(o: &CurveOptions, s: f32, sc: (f32, f32)) -> ScaledThresholds {
        ScaledThresholds {
            rv: o.ridge_threshold / s,
            ar: o.apparent_threshold / (s * s),
            ph: o.principal_threshold / (s * s),
            sh: o.highlight_threshold / (s * s),
            sc: sc.0,
            sh_fade: sc.1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_family_has_its_own_colour() {
        for (i, a) in LineFamily::ALL.iter().enumerate() {
            for b in &LineFamily::ALL[i + 1..] {
                let (ca, cb) = (family_style(*a).0, family_style(*b).0);
                let d: f32 = (0..3).map(|k| (ca[k] - cb[k]).powi(2)).sum::<f32>().sqrt();
                assert!(
                    d > 0.15,
                    "{} and {} look alike: {ca:?} {cb:?}",
                    a.name(),
                    b.name()
                );
            }
        }
    }

    #[test]
    fn feature_sizes_parse_and_print() {
        assert_eq!("rtsc".parse::<FeatureSize>().unwrap(), FeatureSize::Rtsc);
        assert_eq!("edge".parse::<FeatureSize>().unwrap(), FeatureSize::Edge);
        assert_eq!(
            "0.5".parse::<FeatureSize>().unwrap(),
            FeatureSize::Value(0.5)
        );
        for bad in ["0", "-1", "nan", "inf", "median", ""] {
            let e = bad.parse::<FeatureSize>().unwrap_err().to_string();
            assert!(e.contains("rtsc, edge or a positive length"), "{bad}: {e}");
        }
        assert_eq!(FeatureSize::Value(0.25).to_string(), "0.25");
        assert_eq!(FeatureSize::default().to_string(), "rtsc");
    }

    #[test]
    fn canonical_rows_do_not_depend_on_the_input_order() {
        // Segments of several families, sharing edges (isophotes of two
        // levels on one edge pair), with free and centre ends, a face with
        // a repeated corner (both ends on one edge) and a duplicate.
        let mut segs: Vec<Segment> = Vec::new();
        for i in 0..200u32 {
            let e = |a: u32, b: u32| [a % 97, 97 + b % 89];
            let p = |k: u32| [i as f32 * 0.5, k as f32, (i % 7) as f32];
            segs.push(Segment::new(
                p(0),
                p(1),
                i % 12,
                0.5,
                [e(i, i + 1), e(i + 3, i)],
            ));
            segs.push(Segment::new(p(2), p(3), 7, 1.0, [e(i, i + 1), e(i + 3, i)]));
            segs.push(Segment::new(
                p(4),
                p(5),
                1,
                0.25,
                [[LINE_FREE, i], [u32::MAX, i]],
            ));
        }
        segs.push(segs[10]);
        segs.push(Segment::new([0.0; 3], [0.0; 3], 0, 1.0, [[3, 9], [3, 9]]));
        let mut a = segs.clone();
        canonical(&mut a);
        // Shuffled by a fixed permutation: the same rows.
        let n = segs.len();
        let mut b: Vec<Segment> = (0..n).map(|i| segs[(i * 7919) % n]).collect();
        canonical(&mut b);
        type Bits = (u32, [[u32; 2]; 2], [u32; 3], [u32; 3], u32);
        let bits = |v: &[Segment]| -> Vec<Bits> {
            v.iter()
                .map(|s| {
                    (
                        s.family,
                        s.ends,
                        s.a.map(f32::to_bits),
                        s.b.map(f32::to_bits),
                        s.strength.to_bits(),
                    )
                })
                .collect()
        };
        assert_eq!(bits(&a), bits(&b));
        // Sorted by the whole key, the duplicate and the repeated-corner
        // face's segment left out.
        let k = bits(&a);
        assert!(k.windows(2).all(|w| w[0] < w[1]), "sorted, each row once");
        assert_eq!(a.len(), 3 * 200);
        assert!(!a.iter().any(|s| s.ends == [[3, 9], [3, 9]]));
    }
}
