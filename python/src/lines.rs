//! Line drawings: `lines` (every line family of rtsc, Rusinkiewicz and
//! DeCarlo's real-time suggestive contours program) through the front door
//! [`shapecue::api::line_segments_on`]: 3-D segments with their family and
//! strength, no picture.

use super::*;
use shapecue::api::LineSetup;
use shapecue::spec::feature_lines::{CurveOptions, FamilySet, FeatureSize, LineFamily};
use shapecue::spec::view::View;
use shapecue::stages::feature_lines::LineOptions;

/// lines(vertices, faces, families, eye, ortho, thresholds, isophotes,
/// light, switches, setup, device) -> dict
///
/// thresholds: (sc, rv, ar, ph, sh, fade); switches: (cull, test, fade,
/// hermite, hermite_kh); setup: (feature_size, compat, accumulate) by their
/// command-line names ("rtsc" | "edge" | a length; "exact" | "trimesh2";
/// "auto" | a scheme).
#[pyfunction]
#[pyo3(signature = (vertices, faces, families, eye, ortho, thresholds, isophotes, light, switches, setup, device))]
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
    let mesh = read_mesh(vertices, faces)?;
    let fams = FamilySet::parse(families).map_err(to_py)?;
    let [sc, rv, ar, ph, sh, sc_fade] = thresholds;
    let [cull, test, fade, hermite, hermite_kh] = switches;
    let opts = LineOptions {
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
            isophotes,
            light,
            cull,
            test,
            fade,
            hermite,
            hermite_kh,
        },
    };
    let (feature_size, compat, accumulate) = setup;
    let setup = LineSetup {
        curvature: CurvatureOptions {
            accumulate: if accumulate == "auto" {
                Default::default()
            } else {
                parse(&accumulate)?
            },
            compat: parse(&compat)?,
            ..Default::default()
        },
        feature_size: feature_size.parse::<FeatureSize>().map_err(to_py)?,
    };
    let view = View::from_eye(eye, ortho);
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
