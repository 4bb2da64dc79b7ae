//! Line drawings: `lines_views` (every line family of rtsc, Rusinkiewicz and
//! DeCarlo's real-time suggestive contours program) through the front door
//! [`shapecue::api::lines_on`], the one route of one view and of many:
//! per view the pieces of its lines split by exact visibility and chained,
//! with their provenance, and on request the bytes of the command line's
//! NPZ files.

use super::*;
use pyo3::types::{PyBytes, PyList};
use shapecue::api::{
    Camera, CameraDefaults, LineFiles, LineOptions, LineSetup, LineView, LinesPictureOptions, Shot,
    ViewFields, ViewSpec, VisibilityMethod, VisibleLines, check_fov, fibonacci_views, lines_on,
    lines_views_scene, load_camera_file, parse_camera_file, segment_arrays,
};
use shapecue::export::npz::{SegmentArrays, fields_npz_bytes, segments_npz_bytes};
use shapecue::spec::feature_lines::{CurveOptions, FamilySet, FeatureSize, LineFamily};
use std::path::PathBuf;
use std::time::Instant;

/// The keyword options of `lines_views`, as the Python layer passes them
/// (see [`lines_views`] for the order within the tuples).
struct LinesArgs<'a> {
    families: &'a str,
    thresholds: [f32; 6],
    isophotes: u32,
    light: [f32; 3],
    switches: [bool; 5],
    setup: (String, String, String),
}

impl LinesArgs<'_> {
    /// The line families and their thresholds and switches; as the
    /// command line, refuses isophotes of no level (they would find no line).
    fn line_options(&self) -> PyResult<LineOptions> {
        let fams = FamilySet::parse(self.families).map_err(to_py)?;
        if fams.has(LineFamily::Isophotes) && self.isophotes == 0 {
            return Err(value_err(
                "isophotes=0: isophotes need at least 1 level (n·l = j/N for |j| < N)",
            ));
        }
        let [sc, rv, ar, ph, sh, sc_fade] = self.thresholds;
        let [cull, test, fade, hermite, hermite_kh] = self.switches;
        Ok(LineOptions {
            contours: fams.has(LineFamily::Contours),
            suggestive: fams.has(LineFamily::Suggestive),
            threshold: sc,
            fade: sc_fade,
            curves: CurveOptions {
                families: fams.curves(),
                ridge_threshold: rv,
                apparent_threshold: ar,
                principal_threshold: ph,
                highlight_threshold: sh,
                isophotes: self.isophotes,
                light: self.light,
                cull,
                test,
                fade,
                hermite,
                hermite_kh,
            },
        })
    }

    /// The curvature and feature size the lines are computed with, names
    /// checked by the library's parsers; `accumulate = "auto"` is decided
    /// by [`AccumulateChoice::resolve`].
    fn setup(&self) -> PyResult<LineSetup> {
        let (feature_size, compat, accumulate) = &self.setup;
        Ok(LineSetup {
            curvature: CurvatureOptions {
                accumulate: parse::<AccumulateChoice>(accumulate)?.resolve(),
                compat: parse(compat)?,
                ..Default::default()
            },
            feature_size: feature_size.parse::<FeatureSize>().map_err(to_py)?,
        })
    }
}

/// lines_views(mesh, families, cameras, camera_file, views, shot, camera,
/// thresholds, isophotes, light, switches, setup, fields, npz, device) ->
/// list of dicts
///
/// The lines of one view or many in one setup (the pose passes once, the
/// view passes per view), each split by exact visibility and chained. The
/// mesh is a [`PyMesh`]: where it holds stored normals (a file's, or the
/// array given), the curvature and so every family start from them. The
/// cameras, one of four: `cameras`, the JSON text of a camera list
/// (`{"cameras": [...]}`, errors name `cameras` and the camera);
/// `camera_file`, a camera file read as the command line reads it (errors
/// name the file); `views`, that many cameras on the Fibonacci lattice;
/// `shot`: (eye, direction, target, up), the one camera of the command
/// line's `shapecue lines MESH -o FILE` (its `--eye`, `--target`, `--up`):
/// at `eye` looking at `target` (default the centre of the bounds), or
/// without an eye fitted to the bounds from `direction`. `camera`: (fov,
/// ortho, width, height), the cameras' defaults and the image size the
/// fitted views and the visibility's spacing are for.
///
/// `fields` adds each view's per-vertex fields; `npz` each view's
/// `segments_npz` (and with `fields` its `fields_npz`): the bytes of the
/// files `shapecue lines --views N --out DIR --npz --fields` writes for
/// the view, from the same arrays.
///
/// Between views the thread takes the GIL back for a moment to see whether
/// Python has a signal waiting (Ctrl-C): the Python handler's exception
/// (`KeyboardInterrupt`) ends the run, so a call of many views stops within
/// one view's time instead of at its end.
#[pyfunction]
#[pyo3(signature = (mesh, families, cameras, camera_file, views, shot, camera, thresholds, isophotes, light, switches, setup, fields, npz, device))]
#[allow(clippy::too_many_arguments)]
pub fn lines_views<'py>(
    py: Python<'py>,
    mesh: PyRef<'py, PyMesh>,
    families: &str,
    cameras: Option<String>,
    camera_file: Option<PathBuf>,
    views: Option<usize>,
    shot: Option<ShotArg>,
    camera: (f32, bool, u32, u32),
    thresholds: [f32; 6],
    isophotes: u32,
    light: [f32; 3],
    switches: [bool; 5],
    setup: (String, String, String),
    fields: bool,
    npz: bool,
    device: Option<String>,
) -> PyResult<Bound<'py, PyList>> {
    let args = LinesArgs {
        families,
        thresholds,
        isophotes,
        light,
        switches,
        setup,
    };
    let mesh = mesh.mesh.clone();
    let (fov, ortho, ..) = camera;
    let (opts, one) = views_options(&args, shot, camera)?;
    let specs = camera_specs(
        cameras,
        camera_file,
        views,
        one,
        CameraDefaults { fov, ortho },
    )?;
    let (views, name) = run_views(py, &mesh, &opts, &specs, (fields, npz), device)?;
    let list = PyList::empty(py);
    for v in views {
        list.append(v.into_dict(py, &name)?)?;
    }
    Ok(list)
}

/// The picture options of `lines_views` and its one camera's shot, if it
/// was given one: the options of the command line's single picture.
fn views_options(
    args: &LinesArgs,
    shot: Option<ShotArg>,
    (fov, ortho, width, height): (f32, bool, u32, u32),
) -> PyResult<(LinesPictureOptions, Option<Shot>)> {
    let base = Shot {
        fov_deg: fov,
        ortho,
        size: [width, height],
        ..Default::default()
    };
    let one = shot.map(|s| one_shot(s, base));
    let opts = LinesPictureOptions {
        shot: one.unwrap_or(base),
        lines: args.line_options()?,
        image: false,
        svg: false,
        pieces: true,
        visibility: VisibilityMethod::Exact,
        setup: args.setup()?,
        ..Default::default()
    };
    Ok((opts, one))
}

/// Runs the views with the GIL released, each view's arrays (and files'
/// bytes, with `npz`) made as it is handed over; Python's signals are
/// checked between views. Returns the views and the device's name.
fn run_views(
    py: Python<'_>,
    mesh: &Arc<Mesh>,
    opts: &LinesPictureOptions,
    specs: &[ViewSpec],
    (fields, npz): (bool, bool),
    device: Option<String>,
) -> PyResult<(Vec<ViewOut>, String)> {
    let mut interrupt: Option<PyErr> = None;
    let done = py.detach(|| {
        // The first view's wall clock counts opening the device.
        let mut last = Instant::now();
        let gpu = open_gpu(device.as_deref())?;
        let mut out = Vec::with_capacity(specs.len());
        let mut scene = lines_views_scene(mesh.clone(), opts, specs.to_vec());
        scene.fields = fields;
        lines_on(&gpu, &scene, LineFiles::Memory, &mut |v| {
            // The arrays (and files' bytes) made here, without the GIL.
            let mut view = ViewOut::new(v, Some(mesh), npz)?;
            let now = Instant::now();
            view.wall_ms = (now - last).as_secs_f64() * 1e3;
            last = now;
            out.push(view);
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                interrupt = Some(e);
                // Only ends the run: the Python exception is raised below.
                return Err(Error::Interrupted);
            }
            Ok(())
        })?;
        Ok::<_, Error>((out, gpu.info.name.clone()))
    });
    if let Some(e) = interrupt {
        return Err(e);
    }
    done.map_err(to_py)
}

/// The one camera of `lines_views`' `shot`: (eye, direction, target, up).
type ShotArg = (
    Option<[f32; 3]>,
    [f32; 3],
    Option<[f32; 3]>,
    Option<[f32; 3]>,
);

/// The one camera of a [`ShotArg`] as the command line's `-o` picture has
/// it, on `base` (its fov, projection and image size).
fn one_shot((eye, direction, target, up): ShotArg, base: Shot) -> Shot {
    Shot {
        eye: eye.map(glam::Vec3::from),
        target: target.map(glam::Vec3::from),
        up: up.map(glam::Vec3::from),
        fit_direction: glam::Vec3::from(direction),
        ..base
    }
}

/// The cameras of [`lines_views`]: one of a camera list's JSON text, a
/// camera file, a number of fitted views or the one shot.
fn camera_specs(
    cameras: Option<String>,
    camera_file: Option<PathBuf>,
    views: Option<usize>,
    shot: Option<Shot>,
    defaults: CameraDefaults,
) -> PyResult<Vec<ViewSpec>> {
    match (cameras, camera_file, views, shot) {
        (Some(text), None, None, None) => parse_camera_file(&text, "cameras", defaults),
        (None, Some(path), None, None) => load_camera_file(&path, defaults),
        (None, None, Some(n), None) => fibonacci_views(n, defaults),
        (None, None, None, Some(s)) => match check_fov(s.fov_deg) {
            Ok(()) => Ok(vec![s.view()]),
            Err(e) => return Err(value_err(format!("fov: {e}"))),
        },
        _ => {
            return Err(value_err(
                "cameras: give a number of views, a list of camera dicts, a camera JSON file \
                 or one eye",
            ));
        }
    }
    .map_err(to_py)
}

/// check_cameras(cameras, camera_file, views, fov, ortho) -> int
///
/// The number of views a camera set of [`lines_views`] gives, or the error
/// it would raise, without a device: the batch checks its options before
/// any task runs.
#[pyfunction]
#[pyo3(signature = (cameras, camera_file, views, fov, ortho))]
pub fn check_cameras(
    cameras: Option<String>,
    camera_file: Option<PathBuf>,
    views: Option<usize>,
    fov: f32,
    ortho: bool,
) -> PyResult<usize> {
    let defaults = CameraDefaults { fov, ortho };
    Ok(camera_specs(cameras, camera_file, views, None, defaults)?.len())
}

/// line_families(names) -> list of str
///
/// The line families of a comma-separated list of names, in code order
/// (each once), or the error naming the unknown name and the known ones.
#[pyfunction]
pub fn line_families(names: &str) -> PyResult<Vec<&'static str>> {
    let set = FamilySet::parse(names).map_err(to_py)?;
    Ok(set.iter().map(|f| f.name()).collect())
}

/// family_codes() -> list of (int, str)
///
/// Each code of the `family` arrays (as the command line's NPZ files and
/// the `family_codes` of its manifest give them) with its name: the line
/// families (0 to 11), and the layers of feature edges, intersection lines
/// and curvature strokes.
#[pyfunction]
pub fn family_codes() -> Vec<(u32, &'static str)> {
    shapecue::spec::feature_lines::family_codes()
}

/// The chains of a view in walking order: each chain's pieces (rows of
/// the view's arrays) one after another, as the command line's segments
/// document lists them, with whether each is walked from `b` to `a`.
struct Walk {
    /// The rows, chain after chain, each chain's in walking order.
    order: Vec<u32>,
    /// Per row of `order`: walked from its `b` to its `a` (1) or not (0).
    reversed: Vec<u8>,
    /// Each chain's first index into `order`, and one past the last.
    start: Vec<u32>,
    /// Each chain's family or layer code.
    family: Vec<u32>,
    /// Each chain's visibility (1 visible).
    visible: Vec<u8>,
}

impl Walk {
    /// The walk of `vis`'s chains (its pieces are the rows).
    fn of(vis: &VisibleLines) -> Walk {
        let n = vis.chain_pieces.len();
        let mut w = Walk {
            order: Vec::with_capacity(n),
            reversed: Vec::with_capacity(n),
            start: Vec::with_capacity(vis.chains.len() + 1),
            family: Vec::with_capacity(vis.chains.len()),
            visible: Vec::with_capacity(vis.chains.len()),
        };
        for c in &vis.chains {
            w.start.push(w.order.len() as u32);
            w.family.push(c.layer);
            w.visible.push(u8::from(c.visible));
            for &(i, reversed) in &c.pieces {
                w.order.push(i);
                w.reversed.push(u8::from(reversed));
            }
        }
        w.start.push(w.order.len() as u32);
        w
    }
}

/// One view of [`lines_views`], its pieces as the command line's arrays.
struct ViewOut {
    /// The pieces ([`segment_arrays`], as the command line's NPZ and
    /// segments document hold them).
    arrays: SegmentArrays,
    /// The chains in walking order ([`Walk`]).
    walk: Walk,
    /// The per-vertex fields, where asked.
    fields: Option<ViewFields>,
    /// The bytes of the view's `_segments.npz` and, with the fields, its
    /// `_fields.npz`, where asked.
    npz: Option<(Vec<u8>, Option<Vec<u8>>)>,
    camera: Camera,
    passes: Vec<&'static str>,
    /// The passes' own clocks, summed.
    passes_ms: f64,
    /// The summed ms of the passes clocked by the device (kernels).
    kernel_ms: f64,
    feature_size: f32,
    /// Wall clock from the end of the view before (or the start).
    wall_ms: f64,
    /// The frame and the view.
    frame: usize,
    view: usize,
}

impl ViewOut {
    /// The arrays of a view of `mesh` (and the NPZ files' bytes with `npz`);
    /// of the view's own pose where the scene made them (an animation).
    fn new(v: LineView, mesh: Option<&Mesh>, npz: bool) -> shapecue::Result<ViewOut> {
        let vis = v.visible.as_ref().ok_or_else(|| {
            Error::InvalidArgument("internal: the view was not classified".into())
        })?;
        let arrays = match (&v.npz, mesh) {
            (Some(posed), _) => posed.arrays.clone(),
            (None, Some(mesh)) => segment_arrays(vis, mesh),
            (None, None) => {
                return Err(Error::InvalidArgument(
                    "internal: the view's pieces have no pose".into(),
                ));
            }
        };
        let walk = Walk::of(vis);
        let npz = if npz {
            let fields = v.fields.as_ref().map(fields_npz_bytes).transpose()?;
            Some((segments_npz_bytes(&arrays)?, fields))
        } else {
            None
        };
        let sum = |clock: Option<&str>| {
            (v.passes.iter())
                .filter(|p| clock.is_none_or(|c| p.clock == c))
                .map(|p| p.ms())
                .sum()
        };
        Ok(ViewOut {
            npz,
            passes_ms: sum(None),
            kernel_ms: sum(Some("kernel")),
            passes: v.passes.iter().map(|p| p.pass.name()).collect(),
            arrays,
            walk,
            fields: v.fields,
            camera: v.camera,
            feature_size: v.feature_size,
            wall_ms: 0.0,
            frame: v.frame,
            view: v.view,
        })
    }

    /// The view as a dict of numpy arrays (and bytes).
    fn into_dict<'py>(self, py: Python<'py>, device: &str) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let s = self.arrays;
        let n = s.a.len();
        d.set_item("a", array(py, s.a.concat(), &[n, 3])?)?;
        d.set_item("b", array(py, s.b.concat(), &[n, 3])?)?;
        d.set_item("family_code", array(py, s.family, &[n])?)?;
        d.set_item("strength", array(py, s.strength, &[n])?)?;
        d.set_item("visible", array(py, s.visible, &[n])?)?;
        d.set_item("faces", array(py, s.faces.concat(), &[n, 4])?)?;
        d.set_item("chain", array(py, s.chain, &[n])?)?;
        d.set_item("face", array(py, s.face, &[n])?)?;
        let bary: Vec<f32> = s.bary.iter().flatten().flatten().copied().collect();
        d.set_item("bary", array(py, bary, &[n, 2, 3])?)?;
        if let Some(ids) = s.chain_id {
            d.set_item("chain_id", array(py, ids, &[n])?)?;
        }
        let w = self.walk;
        let (k, c) = (w.order.len(), w.visible.len());
        d.set_item("chain_order", array(py, w.order, &[k])?)?;
        d.set_item("chain_reversed", array(py, w.reversed, &[k])?)?;
        d.set_item("chain_start", array(py, w.start, &[c + 1])?)?;
        d.set_item("chain_family_code", array(py, w.family, &[c])?)?;
        d.set_item("chain_visible", array(py, w.visible, &[c])?)?;
        if let Some(f) = self.fields {
            let nv = f.ndotv.len();
            d.set_item("ndotv", array(py, f.ndotv, &[nv])?)?;
            d.set_item("kr", array(py, f.kr, &[nv])?)?;
            d.set_item("dwkr", array(py, f.dwkr, &[nv])?)?;
            d.set_item("q1", array(py, f.q1, &[nv])?)?;
        }
        if let Some((segments, fields)) = self.npz {
            let files = PyDict::new(py);
            files.set_item("segments", PyBytes::new(py, &segments))?;
            if let Some(f) = fields {
                files.set_item("fields", PyBytes::new(py, &f))?;
            }
            d.set_item("npz", files)?;
        }
        // As the command line's manifest lists a view's camera.
        let c = self.camera;
        let cam = PyDict::new(py);
        cam.set_item("eye", c.eye.to_array())?;
        cam.set_item("target", c.target.to_array())?;
        cam.set_item("up", c.up.to_array())?;
        cam.set_item("fov", c.fov_y_deg)?;
        cam.set_item("ortho", c.ortho_height)?;
        cam.set_item("near", c.near)?;
        cam.set_item("far", c.far)?;
        d.set_item("camera", cam)?;
        d.set_item("passes", self.passes)?;
        d.set_item("passes_ms", self.passes_ms)?;
        d.set_item("kernel_ms", self.kernel_ms)?;
        d.set_item("wall_ms", self.wall_ms)?;
        d.set_item("feature_size", self.feature_size)?;
        d.set_item("device", device)?;
        d.set_item("frame", self.frame)?;
        d.set_item("view", self.view)?;
        Ok(d)
    }
}

/// scene_lines(path, device) -> list of dicts
///
/// The lines of every frame and view of a scene file (an animation: a
/// glTF skin, a libigl set, a flipbook; or a static mesh), as its line cues
/// and `[lines]` settings (coherence over the frames included) draw them:
/// each view's pieces as [`lines_views`] gives them, with their faces and
/// barycentric coordinates on that frame's pose (the same rest-mesh point on
/// every frame), its `frame` and `view`. Nothing is written.
#[pyfunction]
#[pyo3(signature = (path, device))]
pub fn scene_lines<'py>(
    py: Python<'py>,
    path: PathBuf,
    device: Option<String>,
) -> PyResult<Bound<'py, PyList>> {
    let mut scene = shapecue::api::Scene::load(&path).map_err(to_py)?;
    scene.png = false;
    scene.svg = false;
    scene.npz = true;
    let done = py.detach(|| {
        let gpu = open_gpu(device.as_deref())?;
        let mut out = Vec::new();
        let mut last = Instant::now();
        lines_on(&gpu, &scene, LineFiles::Memory, &mut |v| {
            let mut view = ViewOut::new(v, None, false)?;
            let now = Instant::now();
            view.wall_ms = (now - last).as_secs_f64() * 1e3;
            last = now;
            out.push(view);
            Ok(())
        })?;
        Ok::<_, Error>((out, gpu.info.name.clone()))
    });
    let (views, name) = done.map_err(to_py)?;
    let list = PyList::empty(py);
    for v in views {
        list.append(v.into_dict(py, &name)?)?;
    }
    Ok(list)
}
