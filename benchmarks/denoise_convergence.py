"""Seconds until the viewport's image is within a given error of the converged image, with and without the denoiser.

For each shipped scene, at a small size (``--size``: the long edge in pixels): a converged reference (``--reference-spp``
samples in two halves of other seeds than the renders compared; cached under ``--cache``, keyed by the scene file, the
size and the kernels' source), then two progressive renders as the studio's viewport makes them (``RenderSession.step``): one plain,
one with the denoiser's feature buffers, whose image is denoised as the viewport's preview is (render/denoise.py,
prefilter off, ``--quality`` fast as the viewport's). At checkpoints spaced by sqrt(2) in time, up to ``--seconds`` of sampling, both are compared with the
reference, by two errors:

* relMSE: the mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01), the denoising literature's relative
  mean squared error (the 0.01 keeps black pixels from dominating), without the 0.1% of pixels where it is largest
  (a firefly would otherwise decide it alone, as in denoising papers), and less the reference's own noise,
  (A - B)^2 / 4 from its two halves A and B: an unbiased estimate of the error against the truly converged image,
  which may dip below 0 there;
* display MAE: the mean absolute difference of the display values in [0, 1] (the default view: ACES 2.0 SDR on sRGB) (what the
  studio shows by default; 0.01 is about 2.5 steps of 255). Not corrected: the reference's own, about half its
  halves' difference, is printed as its floor.

Printed: the seconds until each error is below each threshold (``--relmse``, ``--mae``), interpolated between
checkpoints (log-log). A denoised image's time includes what denoising it once took; the sampling clock is the
session's (GPU dispatches), as the viewport's progress reports it. A plain render that does not get there within
``--seconds`` is extrapolated by its relMSE's 1/t (marked ~); a denoised one that does not is marked >. The spp/s
columns are samples per pixel per second of sampling without and with the feature buffers: what the guides cost.
``--denoise-sizes`` also times the denoiser alone. Usage: python benchmarks/denoise_convergence.py [--size 320]
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import math
import sys
import time
from pathlib import Path

import numpy as np

from lenslab.colour_management.working_space import luminance
from lenslab.render import denoise as oidn
from lenslab.render.film import display_pixels
from lenslab.render.gl import glsl_dir
from lenslab.render.tracer import Renderer, RenderSession
from lenslab.scene.io.loader import open_scene, shipped_scene_names

REFERENCE_SEED_OFFSETS = (1000, 2000)  # the reference's two halves: not the compared renders' samples
TRIMMED = 0.001  # relMSE leaves out this share of pixels, those where it is largest


def camera_exposure_of(scene, halves: np.ndarray) -> float:
    """What the scene's camera multiplies its radiance by (lenslab.optics.exposure: 1 when compensated, its f-number,
    shutter and ISO when physical, the meter's choice on the converged ``halves`` when auto). Every image here is
    compared as the camera records it, where middle grey is 0.18: so relMSE's 0.01 and the display's values mean
    the same whether the lights are written in nits or in plain numbers."""
    camera = scene.camera
    light = camera.aperture(scene.base_dir()).light_fraction
    if camera.exposure_mode != "auto":
        return camera.exposure(light).scale
    converged = halves.mean(axis=0)
    return camera.exposure(light, luminance=luminance(converged, scene.render.working_space)).scale


def rel_mse(image: np.ndarray, halves: np.ndarray) -> float:
    reference = halves.mean(axis=0)
    scale = reference ** 2 + 0.01
    error = ((image - reference) ** 2 / scale).mean(axis=-1)
    noise = ((halves[0] - halves[1]) ** 2 / 4 / scale).mean(axis=-1)  # the reference's own variance, estimated
    kept = error <= np.quantile(error, 1 - TRIMMED)
    return float(np.mean(error[kept] - noise[kept]))


def display_mae(image: np.ndarray, halves: np.ndarray) -> float:
    return float(np.mean(np.abs(display_pixels(image) - display_pixels(halves.mean(axis=0)))))


def reference_floor(halves: np.ndarray) -> dict[str, float]:
    """The reference's own errors: its relMSE estimated from its halves (untrimmed), and its display MAE, about half
    its halves' from each other."""
    reference = halves.mean(axis=0)
    noise = (halves[0] - halves[1]) ** 2 / 4 / (reference ** 2 + 0.01)
    shown = [display_pixels(half) for half in halves]
    return {"relMSE": float(noise.mean()), "display MAE": float(np.mean(np.abs(shown[0] - shown[1]))) / 2}


METRICS = {"relMSE": rel_mse, "display MAE": display_mae}


def sized(scene, long_edge: int):
    width, height = scene.camera.resolution
    scale = long_edge / max(width, height)
    resolution = (max(1, round(width * scale)), max(1, round(height * scale)))
    return dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, resolution=resolution))


def reference(renderer, name: str, scene, spp: int, cache: Path) -> np.ndarray:
    """The converged image's two halves (2, H, W, 3), each of spp / 2 samples, rendered once and cached by scene
    file, size, samples and kernel source."""
    kernels = b"".join(p.read_bytes() for p in sorted(glsl_dir().glob("*.*")))
    key = hashlib.sha256(scene.source_path.read_bytes() + kernels +
                         repr((scene.camera.resolution, spp, REFERENCE_SEED_OFFSETS)).encode()).hexdigest()[:16]
    file = cache / f"denoise_reference_{name}_{key}.npy"
    if not file.exists():
        print(f"  {name}: reference at {spp} spp (cached in {file})", file=sys.stderr, flush=True)
        halves = []
        for offset in REFERENCE_SEED_OFFSETS:
            settings = dataclasses.replace(scene.render, seed=scene.render.seed + offset)
            session = RenderSession(renderer, scene, settings=settings, dispatch_seconds=0.25)
            while not session.done(max(1, spp // 2)):
                session.step(5.0, max(1, spp // 2))
            halves.append(session.image())
            session.release()
        np.save(file, np.stack(halves))
    return np.load(file)


def progression(renderer, scene, ref: np.ndarray, seconds: float, denoised: bool, quality: str = "fast",
                exposure: float = 1.0) -> list[tuple[float, float, int, dict]]:
    """(seconds until shown, seconds sampled, spp, {metric: error}) at checkpoints sqrt(2) apart in sampling time,
    from the first full pass. A denoised image is shown once it is denoised: its time adds one denoise (what the
    viewport pays for the frame it shows; how often it denoises while sampling is the viewport's choice). Each image
    is compared times ``exposure``, the camera's (``ref`` is exposed already)."""
    session = RenderSession(renderer, scene, feature_buffers=denoised)
    while session.samples_per_pixel < 1:
        session.step(1.0, 1)
    points, checkpoint = [], session.elapsed_seconds
    while True:
        image, extra = session.image(), 0.0
        if denoised:
            albedo, normal = session.features_image()
            start = time.perf_counter()
            image = oidn.denoise(image, albedo, normal, quality=quality)
            extra = time.perf_counter() - start
        points.append((session.elapsed_seconds + extra, session.elapsed_seconds, session.samples_per_pixel,
                       {metric: error(image * exposure, ref) for metric, error in METRICS.items()}))
        if session.elapsed_seconds >= seconds:
            break
        checkpoint = min(seconds, checkpoint * math.sqrt(2))
        session.step(max(0.0, checkpoint - session.elapsed_seconds))
    session.release()
    return points


def seconds_to(points, metric: str, threshold: float, extrapolate: bool) -> str:
    """When the error first falls below the threshold, interpolated in log-log between checkpoints."""
    previous = None
    for seconds, _, _, errors in points:
        error = errors[metric]
        if error <= threshold:
            if previous is None:
                return f"<={seconds:.2f}"
            (s0, e0), (s1, e1) = previous, (seconds, error)
            if threshold <= 0 or e1 <= 0:  # the debiased relMSE can reach 0: no logarithm, a straight line
                return f"{s0 + (s1 - s0) * (e0 - threshold) / (e0 - e1):.2f}"
            fraction = math.log(e0 / threshold) / math.log(e0 / e1)
            return f"{math.exp(math.log(s0) + fraction * math.log(s1 / s0)):.2f}"
        previous = (seconds, error)
    seconds, _, _, errors = points[-1]
    if extrapolate and metric == "relMSE":  # an unbiased estimate's relMSE falls as 1 / t
        return f"~{seconds * errors[metric] / threshold:.0f}"
    return f">{seconds:.0f}"


def time_denoiser(sizes: list[tuple[int, int]]) -> None:
    rng = np.random.default_rng(1)
    print(f"\n{oidn.describe()}: seconds to denoise once (best of 3, after a first call that sets the filter up)")
    print(f"{'size':>11} {'colour only':>12} {'+ guides':>9} {'+ guides, fast':>15} {'+ guides, prefiltered':>22}")
    for width, height in sizes:
        color = rng.random((height, width, 3), dtype=np.float32)
        albedo = rng.random((height, width, 3), dtype=np.float32)
        normal = rng.random((height, width, 3), dtype=np.float32) * 2 - 1
        row = []
        guides = {"albedo": albedo, "normal": normal}
        for kwargs in ({}, guides, {**guides, "quality": "fast"}, {**guides, "prefilter": True}):
            oidn.denoise(color, **kwargs)
            times = []
            for _ in range(3):
                start = time.perf_counter()
                oidn.denoise(color, **kwargs)
                times.append(time.perf_counter() - start)
            row.append(min(times))
        print(f"{f'{width}x{height}':>11} {row[0]:>12.3f} {row[1]:>9.3f} {row[2]:>15.3f} {row[3]:>22.3f}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=320, help="the long edge, in pixels")
    parser.add_argument("--seconds", type=float, default=30.0, help="sampling time per progressive render")
    parser.add_argument("--reference-spp", type=int, default=1024)
    parser.add_argument("--relmse", default="0.01,0.002", help="relMSE thresholds, comma-separated")
    parser.add_argument("--mae", default="0.01,0.005", help="display MAE thresholds, comma-separated")
    parser.add_argument("--quality", choices=oidn.QUALITIES, default="fast", help="the preview's (the viewport's: fast)")
    parser.add_argument("--scenes", default=",".join(shipped_scene_names()))
    parser.add_argument("--cache", type=Path, default=Path.home() / ".cache" / "lenslab" / "benchmarks")
    parser.add_argument("--denoise-sizes", default="320x320,800x533,1920x1080",
                        help="sizes to time the denoiser alone at ('' for none)")
    args = parser.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    renderer = Renderer()
    device = renderer.describe()
    print(f"device: {device['renderer']}, {device['version']}; denoiser: {oidn.describe()}")
    thresholds = [(metric, float(value)) for metric, values in (("relMSE", args.relmse), ("display MAE", args.mae))
                  for value in values.split(",")]
    print(f"long edge {args.size} px, reference {args.reference_spp} spp, up to {args.seconds:g} s of sampling, "
          f"denoised at quality {args.quality}")
    print(f"{'scene':<16} {'size':>8} {'metric':<12} {'below':>7} {'plain s':>8} {'denoised s':>11} "
          f"{'plain spp/s':>12} {'guided spp/s':>13} {'error at end: plain':>20} {'denoised':>9} {'ref. floor':>10}")
    for name in [name for name in args.scenes.split(",") if name]:
        scene = sized(open_scene(name), args.size)
        ref = reference(renderer, name, scene, args.reference_spp, args.cache)
        exposure = camera_exposure_of(scene, ref)
        ref = ref * exposure
        floor = reference_floor(ref)
        plain = progression(renderer, scene, ref, args.seconds, denoised=False, exposure=exposure)
        guided = progression(renderer, scene, ref, args.seconds, denoised=True, quality=args.quality,
                             exposure=exposure)
        size = "x".join(map(str, scene.camera.resolution))
        for metric, threshold in thresholds:
            print(f"{name:<16} {size:>8} {metric:<12} {threshold:>7g} {seconds_to(plain, metric, threshold, True):>8} "
                  f"{seconds_to(guided, metric, threshold, False):>11} {plain[-1][2] / plain[-1][1]:>12.2f} "
                  f"{guided[-1][2] / guided[-1][1]:>13.2f} {plain[-1][3][metric]:>20.4g} "
                  f"{guided[-1][3][metric]:>9.4g} {floor[metric]:>10.2g}", flush=True)
    renderer.release()
    sizes = [tuple(int(v) for v in size.split("x")) for size in args.denoise_sizes.split(",") if size]
    if sizes:
        time_denoiser(sizes)


if __name__ == "__main__":
    main()
