"""The peer of the core's resample and morph benches: OpenCV's remap on the
same reverse maps (written by `MORPHFX_MAP_DUMP=DIR cargo bench ... --bench
core -- resample_1080p_rgba_f32/bilinear morph_frame`), 1080p RGBA float32,
clamped edges, as a host's plate would be resampled.

    python benches/remap_peer.py DIR

Prints the median and the fastest of 30 runs of each, in milliseconds (on a
shared machine the fastest is the steadier figure): each into output
arrays made beforehand (`dst=`), as our kernels write into the buffer a
host lends them (the peer figure), and into fresh arrays as a plain call
makes them (which adds the kernel's page faults on 33 MB per array).
It also says whether numpy asked the kernel for 2 MB pages for the arrays
(its default where Linux offers them on request), which our bench's
buffers do not get in that mode. Measuring only:
the project does not depend on OpenCV (pip install opencv-python-headless
numpy in a scratch environment).
"""

import sys
import time

import cv2
import numpy as np

W, H = 1920, 1080


def load(path):
    m = np.fromfile(path, dtype="<f4").reshape(H, W, 2)
    return np.ascontiguousarray(m[..., 0]), np.ascontiguousarray(m[..., 1])


def plate(seed):
    y, x = np.mgrid[0:H, 0:W].astype(np.float32)
    img = np.empty((H, W, 4), np.float32)
    for c in range(3):
        img[..., c] = 0.5 + 0.5 * np.sin((x * 0.05 + seed) * (c + 1)) * np.cos(y * 0.031)
    img[..., 3] = 1.0
    return img


def numpy_huge_pages():
    """Whether numpy asks for 2 MB pages for its large arrays, in words."""
    try:
        from numpy._core.multiarray import _set_madvise_hugepage
    except ImportError:
        try:
            from numpy.core.multiarray import _set_madvise_hugepage
        except ImportError:
            return "unknown"
    on = _set_madvise_hugepage(True)
    _set_madvise_hugepage(on)
    return "asked" if on else "not asked"


class Timed:
    """Median and fastest of `runs` calls, in milliseconds."""

    def __init__(self, f, runs=30):
        f()
        times = []
        for _ in range(runs):
            t = time.perf_counter()
            f()
            times.append(time.perf_counter() - t)
        times.sort()
        self.median, self.fastest = 1000 * times[len(times) // 2], 1000 * times[0]

    def __format__(self, spec):
        return f"{self.median:.2f} ms (fastest {self.fastest:.2f})"


def main(directory):
    ax, ay = load(f"{directory}/map_a.f32")
    bx, by = load(f"{directory}/map_b.f32")
    a, b = plate(0.0), plate(1.7)
    border = cv2.BORDER_REPLICATE
    wa, wb = np.empty_like(a), np.empty_like(b)
    out = np.empty_like(a)
    for name, interp in [("bilinear", cv2.INTER_LINEAR), ("bicubic", cv2.INTER_CUBIC)]:
        remap_a = lambda dst=None: cv2.remap(a, ax, ay, interp, dst=dst, borderMode=border)
        remap_b = lambda dst=None: cv2.remap(b, bx, by, interp, dst=dst, borderMode=border)
        print(f"remap {name}: {Timed(lambda: remap_a(wa))}"
              f"; fresh arrays: {Timed(remap_a)}")

        def morph_into():
            remap_a(wa)
            remap_b(wb)
            cv2.addWeighted(wa, 0.63, wb, 0.37, 0.0, dst=out)

        def morph_fresh():
            return cv2.addWeighted(remap_a(), 0.63, remap_b(), 0.37, 0.0)

        print(f"2 x remap + addWeighted {name}: {Timed(morph_into)}"
              f"; fresh arrays: {Timed(morph_fresh)}")
    print(f"threads: {cv2.getNumThreads()}; "
          f"numpy's arrays on huge pages: {numpy_huge_pages()}")


if __name__ == "__main__":
    main(sys.argv[1])
