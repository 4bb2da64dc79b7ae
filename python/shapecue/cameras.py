"""Cameras of :func:`shapecue.lines` from the matrices and settings other
tools keep: a 4×4 camera-to-world matrix with a field of view or an
orthographic height (:func:`camera_from_matrix`), and Blender's camera
settings (:func:`blender_camera`, or :func:`from_blender` for a camera
object and its scene). Each returns one camera dict of ``lines(mesh,
cameras=[...])``: ``eye``, ``target`` and ``up``, with ``fov`` (the
vertical field of view, degrees) or ``ortho`` (the height an orthographic
view shows)."""

import math
from typing import Any, Optional, Sequence, Tuple

import numpy as np

__all__ = ["blender_camera", "camera_from_matrix", "from_blender"]


def _unit(x: np.ndarray, what: str) -> np.ndarray:
    n = float(np.linalg.norm(x))
    if not math.isfinite(n) or n == 0.0:
        raise ValueError(f"matrix: its {what} has no direction")
    return x / n


def _size(size: Sequence[int]) -> Tuple[int, int]:
    w, h = (int(x) for x in size)
    if w <= 0 or h <= 0:
        raise ValueError(f"size: give a width and a height above 0, not {w} x {h}")
    return w, h


def camera_from_matrix(
    matrix: Any,
    *,
    fov: Optional[float] = None,
    hfov: Optional[float] = None,
    ortho: Optional[float] = None,
    size: Sequence[int] = (800, 600),
) -> dict:
    """The camera of a 4×4 camera-to-world ``matrix`` (row-major, the
    translation in the last column), looking down the camera's -Z axis with
    its +Y axis up, as OpenGL's and Blender's cameras do; a scale in the
    matrix is ignored. Give one of ``fov`` (the vertical field of view in
    degrees), ``hfov`` (the horizontal one: the vertical follows from the
    image ``size``, width by height) or ``ortho`` (the height an
    orthographic view shows, in the mesh's units)."""
    m = np.asarray(matrix, dtype=np.float64)
    if m.shape != (4, 4):
        raise ValueError(f"matrix: give a 4x4 camera-to-world matrix, not shape {m.shape}")
    if not np.isfinite(m).all():
        raise ValueError("matrix: has a value that is not finite")
    given = [k for k, x in (("fov", fov), ("hfov", hfov), ("ortho", ortho)) if x is not None]
    if len(given) != 1:
        raise ValueError(f"give one of fov, hfov and ortho, not {', '.join(given) or 'none'}")
    back = _unit(m[:3, 2], "Z axis")
    up = _unit(m[:3, 1], "Y axis")
    if abs(float(back @ up)) > 0.999:
        raise ValueError("matrix: its Y axis is along its Z axis, so it has no up")
    eye = m[:3, 3]
    cam = {"eye": eye.tolist(), "target": (eye - back).tolist(), "up": up.tolist()}
    if ortho is not None:
        if not (math.isfinite(ortho) and ortho > 0):
            raise ValueError(f"ortho: give a height above 0, not {ortho}")
        cam["ortho"] = float(ortho)
        return cam
    if hfov is not None:
        if not (math.isfinite(hfov) and 0 < hfov < 180):
            raise ValueError(f"hfov: give degrees between 0 and 180, not {hfov}")
        w, h = _size(size)
        fov = math.degrees(2 * math.atan(math.tan(math.radians(hfov) / 2) * h / w))
    cam["fov"] = float(fov)
    return cam


def blender_camera(
    matrix_world: Any,
    *,
    type: str = "PERSP",
    lens: float = 50.0,
    sensor_width: float = 36.0,
    sensor_height: float = 24.0,
    sensor_fit: str = "AUTO",
    ortho_scale: float = 7.2,
    resolution: Sequence[int] = (1920, 1080),
    shift: Sequence[float] = (0.0, 0.0),
) -> dict:
    """The camera of Blender's settings (``bpy.types.Camera``, defaults as
    Blender's): ``matrix_world`` the camera object's, ``type`` "PERSP" or
    "ORTHO", ``lens`` and the sensor in millimetres, ``sensor_fit`` "AUTO"
    (the sensor width spans the image's larger side), "HORIZONTAL" (its
    width spans the image's width) or "VERTICAL" (its height spans the
    image's height), ``ortho_scale`` the orthographic view's extent along
    the same side as the sensor fit's, ``resolution`` the rendered image's
    width and height (the resolution percentage applied). Lens shift is not
    supported: a shift other than zero is refused, as is a panoramic
    camera."""
    w, h = _size(resolution)
    fit = str(sensor_fit).upper()
    if fit not in ("AUTO", "HORIZONTAL", "VERTICAL"):
        raise ValueError(f"sensor_fit: give AUTO, HORIZONTAL or VERTICAL, not {sensor_fit!r}")
    if any(float(s) != 0.0 for s in shift):
        raise ValueError("shift: a lens shift is not supported; set shift_x and shift_y to 0")
    horizontal = fit == "HORIZONTAL" or (fit == "AUTO" and w >= h)
    kind = str(type).upper()
    if kind == "ORTHO":
        if not (math.isfinite(ortho_scale) and ortho_scale > 0):
            raise ValueError(f"ortho_scale: give an extent above 0, not {ortho_scale}")
        height = ortho_scale * h / w if horizontal else ortho_scale
        return camera_from_matrix(matrix_world, ortho=height, size=(w, h))
    if kind != "PERSP":
        raise ValueError(f"type: give PERSP or ORTHO (a {kind} camera is not supported)")
    if not (math.isfinite(lens) and lens > 0):
        raise ValueError(f"lens: give millimetres above 0, not {lens}")
    sensor = sensor_height if fit == "VERTICAL" else sensor_width
    if not (math.isfinite(sensor) and sensor > 0):
        raise ValueError(f"sensor: give millimetres above 0, not {sensor}")
    angle = math.degrees(2 * math.atan(sensor / (2 * lens)))
    if horizontal:
        return camera_from_matrix(matrix_world, hfov=angle, size=(w, h))
    return camera_from_matrix(matrix_world, fov=angle, size=(w, h))


def from_blender(camera_object: Any, scene: Any) -> dict:
    """:func:`blender_camera` of a Blender camera object and its scene
    (``bpy.types.Object`` whose ``data`` is a camera, ``bpy.types.Scene``):
    the object's world matrix, its camera settings and the scene's render
    resolution with its percentage."""
    c = camera_object.data
    r = scene.render
    pct = getattr(r, "resolution_percentage", 100) / 100.0
    res = (max(1, round(r.resolution_x * pct)), max(1, round(r.resolution_y * pct)))
    return blender_camera(
        [list(row) for row in camera_object.matrix_world],
        type=c.type,
        lens=c.lens,
        sensor_width=c.sensor_width,
        sensor_height=c.sensor_height,
        sensor_fit=c.sensor_fit,
        ortho_scale=c.ortho_scale,
        resolution=res,
        shift=(c.shift_x, c.shift_y),
    )
