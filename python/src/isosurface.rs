//! `isosurface`: a volume array's isosurface (marching cubes and vertex
//! fusion on the device, with curvature where asked for) as numpy arrays.

use numpy::{PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use shapecue::Error;
use shapecue::spec::curvature::{AccumulateChoice, CurvatureOptions};

use crate::{array, c_slice, curvature_dict, open_gpu, parse, to_py, value_err};

/// Reads a (z, y, x) float32 or float64 array into a volume (x fastest).
fn read_volume(obj: &Bound<'_, PyAny>) -> PyResult<shapecue::volume::Volume> {
    fn vals<T: numpy::Element + Copy + ToF32>(
        a: &PyReadonlyArray3<'_, T>,
    ) -> ([usize; 3], Vec<f32>) {
        let s = a.shape();
        let dims = [s[2], s[1], s[0]];
        let values = match c_slice(a) {
            Some(sl) => sl.iter().map(|v| v.to_f32()).collect(),
            // Standard (logical C) order is x fastest for a (z, y, x) array.
            None => a.as_array().iter().map(|v| v.to_f32()).collect(),
        };
        (dims, values)
    }
    let (dims, values) = if let Ok(a) = obj.extract::<PyReadonlyArray3<'_, f32>>() {
        vals(&a)
    } else if let Ok(a) = obj.extract::<PyReadonlyArray3<'_, f64>>() {
        vals(&a)
    } else {
        return Err(value_err(
            "volume: expected a 3-D float32 or float64 array in (z, y, x) order",
        ));
    };
    shapecue::volume::Volume::new(dims, values, "volume").map_err(to_py)
}

trait ToF32 {
    fn to_f32(self) -> f32;
}
impl ToF32 for f32 {
    fn to_f32(self) -> f32 {
        self
    }
}
impl ToF32 for f64 {
    fn to_f32(self) -> f32 {
        self as f32
    }
}

/// isosurface(volume, iso, spacing, origin, fusion, inside, curvature, normals, device) -> dict
#[pyfunction]
#[pyo3(signature = (volume, iso, spacing, origin, fusion, inside, curvature, normals, device))]
// PyO3 takes the arguments one by one (the positional signature of
// `_shapecue.pyi`); the body only collects them into `IsoArgs`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn isosurface<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    iso: f32,
    spacing: [f64; 3],
    origin: [f64; 3],
    fusion: &str,
    inside: &str,
    curvature: bool,
    normals: bool,
    device: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let args = IsoArgs {
        iso,
        spacing,
        origin,
        fusion,
        inside,
        curvature,
        normals,
        device,
    };
    isosurface_with(py, volume, args)
}

/// The keyword options of `isosurface`, as the Python layer passes them.
struct IsoArgs<'a> {
    iso: f32,
    spacing: [f64; 3],
    origin: [f64; 3],
    fusion: &'a str,
    inside: &'a str,
    curvature: bool,
    normals: bool,
    device: Option<String>,
}

impl IsoArgs<'_> {
    /// The library's options, names checked by the library's parsers. The
    /// curvature of the result uses the library's defaults ("auto"
    /// accumulation, decided by [`AccumulateChoice::resolve`]).
    fn options(&self) -> PyResult<shapecue::IsoOptions> {
        let curvature = CurvatureOptions {
            accumulate: AccumulateChoice::Auto.resolve(),
            ..CurvatureOptions::default()
        };
        Ok(shapecue::IsoOptions {
            fusion: parse(self.fusion)?,
            inside: parse(self.inside)?,
            curvature: self.curvature.then_some(curvature),
            gradient_normals: self.normals,
            ..Default::default()
        })
    }
}

/// [`isosurface`] with its options collected.
fn isosurface_with<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    args: IsoArgs<'_>,
) -> PyResult<Bound<'py, PyDict>> {
    let iso = args.iso;
    if !iso.is_finite() {
        return Err(value_err(format!("iso: {iso} is not a finite number")));
    }
    let vol = read_volume(volume)?
        .with_geometry(args.spacing, args.origin)
        .map_err(to_py)?;
    let opts = args.options()?;
    let device = args.device;
    let (s, name) = py
        .detach(|| {
            let gpu = open_gpu(device.as_deref())?;
            let s = shapecue::isosurface_on(&gpu, &vol, iso, &opts)?;
            Ok::<_, Error>((s, gpu.info.name.clone()))
        })
        .map_err(to_py)?;
    isosurface_dict(py, s, &name)
}

/// The isosurface as a dict of numpy arrays, counts and timings.
fn isosurface_dict<'py>(
    py: Python<'py>,
    s: shapecue::Isosurface,
    name: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let (nv, nf) = (s.mesh.n_vertices(), s.mesh.n_faces());
    d.set_item(
        "vertices",
        array(py, s.mesh.positions.into_flattened(), &[nv, 3])?,
    )?;
    d.set_item("faces", array(py, s.mesh.faces.into_flattened(), &[nf, 3])?)?;
    match s.normals {
        Some(n) => d.set_item("normals", array(py, n.into_flattened(), &[nv, 3])?)?,
        None => d.set_item("normals", py.None())?,
    }
    match s.curvature {
        Some(c) => d.set_item("curvature", curvature_dict(py, c, name)?)?,
        None => d.set_item("curvature", py.None())?,
    }
    d.set_item("soup_triangles", s.stats.soup_triangles)?;
    d.set_item("degenerate_dropped", s.stats.degenerate_dropped)?;
    d.set_item("kernel_ms", s.stats.timing.kernel_ms)?;
    d.set_item("wall_ms", s.stats.timing.wall_ms)?;
    d.set_item("upload_ms", s.stats.timing.phase_ms("upload"))?;
    d.set_item("device", name)?;
    Ok(d)
}
