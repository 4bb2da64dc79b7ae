"""Curvature through the binding: the analytic torus, the CPU reference,
the command line's PLY, input dtypes and layouts, trimesh objects, bad
input, the deforming-mesh estimator and threads."""

import subprocess
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import shapecue
from conftest import read_ply, torus, write_obj

FIELDS = ("normals", "area", "k1", "k2", "d1", "d2", "dk")


def same(a, b):
    for k in FIELDS:
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k), err_msg=k)


def test_torus_shapes_dtypes_and_oracle(device):
    R, r = 1.0, 0.35
    v, f = torus(96, 48, R, r)
    c = shapecue.curvature(v, f)
    n = len(v)
    for k, shape in [("normals", (n, 3)), ("area", (n,)), ("k1", (n,)), ("k2", (n,)),
                     ("d1", (n, 3)), ("d2", (n, 3)), ("dk", (n, 4))]:
        a = getattr(c, k)
        assert a.shape == shape and a.dtype == np.float64, k
        assert np.all(np.isfinite(a)), k
    assert c.degenerate_faces == 0 and c.vertices_without_curvature == 0
    # k1 = 1/r around the tube, k2 = cos(v) / (R + r cos(v)).
    cosv = (np.hypot(v[:, 0], v[:, 1]) - R) / r
    np.testing.assert_allclose(c.k1, 1 / r, rtol=0.03)
    np.testing.assert_allclose(c.k2, cosv / (R + r * cosv), atol=0.05)
    np.testing.assert_allclose(np.linalg.norm(c.normals, axis=1), 1, atol=1e-5)
    np.testing.assert_allclose(c.mean, 0.5 * (c.k1 + c.k2))
    assert c.device
    assert 0 < c.library_ms


def test_device_matches_cpu_reference(device):
    v, f = torus(40, 20)
    ref = shapecue.curvature(v, f, reference=True)
    assert ref.device.startswith("cpu reference")
    for precision, tol in [("f32", 2e-3), ("f64", 1e-9)]:
        if precision == "f64" and not any(d["default"] and d["fp64"] for d in device):
            continue
        c = shapecue.curvature(v, f, precision=precision, accumulate="gather")
        scale = np.abs(ref.k1).max()
        np.testing.assert_allclose(c.k1, ref.k1, atol=tol * scale)
        np.testing.assert_allclose(c.k2, ref.k2, atol=tol * scale)
        np.testing.assert_allclose(c.normals, ref.normals, atol=tol)
        np.testing.assert_allclose(c.area, ref.area, rtol=tol)


def test_identical_to_command_line_ply(device, cli, tmp_path):
    v, f = torus(30, 14)
    obj, ply = tmp_path / "t.obj", tmp_path / "t.ply"
    write_obj(obj, v, f)
    r = subprocess.run([cli, "curvature", str(obj), "-o", str(ply), "--accumulate", "gather"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    props, faces = read_ply(ply)
    lv, lf = shapecue.load_mesh(obj)
    c = shapecue.curvature(lv, lf, accumulate="gather")
    np.testing.assert_array_equal(faces, lf)
    cols = {
        "x": lv[:, 0], "y": lv[:, 1], "z": lv[:, 2],
        "nx": c.normals[:, 0], "ny": c.normals[:, 1], "nz": c.normals[:, 2],
        "area": c.area, "k1": c.k1, "k2": c.k2,
        "d1x": c.d1[:, 0], "d1y": c.d1[:, 1], "d1z": c.d1[:, 2],
        "d2x": c.d2[:, 0], "d2y": c.d2[:, 1], "d2z": c.d2[:, 2],
        "dk0": c.dk[:, 0], "dk1": c.dk[:, 1], "dk2": c.dk[:, 2], "dk3": c.dk[:, 3],
    }
    assert list(props) == list(cols)
    for k, col in cols.items():
        # The file holds the same numbers, rounded to the file's type.
        np.testing.assert_array_equal(props[k], col.astype(props[k].dtype), err_msg=k)


def test_dtypes_and_layouts_give_the_same_result(device):
    v, f = torus(24, 12)
    base = shapecue.curvature(v, f, accumulate="gather")
    wide = np.zeros((len(v), 6))
    wide[:, ::2] = v
    variants = [
        (v.astype(np.float32).astype(np.float64), f),  # same values as the f32 case
        (np.asfortranarray(v), f.astype(np.int32)),
        (wide[:, ::2], f.astype(np.uint32)),  # strided, not contiguous
        (v.tolist(), f.tolist()),  # lists are converted
        (v, f.astype(np.int16)),  # another integer dtype is converted
        (v, f.astype(np.float64)),  # whole-number floats are accepted as indices
    ]
    for i, (vv, ff) in enumerate(variants):
        c = shapecue.curvature(vv, ff, accumulate="gather")
        if i == 0:
            same(c, shapecue.curvature(v.astype(np.float32), f, accumulate="gather"))
        else:
            same(c, base)


def test_trimesh_object(device):
    trimesh = pytest.importorskip("trimesh")
    v, f = torus(24, 12)
    m = trimesh.Trimesh(v, f, process=False)
    same(shapecue.curvature(m, accumulate="gather"), shapecue.curvature(v, f, accumulate="gather"))
    e = shapecue.feature_edges(m)
    assert e.contour > 0


def test_auto_accumulation_is_gather_on_cpu_devices_and_atomic_elsewhere(device):
    v, f = torus(24, 12)
    auto = shapecue.curvature(v, f)
    kind = next(d["kind"] for d in device if d["default"])
    if kind == "CPU":
        same(auto, shapecue.curvature(v, f, accumulate="gather"))
        same(shapecue.CurvatureEstimator(f, len(v)).run(v), auto)
    else:
        # Atomic sums vary in their last bits between runs.
        np.testing.assert_allclose(auto.k1, shapecue.curvature(v, f, accumulate="atomic").k1,
                                   rtol=1e-4, atol=1e-5)


def close(a, b):
    # Equal up to the last bits that atomic sums may vary in between runs,
    # should the library's default ever be a scatter scheme on the device.
    for k in FIELDS:
        np.testing.assert_allclose(getattr(a, k), getattr(b, k), rtol=1e-4, atol=1e-5, err_msg=k)


def test_auto_accumulation_is_the_default(device):
    v, f = torus(24, 12)
    default = shapecue.curvature(v, f)
    close(shapecue.curvature(v, f, accumulate="auto"), default)
    close(shapecue.CurvatureEstimator(f, len(v), accumulate="auto").run(v), default)
    close(shapecue.CurvatureEstimator(f, len(v)).run(v), default)


# The library's parser's message, naming every valid choice.
UNKNOWN_ACCUMULATION = r'unknown accumulation "sometimes": expected auto, atomic, atomic-native, gather'


def test_unknown_accumulation_names_the_choices(device):
    v, f = torus(12, 8)
    with pytest.raises(ValueError, match=UNKNOWN_ACCUMULATION):
        shapecue.curvature(v, f, accumulate="sometimes")
    with pytest.raises(ValueError, match=UNKNOWN_ACCUMULATION):
        shapecue.curvature(v, f, accumulate="sometimes", reference=True)
    with pytest.raises(ValueError, match=UNKNOWN_ACCUMULATION):
        shapecue.CurvatureEstimator(f, len(v), accumulate="sometimes")
    with pytest.raises(ValueError, match=UNKNOWN_ACCUMULATION):
        shapecue.build_kernels(accumulate=["gather", "sometimes"])


def test_isolated_vertices_and_degenerate_faces_are_counted(device):
    v, f = torus(24, 12)
    v = np.vstack([v, [[5.0, 5.0, 5.0]]])  # an unreferenced vertex
    f = np.vstack([f, [[0, 0, 1]]])  # a degenerate face
    c = shapecue.curvature(v, f)
    assert c.vertices_without_curvature == 1
    assert c.degenerate_faces == 1
    assert np.all(np.isfinite(c.k1)) and c.k1[-1] == 0


@pytest.mark.parametrize(
    "vertices, faces, message",
    [
        ([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]], [[0, 1, 2]], r"vertex 2: non-finite"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]], r"face 0: vertex index 3 out of range"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2], [0, -1, 2]], r"face 1: vertex index -1"),
        (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), r"no (vertices|faces)"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.zeros((0, 3), dtype=np.int64), r"no faces"),
        ([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]], r"vertices: expected shape \(N, 3\)"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2, 0]], r"faces: expected shape \(F, 3\)"),
        ([0, 0, 0], [[0, 1, 2]], r"vertices: expected a 2-D array"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2.5]], r"faces: indices must be whole"),
        ([["a", "b", "c"]], [[0, 0, 0]], r"vertices: expected numbers"),
    ],
)
def test_bad_input_raises_value_error(device, vertices, faces, message):
    with pytest.raises(ValueError, match=message):
        shapecue.curvature(vertices, faces)


def test_bad_options_and_devices(device):
    v, f = torus(12, 8)
    with pytest.raises(ValueError, match="unknown accumulation"):
        shapecue.curvature(v, f, accumulate="sometimes")
    with pytest.raises(ValueError, match="unknown precision"):
        shapecue.curvature(v, f, precision="f16")
    with pytest.raises(shapecue.DeviceError, match="no OpenCL device matches") as e:
        shapecue.curvature(v, f, device="no such device")
    assert isinstance(e.value, RuntimeError)
    with pytest.raises(shapecue.DeviceError):
        shapecue.curvature(v, f, device=99)
    with pytest.raises(TypeError):
        shapecue.curvature(v)
    c = shapecue.curvature(v, f, device=0)
    assert c.device == device[0]["name"]


def test_deforming_mesh_estimator(device):
    v, f = torus(32, 16)
    est = shapecue.CurvatureEstimator(f, len(v), accumulate="gather")
    assert (est.n_vertices, est.n_faces) == (len(v), len(f))
    rng = np.random.default_rng(1)
    for s in (1.0, 2.0, 0.5):
        pose = v * s + rng.normal(scale=1e-3, size=v.shape)
        same(est.run(pose), shapecue.curvature(pose, f, accumulate="gather"))
    with pytest.raises(ValueError, match="pose has 3 vertices"):
        est.run(v[:3])
    with pytest.raises(ValueError, match="vertex 5: non-finite"):
        bad = v.copy()
        bad[5, 1] = np.inf
        est.run(bad)
    with pytest.raises(ValueError, match="out of range"):
        shapecue.CurvatureEstimator(f, 10)


def test_threads_in_parallel_give_correct_results(device):
    meshes = [torus(20 + 4 * i, 10 + 2 * i) for i in range(4)]
    serial = [shapecue.curvature(v, f, accumulate="gather") for v, f in meshes]
    with ThreadPoolExecutor(4) as ex:
        par = list(ex.map(lambda m: shapecue.curvature(*m, accumulate="gather"), meshes * 3))
    for i, c in enumerate(par):
        same(c, serial[i % 4])


def test_gil_is_released_during_the_call(device):
    # While one thread is inside a long call, another keeps running Python
    # code: it could not if the call held the GIL.
    v, f = torus(400, 200)
    ticks = []
    stop = threading.Event()

    def ticker():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=ticker)
    t.start()
    try:
        time.sleep(0.01)
        t0 = time.perf_counter()
        shapecue.curvature(v, f, reference=True)
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    inside = [x for x in ticks if t0 < x < t1]
    assert t1 - t0 > 0.02, "the call was too quick to tell"
    assert len(inside) >= 3, f"{len(inside)} ticks in a {1e3 * (t1 - t0):.0f} ms call"
