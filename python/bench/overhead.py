"""What a 1080p morph costs through Python beyond the plugin's own render.

    python python/bench/overhead.py [--frames N]

Renders a 1920x1080 morph (field method, 24 line pairs, float RGBA plates)
N times with `morphfx.morph`, and prints the median time of the whole call
beside the median time the plugin's render took in it
(`morphfx.last_render_seconds()`): the difference is the module's overhead
(taking the arrays, setting up the node, handing the picture back).
"""

import argparse
import json
import statistics
import time

import numpy as np

import morphfx

W, H = 1920, 1080


def plate(seed):
    y, x = np.mgrid[0:H, 0:W].astype(np.float32)
    rgb = [0.5 + 0.4 * np.sin(0.013 * x + 0.021 * y * (c + 1) + seed + c) for c in range(3)]
    return np.dstack(rgb + [np.ones_like(x)]).astype(np.float32)


def scene():
    rng = np.random.default_rng(7)
    features = []
    for _ in range(24):
        ax, ay = rng.uniform(200, 1700), rng.uniform(150, 930)
        dx, dy = rng.uniform(-40, 40, 2)
        length = rng.uniform(60, 200)
        features.append({"type": "line", "a": [[ax, ay], [ax + length, ay + 10]],
                         "b": [[ax + dx, ay + dy], [ax + dx + length, ay + dy + 10]]})
    return morphfx.Scene.from_json(json.dumps(
        {"format": "morphfx-scene", "version": 1, "method": "field", "features": features}))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, default=9)
    args = parser.parse_args()
    s, a, b = scene(), plate(0), plate(2)
    morphfx.morph(s, a, b, t=0.5)  # warm: the bundle loaded, caches filled
    calls, renders = [], []
    for k in range(args.frames):
        started = time.perf_counter()
        morphfx.morph(s, a, b, t=0.3 + 0.4 * k / args.frames)
        calls.append(time.perf_counter() - started)
        renders.append(morphfx.last_render_seconds())
    call, render = statistics.median(calls), statistics.median(renders)
    print(f"1080p morph through Python: {call * 1000:.1f} ms a call, the plugin's render "
          f"{render * 1000:.1f} ms: overhead {100 * (call - render) / render:.1f} %")


if __name__ == "__main__":
    main()
