//! The strokes front door: curvature-directed strokes on a signed distance
//! field ([`crate::stages::sdf_lines`]); when a picture is asked for, a
//! one-view scene of the field (its isosurface shaded, the strokes over it)
//! that the scene executor runs, strokes included.

use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::mesh::Mesh;
use crate::render::strokes::StrokeStyle;
use crate::render::{Camera, Frame, MeshStyle, RenderOptions};
use crate::scene::exec::{ExecOptions, Session};
use crate::scene::file::{HeldVolume, Scene, Shot, Source, StrokeEffect};
use crate::scene::planner::Cue;
use crate::spec::marching_cubes::Inside;
use crate::spec::mesh_sdf::MeshSdfOptions;
use crate::spec::sdf_lines::{
    Sampling, SdfLineOptions, SdfLineStats, SdfLinesOutput, Seed, Stroke,
};
use crate::spec::timing::Timing;
use crate::spec::visibility::VisibilityMethod;
use crate::stages::mesh_sdf::MeshSdfStats;
use crate::stages::sdf_lines::SdfLines;
use crate::volume::Volume;
use std::sync::Arc;

/// Direction (centre → eye) of the fitted camera when no eye is given.
pub const FIT_DIRECTION: [f32; 3] = [0.3, -1.0, 0.9];

/// What [`strokes`] traces on.
#[derive(Clone, Copy, Debug)]
pub enum StrokesInput<'a> {
    /// A volume (a distance field, or density data with [`Inside::Above`]).
    Volume(&'a Volume),
    /// A triangle mesh, first turned into a signed distance field on the
    /// device (negative inside, sign from the winding number) with
    /// `resolution` samples along its longest axis.
    Mesh(&'a Mesh, usize),
}

/// The picture [`strokes`] draws: the shaded isosurface with the strokes
/// over it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PictureOptions {
    /// The camera and the image size (default: 800 × 800, 35°, fitted to
    /// the surface from [`FIT_DIRECTION`]).
    pub shot: Shot,
    /// Shade the surface; `false` draws it in the background colour, so it
    /// still hides the strokes behind it.
    pub surface: bool,
    /// Draw the image (GL). Off, with `svg` on and exact visibility, no GL
    /// context is opened.
    pub image: bool,
    /// Also find the SVG group of the visible strokes (their centre lines).
    pub svg: bool,
    /// How the SVG's hidden strokes are found: exactly, over the
    /// isosurface's BVH (default), or against the image's depth.
    pub visibility: VisibilityMethod,
}

impl Default for PictureOptions {
    fn default() -> Self {
        PictureOptions {
            shot: Shot {
                size: [800, 800],
                fov_deg: 35.0,
                fit_direction: glam::Vec3::from(FIT_DIRECTION),
                ..Shot::default()
            },
            surface: true,
            image: true,
            svg: false,
            visibility: VisibilityMethod::Exact,
        }
    }
}

/// How [`strokes`] traces and what it draws.
#[derive(Clone, Debug, PartialEq)]
pub struct StrokesOptions {
    /// The iso value of the surface.
    pub iso: f32,
    /// Which side of the iso value is the object
    /// ([`crate::volume::Volume::oriented`]).
    pub inside: Inside,
    /// The Hessian sampling distance (automatic or fixed).
    pub sampling: Sampling,
    /// Poisson-disk seed spacing in world units (`None`: 1.5 × the
    /// sampling distance).
    pub spacing: Option<f64>,
    /// Draw the picture (`None`: strokes only, no surface, no renderer).
    pub picture: Option<PictureOptions>,
}

impl Default for StrokesOptions {
    fn default() -> Self {
        StrokesOptions {
            iso: 0.0,
            inside: Inside::Below,
            sampling: Sampling::Auto(Vec::new()),
            spacing: None,
            picture: Some(PictureOptions::default()),
        }
    }
}

/// A mesh input's signed distance field.
#[derive(Clone, Debug)]
pub struct MeshField {
    /// The field (negative inside).
    pub volume: Volume,
    /// Its sizes, counts and timing.
    pub stats: MeshSdfStats,
}

/// The drawn picture of [`strokes`], in a frame centred on the surface
/// (f32 precision far from 0): positions are world minus [`Picture::centre`].
#[derive(Clone, Debug)]
pub struct Picture {
    /// The image, where one was drawn ([`PictureOptions::image`]).
    pub frame: Option<Frame>,
    /// The SVG groups (the visible strokes' centre lines), where asked for.
    pub layers: Option<Vec<crate::export::svg::SvgLayer>>,
    /// The camera it was drawn with (centred frame).
    pub camera: Camera,
    /// World position of the frame's origin (the surface's bounding-box centre).
    pub centre: [f64; 3],
    /// The strokes in the centred frame.
    pub strokes: Vec<Stroke>,
}

impl Picture {
    /// The strokes whose outward normal at the seed faces the eye (what an
    /// SVG of the picture shows), in the centred frame.
    pub fn facing_strokes(&self) -> Vec<Stroke> {
        let e = self.camera.eye;
        self.strokes
            .iter()
            .filter(|s| facing_eye(s, e))
            .cloned()
            .collect()
    }
}

/// What [`strokes`] made.
#[derive(Clone, Debug)]
pub struct Strokes {
    /// The thinned seeds, world coordinates.
    pub seeds: Vec<Seed>,
    /// The strokes, world coordinates.
    pub strokes: Vec<Stroke>,
    /// Counts, the resolved parameters, the sampling sweep.
    pub stats: SdfLineStats,
    /// Kernel time per step and wall time of the strokes.
    pub timing: Timing,
    /// The volume's grid: samples per axis, spacing, origin.
    pub grid: ([usize; 3], [f64; 3], [f64; 3]),
    /// The mesh input's distance field (`None` for a volume input).
    pub field: Option<MeshField>,
    /// The isosurface under the strokes (world coordinates), when a picture
    /// was asked for.
    pub surface: Option<Mesh>,
    /// The picture, when asked for.
    pub picture: Option<Picture>,
}

/// Curvature-directed strokes on the default device: seeds on the
/// isosurface thinned by Poisson-disk sampling, traced along the first
/// principal direction of the field's Hessian (Interrante 1997, curvature
/// after Kindlmann et al. 2003), as tapered strips; with
/// `opts.picture`, drawn over the shaded isosurface. For many runs on one
/// volume, build a [`SdfLines`] once instead.
///
/// ```
/// use shapecue::volume::sdf::{Sdf, sdf};
/// let vol = sdf(Sdf::Torus, 48);
/// let opts = shapecue::StrokesOptions { picture: None, ..Default::default() };
/// let s = shapecue::strokes(shapecue::StrokesInput::Volume(&vol), &opts)?;
/// assert!(s.stats.strokes > 0 && s.strokes.len() == s.stats.strokes);
/// # Ok::<(), shapecue::Error>(())
/// ```
///
/// # Errors
/// No device, a mesh whose distance field cannot be built, an empty
/// isosurface when a picture is asked for, bad parameters, device and GL
/// failures.
pub fn strokes(input: StrokesInput<'_>, opts: &StrokesOptions) -> Result<Strokes> {
    strokes_on(&super::default_gpu()?, input, opts)
}

/// [`strokes`] on a given device.
pub fn strokes_on(
    gpu: &Arc<Gpu>,
    input: StrokesInput<'_>,
    opts: &StrokesOptions,
) -> Result<Strokes> {
    let field = match input {
        StrokesInput::Volume(_) => None,
        StrokesInput::Mesh(mesh, resolution) => {
            let (volume, stats) = crate::stages::mesh_sdf::mesh_to_sdf(
                gpu.clone(),
                mesh,
                &MeshSdfOptions { resolution },
            )?;
            Some(MeshField { volume, stats })
        }
    };
    let volume = match (input, &field) {
        (StrokesInput::Volume(v), _) => v,
        (_, Some(f)) => &f.volume,
        (StrokesInput::Mesh(..), None) => unreachable!("a mesh input has its field"),
    };
    // Both the surface and the strokes see the object below the iso value.
    let (vol, iso_below) = volume.oriented(opts.iso, opts.inside);
    let (out, surface, picture) = match &opts.picture {
        None => {
            let line_opts = SdfLineOptions {
                iso: iso_below,
                inside: Inside::Below,
                sampling: opts.sampling.clone(),
                spacing: opts.spacing,
                ..SdfLineOptions::default()
            };
            let out = SdfLines::new(gpu.clone(), &vol, &line_opts)?.run()?;
            (out, None, None)
        }
        Some(p) => {
            let what = match input {
                StrokesInput::Mesh(..) => Surface::OfMesh,
                _ => Surface::Iso(volume, opts.iso),
            };
            check_surface(&vol, iso_below, what)?;
            let scene = strokes_scene(Arc::new(vol.into_owned()), iso_below, opts, p);
            let f = Session::on(gpu.clone()).picture(&scene, &ExecOptions::default())?;
            let v = f.out;
            let o = v.origin;
            let local = |p: &[f64; 3]| -> [f64; 3] { std::array::from_fn(|i| p[i] - o[i]) };
            let strokes = (v.strokes.strokes.iter())
                .map(|s| Stroke {
                    points: s.points.iter().map(local).collect(),
                    strip: s.strip.iter().map(local).collect(),
                    ..s.clone()
                })
                .collect();
            let picture = Picture {
                frame: v.image,
                layers: v.layers,
                camera: v.camera,
                centre: o,
                strokes,
            };
            (v.strokes, v.mesh, Some(picture))
        }
    };
    let timing = out.stats.timing.clone();
    let SdfLinesOutput {
        seeds,
        strokes,
        stats,
    } = out;
    Ok(Strokes {
        seeds,
        strokes,
        stats,
        timing,
        grid: (volume.dims, volume.spacing, volume.origin),
        field,
        surface,
        picture,
    })
}

/// The one-view scene of a strokes picture: the field's isosurface shaded
/// (or flat in white) as the renderer's defaults draw a mesh, the strokes in
/// their default colour over it.
fn strokes_scene(vol: Arc<Volume>, iso: f32, opts: &StrokesOptions, p: &PictureOptions) -> Scene {
    let mut s = Scene::held(Source::HeldVolume(HeldVolume(vol), iso, false), &p.shot);
    let [r, g, b, _] = RenderOptions::default().background;
    s.background = [r, g, b];
    s.msaa = RenderOptions::default().msaa;
    s.png = p.image;
    s.svg = p.svg;
    s.visibility = p.visibility;
    let fx = &mut s.effects;
    fx.cues = match p.surface {
        true => vec![Cue::Shading, Cue::CurvatureStrokes],
        false => vec![Cue::CurvatureStrokes],
    };
    let style = MeshStyle::default();
    (fx.ambient, fx.base_color) = (style.ambient, style.color);
    let [r, g, b, _] = StrokeStyle::default().color;
    fx.strokes = StrokeEffect {
        spacing: opts.spacing,
        sampling: opts.sampling.clone(),
        color: [r, g, b],
        width: None,
    };
    s
}

/// What the surface under the strokes is, for the message when it is empty:
/// the zero set of a mesh's distance field, or an isosurface of the user's
/// volume (as given, before orienting) at the user's iso value.
enum Surface<'a> {
    OfMesh,
    Iso(&'a Volume, f32),
}

/// Refuses a field with no surface at the iso value (every finite value on
/// one side of it), before anything is drawn.
fn check_surface(vol: &Volume, iso_below: f32, what: Surface<'_>) -> Result<()> {
    // Finite values only: marching cubes takes an infinite one as missing.
    let finite = vol.values.iter().filter(|v| v.is_finite());
    let (below, above) = finite.fold((false, false), |(b, a), &v| {
        (b || v < iso_below, a || v >= iso_below)
    });
    let crosses = below && above;
    if crosses {
        return Ok(());
    }
    Err(Error::InvalidArgument(match what {
        Surface::OfMesh => "the mesh's distance field has no inside, so there is no \
                            surface to draw strokes on: is the mesh closed?"
            .to_string(),
        Surface::Iso(volume, iso) => {
            let span = volume
                .range()
                .map_or("the volume has no finite values".to_string(), |(lo, hi)| {
                    format!("the values span {lo} to {hi}")
                });
            format!("the isosurface at iso {iso} is empty ({span})")
        }
    }))
}

/// Whether a stroke's outward normal at its seed faces the eye (local frame).
fn facing_eye(s: &Stroke, eye: glam::Vec3) -> bool {
    let (Some(p), Some(n)) = (s.points.get(s.centre), s.normals.get(s.centre)) else {
        return false;
    };
    let d: [f64; 3] = std::array::from_fn(|i| f64::from(eye[i]) - p[i]);
    d[0] * n[0] + d[1] * n[1] + d[2] * n[2] > 0.0
}
