//! Feature edges and scenes: `feature_edges` (House & Li's edge-out and
//! cap-out buffers of one view) and `render_file` / `render_text` (a scene
//! file or a scene given as a dict, through `shapecue::render_scene`).

use super::*;

/// feature_edges(vertices, faces, eye, direction, target, up, fov, ortho,
/// size, line_width, crease, contours, boundaries, depth_scale,
/// half_contours, caps, marked, device) -> dict
#[pyfunction]
#[pyo3(signature = (vertices, faces, eye, direction, target, up, fov, ortho, size,
    line_width, crease, contours, boundaries, depth_scale, half_contours, caps, marked, device))]
// PyO3 takes the arguments one by one (the positional signature of
// `_shapecue.pyi`); the body only collects them into `EdgeArgs`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn feature_edges<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    eye: Option<[f32; 3]>,
    direction: [f32; 3],
    target: Option<[f32; 3]>,
    up: Option<[f32; 3]>,
    fov: f32,
    ortho: bool,
    size: (u32, u32),
    line_width: f32,
    crease: f32,
    contours: bool,
    boundaries: bool,
    depth_scale: Option<f32>,
    half_contours: bool,
    caps: &str,
    marked: Option<&Bound<'py, PyAny>>,
    device: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let args = EdgeArgs {
        eye,
        direction,
        target,
        up,
        fov,
        ortho,
        size,
        line_width,
        crease,
        contours,
        boundaries,
        depth_scale,
        half_contours,
        caps,
        marked,
        device,
    };
    feature_edges_with(py, (vertices, faces), args)
}

/// The keyword options of `feature_edges`, as the Python layer passes them.
struct EdgeArgs<'a, 'py> {
    eye: Option<[f32; 3]>,
    direction: [f32; 3],
    target: Option<[f32; 3]>,
    up: Option<[f32; 3]>,
    fov: f32,
    ortho: bool,
    size: (u32, u32),
    line_width: f32,
    crease: f32,
    contours: bool,
    boundaries: bool,
    depth_scale: Option<f32>,
    half_contours: bool,
    caps: &'a str,
    marked: Option<&'a Bound<'py, PyAny>>,
    device: Option<String>,
}

impl EdgeArgs<'_, '_> {
    /// The view of the camera: at `eye`, or fitted to the mesh's bounds
    /// from `direction`.
    fn view(&self, mesh: &Mesh) -> PyResult<shapecue::spec::view::View> {
        use shapecue::api::{Placement, framed};
        let (w, h) = self.size;
        if w == 0 || h == 0 {
            return Err(value_err(format!("size: ({w}, {h}) must be positive")));
        }
        let placement = match self.eye {
            Some(e) => Placement::At(glam::Vec3::from(e)),
            None => {
                if glam::Vec3::from(self.direction).length_squared() == 0.0 {
                    return Err(value_err("direction: must be a non-zero vector"));
                }
                Placement::Fit(glam::Vec3::from(self.direction))
            }
        };
        let cam = framed(
            placement,
            self.target.map(glam::Vec3::from),
            self.up.map(glam::Vec3::from),
            self.fov,
            self.ortho,
            mesh.bounds(),
            w as f32 / h as f32,
        )
        .map_err(to_py)?;
        Ok(cam.view(w, h))
    }

    /// The library's options, `caps` checked by the library's parser
    /// (after `marked`, as before the options were collected).
    fn options(&self) -> PyResult<shapecue::EdgeOptions> {
        let marked = self.marked.map_or(Ok(Vec::new()), read_marked)?;
        Ok(shapecue::EdgeOptions {
            caps: parse(self.caps)?,
            line_width: self.line_width,
            crease_deg: self.crease,
            contours: self.contours,
            boundaries: self.boundaries,
            depth_scale: self.depth_scale,
            half_contours: self.half_contours,
            marked,
        })
    }
}

/// The `marked` vertex pairs, (M, 2), as u32 pairs.
fn read_marked(m: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 2]>> {
    let rows = m
        .extract::<Vec<[i64; 2]>>()
        .map_err(|_| value_err("marked: expected pairs of vertex indices, shape (M, 2)"))?;
    rows.iter()
        .enumerate()
        .map(|(i, p)| {
            let c = |x: i64| {
                u32::try_from(x).map_err(|_| {
                    value_err(format!("marked: pair {i}: vertex index {x} out of range"))
                })
            };
            Ok([c(p[0])?, c(p[1])?])
        })
        .collect()
}

/// [`feature_edges`] with its options collected.
fn feature_edges_with<'py>(
    py: Python<'py>,
    (vertices, faces): (&Bound<'py, PyAny>, &Bound<'py, PyAny>),
    args: EdgeArgs<'_, 'py>,
) -> PyResult<Bound<'py, PyDict>> {
    let mesh = read_mesh(vertices, faces)?;
    let view = args.view(&mesh)?;
    let opts = args.options()?;
    let device = args.device;
    let (out, name) = py
        .detach(|| {
            let gpu = open_gpu(device.as_deref())?;
            let out = shapecue::feature_edges_on(&gpu, &mesh, &view, &opts)?;
            Ok::<_, Error>((out, gpu.info.name.clone()))
        })
        .map_err(to_py)?;
    edges_dict(py, out, &view, &name)
}

/// The feature edges as a dict of counts and numpy arrays.
fn edges_dict<'py>(
    py: Python<'py>,
    out: shapecue::EdgeOutput,
    view: &shapecue::spec::view::View,
    name: &str,
) -> PyResult<Bound<'py, PyDict>> {
    use shapecue::spec::edges::{KIND_BOUNDARY, KIND_CONTOUR, KIND_CREASE, KIND_DRAWN};
    let d = PyDict::new(py);
    let ne = out.kind.len();
    let quads = |v: Vec<[f32; 4]>, per: usize| {
        let n = v.len() / per;
        array(py, v.into_flattened(), &[n, per, 4])
    };
    d.set_item("contour", out.count(KIND_CONTOUR))?;
    d.set_item("crease", out.count(KIND_CREASE))?;
    d.set_item("boundary", out.count(KIND_BOUNDARY))?;
    d.set_item("drawn", out.count(KIND_DRAWN))?;
    d.set_item("kind", array(py, out.kind, &[ne])?)?;
    d.set_item("quads", quads(out.edge_out, 4)?)?;
    d.set_item("cap_adj", quads(out.cap_adj, 4)?)?;
    d.set_item("cap_mh0", quads(out.cap_mh0, 3)?)?;
    d.set_item("cap_mh1", quads(out.cap_mh1, 3)?)?;
    d.set_item(
        "view_proj",
        array(py, view.view_proj.to_cols_array().to_vec(), &[4, 4])?,
    )?;
    d.set_item("device", name)?;
    Ok(d)
}

/// render_file(path, out_dir, force, device) -> report JSON text
#[pyfunction]
#[pyo3(signature = (path, out_dir, force, device))]
pub(crate) fn render_file(
    py: Python<'_>,
    path: PathBuf,
    out_dir: Option<PathBuf>,
    force: bool,
    device: Option<String>,
) -> PyResult<String> {
    let opts = shapecue::api::ExecOptions {
        out_dir,
        force,
        device: None,
        ..Default::default()
    };
    let report = py
        .detach(|| shapecue::render_scene_on(&open_gpu(device.as_deref())?, &path, &opts))
        .map_err(to_py)?;
    serde_json::to_string(&report).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// render_text(json, anchor, out_dir, force, device) -> report JSON text:
/// a scene given as JSON (from a Python dict), checked as the TOML it
/// stands for; relative paths are relative to `anchor`'s folder.
#[pyfunction]
#[pyo3(signature = (json, anchor, out_dir, force, device))]
pub(crate) fn render_text(
    py: Python<'_>,
    json: &str,
    anchor: PathBuf,
    out_dir: Option<PathBuf>,
    force: bool,
    device: Option<String>,
) -> PyResult<String> {
    let value: serde_json::Value =
        serde_json::from_str(json).map_err(|e| value_err(format!("scene: {e}")))?;
    let text = toml::to_string(&value).map_err(|e| value_err(format!("scene: {e}")))?;
    let scene = shapecue::api::Scene::from_str(&anchor, &text).map_err(to_py)?;
    let opts = shapecue::api::ExecOptions {
        out_dir,
        force,
        device: None,
        ..Default::default()
    };
    let report = py
        .detach(|| {
            let gpu = open_gpu(device.as_deref())?;
            shapecue::api::run_scene_on(&gpu, &scene, &opts, &mut |_, _| {})
        })
        .map_err(to_py)?;
    serde_json::to_string(&report).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}
