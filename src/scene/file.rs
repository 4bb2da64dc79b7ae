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
//! Unknown keys are refused; every error names the scene file and the line.
//! Relative paths are relative to the scene file.

use crate::error::{Error, Result};
use crate::scene::planner::Input;
use crate::spec::curvature::CurvatureOptions;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

mod camera_file;
mod effects;
mod effects_table;
mod held;
mod input;
pub mod lines;
mod output;
mod raw;
mod settings;
mod toml_words;
mod views;

pub use camera_file::{
    CameraDefaults, FOV_RANGE, MAX_CAMERA_FILE_BYTES, check_fov, fibonacci_views, load_camera_file,
    parse_camera_file,
};
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
    /// Several mesh files, drawn as one mesh (their faces concatenated in
    /// order); the intersection lines cross the files, not each file itself.
    Meshes(Vec<PathBuf>),
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
            Source::Mesh(_) | Source::Meshes(_) | Source::Generate(..) | Source::Held(_) => {
                Input::Static
            }
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
    /// Keep the normals mesh files store (the default), or compute them.
    pub normals: crate::mesh::NormalsSource,
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
    /// Write each view's line pieces as NPZ (`formats = [.., "npz"]`):
    /// family, strength, visibility, chain, and the face and barycentric
    /// coordinates each piece lies at.
    pub npz: bool,
    /// MSAA samples.
    pub msaa: u32,
    /// Background.
    pub background: [f32; 3],
    /// The curvature estimator's scheme, precision and least squares
    /// (`[curvature]`; the derivative is on where a pass needs it).
    pub curvature: CurvatureOptions,
    /// How the edges frame's buffers reach GL (default `off`: read back
    /// and uploaded; `auto`: shared memory where the device, GL and Vulkan
    /// offer it). The executor decides.
    pub interop: crate::spec::interop::InteropMode,
    /// How the SVG's hidden lines are found (default `exact`: in object
    /// space over the mesh's BVH, with no GL context when no PNG is
    /// written; `depth`: against the rendered depth).
    pub visibility: crate::spec::visibility::VisibilityMethod,
    /// Keep each view's per-vertex fields (n·v, κr, D_w κr, q1) beside its
    /// lines, for a caller of [`crate::scene::exec::Session::run_each`]
    /// (not a scene file's key: a scene writes no fields).
    pub fields: bool,
    /// Keep each view's lines split by exact visibility and chained (the
    /// pieces with their visibility), with or without an SVG: exact
    /// visibility is planned for them (not a scene file's key).
    pub pieces: bool,
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

/// A table's span, for errors that name the table's line rather than a key
/// (`[effects]`, `[output]`); each table's checks add their methods.
struct Table<'a> {
    ck: &'a Checker<'a>,
    span: Range<usize>,
}

impl Table<'_> {
    /// An error at the table's line.
    fn err(&self, problem: String) -> Error {
        self.ck.err(self.span.clone(), problem)
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
    /// relative paths. Each table is checked by its own function, in file
    /// order: [input], [frames], [[camera]], [effects], [output], [lines],
    /// [curvature].
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
        let input = input::resolve(&ck, file.input)?;
        let (frames, fps) = input::frames(&ck, file.frames.as_ref(), &input.source)?;
        let views = views::resolve(&ck, &file.cameras)?;
        let mut effects =
            effects_table::resolve(&ck, file.effects, input.source.input(), input.kind)?;
        let out = output::resolve(&ck, file.output, &name)?;
        if let Some(l) = &file.lines {
            settings::lines(&ck, l, &mut effects)?;
        }
        let rtsc_lines = effects.cues.iter().any(|c| c.is_rtsc_family());
        let curvature = match &file.curvature {
            Some(c) => settings::curvature(&ck, c, rtsc_lines)?,
            None => CurvatureOptions {
                compat: crate::spec::curvature::Compat::default_for(rtsc_lines),
                ..CurvatureOptions::default()
            },
        };
        if let Some(p) = (file.curvature.as_ref()).and_then(|c| c.precision.as_ref()) {
            settings::check_precision(&ck, p.span(), &curvature, &effects, input.source.input())?;
        }
        Ok(Scene {
            curvature,
            path: path.to_path_buf(),
            out_dir: out.out_dir,
            name,
            source: input.source,
            weld: input.weld,
            normals: input.normals,
            frames,
            fps,
            views,
            effects,
            prefix: out.prefix,
            size: out.size,
            png: out.png,
            svg: out.svg,
            npz: out.npz,
            msaa: out.msaa,
            background: out.background,
            interop: out.interop,
            visibility: out.visibility,
            fields: false,
            pieces: false,
        })
    }
}

#[cfg(test)]
mod tests;
