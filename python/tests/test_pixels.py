"""The module's renders are the command line's: `morphfx.morph(...)` equals
`morphfx morph ... -o out.exr --float` within 1e-5, for every method and view."""

import numpy as np
import pytest

import morphfx
import json

from conftest import LINES, METHODS, plate

MORPH_VIEWS = ["morph", "warped-a", "warped-b", "stmap-a", "stmap-b", "transition",
               "grid", "ghost", "folds", "vectors"]
WARP_VIEWS = ["warped", "stmap", "grid", "folds", "vectors"]


def cli_render(cli, tmp_path, node, scene, view, t, extra=()):
    out = tmp_path / f"{node}-{view}.exr"
    inputs = (["--a", scene.parent / "a.exr", "--b", scene.parent / "b.exr"]
              if node == "morph" else ["--input", scene.parent / "a.exr"])
    cli(node, "--scene", scene, *inputs, "--t", t, "--view", view, "-o", out, "--float",
        *extra)
    return morphfx.read_image(out)


@pytest.mark.parametrize("method", METHODS)
def test_every_morph_view_equals_the_command_line(cli, files, tmp_path, method):
    scene = files / f"{method}.morph.json"
    a, b = morphfx.read_image(files / "a.exr"), morphfx.read_image(files / "b.exr")
    for view in MORPH_VIEWS:
        ours = morphfx.morph(morphfx.Scene.load(scene), a, b, t=0.4, view=view)
        theirs = cli_render(cli, tmp_path, "morph", scene, view, 0.4)
        assert ours.shape == theirs.shape == (64, 96, 4), view
        assert ours.dtype == np.float32
        assert np.abs(ours - theirs).max() <= 1e-5, (method, view)
    # The morph is a real picture: neither A, nor B, nor black.
    picture = morphfx.morph(scene, a, b, t=0.5)
    assert np.abs(picture - a).max() > 0.05 and np.abs(picture - b).max() > 0.05


@pytest.mark.parametrize("method", [m for m in METHODS if m != "auto"])
def test_every_warp_view_equals_the_command_line(cli, files, tmp_path, method):
    scene = files / f"{method}.morph.json"
    a = morphfx.read_image(files / "a.exr")
    for view in WARP_VIEWS:
        ours = morphfx.warp(scene, a, t=0.7, view=view)
        theirs = cli_render(cli, tmp_path, "warp", scene, view, 0.7)
        assert np.abs(ours - theirs).max() <= 1e-5, (method, view)
    # view="morph" is the node's picture.
    assert np.array_equal(morphfx.warp(scene, a, t=0.7), morphfx.warp(scene, a, t=0.7,
                                                                          view="warped"))


def test_params_and_mattes_as_the_command_line_sets_them(cli, files, tmp_path):
    scene = files / "field.morph.json"
    mask = plate(5)
    mask[..., 3] = np.linspace(0, 1, mask.shape[1], dtype=np.float32)[None, :]
    morphfx.write_image(files / "mask.exr", mask)
    params = {"filter": "bicubic", "mix": 0.75, "field_a": 0.5, "settings_from_scene": False,
              "edge": "black", "mask_invert": True}
    a, b = morphfx.read_image(files / "a.exr"), morphfx.read_image(files / "b.exr")
    ours = morphfx.morph(scene, a, b, t=0.3, params=params, mask=mask)
    words = [w for k, v in params.items()
             for w in ("--param", f"{k}={str(v).lower() if isinstance(v, bool) else v}")]
    theirs = cli_render(cli, tmp_path, "morph", scene, "morph", 0.3,
                        [*words, "--mask", files / "mask.exr"])
    assert np.abs(ours - theirs).max() <= 1e-5
    plain = morphfx.morph(scene, a, b, t=0.3)
    assert np.abs(ours - plain).max() > 0.01, "the params changed nothing"


def test_keyed_params_interpolate_like_the_command_lines(cli, files, tmp_path):
    scene = files / "field.morph.json"
    a, b = morphfx.read_image(files / "a.exr"), morphfx.read_image(files / "b.exr")
    ours = morphfx.morph(scene, a, b, frame=5, params={"progress": {0: 0.0, 10: 1.0},
                                                      "use_scene_progress": False})
    out = tmp_path / "keyed.exr"
    cli("morph", "--scene", scene, "--a", files / "a.exr", "--b", files / "b.exr",
        "--frames", "5", "--param", "progress@0=0", "--param", "progress@10=1",
        "--param", "use_scene_progress=false", "-o", out, "--float")
    assert np.abs(ours - morphfx.read_image(out)).max() <= 1e-5
    halfway = morphfx.morph(scene, a, b, t=0.5)
    assert np.abs(ours - halfway).max() <= 1e-5


def test_stmap_is_the_command_lines_and_the_identity_at_the_start(cli, files, tmp_path):
    scene = files / "thin-plate.morph.json"
    st = morphfx.stmap(morphfx.Scene.load(scene), "a", 0.6, 96, 64)
    assert st.shape == (64, 96, 2) and st.dtype == np.float32
    out = tmp_path / "m.exr"
    cli("morph", "--scene", scene, "--a", files / "a.exr", "--b", files / "b.exr", "--t",
        0.6, "--stmap-a", tmp_path / "st.exr", "-o", out)
    assert np.abs(st - morphfx.read_image(tmp_path / "st.exr")[..., :2]).max() <= 1e-5
    # At t = 0 A is not warped: each pixel reads its own centre (x + ½)/W,
    # and row 0, the top row, reads y = (H − ½)/H.
    st0 = morphfx.stmap(scene, "a", 0.0, 96, 64)
    x = (np.arange(96) + 0.5) / 96
    y = (np.arange(64)[::-1] + 0.5) / 64
    assert np.abs(st0[..., 0] - x[None, :]).max() < 1e-6
    assert np.abs(st0[..., 1] - y[:, None]).max() < 1e-6


def test_a_moving_scene_blurs_and_has_vectors_as_the_command_line(cli, files, tmp_path):
    """Keyed features: the vectors view and motion blur match, and move."""
    doc = {"format": "morphfx-scene", "version": 1, "method": "field", "keyframes": [
        {"frame": 0, "features": LINES},
        {"frame": 10, "features": [dict(l, b=[[x + 6, y + 3] for x, y in l["b"]])
                                   for l in LINES]}]}
    scene = tmp_path / "moving.morph.json"
    scene.write_text(json.dumps(doc))
    a, b = morphfx.read_image(files / "a.exr"), morphfx.read_image(files / "b.exr")
    for view, params, words in [
        ("vectors", None, []),
        ("morph", {"motion_blur": 4, "shutter": 1.0},
         ["--param", "motion_blur=4", "--param", "shutter=1.0"]),
    ]:
        ours = morphfx.morph(scene, a, b, t=0.8, frame=4, view=view, params=params)
        out = tmp_path / f"moving-{view}.exr"
        cli("morph", "--scene", scene, "--a", files / "a.exr", "--b", files / "b.exr",
            "--t", 0.8, "--frames", 4, "--view", view, "-o", out, "--float", *words)
        assert np.abs(ours - morphfx.read_image(out)).max() <= 1e-5, view
    vectors = morphfx.morph(scene, a, b, t=0.8, frame=4, view="vectors")
    # B's lines move (6, 3) px over 10 frames, so the in-between lines at
    # t = 0.8 move 0.8 × (0.6, 0.3) a frame, all alike: so does the picture.
    assert np.abs(vectors - [0.48, 0.24, -0.48, -0.24]).max() < 1e-3
    still = morphfx.morph(scene, a, b, t=0.8, frame=4)
    blurred = morphfx.morph(scene, a, b, t=0.8, frame=4,
                            params={"motion_blur": 4, "shutter": 1.0})
    # A smooth plate moved half a pixel: the blur is slight, but there.
    assert np.abs(blurred - still).max() > 1e-4
