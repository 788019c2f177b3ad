"""From a studio edit to its first new samples, in a scene that holds a million-triangle object.

The studio's render worker hands every edit that is not the camera's to ``RenderSession.set_scene`` with a copy
of the scene (gui/controller.py). This script makes the same calls without Qt and times, for each edit, the
whole path to the first sample of the new image (set_scene, then one pass of one sample per pixel, finished on
the device), and where the time went (render/tracer.SceneLoad). Edits:

* ``material``: one material's colour changed;
* ``move small``: a small object moved by a millimetre (a marble; a box in the Cornell box);
* ``move large``: the million-triangle object moved by a millimetre;
* ``hide small``: a small object removed.

Columns after the two times: the two-level run's seconds in each step of set_scene (render/tracer.SceneLoad) and in
sampling the first pass, the megabytes it sent to the device, and the mesh trees it built.

Each edit is timed with two levels (the default: large meshes keep their own trees, render/instancing.py) and
with one (every triangle in one world-space tree, as before), in the same run, and the ratio printed. Scenes:
``marbles_on_sand`` (a million triangles of sand made in code) and a Cornell box holding a bumpy ball of
``--triangles`` read from a PLY file. kd-trees go to a cache folder of the run's own, so that the one-level
build may read back a tree it has already built (as it would in the studio), and nothing else's.

Last, the sampling rate of each scene with two levels and with one (the cost of walking two levels).

Usage: python benchmarks/studio_edits.py [--triangles 1310720] [--width 320] [--repeat 3] [--spp 8] [--scenes a,b]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from lenslab.render import instancing
from lenslab.render import tracer as tracer_module
from lenslab.render.tracer import Renderer, RenderSession
from lenslab.scene.io.loader import open_scene
from lenslab.scene.materials import Diffuse
from lenslab.scene.scene import Node, Scene
from lenslab.scene.shapes import MeshFile
from lenslab.scene.transform import Transform


def bumpy_ball(folder: Path, triangles: int, seed: int = 1) -> Path:
    """An icosphere of at least ``triangles`` triangles with bumps at several scales (``seed`` picks them), as a
    binary PLY."""
    import trimesh

    subdivisions = max(0, int(np.ceil(np.log(max(triangles, 20) / 20) / np.log(4))))
    path = folder / f"bumpy_ball_{subdivisions}{'' if seed == 1 else f'_{seed}'}.ply"
    if not path.exists():
        ball = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
        rng = np.random.default_rng(seed)
        v = ball.vertices
        bumps = sum(np.sin(k * v @ rng.normal(size=3) + rng.uniform(0, 6)) / k for k in (3, 7, 17, 41, 97))
        ball.vertices = v * (1 + 0.03 * bumps)[:, None]
        path.write_bytes(trimesh.exchange.ply.export_ply(ball, encoding="binary", include_attributes=False))
    return path


def moved(node: Node, by=(0.001, 0.0, 0.0)) -> Node:
    t = node.transform
    return dataclasses.replace(node, transform=dataclasses.replace(
        t, translate=tuple(float(a + b) for a, b in zip(t.translate, by))))


def replace_node(scene: Scene, name: str, make) -> Scene:
    """The scene with the top-level node ``name`` replaced by ``make(node)`` (removed where that is None)."""
    nodes = [make(node) if node.name == name else node for node in scene.nodes]
    return dataclasses.replace(scene, nodes=[node for node in nodes if node is not None])


def edits(scene: Scene, small: str, large: str, material: str) -> dict[str, Scene]:
    recoloured = dataclasses.replace(scene.materials[material], albedo=(0.2, 0.5, 0.8))
    return {
        "material": dataclasses.replace(scene, materials={**scene.materials, material: recoloured}),
        "move small": replace_node(scene, small, moved),
        "move large": replace_node(scene, large, moved),
        "hide small": replace_node(scene, small, lambda node: None),
    }


def first_sample(session: RenderSession, scene: Scene) -> float:
    start = time.perf_counter()
    session.set_scene(scene)
    while session.samples_per_pixel < 1:
        session.step(0.05, target_spp=1)
    session.ctx.finish()
    return time.perf_counter() - start


def run_scene(renderer, name: str, scene: Scene, small: str, large: str, material: str, width: int, repeat: int,
              sample_spp: int):
    scene = dataclasses.replace(scene, camera=dataclasses.replace(
        scene.camera, resolution=(width, round(width * scene.camera.resolution[1] / scene.camera.resolution[0]))))
    variants = edits(scene, small, large, material)
    results, rates = {}, {}
    for levels, threshold in (("two levels", instancing.INSTANCE_MIN_TRIANGLES), ("one level", 1 << 62)):
        tracer_module.INSTANCE_MIN_TRIANGLES = threshold
        start = time.perf_counter()
        session = RenderSession(renderer, scene)
        while session.samples_per_pixel < 1:
            session.step(0.05, target_spp=1)
        session.ctx.finish()
        opened = time.perf_counter() - start
        times = {"open": (opened, session.load)}
        session.reset()
        start = time.perf_counter()
        while session.samples_per_pixel < sample_spp:
            session.step(0.25, target_spp=sample_spp)
        session.ctx.finish()
        rates[levels] = session.width * session.height * sample_spp / (time.perf_counter() - start) / 1e6
        for edit, edited in variants.items():
            seconds, loads = [], []
            for _ in range(repeat):
                first_sample(session, scene)  # back to the original, then the edit again
                seconds.append(first_sample(session, edited))
                loads.append(session.load)
            best = int(np.argmin(seconds))
            times[edit] = (statistics.median(seconds), loads[best])
        session.release()
        results[levels] = times
    tracer_module.INSTANCE_MIN_TRIANGLES = instancing.INSTANCE_MIN_TRIANGLES
    print(f"\n{name}: {scene.camera.resolution[0]}x{scene.camera.resolution[1]}, first sample after each edit "
          f"(median of {repeat}); where the time went in the two-level run")
    print(f"{'edit':<12} {'two levels':>11} {'one level':>10} {'speed-up':>9}   "
          f"{'read':>6} {'place':>6} {'trees':>6} {'pack':>6} {'upload':>6} {'kernel':>6} {'sample':>6} {'MB sent':>8} mesh trees built")
    for edit in results["two levels"]:
        two, load = results["two levels"][edit]
        one, _ = results["one level"][edit]
        print(f"{edit:<12} {two:>10.3f}s {one:>9.3f}s {one / two:>8.1f}x   {load.read:>6.3f} {load.place:>6.3f} {load.trees:>6.3f} "
              f"{load.pack:>6.3f} {load.upload:>6.3f} {load.kernel:>6.3f} {two - load.total:>6.3f} "
              f"{load.uploaded_bytes / 1e6:>8.1f} {load.mesh_trees_built}")
    print(f"sampling ({sample_spp} spp): {rates['two levels']:.3g} M samples/s with two levels, "
          f"{rates['one level']:.3g} with one ({rates['two levels'] / rates['one level']:.2f}x)")
    sys.stdout.flush()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--triangles", type=int, default=1_310_720, help="of the Cornell box's bumpy ball")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--spp", type=int, default=8, help="samples per pixel of the sampling-rate comparison")
    parser.add_argument("--scenes", default="marbles_on_sand,cornell_ball")
    parser.add_argument("--cache", type=Path, default=Path.home() / ".cache" / "lenslab" / "benchmarks")
    args = parser.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    os.environ["LENSLAB_KDTREE_CACHE"] = tempfile.mkdtemp(prefix="lenslab-edits-trees-")
    renderer = Renderer()
    print(f"device: {renderer.describe()['renderer']}")
    # The compiled kd-tree build's machine code loaded before anything is timed, so that the first opening does
    # not pay for it alone.
    from lenslab.render.bsp import build_kdtree

    build_kdtree(np.random.default_rng(0).random((100, 2, 3)).astype(np.float32).cumsum(axis=1), builder="compiled")
    for name in args.scenes.split(","):
        if name == "marbles_on_sand":
            scene = open_scene("marbles_on_sand")
            small = next(n.name for n in scene.nodes if n.material == "glass")
            large = next(n.name for n in scene.nodes if n.shape is not None and n.shape.type_name == "relief")
            run_scene(renderer, name, scene, small, large, "sand", args.width, args.repeat, args.spp)
        elif name == "cornell_ball":
            box = open_scene("cornell_box")
            ball = bumpy_ball(args.cache, args.triangles)
            node = Node("bumpy ball", Transform(translate=(0.0, 0.3, 0.0), scale=(0.2, 0.2, 0.2)),
                        MeshFile(str(ball)), material="ball")
            scene = dataclasses.replace(box, nodes=[*box.nodes, node],
                                        materials={**box.materials, "ball": Diffuse(albedo=(0.7, 0.7, 0.7))})
            small = next(n.name for n in box.nodes if n.shape is not None and n.shape.type_name == "box")
            run_scene(renderer, name, scene, small, "bumpy ball", "ball", args.width, args.repeat, args.spp)
        else:
            raise SystemExit(f"unknown scene {name!r}")
    renderer.release()


if __name__ == "__main__":
    main()
