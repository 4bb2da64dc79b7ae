"""Cameras from camera-to-world matrices and from Blender's settings."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

import shapecue


def look_at(eye, target, up=(0.0, 1.0, 0.0), scale=1.0):
    """A camera-to-world matrix looking from eye at target (-Z forward)."""
    eye, target, up = (np.asarray(x, dtype=float) for x in (eye, target, up))
    back = eye - target
    back /= np.linalg.norm(back)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    y = np.cross(back, right)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right * scale, y * scale, back * scale, eye
    return m


def test_a_matrix_gives_eye_target_up_and_the_field_of_view():
    m = look_at((1.0, 2.0, 5.0), (1.0, 2.0, 0.0), scale=3.0)
    cam = shapecue.camera_from_matrix(m, fov=30)
    np.testing.assert_allclose(cam["eye"], [1, 2, 5])
    np.testing.assert_allclose(cam["target"], [1, 2, 4])
    np.testing.assert_allclose(cam["up"], [0, 1, 0], atol=1e-12)
    assert cam["fov"] == 30 and "ortho" not in cam
    # A horizontal field of view: the vertical one of the image's aspect.
    h = shapecue.camera_from_matrix(m, hfov=60, size=(800, 600))
    assert h["fov"] == pytest.approx(math.degrees(2 * math.atan(math.tan(math.radians(30)) * 0.75)))
    assert shapecue.camera_from_matrix(m, ortho=2.5)["ortho"] == 2.5
    for bad, words in [
        (dict(fov=30, ortho=2), "one of fov"),
        (dict(), "one of fov"),
        (dict(hfov=200), "hfov"),
        (dict(ortho=-1), "ortho"),
    ]:
        with pytest.raises(ValueError, match=words):
            shapecue.camera_from_matrix(m, **bad)
    with pytest.raises(ValueError, match="4x4"):
        shapecue.camera_from_matrix(np.eye(3), fov=30)
    flat = m.copy()
    flat[:3, 1] = flat[:3, 2]
    with pytest.raises(ValueError, match="no up"):
        shapecue.camera_from_matrix(flat, fov=30)
    nan = m.copy()
    nan[0, 3] = np.nan
    with pytest.raises(ValueError, match="not finite"):
        shapecue.camera_from_matrix(nan, fov=30)


def test_blender_settings_map_onto_the_field_of_view_and_the_orthographic_height():
    m = look_at((0.0, -6.0, 1.0), (0.0, 0.0, 1.0), up=(0.0, 0.0, 1.0))
    # Blender's default camera: 50 mm on a 36 mm sensor, 1920 x 1080, AUTO
    # fit: the sensor width spans the image's width; the vertical field of
    # view is Blender's 22.9 degrees.
    cam = shapecue.blender_camera(m)
    assert cam["fov"] == pytest.approx(22.895, abs=1e-3)
    np.testing.assert_allclose(cam["up"], [0, 0, 1], atol=1e-12)
    # A portrait image under AUTO: the sensor width spans the height.
    tall = shapecue.blender_camera(m, resolution=(1080, 1920))
    assert tall["fov"] == pytest.approx(math.degrees(2 * math.atan(18 / 50)))
    vert = shapecue.blender_camera(m, sensor_fit="VERTICAL", sensor_height=24)
    assert vert["fov"] == pytest.approx(math.degrees(2 * math.atan(12 / 50)))
    # Orthographic: ortho_scale spans the larger side (AUTO), the width
    # (HORIZONTAL) or the height (VERTICAL).
    o = dict(type="ORTHO", ortho_scale=8.0, resolution=(1600, 900))
    assert shapecue.blender_camera(m, **o)["ortho"] == pytest.approx(4.5)
    assert shapecue.blender_camera(m, sensor_fit="VERTICAL", **o)["ortho"] == pytest.approx(8.0)
    with pytest.raises(ValueError, match="shift"):
        shapecue.blender_camera(m, shift=(0.1, 0.0))
    with pytest.raises(ValueError, match="PANO"):
        shapecue.blender_camera(m, type="PANO")
    # A camera object and its scene, as bpy gives them.
    obj = SimpleNamespace(
        matrix_world=m.tolist(),
        data=SimpleNamespace(type="PERSP", lens=35.0, sensor_width=36.0, sensor_height=24.0,
                             sensor_fit="AUTO", ortho_scale=7.2, shift_x=0.0, shift_y=0.0),
    )
    scene = SimpleNamespace(render=SimpleNamespace(resolution_x=1920, resolution_y=1080,
                                                   resolution_percentage=50))
    got = shapecue.from_blender(obj, scene)
    assert got == shapecue.blender_camera(m, lens=35.0, resolution=(960, 540))


def test_a_matrix_camera_draws_what_the_same_eye_draws(device):
    from test_lines import torus

    v, f = torus(nu=60, nv=30)
    eye, target, up = (2.0, 1.0, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    m = look_at(eye, target, up)
    cam = shapecue.camera_from_matrix(m, fov=35)
    by_matrix = shapecue.lines(v, f, lines="contours,ridges", cameras=[cam])[0]
    d = np.asarray(target) - np.asarray(eye)
    near = (np.asarray(eye) + d / np.linalg.norm(d)).tolist()
    by_eye = shapecue.lines(v, f, lines="contours,ridges", cameras=[
        {"eye": list(eye), "target": near, "up": list(up), "fov": 35}])[0]
    assert len(by_matrix.a) > 100
    np.testing.assert_allclose(by_matrix.a, by_eye.a, atol=1e-5)
    np.testing.assert_array_equal(by_matrix.visible, by_eye.visible)
