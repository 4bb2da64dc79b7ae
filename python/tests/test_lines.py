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
    k = out.of("k-zero", visible_only=False)
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
    np.testing.assert_array_equal(auto.family_code, default.family_code)
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
    for kw, words in (
        ({"cameras": 2, "direction": (0, 0, 1)}, "direction sets the one camera"),
        ({"target": (0, 0, 0)}, "target goes with eye"),
        ({"eye": (0, 0, 3), "direction": (0, 0, 1)}, "give eye or direction, not both"),
        ({"direction": (0, 0, 0)}, "direction: expected three finite numbers, not all zero"),
        ({"eye": (0, float("nan"), 3)}, "eye: expected three finite numbers"),
        ({"up": (0, 1)}, "up: expected three finite numbers"),
        ({"fov": 0.0}, "fov: fov 0 degrees is outside"),
    ):
        with pytest.raises(ValueError, match=words):
            shapecue.lines(v, f, **kw)


def test_isophotes_of_no_level_are_refused_as_on_the_command_line():
    """`--isophotes 0` is refused by the command line; Python used to return
    no segment instead."""
    v, f = torus(nu=24, nv=12)
    for call in (
        lambda: shapecue.lines(v, f, lines="contours,isophotes", isophotes=0),
        lambda: shapecue.lines(v, f, lines="isophotes", isophotes=0, cameras=2),
    ):
        with pytest.raises(ValueError, match=r"isophotes=0: isophotes need at least 1 level"):
            call()
    with pytest.raises(ValueError, match=r"isophotes=-1"):
        shapecue.lines(v, f, lines="isophotes", isophotes=-1)
    # Without isophotes among the families the count is not read.
    assert len(shapecue.lines(v, f, lines="contours", isophotes=0, cull=False).segments) > 0
    assert len(shapecue.lines(v, f, lines="isophotes", isophotes=1, cull=False).segments) > 0


def test_pieces_of_an_unknown_family_are_refused_naming_the_families():
    v, f = torus(nu=24, nv=12)
    one = shapecue.lines(v, f, lines="contours", cull=False)
    view = shapecue.lines(v, f, lines="contours", cameras=1)[0]
    for call in (lambda: one.of("bogus"), lambda: view.of("bogus"), lambda: view.of(3)):
        with pytest.raises(ValueError) as e:
            call()
        msg = str(e.value)
        assert "unknown line family" in msg and "contours, suggestive, ridges" in msg, msg
    # A known family that was not asked for has no pieces, and no error.
    assert one.of("ridges").shape == (0, 2, 3) and view.of("ridges").shape == (0, 2, 3)
    assert len(one.of("contours", visible_only=False)) == len(one.segments)
    assert len(one.of("contours")) == int(one.visible.sum()) < len(one.segments)


def test_family_codes_are_the_files_codes_with_names_beside_them():
    v, f = torus(nu=24, nv=12)
    one = shapecue.lines(v, f, lines="contours,k-zero", cull=False)
    view = shapecue.lines(v, f, lines="contours,k-zero", cameras=1)[0]
    table = shapecue.FAMILY_CODES
    assert table[0] == "contours" and table[8] == "k-zero" and table[1 << 16] == "feature-edges"
    assert shapecue.LINE_FAMILIES[:2] == ("contours", "suggestive") and len(shapecue.LINE_FAMILIES) == 12
    for x in (one, view):
        assert x.family_code.dtype == np.uint32 and set(x.family_code.tolist()) == {0, 8}
        assert [table[c] for c in x.family_code.tolist()] == x.family.tolist()
        # The earlier name still answers, with a deprecation warning.
        with pytest.warns(DeprecationWarning, match="family_code"):
            np.testing.assert_array_equal(x.kind, x.family_code)


def test_camera_mistakes_are_worded_as_given():
    v, f = torus(nu=24, nv=12)
    target = [0.0, 0.0, 0.0]
    cases = [
        # A NaN used to reach the library as JSON it cannot read ("the file:
        # not JSON").
        ([{"eye": [0, 0, 3], "target": target}, {"eye": [0, 0, float("nan")], "target": target}],
         "cameras: camera 1: eye has [0, 0, nan], a number that is not finite"),
        ([{"eye": [0, 0, 3], "target": target, "fov": float("inf")}],
         "cameras: camera 0: fov has inf, a number that is not finite"),
        # Used to be a bare OverflowError.
        (-1, "cameras=-1: give a number of views from 1 to 10000, a list of camera dicts or a "
             "camera JSON file"),
        (10001, "cameras=10001: give a number of views from 1 to 10000"),
        # Used to read "cameras: cameras: the list is empty".
        ([], "cameras: the list is empty: give at least one camera"),
        ({"cameras": []}, "cameras: the list is empty: give at least one camera"),
        ([[0, 0, 3]], "cameras: camera 0: expected a dict with eye and target"),
    ]
    for cams, words in cases:
        with pytest.raises(ValueError) as e:
            shapecue.lines(v, f, cameras=cams)
        msg = str(e.value)
        assert msg.startswith(words), msg
        assert "cameras: cameras" not in msg and "not JSON" not in msg, msg
    # numpy values are numbers like any other.
    cam = {"eye": np.array([0.0, 0.5, 3.0]), "target": np.zeros(3, np.float32), "fov": np.float32(30)}
    assert len(shapecue.lines(v, f, cameras=[cam])) == 1


def test_a_camera_file_is_named_in_its_errors(tmp_path):
    v, f = torus(nu=24, nv=12)
    p = tmp_path / "cams.json"
    p.write_text('{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0]}, {"eye": [0, 0, 3]}]}')
    with pytest.raises(ValueError, match=r"cams\.json: camera 1: .*target"):
        shapecue.lines(v, f, cameras=p)
    with pytest.raises(FileNotFoundError, match=r"absent\.json"):
        shapecue.lines(v, f, cameras=tmp_path / "absent.json")


def sphere(subdivisions=5):
    """An icosphere of radius 1 (10242 vertices at 5 subdivisions)."""
    trimesh = pytest.importorskip("trimesh")
    m = trimesh.creation.icosphere(subdivisions=subdivisions)
    return np.asarray(m.vertices), np.asarray(m.faces)


def test_ctrl_c_stops_a_call_of_many_views_within_a_view(device):
    """SIGINT (Ctrl-C) during a call of thousands of views raises
    KeyboardInterrupt between two views, not once the call has ended."""
    import os
    import signal
    import threading
    import time

    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signals reach the main thread only")
    v, f = sphere()
    fams = "contours,suggestive,isophotes"
    shapecue.lines(v, f, lines=fams, cameras=1)  # the device opened, the kernels built
    t0 = time.perf_counter()
    shapecue.lines(v, f, lines=fams, cameras=1)
    t1 = time.perf_counter()
    shapecue.lines(v, f, lines=fams, cameras=9)
    t9 = time.perf_counter()
    first = t1 - t0
    per_view = max((t9 - t1) - first, 1e-3) / 8
    delay = 0.5
    # Room for one view, the pose passes and a slow machine; a call that
    # ran to its end takes six times longer (as many views as that needs).
    limit = delay + 2.0 + first + 10 * per_view
    n = min(shapecue._shapecue.MAX_VIEWS, max(1000, int(6 * limit / per_view)))
    whole = n * per_view
    if whole < 3 * limit:
        pytest.skip(f"{n} views take {whole:.1f} s here: too few to tell an interrupt from the end")
    timer = threading.Timer(delay, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            shapecue.lines(v, f, lines=fams, cameras=n)
            # Without a check between views Python sees the signal only here,
            # once every view is done.
        elapsed = time.perf_counter() - t0
    finally:
        timer.cancel()
    assert elapsed < limit, f"KeyboardInterrupt after {elapsed:.1f} s; the whole call takes ~{whole:.0f} s"
    # The device is usable afterwards.
    assert len(shapecue.lines(v, f, lines=fams, cameras=2)) == 2


def test_many_views_give_the_same_bytes_every_call():
    v, f = torus(nu=48, nv=24)
    keys = ("a", "b", "family_code", "strength", "visible", "chain", "faces", "face", "bary")
    runs = [shapecue.lines(v, f, lines="contours,suggestive,ridges", cameras=4, fields=True)
            for _ in range(3)]
    for other in runs[1:]:
        for x, y in zip(runs[0], other):
            assert len(x.a) > 0
            for k in keys:
                assert getattr(x, k).tobytes() == getattr(y, k).tobytes(), k
            for k in x.fields:
                assert x.fields[k].tobytes() == y.fields[k].tobytes(), k
            assert x.camera == y.camera


@pytest.mark.parametrize("mesh", ["torus", "bunny"])
def test_views_are_the_command_lines_rows(device, cli, mesh, tmp_path, request):
    """shapecue.lines(path, cameras=N) gives the rows of `shapecue lines
    PATH --views N --out DIR --npz`, in the same order, bit for bit; and the
    same for a camera file."""
    import json
    import subprocess
    from conftest import write_obj

    if mesh == "bunny":
        path = request.getfixturevalue("bunny")
    else:
        v, f = torus(nu=48, nv=24)
        path = tmp_path / "torus.obj"
        write_obj(path, v, f)
    fams = "contours,suggestive,ridges,valleys"
    cams = tmp_path / "cams.json"
    # Fitted views on the bounds would need the bounds here: two explicit
    # cameras, one perspective, one orthographic, around the mesh's centre.
    lo, hi = shapecue.load_mesh(path)[0].min(0), shapecue.load_mesh(path)[0].max(0)
    c, r = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
    cams.write_text(json.dumps({"cameras": [
        {"eye": (c + [0.3 * r, 0.2 * r, 1.5 * r]).tolist(), "target": c.tolist()},
        {"eye": (c + [-1.5 * r, 0.4 * r, 0.1 * r]).tolist(), "target": c.tolist(), "ortho": 1.2 * r},
    ]}))
    for how, arg, cameras in (("views", "3", 3), ("cameras", str(cams), cams)):
        out = tmp_path / f"cli-{how}"
        run = subprocess.run(
            [cli, "lines", str(path), f"--{how}", arg, "--out", str(out), "--npz", "--lines", fams],
            capture_output=True, text=True, timeout=600,
        )
        assert run.returncode == 0, run.stderr
        manifest = json.loads((out / "manifest.json").read_text())
        assert {int(k): n for k, n in manifest["family_codes"].items()} == shapecue.FAMILY_CODES
        views = shapecue.lines(path, lines=fams, cameras=cameras)
        assert len(views) == len(manifest["views"])
        for mv, view in zip(manifest["views"], views):
            npz = next(x["name"] for x in mv["files"] if x["name"].endswith("_segments.npz"))
            z = np.load(out / npz)
            assert len(z["a"]) > 0
            np.testing.assert_array_equal(view.camera["eye"], mv["camera"]["eye"])
            ours = {
                "a": view.a, "b": view.b, "family": view.family_code, "strength": view.strength,
                "visible": view.visible.astype(np.uint8), "faces": view.faces, "chain": view.chain,
                "face": view.face, "bary": view.bary,
            }
            # The code table (family_codes, family_names) may follow.
            assert list(z.files)[: len(ours)] == list(ours)
            if "family_codes" in z.files:
                table = dict(zip(z["family_codes"].tolist(), z["family_names"].tolist()))
                assert table == shapecue.FAMILY_CODES
            for k, a in ours.items():
                assert z[k].dtype == a.dtype and z[k].shape == a.shape, k
                assert z[k].tobytes() == a.tobytes(), (how, mv["index"], k)


def test_the_feature_size_is_rtscs_unless_asked_otherwise():
    """The thresholds scale by rtsc's feature size (0.01 / the 10th
    percentile of |k|, at most 5 % of the bounding radius), not by the median
    edge length, which `feature_size="edge"` asks for."""
    v, f = sphere(4)
    rtsc = shapecue.lines(v, f).feature_size
    edge = shapecue.lines(v, f, feature_size="edge").feature_size
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    e = np.unique(e, axis=0)
    median_edge = float(np.median(np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)))
    # |k| is about 1 on the unit sphere: 0.01 / 1, below 0.05 · 1.
    assert rtsc == pytest.approx(0.01, rel=0.05)
    assert edge == pytest.approx(median_edge, rel=0.05) and abs(edge - rtsc) > 0.02
    assert shapecue.lines(v, f, feature_size=0.5).feature_size == pytest.approx(0.5)
    for doc in (shapecue.Lines.__doc__, shapecue.lines.__doc__):
        assert "rtsc" in doc and "10th percentile" in doc
    assert "scaled by (the median edge length)" not in shapecue.Lines.__doc__


def segments_json_rows(doc):
    """The pieces of a `shapecue lines -o X.svg --segments S.json` document
    as the arrays of a LineView. The document's floats are f32 values
    written as f64 (serde_json widens them): read as float64 and narrowed
    to float32 they are the f32 bits again. A piece on no face has face
    null and bary null there (-1 and zeros in the arrays)."""
    segs = doc["segments"]

    def f32(x):
        return np.asarray(x, dtype=np.float64).astype(np.float32)

    return {
        "a": f32([s["a"] for s in segs]),
        "b": f32([s["b"] for s in segs]),
        "family": np.array([s["family"] for s in segs], dtype=str),
        "strength": f32([s["strength"] for s in segs]),
        "visible": np.array([s["visible"] for s in segs], dtype=bool),
        "chain": np.array([s["chain"] for s in segs], dtype=np.uint32),
        "faces": np.array([s["faces"] + [-1] * (4 - len(s["faces"])) for s in segs], dtype=np.int64),
        "face": np.array([-1 if s["face"] is None else s["face"] for s in segs], dtype=np.int64),
        "bary": f32([np.zeros((2, 3)) if s["bary"] is None else s["bary"] for s in segs]),
    }


@pytest.mark.parametrize("mesh", ["spot", "torus"])
def test_one_eye_is_the_command_lines_picture(device, cli, mesh, tmp_path):
    """shapecue.lines(mesh) from one camera gives the pieces of `shapecue
    lines MESH -o X.svg --segments S.json` (the fitted camera, exact
    visibility): the same rows in the same order, bit for bit; also for an
    explicit orthographic eye with target, up, fov and size. Before, one
    eye went by a route of its own, from another eye, with no visibility."""
    import json
    import subprocess
    from conftest import REPO

    if mesh == "spot":
        path = REPO / "data" / "spot.obj"
        arg, v, f = str(path), *shapecue.load_mesh(path)
    else:
        # The command line's generated torus, the same vertices here.
        arg = "torus"
        v, f = shapecue._shapecue.generated_mesh("torus", 3000)
    c = (v.min(0) + v.max(0)) / 2
    fams = "contours,suggestive,ridges"
    eye = (c + [1.5, 0.3, 2.0]).tolist()
    target = (c + [0.0, 0.1, 0.0]).tolist()
    cases = [
        ([], {}),
        (["--eye", ",".join(map(str, eye)), "--target", ",".join(map(str, target)),
          "--up", "0,1,0.1", "--ortho", "--fov", "30", "--size", "400x300"],
         {"eye": eye, "target": target, "up": (0, 1, 0.1), "ortho": True, "fov": 30,
          "size": (400, 300)}),
    ]
    hidden = 0
    for k, (flags, kw) in enumerate(cases):
        seg = tmp_path / f"s{k}.json"
        cmd = [cli, "lines", arg, "-o", str(tmp_path / f"x{k}.svg"), "--segments", str(seg),
               "--lines", fams, *flags]
        if mesh == "torus":
            cmd += ["--vertices", "3000"]
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr
        doc = json.loads(seg.read_text())
        view = shapecue.lines(v, f, lines=fams, **kw)
        assert isinstance(view, shapecue.LineView) and view.visible.dtype == bool
        expect = segments_json_rows(doc)
        assert len(view.a) == len(expect["a"]) > 100, (k, len(view.a), len(expect["a"]))
        assert view.visible.any()
        hidden += int((~view.visible).sum())
        for name, e in expect.items():
            got = getattr(view, name)
            assert got.dtype == e.dtype and got.shape == e.shape, (k, name)
            if name == "family":
                assert got.tolist() == e.tolist(), (k, name)
            else:
                assert got.tobytes() == e.tobytes(), (k, name)
        assert view.feature_size == doc["feature_size"]
        assert view.segments.shape == (len(view.a), 2, 3)
        np.testing.assert_array_equal(view.segments[:, 1], view.b)
    # Visibility is compared, not only its default: some pieces are hidden.
    assert hidden > 0


def test_chains_are_polylines_in_the_command_lines_walking_order(device, cli, tmp_path):
    """LineView.chains(): each chain an ordered polyline whose pieces are
    the rows the command line's segments document lists for it, in its
    order; consecutive pieces meet (each walked the right way round), every
    point rebuilt from its face and barycentric coordinates, and a family
    or the hidden chains asked for alone."""
    import json
    import subprocess
    from conftest import REPO

    path = REPO / "data" / "spot.obj"
    v, f = shapecue.load_mesh(path)
    fams = "contours,suggestive,ridges,valleys"
    seg = tmp_path / "s.json"
    run = subprocess.run([cli, "lines", str(path), "-o", str(tmp_path / "x.svg"), "--segments", str(seg),
                          "--lines", fams], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    doc = json.loads(seg.read_text())
    view = shapecue.lines(v, f, lines=fams)
    # The walk is the document's chains, concatenated.
    assert len(view.chain_visible) == len(doc["chains"]) > 50
    assert view.chain_order.tolist() == [i for c in doc["chains"] for i in c["segments"]]
    assert view.chain_visible.tolist() == [c["visible"] for c in doc["chains"]]
    every = view.chains(visible_only=False)
    assert len(every) == len(doc["chains"])
    assert every.id.tolist() == list(range(len(every)))
    assert every.family.tolist() == [c["family"] for c in doc["chains"]]
    assert len(every.points) == len(view.a) + len(every)
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    longest = 0
    for k, pts in enumerate(every):
        rows = view.chain_order[view.chain_start[k]:view.chain_start[k + 1]]
        assert len(pts) == len(rows) + 1
        assert np.all(view.chain[rows] == k)
        # Consecutive pieces meet: the polyline's points are its pieces'
        # ends, each piece walked from the point before it.
        ends = np.stack([view.a[rows], view.b[rows]], 1)
        rev = view.chain_reversed[view.chain_start[k]:view.chain_start[k + 1]]
        walked = np.where(rev[:, None, None], ends[:, ::-1], ends)
        assert np.allclose(walked[:, 0], pts[:-1], atol=1e-4 * diag)
        assert np.allclose(walked[:, 1], pts[1:], atol=1e-4 * diag)
        longest = max(longest, len(rows))
    assert longest > 10
    # Each point from its face and barycentric coordinates.
    on = every.face >= 0
    assert on.mean() > 0.99
    rebuilt = (every.bary[on, :, None] * v[f[every.face[on]]]).sum(1)
    assert np.allclose(rebuilt, every.points[on], atol=1e-4 * diag)
    # One family, visible chains only (the default), and the hidden ones.
    ridges = view.chains("ridges")
    assert len(ridges) > 0 and set(ridges.family) == {"ridges"} and ridges.visible.all()
    assert len(ridges) == sum(c["family"] == "ridges" and c["visible"] for c in doc["chains"])
    assert len(view.chains()) == int(view.chain_visible.sum()) < len(every)
    with pytest.raises(ValueError, match="creases"):
        view.chains("creases")
    # A family with no chain (a closed mesh has no boundary): none at all.
    none = shapecue.lines(v, f, lines="contours,boundaries").chains("boundaries")
    assert len(none) == 0 and list(none) == [] and none.points.shape == (0, 3)


def test_several_meshes_hide_each_other_and_each_piece_names_its_mesh(device, tmp_path):
    """lines([a, b]) draws the meshes together: the same rows as the meshes
    joined into one by hand, each piece naming its mesh and its face there,
    and the mesh in front hiding lines of the one behind it."""
    from conftest import write_obj

    v0, f0 = torus(nu=60, nv=30)
    v1 = v0 + [0.4, 0.3, -2.5]
    f1 = f0.copy()
    eye = (0.0, 0.0, 6.0)
    kw = dict(lines="contours,suggestive,ridges", eye=eye, target=(0.0, 0.0, -1.0))
    path = tmp_path / "behind.obj"
    write_obj(path, v1, f1)
    both = shapecue.lines([(v0, f0), path], **kw)
    joined = shapecue.lines(np.concatenate([v0, v1]), np.concatenate([f0, f1 + len(v0)]), **kw)
    for name in ("a", "b", "visible", "face", "chain_order"):
        np.testing.assert_array_equal(getattr(both, name), getattr(joined, name), err_msg=name)
    assert joined.mesh is None
    assert set(both.mesh.tolist()) == {0, 1}
    np.testing.assert_array_equal(both.mesh_face, both.face - np.where(both.mesh == 1, len(f0), 0))
    for k, (v, f) in enumerate([(v0, f0), (v1, f1)]):
        rows = both.mesh == k
        assert np.all((both.mesh_face[rows] >= 0) & (both.mesh_face[rows] < len(f)))
        rebuilt = (both.bary[rows, 0, :, None] * v[f[both.mesh_face[rows]]]).sum(1)
        np.testing.assert_allclose(rebuilt, both.a[rows], atol=1e-4)
    # The torus in front hides part of the one behind: less of its length
    # is visible than when it is drawn alone.
    alone = shapecue.lines(v1, f1, **kw)
    length = lambda a, b, keep: float(np.linalg.norm(b[keep] - a[keep], axis=1).sum())  # noqa: E731
    behind = both.mesh == 1
    seen_alone = length(alone.a, alone.b, alone.visible)
    seen_behind = length(both.a, both.b, behind & both.visible)
    assert seen_behind < 0.8 * seen_alone, (seen_behind, seen_alone)
    with pytest.raises(ValueError, match="several meshes"):
        shapecue.lines([(v0, f0), (v1, f1)], normals=np.zeros((3, 3)))
