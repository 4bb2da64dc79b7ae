"""Shared fixtures: analytic meshes and volumes made here (no data files
needed), the device check, and where the command line and the shared data
are."""

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import shapecue

REPO = Path(__file__).resolve().parents[2]
# The shared data sets: $SHAPECUE_SHARED_DATA, else ../shared/data beside the
# repository (as the Rust tests look for them); tests that need them skip
# when they are absent, as on a fresh clone.
DATA = Path(os.environ.get("SHAPECUE_SHARED_DATA") or REPO.parent / "shared" / "data")


def torus(nu=48, nv=24, R=1.0, r=0.35):
    """A closed torus around z: (vertices, faces int64), faces outward."""
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    v = np.linspace(0, 2 * np.pi, nv, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    x = (R + r * np.cos(vv)) * np.cos(uu)
    y = (R + r * np.cos(vv)) * np.sin(uu)
    z = r * np.sin(vv)
    verts = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    idx = np.arange(nu * nv).reshape(nu, nv)
    a = idx
    b = np.roll(idx, -1, axis=0)
    c = np.roll(np.roll(idx, -1, axis=0), -1, axis=1)
    d = np.roll(idx, -1, axis=1)
    faces = np.concatenate(
        [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    )
    return verts, faces.astype(np.int64)


def sphere_sdf(shape=(34, 30, 26), centre=(12.3, 14.1, 16.7), radius=9.2):
    """A signed distance field of a sphere sampled on a (z, y, x) grid;
    ``centre`` is in (x, y, z) voxel units."""
    z, y, x = np.meshgrid(*[np.arange(n, dtype=np.float64) for n in shape], indexing="ij")
    cx, cy, cz = centre
    return (np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) - radius).astype(np.float32)


def write_obj(path, v, f):
    with open(path, "w") as fh:
        for p in v:
            fh.write("v %r %r %r\n" % (float(p[0]), float(p[1]), float(p[2])))
        for t in f:
            fh.write(f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n")


def read_ply(path):
    """The vertex properties (name -> array) and faces of a binary
    little-endian PLY as shapecue writes it."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    props, nv, nf = [], 0, 0
    for line in header:
        w = line.split()
        if w[:2] == ["element", "vertex"]:
            nv = int(w[2])
        elif w[:2] == ["element", "face"]:
            nf = int(w[2])
        elif w[0] == "property" and w[1] != "list":
            props.append((w[2], "<f4" if w[1] == "float" else "<f8"))
    vt = np.dtype(props)
    verts = np.frombuffer(data, vt, nv, end)
    ft = np.dtype([("n", "u1"), ("i", "<i4", 3)])
    faces = np.frombuffer(data, ft, nf, end + nv * vt.itemsize)
    return {n: verts[n] for n, _ in props}, faces["i"]


@pytest.fixture(scope="session")
def device():
    """Skips a test when no OpenCL device is found (CI installs PoCL)."""
    try:
        devs = shapecue.devices()
    except shapecue.DeviceError as e:
        pytest.skip(f"no OpenCL device: {e}")
    return devs


def main_checkout():
    """The main checkout when this one is a git worktree (its `.git` is a
    file naming `<main>/.git/worktrees/<name>`), else None."""
    git = REPO / ".git"
    if not git.is_file():
        return None
    line = git.read_text().strip()
    if not line.startswith("gitdir:"):
        return None
    gitdir = (REPO / line[len("gitdir:"):].strip()).resolve()
    if gitdir.parent.name != "worktrees":
        return None
    return gitdir.parent.parent.parent


@pytest.fixture(scope="session")
def cli():
    """The shapecue command line built by `cargo test --release`:
    $SHAPECUE_BIN, else in $CARGO_TARGET_DIR (default target/), else, in a
    git worktree, in the main checkout's target/."""
    target = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target")
    exe = os.environ.get("SHAPECUE_BIN") or str(target / "release" / "shapecue")
    main = main_checkout()
    if not (os.path.exists(exe) or shutil.which(exe)) and main is not None:
        if (main / "target" / "release" / "shapecue").exists():
            exe = str(main / "target" / "release" / "shapecue")
    if not (os.path.exists(exe) or shutil.which(exe)):
        pytest.skip(f"the shapecue command line is not built ({exe}); run cargo build --release")
    return exe


@pytest.fixture(scope="session")
def bunny():
    p = DATA / "meshes" / "bunny.off"
    if not p.exists():
        pytest.skip(f"{p} is absent (the shared data folder is not beside the repository)")
    return p
