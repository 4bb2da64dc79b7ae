//! The scene file as written: the TOML tables, deserialized with their
//! spans (serde through the `toml` crate), before the cross-field checks of
//! [`Scene::from_str`](super::Scene::from_str). Every table rejects unknown
//! keys.

use serde::{Deserialize, Deserializer};
use toml::Spanned;

/// An optional fixed-length array that must have exactly `N` entries:
/// `size = [64, 64, 64]` is an error at its line, not a silent `[64, 64]`.
fn exact<'de, D, T, const N: usize>(d: D) -> Result<Option<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let v: Option<Vec<T>> = Option::deserialize(d)?;
    v.map(|v| {
        let n = v.len();
        <[T; N]>::try_from(v)
            .map_err(|_| serde::de::Error::custom(format!("expected {N} numbers, found {n}")))
    })
    .transpose()
}

/// The scene file as written (after syntax and type checks, before the
/// cross-field checks of [`Scene::from_str`](super::Scene::from_str)).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Where the geometry comes from.
    pub input: Spanned<InputSpec>,
    /// Which frames to render.
    #[serde(default)]
    pub frames: Option<Spanned<FramesSpec>>,
    /// Cameras (`[[camera]]` tables).
    #[serde(default, rename = "camera")]
    pub cameras: Vec<Spanned<CameraSpec>>,
    /// The cues.
    pub effects: Spanned<EffectsSpec>,
    /// Images and report.
    #[serde(default)]
    pub output: Option<Spanned<OutputSpec>>,
    /// How curvature is computed (scheme, precision, least squares).
    #[serde(default)]
    pub curvature: Option<CurvatureSpec>,
    /// What every line family shares (feature size, tests, Hermite).
    #[serde(default)]
    pub lines: Option<Spanned<LinesSpec>>,
}

/// `[lines]`: the settings every line family shares.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinesSpec {
    /// `"rtsc"` (default), `"edge"` or a length.
    pub feature_size: Option<toml::Value>,
    /// rtsc's tests (default true).
    pub test: Option<bool>,
    /// rtsc's Hermite placement of suggestive contours and highlights.
    pub hermite: Option<bool>,
    /// Hermite placement of K = 0 and H = 0.
    pub hermite_kh: Option<bool>,
    /// `"auto"` (default), `"on"` or `"off"`: hysteresis over an
    /// animation's frames.
    pub coherence: Option<Spanned<String>>,
    /// The hysteresis' lower threshold, a fraction of each threshold.
    pub coherence_low: Option<f32>,
    /// The delay of births in frames (0, 1 or 2).
    pub coherence_birth: Option<u32>,
    /// The band of the signs of K and H, in units of the feature size.
    pub coherence_band: Option<f32>,
}

/// `[curvature]`: the estimator's options, by their command-line names.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurvatureSpec {
    /// `"gather"` (default), `"atomic"` or `"atomic-native"`.
    pub accumulate: Option<Spanned<String>>,
    /// `"f32"` (default) or `"f64"`.
    pub precision: Option<Spanned<String>>,
    /// `"exact"` (default) or `"trimesh2"`.
    pub compat: Option<Spanned<String>>,
}

/// `[input]`: exactly one of the source keys.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputSpec {
    /// A static mesh file (OBJ, PLY, OFF).
    pub mesh: Option<Spanned<String>>,
    /// Several static mesh files drawn as one scene (their faces
    /// concatenated; intersection lines are where faces of different files
    /// cross).
    pub meshes: Option<Spanned<Vec<String>>>,
    /// A generated mesh: torus, sphere, ellipsoid, cylinder or plane.
    pub generate: Option<Spanned<String>>,
    /// Vertex count of a generated mesh, or grid resolution of an SDF (default 40000 / 128).
    pub resolution: Option<usize>,
    /// A glTF 2.0 file with a skin and animations.
    pub gltf: Option<Spanned<String>>,
    /// The glTF clip: index or name (default 0).
    pub clip: Option<Spanned<ClipRef>>,
    /// A glob of OBJ/PLY frames with one topology, in natural order.
    pub flipbook: Option<Spanned<String>>,
    /// A libigl LBS set: `<stem>.obj` with `<stem>.tgf`, `<stem>-weights.dmat`, `<stem>-anim.dmat`.
    pub lbs: Option<Spanned<String>>,
    /// A volume file (NRRD, MetaImage, VTK, VTI, SLC) to extract an isosurface of.
    pub volume: Option<Spanned<String>>,
    /// A procedural signed distance field: sphere, torus or gyroid.
    pub sdf: Option<Spanned<String>>,
    /// Isovalue (volume: required; SDF: default 0).
    pub iso: Option<f32>,
    /// Which side of the isovalue is the object: `above` (density data such
    /// as CT or electron density; the default for volume files) or `below`
    /// (distance fields; the default for SDFs). Normals point out of the
    /// object, so convex parts of it have positive curvature.
    pub inside: Option<Spanned<String>>,
    /// Weld coincident vertices of mesh, flipbook, glTF and libigl inputs
    /// (skinned vertices keep the weights of the first of those merged).
    #[serde(default)]
    pub weld: bool,
    /// Which vertex normals a mesh file's curvature starts from: `file`
    /// (those it stores, as trimesh2 and rtsc use them; the default) or
    /// `computed` (from the faces).
    pub normals: Option<Spanned<String>>,
}

/// A glTF clip by index or by name.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(try_from = "toml::Value")]
pub enum ClipRef {
    /// The clip's index.
    Index(usize),
    /// The clip's name.
    Name(String),
}

impl TryFrom<toml::Value> for ClipRef {
    type Error = String;
    fn try_from(v: toml::Value) -> Result<ClipRef, String> {
        match v {
            toml::Value::String(s) => Ok(ClipRef::Name(s)),
            toml::Value::Integer(i) if i >= 0 => Ok(ClipRef::Index(i as usize)),
            other => Err(format!(
                "clip = {other}: expected a clip's index (a whole number of 0 or more) or its \
                 name in quotes"
            )),
        }
    }
}

/// `[frames]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FramesSpec {
    /// First frame (inclusive).
    #[serde(default)]
    pub start: usize,
    /// Last frame (exclusive); default: the whole animation (1 for a static input).
    pub end: Option<usize>,
    /// Frame step (≥ 1).
    #[serde(default = "one")]
    pub step: usize,
    /// Frames per second for glTF clips (t = frame / fps).
    #[serde(default = "thirty")]
    pub fps: f32,
}

fn one() -> usize {
    1
}
fn thirty() -> f32 {
    30.0
}

impl Default for FramesSpec {
    fn default() -> Self {
        FramesSpec {
            start: 0,
            end: None,
            step: 1,
            fps: 30.0,
        }
    }
}

/// `[[camera]]`: an explicit eye, a fitted direction, or an orbit of fitted views.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position (explicit camera).
    #[serde(default, deserialize_with = "exact")]
    pub eye: Option<[f32; 3]>,
    /// Look-at point (default: the centre of the first pose's bounds).
    #[serde(default, deserialize_with = "exact")]
    pub target: Option<[f32; 3]>,
    /// Up vector (default +Y).
    #[serde(default, deserialize_with = "exact")]
    pub up: Option<[f32; 3]>,
    /// Direction from the centre towards the eye of a fitted camera.
    #[serde(default, deserialize_with = "exact")]
    pub direction: Option<[f32; 3]>,
    /// Number of fitted views evenly spaced around the up axis.
    pub orbit: Option<usize>,
    /// Orbit elevation above the horizon, degrees (default 20).
    pub elevation: Option<f32>,
    /// Azimuth of the first orbit view, degrees (default 0: looking down −Z... from +Z).
    pub azimuth: Option<f32>,
    /// Vertical field of view, degrees (default 35).
    pub fov: Option<f32>,
    /// Orthographic projection.
    #[serde(default)]
    pub ortho: bool,
}

/// `[effects]`: each present table is a cue.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectsSpec {
    /// Plain Lambert shading.
    pub shading: Option<ShadingSpec>,
    /// Curvature colours.
    pub curvature_colors: Option<CurvatureColorSpec>,
    /// Ambient occlusion from curvature (Lambert × AO).
    pub ao: Option<AoSpec>,
    /// Occluding contours.
    pub contours: Option<LineSpec>,
    /// Suggestive contours.
    pub suggestive_contours: Option<SuggestiveSpec>,
    /// Feature edges with caps.
    pub feature_edges: Option<EdgeSpec>,
    /// Intersection lines: where faces cross (Line Art's "intersection").
    pub intersection_lines: Option<LineSpec>,
    /// Curvature-directed strokes (volume inputs only).
    pub curvature_strokes: Option<StrokeSpec>,
    /// Ridges.
    pub ridges: Option<ThresholdLineSpec>,
    /// Valleys.
    pub valleys: Option<ThresholdLineSpec>,
    /// Apparent ridges.
    pub apparent_ridges: Option<ThresholdLineSpec>,
    /// Suggestive highlights.
    pub suggestive_highlights: Option<ThresholdLineSpec>,
    /// Principal highlights.
    pub principal_highlights: Option<ThresholdLineSpec>,
    /// Isophotes.
    pub isophotes: Option<IsophoteSpec>,
    /// Parabolic lines, K = 0.
    pub k_zero: Option<PlainLineSpec>,
    /// Lines of zero mean curvature, H = 0.
    pub h_zero: Option<PlainLineSpec>,
    /// D_w κr = 0.
    pub dwkr_zero: Option<PlainLineSpec>,
    /// Mesh boundaries as a line family.
    pub boundaries: Option<PlainLineSpec>,
}

/// `[effects.shading]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadingSpec {
    /// Base colour (default light grey).
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
    /// Ambient term in [0, 1] (default 0.15).
    pub ambient: Option<f32>,
}

/// `[effects.curvature_colors]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurvatureColorSpec {
    /// Curvature (world units⁻¹) at which colours are 76 % saturated (tanh 1);
    /// default: the 90th percentile of |k| on the first pose.
    pub scale: Option<f32>,
}

/// `[effects.ao]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AoSpec {
    /// `poly` (seed polynomial), `lut` (table, default) or `exact` (integral per vertex).
    pub level: Option<Spanned<String>>,
    /// Hemisphere radius as a fraction of the first pose's bounding-box diagonal (default 0.02).
    pub radius: Option<f32>,
}

/// `[effects.contours]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineSpec {
    /// Line width in pixels (default 2).
    pub width: Option<f32>,
    /// RGB (default black).
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
}

/// `[effects.suggestive_contours]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuggestiveSpec {
    /// Line width in pixels (default 1.5).
    pub width: Option<f32>,
    /// RGB (default dark grey).
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
    /// Dimensionless threshold (default 0.05; see `LineOptions`).
    pub threshold: Option<f32>,
    /// n·v fade (default 0.2).
    pub fade: Option<f32>,
}

/// `[effects.feature_edges]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EdgeSpec {
    /// Width in pixels (default 3).
    pub width: Option<f32>,
    /// RGB (default black).
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
    /// Crease angle in degrees, (0, 180]; 180 turns creases off (default 30).
    pub crease: Option<f32>,
    /// `none`, `mh` or `adjacency` (default).
    pub caps: Option<Spanned<String>>,
    /// Detect contour edges (default true).
    pub contours: Option<bool>,
    /// Draw boundary edges (default true).
    pub boundaries: Option<bool>,
    /// Depth scale k of the width factor max(1, k/w) (default: none).
    pub depth_scale: Option<f32>,
    /// Contour-only edges as half quads, outward from the silhouette.
    pub half_contours: Option<bool>,
    /// A text file of marked edges (vertex-index pairs), relative to the
    /// scene file.
    pub marked: Option<Spanned<String>>,
}

/// `[effects.curvature_strokes]`: Interrante-style strokes along the first
/// principal direction of a volume's isosurface. Lengths are world units;
/// the defaults are multiples of the Hessian sampling distance h
/// (`crate::spec::sdf_lines`).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrokeSpec {
    /// Poisson-disk seed spacing r (default 1.5 h).
    pub spacing: Option<f64>,
    /// Hessian sampling distance: `"auto"` (default: the candidate whose
    /// coefficient of variation of κ1 is closest to 1) or a distance.
    pub sampling: Option<Spanned<SamplingSpec>>,
    /// RGB (default near black).
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
    /// Stroke width at the largest κ1 (default 0.4 h).
    pub width: Option<f64>,
}

/// `sampling = "auto"` or `sampling = 0.03`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum SamplingSpec {
    /// A distance in world units.
    Distance(f64),
    /// A word (only `auto` is accepted).
    Word(String),
}

/// `[output]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Output folder (default `out/<scene name>`, relative to the working directory).
    pub dir: Option<String>,
    /// File name prefix (default: the scene file's stem).
    pub name: Option<String>,
    /// Image size (default 640 × 480).
    #[serde(default, deserialize_with = "exact")]
    pub size: Option<[u32; 2]>,
    /// `png` and/or `svg` (lines only) (default `["png"]`).
    pub formats: Option<Spanned<Vec<String>>>,
    /// Multisampling: 0, 2, 4 or 8 (default 4).
    pub msaa: Option<u32>,
    /// Background RGB (default white).
    #[serde(default, deserialize_with = "exact")]
    pub background: Option<[f32; 3]>,
    /// How feature edges reach GL: `off` (default), `auto` or `on`.
    pub interop: Option<Spanned<String>>,
    /// How an SVG's hidden lines are found: `exact` (default) or `depth`.
    pub visibility: Option<Spanned<String>>,
}

/// `[effects.ridges]`, `valleys`, `apparent_ridges`, `suggestive_highlights`
/// and `principal_highlights`: the families with a threshold.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThresholdLineSpec {
    /// Line width in pixels.
    pub width: Option<f32>,
    /// RGB.
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
    /// Dimensionless threshold, times the mesh's feature size.
    pub threshold: Option<f32>,
    /// Strength (opacity) fades with the test's margin (default true).
    pub fade: Option<bool>,
    /// Back-face culling (default true).
    pub cull: Option<bool>,
    /// Hidden parts in the SVG: `remove` (default), `faded` or `dashed`.
    pub hidden: Option<String>,
}

/// `[effects.isophotes]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsophoteSpec {
    /// Line width in pixels.
    pub width: Option<f32>,
    /// RGB.
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
    /// Levels n·l = j / count for |j| < count (default 20).
    pub count: Option<u32>,
    /// Direction towards the light, world coordinates (default +Z).
    #[serde(default, deserialize_with = "exact")]
    pub light: Option<[f32; 3]>,
    /// Strength fades (default true).
    pub fade: Option<bool>,
    /// Back-face culling (default true).
    pub cull: Option<bool>,
    /// Hidden parts in the SVG.
    pub hidden: Option<String>,
}

/// `[effects.k_zero]`, `h_zero`, `dwkr_zero` and `boundaries`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlainLineSpec {
    /// Line width in pixels.
    pub width: Option<f32>,
    /// RGB.
    #[serde(default, deserialize_with = "exact")]
    pub color: Option<[f32; 3]>,
    /// Strength fades (default true).
    pub fade: Option<bool>,
    /// Back-face culling (default true).
    pub cull: Option<bool>,
    /// Hidden parts in the SVG.
    pub hidden: Option<String>,
}
