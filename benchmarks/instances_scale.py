"""Many instances of one large mesh: a grid of N x N bumpy balls (one PLY of ``--triangles``) on a floor.

Prints the triangles as the camera sees them and as stored (each mesh once: render/instancing.py), where the
opening's time went (render/tracer.SceneLoad), and the sampling rate. On llvmpipe a hundred instances of 1.31 M
triangles (131 M placed) fit in the 2 M triangles a storage block holds; on a GPU, ``--unique`` places N x N
different meshes instead (each its own file and tree), for the scale of unique triangles a GPU's memory holds.

Usage: python benchmarks/instances_scale.py [--grid 10] [--triangles 1000000] [--width 160] [--spp 4] [--unique]
       [--no-instance-tree]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from studio_edits import bumpy_ball

from lenslab.render import instancing
from lenslab.render.tracer import Renderer, RenderSession
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.materials import Diffuse
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
from lenslab.scene.shapes import MeshFile, Rectangle
from lenslab.scene.transform import Transform


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=10, help="N: N x N balls")
    parser.add_argument("--triangles", type=int, default=1_000_000, help="of each ball (at least)")
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--unique", action="store_true", help="a mesh file of its own for every ball")
    parser.add_argument("--no-instance-tree", action="store_true",
                        help="every ray tests every instance's box (no kd-tree over the instances)")
    parser.add_argument("--cache", type=Path, default=Path.home() / ".cache" / "lenslab" / "benchmarks")
    args = parser.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    if args.no_instance_tree:
        instancing.INSTANCE_TREE_MIN_INSTANCES = 1 << 62
    n = args.grid
    files = []
    for k in range(n * n if args.unique else 1):
        folder = args.cache / (f"unique_{k}" if args.unique else "")
        folder.mkdir(parents=True, exist_ok=True)
        files.append(bumpy_ball(folder, args.triangles, seed=k + 1))
    nodes = [Node(f"ball {i} {j}", Transform(translate=(2.2 * i - 1.1 * n, 1.0, -2.2 * j)),
                  MeshFile(str(files[(i * n + j) % len(files)])), material="clay")
             for i in range(n) for j in range(n)]
    nodes.append(Node("floor", Transform(rotate_deg=(-90, 0, 0), scale=(100, 100, 1)), Rectangle(), material="clay"))
    height = max(1, round(args.width * 2 / 3))
    scene = Scene(camera=ThinLensCamera(position=(0, 6, 8), look_at=(0, 0, -n), focal_length_mm=24, f_number=8,
                                        focus_distance_m=12, resolution=(args.width, height)),
                  environment=ConstantEnvironment((1.0, 1.0, 1.0)), render=RenderSettings(max_depth=4),
                  materials={"clay": Diffuse(albedo=(0.6, 0.5, 0.4))}, nodes=nodes)
    renderer = Renderer()
    print(f"device: {renderer.describe()['renderer']}")
    start = time.perf_counter()
    session = RenderSession(renderer, scene)
    opened = time.perf_counter() - start
    flat, load = session.flat_scene, session.load
    print(f"{n * n} balls: {flat.placed_triangle_count:,} triangles placed, {flat.stored_triangle_count:,} stored, "
          f"{len(flat.groups)} mesh trees; opened in {opened:.2f} s: read {load.read:.2f} s, placed {load.place:.2f} s, trees "
          f"{load.trees:.2f} s, packed {load.pack:.2f} s, uploaded {load.upload:.2f} s ({load.uploaded_bytes / 1e6:.0f} MB)")
    start = time.perf_counter()
    while session.samples_per_pixel < args.spp:
        session.step(1.0, target_spp=args.spp)
    session.ctx.finish()
    seconds = time.perf_counter() - start
    print(f"{args.spp} spp at {args.width}x{height} in {seconds:.2f} s: "
          f"{args.width * height * args.spp / seconds / 1e6:.3g} M samples/s")
    sys.stdout.flush()
    session.release()
    renderer.release()


if __name__ == "__main__":
    main()
