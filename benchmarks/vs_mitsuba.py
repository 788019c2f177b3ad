"""LensLab against Mitsuba 3 on the same Mitsuba XML scenes, on this machine, in one run.

For each scene (benchmarks/scenes/*.xml) at the same resolution, samples per pixel and pixel filter:

* Mitsuba 3 (``llvm_ad_rgb``; ``LENSLAB_MITSUBA_VARIANT=cuda_ad_rgb`` on an NVIDIA GPU) with the independent
  sampler the files ask for;
* LensLab with the same independent sampler, and with its default Owen-scrambled Sobol sampler;

each against a converged reference (Mitsuba at ``--reference-spp``, cached under ``--cache``). Printed per
render: wall seconds (loading, tree build and kernel compile included, as a user waits) of a cold first render
and of the warm ones after it, samples per second of the rendering alone, relative MSE against the reference,
and efficiency 1 / (warm seconds x relMSE) as a multiple of Mitsuba's. Ratios are what to compare across
machines: these are shared and noisy. Cold, for LensLab: its kd-trees kept in a cache folder of the run's own,
empty at first, so the first render builds them and the later ones read them back (as a user's second
opening does); shader caches (Mesa's, Dr.Jit's) are as the machine has them.

With ``--seeds N`` every render is made N times with seeds 0 ... N-1 and the mean seconds and mean relMSE are
printed: a scene with small bright lights far out of focus (dof_lights) has most of its squared error in a
handful of pixels at the rims of the bokeh disks, where one lens sample in hundreds sees the lamp, so one
seed's relMSE there varies by 2x from seed to seed.

Mitsuba renders in a child process of its own (lenslab.validate.runner.render_mitsuba_file says why).

Usage: python benchmarks/vs_mitsuba.py [--res 256] [--spp 64] [--reference-spp 1024] [--seeds 1] [--scenes a,b]
       python benchmarks/vs_mitsuba.py --lenslab-only --res 16 --spp 2 --triangles 2000   (no Mitsuba needed;
       relMSE against references already in the cache, made on another machine, say)
The million-triangle scene's mesh (a bumpy torus) is written into the cache as a PLY the first time.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lenslab.validate.metrics import relative_mse

HERE = Path(__file__).resolve().parent
SCENES = ("cornell_dof", "dof_lights", "glass_metal_envmap", "million_triangles")


@dataclass
class Result:
    image: np.ndarray
    seconds: float  # wall, loading included
    render_seconds: float  # sampling alone
    samples: int


def torus_mesh(cache: Path, triangles: int) -> Path:
    """The million-triangle scene's mesh: benchmarks/bsp_build.py's bumpy torus as a binary PLY, its faces wound
    to face outwards (Mitsuba's diffuse reflects on the front side only; LensLab's on both)."""
    import trimesh

    from bsp_build import bumpy_torus

    path = cache / f"torus_outward_{triangles}.ply"
    if not path.exists():
        soup = bumpy_torus(triangles).reshape(-1, 3)
        mesh = trimesh.Trimesh(vertices=soup, faces=np.arange(len(soup)).reshape(-1, 3)[:, ::-1],
                               process=False)
        mesh.merge_vertices()
        path.write_bytes(trimesh.exchange.ply.export_ply(mesh, encoding="binary", include_attributes=False))
    return path


def render_lenslab(renderer, path: Path, defines: dict, spp: int, sampler: str, seed: int) -> Result:
    from lenslab.render.job import RenderJob
    from lenslab.scene.overrides import SceneOverrides

    start = time.perf_counter()
    overrides = SceneOverrides(spp=spp, seed=seed, sampler=sampler, defines=defines)
    scene = overrides.open(path, warn=lambda message: print(f"  lenslab: {message}", file=sys.stderr))
    job = RenderJob(renderer, scene, spp=spp, dispatch_seconds=0.25)
    try:
        image = job.run()
        render_seconds = job.session.elapsed_seconds
        samples = job.session.width * job.session.height * spp
    finally:
        job.release()
    return Result(image, time.perf_counter() - start, render_seconds, samples)


def render_mitsuba(path: Path, defines: dict, spp: int, seed: int) -> Result:
    from lenslab.validate.runner import render_mitsuba_file

    image, seconds, render_seconds = render_mitsuba_file(path, defines, spp, seed)
    height, width = image.shape[:2]
    return Result(image, seconds, render_seconds, width * height * spp)


def reference(path: Path, defines: dict, spp: int, cache: Path, render: bool = True) -> np.ndarray | None:
    """Mitsuba at ``spp`` (seeds from 1000, apart from the compared renders'), cached by scene file and settings;
    None when it is not cached and ``render`` is False."""
    key = hashlib.sha256(path.read_bytes() + repr(sorted(defines.items())).encode() + str(spp).encode()).hexdigest()[:16]
    file = cache / f"reference_{path.stem}_{key}.npy"
    if not file.exists() and not render:
        return None
    if not file.exists():
        print(f"  {path.stem}: Mitsuba reference at {spp} spp (cached in {file})", file=sys.stderr)
        np.save(file, render_mitsuba(path, defines, spp, 1000).image)
    return np.load(file)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", type=int, default=256)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--reference-spp", type=int, default=1024)
    parser.add_argument("--seeds", type=int, default=1, help="renders per renderer, seeds 0 ... N-1: means printed")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--triangles", type=int, default=1_000_000, help="of the million-triangle scene's torus")
    parser.add_argument("--cache", type=Path, default=Path.home() / ".cache" / "lenslab" / "benchmarks")
    parser.add_argument("--lenslab-only", action="store_true", help="no Mitsuba: times and samples per second only")
    args = parser.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)

    from lenslab.render.tracer import Renderer

    from lenslab.validate.mitsuba_env import VARIANT

    renderer = Renderer()
    device = renderer.describe()
    print(f"device: {device['renderer']}, {device['version']}; {args.res}x{args.res}, {args.spp} spp, box filter; "
          f"reference: Mitsuba at {args.reference_spp} spp" + ("" if args.lenslab_only else f"; Mitsuba {VARIANT}"))
    import os
    import tempfile

    os.environ["LENSLAB_KDTREE_CACHE"] = tempfile.mkdtemp(prefix="lenslab-vs-mitsuba-trees-")
    header = (f"{'scene':<20} {'renderer':<22} {'cold s':>7} {'seconds':>8} {'Msamples/s':>11} {'relMSE':>9} "
              f"{'efficiency':>11}")
    print(header)
    print("-" * len(header))
    for name in args.scenes.split(","):
        path = HERE / "scenes" / f"{name}.xml"
        defines = {"res": str(args.res), "spp": str(args.spp)}
        if name == "million_triangles":
            defines["mesh"] = str(torus_mesh(args.cache, args.triangles))
        runs: list[tuple[str, list[Result]]] = []
        ref = reference(path, defines, args.reference_spp, args.cache, render=not args.lenslab_only)
        seeds = range(args.seeds)
        cold: dict[str, float] = {}
        if not args.lenslab_only:
            cold["mitsuba independent"] = render_mitsuba(path, defines, args.spp, 0).seconds
            runs.append(("mitsuba independent", [render_mitsuba(path, defines, args.spp, seed) for seed in seeds]))
        for sampler in ("independent", "sobol"):
            label = f"lenslab {sampler}"
            cold[label] = render_lenslab(renderer, path, defines, args.spp, sampler, 0).seconds
            runs.append((label, [render_lenslab(renderer, path, defines, args.spp, sampler, seed) for seed in seeds]))
        baseline = None
        for label, results in runs:
            seconds = float(np.mean([result.seconds for result in results]))
            rate = sum(result.samples for result in results) / sum(result.render_seconds for result in results) / 1e6
            start = f"{name:<20} {label:<22} {cold[label]:>7.2f} {seconds:>8.2f} {rate:>11.3g}"
            if ref is None:
                print(f"{start} {'-':>9} {'-':>11}")
                continue
            error = float(np.mean([relative_mse(result.image, ref) for result in results]))
            if args.lenslab_only:  # no Mitsuba time here to compare with
                print(f"{start} {error:>9.5f} {'-':>11}")
                continue
            efficiency = 1.0 / (seconds * error)
            baseline = baseline or efficiency
            print(f"{start} {error:>9.5f} {efficiency / baseline:>10.2f}x")
        sys.stdout.flush()
    renderer.release()


if __name__ == "__main__":
    main()
