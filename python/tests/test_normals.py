"""Stored vertex normals from Python: a mesh file's normals (OBJ ``vn``
lines, one per vertex) are kept by the library's loader and the curvature
and every line family start from them, as on the command line
(``--normals file``, the default); ``normals="computed"`` drops them, as
``--normals computed``; arrays take them as ``normals=``."""

import json
import subprocess

import numpy as np
import pytest

import shapecue
from conftest import read_ply, torus
from test_lines import segments_json_rows

FAMILIES = "contours,suggestive,ridges,valleys"


def leaning_normals(v):
    """Normals leaning away from a torus' true ones by a smooth field (as
    the Rust tests' leaning sphere), float32 as a file stores them, so that
    they change the curvature and the lines measurably."""
    R = 1.0
    ring = v.copy()
    ring[:, 2] = 0.0
    ring *= (R / np.linalg.norm(ring, axis=1))[:, None]
    true = (v - ring) / np.linalg.norm(v - ring, axis=1)[:, None]
    lean = np.stack([np.sin(3 * v[:, 1]), np.cos(2 * v[:, 2]), np.sin(v[:, 0])], axis=1)
    return (true + 0.15 * lean).astype(np.float32)


def write_obj_normals(path, v, f, n):
    """An OBJ with one ``vn`` line per vertex (in vertex order, as trimesh2
    pairs them), every number written so that it reads back exactly."""
    with open(path, "w") as fh:
        for p in v:
            fh.write("v %r %r %r\n" % tuple(float(c) for c in p))
        for m in n:
            fh.write("vn %r %r %r\n" % tuple(float(c) for c in m))
        for t in f:
            fh.write(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n")


@pytest.fixture
def mesh(tmp_path):
    v, f = torus(60, 30)
    n = leaning_normals(v)
    path = tmp_path / "leaning.obj"
    write_obj_normals(path, v, f, n)
    return path, v, f, n


def assert_same_rows(view, expect, what):
    assert len(view.a) == len(expect["a"]) > 100, (what, len(view.a), len(expect["a"]))
    for name, e in expect.items():
        got = getattr(view, name)
        assert got.dtype == e.dtype and got.shape == e.shape, (what, name)
        if name == "family":
            assert got.tolist() == e.tolist(), (what, name)
        else:
            assert got.tobytes() == e.tobytes(), (what, name)


def same_view(x, y):
    return all(
        getattr(x, k).tobytes() == getattr(y, k).tobytes()
        for k in ("a", "b", "family_code", "strength", "visible", "chain", "face", "bary")
    )


def test_load_mesh_keeps_the_files_normals_on_request(mesh, tmp_path):
    path, v, f, n = mesh
    # Backward compatible: two arrays by default.
    lv, lf = shapecue.load_mesh(path)
    np.testing.assert_array_equal(lv, v)
    np.testing.assert_array_equal(lf, f)
    lv, lf, ln = shapecue.load_mesh(path, return_normals=True)
    assert ln.dtype == np.float32 and ln.shape == (len(v), 3)
    # As stored: the vn lines in order, not normalized.
    np.testing.assert_array_equal(ln, n)
    assert shapecue.load_mesh(path, normals="computed", return_normals=True)[2] is None
    plain = tmp_path / "plain.obj"
    with open(plain, "w") as fh:
        fh.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert shapecue.load_mesh(plain, return_normals=True)[2] is None
    with pytest.raises(ValueError, match="normals source"):
        shapecue.load_mesh(path, normals="stored")


def test_lines_from_a_file_are_the_command_lines_with_either_normals(device, cli, mesh, tmp_path):
    """lines(path) gives the rows of `shapecue lines PATH --segments S.json`
    bit for bit: with the file's normals by default, with the faces' under
    normals="computed" (--normals computed), and the two differ."""
    path = mesh[0]
    views = {}
    for normals in ("file", "computed"):
        seg = tmp_path / f"{normals}.json"
        cmd = [cli, "lines", str(path), "-o", str(tmp_path / f"{normals}.svg"),
               "--segments", str(seg), "--lines", FAMILIES, "--normals", normals]
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr
        said = "normals from the file" if normals == "file" else "normals from the faces"
        assert said in run.stdout, run.stdout
        kw = {} if normals == "file" else {"normals": "computed"}
        view = shapecue.lines(path, lines=FAMILIES, **kw)
        doc = json.loads(seg.read_text())
        assert_same_rows(view, segments_json_rows(doc), normals)
        assert view.feature_size == doc["feature_size"]
        views[normals] = view
    # The stored normals matter: they change the drawing.
    assert not same_view(views["file"], views["computed"])


def test_arrays_with_normals_are_the_files_route(device, mesh):
    path, v, f, n = mesh
    lv, lf, ln = shapecue.load_mesh(path, return_normals=True)
    from_file = shapecue.lines(path, lines=FAMILIES)
    assert same_view(shapecue.lines(lv, lf, lines=FAMILIES, normals=ln), from_file)
    # The normals as the caller made them (float32 or float64, any layout).
    assert same_view(shapecue.lines(v, f, lines=FAMILIES, normals=n), from_file)
    assert same_view(
        shapecue.lines(v, f, lines=FAMILIES, normals=np.asfortranarray(n.astype(np.float64))),
        from_file,
    )
    # Arrays without normals: the faces' normals, as normals="computed".
    computed = shapecue.lines(path, lines=FAMILIES, normals="computed")
    for kw in ({}, {"normals": "computed"}, {"normals": None}):
        assert same_view(shapecue.lines(v, f, lines=FAMILIES, **kw), computed), kw
    # Many views take them too.
    many = shapecue.lines(path, lines=FAMILIES, cameras=3)
    again = shapecue.lines(v, f, lines=FAMILIES, cameras=3, normals=n)
    assert all(same_view(x, y) for x, y in zip(many, again))
    # The curvature alike.
    c = shapecue.curvature(path, accumulate="gather")
    ca = shapecue.curvature(v, f, normals=n, accumulate="gather")
    for k in ("normals", "k1", "k2", "d1", "d2", "dk"):
        np.testing.assert_array_equal(getattr(c, k), getattr(ca, k), err_msg=k)
    unit = n / np.linalg.norm(n.astype(np.float64), axis=1)[:, None]
    np.testing.assert_allclose(c.normals, unit, atol=1e-6)
    cc = shapecue.curvature(path, normals="computed", accumulate="gather")
    assert np.abs(c.k1 - cc.k1).max() > 0.05
    plain = shapecue.curvature(v, f, accumulate="gather")
    np.testing.assert_array_equal(plain.k1, cc.k1)
    # The reference starts from them as the device does.
    ref = shapecue.curvature(v, f, normals=n, reference=True)
    np.testing.assert_allclose(ref.k1, c.k1, atol=1e-3 * np.abs(ref.k1).max())


def test_curvature_from_a_file_is_the_command_lines(device, cli, mesh, tmp_path):
    path = mesh[0]
    for normals in ("file", "computed"):
        ply = tmp_path / f"{normals}.ply"
        r = subprocess.run([cli, "curvature", str(path), "-o", str(ply), "--accumulate", "gather",
                            "--normals", normals], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        props, _ = read_ply(ply)
        c = shapecue.curvature(path, normals=normals, accumulate="gather")
        cols = {"nx": c.normals[:, 0], "ny": c.normals[:, 1], "nz": c.normals[:, 2],
                "k1": c.k1, "k2": c.k2}
        for k, col in cols.items():
            np.testing.assert_array_equal(props[k], col.astype(props[k].dtype), err_msg=(normals, k))


def test_a_normal_without_direction_is_refused_naming_its_vertex(device, mesh, tmp_path):
    path, v, f, n = mesh
    bad = n.copy()
    bad[7] = 0.0
    with pytest.raises(ValueError, match=r"normals: vertex 7: .*no direction"):
        shapecue.lines(v, f, normals=bad)
    with pytest.raises(ValueError, match=r"vertex 7"):
        shapecue.curvature(v, f, normals=bad)
    nan = n.astype(np.float64)
    nan[11, 1] = np.nan
    with pytest.raises(ValueError, match=r"vertex 11"):
        shapecue.curvature(v, f, normals=nan)
    # A file's: named too; "computed" does not read them.
    broken = tmp_path / "broken.obj"
    write_obj_normals(broken, v, f, bad)
    with pytest.raises(ValueError, match=r"vertex 7"):
        shapecue.lines(broken)
    with pytest.raises(ValueError, match=r"vertex 7"):
        shapecue.load_mesh(broken, return_normals=True)
    shapecue.curvature(broken, normals="computed")
    # A vertex no face uses may have any normal.
    v2 = np.vstack([v, [[5.0, 5.0, 5.0]]])
    n2 = np.vstack([n, [[0.0, 0.0, 0.0]]])
    shapecue.curvature(v2, f, normals=n2)
    # Shape and kind.
    with pytest.raises(ValueError, match=r"normals: .*one normal per vertex"):
        shapecue.curvature(v, f, normals=n[:-1])
    with pytest.raises(ValueError, match=r"normals: expected shape \(N, 3\)"):
        shapecue.curvature(v, f, normals=n[:, :2])
    with pytest.raises(ValueError, match="normals source"):
        shapecue.curvature(v, f, normals="stored")
    with pytest.raises(ValueError, match="with a mesh file give 'file'"):
        shapecue.lines(path, normals=n)


def test_batch_tasks_keep_the_files_normals(device, mesh, tmp_path):
    from shapecue import batch

    path = str(mesh[0])
    for normals in ("file", "computed"):
        out = tmp_path / normals
        out.mkdir()
        rec = batch.process_one(path, "curvature", str(out),
                                {"normals": normals, "accumulate": "gather"})
        assert rec["status"] == "ok", rec
        got = np.load(rec["output"])
        c = shapecue.curvature(path, normals=normals, accumulate="gather")
        np.testing.assert_array_equal(got["k1"], c.k1)
        rec = batch.process_one(path, "lines", str(out),
                                {"views": 2, "lines": FAMILIES, "normals": normals})
        assert rec["status"] == "ok", rec
        assert rec["options"]["normals"] == normals
        views = shapecue.lines(path, lines=FAMILIES, cameras=2, normals=normals, npz=True)
        for i, view in enumerate(views):
            name = f"leaning_f0000_v{i:02d}_segments.npz"
            data = (tmp_path / normals / "leaning" / name).read_bytes()
            assert data == view.npz["segments"], (normals, i)
    with pytest.raises(ValueError, match="normals="):
        batch.run([path], tmp_path / "x", task="lines", options={"normals": "stored"})
