"""shapecue.batch on a Dask LocalCluster (two worker processes, no
service): a few small meshes and one broken file; the failure is recorded
and the rest finish; a rerun skips what finished."""

import json

import numpy as np
import pytest

import shapecue
from conftest import sphere_sdf, torus, write_obj

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_curvature_batch_records_failures_and_resumes(device, client, tmp_path):
    from shapecue import batch

    src = tmp_path / "in"
    src.mkdir()
    meshes = {}
    for i in range(3):
        v, f = torus(16 + 4 * i, 8 + 2 * i)
        write_obj(src / f"torus{i}.obj", v, f)
        meshes[f"torus{i}"] = (v, f)
    (src / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 3\n")  # index 3 of 2 vertices
    out = tmp_path / "out"

    recs = batch.run(str(src / "*.obj"), out, client=client, options={"accumulate": "gather"})
    assert len(recs) == 4
    by = {r["input"].rsplit("/", 1)[-1]: r for r in recs}
    assert by["broken.obj"]["status"] == "error"
    assert "broken.obj: face 0" in by["broken.obj"]["error"]
    assert by["broken.obj"]["error"].startswith("ValueError")
    for name, (v, f) in meshes.items():
        r = by[name + ".obj"]
        assert r["status"] == "ok", r
        assert r["worker"] and r["timings"]["total_ms"] >= r["timings"]["compute_ms"] > 0
        data = np.load(r["output"])
        expect = shapecue.curvature(v, f, accumulate="gather")
        np.testing.assert_array_equal(data["k1"], expect.k1)
        np.testing.assert_array_equal(data["faces"], f)

    lines = [json.loads(x) for x in (out / "manifest.jsonl").read_text().splitlines()]
    assert len(lines) == 4 and {x["status"] for x in lines} == {"ok", "error"}
    for x in lines:
        assert set(x) >= {"input", "output", "status", "error", "timings"}

    # A rerun skips the three finished meshes and tries the broken one again.
    again = batch.run(str(src / "*.obj"), out, client=client, options={"accumulate": "gather"})
    assert [r["input"].rsplit("/", 1)[-1] for r in again] == ["broken.obj"]
    assert len(batch.read_manifest(out)) == 5
    # Once it is fixed, it is run, and then nothing is left.
    v, f = torus(12, 8)
    write_obj(src / "broken.obj", v, f)
    fixed = batch.run(str(src / "*.obj"), out, client=client)
    assert [r["status"] for r in fixed] == ["ok"], fixed
    assert batch.run(str(src / "*.obj"), out, client=client) == []


def test_isosurface_batch(device, client, tmp_path):
    from shapecue import batch
    from test_isosurface import write_nrrd

    paths = []
    for i, r in enumerate((6.0, 8.0)):
        p = tmp_path / f"ball{i}.nrrd"
        write_nrrd(p, sphere_sdf(radius=r), (1.0, 1.0, 1.0))
        paths.append(str(p))
    recs = batch.run(paths, tmp_path / "out", task="isosurface", client=client,
                     options={"iso": 0.0, "curvature": True})
    assert [r["status"] for r in recs] == ["ok", "ok"], recs
    for r in recs:
        d = np.load(r["output"])
        assert d["vertices"].shape[1] == 3 and len(d["curvature_k1"]) == len(d["vertices"])
    # Without an iso value the whole call is refused before any task runs.
    with pytest.raises(ValueError, match="iso"):
        batch.run(paths[:1], tmp_path / "out2", task="isosurface", client=client)
    assert not (tmp_path / "out2" / "manifest.jsonl").exists()
    (tmp_path / "other").mkdir()
    twin = tmp_path / "other" / "ball0.nrrd"
    twin.write_bytes(open(paths[0], "rb").read())
    with pytest.raises(ValueError, match="would both write"):
        batch.run([paths[0], str(twin)], tmp_path / "out4", task="isosurface", client=client,
                  options={"iso": 0.0})
    with pytest.raises(ValueError, match="unknown task"):
        batch.run(paths, tmp_path / "out3", task="sculpt", client=client)


def test_resources_no_worker_offers_are_refused_at_once(device, client, tmp_path):
    """Dask holds a task whose resources no worker offers forever: the call
    says so at once instead."""
    import time

    from shapecue import batch

    v, f = torus(12, 8)
    write_obj(tmp_path / "t.obj", v, f)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="no worker of the cluster offers the resources GPU=1"):
        batch.run([str(tmp_path / "t.obj")], tmp_path / "out", client=client, resources={"GPU": 1})
    assert time.perf_counter() - t0 < 30


def test_resources_without_a_client(device, tmp_path):
    """Without a client, the LocalCluster made for the call offers the
    resources asked for, so the documented call runs instead of hanging.
    In a process of its own: this module's client would be found and used."""
    import subprocess
    import sys

    v, f = torus(12, 8)
    write_obj(tmp_path / "t.obj", v, f)
    code = (
        "from shapecue import batch\n"
        f"recs = batch.run([{str(tmp_path / 't.obj')!r}], {str(tmp_path / 'out')!r}, "
        "resources={'GPU': 1})\n"
        "assert [r['status'] for r in recs] == ['ok'], recs\n"
        "print('ran', len(recs))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0 and "ran 1" in out.stdout, out.stderr[-2000:]


def awkward_meshes(src):
    """A generated collection of the meshes real datasets hold, each
    expected to give lines, and of broken files, each expected to fail
    with the element named."""
    v, f = torus(24, 12)
    f = np.asarray(f)
    good = {
        "two_components": (np.concatenate([v, v + [3.0, 0, 0]]), np.concatenate([f, f + len(v)])),
        # Half the torus's faces: an open boundary.
        "open_boundary": (v, f[: len(f) // 2]),
        "isolated_vertices": (np.concatenate([v, [[9.0, 9, 9], [-9.0, 2, 1]]]), f),
        "degenerate_faces": (v, np.concatenate([f, [[0, 0, 1], [2, 2, 2]]])),
        "duplicate_faces": (v, np.concatenate([f, f[:40]])),
        # A fin: one edge of the torus shared by a third face.
        "non_manifold": (
            np.concatenate([v, [[0.0, 0.0, 2.0]]]),
            np.concatenate([f, [[f[0][0], f[0][1], len(v)]]]),
        ),
        "huge": (v * 1e6 + 3e6, f),
        "tiny": (v * 1e-6 - 2e-6, f),
    }
    for name, (vv, ff) in good.items():
        write_obj(src / f"{name}.obj", vv, ff)
    (src / "nan_vertex.obj").write_text("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    (src / "bad_index.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    (src / "empty.obj").write_text("")
    return sorted(good), {"nan_vertex": "vertex 1: non-finite", "bad_index": "7", "empty": "empty.obj"}


def test_lines_batch_over_awkward_and_broken_meshes(device, client, tmp_path):
    from shapecue import batch

    src = tmp_path / "in"
    src.mkdir()
    good, broken = awkward_meshes(src)
    out = tmp_path / "out"
    opts = {"views": 3, "lines": "contours,suggestive,ridges", "size": (320, 240)}
    recs = batch.run(str(src / "*.obj"), out, task="lines", client=client, options=opts)
    by = {r["input"].rsplit("/", 1)[-1][:-4]: r for r in recs}
    assert sorted(by) == sorted(good + list(broken))
    for name in good:
        r = by[name]
        assert r["status"] == "ok", (name, r["error"])
        assert r["views"] == 3
        doc = json.loads((out / name / "views.json").read_text())
        names = [[x["name"] for x in e["files"]] for e in doc["views"]]
        assert names == [[f"{name}_f0000_v{i:02d}_segments.npz", f"{name}_f0000_v{i:02d}_fields.npz"]
                         for i in range(3)]
        assert [e["index"] for e in doc["views"]] == [0, 1, 2]
        z = np.load(out / name / names[1][0])
        for k in ("a", "b", "family", "family_codes", "family_names", "visible", "face", "bary"):
            assert k in z.files, (name, k)
        fz = np.load(out / name / names[1][1])
        assert fz.files == ["ndotv", "kr", "dwkr", "q1"]
        assert np.all(np.isfinite(z["a"])) and np.all(np.isfinite(fz["ndotv"]))
        assert len(fz["ndotv"]) == doc["vertices"] and len(z["a"]) == doc["views"][1]["pieces"]
        assert sorted(p.name for p in (out / name).iterdir()) == sorted(sum(names, ["views.json"]))
    assert sum(len(json.loads((out / n / "views.json").read_text())["views"]) for n in good) == 3 * len(good)
    for name, words in broken.items():
        r = by[name]
        assert r["status"] == "error" and words in r["error"], (name, r["error"])
        assert not (out / name).exists()
    # Nothing half-written is left beside the outputs.
    assert not [p for p in out.iterdir() if ".part" in p.name]
    # A rerun runs only the failures again.
    again = batch.run(str(src / "*.obj"), out, task="lines", client=client, options=opts)
    assert sorted(r["input"].rsplit("/", 1)[-1][:-4] for r in again) == sorted(broken)


def test_lines_options_are_refused_before_any_cluster_starts(tmp_path, monkeypatch):
    """As the isosurface task's iso: a bad option of the lines task is a
    ValueError of run() itself, with no cluster, client or task started."""
    from shapecue import batch

    v, f = torus(12, 8)
    write_obj(tmp_path / "t.obj", v, f)

    def no_cluster(*a, **k):
        raise AssertionError("a cluster or client was started")

    monkeypatch.setattr(distributed, "LocalCluster", no_cluster)
    monkeypatch.setattr(distributed, "Client", no_cluster)
    monkeypatch.setattr(distributed, "get_client", no_cluster)
    cams = [{"eye": [0, 0, 3], "target": [0, 0, 0]}]
    cases = [
        ({"views": 0}, "views=0: give a number of views from 1 to 10000"),
        ({"views": 10001}, "views=10001"),
        ({"views": True}, "views=True"),
        ({"vews": 4}, "unknown option 'vews': the options are "),
        ({"views": 4, "cameras": cams}, "give the option views or cameras, not both"),
        ({"eye": [0, 0, 3]}, "option 'eye' sets the one camera"),
        ({"lines": "contours,creases"}, "creases"),
        ({"lines": "isophotes", "isophotes": 0}, "isophotes=0"),
        ({"cameras": []}, "cameras: the list is empty"),
        ({"cameras": [{"eye": [0, 0, 3]}]}, "cameras: camera 0: "),
        ({"cameras": str(tmp_path / "absent.json")}, "absent.json"),
    ]
    for options, words in cases:
        with pytest.raises((ValueError, OSError)) as e:
            batch.run([str(tmp_path / "t.obj")], tmp_path / "out", task="lines", options=options)
        assert words in str(e.value), (options, str(e.value))
        assert not (tmp_path / "out" / "manifest.jsonl").exists()


def test_lines_batch_records_its_options_and_redoes_what_changed(device, client, tmp_path):
    """A rerun with other options redoes the inputs (it used to keep the
    earlier views and return no record); views_per_second is the views over
    the wall-clock time of computing them."""
    from shapecue import batch

    src = tmp_path / "in"
    src.mkdir()
    for i in range(2):
        v, f = torus(20 + 4 * i, 10)
        write_obj(src / f"t{i}.obj", v, f)
    out = tmp_path / "out"
    first = batch.run(str(src / "*.obj"), out, task="lines", client=client,
                      options={"views": 4, "size": (320, 240)})
    assert [r["status"] for r in first] == ["ok", "ok"], first
    for r in first:
        assert r["options"]["views"] == 4 and r["options"]["size"] == [320, 240]
        assert r["options"]["lines"] == ["contours", "suggestive"]
        # Wall clock: the views over the call that computed them.
        assert r["views_per_second"] == pytest.approx(4 / (r["timings"]["compute_ms"] / 1e3))
        t = r["timings"]
        assert 0 < t["first_view_ms"] + t["later_views_ms"] <= t["compute_ms"] * 1.001 + 1
        doc = json.loads((out / r["output"].rsplit("/", 1)[-1] / "views.json").read_text())
        assert doc["options"] == r["options"] and len(doc["views"]) == 4
    # The same options, written in other words (the defaults given, a list
    # of families): nothing to do.
    same = {"views": 4, "size": [320, 240], "lines": ["suggestive", "contours"], "fields": True}
    assert batch.run(str(src / "*.obj"), out, task="lines", client=client, options=same) == []
    again = batch.run(str(src / "*.obj"), out, task="lines", client=client,
                      options={"views": 8, "size": (320, 240)})
    assert sorted(r["input"].rsplit("/", 1)[-1] for r in again) == ["t0.obj", "t1.obj"]
    for r in again:
        assert r["status"] == "ok" and r["views"] == 8 and r["options"]["views"] == 8
        folder = out / r["output"].rsplit("/", 1)[-1]
        doc = json.loads((folder / "views.json").read_text())
        assert len(doc["views"]) == 8 and doc["options"]["views"] == 8
        assert len(list(folder.glob("*_segments.npz"))) == 8
        assert len(list(folder.glob("*_fields.npz"))) == 8
    assert batch.run(str(src / "*.obj"), out, task="lines", client=client,
                     options={"views": 8, "size": (320, 240)}) == []


def sha256_tree(folder):
    import hashlib

    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != "manifest.jsonl"
    }


def test_batch_outputs_are_the_same_bytes_every_run(device, client, tmp_path):
    """Two runs into two folders write the same bytes in every file but the
    manifest (the run's log, with its timings and workers); the lines NPZ
    holds the command line's arrays, by its names and in its order, with the
    code table."""
    import time

    from shapecue import batch

    src = tmp_path / "in"
    src.mkdir()
    for i in range(2):
        v, f = torus(20 + 4 * i, 10)
        write_obj(src / f"t{i}.obj", v, f)
    opts = {"views": 3, "lines": "contours,suggestive,ridges", "size": (320, 240)}
    outs = []
    for k in range(2):
        if k:
            time.sleep(2.1)  # a zip stamp of the time of writing (to 2 s) would differ
        out = tmp_path / f"out{k}"
        for task, o in (("lines", opts), ("curvature", {"accumulate": "gather"})):
            recs = batch.run(str(src / "*.obj"), out, task=task, client=client, options=o)
            assert [r["status"] for r in recs] == ["ok", "ok"], recs
        outs.append(sha256_tree(out))
    # Per input views.json and 3 views of two files; the curvature NPZ.
    assert len(outs[0]) == 2 * (1 + 3 * 2) + 2, sorted(outs[0])
    assert outs[0] == outs[1]

    z = np.load(tmp_path / "out0" / "t0" / "t0_f0000_v01_segments.npz")
    cli_names = ["a", "b", "family", "strength", "visible", "faces", "chain", "face", "bary",
                 "family_codes", "family_names"]
    assert z.files == cli_names
    dtypes = ["float32", "float32", "uint32", "float32", "uint8", "int64", "uint32", "int64",
              "float32", "uint32", "<U24"]
    assert [str(z[k].dtype) for k in cli_names[:-1]] == dtypes[:-1]
    assert z["family_names"].dtype.str == "<U24"
    table = dict(zip(z["family_codes"].tolist(), z["family_names"].tolist()))
    assert table == shapecue.FAMILY_CODES
    assert set(z["family"].tolist()) <= {0, 1, 2}
    doc = json.loads((tmp_path / "out0" / "t0" / "views.json").read_text())
    assert {int(c): n for c, n in doc["family_codes"].items()} == shapecue.FAMILY_CODES
    assert "timing" not in doc and not any("ms" in k for e in doc["views"] for k in e)
    # Each file's SHA-256 as views.json lists it.
    for e in doc["views"]:
        for x in e["files"]:
            assert outs[0][f"t0/{x['name']}"] == x["sha256"]


def test_lines_task_writes_the_command_lines_files(device, client, cli, tmp_path):
    """The lines task writes each view's `_segments.npz` and `_fields.npz`
    under the names `shapecue lines MESH --views 3 --out DIR --npz --fields`
    gives them and with the same bytes (SHA-256), and views.json lists them
    and the cameras as the command line's manifest does. Before, the task
    wrote one view_NNN.npz of its own per view."""
    import subprocess

    from conftest import REPO
    from shapecue import batch

    mesh = tmp_path / "in" / "spot.obj"
    mesh.parent.mkdir()
    mesh.write_bytes((REPO / "data" / "spot.obj").read_bytes())
    fams = "contours,suggestive,ridges"
    cli_out = tmp_path / "cli"
    run = subprocess.run(
        [cli, "lines", str(mesh), "--views", "3", "--out", str(cli_out), "--npz", "--fields",
         "--lines", fams, "--size", "320x240"],
        capture_output=True, text=True, timeout=600,
    )
    assert run.returncode == 0, run.stderr
    manifest = json.loads((cli_out / "manifest.json").read_text())
    recs = batch.run([str(mesh)], tmp_path / "out", task="lines", client=client,
                     options={"views": 3, "lines": fams, "size": (320, 240)})
    assert [r["status"] for r in recs] == ["ok"], recs
    folder = tmp_path / "out" / "spot"
    doc = json.loads((folder / "views.json").read_text())
    assert len(doc["views"]) == len(manifest["views"]) == 3
    checked = 0
    for ours, theirs in zip(doc["views"], manifest["views"]):
        assert ours["index"] == theirs["index"]
        for k in ("eye", "target", "up", "fov", "ortho", "near", "far"):
            assert ours["camera"][k] == theirs["camera"][k], k
        npz = [x for x in theirs["files"] if x["name"].endswith(("_segments.npz", "_fields.npz"))]
        assert [x["name"] for x in npz] == [x["name"] for x in ours["files"]]
        stem = f"spot_f0000_v{ours['index']:02d}"
        assert [x["name"] for x in npz] == [f"{stem}_segments.npz", f"{stem}_fields.npz"]
        for x, y in zip(npz, ours["files"]):
            assert x == y, (x, y)
            assert sha256_file(folder / y["name"]) == sha256_file(cli_out / x["name"]) == x["sha256"]
            checked += 1
    assert checked == 6
    assert doc["family_codes"] == manifest["family_codes"]


def sha256_file(p):
    import hashlib

    return hashlib.sha256(p.read_bytes()).hexdigest()
