"""How soon the studio's viewport shows an edit: the first picture of it, the first at full resolution, and the
first clean one, with the denoiser on as the studio starts (docs/studio.md, "A clean picture after every edit").

The viewport's own render loop (lenslab.gui.render_loop.RenderLoop, which the studio's worker thread drives) is
driven here without Qt, at the size the studio's viewport renders at in its default window (800 x 673 on a CPU
device). After a warm-up, each edit the photographer makes most (the f-number, the focus distance, the focal
length) is sent as the camera panel sends it, and every picture the loop publishes is timed and compared with a
converged image of the edited camera (``--reference-spp`` samples in two halves of other seeds, cached in
``--cache``) by relMSE, as benchmarks/denoise_convergence.py defines it (trimmed, less the reference's own noise).

Printed per edit: seconds until the first picture of the edit (and whether it was a denoised preview), until the
first full-resolution denoised picture, until relMSE is below ``--relmse``; the relMSE of the first picture and of
the first full-resolution one; and how many raw (not denoised) pictures were shown, which must be none.

Usage: python benchmarks/edit_to_clean.py [--scene cornell_box] [--width 800 --height 673] [--seconds 6]
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from denoise_convergence import REFERENCE_SEED_OFFSETS, camera_exposure_of, rel_mse  # noqa: E402

from lenslab.gui.controller import VIEW_MARGIN  # noqa: E402
from lenslab.gui.render_loop import CameraEdit, DenoiseEdit, RenderLoop, SceneEdit, TargetSpp  # noqa: E402
from lenslab.render.gl import glsl_dir  # noqa: E402
from lenslab.render.tracer import Renderer, RenderSession  # noqa: E402
from lenslab.scene.io.loader import open_scene  # noqa: E402

EDITS = {
    "f-number x2": lambda c: dataclasses.replace(c, f_number=c.f_number * 2),
    "focus -20%": lambda c: dataclasses.replace(c, focus_distance_m=c.focus_distance_m * 0.8),
    "focal length +20%": lambda c: dataclasses.replace(c, focal_length_mm=c.focal_length_mm * 1.2),
}


class QuietEvents:
    """The loop's reports, unused here but the pictures (taken with take_frame)."""

    def __getattr__(self, name):
        return lambda *args: None


def reference(renderer, scene, size, spp: int, cache: Path) -> np.ndarray:
    """The edited camera's converged viewport picture as two halves (2, H, W, 3), framed as the viewport frames,
    exposed as its camera exposes it."""
    kernels = b"".join(p.read_bytes() for p in sorted(glsl_dir().glob("*.*")))
    key = hashlib.sha256(scene.source_path.read_bytes() + kernels + repr(
        (scene.camera, size, spp, VIEW_MARGIN, REFERENCE_SEED_OFFSETS)).encode()).hexdigest()[:16]
    file = cache / f"edit_reference_{key}.npy"
    if not file.exists():
        print(f"  reference at {spp} spp (cached in {file})", file=sys.stderr, flush=True)
        halves = []
        for offset in REFERENCE_SEED_OFFSETS:
            settings = dataclasses.replace(scene.render, seed=scene.render.seed + offset)
            session = RenderSession(renderer, scene, settings=settings, width=size[0], height=size[1],
                                    dispatch_seconds=0.25)
            session.set_view(*size, VIEW_MARGIN)
            while not session.done(max(1, spp // 2)):
                session.step(5.0, max(1, spp // 2))
            halves.append(session.image())
            session.release()
        np.save(file, np.stack(halves))
    halves = np.load(file)
    return halves * camera_exposure_of(scene, halves)


def time_edit(loop: RenderLoop, camera, size, generation: int, halves, seconds: float, threshold: float) -> dict:
    loop.handle([CameraEdit(camera, size, generation, False, VIEW_MARGIN)])
    start = time.perf_counter()
    result = {"first": None, "first denoised": None, "full": None, "clean": None, "first relMSE": None,
              "full relMSE": None, "raw shown": 0}
    while time.perf_counter() - start < seconds and (result["clean"] is None or result["full"] is None):
        loop.step()
        frame = loop.take_frame()
        if frame is None or frame.generation != generation:
            continue
        now = time.perf_counter() - start
        exposure = frame.exposure.scale if frame.exposure is not None else 1.0
        error = rel_mse(frame.image * exposure, halves) if frame.image is not None else None
        if not frame.denoised:
            result["raw shown"] += 1
        if result["first"] is None:
            result["first"], result["first denoised"], result["first relMSE"] = now, frame.denoised, error
        if not frame.preview and result["full"] is None and frame.denoised:
            result["full"], result["full relMSE"] = now, error
        if error is not None and error < threshold and result["clean"] is None:
            result["clean"] = now
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="cornell_box")
    parser.add_argument("--width", type=int, default=800)
    parser.add_argument("--height", type=int, default=673)
    parser.add_argument("--seconds", type=float, default=6.0, help="the longest wait for each edit")
    parser.add_argument("--relmse", type=float, default=0.01, help="the level called clean")
    parser.add_argument("--reference-spp", type=int, default=128)
    parser.add_argument("--cache", type=Path, default=Path("/tmp"))
    args = parser.parse_args()
    size = (args.width, args.height)
    renderer = Renderer()
    scene = open_scene(args.scene)
    loop = RenderLoop(renderer, QuietEvents())
    loop.start()
    loop.handle([DenoiseEdit(True), TargetSpp(None), SceneEdit(scene, size, 1, VIEW_MARGIN)])
    warm = None
    while warm is None or warm.preview or warm.samples_per_pixel < 2:
        loop.step()  # warm: every kernel compiled, the denoiser loaded
        warm = loop.take_frame() or warm
    print(f"{args.scene} at {size[0]} x {size[1]}, denoiser on; {renderer.describe().get('renderer', '?')}")
    print("| edit | first picture | denoised | relMSE | full resolution | relMSE | "
          f"relMSE < {args.relmse} | raw pictures shown |")
    print("|---|---:|---|---:|---:|---:|---:|---:|")
    generation = 1
    for name, edit in EDITS.items():
        camera = edit(scene.camera)
        halves = reference(renderer, dataclasses.replace(scene, camera=camera), size, args.reference_spp,
                           args.cache)
        generation += 1
        r = time_edit(loop, camera, size, generation, halves, args.seconds, args.relmse)

        def s(v):
            return "-" if v is None else f"{v:.2f} s"

        def e(v):
            return "-" if v is None else f"{v:.4f}"
        clean = s(r["clean"]) if r["clean"] is not None else f">{args.seconds:g} s"
        print(f"| {name} | {s(r['first'])} | {'yes' if r['first denoised'] else 'no'} | {e(r['first relMSE'])} | "
              f"{s(r['full'])} | {e(r['full relMSE'])} | {clean} | {r['raw shown']} |", flush=True)
        generation += 1  # back to the scene's camera for the next edit, and let it settle
        loop.handle([CameraEdit(scene.camera, size, generation, False, VIEW_MARGIN)])
        settle = time.perf_counter()
        while time.perf_counter() - settle < 1.0:
            loop.step()
        loop.take_frame()
    loop.release()


if __name__ == "__main__":
    main()
