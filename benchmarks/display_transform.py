"""What the view transform costs: the studio's picture through OpenColorIO's GLSL on the GPU (display.comp) for
each kind of view, against the same transform on OCIO's CPU processor (what an export does), at one size.

    python benchmarks/display_transform.py [--width 1920 --height 1080]

Prints the median milliseconds per picture (including reading the RGBA8 back) and the ratio to the CPU's. Run it
on llvmpipe and on a GPU: the GPU's figure is the one the studio lives with.
"""

from __future__ import annotations

import argparse
import statistics
import time

from lenslab.colour_management.view import ViewTransform
from lenslab.render.film import display_pixels, resolve, to_8bit
from lenslab.render.tracer import Renderer, RenderSession
from lenslab.scene.io.loader import open_scene

VIEWS = {
    "ACES 2.0 SDR (sRGB)": ViewTransform(),
    "Un-tone-mapped (sRGB)": ViewTransform(view="Un-tone-mapped"),
    "ACES 2.0 SDR (Display P3) + gamut look": ViewTransform(display="Display P3 - Display",
                                                            looks="ACES 1.3 Reference Gamut Compression"),
}


def median_ms(run, repeats: int) -> float:
    run()  # the first call compiles the shader or builds the processor
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=960)
    parser.add_argument("--height", type=int, default=540)
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
    renderer = Renderer()
    session = RenderSession(renderer, open_scene("cornell_box"), width=args.width, height=args.height)
    session.step(0.0, target_spp=1)
    linear = resolve(session.accumulation())  # pixels the first pass has not reached yet are black
    print(f"{renderer.describe().get('renderer', '')}: {args.width} x {args.height}, median of {args.repeats}")
    for name, view in VIEWS.items():
        gpu = median_ms(lambda: session.display(view), args.repeats)
        cpu = median_ms(lambda: to_8bit(display_pixels(linear, view)), max(3, args.repeats // 3))
        print(f"  {name:<42} GPU {gpu:8.2f} ms   CPU {cpu:8.2f} ms   ({cpu / gpu:5.1f}x)")
    session.release()
    renderer.release()


if __name__ == "__main__":
    main()
