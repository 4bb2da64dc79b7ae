"""Isosurfaces through the binding: the same surface as scikit-image's
marching cubes on the same (z, y, x) array, spacing and origin, curvature
on the result, volumes read from files, bad input."""

import numpy as np
import pytest

import shapecue
from conftest import sphere_sdf


def match(ours, theirs, tol):
    """Index of the vertex of ``theirs`` at each of ``ours`` (within
    ``tol``), checking that it is one-to-one."""
    from scipy.spatial import cKDTree

    d, idx = cKDTree(theirs).query(ours)
    assert d.max() < tol, f"a vertex {d.max()} away from the nearest of scikit-image's"
    assert len(np.unique(idx)) == len(ours), "two vertices match one of scikit-image's"
    return idx


def area_volume(v, f):
    """Surface area and signed enclosed volume (positive when the faces
    point outwards)."""
    a, b, c = (v[f[:, i].astype(np.int64)] for i in range(3))
    cr = np.cross(b - a, c - a)
    return 0.5 * np.linalg.norm(cr, axis=1).sum(), np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def euler(v, f):
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]).astype(np.int64), axis=1)
    return len(v) - len(np.unique(e, axis=0)) + len(f)


@pytest.mark.parametrize("iso", [0.0, 0.37])
@pytest.mark.parametrize("fusion", ["direct", "hash", "edge"])
def test_same_surface_as_scikit_image(device, iso, fusion):
    measure = pytest.importorskip("skimage.measure")
    vol = sphere_sdf()  # (z, y, x), deliberately not a cube
    spacing, origin = (0.5, 0.75, 1.25), (3.0, -2.0, 1.0)  # (x, y, z)
    s = shapecue.isosurface(vol, iso, spacing=spacing, origin=origin, fusion=fusion)
    # scikit-image: spacing in array-axis order (z, y, x), vertices likewise.
    sv, sf, _, _ = measure.marching_cubes(vol, iso, spacing=spacing[::-1])
    sv = sv[:, ::-1] + np.array(origin)
    assert s.vertices.shape == sv.shape and s.faces.shape == sf.shape
    assert s.vertices.dtype == np.float64 and s.faces.dtype == np.uint32
    # The same points on the grid edges, each once in both.
    match(s.vertices, sv, 1e-4)
    # The same closed surface: a cell's polygon may be split along the
    # other diagonal (scikit-image uses Lewiner et al.'s tables, shapecue
    # the classic ones), so compare what does not depend on that.
    assert euler(s.vertices, s.faces) == euler(sv, sf) == 2
    a, vol_ours = area_volume(s.vertices, s.faces)
    b, vol_sk = area_volume(sv, sf)
    np.testing.assert_allclose(a, b, rtol=2e-3)
    # shapecue's faces point out of the object (values below iso for
    # inside="below"); scikit-image's, in (x, y, z), point in.
    np.testing.assert_allclose(vol_ours, -vol_sk, rtol=2e-3)
    assert vol_ours > 0
    # inside="above" (a density): the same points, faces turned inwards.
    up = shapecue.isosurface(vol, iso, spacing=spacing, origin=origin, fusion=fusion, inside="above")
    match(up.vertices, sv, 1e-4)
    assert area_volume(up.vertices, up.faces)[1] < 0


def test_unpacks_and_computes_curvature(device):
    vol = sphere_sdf(shape=(40, 40, 40), centre=(19.5, 19.5, 19.5), radius=14.0)
    v, f = shapecue.isosurface(vol, 0.0)
    s = shapecue.isosurface(vol, 0.0, curvature=True, normals=True)
    np.testing.assert_array_equal(np.sort(v, axis=0), np.sort(s.vertices, axis=0))
    assert s.normals.shape == s.vertices.shape
    k = s.curvature
    assert k.k1.shape == (len(s.vertices),)
    np.testing.assert_allclose(np.median(k.mean), 1 / 14.0, rtol=0.05)
    # Gradient normals of a sphere point away from its centre.
    out = s.vertices - 19.5
    assert np.all(np.sum(out * s.normals, axis=1) > 0)


def test_dtypes_and_layouts(device):
    vol = sphere_sdf()
    base = shapecue.isosurface(vol, 0.0, fusion="edge")
    for other in (vol.astype(np.float64), vol.copy(order="F"), np.pad(vol, 1)[1:-1, 1:-1, 1:-1]):
        s = shapecue.isosurface(other, 0.0, fusion="edge")
        np.testing.assert_array_equal(s.vertices, base.vertices)
        np.testing.assert_array_equal(s.faces, base.faces)


def test_bad_input(device):
    vol = sphere_sdf()
    with pytest.raises(ValueError, match="3-D array"):
        shapecue.isosurface(vol[0], 0.0)
    with pytest.raises(ValueError, match="iso: NaN is not a finite"):
        shapecue.isosurface(vol, float("nan"))
    with pytest.raises(ValueError, match="spacing"):
        shapecue.isosurface(vol, 0.0, spacing=(1, 0, 1))
    with pytest.raises(ValueError, match="unknown vertex fusion"):
        shapecue.isosurface(vol, 0.0, fusion="glue")
    with pytest.raises(ValueError):
        shapecue.isosurface(np.zeros((0, 4, 4), np.float32), 0.0)


def write_nrrd(path, vol, spacing):
    nz, ny, nx = vol.shape
    header = (
        "NRRD0004\ntype: float\ndimension: 3\n"
        f"sizes: {nx} {ny} {nz}\nspacings: {spacing[0]} {spacing[1]} {spacing[2]}\n"
        "encoding: raw\nendian: little\n\n"
    )
    with open(path, "wb") as fh:
        fh.write(header.encode())
        fh.write(vol.astype("<f4").tobytes())


def test_load_volume_keeps_z_y_x(device, tmp_path):
    vol = sphere_sdf()
    p = tmp_path / "ball.nrrd"
    write_nrrd(p, vol, (0.5, 0.75, 1.25))
    v = shapecue.load_volume(p)
    assert v.values.shape == vol.shape and v.values.dtype == np.float32
    np.testing.assert_array_equal(v.values, vol)
    assert v.spacing == (0.5, 0.75, 1.25)
    a = shapecue.isosurface(v, 0.0, fusion="edge")
    b = shapecue.isosurface(vol, 0.0, spacing=(0.5, 0.75, 1.25), fusion="edge")
    np.testing.assert_array_equal(a.vertices, b.vertices)
    bad = tmp_path / "short.nrrd"
    bad.write_bytes(p.read_bytes()[:-10])
    with pytest.raises(ValueError, match="short.nrrd"):
        shapecue.load_volume(bad)
    with pytest.raises(FileNotFoundError, match="absent.nrrd"):
        shapecue.load_volume(tmp_path / "absent.nrrd")
