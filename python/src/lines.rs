//! Line drawings: `lines` (every line family of rtsc, Rusinkiewicz and
//! DeCarlo's real-time suggestive contours program) through the front door
//! [`shapecue::api::line_segments_on`]: 3-D segments with their family and
//! strength, no picture.

use super::*;
use pyo3::types::PyList;
use shapecue::api::{
    CameraDefaults, LineOptions, LineSetup, LineView, LinesPictureOptions, Shot, ViewSpec,
    VisibilityMethod, fibonacci_views, line_views_on, load_camera_file, parse_camera_file,
    segment_arrays,
};
use shapecue::spec::feature_lines::{CurveOptions, FamilySet, FeatureSize, LineFamily};
use shapecue::spec::view::View;
use std::path::PathBuf;
use std::time::Instant;

/// lines(vertices, faces, families, eye, ortho, thresholds, isophotes,
/// light, switches, setup, device) -> dict
///
/// thresholds: (sc, rv, ar, ph, sh, fade); switches: (cull, test, fade,
/// hermite, hermite_kh); setup: (feature_size, compat, accumulate) by their
/// command-line names ("rtsc" | "edge" | a length; "exact" | "trimesh2";
/// "auto" | a scheme).
#[pyfunction]
#[pyo3(signature = (vertices, faces, families, eye, ortho, thresholds, isophotes, light, switches, setup, device))]
// PyO3 takes the arguments one by one (the positional signature of
// `_shapecue.pyi`); the body only collects them into `LinesArgs`.
#[allow(clippy::too_many_arguments)]
pub fn lines<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    families: &str,
    eye: [f32; 3],
    ortho: bool,
    thresholds: [f32; 6],
    isophotes: u32,
    light: [f32; 3],
    switches: [bool; 5],
    setup: (String, String, String),
    device: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let args = LinesArgs {
        families,
        eye,
        ortho,
        thresholds,
        isophotes,
        light,
        switches,
        setup,
        device,
    };
    lines_with(py, (vertices, faces), args)
}

/// The keyword options of `lines`, as the Python layer passes them (see
/// [`lines`] for the order within the tuples).
struct LinesArgs<'a> {
    families: &'a str,
    eye: [f32; 3],
    ortho: bool,
    thresholds: [f32; 6],
    isophotes: u32,
    light: [f32; 3],
    switches: [bool; 5],
    setup: (String, String, String),
    device: Option<String>,
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

/// [`lines`] with its options collected.
fn lines_with<'py>(
    py: Python<'py>,
    (vertices, faces): (&Bound<'py, PyAny>, &Bound<'py, PyAny>),
    args: LinesArgs<'_>,
) -> PyResult<Bound<'py, PyDict>> {
    let mesh = read_mesh(vertices, faces)?;
    let opts = args.line_options()?;
    let setup = args.setup()?;
    let view = View::from_eye(args.eye, args.ortho);
    let device = args.device;
    let (ls, name) = py
        .detach(|| {
            let gpu = open_gpu(device.as_deref())?;
            let ls = shapecue::api::line_segments_on(&gpu, &mesh, view, &opts, &setup)?;
            Ok::<_, Error>((ls, gpu.info.name.clone()))
        })
        .map_err(to_py)?;
    let n = ls.segments.len();
    let pts: Vec<f32> = ls
        .segments
        .iter()
        .flat_map(|s| s.0.into_iter().chain(s.1))
        .collect();
    let code: Vec<u32> = ls.segments.iter().map(|s| s.2).collect();
    let strength: Vec<f32> = ls.segments.iter().map(|s| s.3).collect();
    let d = PyDict::new(py);
    d.set_item("segments", array(py, pts, &[n, 2, 3])?)?;
    d.set_item("family_code", array(py, code, &[n])?)?;
    d.set_item("strength", array(py, strength, &[n])?)?;
    d.set_item("feature_size", ls.feature_size)?;
    d.set_item("kernel_ms", ls.timing.kernel_ms)?;
    d.set_item("device", name)?;
    Ok(d)
}

/// lines_views(vertices, faces, families, cameras, camera_file, views,
/// camera, thresholds, isophotes, light, switches, setup, fields, device)
/// -> list of dicts
///
/// The lines of many views in one setup (the pose passes once, the view
/// passes per view), each split by exact visibility and chained. The
/// cameras, one of three: `cameras`, the JSON text of a camera list
/// (`{"cameras": [...]}`, errors name `cameras` and the camera);
/// `camera_file`, a camera file read as the command line reads it (errors
/// name the file); `views`, that many cameras on the Fibonacci lattice.
/// `camera`: (fov, ortho, width, height), the cameras' defaults and the
/// image size the fitted views and the visibility's spacing are for.
///
/// Between views the thread takes the GIL back for a moment to see whether
/// Python has a signal waiting (Ctrl-C): the Python handler's exception
/// (`KeyboardInterrupt`) ends the run, so a call of many views stops within
/// one view's time instead of at its end.
#[pyfunction]
#[pyo3(signature = (vertices, faces, families, cameras, camera_file, views, camera, thresholds, isophotes, light, switches, setup, fields, device))]
#[allow(clippy::too_many_arguments)]
pub fn lines_views<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    families: &str,
    cameras: Option<String>,
    camera_file: Option<PathBuf>,
    views: Option<usize>,
    camera: (f32, bool, u32, u32),
    thresholds: [f32; 6],
    isophotes: u32,
    light: [f32; 3],
    switches: [bool; 5],
    setup: (String, String, String),
    fields: bool,
    device: Option<String>,
) -> PyResult<Bound<'py, PyList>> {
    let args = LinesArgs {
        families,
        eye: [0.0; 3],
        ortho: camera.1,
        thresholds,
        isophotes,
        light,
        switches,
        setup,
        device,
    };
    let mesh = Arc::new(read_mesh(vertices, faces)?);
    let opts = LinesPictureOptions {
        shot: Shot {
            fov_deg: camera.0,
            ortho: camera.1,
            size: [camera.2, camera.3],
            ..Default::default()
        },
        lines: args.line_options()?,
        image: false,
        svg: true,
        visibility: VisibilityMethod::Exact,
        setup: args.setup()?,
        ..Default::default()
    };
    let defaults = CameraDefaults {
        fov: camera.0,
        ortho: camera.1,
    };
    let specs = camera_specs(cameras, camera_file, views, defaults)?;
    let device = args.device.clone();
    let mut interrupt: Option<PyErr> = None;
    let done = py.detach(|| {
        let start = Instant::now();
        let gpu = open_gpu(device.as_deref())?;
        let mut out = Vec::with_capacity(specs.len());
        let mut last = start;
        line_views_on(&gpu, mesh.clone(), &opts, &specs, fields, &mut |_, v| {
            let now = Instant::now();
            out.push((v, (now - last).as_secs_f64() * 1e3));
            last = now;
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
    let (views, name) = done.map_err(to_py)?;
    let list = PyList::empty(py);
    for (v, wall_ms) in views {
        let d = view_dict(py, &mesh, v, &name)?;
        d.set_item("wall_ms", wall_ms)?;
        list.append(d)?;
    }
    Ok(list)
}

/// The cameras of [`lines_views`]: one of a camera list's JSON text, a
/// camera file or a number of fitted views.
fn camera_specs(
    cameras: Option<String>,
    camera_file: Option<PathBuf>,
    views: Option<usize>,
    defaults: CameraDefaults,
) -> PyResult<Vec<ViewSpec>> {
    match (cameras, camera_file, views) {
        (Some(text), None, None) => parse_camera_file(&text, "cameras", defaults),
        (None, Some(path), None) => load_camera_file(&path, defaults),
        (None, None, Some(n)) => fibonacci_views(n, defaults),
        _ => {
            return Err(value_err(
                "cameras: give a number of views, a list of camera dicts or a camera JSON file",
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
    Ok(camera_specs(cameras, camera_file, views, defaults)?.len())
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

/// One view of [`lines_views`] as a dict of numpy arrays.
fn view_dict<'py>(
    py: Python<'py>,
    mesh: &Mesh,
    v: LineView,
    device: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let vis = v
        .visible
        .as_ref()
        .ok_or_else(|| value_err("internal: the view was not classified"))?;
    let s = segment_arrays(vis, mesh);
    let n = s.a.len();
    let flat3 = |v: &[[f32; 3]]| v.concat();
    d.set_item("a", array(py, flat3(&s.a), &[n, 3])?)?;
    d.set_item("b", array(py, flat3(&s.b), &[n, 3])?)?;
    d.set_item("family_code", array(py, s.family, &[n])?)?;
    d.set_item("strength", array(py, s.strength, &[n])?)?;
    d.set_item("visible", array(py, s.visible, &[n])?)?;
    d.set_item("faces", array(py, s.faces.concat(), &[n, 4])?)?;
    d.set_item("chain", array(py, s.chain, &[n])?)?;
    d.set_item("face", array(py, s.face, &[n])?)?;
    let bary: Vec<f32> = s.bary.iter().flatten().flatten().copied().collect();
    d.set_item("bary", array(py, bary, &[n, 2, 3])?)?;
    if let Some(f) = v.fields {
        let nv = f.ndotv.len();
        d.set_item("ndotv", array(py, f.ndotv, &[nv])?)?;
        d.set_item("kr", array(py, f.kr, &[nv])?)?;
        d.set_item("dwkr", array(py, f.dwkr, &[nv])?)?;
        d.set_item("q1", array(py, f.q1, &[nv])?)?;
    }
    let c = v.camera;
    let cam = PyDict::new(py);
    cam.set_item("eye", c.eye.to_array())?;
    cam.set_item("target", c.target.to_array())?;
    cam.set_item("up", c.up.to_array())?;
    cam.set_item("fov", c.fov_y_deg)?;
    cam.set_item("ortho", c.ortho_height)?;
    d.set_item("camera", cam)?;
    let ms: f64 = v.passes.iter().map(|p| p.ms).sum();
    d.set_item("passes_ms", ms)?;
    let passes: Vec<&str> = v.passes.iter().map(|p| p.pass.name()).collect();
    d.set_item("passes", passes)?;
    d.set_item("feature_size", v.feature_size)?;
    d.set_item("device", device)?;
    Ok(d)
}
