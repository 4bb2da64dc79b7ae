//! Shared types of the `curvature` family (see [`crate::spec`]): the
//! per-vertex output ([`CurvatureField`]), the skip counters
//! ([`CurvatureCounts`]), the variant choice ([`CurvatureOptions`] with
//! [`Accumulate`], [`Precision`], [`Compat`]), the pose [`Normalization`], the
//! degenerate-face thresholds and the device memory bound.
//!
//! Mirrors in `kernels/curvature.cl`: the `DEGEN_*` `#define`s
//! ([`DEGEN_AREA_REL`], [`DEGEN_EDGE2`], [`DEGEN_HEIGHT_ULP`]); the
//! `SC_DOUBLE` / `SC_COMPAT` build options select [`Precision::F64`] and
//! [`Compat::Trimesh2`]; the counters buffer `uint[4]` is
//! [`CurvatureCounts`] in field order. The kernels take scalar arguments
//! only, so no parameter struct crosses.
//!
//! Used by `stages::curvature` (host wiring), `cpu::curvature` (the twin),
//! the exporters, the planner and the CLI; imports no device layer.

/// Per-vertex differential quantities of a triangle mesh, in the mesh's own
/// coordinates (whatever centring and scaling a stage used internally has been
/// undone).
///
/// Conventions: `k1 >= k2` (signed), positive where the surface is convex with
/// outward normals; `d1`, `d2` unit and tangent with `d2 = n × d1`; `dk` is the
/// curvature derivative tensor (C₁₁₁, C₁₁₂, C₁₂₂, C₂₂₂) in the (d1, d2) frame.
/// In trimesh2 compatibility mode the ordering is |k1| ≥ |k2| instead.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CurvatureField {
    /// Unit vertex normals ((0,0,1) where no non-degenerate face touches the vertex).
    pub normals: Vec<[f64; 3]>,
    /// Voronoi point areas (0 where no non-degenerate face touches the vertex).
    pub areas: Vec<f64>,
    /// Maximum principal curvature.
    pub k1: Vec<f64>,
    /// Minimum principal curvature.
    pub k2: Vec<f64>,
    /// Principal direction of `k1`.
    pub d1: Vec<[f64; 3]>,
    /// Principal direction of `k2`.
    pub d2: Vec<[f64; 3]>,
    /// Curvature derivative tensor in the (d1, d2) frame; zeros when not computed.
    pub dk: Vec<[f64; 4]>,
}

/// One vertex's values of a [`CurvatureField`] (the same conventions).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VertexCurvature {
    /// Unit normal.
    pub normal: [f64; 3],
    /// Voronoi point area.
    pub area: f64,
    /// Maximum principal curvature.
    pub k1: f64,
    /// Minimum principal curvature.
    pub k2: f64,
    /// Principal direction of `k1`.
    pub d1: [f64; 3],
    /// Principal direction of `k2`.
    pub d2: [f64; 3],
    /// Curvature derivative tensor in the (d1, d2) frame.
    pub dk: [f64; 4],
}

impl VertexCurvature {
    /// The values in the order the fields are declared (the order of the
    /// PLY properties shapecue writes): normal, area, k1, k2, d1, d2, dk.
    pub fn row(&self) -> [f64; 16] {
        let [nx, ny, nz] = self.normal;
        let [ax, ay, az] = self.d1;
        let [bx, by, bz] = self.d2;
        let [d0, d1, d2, d3] = self.dk;
        [
            nx, ny, nz, self.area, self.k1, self.k2, ax, ay, az, bx, by, bz, d0, d1, d2, d3,
        ]
    }

    /// True if every value is finite.
    pub fn all_finite(&self) -> bool {
        self.row().iter().fold(true, |ok, x| ok & x.is_finite())
    }
}

impl CurvatureField {
    /// A field of `n` vertices with every value zero.
    pub fn zeros(n: usize) -> Self {
        CurvatureField {
            normals: vec![[0.0; 3]; n],
            areas: vec![0.0; n],
            k1: vec![0.0; n],
            k2: vec![0.0; n],
            d1: vec![[0.0; 3]; n],
            d2: vec![[0.0; 3]; n],
            dk: vec![[0.0; 4]; n],
        }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.k1.len()
    }

    /// The values of vertex `i` (which must be below [`CurvatureField::len`]).
    pub fn vertex(&self, i: usize) -> VertexCurvature {
        VertexCurvature {
            normal: self.normals[i],
            area: self.areas[i],
            k1: self.k1[i],
            k2: self.k2[i],
            d1: self.d1[i],
            d2: self.d2[i],
            dk: self.dk[i],
        }
    }

    /// True when there are no vertices.
    pub fn is_empty(&self) -> bool {
        self.k1.is_empty()
    }

    /// Mean curvature (k1 + k2) / 2 per vertex.
    pub fn mean(&self) -> Vec<f64> {
        self.k1
            .iter()
            .zip(&self.k2)
            .map(|(a, b)| 0.5 * (a + b))
            .collect()
    }

    /// Gaussian curvature k1·k2 per vertex.
    pub fn gaussian(&self) -> Vec<f64> {
        self.k1.iter().zip(&self.k2).map(|(a, b)| a * b).collect()
    }

    /// True if every value is finite.
    pub fn all_finite(&self) -> bool {
        let v3 = |v: &Vec<[f64; 3]>| v.iter().flatten().all(|x| x.is_finite());
        v3(&self.normals)
            && v3(&self.d1)
            && v3(&self.d2)
            && self.areas.iter().all(|x| x.is_finite())
            && self.k1.iter().all(|x| x.is_finite())
            && self.k2.iter().all(|x| x.is_finite())
            && self.dk.iter().flatten().all(|x| x.is_finite())
    }
}

/// How the one-ring sums are formed on the device.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Accumulate {
    /// One work-item per face adds into its vertices with float atomics
    /// (compare-and-swap), as in Griffin et al. Summation order varies run to run.
    Atomic,
    /// As `Atomic`, with the device's own float atomic add
    /// (`cl_ext_float_atomics`, OpenCL C 3.0 `atomic_fetch_add_explicit`,
    /// relaxed) in place of compare-and-swap loops. Summation order varies
    /// run to run. Only on devices that offer it (Intel's CPU runtime, not
    /// PoCL 3.1); f64 also needs its 64-bit global add.
    AtomicNative,
    /// Per-face kernels write each corner's contribution to a buffer (12
    /// reals per face, no atomics); per-vertex kernels sum their one-ring
    /// (built once) in face order. Bitwise identical from run to run. The
    /// default everywhere (command line, scenes, the viewer, lines,
    /// isosurfaces, Python): [`Accumulate::why_default`] says why.
    #[default]
    Gather,
}

impl Accumulate {
    /// Both schemes, in the order of tables and benches.
    pub const ALL: [Accumulate; 3] = [
        Accumulate::Atomic,
        Accumulate::AtomicNative,
        Accumulate::Gather,
    ];

    /// Why gather is the default scheme ([`Accumulate::default`], the one
    /// place it is decided), as `--stats` says it. The measurements behind
    /// it live in docs/performance.md and docs/notes/, not in the library.
    pub fn why_default() -> &'static str {
        "gather: bitwise reproducible from run to run, and faster than the \
         compare-and-swap atomics on every device measured (docs/performance.md)"
    }

    /// The name used on the command line (`--accumulate`), in scene files,
    /// stats and bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Accumulate::Atomic => "atomic",
            Accumulate::AtomicNative => "atomic-native",
            Accumulate::Gather => "gather",
        }
    }

    /// Whether the one-ring sums are atomic adds from the face kernels (the
    /// scatter form, compare-and-swap or native).
    pub fn scatters(self) -> bool {
        self != Accumulate::Gather
    }
}

/// Floating-point precision of the device computation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// 32-bit floats (default).
    #[default]
    F32,
    /// 64-bit floats (needs cl_khr_fp64; atomic accumulation also needs
    /// cl_khr_int64_base_atomics). Build option `-DSC_DOUBLE` (`REAL` =
    /// `double` in `kernels/common/real.h`).
    F64,
}

impl Precision {
    /// Both precisions, in the order of tables and benches.
    pub const ALL: [Precision; 2] = [Precision::F32, Precision::F64];

    /// The name used on the command line (`--precision`), in stats and bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }

    /// Bytes of one device real (`REAL` in the kernels).
    pub fn bytes(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }
}

/// Which least-squares solve and ordering to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Compat {
    /// The exact solve of the per-face normal equations; k1 ≥ k2 (signed).
    #[default]
    Exact,
    /// trimesh2 2.16: its 3×3 LDLᵀ pivot quirk and |k1| ≥ |k2| ordering, for
    /// comparing with that library directly. Build option `-DSC_COMPAT`.
    Trimesh2,
}

impl Compat {
    /// Both modes, in the order of tables and benches.
    pub const ALL: [Compat; 2] = [Compat::Exact, Compat::Trimesh2];

    /// The least squares a computation takes when none is given, the one
    /// place that decides it: trimesh2's where any of rtsc's line families
    /// is drawn (rtsc computes its lines from trimesh2's curvature, and the
    /// exact solve moves them on thin triangles and flat patches:
    /// `docs/lines.md`), the exact solve where curvature is the result
    /// (curvature as data, its colours, ambient occlusion), whose `k1 ≥
    /// k2` is signed and whose values are closer to the analytic ones.
    pub fn default_for(draws_rtsc_lines: bool) -> Compat {
        if draws_rtsc_lines {
            Compat::Trimesh2
        } else {
            Compat::Exact
        }
    }

    /// The name used on the command line (`--compat`), in stats and bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Compat::Exact => "exact",
            Compat::Trimesh2 => "trimesh2",
        }
    }
}

/// The accumulation scheme as a caller asks for it: `Auto` (the library's
/// default, decided in one place, [`AccumulateChoice::resolve`]) or a scheme.
/// The command line (`--accumulate auto`), scene files, Python
/// (`accumulate="auto"`) and `shapecue build-kernels` pass this on; only
/// the library resolves it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AccumulateChoice {
    /// The library's default scheme ([`Accumulate::default`]; see
    /// [`Accumulate::why_default`]).
    #[default]
    Auto,
    /// This scheme.
    Use(Accumulate),
}

impl AccumulateChoice {
    /// Every choice, in the order `--help` lists them.
    pub const ALL: [AccumulateChoice; 4] = [
        AccumulateChoice::Auto,
        AccumulateChoice::Use(Accumulate::Atomic),
        AccumulateChoice::Use(Accumulate::AtomicNative),
        AccumulateChoice::Use(Accumulate::Gather),
    ];

    /// `auto`, or the scheme's name.
    pub fn name(self) -> &'static str {
        match self {
            AccumulateChoice::Auto => "auto",
            AccumulateChoice::Use(a) => a.name(),
        }
    }

    /// The scheme to run: the one place where `Auto` is decided.
    pub fn resolve(self) -> Accumulate {
        match self {
            AccumulateChoice::Auto => Accumulate::default(),
            AccumulateChoice::Use(a) => a,
        }
    }

    /// Why [`resolve`](Self::resolve) gives its scheme, as `--stats` says it.
    pub fn why(self) -> &'static str {
        match self {
            AccumulateChoice::Auto => Accumulate::why_default(),
            AccumulateChoice::Use(_) => "as asked for",
        }
    }
}

impl From<Accumulate> for AccumulateChoice {
    fn from(a: Accumulate) -> Self {
        AccumulateChoice::Use(a)
    }
}

super::named_choice!(AccumulateChoice, "accumulation");
super::named_choice!(Accumulate, "accumulation");
super::named_choice!(Precision, "precision");
super::named_choice!(Compat, "compat mode");

/// Variant choice for curvature estimation (device and CPU reference alike).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct CurvatureOptions {
    /// One-ring accumulation scheme (device only; the CPU reference is sequential).
    pub accumulate: Accumulate,
    /// Device precision (the CPU reference is always f64).
    pub precision: Precision,
    /// Exact solve or trimesh2 compatibility.
    pub compat: Compat,
    /// Compute the curvature derivative (the dcurv pass).
    pub dcurv: bool,
    /// Faces per work-item of the per-face kernels (and vertices per
    /// work-item of the frame and principal kernels), as explicit SIMD
    /// lanes: by device type ([`Lanes::Auto`], resolved by
    /// [`face_lanes_for`]), or 1, 2, 4, 8 or 16. The gather variant gives
    /// the same bits for every count, the atomic variants the same values
    /// up to the rounding of their sums. A mesh already on the device
    /// (`CurvatureEstimator::from_device`) always runs with 1.
    pub lanes: Lanes,
}

/// The face lanes asked for: by device type, or a count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Lanes {
    /// The device type's count ([`face_lanes_for`], [`why_face_lanes`]).
    #[default]
    Auto,
    /// This many (1, 2, 4, 8 or 16; the estimator refuses others).
    Fixed(u32),
}

impl Lanes {
    /// Every choice, in the order `--help` lists them.
    pub const ALL: [Lanes; 6] = [
        Lanes::Auto,
        Lanes::Fixed(1),
        Lanes::Fixed(2),
        Lanes::Fixed(4),
        Lanes::Fixed(8),
        Lanes::Fixed(16),
    ];

    /// `auto`, or the count (`other` for a count the estimator refuses).
    pub fn name(self) -> &'static str {
        match self {
            Lanes::Auto => "auto",
            Lanes::Fixed(1) => "1",
            Lanes::Fixed(2) => "2",
            Lanes::Fixed(4) => "4",
            Lanes::Fixed(8) => "8",
            Lanes::Fixed(16) => "16",
            Lanes::Fixed(_) => "other",
        }
    }
}

/// Stats and bench ids write the count as before: 0 for `auto`.
impl serde::Serialize for Lanes {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_u32(match self {
            Lanes::Auto => 0,
            Lanes::Fixed(n) => *n,
        })
    }
}

super::named_choice!(Lanes, "face lane count");

impl CurvatureOptions {
    /// Every combination of the given schemes, precisions and least-squares
    /// variants (in that nesting order), with `lanes` and the derivative on:
    /// what `shapecue build-kernels` and the Python `build_kernels` build.
    pub fn combinations(
        accumulate: &[Accumulate],
        precision: &[Precision],
        compat: &[Compat],
        lanes: Lanes,
    ) -> Vec<CurvatureOptions> {
        let mut v = Vec::with_capacity(accumulate.len() * precision.len() * compat.len());
        for &accumulate in accumulate {
            for &precision in precision {
                for &compat in compat {
                    v.push(CurvatureOptions {
                        accumulate,
                        precision,
                        compat,
                        dcurv: true,
                        lanes,
                    });
                }
            }
        }
        v
    }
}

impl Default for CurvatureOptions {
    fn default() -> Self {
        CurvatureOptions {
            accumulate: Accumulate::default(),
            precision: Precision::F32,
            compat: Compat::Exact,
            dcurv: true,
            lanes: Lanes::Auto,
        }
    }
}

/// The similarity that maps a pose to unit size at the origin before it is
/// computed on: p' = (p − center) / scale. Curvature is invariant in shape, so
/// results are mapped back exactly (k / scale, area · scale², dk / scale²).
/// This keeps f32 meaningful for meshes far from the origin (1e6 away) and at
/// extreme scales (1e-6, 1e6), and makes the degenerate-face thresholds
/// relative to the mesh's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalization {
    /// Centroid of the vertices.
    pub center: [f64; 3],
    /// RMS distance of the vertices from the centroid (1 if that is 0).
    pub scale: f64,
}

impl Normalization {
    /// Computes the normalization of a set of positions (in f64).
    pub fn of(positions: &[[f64; 3]]) -> Self {
        Self::of_masked(positions, None)
    }

    /// The normalization of the positions whose `mask` entry is true (all if
    /// `None`): stages pass the vertices that faces reference, so a stray
    /// unreferenced vertex far away cannot shrink the mesh to nothing.
    pub fn of_masked(positions: &[[f64; 3]], mask: Option<&[bool]>) -> Self {
        let used = |i: usize| mask.is_none_or(|m| m[i]);
        let mut n = 0usize;
        let mut c = [0.0; 3];
        for (_, p) in positions.iter().enumerate().filter(|(i, _)| used(*i)) {
            n += 1;
            for k in 0..3 {
                c[k] += p[k];
            }
        }
        let c = c.map(|x| x / n.max(1) as f64);
        let mut ss = 0.0;
        for (_, p) in positions.iter().enumerate().filter(|(i, _)| used(*i)) {
            ss += (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2);
        }
        let s = (ss / n.max(1) as f64).sqrt();
        Normalization {
            center: c,
            scale: if s > 0.0 && s.is_finite() { s } else { 1.0 },
        }
    }

    /// Maps a position into normalized coordinates.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let inv = 1.0 / self.scale;
        [
            (p[0] - self.center[0]) * inv,
            (p[1] - self.center[1]) * inv,
            (p[2] - self.center[2]) * inv,
        ]
    }

    /// Maps a field computed on normalized positions back to the original scale.
    pub fn unapply(&self, f: &mut CurvatureField) {
        let s = self.scale;
        f.areas.iter_mut().for_each(|a| *a *= s * s);
        f.k1.iter_mut().for_each(|k| *k /= s);
        f.k2.iter_mut().for_each(|k| *k /= s);
        f.dk.iter_mut().flatten().for_each(|d| *d /= s * s);
    }
}

/// Counts of what the estimator had to skip; all zero on a clean mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct CurvatureCounts {
    /// Faces skipped as degenerate (zero-length edge or (near) zero area).
    pub degenerate_faces: u32,
    /// Vertices with no non-degenerate face (unreferenced or only degenerate
    /// faces): normal (0,0,1) unless faces give one, zero curvature.
    pub vertices_without_curvature: u32,
    /// Faces whose curvature least-squares system had a non-positive pivot.
    pub tensor_solves_skipped: u32,
    /// Faces whose derivative least-squares system had a non-positive pivot.
    pub dcurv_solves_skipped: u32,
}

impl CurvatureCounts {
    /// True when at least half of the `n_faces` faces were skipped as
    /// degenerate: the result is then mostly zeros and the caller should say
    /// so loudly (the usual causes: a mesh far from the origin computed in
    /// f32, or a mesh of slivers).
    pub fn mostly_degenerate(&self, n_faces: usize) -> bool {
        n_faces > 0 && 2 * self.degenerate_faces as usize >= n_faces
    }
}

/// What one curvature run gives (the front door's `shapecue::curvature` and
/// its CPU twin `cpu::curvature::curvature`): the field, what was skipped,
/// and how long it took.
#[derive(Clone, Debug)]
pub struct Curvature {
    /// Per-vertex outputs.
    pub field: CurvatureField,
    /// Skip counters.
    pub counts: CurvatureCounts,
    /// Kernel ms per step and the run's wall ms (mesh already on the
    /// device), and the phase `topology` (building the one-rings or owning
    /// faces, and any memory reorder; absent for the twin); for the CPU
    /// twin, the wall ms of the whole reference run.
    pub timing: crate::spec::timing::Timing,
    /// Device bytes allocated; 0 for the twin.
    pub device_bytes: u64,
}

/// Relative area threshold of the degenerate-face rule, × Σ edge²
/// (`DEGEN_AREA_REL` in `kernels/curvature.cl`).
pub const DEGEN_AREA_REL: f64 = 5e-8;
/// Squared edge-length threshold in normalized coordinates (`DEGEN_EDGE2`).
pub const DEGEN_EDGE2: f64 = 1e-24;
/// Heights below this × (|p0| + |p1| + |p2|) (normalized coordinates) are
/// under the f32 rounding of the positions (2⁻²³): degenerate when computing
/// in f32 (`DEGEN_HEIGHT_ULP` in `kernels/curvature.cl` without `SC_DOUBLE`).
pub const DEGEN_HEIGHT_ULP: f64 = 1.0 / 8_388_608.0;
/// The same for f64 (2⁻⁵²; `DEGEN_HEIGHT_ULP` with `SC_DOUBLE`). A face is
/// judged by the rounding of the precision it is computed in: two unit
/// spheres 10⁶ apart are well resolved in f64 but not in f32.
pub const DEGEN_HEIGHT_ULP_F64: f64 = f64::EPSILON;

/// The height threshold of the degenerate-face rule at a precision.
pub fn degen_height_ulp(p: Precision) -> f64 {
    match p {
        Precision::F32 => DEGEN_HEIGHT_ULP,
        Precision::F64 => DEGEN_HEIGHT_ULP_F64,
    }
}

/// Entries of the one-ring lists of a mesh with `nf` faces (one per face
/// corner; their CSR offsets have `nv + 1` entries): the `ring` buffer of the
/// gather variant.
pub fn one_ring_len_bound(nf: usize) -> usize {
    3 * nf
}

/// The most faces one work-item of the per-face kernels handles (`SC_LANES`
/// in `kernels/curvature.cl`).
pub const MAX_FACE_LANES: u32 = 16;

/// Faces the gather variant's buffers are sized for: `nf` rounded up to whole
/// blocks of [`MAX_FACE_LANES`] (a block's lanes past the last face write
/// into this padding).
pub fn padded_faces(nf: usize) -> usize {
    nf.div_ceil(MAX_FACE_LANES as usize) * MAX_FACE_LANES as usize
}

/// Vertices the per-vertex buffers are sized for: `nv` rounded up to whole
/// blocks of [`MAX_FACE_LANES`] (the per-vertex kernels with lanes read and
/// write whole blocks).
pub fn padded_vertices(nv: usize) -> usize {
    nv.div_ceil(MAX_FACE_LANES as usize) * MAX_FACE_LANES as usize
}

/// Reals per vertex record of the gather scheme with face lanes (the
/// `REC_*` layout of kernels/common/curvature_lanes.h: position and point area, normal
/// and k1, first direction and k2, second direction), read by the tensor and
/// derivative face kernels as whole vectors.
pub const REC_REALS: usize = 16;

/// Reals of the gather variant's corner buffer for `nf` faces: 4 per corner
/// (the widest pass, the derivative tensor), 12 per face, for
/// [`padded_faces`] faces.
pub fn corner_reals_bound(nf: usize) -> usize {
    12 * padded_faces(nf)
}

/// Reals of the gather scheme's corner areas (then weights): 3 per face,
/// for [`padded_faces`] faces.
pub fn corner_weights_bound(nf: usize) -> usize {
    3 * padded_faces(nf)
}

/// Faces per work-item of the per-face kernels on a device (either scheme):
/// `requested` when not 0, else by device type (the rule the estimator uses;
/// `native_width` is the device's `CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT` or
/// `_DOUBLE` for the precision):
/// - **CPU devices: the native vector width** (8 floats for AVX2, 16 for
///   AVX-512), so that each face kernel's arithmetic is SIMD code whatever
///   the runtime's own work-item vectoriser does (PoCL 3.1 leaves these
///   kernels scalar; see `kernels/curvature.cl`).
/// - **Other devices (GPUs): 1**, one face per work-item: a GPU's SIMD runs
///   across work-items already.
///
/// The count is rounded down to a power of two and clamped to
/// 1..=[`MAX_FACE_LANES`]. The results are the same for every count.
pub fn face_lanes_for(requested: Lanes, device_kind: &str, native_width: u32) -> u32 {
    let n = face_lanes_unclamped(requested, device_kind, native_width);
    let n = n.clamp(1, MAX_FACE_LANES);
    1 << (31 - n.leading_zeros())
}

/// Why [`face_lanes_for`] picks its count when none is requested (printed by
/// `--stats`).
pub fn why_face_lanes(device_kind: &str) -> &'static str {
    if device_kind.eq_ignore_ascii_case("CPU") {
        "the device's native float vector width: a CPU runtime runs one \
         work-item per SIMD lane group, so several faces per work-item fill its lanes"
    } else {
        "1: a GPU's work-items are its lanes already"
    }
}

fn face_lanes_unclamped(requested: Lanes, device_kind: &str, native_width: u32) -> u32 {
    match requested {
        Lanes::Auto if device_kind.eq_ignore_ascii_case("CPU") => native_width,
        Lanes::Auto => 1,
        Lanes::Fixed(n) => n,
    }
}

/// Bytes of device memory the curvature estimator allocates for a mesh, by
/// variant and face lanes (the same arithmetic as its allocations): more
/// than one lane adds [`REC_REALS`] reals per vertex of vertex records.
pub fn device_bytes_bound(nv: usize, nf: usize, opts: &CurvatureOptions, lanes: u32) -> u64 {
    let r = opts.precision.bytes() as u64;
    let (nv, nf) = (nv.max(1), nf.max(1));
    // pos, nrm, pd1, pd2, tens: 3 reals; area: 1; kk: 2; dk: 4  → 20 reals per
    // vertex, for whole blocks of vertices
    let per_vertex = 20 * r + 4; // + owner
    let per_face = 12;
    // (faces in whole blocks, + one real of padding past the positions, + the
    // counters)
    let mut b =
        padded_vertices(nv) as u64 * per_vertex + padded_faces(nf) as u64 * per_face + r + 16;
    if opts.accumulate == Accumulate::Gather {
        // one-ring CSR, 4 reals per face corner, 1 corner weight per corner
        b += (nv as u64 + 1) * 4
            + one_ring_len_bound(nf) as u64 * 4
            + (corner_reals_bound(nf) + corner_weights_bound(nf)) as u64 * r;
    }
    if lanes > 1 {
        b += padded_vertices(nv) as u64 * REC_REALS as u64 * r;
    }
    b
}

crate::spec::kernels::kernel_entries! {
    /// The entry points of `kernels/curvature.cl` and the scheme file it
    /// includes (`curvature_atomic.cl` or, with `SC_GATHER`,
    /// `curvature_gather.cl`).
    pub enum CurvKernel {
        /// Owning face per vertex (atomic_max).
        MaxFace = "curv_max_face",
        /// The accumulators zeroed (atomic schemes).
        Clear = "curv_clear",
        /// Corner-weighted normals and Voronoi point areas, added with atomics.
        NormalsAreas = "curv_normals_areas",
        /// The same per face corner, written for the ring sums (gather).
        NormalsAreasCorners = "curv_normals_areas_corners",
        /// Each vertex's one-ring of normal and area corners summed (gather).
        NormalsAreasSum = "curv_normals_areas_sum",
        /// Unit normals and the initial per-vertex frames.
        Frames = "curv_frames",
        /// Per-face curvature tensors added into the vertex frames (atomics).
        Tensor = "curv_tensor",
        /// The same per face corner (gather).
        TensorCorners = "curv_tensor_corners",
        /// Each vertex's one-ring of tensor corners summed (gather).
        TensorSum = "curv_tensor_sum",
        /// Diagonalisation: k1, k2, d1, d2.
        Principal = "curv_principal",
        /// The curvature derivative, added with atomics.
        Dcurv = "curv_dcurv",
        /// The same per face corner (gather).
        DcurvCorners = "curv_dcurv_corners",
        /// Each vertex's one-ring of derivative corners summed (gather).
        DcurvSum = "curv_dcurv_sum",
        /// Vertices left without a usable face, counted.
        CountEmpty = "curv_count_empty",
        /// Corners per vertex counted, for the one-ring lists on the device (gather).
        RingCount = "curv_ring_count",
        /// Each corner into its vertex's one-ring list (gather).
        RingFill = "curv_ring_fill",
        /// Each one-ring list in face order, and the owner faces (gather).
        RingOrder = "curv_ring_order",
        /// Positions from a device buffer (isosurfaces) into the records.
        LoadPositions = "curv_load_positions",
        /// Vertex normals given by the caller (gradient normals) over the computed ones.
        OverrideNormals = "curv_override_normals",
    }
}
