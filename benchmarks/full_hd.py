"""Full-HD figures on this machine's GL device: what a photographer waits for at 1920 x 1080.

Printed, in one run:

* the Cornell box with its thin-lens depth of field: samples per second, and the seconds to N samples per
  pixel (default 1024) the way a headless render takes them (lenslab.render.job.RenderJob);
* the studio's progressive update at one sample per pixel: each update traces one more sample per pixel and
  then makes the picture the viewport shows, on the GPU (display.comp, as the render worker does) or, for
  comparison, on the CPU (read the float image back, resolve it and run the view transform on the CPU, as it did before);
  updates per second in all and the median time of each part;
* the million-triangle scene (scenes/marbles_on_sand): making the mesh and building its kd-tree, the kernel's
  first compile, and the seconds to 5 samples per pixel.

The targets for an NVIDIA GPU are printed beside the figures: 1024 spp of the Cornell box in
under 10 s, 5 spp of the million triangles in under 1 s, 60 or more updates per second.

Usage: python benchmarks/full_hd.py [--width 1920] [--height 1080] [--spp 1024] [--updates 60] [--save DIR]
       (--save writes each image as .npy, to compare a device's images with another's)
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from pathlib import Path

import numpy as np

from lenslab.render.film import display_pixels, resolve, to_8bit
from lenslab.render.job import RenderJob
from lenslab.render.tracer import Renderer, RenderSession
from lenslab.scene.io.loader import open_scene


def timed(function):
    start = time.perf_counter()
    result = function()
    return result, time.perf_counter() - start


def at_size(scene, width: int, height: int):
    return dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, resolution=(width, height)))


def cornell_to_spp(renderer, width: int, height: int, spp: int, save: Path | None) -> None:
    scene = at_size(open_scene("cornell_box"), width, height)
    warm = RenderSession(renderer, scene, width=64, height=64)  # compile the kernel outside the figure
    warm.step(0.0, 1)
    warm.release()
    job = RenderJob(renderer, scene, spp=spp)
    image, seconds = timed(job.run)
    rate = job.session.progress().samples_per_second
    job.release()
    print(f"cornell_box {width}x{height}: {spp} spp in {seconds:.2f} s, {rate / 1e6:.1f} M samples/s"
          f"   (target for a GPU: 1024 spp in under 10 s)")
    if save:
        np.save(save / f"cornell_box_{spp}spp.npy", image)


def progressive_updates(renderer, width: int, height: int, updates: int) -> None:
    scene = open_scene("cornell_box")
    session = RenderSession(renderer, scene, width=width, height=height)
    session.step(0.0, 1)  # compile and warm up
    session.display()

    def run(label: str, show) -> None:
        """``updates`` updates of one more sample per pixel each, then ``show`` (None: trace only)."""
        session.reset()
        parts: dict[str, list[float]] = {"trace 1 spp": []}
        start = time.perf_counter()
        for update in range(updates):
            _, seconds = timed(lambda: session.step(60.0, target_spp=update + 1))
            parts["trace 1 spp"].append(seconds)
            for name, seconds in (show() if show else {}).items():
                parts.setdefault(name, []).append(seconds)
        total = time.perf_counter() - start
        breakdown = ", ".join(f"{name} {statistics.median(seconds) * 1e3:.2f} ms" for name, seconds in parts.items())
        print(f"  {label:<34} {updates / total:7.1f} updates/s   (median: {breakdown})")

    def on_the_gpu() -> dict[str, float]:  # what the studio does now: display.comp, RGBA8 back
        _, seconds = timed(lambda: session.display())
        return {"display.comp and read back": seconds}

    def on_the_cpu() -> dict[str, float]:  # what the studio did before: float32 back, numpy per pixel
        accumulation, read_seconds = timed(session.accumulation)
        linear, resolve_seconds = timed(lambda: resolve(accumulation))
        _, tone_seconds = timed(lambda: to_8bit(display_pixels(linear)))
        return {"read back": read_seconds, "resolve": resolve_seconds, "view transform (OCIO, CPU) to 8 bit": tone_seconds}

    print(f"progressive update {width}x{height}, one sample per pixel each   (target for a GPU: 60 or more)")
    run("trace alone", None)
    run("trace, picture on the GPU", on_the_gpu)
    run("trace, picture on the CPU (numpy)", on_the_cpu)
    session.release()


def million_triangles(renderer, width: int, height: int, spp: int, save: Path | None) -> None:
    scene, load_seconds = timed(lambda: open_scene("marbles_on_sand"))
    session, build_seconds = timed(lambda: RenderSession(renderer, scene, width=width, height=height))
    _, first_seconds = timed(lambda: session.step(0.0, 1))  # the kernel's first compile, and one sample
    session.reset()
    _, seconds = timed(lambda: session.step(1e9, target_spp=spp))
    triangles = session.flat_scene.triangle_count
    if save:
        np.save(save / f"marbles_on_sand_{spp}spp.npy", session.image())
    session.release()
    print(f"marbles_on_sand {width}x{height} ({triangles:,} triangles): scene {load_seconds:.2f} s, mesh, kd-tree and upload "
          f"{build_seconds:.2f} s, first sample with compile {first_seconds:.2f} s; {spp} spp in {seconds:.3f} s"
          f"   (target for a GPU: 5 spp in under 1 s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    parser.add_argument("--spp", type=int, default=1024, help="of the Cornell box")
    parser.add_argument("--updates", type=int, default=60, help="progressive updates to time")
    parser.add_argument("--triangle-spp", type=int, default=5, help="of the million-triangle scene")
    parser.add_argument("--save", type=Path, help="a folder to write the images into, as .npy")
    args = parser.parse_args()
    if args.save:
        args.save.mkdir(parents=True, exist_ok=True)
    renderer = Renderer()
    device = renderer.describe()
    print(f"device: {device['renderer']} ({device['vendor']}), {device['version']}")
    cornell_to_spp(renderer, args.width, args.height, args.spp, args.save)
    progressive_updates(renderer, args.width, args.height, args.updates)
    million_triangles(renderer, args.width, args.height, args.triangle_spp, args.save)
    renderer.release()


if __name__ == "__main__":
    main()
