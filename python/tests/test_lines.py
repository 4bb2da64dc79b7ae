"""shapecue.lines: the line families of rtsc on generated meshes."""

import numpy as np
import pytest

import shapecue


def torus(R=1.0, r=0.4, nu=80, nv=40):
    u, v = np.meshgrid(np.arange(nu) * 2 * np.pi / nu, np.arange(nv) * 2 * np.pi / nv, indexing="ij")
    p = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1)
    idx = np.arange(nu * nv).reshape(nu, nv)
    a, b = idx, np.roll(idx, -1, 0)
    c, d = np.roll(idx, -1, 1), np.roll(np.roll(idx, -1, 0), -1, 1)
    f = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return p.reshape(-1, 3), f


def test_parabolic_lines_of_a_torus_are_its_top_and_bottom_circles():
    v, f = torus()
    out = shapecue.lines(v, f, lines="k-zero,contours", cull=False)
    k = out.of("k-zero")
    assert len(k) > 100
    rho = np.hypot(k[..., 0], k[..., 1])
    assert np.all(np.abs(rho - 1.0) < 0.03)
    assert np.all(np.abs(np.abs(k[..., 2]) - 0.4) < 0.03)
    assert set(out.family) == {"k-zero", "contours"}
    assert np.all((out.strength >= 0) & (out.strength <= 1))


def test_unknown_family_is_a_clear_error():
    v, f = torus(nu=8, nv=4)
    with pytest.raises(ValueError, match="creases"):
        shapecue.lines(v, f, lines=["ridges", "creases"])


def test_auto_accumulation_is_the_default_and_unknown_names_the_choices():
    v, f = torus(nu=24, nv=12)
    default = shapecue.lines(v, f, lines="k-zero,contours", cull=False)
    auto = shapecue.lines(v, f, lines="k-zero,contours", cull=False, accumulate="auto")
    assert auto.segments.shape == default.segments.shape
    np.testing.assert_allclose(auto.segments, default.segments, rtol=1e-4, atol=1e-5)
    np.testing.assert_array_equal(auto.kind, default.kind)
    msg = r'unknown accumulation "sometimes": expected auto, atomic, atomic-native, gather'
    with pytest.raises(ValueError, match=msg):
        shapecue.lines(v, f, accumulate="sometimes")


def test_many_views_share_the_pose_and_carry_provenance_and_fields():
    v, f = torus()
    v = v * 3.0 + np.array([40.0, -10.0, 5.0])
    centre = np.array([40.0, -10.0, 5.0])
    cams = [
        {"eye": (centre + [0.0, -12.0, 6.0]).tolist(), "target": centre.tolist()},
        {"eye": centre + np.array([9.0, 0.0, 9.0]), "target": centre, "ortho": 10.0},
    ]
    views = shapecue.lines(v, f, lines="contours,suggestive,ridges", cameras=cams, fields=True)
    assert len(views) == 2
    # The pose passes ran with the first view only.
    assert "curvature" in views[0].passes and "bvh" in views[0].passes
    assert "curvature" not in views[1].passes and "bvh" not in views[1].passes
    assert "visibility" in views[1].passes and "view_fields" in views[1].passes
    assert views[1].camera["ortho"] == pytest.approx(10.0)
    for view, cam in zip(views, cams):
        n = len(view.a)
        assert n > 100 and view.bary.shape == (n, 2, 3) and view.faces.shape == (n, 4)
        assert view.visible.dtype == bool and 0 < view.visible.mean() < 1
        assert set(view.family) <= {"contours", "suggestive", "ridges"}
        # Each end rebuilt from its face's corners and its barycentric
        # coordinates.
        assert np.all(view.face >= 0)
        corners = v[f[view.face]]
        for end, pts in ((0, view.a), (1, view.b)):
            rebuilt = np.einsum("pj,pjc->pc", view.bary[:, end], corners)
            assert np.abs(rebuilt - pts).max() < 1e-4 * 3.0
        # n·v per vertex from the vertex positions (the torus's normals).
        nd = view.fields["ndotv"]
        assert nd.shape == (len(v),)
        eye = np.asarray(cam["eye"], dtype=float)
        to_eye = eye - v if "ortho" not in cam else np.broadcast_to(eye - centre, v.shape)
        to_eye = to_eye / np.linalg.norm(to_eye, axis=1, keepdims=True)
        q = (v - centre) / 3.0
        ring = q.copy()
        ring[:, 2] = 0.0
        ring = ring / np.linalg.norm(ring, axis=1, keepdims=True)
        normal = q - ring * 1.0
        normal = normal / np.linalg.norm(normal, axis=1, keepdims=True)
        assert np.abs(nd - np.sum(normal * to_eye, axis=1)).max() < 0.02
        assert all(np.all(np.isfinite(view.fields[k])) for k in ("kr", "dwkr", "q1"))
    # A number of views: the Fibonacci cameras, the same for the same count.
    a = shapecue.lines(v, f, cameras=3)
    b = shapecue.lines(v, f, cameras=3)
    assert [x.camera["eye"] for x in a] == [x.camera["eye"] for x in b]
    assert a[0].fields is None


def test_bad_cameras_are_clear_errors():
    v, f = torus(nu=24, nv=12)
    with pytest.raises(ValueError, match="camera 1"):
        shapecue.lines(v, f, cameras=[{"eye": [0, 0, 3], "target": [0, 0, 0]}, {"eye": [0, 0, 3]}])
    with pytest.raises(ValueError, match="cameras"):
        shapecue.lines(v, f, cameras=True)
    with pytest.raises(ValueError, match="eye"):
        shapecue.lines(v, f, cameras=2, eye=(0, 0, 3))
    with pytest.raises(ValueError, match="0 views|1 to"):
        shapecue.lines(v, f, cameras=0)
    with pytest.raises(ValueError, match="fields"):
        shapecue.lines(v, f, fields=True)
