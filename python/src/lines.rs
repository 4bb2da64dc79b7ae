//! Line drawings: `lines` (every line family of rtsc, Rusinkiewicz and
//! DeCarlo's real-time suggestive contours program) through the front door
//! [`shapecue::api::line_segments_on`]: 3-D segments with their family and
//! strength, no picture.

use super::*;
use pyo3::types::PyList;
use shapecue::api::{
    CameraDefaults, LineOptions, LineSetup, LineView, LinesPictureOptions, Shot, VisibilityMethod,
    fibonacci_views, line_views_on, parse_camera_file, segment_arrays,
};
use shapecue::spec::feature_lines::{CurveOptions, FamilySet, FeatureSize, LineFamily};
use shapecue::spec::view::View;

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
    /// The line families and their thresholds and switches.
    fn line_options(&self) -> PyResult<LineOptions> {
        let fams = FamilySet::parse(self.families).map_err(to_py)?;
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
    let kind: Vec<u32> = ls.segments.iter().map(|s| s.2).collect();
    let strength: Vec<f32> = ls.segments.iter().map(|s| s.3).collect();
    let d = PyDict::new(py);
    d.set_item("segments", array(py, pts, &[n, 2, 3])?)?;
    d.set_item("kind", array(py, kind, &[n])?)?;
    d.set_item("strength", array(py, strength, &[n])?)?;
    let names: Vec<&str> = LineFamily::ALL.iter().map(|f| f.name()).collect();
    d.set_item("family_names", names)?;
    d.set_item("feature_size", ls.feature_size)?;
    d.set_item("kernel_ms", ls.timing.kernel_ms)?;
    d.set_item("device", name)?;
    Ok(d)
}

/// lines_views(vertices, faces, families, cameras, views, camera, thresholds,
/// isophotes, light, switches, setup, fields, device) -> list of dicts
///
/// The lines of many views in one setup (the pose passes once, the view
/// passes per view), each split by exact visibility and chained. `cameras`:
/// the JSON text of a camera file (`{"cameras": [...]}`), or `None` with
/// `views` cameras on the Fibonacci lattice; `camera`: (fov, ortho, width,
/// height), the cameras' defaults and the image size the fitted views and
/// the visibility's spacing are for.
#[pyfunction]
#[pyo3(signature = (vertices, faces, families, cameras, views, camera, thresholds, isophotes, light, switches, setup, fields, device))]
#[allow(clippy::too_many_arguments)]
pub fn lines_views<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    families: &str,
    cameras: Option<String>,
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
    let specs = match (cameras, views) {
        (Some(text), None) => parse_camera_file(&text, "cameras", defaults),
        (None, Some(n)) => fibonacci_views(n, defaults),
        _ => return Err(value_err("give cameras or views, not both")),
    }
    .map_err(to_py)?;
    let device = args.device.clone();
    let done = py
        .detach(|| {
            let gpu = open_gpu(device.as_deref())?;
            let mut out = Vec::with_capacity(specs.len());
            line_views_on(&gpu, mesh.clone(), &opts, &specs, fields, &mut |_, v| {
                out.push(v);
                Ok(())
            })?;
            Ok::<_, Error>((out, gpu.info.name.clone()))
        })
        .map_err(to_py)?;
    let (views, name) = done;
    let list = PyList::empty(py);
    for v in views {
        list.append(view_dict(py, &mesh, v, &name)?)?;
    }
    Ok(list)
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
    d.set_item("kind", array(py, s.family, &[n])?)?;
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
    let names: Vec<&str> = LineFamily::ALL.iter().map(|f| f.name()).collect();
    d.set_item("family_names", names)?;
    Ok(d)
}
