"""OpenCV's pyramidal Lucas-Kanade, frame to frame, on the line-tracking
test shot: the peer docs/tracking.md reports beside MorphFX's tracker.

    MORPHFX_TRACK_DUMP=DIR cargo test -p morphfx-harness --test track_lines bends
    python3 -m venv v && v/bin/pip install opencv-python-headless numpy
    v/bin/python benches/lk_peer.py DIR

The test writes the frames as 8-bit grey PNGs (Rec. 709 luminance of the
float frames MorphFX tracks, a 1/2.2 gamma: LK takes 8-bit images), and every keyed position is
tracked from frame to frame (21 x 21 window, 3 levels, OpenCV's defaults
otherwise). Errors against the true positions, as the Rust test scores them.
"""
import json
import os
import sys

import cv2
import numpy as np


def main(folder):
    shot = json.load(open(os.path.join(folder, "shot.json")))
    h, truth = shot["height"], np.array(shot["truth"])
    # Canonical (y up, pixel centres at +0.5) to OpenCV's (y down, at 0).
    to_cv = lambda p: np.stack([p[:, 0] - 0.5, h - p[:, 1] - 0.5], axis=1)
    from_cv = lambda p: np.stack([p[:, 0] + 0.5, h - 0.5 - p[:, 1]], axis=1)
    frames = [
        cv2.imread(os.path.join(folder, f"frame.{f:04d}.png"), cv2.IMREAD_GRAYSCALE)
        for f in range(len(truth))
    ]
    at = to_cv(truth[0]).astype(np.float32).reshape(-1, 1, 2)
    errors, lost = [], 0
    for f in range(1, len(frames)):
        at, status, _ = cv2.calcOpticalFlowPyrLK(
            frames[f - 1], frames[f], at, None, winSize=(21, 21), maxLevel=3
        )
        lost += int((status == 0).sum())
        errors.extend(np.linalg.norm(from_cv(at.reshape(-1, 2)) - truth[f], axis=1))
    e = np.sort(np.array(errors))
    pick = lambda q: e[int(round((len(e) - 1) * q))]
    print(
        f"OpenCV {cv2.__version__} pyramidal LK, frame to frame: {len(e)} positions: "
        f"median {pick(0.5):.3f} px, 90 % {pick(0.9):.3f} px, worst {e[-1]:.3f} px, "
        f"{lost} flagged"
    )


if __name__ == "__main__":
    main(sys.argv[1])
