"""Shared fixtures: generated plates and scenes, and the `morphfx` command line.

`cargo xtask test` runs these with MORPHFX_CLI (a built `morphfx`) and
MORPHFX_BUNDLE (the bundle it renders) set: the module's pixels are held to
the command line's, which reaches the plugin through its own bundle.
"""

import json
import os
import subprocess

import numpy as np
import pytest

import morphfx

W, H = 96, 64


def plate(seed: int, w: int = W, h: int = H) -> np.ndarray:
    """A smooth, colourful, opaque plate (top row first)."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    rgb = [0.5 + 0.4 * np.sin(0.21 * x + 0.13 * y * (c + 1) + seed + c) for c in range(3)]
    return np.dstack(rgb + [np.ones_like(x)]).astype(np.float32)


def points(pairs):
    return [{"type": "point", "a": [list(a)], "b": [list(b)]} for a, b in pairs]


POINTS = points([((30, 20), (34, 24)), ((64, 24), (60, 20)), ((48, 44), (50, 40)),
                 ((20, 48), (22, 46)), ((76, 46), (72, 48))])
LINES = [
    {"type": "line", "a": [[20, 20], [70, 22]], "b": [[24, 16], [74, 26]]},
    {"type": "line", "a": [[30, 50], [60, 40]], "b": [[28, 46], [62, 44]]},
]


def scene_doc(method: str) -> dict:
    """A scene of `method` fitting the plates."""
    doc = {"format": "morphfx-scene", "version": 1, "method": method}
    if method == "field":
        doc["features"] = LINES
    elif method == "mesh":
        xs, ys = [0, 32, 64, 96], [0, 32, 64]
        a = [[x, y] for y in ys for x in xs]
        b = [list(p) for p in a]
        b[5] = [36, 28]
        b[6] = [60, 36]
        doc["mesh"] = {"rows": 3, "cols": 4, "a": a, "b": b}
    elif method == "auto":
        doc["auto"] = {"levels": 3}
    else:
        doc["features"] = POINTS
    return doc


METHODS = ["field", "mesh", "triangles", "thin-plate", "mffd", "hybrid", "auto"]


@pytest.fixture(scope="session")
def cli():
    """Runs `morphfx ARGS...` with the test bundle; returns the process."""
    exe, bundle = os.environ.get("MORPHFX_CLI"), os.environ.get("MORPHFX_BUNDLE")
    if not exe or not bundle:
        pytest.fail("MORPHFX_CLI and MORPHFX_BUNDLE must name morphfx and its bundle "
                    "(cargo xtask test sets them)")

    def run(*args, check=True):
        done = subprocess.run([exe, "--bundle", bundle, *map(str, args)],
                              capture_output=True, text=True)
        if check and done.returncode != 0:
            raise AssertionError(f"morphfx {' '.join(map(str, args))}: {done.stderr}")
        return done

    return run


@pytest.fixture(scope="session")
def files(tmp_path_factory):
    """Plates A and B as float EXRs, and a scene file per method."""
    d = tmp_path_factory.mktemp("plates")
    morphfx.write_image(d / "a.exr", plate(0))
    morphfx.write_image(d / "b.exr", plate(2))
    for m in METHODS:
        (d / f"{m}.morph.json").write_text(json.dumps(scene_doc(m)))
    return d


def cli_error(done) -> str:
    """The message of a failed command line: its `morphfx: error: ` line."""
    assert done.returncode == 2, done.stderr
    lines = [l for l in done.stderr.splitlines() if l.startswith("morphfx: error: ")]
    return lines[-1][len("morphfx: error: "):]


