"""Lines of every frame of an animation from a scene file, with coherence
over the frames off and on."""

import os

import numpy as np

import shapecue

FOX = os.path.join(os.path.dirname(__file__), "..", "..", "data", "Fox.glb")


def fox_scene(tmp_path, coherence):
    path = tmp_path / f"fox-{coherence}.toml"
    path.write_text(
        f'[input]\ngltf = "{os.path.abspath(FOX)}"\nclip = "Walk"\nweld = true\n'
        "[frames]\nend = 6\n[[camera]]\ndirection = [1.0, 0.4, 0.2]\n"
        "[effects]\ncontours = {}\nsuggestive_contours = {}\nridges = {}\nk_zero = {}\n"
        f'[lines]\ncoherence = "{coherence}"\n[output]\nsize = [320, 240]\n'
    )
    return path


def test_every_frame_comes_back_with_its_rest_mesh_provenance(tmp_path):
    off = shapecue.scene_lines(fox_scene(tmp_path, "off"))
    on = shapecue.scene_lines(fox_scene(tmp_path, "on"))
    for views in (off, on):
        assert [v.frame for v in views] == list(range(6))
        assert all(v.view == 0 for v in views)
        for v in views:
            assert len(v.a) > 0 and (v.face >= 0).all()
            np.testing.assert_allclose(v.bary.sum(axis=2), 1.0, atol=1e-5)
            assert set(v.family) <= {"contours", "suggestive", "ridges", "k-zero"}
            assert len(v.chains(visible_only=False)) > 0
    # The first frame is the same with and without coherence; later ones
    # are held from frame to frame.
    for k in ("a", "b", "face", "bary", "family_code"):
        np.testing.assert_array_equal(getattr(off[0], k), getattr(on[0], k))
    assert any(len(a.a) != len(b.a) or (a.a != b.a).any() for a, b in zip(off[1:], on[1:]))
    # Held lines keep their chains' ids from frame to frame.
    assert all(v.chain_id is None for v in off)
    assert all(v.chain_id is not None and len(v.chain_id) == len(v.a) for v in on)
    kept = [len(set(a.chain_id) & set(b.chain_id)) for a, b in zip(on, on[1:])]
    assert all(k > 0 for k in kept), kept


def test_a_missing_scene_file_names_it(tmp_path):
    missing = tmp_path / "nothing.toml"
    try:
        shapecue.scene_lines(missing)
    except (ValueError, OSError) as e:
        assert "nothing.toml" in str(e)
    else:
        raise AssertionError("a missing scene file raises")
