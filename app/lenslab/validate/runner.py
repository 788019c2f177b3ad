"""Render each validation scene with LensLab and with Mitsuba 3 and compare them.

Per scene (all images at the scene's film size, ``res`` x ``res``):

* the **reference**: Mitsuba 3 at ``reference_spp`` samples per pixel (in passes of at most 256 spp with
  their own seeds, averaged), seed base 1000;
* **equal samples**: each renderer at ``spp``, seed 0 (LensLab) / 0 (Mitsuba, a different random sequence);
  their relative MSE against the reference is the noise figure;
* **bias**: each renderer at ``bias_spp`` (Mitsuba with seeds from 500, so independent of the reference),
  16 x 16 block means against the reference. Mitsuba's own row is the floor that noise alone reaches;
* **time**: wall seconds of the equal-sample render, loading and compiling included, as a user would wait.

LensLab renders exactly as ``lenslab scene.xml --headless`` does: the same overrides and the same
:class:`~lenslab.render.job.RenderJob`, stepped until the samples are in. Mitsuba loads the same file with ``mi.load_file`` and renders with
``mi.render``, in a child process of its own (:func:`render_mitsuba_file`).
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from lenslab.validate import metrics
from lenslab.validate.mitsuba_env import load_mitsuba

SCENES_DIR = Path(__file__).resolve().parent / "scenes"
SCENE_NAMES = ("cornell_dof", "glass_metal", "environment_depths", "bokeh", "point_sun", "light_bsdf", "beckmann",
               "spot", "rotated_env", "textured", "relief")
MITSUBA_PASS_SPP = 256  # Mitsuba's LLVM wavefront holds every sample of a pass in memory


@dataclass
class Render:
    image: np.ndarray  # (H, W, 3) float32 linear radiance
    spp: int
    seconds: float


@dataclass
class SceneResult:
    name: str
    resolution: tuple[int, int]
    reference: Render
    mitsuba: Render  # equal samples
    lenslab: Render
    mitsuba_bias: metrics.BiasSummary
    lenslab_bias: metrics.BiasSummary
    mitsuba_rel_mse: float
    lenslab_rel_mse: float
    lenslab_converged: Render  # the bias_spp renders
    mitsuba_converged: Render
    warnings: list[str] = field(default_factory=list)

    @property
    def meets_goal(self) -> bool:
        return self.lenslab_bias.meets() and self.lenslab_rel_mse <= self.mitsuba_rel_mse


def scene_path(name: str) -> Path:
    path = SCENES_DIR / f"{name}.xml"
    if not path.is_file():
        raise ValueError(f"no validation scene '{name}' (choose from {', '.join(SCENE_NAMES)})")
    return path


def render_lenslab(path: Path, spp: int, seed: int, res: int, renderer, warn: Callable[[str], None]) -> Render:
    from lenslab.scene.overrides import SceneOverrides

    start = time.perf_counter()
    scene = SceneOverrides(spp=spp, seed=seed, defines={"res": str(res), "spp": str(spp)}).open(path, warn=warn)
    return render_scene(scene, spp, renderer, warn, start)


def render_scene(scene, spp: int, renderer, warn: Callable[[str], None], start: float | None = None) -> Render:
    """An opened scene rendered to ``spp`` by the job ``--headless`` runs; ``seconds`` count from ``start``
    (when the file began to load), or from now."""
    from lenslab.render.job import OFFLINE_DISPATCH_SECONDS, RenderJob

    start = time.perf_counter() if start is None else start
    job = RenderJob(renderer, scene, spp=spp, dispatch_seconds=OFFLINE_DISPATCH_SECONDS)
    for message in job.session.warnings:
        warn(message)
    try:
        image = job.run()
    finally:
        job.release()
    return Render(image, spp, time.perf_counter() - start)


def render_mitsuba(path: Path, spp: int, seed: int, res: int) -> Render:
    image, seconds, _ = render_mitsuba_file(path, {"res": str(res), "spp": str(spp)}, spp, seed)
    return Render(image, spp, seconds)


def render_mitsuba_file(path: Path, defines: dict[str, str], spp: int, seed: int) -> tuple[np.ndarray, float, float]:
    """Mitsuba's image of a scene file at ``spp`` (see :func:`mitsuba_image`), the wall seconds from loading
    the file and the seconds of the rendering alone.

    It runs in a child process: Dr.Jit's LLVM JIT and thread pool in the process where Mesa's llvmpipe then
    renders LensLab slowed LensLab's sampling by up to four times (docs/performance.md), so that the timings
    measured the neighbourhood, not the renderer.
    """
    return in_child_process(_render_mitsuba_here, path, defines, spp, seed)


def in_child_process(function, *args):
    """``function(*args)`` run in a fresh (spawned) child process, for Mitsuba (see :func:`render_mitsuba_file`);
    its exception is raised here. A child that dies (a crash inside Mitsuba) raises BrokenProcessPool."""
    with concurrent.futures.ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn")) as child:
        return child.submit(function, *args).result()


def _render_mitsuba_here(path: Path, defines: dict[str, str], spp: int, seed: int) -> tuple[np.ndarray, float, float]:
    mi = load_mitsuba()
    start = time.perf_counter()
    scene = mi.load_file(str(path), **defines)
    loaded = time.perf_counter()
    image = mitsuba_image(mi, scene, spp, seed)
    end = time.perf_counter()
    return image, end - start, end - loaded


def mitsuba_image(mi, scene, spp: int, seed: int) -> np.ndarray:
    """A loaded Mitsuba scene at ``spp``, rendered in passes of at most MITSUBA_PASS_SPP (seeds seed, seed + 1,
    ...) and averaged: linear RGB, float32."""
    total = None
    done, pass_index = 0, 0
    while done < spp:
        n = min(MITSUBA_PASS_SPP, spp - done)
        image = np.array(mi.render(scene, spp=n, seed=seed + pass_index), dtype=np.float64)[..., :3]
        total = image * n if total is None else total + image * n
        done += n
        pass_index += 1
    return (total / spp).astype(np.float32)


def validate_scene(name: str, *, spp: int, reference_spp: int, bias_spp: int, res: int, renderer,
                   log: Callable[[str], None] = lambda _: None) -> SceneResult:
    path = scene_path(name)
    warnings: list[str] = []
    log(f"{name}: Mitsuba reference, {reference_spp} spp")
    reference = render_mitsuba(path, reference_spp, 1000, res)
    log(f"{name}: Mitsuba and LensLab at {spp} spp")
    mitsuba = render_mitsuba(path, spp, 0, res)
    lenslab = render_lenslab(path, spp, 0, res, renderer, warnings.append)
    if bias_spp == spp:
        mitsuba_conv, lenslab_conv = mitsuba, lenslab
    else:
        log(f"{name}: Mitsuba and LensLab at {bias_spp} spp for the bias")
        mitsuba_conv = render_mitsuba(path, bias_spp, 500, res)
        lenslab_conv = render_lenslab(path, bias_spp, 1, res, renderer, lambda _: None)
    ref = reference.image
    return SceneResult(
        name=name, resolution=(ref.shape[1], ref.shape[0]), reference=reference, mitsuba=mitsuba, lenslab=lenslab,
        mitsuba_bias=metrics.summarize_bias(metrics.block_bias(mitsuba_conv.image, ref)),
        lenslab_bias=metrics.summarize_bias(metrics.block_bias(lenslab_conv.image, ref)),
        mitsuba_rel_mse=metrics.relative_mse(mitsuba.image, ref),
        lenslab_rel_mse=metrics.relative_mse(lenslab.image, ref),
        lenslab_converged=lenslab_conv, mitsuba_converged=mitsuba_conv, warnings=sorted(set(warnings)),
    )
