//! Scene files (TOML, read with serde through the `toml` crate): what to
//! draw, from where, which cues, and where the images go.
//!
//! ```toml
//! [input]                      # exactly one source
//! gltf = "../data/BrainStem.glb"   # or mesh = "bunny.obj", generate = "torus",
//! clip = 0                         # flipbook = "frames/hand_*.obj", lbs = "elephant.obj",
//!                                  # volume = "bucky.nhdr" + iso = 51, sdf = "gyroid"
//! [frames]
//! start = 0                    # first frame (inclusive)
//! end = 60                     # last frame (exclusive); default: the whole animation
//! step = 2
//! fps = 30                     # glTF clips are sampled at t = frame / fps
//!
//! [[camera]]                   # any number; none: one fitted view
//! orbit = 8                    # 8 fitted views around the up axis
//! elevation = 20               # degrees above the horizon
//!
//! [[camera]]
//! eye = [0, 1, 4]              # an explicit camera (target defaults to the centre)
//! fov = 35
//! ortho = true
//!
//! [effects]                    # the cues: only their passes run
//! shading = {}
//! curvature_colors = { scale = 2.0 }
//! ao = { level = "lut", radius = 0.05 }
//! contours = { width = 2 }
//! suggestive_contours = { threshold = 0.01, fade = 0.03 }
//! feature_edges = { crease = 30, caps = "adjacency" }
//! curvature_strokes = { spacing = 0.05, sampling = "auto", color = [0.1, 0.1, 0.2], width = 0.01 }
//!                              # volume and sdf inputs only
//! ridges = { threshold = 0.1 } # and every other line family of rtsc: see [`lines`]
//!
//! [output]
//! dir = "out/brainstem"        # `--out DIR` on the command line overrides it
//! size = [640, 480]
//! formats = ["png", "svg"]
//! ```
//!
//! Every table rejects unknown keys, and every error (syntax, unknown key,
//! wrong type, a missing or second source, a missing file) names the scene
//! file and the line. Relative paths are relative to the scene file.

use crate::error::{Error, Result};
use crate::scene::planner::{Cue, Input};
use crate::spec::ao::AoMode;
use crate::spec::curvature::CurvatureOptions;
use crate::spec::edges::CapMode;
use crate::spec::feature_lines::FeatureSize;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

mod effects;
mod held;
pub mod lines;
mod raw;
mod settings;
mod toml_words;

pub use effects::{Effects, StrokeEffect};
pub use held::{HeldMesh, HeldVolume, Shot};
pub use lines::{LineEffects, LineStyle};
pub use raw::{
    AoSpec, CameraSpec, ClipRef, CurvatureColorSpec, EdgeSpec, EffectsSpec, FramesSpec, InputSpec,
    IsophoteSpec, LineSpec, OutputSpec, PlainLineSpec, SamplingSpec, SceneFile, ShadingSpec,
    StrokeSpec, SuggestiveSpec, ThresholdLineSpec,
};
use toml_words::plain_toml_message;

/// Where a scene's geometry comes from, resolved.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// A mesh file.
    Mesh(PathBuf),
    /// A generated mesh (kind, vertex count).
    Generate(String, usize),
    /// A glTF skin and clip (`None`: clip 0, or the rest pose when the file
    /// has no animation).
    Gltf(PathBuf, Option<ClipRef>),
    /// A glob of frames.
    Flipbook(String),
    /// A libigl LBS set (the OBJ).
    Lbs(PathBuf),
    /// A volume file, isovalue, and whether the object is above the isovalue.
    Volume(PathBuf, f32, bool),
    /// An SDF (kind, resolution, isovalue, object above the isovalue).
    Sdf(String, usize, f32, bool),
    /// A mesh the caller holds (the front door's pictures).
    Held(HeldMesh),
    /// A volume the caller holds, its isovalue, object above the isovalue.
    HeldVolume(HeldVolume, f32, bool),
}

impl Source {
    /// The planner's input kind.
    pub fn input(&self) -> Input {
        match self {
            Source::Mesh(_) | Source::Generate(..) | Source::Held(_) => Input::Static,
            Source::Gltf(..) | Source::Lbs(_) => Input::Skinned,
            Source::Flipbook(_) => Input::Flipbook,
            Source::Volume(..) | Source::Sdf(..) | Source::HeldVolume(..) => Input::Volume,
        }
    }
}

/// A camera as the scene asks for it (fitted ones are resolved once the
/// first pose's bounds are known).
#[derive(Debug, Clone, PartialEq)]
pub enum CameraKind {
    /// Explicit eye; target `None` = the centre of the bounds.
    LookAt {
        /// Eye.
        eye: [f32; 3],
        /// Target.
        target: Option<[f32; 3]>,
    },
    /// Fitted to the bounds from a direction (centre → eye).
    Fit([f32; 3]),
}

/// One resolved view.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSpec {
    /// Position.
    pub kind: CameraKind,
    /// Up (default +Y).
    pub up: Option<[f32; 3]>,
    /// Vertical field of view in degrees.
    pub fov: f32,
    /// Orthographic.
    pub ortho: bool,
}

/// A checked scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The scene file.
    pub path: PathBuf,
    /// The scene's name (file stem).
    pub name: String,
    /// Geometry source.
    pub source: Source,
    /// Weld mesh files.
    pub weld: bool,
    /// First frame, end (exclusive; None = whole animation), step.
    pub frames: (usize, Option<usize>, usize),
    /// Frames per second of glTF sampling.
    pub fps: f32,
    /// Views, orbits expanded.
    pub views: Vec<ViewSpec>,
    /// Cues and their parameters.
    pub effects: Effects,
    /// Output folder.
    pub out_dir: PathBuf,
    /// File prefix.
    pub prefix: String,
    /// Image size.
    pub size: [u32; 2],
    /// Write PNG images.
    pub png: bool,
    /// Write SVG line drawings.
    pub svg: bool,
    /// MSAA samples.
    pub msaa: u32,
    /// Background.
    pub background: [f32; 3],
    /// The curvature estimator's scheme, precision and least squares
    /// (`[curvature]`; the derivative is on where a pass needs it).
    pub curvature: CurvatureOptions,
}

/// 1-based line and column of a byte offset.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

/// Checks a scene's cross-field rules with the text at hand for line numbers.
struct Checker<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Checker<'_> {
    fn err(&self, span: Range<usize>, problem: impl Into<String>) -> Error {
        let (l, c) = line_col(self.text, span.start);
        Error::input(
            self.path.display().to_string(),
            format!("line {l}, column {c}"),
            problem,
        )
    }

    /// A path relative to the scene file; it must exist.
    fn existing(&self, s: &Spanned<String>) -> Result<PathBuf> {
        let p = self.relative(s.get_ref());
        if !p.exists() {
            return Err(self.err(s.span(), format!("{} does not exist", p.display())));
        }
        Ok(p)
    }

    fn relative(&self, s: &str) -> PathBuf {
        let p = Path::new(s);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.path.parent().unwrap_or(Path::new("")).join(p)
        }
    }
}

fn positive(x: Option<f32>, default: f32, what: &str) -> std::result::Result<f32, String> {
    let v = x.unwrap_or(default);
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{what} must be a positive number, got {v}"))
    }
}

fn color(
    c: Option<[f32; 3]>,
    default: [f32; 3],
    what: &str,
) -> std::result::Result<[f32; 3], String> {
    let v = c.unwrap_or(default);
    if v.iter().all(|x| (0.0..=1.0).contains(x)) {
        Ok(v)
    } else {
        Err(format!("{what} {v:?}: components must be in [0, 1]"))
    }
}

impl Scene {
    /// Reads and checks a scene file.
    pub fn load(path: &Path) -> Result<Scene> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Scene::from_str(path, &text)
    }

    /// Parses and checks scene text; `path` names it in errors and anchors
    /// relative paths.
    pub fn from_str(path: &Path, text: &str) -> Result<Scene> {
        let ck = Checker { path, text };
        let file: SceneFile = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            ck.err(span, plain_toml_message(e.message().trim()))
        })?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into());

        // Input: exactly one source.
        let input_span = file.input.span();
        let inp = file.input.into_inner();
        let given: Vec<&str> = [
            ("mesh", inp.mesh.is_some()),
            ("generate", inp.generate.is_some()),
            ("gltf", inp.gltf.is_some()),
            ("flipbook", inp.flipbook.is_some()),
            ("lbs", inp.lbs.is_some()),
            ("volume", inp.volume.is_some()),
            ("sdf", inp.sdf.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, g)| g.then_some(k))
        .collect();
        if given.len() != 1 {
            return Err(ck.err(
                input_span,
                format!(
                    "[input] needs exactly one of mesh, generate, gltf, flipbook, lbs, volume, sdf; got {}",
                    if given.is_empty() {
                        "none".to_string()
                    } else {
                        given.join(", ")
                    }
                ),
            ));
        }
        let only = |key: &str, ok: bool| -> Result<()> {
            if ok {
                Ok(())
            } else {
                Err(ck.err(
                    input_span.clone(),
                    format!("`{key}` does not apply to a {} input", given[0]),
                ))
            }
        };
        only("clip", inp.clip.is_none() || inp.gltf.is_some())?;
        only(
            "iso",
            inp.iso.is_none() || inp.volume.is_some() || inp.sdf.is_some(),
        )?;
        only(
            "resolution",
            inp.resolution.is_none() || inp.generate.is_some() || inp.sdf.is_some(),
        )?;
        only(
            "inside",
            inp.inside.is_none() || inp.volume.is_some() || inp.sdf.is_some(),
        )?;
        let above = |default: bool| -> Result<bool> {
            match &inp.inside {
                None => Ok(default),
                Some(v) => match v.get_ref().as_str() {
                    "above" => Ok(true),
                    "below" => Ok(false),
                    other => Err(ck.err(
                        v.span(),
                        format!("inside = {other:?}: expected \"above\" or \"below\""),
                    )),
                },
            }
        };
        only(
            "weld",
            !inp.weld
                || inp.mesh.is_some()
                || inp.flipbook.is_some()
                || inp.gltf.is_some()
                || inp.lbs.is_some(),
        )?;
        let source = if let Some(m) = &inp.mesh {
            Source::Mesh(ck.existing(m)?)
        } else if let Some(g) = &inp.generate {
            use crate::mesh::GENERATED_NAMES as NAMES;
            if !NAMES.contains(&g.get_ref().as_str()) {
                let (got, want) = (g.get_ref(), crate::error::one_of(&NAMES));
                return Err(ck.err(g.span(), format!("generate = {got:?}: expected {want}")));
            }
            Source::Generate(g.get_ref().clone(), inp.resolution.unwrap_or(40_000))
        } else if let Some(g) = &inp.gltf {
            let clip = inp.clip.as_ref().map(|c| c.get_ref().clone());
            Source::Gltf(ck.existing(g)?, clip)
        } else if let Some(f) = &inp.flipbook {
            let pat = ck.relative(f.get_ref());
            Source::Flipbook(pat.to_string_lossy().into_owned())
        } else if let Some(l) = &inp.lbs {
            Source::Lbs(ck.existing(l)?)
        } else if let Some(v) = &inp.volume {
            let Some(iso) = inp.iso else {
                return Err(ck.err(v.span(), "a volume input needs `iso`"));
            };
            if !iso.is_finite() {
                return Err(ck.err(input_span, format!("iso {iso} must be finite")));
            }
            Source::Volume(ck.existing(v)?, iso, above(true)?)
        } else {
            let s = inp.sdf.as_ref().expect("one source is given");
            const KINDS: [&str; 3] = ["sphere", "torus", "gyroid"];
            if !KINDS.contains(&s.get_ref().as_str()) {
                let (got, want) = (s.get_ref(), crate::error::one_of(&KINDS));
                return Err(ck.err(s.span(), format!("sdf = {got:?}: expected {want}")));
            }
            let res = inp.resolution.unwrap_or(128);
            if !(4..=1024).contains(&res) {
                return Err(ck.err(
                    input_span,
                    format!("resolution {res}: an SDF grid needs 4..=1024 points per axis"),
                ));
            }
            Source::Sdf(
                s.get_ref().clone(),
                res,
                inp.iso.unwrap_or(0.0),
                above(false)?,
            )
        };
        if let Source::Generate(_, n) = &source
            && !(12..=20_000_000).contains(n)
        {
            return Err(ck.err(
                input_span,
                format!("resolution {n}: a generated mesh needs 12..=20000000 vertices"),
            ));
        }

        // Frames.
        let (frames, fps) = match &file.frames {
            None => ((0, None, 1), 30.0),
            Some(f) => {
                let s = f.get_ref();
                if s.step == 0 {
                    return Err(ck.err(f.span(), "frames.step must be at least 1"));
                }
                if let Some(e) = s.end
                    && e <= s.start
                {
                    return Err(ck.err(
                        f.span(),
                        format!("frames: end {e} must be greater than start {}", s.start),
                    ));
                }
                if !(s.fps.is_finite() && s.fps > 0.0) {
                    return Err(ck.err(f.span(), format!("frames.fps {} must be positive", s.fps)));
                }
                if source.input() == Input::Static && (s.start > 0 || s.end.is_some_and(|e| e > 1))
                {
                    return Err(ck.err(
                        f.span(),
                        "a static mesh has one frame (0); use cameras for more views",
                    ));
                }
                ((s.start, s.end, s.step), s.fps)
            }
        };

        // Cameras.
        let mut views = Vec::new();
        for c in &file.cameras {
            let s = c.get_ref();
            let e = |p: String| ck.err(c.span(), p);
            let fov = s.fov.unwrap_or(35.0);
            if !(fov > 0.0 && fov < 180.0) {
                return Err(e(format!("fov {fov} must be in (0, 180) degrees")));
            }
            let finite = |v: &Option<[f32; 3]>| v.is_none_or(|v| v.iter().all(|x| x.is_finite()));
            if !(finite(&s.eye) && finite(&s.target) && finite(&s.up) && finite(&s.direction)) {
                return Err(e("camera vectors must be finite".into()));
            }
            if s.up.is_some_and(|u| u == [0.0; 3]) || s.direction.is_some_and(|d| d == [0.0; 3]) {
                return Err(e("up and direction must be non-zero".into()));
            }
            // A view direction parallel to `up` has no image orientation;
            // checked here, with the line, rather than when the camera is
            // built after earlier scenes have rendered.
            let parallel = |d: glam::Vec3| {
                s.up.is_some_and(|u| {
                    d.normalize_or_zero()
                        .cross(glam::Vec3::from(u).normalize_or_zero())
                        .length()
                        < 1e-4
                })
            };
            if let Some(d) = s.direction
                && parallel(glam::Vec3::from(d))
            {
                return Err(e(format!(
                    "direction {d:?} is parallel to up {:?}: the image would have no up",
                    s.up.unwrap_or_default()
                )));
            }
            if let (Some(eye), Some(target)) = (s.eye, s.target)
                && target != eye
                && parallel(glam::Vec3::from(target) - glam::Vec3::from(eye))
            {
                return Err(e(format!(
                    "the view from {eye:?} to {target:?} is parallel to up {:?}: the image \
                     would have no up",
                    s.up.unwrap_or_default()
                )));
            }
            let modes = [s.eye.is_some(), s.direction.is_some(), s.orbit.is_some()];
            if modes.iter().filter(|&&m| m).count() > 1 {
                return Err(e("a camera has one of eye, direction or orbit".into()));
            }
            if s.target.is_some() && s.eye.is_none() {
                return Err(e("target goes with eye".into()));
            }
            if (s.elevation.is_some() || s.azimuth.is_some()) && s.orbit.is_none() {
                return Err(e("elevation and azimuth go with orbit".into()));
            }
            let view = |kind| ViewSpec {
                kind,
                up: s.up,
                fov,
                ortho: s.ortho,
            };
            if let Some(n) = s.orbit {
                if !(1..=360).contains(&n) {
                    return Err(e(format!("orbit {n} must be 1..=360 views")));
                }
                let el = s.elevation.unwrap_or(20.0);
                if !(el.is_finite() && el.abs() < 90.0) {
                    return Err(e(format!("elevation {el} must be in (−90, 90) degrees")));
                }
                let az0 = s.azimuth.unwrap_or(0.0);
                let up = glam::Vec3::from(s.up.unwrap_or([0.0, 1.0, 0.0])).normalize();
                // An orthonormal frame around `up`: the azimuth-0 view looks from +Z
                // when up is +Y.
                let side = up.any_orthonormal_pair();
                let (a, b) = if up.abs_diff_eq(glam::Vec3::Y, 1e-6) {
                    (glam::Vec3::Z, glam::Vec3::X)
                } else {
                    (side.1, side.0)
                };
                for i in 0..n {
                    let az = (az0 + 360.0 * i as f32 / n as f32).to_radians();
                    let (el, az) = (el.to_radians(), az);
                    let d = (a * az.cos() + b * az.sin()) * el.cos() + up * el.sin();
                    views.push(view(CameraKind::Fit(d.to_array())));
                }
            } else if let Some(eye) = s.eye {
                if s.target == Some(eye) {
                    return Err(e("eye and target must differ".into()));
                }
                views.push(view(CameraKind::LookAt {
                    eye,
                    target: s.target,
                }));
            } else {
                views.push(view(CameraKind::Fit(
                    s.direction.unwrap_or([0.4, 0.3, 1.0]),
                )));
            }
        }
        if views.is_empty() {
            views.push(ViewSpec {
                kind: CameraKind::Fit([0.4, 0.3, 1.0]),
                up: None,
                fov: 35.0,
                ortho: false,
            });
        }

        // Effects.
        let fx_span = file.effects.span();
        let fx = file.effects.into_inner();
        let e = |p: String| ck.err(fx_span.clone(), p);
        let mut cues = Vec::new();
        let shading = fx.shading.clone().unwrap_or_default();
        if fx.shading.is_some() {
            cues.push(Cue::Shading);
        }
        let base_color = color(shading.color, [0.82, 0.82, 0.8], "shading.color").map_err(e)?;
        let ambient = shading.ambient.unwrap_or(0.15);
        if !(0.0..=1.0).contains(&ambient) {
            return Err(e(format!("shading.ambient {ambient} must be in [0, 1]")));
        }
        let mut curvature_scale = None;
        if let Some(c) = &fx.curvature_colors {
            cues.push(Cue::CurvatureColors);
            if let Some(s) = c.scale {
                curvature_scale =
                    Some(positive(Some(s), 1.0, "curvature_colors.scale").map_err(e)?);
            }
        }
        let mut ao_mode = AoMode::Lut;
        let mut ao_radius = 0.02;
        if let Some(a) = &fx.ao {
            cues.push(Cue::AmbientOcclusion);
            if let Some(l) = &a.level {
                ao_mode = match l.get_ref().as_str() {
                    "poly" => AoMode::Poly,
                    "lut" => AoMode::Lut,
                    "exact" => AoMode::Exact,
                    other => {
                        return Err(ck.err(
                            l.span(),
                            format!("ao.level {other:?}: expected poly, lut or exact"),
                        ));
                    }
                };
            }
            ao_radius = positive(a.radius, 0.02, "ao.radius").map_err(e)?;
        }
        let c = fx.contours.clone().unwrap_or_default();
        if fx.contours.is_some() {
            cues.push(Cue::Contours);
        }
        let contour = (
            positive(c.width, 2.0, "contours.width").map_err(e)?,
            color(c.color, [0.0; 3], "contours.color").map_err(e)?,
        );
        let sc = fx.suggestive_contours.clone().unwrap_or_default();
        if fx.suggestive_contours.is_some() {
            cues.push(Cue::SuggestiveContours);
        }
        let suggestive = (
            positive(sc.width, 1.5, "suggestive_contours.width").map_err(e)?,
            color(sc.color, [0.15; 3], "suggestive_contours.color").map_err(e)?,
        );
        let suggestive_threshold = sc.threshold.unwrap_or(0.01);
        if !(suggestive_threshold.is_finite() && suggestive_threshold >= 0.0) {
            return Err(e(format!(
                "suggestive_contours.threshold {suggestive_threshold} must be ≥ 0"
            )));
        }
        let suggestive_fade = sc.fade.unwrap_or(0.03);
        if !(suggestive_fade.is_finite() && suggestive_fade >= 0.0) {
            return Err(e(format!(
                "suggestive_contours.fade {suggestive_fade} must be ≥ 0 (0: no fade)"
            )));
        }
        let fe = fx.feature_edges.clone().unwrap_or_default();
        if fx.feature_edges.is_some() {
            cues.push(Cue::FeatureEdges);
        }
        let edge = (
            positive(fe.width, 3.0, "feature_edges.width").map_err(e)?,
            color(fe.color, [0.0; 3], "feature_edges.color").map_err(e)?,
        );
        let crease_deg = fe.crease.unwrap_or(30.0);
        if !(crease_deg > 0.0 && crease_deg <= 180.0) {
            return Err(e(format!(
                "feature_edges.crease {crease_deg} must be in (0, 180] degrees"
            )));
        }
        let caps = match &fe.caps {
            None => CapMode::Adjacency,
            Some(c) => c
                .get_ref()
                .parse()
                .map_err(|x: Error| ck.err(c.span(), x.to_string()))?,
        };
        let st = fx.curvature_strokes.clone().unwrap_or_default();
        if fx.curvature_strokes.is_some() {
            cues.push(Cue::CurvatureStrokes);
        }
        let world = |v: Option<f64>, what: &str| -> std::result::Result<Option<f64>, String> {
            match v {
                Some(x) if !(x.is_finite() && x > 0.0) => Err(format!(
                    "curvature_strokes.{what} {x} must be a positive number of world units"
                )),
                _ => Ok(v),
            }
        };
        let sampling = match &st.sampling {
            None => None,
            Some(s) => match s.get_ref() {
                SamplingSpec::Word(w) if w == "auto" => None,
                SamplingSpec::Distance(h) if h.is_finite() && *h > 0.0 => Some(*h),
                other => {
                    return Err(ck.err(
                        s.span(),
                        format!(
                            "curvature_strokes.sampling {}: expected \"auto\" or a positive \
                             distance in world units",
                            match other {
                                SamplingSpec::Word(w) => format!("{w:?}"),
                                SamplingSpec::Distance(h) => h.to_string(),
                            }
                        ),
                    ));
                }
            },
        };
        let strokes = StrokeEffect {
            spacing: world(st.spacing, "spacing").map_err(e)?,
            sampling,
            color: color(st.color, [0.05, 0.05, 0.1], "curvature_strokes.color").map_err(e)?,
            width: world(st.width, "width").map_err(e)?,
        };
        let lines = lines::resolve(&fx, &mut cues).map_err(e)?;
        if cues.is_empty() {
            return Err(e(
                "[effects] asks for no cue: add shading, curvature_colors, ao, contours, \
                 suggestive_contours, feature_edges, curvature_strokes or a line family \
                 (ridges, valleys, isophotes, ...)"
                    .into(),
            ));
        }
        let input = source.input();
        if let Some(c) = cues.iter().find(|c| !c.accepts(input)) {
            return Err(e(format!(
                "{}: curvature-directed strokes are traced on a signed distance field; they \
                 need a volume or sdf input, not a {} input",
                c.key(),
                given[0]
            )));
        }
        let effects = Effects {
            cues,
            base_color,
            ambient,
            curvature_scale,
            ao_mode,
            ao_radius,
            contour,
            suggestive,
            suggestive_threshold,
            suggestive_fade,
            edge,
            crease: (crease_deg < 180.0).then_some(crease_deg),
            caps,
            edge_contours: fe.contours.unwrap_or(true),
            edge_boundaries: fe.boundaries.unwrap_or(true),
            strokes,
            lines,
            feature_size: FeatureSize::default(),
        };

        // Output.
        let (out, out_span) = match file.output {
            Some(o) => {
                let s = o.span();
                (o.into_inner(), s)
            }
            None => (OutputSpec::default(), 0..0),
        };
        let e = |p: String| ck.err(out_span.clone(), p);
        let size = out.size.unwrap_or([640, 480]);
        if let Err(err) = crate::spec::limits::check_image_size("output.size", size[0], size[1]) {
            let msg = err.to_string();
            return Err(e(msg
                .strip_prefix("invalid argument: ")
                .unwrap_or(&msg)
                .to_string()));
        }
        let msaa = out.msaa.unwrap_or(4);
        if ![0, 2, 4, 8].contains(&msaa) {
            return Err(e(format!("output.msaa {msaa} must be 0, 2, 4 or 8")));
        }
        let (mut png, mut svg) = (true, false);
        if let Some(f) = &out.formats {
            png = false;
            for x in f.get_ref() {
                match x.as_str() {
                    "png" => png = true,
                    "svg" => svg = true,
                    other => {
                        return Err(ck.err(
                            f.span(),
                            format!("output format {other:?}: expected png or svg"),
                        ));
                    }
                }
            }
            if !png && !svg {
                return Err(ck.err(f.span(), "output.formats is empty"));
            }
        }
        let background = color(out.background, [1.0, 1.0, 1.0], "output.background").map_err(e)?;
        let prefix = out.name.clone().unwrap_or_else(|| name.clone());
        if prefix.is_empty() || prefix.contains(['/', '\\']) {
            return Err(e(format!(
                "output.name {prefix:?} must be a non-empty file name prefix"
            )));
        }
        let mut effects = effects;
        if let Some(l) = &file.lines {
            settings::lines(&ck, l, &mut effects)?;
        }
        let curvature = match &file.curvature {
            Some(c) => settings::curvature(&ck, c)?,
            None => CurvatureOptions::default(),
        };
        Ok(Scene {
            curvature,
            path: path.to_path_buf(),
            out_dir: out
                .dir
                .map(PathBuf::from)
                .unwrap_or_else(|| Path::new("out").join(&name)),
            name,
            source,
            weld: inp.weld,
            frames,
            fps,
            views,
            effects,
            prefix,
            size,
            png,
            svg,
            msaa,
            background,
        })
    }
}

#[cfg(test)]
mod tests;
