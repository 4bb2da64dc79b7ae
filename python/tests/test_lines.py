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
