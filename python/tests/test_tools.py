"""track, snap and suggest with the command line's meanings: on arrays or
files, the scene they return is the one the command writes."""

import json

import numpy as np
import pytest

import morphfx


def blocks(shift=(0, 0), w=96, h=64):
    """Bright rectangles on grey (corners and straight edges), shifted by
    `shift` pixels (x right, y up)."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    x, y = x - shift[0], y + shift[1]
    v = 0.2 + 0.6 * (((x > 20) & (x < 44) & (y > 14) & (y < 34))
                     | ((x > 56) & (x < 80) & (y > 30) & (y < 52)))
    v = v + 0.3 * ((x > 30) & (x < 70) & (y > 40) & (y < 58))
    return np.dstack([v, 0.8 * v, 0.6 * v, np.ones_like(v)]).astype(np.float32)


def step(edge, w=96, h=64):
    """A vertical step edge at canonical x = `edge`."""
    x = np.arange(w, dtype=np.float32)[None, :] + 0.5
    v = np.repeat(np.where(x < edge, 0.1, 0.9), h, axis=0).astype(np.float32)
    return np.dstack([v, v, v, np.ones_like(v)])


SNAP_SCENE = {"format": "morphfx-scene", "version": 1, "method": "field", "features": [
    {"name": "edge", "type": "curve", "a": [[44, 10], [45, 32], [44, 54]],
     "b": [[48, 10], [47, 32], [48, 54]]},
    {"name": "dot", "type": "point", "a": [[20, 20]], "b": [[22, 21]]}]}


def test_snap_on_arrays_is_the_command_on_files(cli, tmp_path):
    a, b = step(40.0), step(52.0)
    morphfx.write_image(tmp_path / "a.exr", a)
    morphfx.write_image(tmp_path / "b.exr", b)
    scene = morphfx.Scene.from_json(json.dumps(SNAP_SCENE))
    scene.save(tmp_path / "s.morph.json")
    ours = morphfx.snap(scene, a, b, sigma=2.0)
    cli("snap", "--scene", tmp_path / "s.morph.json", "--a", tmp_path / "a.exr", "--b",
        tmp_path / "b.exr", "--sigma", 2.0, "-o", tmp_path / "out.morph.json")
    theirs = json.loads((tmp_path / "out.morph.json").read_text())
    assert json.loads(ours.to_json()) == theirs
    edge = ours.features[0]
    assert edge["type"] == "polyline"
    assert all(abs(x - 40) < 1.0 for x, _ in edge["a"]), "snapped onto A's edge"
    assert all(abs(x - 52) < 1.0 for x, _ in edge["b"]), "snapped onto B's edge"
    assert ours.features[1] == SNAP_SCENE["features"][1]
    # Paths work as the command line's do.
    by_path = morphfx.snap(tmp_path / "s.morph.json", tmp_path / "a.exr",
                           str(tmp_path / "b.exr"), sigma=2.0)
    assert by_path.to_json() == ours.to_json()


def test_suggest_on_arrays_is_the_command_on_files(cli, tmp_path):
    a, b = blocks(), blocks(shift=(3, 2))
    morphfx.write_image(tmp_path / "a.exr", a)
    morphfx.write_image(tmp_path / "b.exr", b)
    ours = morphfx.suggest(a, b, count=8)
    cli("suggest", "--a", tmp_path / "a.exr", "--b", tmp_path / "b.exr", "--count", 8, "-o",
        tmp_path / "out.morph.json")
    assert json.loads(ours.to_json()) == json.loads((tmp_path / "out.morph.json").read_text())
    assert ours.method == "hybrid" and 0 < len(ours.features) <= 8
    for f in ours.features:
        for (ax, ay), (bx, by) in zip(f["a"], f["b"]):
            assert abs(bx - ax - 3) < 0.5 and abs(by - ay - 2) < 0.5, f


def test_track_on_arrays_is_the_command_on_files(cli, tmp_path):
    frames = range(1, 6)
    seq = [blocks(shift=(k, 0)) for k in range(5)]
    for f, picture in zip(frames, seq):
        morphfx.write_image(tmp_path / f"a.{f:04d}.exr", picture)
    doc = {"format": "morphfx-scene", "version": 1, "method": "thin-plate", "keyframes": [
        {"frame": 1, "features": [{"type": "point", "a": [[21, 50]], "b": [[21, 50]]},
                                  {"type": "point", "a": [[57, 34]], "b": [[57, 34]]}]}]}
    scene = morphfx.Scene.from_json(json.dumps(doc))
    scene.save(tmp_path / "s.morph.json")
    ours = morphfx.track(scene, seq, frames=(1, 5))
    cli("track", "--scene", tmp_path / "s.morph.json", "--a", tmp_path / "a.####.exr",
        "--frames", "1-5", "-o", tmp_path / "out.morph.json")
    assert json.loads(ours.to_json()) == json.loads((tmp_path / "out.morph.json").read_text())
    keys = ours.keyframes
    assert [k["frame"] for k in keys] == [1, 2, 3, 4, 5]
    for k in keys:
        (x, y), = k["features"][0]["a"]
        assert abs(x - (21 + k["frame"] - 1)) < 0.1 and abs(y - 50) < 0.1, k
    by_pattern = morphfx.track(scene, str(tmp_path / "a.####.exr"), frames="1-5")
    assert by_pattern.to_json() == ours.to_json()


def test_tools_raise_the_command_lines_errors(cli, tmp_path):
    scene = morphfx.Scene.from_json(json.dumps(SNAP_SCENE))
    with pytest.raises(morphfx.ParamError, match="--sigma 500"):
        morphfx.snap(scene, step(40.0), step(50.0), sigma=500.0)
    with pytest.raises(morphfx.ImageError, match="no such file"):
        morphfx.snap(scene, tmp_path / "none.exr", step(50.0))
    with pytest.raises(morphfx.SceneError, match="no keyframes"):
        morphfx.track(scene, [step(40.0)] * 3, frames=(1, 3))
    with pytest.raises(morphfx.ImageError, match="2 pictures for 3 frames"):
        morphfx.track(scene, [step(40.0)] * 2, frames=(1, 3))
    with pytest.raises(morphfx.ParamError, match="method"):
        morphfx.suggest(blocks(), blocks(), method="magic")
