"""The README's Python example and every Python block of docs/python.md run
as shown, in a folder holding the files they name; and what the guide says
of defaults and conversions holds."""

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

import morphfx
from conftest import cli_error, plate

ROOT = Path(__file__).resolve().parents[2]


def blocks(path):
    return re.findall(r"```python\n(.*?)```", path.read_text(), re.S)


def shapes(w, h, dx=0.0):
    """Blocks with corners on a smooth ground, shifted `dx` pixels right."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    x = x - dx
    v = 0.3 + 0.1 * np.sin(0.05 * x + 0.07 * y)
    v = v + 0.5 * ((x > 60) & (x < 140) & (y > 50) & (y < 120))
    v = v + 0.4 * ((x > 180) & (x < 260) & (y > 100) & (y < 190))
    return np.dstack([v, 0.9 * v, 0.7 * v, np.ones_like(v)]).astype(np.float32)


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """What the examples name: a face scene, plates A and B, a short shot."""
    monkeypatch.chdir(tmp_path)
    lines = [{"type": "line", "a": [[60, 50], [140, 50]], "b": [[64, 54], [144, 54]]},
             {"type": "line", "a": [[180, 190], [260, 190]], "b": [[176, 186], [256, 186]]}]
    keyed = {"format": "morphfx-scene", "version": 1, "method": "field",
             "keyframes": [{"frame": 1001, "features": lines}]}
    Path("face.morph.json").write_text(json.dumps(keyed))
    morphfx.write_image("a.exr", shapes(320, 240))
    morphfx.write_image("b.exr", shapes(320, 240, 4.0))
    os.makedirs("shot")
    for k, f in enumerate(range(1001, 1004)):
        morphfx.write_image(f"shot/a.{f}.exr", shapes(320, 240, k))
        morphfx.write_image(f"shot/b.{f}.exr", shapes(320, 240, 4.0 + k))
    return tmp_path


def test_the_readme_example_runs(folder):
    (example,) = [b for b in blocks(ROOT / "README.md")]
    exec(compile(example, "README.md", "exec"), {})
    scene = morphfx.Scene.load("face.morph.json")
    expected = morphfx.morph(scene, morphfx.read_image("a.exr"), morphfx.read_image("b.exr"),
                             t=0.5)
    assert np.array_equal(morphfx.read_image("out.exr"), expected)


def test_every_block_of_the_python_guide_runs_in_order(folder):
    found = blocks(ROOT / "docs" / "python.md")
    assert len(found) >= 5
    namespace = {}
    for k, block in enumerate(found):
        exec(compile(block, f"docs/python.md block {k + 1}", "exec"), namespace)
    for name in ["copy.exr", "small.exr", "mine.morph.json", "out/morph.1003.exr"]:
        assert Path(name).is_file(), name
    assert len(namespace["tracked"].keyframes) == 3
    assert len(namespace["found"].features) > 0


def test_an_rgb_file_reads_opaque_and_one_channel_writes_as_grey(tmp_path):
    rgb = plate(0)[..., :3]
    morphfx.write_image(tmp_path / "rgb.exr", rgb)
    back = morphfx.read_image(tmp_path / "rgb.exr")
    assert np.array_equal(back[..., :3], rgb) and np.all(back[..., 3] == 1)
    grey = plate(0)[..., :1]
    morphfx.write_image(tmp_path / "grey.exr", grey)
    back = morphfx.read_image(tmp_path / "grey.exr")
    assert all(np.array_equal(back[..., c], grey[..., 0]) for c in range(4))


def test_8_bit_files_are_decoded_from_srgb_unless_raw(tmp_path):
    code = np.full((2, 2, 4), 128 / 255, np.float32)
    code[..., 3] = 1.0
    morphfx.write_image(tmp_path / "p.png", code, raw=True)
    linear = ((128 / 255 + 0.055) / 1.055) ** 2.4  # IEC 61966-2-1
    decoded = morphfx.read_image(tmp_path / "p.png")
    assert abs(decoded[0, 0, 0] - linear) < 1e-6 and decoded[0, 0, 3] == 1.0
    assert np.allclose(morphfx.read_image(tmp_path / "p.png", raw=True), code, atol=1e-7)
    # PNG stores colour straight; pictures hold it premultiplied, as the nodes take it.
    code[..., 3] = 0.4
    morphfx.write_image(tmp_path / "half.png", code * [0.4, 0.4, 0.4, 1.0], raw=True)
    back = morphfx.read_image(tmp_path / "half.png", raw=True)
    assert abs(back[0, 0, 0] - 0.4 * 128 / 255) < 2e-3 and abs(back[0, 0, 3] - 0.4) < 2e-3


def test_the_default_progress_and_frame_are_the_command_lines(files):
    scene = files / "field.morph.json"
    a, b = morphfx.read_image(files / "a.exr"), morphfx.read_image(files / "b.exr")
    assert np.array_equal(morphfx.morph(scene, a, b), morphfx.morph(scene, a, b, t=0.5))
    doc = json.loads(scene.read_text())
    lines = doc.pop("features")
    moved = [dict(l, b=[[x + 5, y] for x, y in l["b"]]) for l in lines]
    doc["keyframes"] = [{"frame": 7, "features": lines}, {"frame": 9, "features": moved}]
    keyed = morphfx.Scene.from_json(json.dumps(doc))
    at_first = morphfx.morph(keyed, a, b, t=0.5)
    assert np.array_equal(at_first, morphfx.morph(keyed, a, b, t=0.5, frame=7))
    assert not np.array_equal(at_first, morphfx.morph(keyed, a, b, t=0.5, frame=9))
    doc.pop("keyframes")
    doc["features"] = lines
    doc["progress"] = [[3, 0.0], [5, 1.0]]
    paced = morphfx.Scene.from_json(json.dumps(doc))
    assert np.array_equal(morphfx.morph(paced, a, b), morphfx.morph(paced, a, b, t=0.0))


def test_params_lists_what_the_command_line_lists(cli):
    for node in ["morph", "warp"]:
        listed = [l for l in cli("params", "--node", node).stdout.splitlines()
                  if not l.startswith("#")]
        assert morphfx.params(node) == listed
    with pytest.raises(morphfx.ParamError):
        morphfx.params("blur")


def test_a_tools_scratch_folder_goes_when_the_call_ends(tmp_path):
    import tempfile
    mine = f"morphfx-{os.getpid()}-"
    before = {p for p in os.listdir(tempfile.gettempdir()) if p.startswith(mine)}
    morphfx.suggest(shapes(320, 240), shapes(320, 240, 3.0), count=4)
    after = {p for p in os.listdir(tempfile.gettempdir()) if p.startswith(mine)}
    assert after == before


def test_the_error_classes_are_as_the_guide_says(cli, files, tmp_path):
    for name in ["SceneError", "ImageError", "ParamError", "RenderError"]:
        assert issubclass(getattr(morphfx, name), morphfx.Error)
    assert issubclass(morphfx.Error, Exception)
    scene = morphfx.Scene.load(files / "field.morph.json")
    with pytest.raises(morphfx.ParamError) as raised:
        morphfx.morph(scene, plate(0), plate(0), params={"mix": 2.0})
    done = cli("morph", "--scene", files / "field.morph.json", "--a", files / "a.exr",
               "--b", files / "b.exr", "--param", "mix=2.0", "-o", tmp_path / "o.exr",
               check=False)
    assert str(raised.value) == cli_error(done)
