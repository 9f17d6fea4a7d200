"""Scenes, images, errors and threads: the module's own promises."""

import json
import os
import struct
import threading
import zlib

import numpy as np
import pytest

import morphfx
from conftest import W, H, cli_error, plate, scene_doc


def test_a_scene_round_trips_and_says_what_it_holds(files):
    scene = morphfx.Scene.load(files / "field.morph.json")
    assert scene.method == "field"
    assert scene.features == scene_doc("field")["features"]
    assert scene.keyframes == []
    again = morphfx.Scene.from_json(scene.to_json())
    assert json.loads(again.to_json()) == scene_doc("field")
    moved = scene.with_("features", [dict(f, b=[[x + 1, y] for x, y in f["b"]])
                                     for f in scene.features])
    assert moved.features[0]["b"][0] == [25, 16]
    assert scene.features[0]["b"][0] == [24, 16], "with_ makes a copy"
    assert "method=field" in repr(scene)


def test_a_bad_scene_raises_scene_error_with_the_command_lines_message(cli, tmp_path):
    bad = tmp_path / "bad.morph.json"
    bad.write_text(json.dumps({"format": "morphfx-scene", "version": 1, "method": "field"}))
    with pytest.raises(morphfx.SceneError) as raised:
        morphfx.Scene.load(bad)
    done = cli("morph", "--scene", bad, "--a", "x.exr", "--b", "y.exr", "-o",
               tmp_path / "o.exr", check=False)
    assert str(raised.value) == cli_error(done)
    assert isinstance(raised.value, morphfx.Error)
    with pytest.raises(morphfx.SceneError, match="scene text"):
        morphfx.Scene.from_json("{")
    with pytest.raises(TypeError):
        morphfx.Scene()  # scenes come from files or text, validated


def test_images_round_trip_exactly_with_row_0_at_the_top(tmp_path):
    picture = plate(1)
    picture[0, :, :3] = 7.5  # HDR values survive a float EXR
    morphfx.write_image(tmp_path / "p.exr", picture)
    back = morphfx.read_image(tmp_path / "p.exr")
    assert back.dtype == np.float32 and back.shape == (H, W, 4)
    assert np.array_equal(back, picture)
    half = tmp_path / "h.exr"
    morphfx.write_image(half, picture, half=True, compression="piz")
    assert np.abs(morphfx.read_image(half) - picture).max() < 4e-3


def png_rows(path):
    """The rows of an 8-bit RGBA PNG, decoded here from the format itself
    (chunks, zlib, the five row filters), as bytes without the filter byte."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width = 8, b"", None
    while pos < len(data):
        (n,), kind = struct.unpack(">I", data[pos:pos + 4]), data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            width, _, depth, colour = struct.unpack(">IIBB", body[:10])
            assert (depth, colour) == (8, 6), "8-bit RGBA"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw, stride, bpp = zlib.decompress(idat), 4 * width, 4
    rows, prior = [], bytes(stride)
    for k in range(len(raw) // (stride + 1)):
        kind, line = raw[k * (stride + 1)], raw[k * (stride + 1) + 1:(k + 1) * (stride + 1)]
        out = bytearray(stride)
        for i in range(stride):
            left = out[i - bpp] if i >= bpp else 0
            up, corner = prior[i], prior[i - bpp] if i >= bpp else 0
            if kind == 4:
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                guess = left if pa <= pb and pa <= pc else up if pb <= pc else corner
            else:
                guess = [0, left, up, (left + up) // 2][kind]
            out[i] = (line[i] + guess) & 0xFF
        rows.append(bytes(out))
        prior = bytes(out)
    return rows


def test_row_0_is_the_first_row_a_png_stores(tmp_path):
    picture = np.zeros((4, 5, 4), np.float32)
    picture[..., 3] = 1
    picture[0] = [1, 1, 1, 1]
    morphfx.write_image(tmp_path / "top.png", picture, raw=True)
    rows = png_rows(tmp_path / "top.png")
    assert set(rows[0]) == {255}, "the white row is stored first"
    assert rows[1][:4] == bytes([0, 0, 0, 255])
    assert np.array_equal(morphfx.read_image(tmp_path / "top.png", raw=True), picture)


def test_pictures_of_another_type_or_layout_are_converted():
    a64 = plate(0).astype(np.float64)
    flipped = np.ascontiguousarray(plate(2)[::-1])[::-1]  # a strided view
    scene = morphfx.Scene.from_json(json.dumps(scene_doc("field")))
    assert np.array_equal(morphfx.morph(scene, a64, flipped, t=0.5),
                          morphfx.morph(scene, plate(0), plate(2), t=0.5))
    rgb = plate(0)[..., :3]
    opaque = morphfx.warp(scene, rgb, t=0.5)
    assert opaque.shape == (H, W, 4) and np.all(opaque[..., 3] == 1)


def test_bad_pictures_and_params_raise_their_errors(cli, files, tmp_path):
    scene = morphfx.Scene.load(files / "field.morph.json")
    a = plate(0)
    with pytest.raises(morphfx.ImageError, match=r"shape \(64, 96, 2\)"):
        morphfx.morph(scene, a, a[..., :2])
    with pytest.raises(morphfx.ImageError, match="size mismatch"):
        morphfx.morph(scene, a, plate(0, 50, 40))
    with pytest.raises(morphfx.ImageError, match="no such file"):
        morphfx.read_image(tmp_path / "missing.exr")
    with pytest.raises(morphfx.ParamError, match="one of"):
        morphfx.write_image(tmp_path / "x.exr", a, compression="lzma")
    for params, option in [({"filter": "sharpest"}, "filter=sharpest"),
                           ({"mix": 2.0}, "mix=2.0"),
                           ({"no_such_param": 1}, "no_such_param=1"),
                           ({"field_a": 0.2}, "field_a=0.2")]:
        with pytest.raises(morphfx.ParamError) as raised:
            morphfx.morph(scene, a, a, params=params)
        done = cli("morph", "--scene", files / "field.morph.json", "--a", files / "a.exr",
                   "--b", files / "b.exr", "--param", option, "-o", tmp_path / "o.exr",
                   check=False)
        assert str(raised.value) == cli_error(done)
    with pytest.raises(morphfx.ParamError, match="view"):
        morphfx.morph(scene, a, a, view="sideways")
    with pytest.raises(morphfx.ParamError, match=r"t 1.5: must be in \[0, 1\]"):
        morphfx.morph(scene, a, a, t=1.5)
    with pytest.raises(morphfx.ParamError):
        morphfx.stmap(scene, "c", 0.5, W, H)


def test_renders_from_many_threads_at_once_equal_renders_one_by_one():
    scenes = [morphfx.Scene.from_json(json.dumps(scene_doc(m)))
              for m in ["field", "thin-plate", "triangles", "mesh"]]
    jobs = [(s, t) for s in scenes for t in (0.25, 0.75)]
    alone = [morphfx.morph(s, plate(0), plate(2), t=t) for s, t in jobs]
    together = [None] * len(jobs)

    def render(k):
        s, t = jobs[k]
        together[k] = morphfx.morph(s, plate(0), plate(2), t=t)

    threads = [threading.Thread(target=render, args=(k,)) for k in range(len(jobs))]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for k, (x, y) in enumerate(zip(alone, together)):
        assert np.array_equal(x, y), jobs[k][1]


def test_the_gil_is_released_while_rendering():
    """A render on one thread lets Python run on another: were the GIL
    held, this thread would not run one bytecode until the render returned."""
    scene = morphfx.Scene.from_json(json.dumps(scene_doc("auto")))
    big_a, big_b = plate(0, 512, 384), plate(2, 512, 384)
    started, ticks = threading.Event(), []

    def render():
        started.set()
        morphfx.morph(scene, big_a, big_b, t=0.5)

    th = threading.Thread(target=render)
    th.start()
    started.wait()
    while th.is_alive():
        ticks.append(1)
    th.join()
    assert len(ticks) > 1000, f"{len(ticks)} ticks beside the render"


def test_a_render_keeps_nothing_of_the_one_before(files):
    """Renders reuse node instances: params, keys, mattes and views of one
    call must not reach the next."""
    scene = morphfx.Scene.load(files / "field.morph.json")
    a, b = plate(0), plate(2)
    first = morphfx.morph(scene, a, b, t=0.4)
    mask = plate(5)
    morphfx.morph(scene, a, b, t=0.9, frame=3, view="ghost", mask=mask, timing=mask,
                  params={"filter": "bicubic", "mix": {0: 0.2, 9: 0.9}, "edge": "black"})
    morphfx.warp(scene, a, t=0.1, params={"mix": 0.3}, mask=mask)
    assert np.array_equal(morphfx.morph(scene, a, b, t=0.4), first)


def test_a_failed_render_raises_and_the_next_one_renders(files):
    """The plugin fails this render after it has fetched the pictures: the
    error is raised, the pictures are let go, and rendering goes on."""
    far = json.loads((files / "thin-plate.morph.json").read_text())
    far["features"][0]["a"] = [[500.0, 20.0]]
    scene = morphfx.Scene.from_json(json.dumps(far))
    with pytest.raises(morphfx.RenderError, match="outside the frame"):
        morphfx.morph(scene, plate(0), plate(2), t=0.5)
    good = morphfx.Scene.load(files / "thin-plate.morph.json")
    assert morphfx.morph(good, plate(0), plate(2), t=0.5).shape == (H, W, 4)


def test_threads_that_render_first_all_at_once_finish(tmp_path):
    """The module loads its plugin on first use: threads that all start
    there at once must each get it, none waiting on another for ever."""
    import subprocess
    import sys
    script = tmp_path / "first.py"
    script.write_text(
        "import threading, numpy as np, morphfx, json\n"
        f"scene = morphfx.Scene.from_json({json.dumps(json.dumps(scene_doc('field')))})\n"
        "a = np.zeros((64, 96, 4), np.float32)\n"
        "out = []\n"
        "def go():\n"
        "    out.append(morphfx.morph(scene, a, a, t=0.5).shape)\n"
        "ts = [threading.Thread(target=go) for _ in range(16)]\n"
        "[t.start() for t in ts]\n"
        "[t.join() for t in ts]\n"
        "print(len(out))\n")
    for _ in range(5):  # a race: several fresh processes give it its chances
        done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                              timeout=60)
        assert done.returncode == 0 and done.stdout.strip() == "16", done.stderr


def test_the_fast_build_renders_where_the_cpu_runs_it():
    """The module carries the plugin's x86-64-v3 build beside its own, and
    hands renders to it on a CPU with AVX2 and FMA, as the bundle does;
    MORPHFX_CPU=baseline keeps the baseline build."""
    import platform
    import subprocess
    import sys
    flags = ""
    if platform.machine() == "x86_64":
        with open("/proc/cpuinfo") as f:
            flags = next((l for l in f if l.startswith("flags")), "")
    fast = {"avx2", "fma"} <= set(flags.split())
    expected = "x86-64-v3 build with AVX2 and FMA" if fast else "baseline x86-64 build"
    assert morphfx.build() == expected
    done = subprocess.run([sys.executable, "-c", "import morphfx; print(morphfx.build())"],
                          capture_output=True, text=True, env={**os.environ,
                                                               "MORPHFX_CPU": "baseline"})
    assert done.stdout.strip() == "baseline x86-64 build", done.stderr
