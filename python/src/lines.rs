//! Line drawings: `lines` (every line family of rtsc, Rusinkiewicz and
//! DeCarlo's real-time suggestive contours program) through the front door
//! [`shapecue::api::line_segments_on`]: 3-D segments with their family and
//! strength, no picture.

use super::*;
use shapecue::api::LineOptions;
use shapecue::api::LineSetup;
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
