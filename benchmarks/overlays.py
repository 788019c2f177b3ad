"""What the viewport's judging aids cost per picture: focus peaking, the histogram and the clipping masks
(lenslab.optics.peaking and .histogram), on a synthetic picture and depth buffer of each size.

Prints, for each size, milliseconds of CPU time (process time, so that other work on the machine does not count)
per call, the median of --repeat calls: peaking without and with the veil of a blurred foreground (the depth
ramp puts a third of the picture in front of the depth of field), the histogram, the clipping masks. The studio
works each one out at most four times a second.

Usage: python benchmarks/overlays.py [--sizes 800x600 1600x900 3840x2160] [--repeat 20]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from lenslab.optics.histogram import clipping_masks, histogram
from lenslab.optics.peaking import peaking_mask


def picture_and_depth(width: int, height: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Noise over soft gradients, RGBA8, and a depth ramp from 0.5 to 10 m with a background strip."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    base = 127 + 100 * np.sin(x / 37.0)[..., None] * np.cos(y / 23.0)[..., None]
    rgb = np.clip(base + rng.normal(0, 12, (height, width, 3)), 0, 255)
    rgba = np.concatenate([rgb, np.full((height, width, 1), 255.0)], axis=2).astype(np.uint8)
    depth = (0.5 + 9.5 * x / width).astype(np.float32)
    depth[: height // 10] = np.inf
    return rgba, depth


def cpu_ms(call, repeat: int) -> float:
    call()  # warm up
    times = []
    for _ in range(repeat):
        start = time.process_time()
        call()
        times.append(time.process_time() - start)
    return 1000 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", nargs="+", default=["800x600", "1600x900", "3840x2160"])
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    print(f"{'size':>11}  {'peaking':>9}  {'+ veil':>9}  {'histogram':>9}  {'clipping':>9}   (ms of CPU per picture)")
    for size in args.sizes:
        width, height = (int(v) for v in size.lower().split("x"))
        rgba, depth = picture_and_depth(width, height)
        figures = (cpu_ms(lambda: peaking_mask(rgba, depth, 2.0, 4.0), args.repeat),
                   cpu_ms(lambda: peaking_mask(rgba, depth, 2.0, 4.0, coc_px=1.5), args.repeat),
                   cpu_ms(lambda: histogram(rgba), args.repeat),
                   cpu_ms(lambda: clipping_masks(rgba), args.repeat))
        print(f"{size:>11}  " + "  ".join(f"{f:9.1f}" for f in figures), flush=True)


if __name__ == "__main__":
    main()
