"""What a real lens costs: camera samples through the glass against the thin lens of the same focal length and
f-number, on this machine's GL device, and the time to build a lens's exit-pupil table.

For each shipped real lens, the same scene is rendered through the thin lens and through the glass, in turns
(thin, real, thin, real, ...), and the median rate of each is printed with their ratio: these machines are
shared and noisy, so only ratios taken in one run are worth comparing. Two path lengths: max depth 1 (camera
rays and their first hit: where the camera's share of the work is largest) and the scene's own (what a user
waits for). "useful" is the rate of samples that get through the glass (the pupil table's waste taken out).

Usage: python benchmarks/real_lens.py [--scene cornell_box] [--size 192] [--seconds 2] [--rounds 3]
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from render_throughput import samples_per_second  # noqa: E402

from lenslab.optics.lenses import load_lens_presets  # noqa: E402
from lenslab.optics.real_lenses import system_for  # noqa: E402
from lenslab.render.tracer import Renderer  # noqa: E402
from lenslab.scene.io.loader import open_scene  # noqa: E402


def with_camera(scene, **fields):
    return dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, **fields))


def through_fraction(camera, size: int, samples: int = 20000) -> float:
    """The share of camera samples that get through the glass (the rest fall where the pupil's box is empty)."""
    frame = camera.frame(size, size)
    rng = np.random.default_rng(1)
    pixels = rng.random((samples, 2)) * size
    _, _, weights = frame.rays(pixels, rng.random((samples, 2)), with_weights=True)
    return float((weights.max(axis=1) > 0).mean())


def pupil_table_seconds(lens, repeats: int = 5) -> float:
    system = system_for(lens.prescription)
    times = []
    for i in range(repeats):  # a new focus each time: nothing kept from the last
        start = time.perf_counter()
        setting = system.setting(lens.widest_f_number, 3000.0 + 100.0 * i, (36.0, 24.0))
        setting.pupil_bounds
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="cornell_box")
    parser.add_argument("--size", type=int, default=192)
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    lenses = [lens for lens in load_lens_presets() if lens.is_real]
    start = time.perf_counter()
    system_for(lenses[0].prescription).setting(lenses[0].widest_f_number, 2000.0, (36.0, 24.0)).pupil_bounds
    first_table = time.perf_counter() - start
    renderer = Renderer()
    device = renderer.describe()
    scene = open_scene(args.scene)
    print(f"device: {device['renderer']}, {device['version']}; scene {args.scene}, {args.size}x{args.size}, "
          f"{args.seconds:g} s per figure, median of {args.rounds} rounds")
    print(f"first pupil table in this process (numba's cached code loaded): {first_table * 1000:.0f} ms")
    print(f"\n{'lens':<24} {'depth':>5} {'thin Ms/s':>10} {'real Ms/s':>10} {'cost':>6} {'through':>8} "
          f"{'useful cost':>12} {'table ms':>9}")
    for lens in lenses:
        table_ms = pupil_table_seconds(lens) * 1000
        for depth in (1, scene.render.max_depth):
            base = dataclasses.replace(scene, render=dataclasses.replace(scene.render, max_depth=depth))
            thin = with_camera(base, focal_length_mm=lens.focal_length_mm, f_number=lens.widest_f_number,
                               real_lens="")
            real = with_camera(base, **lens.mount(lens.focal_length_mm, lens.widest_f_number))
            rates = {"thin": [], "real": []}
            for _ in range(args.rounds):
                rates["thin"].append(samples_per_second(renderer, thin, args.size, args.seconds))
                rates["real"].append(samples_per_second(renderer, real, args.size, args.seconds))
            thin_rate, real_rate = statistics.median(rates["thin"]), statistics.median(rates["real"])
            through = through_fraction(real.camera, args.size)
            cost = thin_rate / real_rate
            print(f"{lens.name:<24} {depth:>5} {thin_rate / 1e6:>10.3f} {real_rate / 1e6:>10.3f} {cost:>6.2f} "
                  f"{through:>8.2f} {cost / through if through else math.inf:>12.2f} {table_ms:>9.1f}")
    renderer.release()


if __name__ == "__main__":
    main()
