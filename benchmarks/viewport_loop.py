"""The studio viewport's loop without Qt: what a photographer sees per second at a given viewport size.

The render worker (lenslab.gui.worker) does, per displayed frame: trace for a frame's time (a sixtieth of a
second), then make the picture: on the GPU (display.comp, RGBA8 read back) or, with the denoiser on, read back
the linear image and the albedo and normal guides, run Intel Open Image Denoise and show its result through the view transform on the
GPU (RenderSession.display_image). This script times
those steps at the viewport's size, framed as the viewport frames it (ThinLensCamera.view_frame), and prints:

* pictures per second and samples per pixel after N seconds, without the denoiser;
* the same with the denoiser run on every picture (the worst case; the worker runs it at most every 0.25 s),
  and the median cost of each part: tracing, reading back, denoising, the view transform.

Usage: python benchmarks/viewport_loop.py [--scene cornell_box] [--width 1920] [--height 1080] [--seconds 5]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from lenslab.render.tracer import Renderer, RenderSession
from lenslab.scene.io.loader import open_scene

FRAME_SECONDS = 1 / 60
VIEW_MARGIN = 0.04


def run(session: RenderSession, seconds: float, denoise) -> dict[str, list[float]]:
    times: dict[str, list[float]] = {"trace": [], "picture": [], "read back": [], "denoise": [], "tone map": []}
    session.reset()
    end = time.perf_counter() + seconds
    pictures = 0
    while time.perf_counter() < end:
        start = time.perf_counter()
        session.step(FRAME_SECONDS, None)
        times["trace"].append(time.perf_counter() - start)
        start = time.perf_counter()
        if denoise is None:
            session.display()
        else:
            t0 = time.perf_counter()
            image = session.image()
            albedo, normal = session.features_image()
            t1 = time.perf_counter()
            clean = denoise(image, albedo, normal)
            t2 = time.perf_counter()
            session.display_image(clean)
            t3 = time.perf_counter()
            times["read back"].append(t1 - t0)
            times["denoise"].append(t2 - t1)
            times["tone map"].append(t3 - t2)
        times["picture"].append(time.perf_counter() - start)
        pictures += 1
    times["pictures per second"] = [pictures / seconds]
    times["spp"] = [session.samples_per_pixel]
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="cornell_box")
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--no-denoise", action="store_true")
    args = parser.parse_args()

    renderer = Renderer()
    print(f"device: {renderer.describe()['renderer']}")
    scene = open_scene(args.scene)
    session = RenderSession(renderer, scene, width=args.width, height=args.height, dispatch_seconds=FRAME_SECONDS)
    session.set_feature_buffers(True)
    session.set_view(args.width, args.height, VIEW_MARGIN)
    session.step(0.0, 1)  # compile and warm up outside the figures
    plans = [("without the denoiser", None)]
    if not args.no_denoise:
        from lenslab.render.denoise import denoise, describe

        denoise(np.zeros((8, 8, 3), np.float32))  # make the device outside the figures
        print(f"denoiser: {describe()}")
        plans.append(("denoising every picture", denoise))
    for label, denoiser in plans:
        times = run(session, args.seconds, denoiser)
        parts = ", ".join(f"{name} {statistics.median(values) * 1000:.1f} ms" for name, values in times.items()
                          if values and name not in ("pictures per second", "spp"))
        print(f"{args.scene} {args.width} x {args.height}, {label}: {times['pictures per second'][0]:.1f} pictures/s, "
              f"{times['spp'][0]} spp after {args.seconds:g} s; medians: {parts}")
    session.release()
    renderer.release()


if __name__ == "__main__":
    main()
