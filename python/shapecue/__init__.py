"""shapecue from Python: curvature, isosurfaces, feature edges and scene
rendering computed by OpenCL kernels, on numpy arrays.

Every call takes ``device=``: an index from :func:`devices` or a
case-insensitive substring of "platform device"; ``None`` uses the
``SHAPECUE_DEVICE`` environment variable, else the first GPU, else the first
CPU device (as the ``shapecue`` command line does). The device work runs with
the GIL released, so Python threads compute in parallel.

Inputs: C-contiguous ``float64``/``float32`` vertices and
``int32``/``int64``/``uint32`` faces are read where they lie; strided arrays
of those dtypes are read element by element; anything else (lists, other
dtypes) is converted with :func:`numpy.asarray` first, which copies. The
library then holds its own double-precision copy of the mesh, so the arrays
may change after the call returns.

Errors: bad input raises :class:`ValueError` with a message naming the
element (``mesh: face 12: vertex index 99 out of range ...``); unreadable
files :class:`OSError`; device problems :class:`DeviceError` and GL problems
:class:`RenderError`, both :class:`RuntimeError` subclasses.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from dataclasses import dataclass
from typing import Any, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _shapecue
from ._shapecue import DeviceError, RenderError
from .cameras import blender_camera, camera_from_matrix, from_blender

__all__ = [
    "Chains",
    "Curvature",
    "CurvatureEstimator",
    "DeviceError",
    "FAMILY_CODES",
    "FeatureEdges",
    "Isosurface",
    "LINE_FAMILIES",
    "LineView",
    "Lines",
    "RenderError",
    "Volume",
    "blender_camera",
    "build_kernels",
    "camera_from_matrix",
    "curvature",
    "devices",
    "feature_edges",
    "from_blender",
    "isosurface",
    "lines",
    "load_mesh",
    "load_volume",
    "render",
    "scene_lines",
]

#: The code of each line family or layer in the ``family`` arrays of the
#: NPZ files (those of ``shapecue lines --npz`` and of the batch's ``lines``
#: task) and in :attr:`LineView.family_code`, with its name: the line
#: families 0 to 11, the layers of feature edges, intersection lines and
#: curvature strokes above 65535. The same table as the ``family_codes`` of
#: the command line's manifest.
FAMILY_CODES: dict = dict(_shapecue.family_codes())

#: The line families by code (0 to 11): the names ``lines=`` takes and
#: :meth:`LineView.of` selects.
LINE_FAMILIES: tuple = tuple(n for c, n in sorted(FAMILY_CODES.items()) if c < 1 << 16)

_VERTEX_DTYPES = (np.float64, np.float32)
_FACE_DTYPES = (np.int32, np.int64, np.uint32)


def _device(device: Union[int, str, None]) -> Optional[str]:
    if device is None:
        return None
    if isinstance(device, bool) or not isinstance(device, (int, str)):
        raise TypeError("device: expected an index (int), a name substring (str) or None")
    return str(device)


def _as_array(a: Any, dtypes: tuple, default: type, ndim: int, what: str) -> np.ndarray:
    """``a`` unchanged when it is an ndarray of an accepted dtype (the
    extension reads it in place, strided or not); else a converted copy."""
    if isinstance(a, np.ndarray) and a.dtype.type in dtypes:
        arr = a
    else:
        try:
            arr = np.asarray(a)
        except Exception as e:  # ragged lists and the like
            raise ValueError(f"{what}: cannot be read as an array: {e}") from None
        if arr.dtype.type not in dtypes:
            if default in _FACE_DTYPES and arr.size and arr.dtype.kind == "f":
                if not np.all(np.isfinite(arr)) or not np.all(arr == np.round(arr)):
                    raise ValueError(f"{what}: indices must be whole numbers")
            if arr.dtype.kind not in "biuf":
                raise ValueError(f"{what}: expected numbers, got dtype {arr.dtype}")
            arr = arr.astype(default)
    if arr.ndim != ndim:
        raise ValueError(f"{what}: expected a {ndim}-D array, got shape {arr.shape}")
    return arr


def _mesh_arrays(vertices: Any, faces: Any) -> Tuple[np.ndarray, np.ndarray]:
    if faces is None:
        if hasattr(vertices, "vertices") and hasattr(vertices, "faces"):
            vertices, faces = vertices.vertices, vertices.faces
        else:
            raise TypeError(
                "give vertices and faces, or one object with .vertices and .faces "
                "(such as a trimesh.Trimesh)"
            )
    v = _as_array(vertices, _VERTEX_DTYPES, np.float64, 2, "vertices")
    f = _as_array(faces, _FACE_DTYPES, np.int64, 2, "faces")
    return v, f


def _is_several(vertices: Any, faces: Any) -> bool:
    """Whether ``vertices`` is a list of meshes (each a mesh file, a
    ``(vertices, faces)`` pair or an object with ``.vertices`` and
    ``.faces``), not the vertices of one."""
    if faces is not None or not isinstance(vertices, list) or not vertices:
        return False

    def one(m: Any) -> bool:
        if isinstance(m, (str, os.PathLike)) or hasattr(m, "faces"):
            return True
        return isinstance(m, tuple) and len(m) == 2
    return all(one(m) for m in vertices)


def _several(meshes: list, normals: Any) -> Tuple["_shapecue._Mesh", np.ndarray]:
    """The meshes of a list joined into one (their faces' vertex indices
    shifted past the meshes before), so that each hides the others, and
    each mesh's first face in the joined faces (one more entry: the total).
    A file keeps the normals it stores (``normals="file"``) where every
    mesh of the list stores some; else the normals come from the faces."""
    if not isinstance(normals, str):
        raise ValueError(
            "normals: with several meshes give 'file' (the normals the files store) or "
            "'computed' (from the faces)"
        )
    vs, fs, ns = [], [], []
    for k, m in enumerate(meshes):
        if isinstance(m, (str, os.PathLike)):
            v, f, n = load_mesh(m, normals=normals, return_normals=True)
        else:
            v, f = _mesh_arrays(*(m if isinstance(m, tuple) else (m, None)))
            n = None
        if len(f) == 0:
            raise ValueError(f"meshes[{k}]: has no faces")
        vs.append(np.asarray(v, dtype=np.float64))
        fs.append(np.asarray(f, dtype=np.int64))
        ns.append(n)
    shift = np.cumsum([0] + [len(v) for v in vs[:-1]])
    faces = np.concatenate([f + d for f, d in zip(fs, shift)])
    first = np.cumsum([0] + [len(f) for f in fs]).astype(np.int64)
    stored = normals == "file" and all(n is not None for n in ns)
    n = np.concatenate(ns).astype(np.float64) if stored else normals
    return _shapecue.mesh_from_arrays(np.concatenate(vs), faces, n), first


def _mesh(vertices: Any, faces: Any, normals: Any) -> "_shapecue._Mesh":
    """The mesh of a call that takes ``normals``, as the library holds it: a
    mesh file (``vertices`` a path, no ``faces``) read by the library's
    loader, keeping its stored normals with ``normals="file"`` and dropping
    them with ``"computed"``, as ``--normals`` on the command line; or
    arrays (or an object with ``.vertices`` and ``.faces``) with, where
    ``normals`` is an array, those vertex normals."""
    if isinstance(vertices, _shapecue._Mesh) and faces is None:
        # Held already (the batch's tasks load the file once).
        return vertices
    if isinstance(vertices, (str, os.PathLike)) and faces is None:
        if not isinstance(normals, str):
            raise ValueError(
                "normals: with a mesh file give 'file' (the normals it stores, if any) or "
                "'computed' (from the faces); an array of normals goes with vertices and faces"
            )
        return _shapecue.load_mesh(os.fspath(vertices), False, normals)
    v, f = _mesh_arrays(vertices, faces)
    # A name is passed on (the library checks it: arrays store no normals,
    # so "file" and "computed" both compute them from the faces).
    n = normals
    if normals is not None and not isinstance(normals, str):
        n = _as_array(normals, _VERTEX_DTYPES, np.float64, 2, "normals")
    return _shapecue.mesh_from_arrays(v, f, n)


def _accumulate(accumulate: str) -> str:
    # "auto": the command line's default, decided for the device by the
    # library: gather (the faster exact scheme on CPU devices and GPUs
    # measured, and bitwise reproducible).
    return accumulate


@dataclass(frozen=True)
class Curvature:
    """Per-vertex curvature of a triangle mesh (Rusinkiewicz 2004, as in
    Griffin et al. 2012), in the mesh's own units.

    ``k1 >= k2`` (signed, positive where convex with outward normals; with
    ``compat="trimesh2"``, ``|k1| >= |k2|``); ``d1``, ``d2`` unit tangent
    principal directions with ``d2 = n x d1``; ``dk`` the curvature
    derivative tensor (C111, C112, C122, C222) in the (d1, d2) frame, zeros
    when ``dcurv=False``.
    """

    normals: np.ndarray  #: (V, 3) float64 unit vertex normals
    area: np.ndarray  #: (V,) float64 Voronoi point areas
    k1: np.ndarray  #: (V,) float64 maximum principal curvature
    k2: np.ndarray  #: (V,) float64 minimum principal curvature
    d1: np.ndarray  #: (V, 3) float64 direction of k1
    d2: np.ndarray  #: (V, 3) float64 direction of k2
    dk: np.ndarray  #: (V, 4) float64 derivative tensor
    degenerate_faces: int  #: faces skipped as degenerate
    vertices_without_curvature: int  #: vertices no usable face touches
    tensor_solves_skipped: int
    dcurv_solves_skipped: int
    kernel_ms: float  #: summed kernel time (0 for the reference)
    wall_ms: float  #: wall time of the computation
    topology_ms: float
    device_bytes: int
    device: str  #: the device that computed it
    #: ms spent in the library call itself (the rest of a call's wall time
    #: is the binding: reading the arrays, making the result)
    library_ms: float = 0.0

    @property
    def mean(self) -> np.ndarray:
        """Mean curvature (k1 + k2) / 2."""
        return 0.5 * (self.k1 + self.k2)

    @property
    def gaussian(self) -> np.ndarray:
        """Gaussian curvature k1 * k2."""
        return self.k1 * self.k2


def devices() -> list:
    """The OpenCL devices of every platform, as dicts with the fields of
    ``shapecue devices --json`` (``index``, ``platform``, ``name``, ``kind``
    ("GPU", "CPU", ...), ``version``, ``compute_units``, ``global_mem``,
    ``max_alloc``, ``fp64``, ``gl_sharing``, ``int64_atomics``, ...) and
    ``default`` (the device used without ``device=``). Raises
    :class:`DeviceError` without any platform."""
    return json.loads(_shapecue.devices())


def build_kernels(
    *,
    accumulate: Sequence[str] = ("auto",),
    precision: Sequence[str] = ("f32",),
    compat: Sequence[str] = ("exact",),
    device: Union[int, str, None] = None,
) -> list:
    """Builds the curvature kernels of every combination of the given
    variants on the device once and keeps them in shapecue's kernel cache
    (``$SHAPECUE_CACHE_DIR``, else ``$XDG_CACHE_HOME/shapecue`` or
    ``~/.cache/shapecue``), as the command line's ``shapecue build-kernels``
    does, so that later processes load them instead of compiling (on PoCL a
    process with nothing built compiles for seconds). Run it once after
    installing or after a driver update. The defaults are :func:`curvature`'s.

    Returns one dict per program: ``variant`` ("gather f32 exact"),
    ``options`` (the build options), ``cache`` ("hit" when it was built
    already, else "miss"), ``saved``, ``build_s`` and ``save_s``. Raises
    :class:`ValueError` for an unknown variant name or when the cache is off
    (``SHAPECUE_NO_CACHE``), :class:`DeviceError` for a variant the device
    cannot run."""
    def names(v: Sequence[str], what: str) -> list:
        if isinstance(v, str):
            v = (v,)
        v = list(v)
        if not v or not all(isinstance(x, str) for x in v):
            raise TypeError(f"{what}: expected a non-empty list of names")
        return v

    return _shapecue.build_kernels(
        [_accumulate(a) for a in names(accumulate, "accumulate")],
        names(precision, "precision"),
        names(compat, "compat"),
        _device(device),
    )


def curvature(
    vertices: Any,
    faces: Any = None,
    *,
    normals: Any = "file",
    accumulate: str = "auto",
    precision: str = "f32",
    compat: Optional[str] = None,
    dcurv: bool = True,
    device: Union[int, str, None] = None,
    reference: bool = False,
) -> Curvature:
    """Principal curvatures, directions, normals, point areas and the
    curvature derivative of a triangle mesh.

    ``vertices`` (V, 3) and ``faces`` (F, 3) arrays, or one object with
    ``.vertices`` and ``.faces`` (a ``trimesh.Trimesh``), or a mesh file
    (.obj/.ply/.off) read by the library's loader as ``shapecue curvature
    FILE`` reads it. Isolated vertices,
    degenerate and duplicate faces, boundaries and non-manifold edges are
    handled (counted in the result); NaN coordinates, out-of-range indices and
    empty meshes raise :class:`ValueError`.

    ``normals``: the vertex normals the curvature starts from, as the
    command line's ``--normals``. For a file, "file" (the default: the
    normals it stores, OBJ ``vn`` lines one per vertex or PLY ``nx ny nz``,
    as trimesh2 and rtsc use them; from the faces where it stores none) or
    "computed" (always from the faces). With arrays, a (V, 3) float array
    of normals to start from (any non-zero length; a zero or non-finite
    normal at a vertex some face uses raises :class:`ValueError` naming the
    vertex), or "file"/"computed"/None: from the faces. The result's
    ``normals`` are then those normals at unit length.

    ``accumulate``: "auto" (gather, the faster exact scheme on CPU devices
    and GPUs measured), "atomic" (Griffin et al.'s float
    atomics) or "gather" (bitwise reproducible). ``precision``: "f32" or "f64" (needs fp64).
    ``compat``: None/"exact" or "trimesh2" (trimesh2 2.16's solve and
    ordering). ``reference=True`` computes with the single-threaded f64 CPU
    reference instead of the device.
    """
    d = _shapecue.curvature(
        _mesh(vertices, faces, normals),
        _accumulate(accumulate),
        precision,
        compat or "exact",
        bool(dcurv),
        _device(device),
        bool(reference),
    )
    return Curvature(**d)


class CurvatureEstimator:
    """Curvature of one mesh topology over many poses (a deforming mesh):
    the topology (one-rings, device buffers, kernels) is built once, each
    :meth:`run` uploads new positions and reruns only the per-pose passes.

    >>> est = CurvatureEstimator(faces, len(vertices))
    >>> for pose in poses:
    ...     k = est.run(pose)

    Calls on one estimator from several threads are serialised; use one
    estimator per thread to compute in parallel.
    """

    def __init__(
        self,
        faces: Any,
        n_vertices: int,
        *,
        accumulate: str = "auto",
        precision: str = "f32",
        compat: Optional[str] = None,
        dcurv: bool = True,
        device: Union[int, str, None] = None,
    ) -> None:
        f = _as_array(faces, _FACE_DTYPES, np.int64, 2, "faces")
        if isinstance(n_vertices, bool) or int(n_vertices) != n_vertices or n_vertices < 0:
            raise ValueError(f"n_vertices: {n_vertices!r} is not a vertex count")
        self._inner = _shapecue._CurvatureEstimator(
            f,
            int(n_vertices),
            _accumulate(accumulate),
            precision,
            compat or "exact",
            bool(dcurv),
            _device(device),
        )

    def run(self, positions: Any) -> Curvature:
        """The curvature of the mesh at ``positions`` (V, 3)."""
        p = _as_array(positions, _VERTEX_DTYPES, np.float64, 2, "positions")
        return Curvature(**self._inner.run(p))

    @property
    def n_vertices(self) -> int:
        return self._inner.n_vertices

    @property
    def n_faces(self) -> int:
        return self._inner.n_faces

    @property
    def device(self) -> str:
        """The device's name."""
        return self._inner.device

    @property
    def topology_ms(self) -> float:
        """Time spent building the topology, ms."""
        return self._inner.topology_ms

    @property
    def device_bytes(self) -> int:
        return self._inner.device_bytes


@dataclass(frozen=True)
class Volume:
    """A scalar volume: ``values`` (nz, ny, nx) float32, sample
    ``values[z, y, x]`` at world ``origin + spacing * (x, y, z)``;
    ``spacing`` and ``origin`` are in (x, y, z) order."""

    values: np.ndarray
    spacing: Tuple[float, float, float] = (1.0, 1.0, 1.0)
    origin: Tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Isosurface:
    """An extracted isosurface. Unpacks as ``vertices, faces = ...``."""

    vertices: np.ndarray  #: (V, 3) float64 world (x, y, z)
    faces: np.ndarray  #: (F, 3) uint32, counter-clockwise seen from outside
    normals: Optional[np.ndarray]  #: (V, 3) gradient normals, when asked for
    curvature: Optional[Curvature]  #: when asked for
    soup_triangles: int  #: triangles before vertex fusion
    degenerate_dropped: int  #: triangles dropped because fused corners coincide
    kernel_ms: float
    wall_ms: float
    upload_ms: float
    device: str

    def __iter__(self) -> Iterator[np.ndarray]:
        return iter((self.vertices, self.faces))


def isosurface(
    volume: Any,
    iso: float,
    *,
    spacing: Optional[Sequence[float]] = None,
    origin: Optional[Sequence[float]] = None,
    fusion: str = "direct",
    inside: str = "below",
    curvature: bool = False,
    normals: bool = False,
    device: Union[int, str, None] = None,
) -> Isosurface:
    """Marching cubes with vertex fusion on the device (Griffin et al. 2012).

    ``volume``: a 3-D array indexed ``volume[z, y, x]`` (the axis order of
    scikit-image and of C-ordered medical volumes: x varies fastest), or a
    :class:`Volume` from :func:`load_volume`. ``spacing`` and ``origin`` are
    given in (x, y, z) order, the order of the returned vertices, which are
    world (x, y, z) positions. So for the same array,
    ``skimage.measure.marching_cubes(vol, iso)[0][:, ::-1]`` lists the same
    points as these vertices, and the two surfaces have the same area and
    volume; a cell's polygon may be split into triangles along the other
    diagonal (scikit-image uses Lewiner et al.'s tables), and scikit-image's
    faces, seen in (x, y, z), point the other way. Triangles whose fused
    corners coincide (an iso value equal to sample values) are dropped and
    counted in ``degenerate_dropped``.

    ``inside``: "below" (signed distance fields, the default) or "above"
    (densities): faces and normals point away from that side.
    ``fusion``: "direct" (each vertex made once by its voxel edge, as Flying
    Edges does: exact and the fastest), "edge" (the soup fused by exact
    keys), "hash" (Griffin et al.'s position hash) or "none" (the triangle
    soup). ``curvature=True`` also computes the curvature of the
    result on the device; ``normals=True`` adds gradient normals.

    Returns an :class:`Isosurface`, which unpacks as ``vertices, faces``.
    """
    if isinstance(volume, Volume):
        spacing = volume.spacing if spacing is None else spacing
        origin = volume.origin if origin is None else origin
        volume = volume.values
    vol = _as_array(volume, (np.float32, np.float64), np.float32, 3, "volume")
    sp = tuple(float(x) for x in (spacing if spacing is not None else (1.0, 1.0, 1.0)))
    org = tuple(float(x) for x in (origin if origin is not None else (0.0, 0.0, 0.0)))
    if len(sp) != 3 or len(org) != 3:
        raise ValueError("spacing and origin: expected three numbers each, in (x, y, z) order")
    d = _shapecue.isosurface(
        vol, float(iso), sp, org, fusion, inside, bool(curvature), bool(normals), _device(device)
    )
    if d["curvature"] is not None:
        d["curvature"] = Curvature(**d["curvature"])
    return Isosurface(**d)


@dataclass(frozen=True)
class FeatureEdges:
    """Object-space feature edges as clip-space quads (House & Li, after
    McGuire & Hughes 2004), ready to draw; one entry per edge of the mesh."""

    kind: np.ndarray  #: (E,) uint32 bits: 1 contour, 2 crease, 4 boundary, 8 drawn
    quads: np.ndarray  #: (E, 4, 4) float32 clip-space quad corners per edge
    cap_adj: np.ndarray  #: (C, 4, 4) adjacency caps (caps="adjacency")
    cap_mh0: np.ndarray  #: (E, 3, 4) McGuire-Hughes half-caps at one end (caps="mh")
    cap_mh1: np.ndarray  #: (E, 3, 4) ... and at the other end
    contour: int  #: edges marked contour
    crease: int
    boundary: int
    drawn: int
    view_proj: np.ndarray  #: (4, 4) world-to-clip matrix used (column-major)
    device: str


def feature_edges(
    vertices: Any,
    faces: Any = None,
    *,
    eye: Optional[Sequence[float]] = None,
    direction: Sequence[float] = (1.0, 1.0, 1.0),
    target: Optional[Sequence[float]] = None,
    up: Optional[Sequence[float]] = None,
    fov: float = 40.0,
    ortho: bool = False,
    size: Tuple[int, int] = (640, 480),
    line_width: float = 4.0,
    crease: float = 30.0,
    contours: bool = True,
    boundaries: bool = True,
    depth_scale: Optional[float] = None,
    half_contours: bool = False,
    caps: str = "adjacency",
    marked: Any = None,
    device: Union[int, str, None] = None,
) -> FeatureEdges:
    """Contour, crease, boundary and marked edges of a mesh seen from a
    camera, with their screen-space quads and caps (nothing is drawn).

    The camera: ``eye`` (looking at ``target``, default the centre of the
    bounds), or, without ``eye``, fitted to the bounds from ``direction``.
    ``size`` is the image (width, height) in pixels, ``line_width`` in pixels,
    ``crease`` the crease angle in degrees, ``caps`` "none", "mh" or
    "adjacency". ``marked``: (M, 2) vertex pairs drawn like boundaries.
    """
    v, f = _mesh_arrays(vertices, faces)

    def vec(x, what):
        if x is None:
            return None
        t = tuple(float(c) for c in x)
        if len(t) != 3:
            raise ValueError(f"{what}: expected three numbers")
        return t

    d = _shapecue.feature_edges(
        v,
        f,
        vec(eye, "eye"),
        vec(direction, "direction"),
        vec(target, "target"),
        vec(up, "up"),
        float(fov),
        bool(ortho),
        (int(size[0]), int(size[1])),
        float(line_width),
        float(crease),
        bool(contours),
        bool(boundaries),
        None if depth_scale is None else float(depth_scale),
        bool(half_contours),
        caps,
        None if marked is None else np.asarray(marked, dtype=np.int64).tolist(),
        _device(device),
    )
    return FeatureEdges(**d)


def render(
    scene: Union[str, os.PathLike, dict],
    out_dir: Union[str, os.PathLike, None] = None,
    *,
    force: bool = False,
    device: Union[int, str, None] = None,
    base_dir: Union[str, os.PathLike, None] = None,
) -> dict:
    """Renders a scene (a TOML scene file, or a dict with the same tables:
    ``{"input": {"generate": "torus"}, "effects": {"shading": {}}, ...}``):
    runs only the passes its cues need, writes the images and a report into
    ``out_dir`` (default: the scene's ``[output] dir``) and returns the
    report as a dict. Existing outputs raise :class:`ValueError` unless
    ``force``. Relative paths in a dict are relative to ``base_dir``
    (default: the working directory). A mesh file's stored normals are
    used as on the command line: ``{"input": {"mesh": "m.obj", "normals":
    "computed"}}`` (``normals = "computed"`` in the TOML) drops them; the
    default is "file"."""
    out = None if out_dir is None else os.fspath(out_dir)
    if isinstance(scene, dict):
        anchor = os.path.join(os.fspath(base_dir or os.getcwd()), "scene.toml")
        text = _shapecue.render_text(json.dumps(scene), anchor, out, bool(force), _device(device))
    else:
        text = _shapecue.render_file(os.fspath(scene), out, bool(force), _device(device))
    return json.loads(text)


def _family_names(codes: np.ndarray) -> np.ndarray:
    """The family name (str) of each code of a ``family`` array."""
    codes = np.asarray(codes)
    if not len(codes):
        return np.asarray([], dtype=str)
    uniq, inverse = np.unique(codes, return_inverse=True)
    names = np.asarray([FAMILY_CODES.get(int(c), f"unknown code {int(c)}") for c in uniq])
    return names[inverse.reshape(-1)]


def _known_family(family: Any) -> str:
    """``family`` when it names a line family, else a ValueError listing them."""
    if not isinstance(family, str) or family not in LINE_FAMILIES:
        raise ValueError(
            f"unknown line family {family!r}: the families are {', '.join(LINE_FAMILIES)}"
        )
    return family


def _deprecated_kind(owner: str) -> None:
    warnings.warn(
        f"{owner}.kind is deprecated: it is family_code (the number files hold under "
        f"'family'); family gives the names",
        DeprecationWarning,
        stacklevel=3,
    )


@dataclass
class LineView:
    """One view of :func:`lines`: its lines split where their visibility
    changes (exact, in object space) and chained, one row per piece, in the
    library's canonical order. One eye gives the rows of ``shapecue lines
    MESH -o FILE.svg --segments FILE.json`` (its ``segments`` list), a view
    of ``cameras`` those of the NPZ of ``shapecue lines --views N --npz``:
    the same rows, in the same order, bit for bit.

    ``a``, ``b`` (P, 3) float32 piece ends (world coordinates), also as
    ``segments`` (P, 2, 3); ``family`` (P,) each piece's family name (str)
    and ``family_code`` (P,) uint32 its code, the number NPZ files hold in
    their ``family`` array (:data:`FAMILY_CODES` maps codes to names);
    ``strength`` (P,) float32 in (0, 1]; ``visible`` (P,) bool; ``chain``
    (P,) uint32 the chain (polyline) of each piece; provenance: ``faces``
    (P, 4) int64 the faces its segment lies on (-1 past the last), ``face``
    (P,) int64 the face it lies in and ``bary`` (P, 2, 3) float32 each
    end's barycentric coordinates in that face, so that ``a ==
    (bary[:, 0, :, None] * vertices[faces_of_mesh[face]]).sum(1)``.
    ``fields`` (with ``fields=True``): per vertex ``ndotv``, ``kr`` (κr
    sin²θ), ``dwkr`` (D_w κr) and ``q1`` (apparent ridges' view-dependent
    curvature, as rtsc keeps it), world units. ``npz`` (with ``npz=True``):
    ``{"segments": bytes, "fields": bytes}``, the bytes of the view's
    ``_segments.npz`` and (with ``fields=True``) ``_fields.npz`` files as
    ``shapecue lines --views N --out DIR --npz --fields`` writes them.
    ``camera``: eye, target, up, fov (degrees) or ortho (height), near and
    far, as the command line's manifest lists them. ``passes``: the passes
    that ran for this view (the first view also runs the pose's:
    curvature, the feature size, the BVH), ``passes_ms`` their own clocks
    summed and ``kernel_ms`` the part the device clocked (kernels);
    ``wall_ms`` the wall-clock ms from the end of the view before (for the
    first, from the start of the call: opening the device and the pose
    passes included) to the end of this one. ``feature_size``: the length
    the dimensionless thresholds were scaled by: with ``feature_size="rtsc"``
    (the default) rtsc's, 0.01 over the 10th percentile of |k1| and |k2| at
    500 sampled vertices and at most 5 % of the bounding sphere's radius,
    with ``"edge"`` the median edge length, or the length given.
    ``device``: the device's name.

    From a list of meshes (``lines([mesh_a, mesh_b, ...])``): ``mesh`` (P,)
    int32 the mesh of the list each piece lies on and ``mesh_face`` (P,)
    int64 its face in that mesh (``face`` and ``faces`` number the faces of
    the meshes one after another); None otherwise.

    The chains in walking order: ``chain_order`` (P,) uint32 the rows,
    chain after chain, each chain's as it is walked (the ``chains`` of the
    segments document, concatenated); ``chain_reversed`` (P,) bool whether
    that row is walked from ``b`` to ``a``; ``chain_start`` (C + 1,) uint32
    each chain's first index into ``chain_order``; ``chain_family_code``
    (C,) uint32 and ``chain_visible`` (C,) bool. :meth:`chains` turns them
    into polylines.

    ``frame`` and ``view``: the frame of the input (0 for a static mesh)
    and the camera's index; :func:`scene_lines` gives every frame of an
    animation, its ``face`` and ``bary`` naming the same point of the rest
    mesh on every frame. Where the scene holds its lines over the frames
    (``[lines] coherence``), ``chain_id`` (P,) uint32 is each piece's
    chain's id across frames: a chain takes the id of the previous frame's
    chain that most of its length lies on, so strokes can be animated one
    by one; None otherwise.

    ``kind``: deprecated, the earlier name of ``family_code`` (reading it
    warns).
    """

    a: np.ndarray
    b: np.ndarray
    family_code: np.ndarray
    family: np.ndarray
    strength: np.ndarray
    visible: np.ndarray
    chain: np.ndarray
    faces: np.ndarray
    face: np.ndarray
    bary: np.ndarray
    fields: Optional[dict]
    camera: dict
    passes: list
    passes_ms: float
    kernel_ms: float
    wall_ms: float
    feature_size: float
    device: str
    chain_order: np.ndarray
    chain_reversed: np.ndarray
    chain_start: np.ndarray
    chain_family_code: np.ndarray
    chain_visible: np.ndarray
    npz: Optional[dict] = None
    mesh: Optional[np.ndarray] = None
    mesh_face: Optional[np.ndarray] = None
    frame: int = 0
    view: int = 0
    chain_id: Optional[np.ndarray] = None

    def chains(self, family: Optional[str] = None, visible_only: bool = True) -> "Chains":
        """The chains as polylines, each an ordered array of points (one
        more than its pieces: where two pieces meet, the point that ends the
        first), with each point's face and barycentric coordinates (where
        the point begins a piece, that piece's; the last point, the last
        piece's end), so a stroke can follow the surface in any pose. Only
        ``family`` (a name of :data:`LINE_FAMILIES`) where given; only the
        visible chains by default."""
        keep = np.ones(len(self.chain_visible), dtype=bool)
        if family is not None:
            keep &= _family_names(self.chain_family_code) == _known_family(family)
        if visible_only:
            keep &= self.chain_visible
        ids = np.flatnonzero(keep).astype(np.uint32)
        start, stop = self.chain_start[:-1][ids], self.chain_start[1:][ids]
        counts = (stop - start).astype(np.int64)
        # The rows of the kept chains, in walking order.
        at = np.repeat(start.astype(np.int64) - np.cumsum(counts) + counts, counts)
        at += np.arange(int(counts.sum()), dtype=np.int64)
        rows = self.chain_order[at].astype(np.int64)
        rev = self.chain_reversed[at]
        first = np.where(rev, 1, 0)
        ends = np.stack([self.a[rows], self.b[rows]], axis=1)
        p0 = ends[np.arange(len(rows)), first]
        p1 = ends[np.arange(len(rows)), 1 - first]
        bary0 = self.bary[rows, first]
        bary1 = self.bary[rows, 1 - first]
        face = self.face[rows]
        # Each chain: its first piece's start, then every piece's end.
        heads = np.cumsum(counts) - counts
        points = np.insert(p1, heads, p0[heads], axis=0)
        bary = np.insert(bary1, heads, bary0[heads], axis=0)
        # A point that begins a piece takes that piece's face: the chain's
        # first point its first piece's, the others their next piece's.
        faces = np.insert(face, heads, face[heads])
        nxt = np.arange(len(rows)) + 1
        inner = np.ones(len(rows), dtype=bool)
        inner[np.cumsum(counts)[counts > 0] - 1] = False
        at_points = np.arange(len(rows)) + np.repeat(np.arange(len(ids)), counts) + 1
        faces[at_points[inner]] = face[nxt[inner]]
        bary[at_points[inner]] = bary0[nxt[inner]]
        offsets = np.concatenate([[0], np.cumsum(counts + 1)]).astype(np.int64)
        return Chains(
            points=points.astype(np.float32),
            face=faces.astype(np.int64),
            bary=bary.astype(np.float32),
            start=offsets,
            id=ids,
            family=_family_names(self.chain_family_code[ids]),
            visible=self.chain_visible[ids].astype(bool),
        )

    @property
    def segments(self) -> np.ndarray:
        """The (P, 2, 3) pieces, ``a`` and ``b`` of each row (visible or
        not)."""
        return np.stack([self.a, self.b], axis=1)

    @property
    def kind(self) -> np.ndarray:
        """Deprecated: :attr:`family_code` under its earlier name."""
        _deprecated_kind("LineView")
        return self.family_code

    def of(self, family: str, visible_only: bool = True) -> np.ndarray:
        """The (k, 2, 3) pieces of one family (a name of
        :data:`LINE_FAMILIES`; another name raises :class:`ValueError`),
        the visible ones only by default."""
        keep = self.family == _known_family(family)
        if visible_only:
            keep &= self.visible
        return np.stack([self.a[keep], self.b[keep]], axis=1)


@dataclass
class Chains:
    """Chains of a :class:`LineView` as polylines (:meth:`LineView.chains`):
    ``points`` (N, 3) float32, chain after chain; ``start`` (K + 1,) int64
    each chain's first index into ``points``; ``face`` (N,) int64 and
    ``bary`` (N, 3) float32 each point's face and barycentric coordinates
    in it (-1 and zeros for a line on no face); ``id`` (K,) uint32 each
    chain's number (the ``chain`` of its pieces); ``family`` (K,) str;
    ``visible`` (K,) bool. ``len(chains)`` is K, ``chains[k]`` the points of
    chain k, and iterating gives each chain's points."""

    points: np.ndarray
    face: np.ndarray
    bary: np.ndarray
    start: np.ndarray
    id: np.ndarray
    family: np.ndarray
    visible: np.ndarray

    def __len__(self) -> int:
        return len(self.id)

    def __getitem__(self, k: int) -> np.ndarray:
        return self.points[self.start[k] : self.start[k + 1]]

    def __iter__(self):
        if len(self) == 0:
            return iter([])
        return iter(np.split(self.points, self.start[1:-1]))


#: The earlier name of the result of :func:`lines` from one eye, kept so
#: that code naming it still runs: one eye now gives a :class:`LineView`
#: (pieces with exact visibility, as the command line draws them) instead
#: of whole segments with no visibility. Its ``segments`` are the pieces,
#: and ``of(family)`` gives the visible ones unless ``visible_only=False``.
Lines = LineView


_CAMERA_SET_WORDS = "a number of views from 1 to {}, a list of camera dicts or a camera JSON file"


def _plain(x: Any) -> Any:
    """``x`` with numpy arrays and scalars as lists and Python numbers."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, (list, tuple)):
        return [_plain(y) for y in x]
    return x


def _non_finite(x: Any) -> bool:
    if isinstance(x, float):
        return not math.isfinite(x)
    if isinstance(x, list):
        return any(_non_finite(y) for y in x)
    return False


def _camera_set(cameras: Any) -> Tuple[Optional[str], Optional[str], Optional[int]]:
    """The cameras of :func:`lines`, one of ``(json_text, None, None)``,
    ``(None, file, None)`` or ``(None, None, n)``; the library checks each
    camera, these checks what it cannot word (values JSON has no text for,
    a count below zero)."""
    words = _CAMERA_SET_WORDS.format(_shapecue.MAX_VIEWS)
    if isinstance(cameras, (bool, np.bool_)):
        raise ValueError(f"cameras={cameras!r}: give {words}")
    if isinstance(cameras, (int, np.integer)):
        n = int(cameras)
        if not 1 <= n <= _shapecue.MAX_VIEWS:
            raise ValueError(f"cameras={n}: give {words}")
        return None, None, n
    if isinstance(cameras, (str, os.PathLike)):
        return None, os.fspath(cameras), None
    if isinstance(cameras, dict):
        if "cameras" not in cameras:
            raise ValueError(
                f"cameras: one dict ({', '.join(map(str, cameras))}); give {words}, or "
                f'{{"cameras": [...]}}'
            )
        cameras = cameras["cameras"]
    if isinstance(cameras, np.ndarray) or not hasattr(cameras, "__iter__"):
        raise ValueError(f"cameras: give {words}, not {type(cameras).__name__}")
    cams = list(cameras)
    if not cams:
        raise ValueError("cameras: the list is empty: give at least one camera")
    out = []
    for i, c in enumerate(cams):
        if not hasattr(c, "items"):
            raise ValueError(
                f"cameras: camera {i}: expected a dict with eye and target, got "
                f"{type(c).__name__} {c!r}"
            )
        d = {str(k): _plain(v) for k, v in c.items()}
        for k, v in d.items():
            if _non_finite(v):
                raise ValueError(
                    f"cameras: camera {i}: {k} has {c[k]!r}, a number that is not finite"
                )
        out.append(d)
    try:
        text = json.dumps({"cameras": out}, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ValueError(f"cameras: a value is not a number or a list of numbers ({e})") from None
    return text, None, None


def _levels(isophotes: Any) -> int:
    """``isophotes`` as a count of levels (0 or more; the library refuses 0
    where isophotes are drawn)."""
    if isinstance(isophotes, (bool, np.bool_)) or not isinstance(isophotes, (int, np.integer)):
        if not (isinstance(isophotes, float) and isophotes.is_integer()):
            raise ValueError(f"isophotes={isophotes!r}: give a whole number of levels, 1 or more")
    n = int(isophotes)
    if not 0 <= n < 1 << 32:
        raise ValueError(f"isophotes={n}: give a whole number of levels, 1 or more")
    return n


def _vec3(x: Any, what: str) -> Optional[Tuple[float, float, float]]:
    """``x`` as three finite floats, or None for None."""
    if x is None:
        return None
    try:
        t = tuple(float(c) for c in x)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected three finite numbers, got {x!r}") from None
    if len(t) != 3 or not all(math.isfinite(c) for c in t):
        raise ValueError(f"{what}: expected three finite numbers, got {x!r}")
    return t


def _one_shot(
    eye: Any, direction: Any, target: Any, up: Any
) -> Tuple[Optional[tuple], tuple, Optional[tuple], Optional[tuple]]:
    """The one camera of :func:`lines` without ``cameras``, as the binding
    takes it: (eye, direction, target, up)."""
    e = _vec3(eye, "eye")
    d = _vec3((1.0, 1.0, 1.0) if direction is None else direction, "direction")
    if not any(d):
        raise ValueError("direction: expected three finite numbers, not all zero")
    if e is None and target is not None:
        raise ValueError("target goes with eye: a camera fitted from direction looks at the centre")
    if e is not None and direction is not None:
        raise ValueError("give eye or direction, not both: direction fits the camera when no eye is given")
    return e, d, _vec3(target, "target"), _vec3(up, "up")


def lines(
    vertices: Any,
    faces: Any = None,
    *,
    lines: Union[str, Sequence[str]] = "contours,suggestive",
    cameras: Any = None,
    fields: bool = False,
    npz: bool = False,
    size: Tuple[int, int] = (800, 600),
    fov: float = 40.0,
    eye: Optional[Sequence[float]] = None,
    direction: Optional[Sequence[float]] = None,
    target: Optional[Sequence[float]] = None,
    up: Optional[Sequence[float]] = None,
    ortho: bool = False,
    sc_threshold: float = 0.01,
    rv_threshold: float = 0.1,
    ar_threshold: float = 0.1,
    ph_threshold: float = 0.04,
    sh_threshold: float = 0.02,
    sc_fade: float = 0.03,
    isophotes: int = 20,
    light: Sequence[float] = (0.0, 0.0, 1.0),
    cull: bool = True,
    test: bool = True,
    fade: bool = True,
    hermite: bool = False,
    hermite_kh: bool = False,
    feature_size: Union[str, float] = "rtsc",
    normals: Any = "file",
    compat: str = "trimesh2",
    accumulate: str = "auto",
    device: Union[int, str, None] = None,
) -> Union[LineView, List[LineView]]:
    """The line families of rtsc (Rusinkiewicz and DeCarlo) on a mesh, from
    one camera (a :class:`LineView`) or many (``cameras``: a list of them),
    by one route: the library's views of one setup (curvature, the feature
    size and the BVH once, the view passes per camera), each view's lines
    split by exact visibility and chained, with their faces and barycentric
    coordinates. No OpenGL is needed.

    **One camera** (no ``cameras``): the camera of ``shapecue lines MESH -o
    FILE.svg``, at ``eye`` (a point, also with ``ortho``, as ``--eye``)
    looking at ``target`` (default: the centre of the bounding box) with
    ``up`` (default +Y, or +Z when looking along Y); without ``eye`` fitted
    from ``direction`` (default (1, 1, 1)), the bounding sphere filling the
    view with a 5 % margin. Returns one :class:`LineView` with the rows of
    ``shapecue lines MESH -o FILE.svg --segments FILE.json`` with the same
    options: the same pieces, in the same order, bit for bit. One eye now
    returns a LineView with exact visibility, as the command line draws it;
    earlier it returned whole segments with no visibility (``Lines``, now a
    name of :class:`LineView`), from an eye three bounding radii out, and
    with ``ortho`` ``eye`` was a direction.

    **Many views** (``cameras``: a number N of views on the Fibonacci
    lattice around the mesh, a list of ``{"eye", "target", "up"?, "fov"? |
    "ortho"?}`` dicts, or a camera JSON file as ``shapecue lines
    --cameras`` reads): returns a list of :class:`LineView`, one per camera.
    The rows are the same, in the same order, as those of ``shapecue lines
    MESH --views N --npz`` (or ``--cameras FILE``) with the same options.
    Ctrl-C (``KeyboardInterrupt``) stops a call of many views within one
    view's time.

    ``size`` (width, height) is the image the fitted views frame and the
    visibility's sample spacing is for; ``fov`` and ``ortho`` are the
    cameras' defaults. ``fields=True`` adds each view's per-vertex fields;
    ``npz=True`` each view's ``npz``, the bytes of the command line's
    ``_segments.npz`` (and with ``fields`` ``_fields.npz``) files. The same
    options give the same bytes every call.

    ``lines``: names among contours, suggestive, ridges, valleys,
    apparent-ridges, suggestive-highlights, principal-highlights, isophotes,
    k-zero, h-zero, dwkr-zero, boundaries. The defaults are rtsc's: its
    thresholds (dimensionless, scaled by the feature size as in ``shapecue
    lines``), its fade ``sc_fade`` of suggestive contours and highlights, its
    tests (``test``), its Hermite placement (``hermite``; ``hermite_kh`` is
    shapecue's for K = 0 and H = 0) and its feature size (``feature_size``:
    "rtsc", rtsc's own, 0.01 over the 10th percentile of |k1| and |k2| at
    500 sampled vertices and at most 5 % of the bounding sphere's radius;
    "edge" for the median edge length; or a length in the mesh's units).
    ``isophotes``: the levels N of isophotes, n·l = j/N for |j| < N (at
    least 1 when isophotes are drawn, as on the command line). ``compat``:
    "trimesh2" (the default, as the command line's) computes the curvature
    as trimesh2 (and so rtsc) does; "exact" is the exact least-squares solve.

    ``vertices`` may also be a mesh file (.obj/.ply/.off), read by the
    library's loader as ``shapecue lines FILE`` reads it, or a list of
    meshes (each a file, a ``(vertices, faces)`` pair or an object with
    ``.vertices`` and ``.faces``), drawn together so that each hides the
    others' lines: each piece names its mesh (``mesh``) and its face there
    (``mesh_face``). ``normals``: the
    vertex normals the curvature, and so every line family, starts from, as
    ``--normals`` on the command line: for a file "file" (the default: those
    it stores, OBJ ``vn`` or PLY ``nx ny nz``, as rtsc uses them; from the
    faces where it stores none) or "computed" (from the faces); with arrays
    a (V, 3) float array of normals (checked: a zero or non-finite normal at
    a vertex some face uses raises :class:`ValueError` naming the vertex),
    or "file"/"computed"/None for the faces' normals. A file with ``vn``
    lines and its arrays with those normals (``load_mesh(path,
    return_normals=True)``) give the same rows.
    """
    first_face = None
    if _is_several(vertices, faces):
        mesh, first_face = _several(vertices, normals)
    else:
        mesh = _mesh(vertices, faces, normals)
    names = lines if isinstance(lines, str) else ",".join(lines)
    thresholds = (
        float(sc_threshold),
        float(rv_threshold),
        float(ar_threshold),
        float(ph_threshold),
        float(sh_threshold),
        float(sc_fade),
    )
    switches = (bool(cull), bool(test), bool(fade), bool(hermite), bool(hermite_kh))
    setup = (str(feature_size), str(compat), str(accumulate))
    l3 = _vec3(light, "light")
    levels = _levels(isophotes)
    text = file = n = shot = None
    if cameras is not None:
        for k, x in (("eye", eye), ("direction", direction), ("target", target), ("up", up)):
            if x is not None:
                raise ValueError(f"{k} sets the one camera; with cameras give each its eye")
        text, file, n = _camera_set(cameras)
    else:
        shot = _one_shot(eye, direction, target, up)
    w, h = (int(x) for x in size)
    views = _shapecue.lines_views(
        mesh, names, text, file, n, shot, (float(fov), bool(ortho), w, h),
        thresholds, levels, l3, switches, setup, bool(fields), bool(npz), _device(device),
    )
    out = [_line_view(d, first_face) for d in views]
    return out if cameras is not None else out[0]


def scene_lines(
    scene: Union[str, os.PathLike],
    *,
    device: Union[int, str, None] = None,
) -> List[LineView]:
    """The lines of every frame and view of a scene file, as its line cues
    and ``[lines]`` settings draw them (for an animation, coherence over the
    frames included: ``[lines] coherence = "auto"`` holds lines from frame
    to frame, ``"off"`` finds each frame's on its own), one
    :class:`LineView` per frame and camera in frame order, with its
    ``frame`` and ``view``. Each piece's ``face`` and ``bary`` name a point
    of the rest mesh, the same on every frame, so lines of different frames
    can be compared where the surface is. Nothing is written."""
    views = _shapecue.scene_lines(os.fspath(scene), _device(device))
    return [_line_view(d) for d in views]


def _line_view(d: dict, first_face: Optional[np.ndarray] = None) -> LineView:
    if first_face is not None:
        # Each piece's mesh of the list, and its face in that mesh.
        on = d["face"] >= 0
        of = np.searchsorted(first_face, np.where(on, d["face"], d["faces"][:, 0]), "right") - 1
        d["mesh"] = of.astype(np.int32)
        d["mesh_face"] = np.where(on, d["face"] - first_face[of], -1)
    fields = None
    if "ndotv" in d:
        fields = {k: d.pop(k) for k in ("ndotv", "kr", "dwkr", "q1")}
    d["visible"] = d["visible"].astype(bool)
    d["chain_reversed"] = d["chain_reversed"].astype(bool)
    d["chain_visible"] = d["chain_visible"].astype(bool)
    return LineView(family=_family_names(d["family_code"]), fields=fields, **d)


def load_mesh(
    path: Union[str, os.PathLike],
    *,
    weld: bool = False,
    normals: str = "file",
    return_normals: bool = False,
) -> Union[Tuple[np.ndarray, np.ndarray], Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]]:
    """Reads an .obj, .ply or .off mesh: ``(vertices float64 (V, 3), faces
    uint32 (F, 3))``, polygons fan-triangulated; ``weld`` merges vertices with
    bit-identical positions. Malformed files raise :class:`ValueError`
    naming the file and the element.

    ``return_normals=True`` returns ``(vertices, faces, normals)``:
    ``normals`` the (V, 3) float32 vertex normals the file stores (OBJ ``vn``
    lines, one per vertex, in order; PLY ``nx ny nz``; as trimesh2 reads
    them, not normalized; summed over merged copies with ``weld``), or None
    where it stores none. ``normals``: "file" (the default) keeps and checks
    them (a zero or non-finite normal at a vertex some face uses raises
    :class:`ValueError` naming the vertex), "computed" drops them (then
    ``normals`` is None), as the command line's ``--normals``. Passing them
    on, ``lines(vertices, faces, normals=normals)`` draws what
    ``lines(path)`` draws."""
    m = _shapecue.load_mesh(os.fspath(path), bool(weld), normals)
    v, f, n = m.arrays()
    return (v, f, n) if return_normals else (v, f)


def load_volume(path: Union[str, os.PathLike]) -> Volume:
    """Reads a volume (.nrrd/.nhdr, .mhd/.mha, .vtk, .vti, .slc, ...) as a
    :class:`Volume` with ``values`` in (z, y, x) order."""
    values, spacing, origin = _shapecue.load_volume(os.fspath(path))
    return Volume(values, tuple(spacing), tuple(origin))
