"""Shots per minute of `lenslab batch` on this machine: one process without Dask, and Dask with 1 and 2 workers.

An aperture bracket of the shipped Cornell box (every shot its own image) is rendered three ways in one run:
in this process one shot after another (RenderJob, no engine), then through `run_batch` on a LocalCluster of
one worker and of two. Prints shots per minute for each, the engine's cost per shot (one Dask worker against no
engine), the cluster's start-up, and one shot split across two workers against the same shot on one worker. Usage:
python benchmarks/batch_scaling.py [--shots 8] [--size 96] [--spp 16] [--rounds 1]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from lenslab.batch.spec import read_batch


def bracket(folder: Path, shots: int, size: int, spp: int, split: int = 1) -> list:
    stops = [1.4 * 2 ** (k / 2) for k in range(shots)]  # a half-stop bracket from f/1.4
    (folder / "shots.toml").write_text(
        f'[[shots]]\nscene = "cornell_box"\noutput = "f{{f_number:.2f}}.exr"\nwidth = {size}\nspp = {spp}\n'
        f"split = {split}\nf_number = [{', '.join(f'{n:.4f}' for n in stops)}]\n")
    return list(read_batch(folder / "shots.toml").shots)


def in_process(shots) -> float:
    """Seconds to render and write every shot here, one after another, as `lenslab SCENE --headless` would."""
    from lenslab.render.job import OFFLINE_DISPATCH_SECONDS, RenderJob
    from lenslab.render.tracer import Renderer

    start = time.perf_counter()
    renderer = Renderer()
    for shot in shots:
        job = RenderJob(renderer, shot.open_scene(), spp=shot.overrides.spp,
                        dispatch_seconds=OFFLINE_DISPATCH_SECONDS)
        job.run()
        job.write(shot.output)
        job.release()
    renderer.release()
    return time.perf_counter() - start


def on_cluster(shots, workers: int) -> tuple[float, float]:
    """(seconds to start the cluster, seconds to render and write every shot on it)."""
    from distributed import Client

    from lenslab.batch.farm import local_cluster, run_batch

    start = time.perf_counter()
    with local_cluster(workers) as cluster, Client(cluster) as client:
        client.wait_for_workers(workers)
        started = time.perf_counter()
        summary = run_batch(shots, client, force=True)
        finished = time.perf_counter()
    assert summary.ok, summary.failed
    return started - start, finished - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", type=int, default=8)
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--rounds", type=int, default=1, help="repeat the measurements, interleaved")
    args = parser.parse_args()
    print(f"{os.cpu_count()} CPU cores; {args.shots} shots of the Cornell box, {args.size} px wide, {args.spp} spp "
          f"(the first run of each compiles the kernel; Mesa's shader cache then keeps it)")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        shots = bracket(folder, args.shots, args.size, args.spp)
        in_process(shots[:1])  # warm Mesa's shader cache so that no column pays the compile alone
        rows = {"no engine (this process)": [], "Dask, 1 worker": [], "Dask, 2 workers": []}
        startups = {1: [], 2: []}
        for _ in range(args.rounds):
            rows["no engine (this process)"].append(in_process(shots))
            for workers in (1, 2):
                startup, seconds = on_cluster(shots, workers)
                startups[workers].append(startup)
                rows[f"Dask, {workers} worker{'s' if workers > 1 else ''}"].append(seconds)
        best = {name: min(times) for name, times in rows.items()}
        print(f"\n{'':<26} {'seconds':>8} {'shots/min':>10} {'x no engine':>12}")
        for name, seconds in best.items():
            print(f"{name:<26} {seconds:>8.2f} {60 * args.shots / seconds:>10.1f} "
                  f"{best['no engine (this process)'] / seconds:>12.2f}")
        overhead = (best["Dask, 1 worker"] - best["no engine (this process)"]) / args.shots
        print(f"\nengine cost per shot (1 worker against no engine): {overhead * 1000:.0f} ms")
        print(f"cluster start-up: {min(startups[1]):.2f} s (1 worker), {min(startups[2]):.2f} s (2 workers)")

        heavy = args.spp * 8
        one = bracket(folder, 1, args.size * 2, heavy, split=1)
        two = bracket(folder, 1, args.size * 2, heavy, split=2)
        whole = min(on_cluster(one, 1)[1] for _ in range(args.rounds))
        halves = min(on_cluster(two, 2)[1] for _ in range(args.rounds))
        print(f"\none shot of {args.size * 2} px at {heavy} spp: {whole:.2f} s on 1 worker (all cores), "
              f"{halves:.2f} s split across 2 workers ({whole / halves:.2f}x)")

if __name__ == "__main__":
    main()
