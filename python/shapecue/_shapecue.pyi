"""Type stubs of the extension module. Call it through the ``shapecue``
package, whose functions check and convert their arguments and wrap the
dicts returned here in result objects."""

from typing import Any, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

class DeviceError(RuntimeError):
    """No OpenCL device, none matching the selection, a device lacking what
    the variant needs, an OpenCL call or kernel build failure."""

class RenderError(RuntimeError):
    """No headless OpenGL, or an OpenGL call failed."""

def devices() -> str: ...
def build_kernels(
    accumulate: list[str], precision: list[str], compat: list[str], device: str | None
) -> list[dict[str, Any]]: ...
def curvature(
    mesh: _Mesh,
    accumulate: str,
    precision: str,
    compat: str,
    dcurv: bool,
    device: Optional[str],
    reference: bool,
) -> dict[str, Any]: ...
def isosurface(
    volume: npt.NDArray[np.floating],
    iso: float,
    spacing: Tuple[float, float, float],
    origin: Tuple[float, float, float],
    fusion: str,
    inside: str,
    curvature: bool,
    normals: bool,
    device: Optional[str],
) -> dict[str, Any]: ...
def feature_edges(
    vertices: npt.NDArray[np.floating],
    faces: npt.NDArray[np.integer],
    eye: Optional[Tuple[float, float, float]],
    direction: Tuple[float, float, float],
    target: Optional[Tuple[float, float, float]],
    up: Optional[Tuple[float, float, float]],
    fov: float,
    ortho: bool,
    size: Tuple[int, int],
    line_width: float,
    crease: float,
    contours: bool,
    boundaries: bool,
    depth_scale: Optional[float],
    half_contours: bool,
    caps: str,
    marked: Optional[list[list[int]]],
    device: Optional[str],
) -> dict[str, Any]: ...
def lines_views(
    mesh: _Mesh,
    families: str,
    cameras: Optional[str],
    camera_file: Optional[str],
    views: Optional[int],
    shot: Optional[
        Tuple[
            Optional[Tuple[float, float, float]],
            Tuple[float, float, float],
            Optional[Tuple[float, float, float]],
            Optional[Tuple[float, float, float]],
        ]
    ],
    camera: Tuple[float, bool, int, int],
    thresholds: Tuple[float, float, float, float, float, float],
    isophotes: int,
    light: Tuple[float, float, float],
    switches: Tuple[bool, bool, bool, bool, bool],
    setup: Tuple[str, str, str],
    fields: bool,
    npz: bool,
    device: Optional[str],
) -> list[dict[str, Any]]: ...
def check_cameras(
    cameras: Optional[str],
    camera_file: Optional[str],
    views: Optional[int],
    fov: float,
    ortho: bool,
) -> int: ...
def line_families(names: str) -> list[str]: ...
def family_codes() -> list[Tuple[int, str]]: ...

MAX_VIEWS: int

def render_file(path: str, out_dir: Optional[str], force: bool, device: Optional[str]) -> str: ...
def scene_lines(path: str, device: Optional[str]) -> list[dict[str, Any]]: ...
def render_text(
    json: str, anchor: str, out_dir: Optional[str], force: bool, device: Optional[str]
) -> str: ...
def load_mesh(path: str, weld: bool, normals: str) -> _Mesh:
    """The file read by the library's loader; ``normals`` "file" keeps the
    normals it stores (checked), "computed" drops them."""
def mesh_from_arrays(
    vertices: npt.NDArray[np.floating],
    faces: npt.NDArray[np.integer],
    normals: Optional[Union[str, npt.NDArray[np.floating]]],
) -> _Mesh:
    """A mesh of arrays, with the (V, 3) normals given (checked) or none
    (None, "file" or "computed")."""
def generated_mesh(name: str, vertices: int) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]:
    """The command line's generated meshes (torus, sphere, ellipsoid, cylinder,
    plane) at about ``vertices`` vertices, for tests that compare with it."""
def load_volume(
    path: str,
) -> Tuple[npt.NDArray[np.float32], Tuple[float, float, float], Tuple[float, float, float]]: ...

class _CurvatureEstimator:
    def __init__(
        self,
        faces: npt.NDArray[np.integer],
        n_vertices: int,
        accumulate: str,
        precision: str,
        compat: str,
        dcurv: bool,
        device: Optional[str],
    ) -> None: ...
    def run(self, positions: npt.NDArray[np.floating]) -> dict[str, Any]: ...
    @property
    def n_vertices(self) -> int: ...
    @property
    def n_faces(self) -> int: ...
    @property
    def device(self) -> str: ...
    @property
    def topology_ms(self) -> float: ...
    @property
    def device_bytes(self) -> int: ...

class _Mesh:
    """A mesh the library holds (positions, faces and stored normals, if
    any), as ``curvature`` and ``lines_views`` take it."""

    @property
    def n_vertices(self) -> int: ...
    @property
    def n_faces(self) -> int: ...
    @property
    def has_normals(self) -> bool: ...
    def arrays(
        self,
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], Optional[npt.NDArray[np.float32]]]: ...
