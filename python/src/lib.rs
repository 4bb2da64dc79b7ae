//! `shapecue._shapecue`: the Python extension module over shapecue's front
//! door (`shapecue::curvature`, `shapecue::isosurface`,
//! `shapecue::feature_edges`, `shapecue::render_scene`), its stateful
//! per-topology estimator and the mesh and volume loaders.
//!
//! What crosses: numpy arrays in, read where they lie (C-contiguous arrays of
//! the accepted dtypes through their slice, strided ones element by element,
//! any other dtype converted by the Python layer first) into the library's
//! owned `Mesh` / `Volume`; results out as numpy arrays that take ownership
//! of the library's vectors (no copy). Every call that touches the device
//! runs with the GIL released (`Python::detach`), so Python threads compute
//! in parallel. Errors become Python exceptions: bad input `ValueError`
//! (the library's message, naming the element), unreadable files `OSError`,
//! device problems `DeviceError` (a `RuntimeError`), GL problems
//! `RenderError` (a `RuntimeError`). The Python package `shapecue` wraps
//! these functions in typed result objects; call them through it.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use shapecue::api::CurvatureEstimator as RustEstimator;
use shapecue::api::Gpu;
use shapecue::mesh::NormalsSource;
use shapecue::spec::curvature::{
    Accumulate, AccumulateChoice, Compat, Curvature, CurvatureOptions, Precision,
};
use shapecue::{Error, Mesh};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

mod isosurface;
mod lines;
mod scene;

create_exception!(
    _shapecue,
    DeviceError,
    PyRuntimeError,
    "No OpenCL device, no device matching the selection, a device lacking what \
     the variant needs (fp64, 64-bit atomics), an OpenCL call or kernel build failure."
);
create_exception!(
    _shapecue,
    RenderError,
    PyRuntimeError,
    "No headless OpenGL (EGL and Mesa missing), or an OpenGL call failed."
);

/// The library's error as the Python exception a caller can catch.
fn to_py(e: Error) -> PyErr {
    let msg = e.to_string();
    match e {
        Error::InvalidInput { .. }
        | Error::InvalidArgument(_)
        | Error::UnsupportedFormat { .. } => PyValueError::new_err(msg),
        Error::Io { ref source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(msg)
        }
        Error::Io { .. } | Error::Write { .. } => PyOSError::new_err(msg),
        Error::NoGl { .. } | Error::Render { .. } => RenderError::new_err(msg),
        _ => DeviceError::new_err(msg),
    }
}

fn value_err(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// The array's data as one slice in logical (C) order, when it is laid out
/// so; `None` for strided and Fortran-ordered arrays (numpy's `as_slice`
/// also accepts the latter, in memory order).
fn c_slice<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
    a: &'a numpy::PyReadonlyArray<'_, T, D>,
) -> Option<&'a [T]> {
    if a.is_c_contiguous() {
        a.as_slice().ok()
    } else {
        None
    }
}

/// Reads an (N, 3) array of f64 or f32 (any strides) into owned rows.
fn read_rows3f(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    fn rows<T: numpy::Element + Copy + Into<f64>>(
        a: &PyReadonlyArray2<'_, T>,
        what: &str,
    ) -> PyResult<Vec<[f64; 3]>> {
        let shape = a.shape();
        if shape[1] != 3 {
            return Err(value_err(format!(
                "{what}: expected shape (N, 3), got ({}, {})",
                shape[0], shape[1]
            )));
        }
        if let Some(s) = c_slice(a) {
            return Ok(s
                .chunks_exact(3)
                .map(|c| [c[0].into(), c[1].into(), c[2].into()])
                .collect());
        }
        let v = a.as_array();
        Ok(v.rows()
            .into_iter()
            .map(|r| [r[0].into(), r[1].into(), r[2].into()])
            .collect())
    }
    if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, f64>>() {
        rows(&a, what)
    } else if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, f32>>() {
        rows(&a, what)
    } else {
        Err(value_err(format!(
            "{what}: expected a 2-D float64 or float32 array of shape (N, 3)"
        )))
    }
}

/// Reads an (F, 3) integer array (int32, int64, uint32; any strides) into
/// u32 triangles; negative or too large indices are refused naming the face.
fn read_faces(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[u32; 3]>> {
    fn tris<T: numpy::Element + Copy + TryInto<u32> + std::fmt::Display>(
        a: &PyReadonlyArray2<'_, T>,
        what: &str,
    ) -> PyResult<Vec<[u32; 3]>> {
        let shape = a.shape();
        if shape[1] != 3 {
            return Err(value_err(format!(
                "{what}: expected shape (F, 3) (triangles), got ({}, {})",
                shape[0], shape[1]
            )));
        }
        let conv = |i: usize, c: &[T]| -> PyResult<[u32; 3]> {
            let mut out = [0u32; 3];
            for k in 0..3 {
                out[k] = c[k].try_into().map_err(|_| {
                    value_err(format!(
                        "{what}: face {i}: vertex index {} out of range",
                        c[k]
                    ))
                })?;
            }
            Ok(out)
        };
        if let Some(s) = c_slice(a) {
            return s
                .chunks_exact(3)
                .enumerate()
                .map(|(i, c)| conv(i, c))
                .collect();
        }
        a.as_array()
            .rows()
            .into_iter()
            .enumerate()
            .map(|(i, r)| conv(i, &[r[0], r[1], r[2]]))
            .collect()
    }
    if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, i32>>() {
        tris(&a, what)
    } else if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, i64>>() {
        tris(&a, what)
    } else if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, u32>>() {
        tris(&a, what)
    } else {
        Err(value_err(format!(
            "{what}: expected a 2-D int32, int64 or uint32 array of shape (F, 3)"
        )))
    }
}

/// Reads an (N, 3) array of f32 or f64 (any strides) into f32 rows, as the
/// library holds stored normals.
fn read_rows3f32(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f32; 3]>> {
    if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, f32>>() {
        let shape = a.shape();
        if shape[1] != 3 {
            return Err(value_err(format!(
                "{what}: expected shape (N, 3), got ({}, {})",
                shape[0], shape[1]
            )));
        }
        if let Some(s) = c_slice(&a) {
            return Ok(s.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
        }
        return Ok(a
            .as_array()
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect());
    }
    // f64 (or an error naming both dtypes), rounded to f32 as the device
    // takes them.
    Ok(read_rows3f(obj, what)?
        .into_iter()
        .map(|r| r.map(|c| c as f32))
        .collect())
}

fn read_mesh(vertices: &Bound<'_, PyAny>, faces: &Bound<'_, PyAny>) -> PyResult<Mesh> {
    let positions = read_rows3f(vertices, "vertices")?;
    let faces = read_faces(faces, "faces")?;
    if positions.is_empty() {
        return Err(value_err("vertices: the mesh has no vertices"));
    }
    Mesh::new(positions, faces, "mesh").map_err(to_py)
}

/// An owned Vec as a numpy array of shape `shape` (no copy).
fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    v: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let a = PyArray1::from_vec(py, v);
    if shape.len() == 1 {
        return Ok(a.into_any());
    }
    Ok(a.reshape(shape)?.into_any())
}

fn parse<T: std::str::FromStr<Err = Error>>(s: &str) -> PyResult<T> {
    s.parse::<T>().map_err(to_py)
}

/// The curvature keyword options of `curvature` and `CurvatureEstimator`,
/// as the Python layer passes them (its names and defaults).
struct CurvatureArgs<'a> {
    accumulate: &'a str,
    precision: &'a str,
    compat: &'a str,
    dcurv: bool,
    device: Option<String>,
}

impl CurvatureArgs<'_> {
    /// The library's options, every name checked by the library's parser
    /// before a device opens; `accumulate = "auto"` is decided by
    /// [`AccumulateChoice::resolve`], the library's one place for it.
    fn options(&self) -> PyResult<CurvatureOptions> {
        Ok(CurvatureOptions {
            accumulate: parse::<AccumulateChoice>(self.accumulate)?.resolve(),
            precision: parse(self.precision)?,
            compat: parse(self.compat)?,
            dcurv: self.dcurv,
            // by device type, as on the command line
            lanes: shapecue::spec::curvature::Lanes::Auto,
        })
    }
}

/// A device selection: `device=` and the `SHAPECUE_DEVICE` it was made under.
type DeviceKey = (Option<String>, Option<String>);

thread_local! {
    /// The devices this thread has opened, by (`device=`, `SHAPECUE_DEVICE`):
    /// opening a context and building the kernels costs far more than a
    /// call on a small mesh, so each Python thread opens a device once and
    /// reuses it (its own queue, so threads compute in parallel).
    static DEVICES: RefCell<HashMap<DeviceKey, Arc<Gpu>>> =
        RefCell::new(HashMap::new());
}

/// This thread's device for `device` (see [`DEVICES`]).
fn open_gpu(device: Option<&str>) -> shapecue::Result<Arc<Gpu>> {
    let key = (
        device.map(str::to_string),
        std::env::var("SHAPECUE_DEVICE").ok(),
    );
    if let Some(g) = DEVICES.with(|m| m.borrow().get(&key).cloned()) {
        return Ok(g);
    }
    let g = Arc::new(Gpu::new(device)?);
    DEVICES.with(|m| m.borrow_mut().insert(key, g.clone()));
    Ok(g)
}

/// The curvature result as a dict of numpy arrays, counts and timings.
fn curvature_dict<'py>(
    py: Python<'py>,
    c: Curvature,
    device: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = c.field.len();
    let f = c.field;
    d.set_item("normals", array(py, f.normals.into_flattened(), &[n, 3])?)?;
    d.set_item("area", array(py, f.areas, &[n])?)?;
    d.set_item("k1", array(py, f.k1, &[n])?)?;
    d.set_item("k2", array(py, f.k2, &[n])?)?;
    d.set_item("d1", array(py, f.d1.into_flattened(), &[n, 3])?)?;
    d.set_item("d2", array(py, f.d2.into_flattened(), &[n, 3])?)?;
    d.set_item("dk", array(py, f.dk.into_flattened(), &[n, 4])?)?;
    d.set_item("degenerate_faces", c.counts.degenerate_faces)?;
    d.set_item(
        "vertices_without_curvature",
        c.counts.vertices_without_curvature,
    )?;
    d.set_item("tensor_solves_skipped", c.counts.tensor_solves_skipped)?;
    d.set_item("dcurv_solves_skipped", c.counts.dcurv_solves_skipped)?;
    d.set_item("kernel_ms", c.timing.kernel_ms)?;
    d.set_item("wall_ms", c.timing.wall_ms)?;
    d.set_item("topology_ms", c.timing.phase_ms("topology"))?;
    d.set_item("device_bytes", c.device_bytes)?;
    d.set_item("device", device)?;
    Ok(d)
}

/// devices() -> str: the devices as `shapecue devices --json` writes them
/// (the same fields), each with `default` added; the package parses it.
#[pyfunction]
fn devices(py: Python<'_>) -> PyResult<String> {
    let (all, default) = py
        .detach(|| {
            let all = shapecue::api::list_devices()?;
            let default = Gpu::new(None).ok().map(|g| g.info.index);
            Ok::<_, Error>((all, default))
        })
        .map_err(to_py)?;
    let mut list = Vec::with_capacity(all.len());
    for d in all {
        let mut v = serde_json::to_value(&d)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
        if let Some(m) = v.as_object_mut() {
            m.insert("default".into(), (Some(d.index) == default).into());
        }
        list.push(v);
    }
    Ok(serde_json::Value::Array(list).to_string())
}

/// build_kernels(accumulate, precision, compat, device) -> list[dict]
///
/// Builds the curvature program of every combination of the given
/// variants on the device, runs it once and saves it into shapecue's kernel
/// cache (`shapecue::api::build_kernels`), with a `Gpu` of its
/// own so that later calls of this process keep the usual saving rule.
#[pyfunction]
#[pyo3(signature = (accumulate, precision, compat, device))]
fn build_kernels<'py>(
    py: Python<'py>,
    accumulate: Vec<String>,
    precision: Vec<String>,
    compat: Vec<String>,
    device: Option<String>,
) -> PyResult<Bound<'py, PyList>> {
    // Names are checked by the library's parsers before the device opens;
    // "auto" is decided by the library (AccumulateChoice::resolve).
    let accumulate: Vec<Accumulate> = accumulate
        .iter()
        .map(|a| parse::<AccumulateChoice>(a).map(AccumulateChoice::resolve))
        .collect::<PyResult<_>>()?;
    let precision: Vec<Precision> = precision
        .iter()
        .map(|p| parse(p))
        .collect::<PyResult<_>>()?;
    let compat: Vec<Compat> = compat.iter().map(|c| parse(c)).collect::<PyResult<_>>()?;
    let built = py
        .detach(|| {
            let gpu = Arc::new(Gpu::new(device.as_deref())?);
            // lanes by device type, as on the command line
            let lanes = shapecue::spec::curvature::Lanes::Auto;
            let variants = CurvatureOptions::combinations(&accumulate, &precision, &compat, lanes);
            shapecue::api::build_kernels(&gpu, &variants, |_| {})
        })
        .map_err(to_py)?;
    let out = PyList::empty(py);
    for b in built {
        let e = PyDict::new(py);
        e.set_item("variant", &b.variant)?;
        e.set_item("options", &b.program.options)?;
        e.set_item("cache", &b.program.cache)?;
        e.set_item("saved", b.program.saved)?;
        e.set_item("build_s", b.build_s)?;
        e.set_item("save_s", b.save_s)?;
        out.append(e)?;
    }
    Ok(out)
}

/// curvature(mesh, accumulate, precision, compat, dcurv, device, reference) -> dict
///
/// The curvature of a [`PyMesh`]; where it holds stored normals (a file's,
/// or the array given), the curvature starts from them.
#[pyfunction]
#[pyo3(signature = (mesh, accumulate, precision, compat, dcurv, device, reference))]
// PyO3 takes the arguments one by one (the positional signature of
// `_shapecue.pyi`); the body only collects them into `CurvatureArgs`.
#[allow(clippy::too_many_arguments)]
fn curvature<'py>(
    py: Python<'py>,
    mesh: PyRef<'py, PyMesh>,
    accumulate: &str,
    precision: &str,
    compat: &str,
    dcurv: bool,
    device: Option<String>,
    reference: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let args = CurvatureArgs {
        accumulate,
        precision,
        compat,
        dcurv,
        device,
    };
    curvature_with(py, mesh.mesh.clone(), args, reference)
}

/// [`curvature`] with its options collected: on the device, or with the
/// single-threaded f64 CPU reference when `reference`.
fn curvature_with<'py>(
    py: Python<'py>,
    mesh: Arc<Mesh>,
    args: CurvatureArgs<'_>,
    reference: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let opts = args.options()?;
    let device = args.device;
    let mut library_ms = 0.0;
    let (c, name) = py
        .detach(|| {
            if reference {
                // The reference computes in f64, so it judges faces by f64
                // rounding (as the command line's --cpu does).
                let opts = CurvatureOptions {
                    precision: Precision::F64,
                    ..opts
                };
                let t = Instant::now();
                let c = shapecue::api::curvature_reference(&mesh, opts)?;
                library_ms = t.elapsed().as_secs_f64() * 1e3;
                Ok::<_, Error>((c, "cpu reference (f64, single thread)".to_string()))
            } else {
                let gpu = open_gpu(device.as_deref())?;
                let t = Instant::now();
                let c = shapecue::curvature_on(&gpu, &mesh, opts)?;
                library_ms = t.elapsed().as_secs_f64() * 1e3;
                Ok((c, gpu.info.name.clone()))
            }
        })
        .map_err(to_py)?;
    let d = curvature_dict(py, c, &name)?;
    // The library call alone, so that the binding's own cost (arrays in and
    // out) is the caller's wall time minus this, measured in one call.
    d.set_item("library_ms", library_ms)?;
    Ok(d)
}

/// A mesh topology's curvature estimator on one device (see the Python
/// class `shapecue.CurvatureEstimator`).
#[pyclass(name = "_CurvatureEstimator", module = "shapecue._shapecue")]
struct PyEstimator {
    // The library's estimator is Send but not Sync (OpenCL kernels): the
    // mutex makes the Python object shareable and serialises runs on it.
    inner: Mutex<RustEstimator>,
    n_vertices: usize,
    n_faces: usize,
    device: String,
}

impl PyEstimator {
    /// [`PyEstimator::new`] with its options collected: the topology checked
    /// and built on this thread's device.
    fn open(
        py: Python<'_>,
        faces: &Bound<'_, PyAny>,
        n_vertices: usize,
        args: CurvatureArgs<'_>,
    ) -> PyResult<Self> {
        let faces = read_faces(faces, "faces")?;
        if n_vertices == 0 {
            return Err(value_err("n_vertices: the mesh has no vertices"));
        }
        shapecue::mesh::check_faces(n_vertices, &faces, "faces").map_err(to_py)?;
        let opts = args.options()?;
        let device = args.device;
        let n_faces = faces.len();
        let (est, device) = py
            .detach(|| {
                let gpu = open_gpu(device.as_deref())?;
                let name = gpu.info.name.clone();
                Ok::<_, Error>((RustEstimator::new(gpu, n_vertices, &faces, opts)?, name))
            })
            .map_err(to_py)?;
        Ok(PyEstimator {
            inner: Mutex::new(est),
            n_vertices,
            n_faces,
            device,
        })
    }
}

#[pymethods]
impl PyEstimator {
    #[new]
    #[pyo3(signature = (faces, n_vertices, accumulate, precision, compat, dcurv, device))]
    // PyO3 takes the arguments one by one (the positional signature of
    // `_shapecue.pyi`); the body only collects them into `CurvatureArgs`.
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        faces: &Bound<'_, PyAny>,
        n_vertices: usize,
        accumulate: &str,
        precision: &str,
        compat: &str,
        dcurv: bool,
        device: Option<String>,
    ) -> PyResult<Self> {
        let args = CurvatureArgs {
            accumulate,
            precision,
            compat,
            dcurv,
            device,
        };
        Self::open(py, faces, n_vertices, args)
    }

    /// run(positions) -> dict: the curvature of one pose.
    fn run<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let pos = read_rows3f(positions, "positions")?;
        let inner = &self.inner;
        let c = py
            .detach(|| {
                let mut est = inner.lock().unwrap_or_else(|p| p.into_inner());
                let t = Instant::now();
                est.set_positions(&pos)?;
                let mut timing = est.run()?;
                let field = est.read()?;
                timing.wall_ms = t.elapsed().as_secs_f64() * 1e3;
                timing.phase("topology", est.topology_ms());
                Ok::<_, Error>(Curvature {
                    field,
                    counts: est.counts()?,
                    timing,
                    device_bytes: est.device_bytes(),
                })
            })
            .map_err(to_py)?;
        let d = curvature_dict(py, c, &self.device)?;
        d.set_item("library_ms", d.get_item("wall_ms")?)?;
        Ok(d)
    }

    #[getter]
    fn n_vertices(&self) -> usize {
        self.n_vertices
    }

    #[getter]
    fn n_faces(&self) -> usize {
        self.n_faces
    }

    #[getter]
    fn device(&self) -> &str {
        &self.device
    }

    #[getter]
    fn topology_ms(&self) -> f64 {
        self.inner
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .topology_ms()
    }

    #[getter]
    fn device_bytes(&self) -> u64 {
        self.inner
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .device_bytes()
    }
}

/// A mesh the library holds for the calls that take one (`curvature`,
/// `lines_views`): loaded from a file by the library's loader, which keeps
/// the vertex normals the file stores (as the command line loads it), or
/// made from arrays, with the normals given, if any.
#[pyclass(name = "_Mesh", module = "shapecue._shapecue", frozen)]
pub(crate) struct PyMesh {
    pub(crate) mesh: Arc<Mesh>,
}

#[pymethods]
impl PyMesh {
    #[getter]
    fn n_vertices(&self) -> usize {
        self.mesh.n_vertices()
    }

    #[getter]
    fn n_faces(&self) -> usize {
        self.mesh.n_faces()
    }

    /// Whether the mesh holds stored normals (a file's, or the array given).
    #[getter]
    fn has_normals(&self) -> bool {
        self.mesh.normals.is_some()
    }

    /// arrays() -> (vertices float64 (V, 3), faces uint32 (F, 3), normals
    /// float32 (V, 3) or None): copies of what the library holds.
    fn arrays<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let m = &self.mesh;
        let (nv, nf) = (m.n_vertices(), m.n_faces());
        let normals = match &m.normals {
            Some(n) => array(py, n.as_flattened().to_vec(), &[nv, 3])?,
            None => py.None().into_bound(py),
        };
        Ok((
            array(py, m.positions.as_flattened().to_vec(), &[nv, 3])?,
            array(py, m.faces.as_flattened().to_vec(), &[nf, 3])?,
            normals,
        ))
    }
}

/// load_mesh(path, weld, normals) -> _Mesh
///
/// The mesh file read by the library's loader, as the command line reads
/// it: `normals` "file" keeps (and checks) the vertex normals it stores,
/// "computed" drops them (`--normals`).
#[pyfunction]
#[pyo3(signature = (path, weld, normals))]
fn load_mesh(py: Python<'_>, path: PathBuf, weld: bool, normals: &str) -> PyResult<PyMesh> {
    let opts = shapecue::mesh::LoadOptions {
        weld,
        normals: parse::<NormalsSource>(normals)?,
    };
    let m = py
        .detach(|| shapecue::mesh::load(Path::new(&path), &opts))
        .map_err(to_py)?;
    Ok(PyMesh { mesh: Arc::new(m) })
}

/// mesh_from_arrays(vertices, faces, normals) -> _Mesh
///
/// A mesh of arrays. `normals`: a (V, 3) float array of vertex normals the
/// curvature starts from (as from a file's), checked as the loader checks
/// a file's (`Mesh::check_normals`: a zero or non-finite normal at a vertex
/// some face uses is refused, naming the vertex); or None, or the name
/// "file" or "computed" (checked by the library's parser): arrays store no
/// normals, so both compute them from the faces.
#[pyfunction]
#[pyo3(signature = (vertices, faces, normals))]
fn mesh_from_arrays(
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    normals: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyMesh> {
    let mut mesh = read_mesh(vertices, faces)?;
    if let Some(name) = normals.and_then(|n| n.extract::<String>().ok()) {
        parse::<NormalsSource>(&name)?;
    } else if let Some(n) = normals {
        let n = read_rows3f32(n, "normals")?;
        if n.len() != mesh.n_vertices() {
            return Err(value_err(format!(
                "normals: {} rows for {} vertices: give one normal per vertex, shape ({}, 3)",
                n.len(),
                mesh.n_vertices(),
                mesh.n_vertices()
            )));
        }
        mesh.normals = Some(n);
        mesh.check_normals("normals").map_err(to_py)?;
    }
    Ok(PyMesh {
        mesh: Arc::new(mesh),
    })
}

/// generated_mesh(name, vertices) -> (vertices float64 (V, 3), faces uint32 (F, 3))
///
/// The command line's generated meshes (`shapecue lines torus --vertices
/// N`: torus, sphere, ellipsoid, cylinder, plane), for comparing with it.
#[pyfunction]
fn generated_mesh<'py>(
    py: Python<'py>,
    name: &str,
    vertices: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    shapecue::spec::limits::check_mesh_vertices("vertices", vertices).map_err(to_py)?;
    let Some((_, m)) = shapecue::mesh::generated_by_name(name, vertices) else {
        return Err(value_err(format!(
            "{name:?} names no generated mesh: torus, sphere, ellipsoid, cylinder or plane"
        )));
    };
    let (nv, nf) = (m.n_vertices(), m.n_faces());
    Ok((
        array(py, m.positions.into_flattened(), &[nv, 3])?,
        array(py, m.faces.into_flattened(), &[nf, 3])?,
    ))
}

/// load_volume(path) -> (values float32 (z, y, x), spacing (x, y, z), origin (x, y, z))
#[pyfunction]
fn load_volume(py: Python<'_>, path: PathBuf) -> PyResult<(Bound<'_, PyAny>, [f64; 3], [f64; 3])> {
    let v = py
        .detach(|| shapecue::volume::load(Path::new(&path), None))
        .map_err(to_py)?;
    let [nx, ny, nz] = v.dims;
    Ok((array(py, v.values, &[nz, ny, nx])?, v.spacing, v.origin))
}

/// The extension module.
#[pymodule]
fn _shapecue(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("DeviceError", py.get_type::<DeviceError>())?;
    m.add("RenderError", py.get_type::<RenderError>())?;
    m.add_function(wrap_pyfunction!(devices, m)?)?;
    m.add_function(wrap_pyfunction!(curvature, m)?)?;
    m.add_function(wrap_pyfunction!(build_kernels, m)?)?;
    m.add_function(wrap_pyfunction!(isosurface::isosurface, m)?)?;
    m.add_function(wrap_pyfunction!(scene::feature_edges, m)?)?;
    m.add_function(wrap_pyfunction!(scene::render_file, m)?)?;
    m.add_function(wrap_pyfunction!(scene::render_text, m)?)?;
    m.add_function(wrap_pyfunction!(lines::lines_views, m)?)?;
    m.add_function(wrap_pyfunction!(lines::scene_lines, m)?)?;
    m.add_function(wrap_pyfunction!(lines::check_cameras, m)?)?;
    m.add_function(wrap_pyfunction!(lines::line_families, m)?)?;
    m.add_function(wrap_pyfunction!(lines::family_codes, m)?)?;
    m.add("MAX_VIEWS", shapecue::api::MAX_VIEWS)?;
    m.add_function(wrap_pyfunction!(load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_from_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(load_volume, m)?)?;
    m.add_function(wrap_pyfunction!(generated_mesh, m)?)?;
    m.add_class::<PyEstimator>()?;
    m.add_class::<PyMesh>()?;
    Ok(())
}
