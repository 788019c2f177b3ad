"""Path-tracing throughput of the shipped scenes on this machine's GL device.

Prints samples per second for each scene and path length, the Sobol sampler's cost relative to
independent random numbers, and what splatting a gaussian pixel filter costs against a box filter, measured
in one run (ratios are what to compare across machines: these are shared and noisy). Usage: python benchmarks/render_throughput.py [--seconds 3] [--size 192]
"""

from __future__ import annotations

import argparse
import dataclasses
import time

from lenslab.render.tracer import Renderer, RenderSession
from lenslab.scene.io.loader import open_scene


def samples_per_second(renderer, scene, size: int, seconds: float) -> float:
    session = RenderSession(renderer, scene, width=size, height=size, dispatch_seconds=0.25)
    session.step(0.0, 1)  # compile and warm up, excluded from the figure
    start, traced = time.perf_counter(), session.progress().samples_per_second * session.elapsed_seconds
    session.step(seconds)
    rate = (session.progress().samples_per_second * session.elapsed_seconds - traced) / (time.perf_counter() - start)
    session.release()
    return rate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--size", type=int, default=192)
    args = parser.parse_args()
    renderer = Renderer()
    device = renderer.describe()
    print(f"device: {device['renderer']}, {device['version']}, image {args.size}x{args.size}, {args.seconds:g} s per figure")
    print(f"{'scene':<12} {'max_depth':>9} {'sobol Msamples/s':>17} {'independent':>12} {'sobol/indep':>12}")
    for name in ("cornell_box", "dof_chart"):
        scene = open_scene(name)
        for depth in (1, 2, scene.render.max_depth):
            rates = {}
            for sampler in ("sobol", "independent"):
                settings = dataclasses.replace(scene.render, max_depth=depth, sampler=sampler)
                rates[sampler] = samples_per_second(renderer, dataclasses.replace(scene, render=settings), args.size, args.seconds)
            print(f"{name:<12} {depth:>9} {rates['sobol'] / 1e6:>17.3f} {rates['independent'] / 1e6:>12.3f} "
                  f"{rates['sobol'] / rates['independent']:>12.2f}")
    print(f"\n{'scene':<12} {'max_depth':>9} {'box Msamples/s':>15} {'gaussian splat':>15} {'splat/box':>10}")
    for name in ("cornell_box", "dof_chart"):
        scene = open_scene(name)
        for depth in (2, scene.render.max_depth):
            rates = {}
            for pixel_filter in ("box", "gaussian"):
                settings = dataclasses.replace(scene.render, max_depth=depth, pixel_filter=pixel_filter)
                rates[pixel_filter] = samples_per_second(renderer, dataclasses.replace(scene, render=settings), args.size,
                                                         args.seconds)
            print(f"{name:<12} {depth:>9} {rates['box'] / 1e6:>15.3f} {rates['gaussian'] / 1e6:>15.3f} "
                  f"{rates['gaussian'] / rates['box']:>10.2f}")
    renderer.release()


if __name__ == "__main__":
    main()
