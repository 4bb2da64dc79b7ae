"""Devices, mesh loading, feature edges and scene rendering through the
binding."""

import json
import os
import shutil
import subprocess

import numpy as np
import pytest

import shapecue
from conftest import REPO, torus, write_obj


def test_devices(device):
    assert device and all(isinstance(d, dict) for d in device)
    for key in ("index", "platform", "name", "kind", "fp64", "gl_sharing", "default"):
        assert key in device[0]
    assert sum(d["default"] for d in device) == 1
    # The same fields as the command line's JSON.
    cli = shutil.which("shapecue") or str(REPO / "target" / "release" / "shapecue")
    if os.path.exists(cli):
        out = subprocess.run([cli, "devices", "--json"], capture_output=True, text=True)
        listed = json.loads(out.stdout)
        assert [sorted(d) for d in listed] == [sorted(k for k in d if k != "default") for d in device]


def test_load_mesh(tmp_path):
    v, f = torus(12, 8)
    p = tmp_path / "t.obj"
    write_obj(p, v, f)
    lv, lf = shapecue.load_mesh(p)
    assert lv.dtype == np.float64 and lf.dtype == np.uint32
    np.testing.assert_array_equal(lv, v)
    np.testing.assert_array_equal(lf, f)
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(ValueError, match=r"broken.obj: face 0"):
        shapecue.load_mesh(broken)
    with pytest.raises(FileNotFoundError, match="absent.obj"):
        shapecue.load_mesh(tmp_path / "absent.obj")
    with pytest.raises(ValueError, match="unsupported format"):
        shapecue.load_mesh(tmp_path / "t.xyz")


def test_feature_edges(device):
    v, f = torus(48, 24)
    e = shapecue.feature_edges(v, f, eye=(0, -4, 2), size=(320, 240), crease=60)
    n = len(e.kind)
    assert n > 0 and e.quads.shape == (n, 4, 4) and e.quads.dtype == np.float32
    assert e.contour > 0 and e.boundary == 0
    assert e.contour == int(np.count_nonzero(e.kind & 1))
    assert e.view_proj.shape == (4, 4)
    fitted = shapecue.feature_edges(v, f, caps="mh")
    assert fitted.cap_mh0.shape[1:] == (3, 4)
    with pytest.raises(ValueError, match="crease"):
        shapecue.feature_edges(v, f, crease=0)
    with pytest.raises(ValueError, match="marked"):
        shapecue.feature_edges(v, f, marked=[[0, 999]])


def _gl_or_skip(fn):
    try:
        return fn()
    except shapecue.RenderError as e:
        if os.environ.get("SHAPECUE_REQUIRE_GL"):
            raise
        pytest.skip(f"no headless OpenGL: {e}")


def test_render_dict_and_file(device, tmp_path):
    scene = {
        "input": {"generate": "torus"},
        "effects": {"shading": {}, "contours": {"width": 2}},
        "output": {"size": [96, 64], "dir": "out"},
    }
    report = _gl_or_skip(lambda: shapecue.render(scene, tmp_path / "a"))
    pngs = list((tmp_path / "a").glob("*.png"))
    assert pngs and report["passes"]
    with pytest.raises(ValueError):
        shapecue.render(scene, tmp_path / "a")  # outputs exist, no force
    shapecue.render(scene, tmp_path / "a", force=True)
    with pytest.raises(ValueError, match="scene.toml"):
        shapecue.render({"input": {"generate": "torus"}, "bogus": 1}, tmp_path / "b")
    report = _gl_or_skip(lambda: shapecue.render(REPO / "scenes" / "torus.toml", tmp_path / "c"))
    assert list((tmp_path / "c").glob("*.png"))


def test_readme_python_example(device, tmp_path, monkeypatch):
    """The Python examples of README.md and docs/python.md, run as written
    (all but the Dask one, which names a cluster's scheduler address)."""
    ran = 0
    for page in ("README.md", "docs/python.md"):
        text = (REPO / page).read_text()
        for block in text.split("```python")[1:]:
            block = block[: block.index("```")]
            if "Client(" in block:
                continue
            monkeypatch.chdir(REPO)
            exec(compile(block, page, "exec"), {})
            ran += 1
    assert ran >= 2


def test_build_kernels_fills_the_kernel_cache(tmp_path, monkeypatch, device):
    cache = tmp_path / "kernels"
    monkeypatch.setenv("SHAPECUE_CACHE_DIR", str(cache))
    monkeypatch.delenv("SHAPECUE_NO_CACHE", raising=False)
    first = shapecue.build_kernels(accumulate=["gather"], precision="f32")
    assert [b["variant"] for b in first] == ["gather f32 exact"]
    # An empty cache folder: built and saved, on PoCL too.
    assert first[0]["cache"] == "miss" and first[0]["saved"] is True, first
    assert first[0]["build_s"] >= 0 and first[0]["save_s"] >= 0
    assert len(list(cache.glob("*.clbin"))) == 1
    again = shapecue.build_kernels(accumulate=["gather"])
    assert again[0]["cache"] == "hit" and again[0]["saved"] is False
    # "auto" builds the default's variant (loaded from the cache now).
    auto = shapecue.build_kernels(accumulate="auto")
    assert [b["variant"] for b in auto] == [b["variant"] for b in shapecue.build_kernels()]
    with pytest.raises(ValueError, match="accumulation"):
        shapecue.build_kernels(accumulate=["sideways"])
    with pytest.raises(TypeError, match="precision"):
        shapecue.build_kernels(precision=[])
    monkeypatch.setenv("SHAPECUE_NO_CACHE", "1")
    with pytest.raises(ValueError, match="kernel cache is off"):
        shapecue.build_kernels()


def test_extension_signatures_match_the_stub():
    # The extension's functions keep the positional signatures of
    # _shapecue.pyi (their options are collected into one struct per entry
    # point inside the Rust functions, not in their Python signatures).
    import ast
    import inspect

    stub = REPO / "python" / "shapecue" / "_shapecue.pyi"
    tree = ast.parse(stub.read_text())
    funcs = {n.name: [a.arg for a in n.args.args] for n in tree.body if isinstance(n, ast.FunctionDef)}
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "_CurvatureEstimator")
    init = next(n for n in cls.body if isinstance(n, ast.FunctionDef) and n.name == "__init__")
    exported = {k for k, v in vars(shapecue._shapecue).items() if callable(v) and not isinstance(v, type)}
    assert exported == set(funcs)
    for name, params in funcs.items():
        sig = inspect.signature(getattr(shapecue._shapecue, name))
        assert list(sig.parameters) == params, name
    try:
        sig = inspect.signature(shapecue._shapecue._CurvatureEstimator)
    except ValueError:  # no class text signature under this build (abi3)
        return
    assert list(sig.parameters) == [a.arg for a in init.args.args][1:]
