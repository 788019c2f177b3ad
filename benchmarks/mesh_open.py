"""Reading and packing a large mesh: triangles per second in each file format, and each step of the way to the GPU.

The same bumpy ball of ``--triangles`` (at least) is written as binary PLY, ASCII PLY, OBJ (positions, normals,
texture coordinates), GLB and Mitsuba ``.serialized`` (zlib); each file is read the way a scene reads it
(scene/io/meshes.load_mesh_parts, its cache emptied first: the file read, parsed, checked, smooth normals made
where it has none), best of ``--repeat``; the text formats also through trimesh's parser alone, as they were
read before scene/io/text_meshes.py; on this process's one thread unless numpy's own use more. Then the
steps after reading, for one mesh node: placing it (scene/flatten.py: a mesh group in its own space), building
its kd-tree (render/bsp.py, the compiled build, on all cores), and packing its rows for the GPU
(render/instancing.py). Printed per step: seconds and millions of triangles per second.

Usage: python benchmarks/mesh_open.py [--triangles 1000000] [--repeat 3] [--formats ply,ply-ascii,obj,glb,serialized]
"""

from __future__ import annotations

import argparse
import struct
import sys
import tempfile
import time
import zlib
from pathlib import Path

import numpy as np

FORMATS = ("ply", "ply-ascii", "obj", "glb", "serialized")


def bumpy_ball(triangles: int):
    import trimesh

    subdivisions = max(0, int(np.ceil(np.log(max(triangles, 20) / 20) / np.log(4))))
    ball = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    rng = np.random.default_rng(1)
    bumps = sum(np.sin(k * ball.vertices @ rng.normal(size=3) + rng.uniform(0, 6)) / k for k in (3, 7, 17, 41, 97))
    ball.vertices = ball.vertices * (1 + 0.03 * bumps)[:, None]
    return ball


def write_serialized(path: Path, vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray) -> None:
    """One mesh in Mitsuba's .serialized format (version 4: float positions and normals, uint32 faces)."""
    flags = 0x1000 | 0x1  # single precision, vertex normals
    body = struct.pack("<I", flags) + b"ball\0" + struct.pack("<QQ", len(vertices), len(faces))
    body += np.asarray(vertices, "<f4").tobytes() + np.asarray(normals, "<f4").tobytes()
    body += np.asarray(faces, "<u4").tobytes()
    data = struct.pack("<HH", 0x041C, 4) + zlib.compress(body, 1)
    path.write_bytes(data + struct.pack("<QI", 0, 1))


def write(ball, folder: Path, kind: str) -> Path:
    import trimesh

    if kind == "ply":
        path = folder / "ball.ply"
        path.write_bytes(trimesh.exchange.ply.export_ply(ball, encoding="binary", include_attributes=False))
    elif kind == "ply-ascii":
        path = folder / "ball_ascii.ply"
        path.write_bytes(trimesh.exchange.ply.export_ply(ball, encoding="ascii", include_attributes=False))
    elif kind == "obj":
        path = folder / "ball.obj"  # as exporters write it: eight decimals, a uv and a normal per vertex
        with open(path, "w") as out:
            np.savetxt(out, ball.vertices, fmt="v %.8f %.8f %.8f")
            np.savetxt(out, (ball.vertices[:, :2] + 1) / 2, fmt="vt %.8f %.8f")
            np.savetxt(out, ball.vertex_normals, fmt="vn %.8f %.8f %.8f")
            np.savetxt(out, np.repeat(ball.faces + 1, 3, axis=1), fmt="f %d/%d/%d %d/%d/%d %d/%d/%d")
    elif kind == "glb":
        path = folder / "ball.glb"
        path.write_bytes(trimesh.exchange.gltf.export_glb(trimesh.Scene(ball), include_normals=True))
    elif kind == "serialized":
        path = folder / "ball.serialized"
        write_serialized(path, ball.vertices, ball.faces, ball.vertex_normals)
    else:
        raise SystemExit(f"unknown format {kind!r}")
    return path


def best_of(repeat: int, work) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return min(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--triangles", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--formats", default=",".join(FORMATS))
    args = parser.parse_args()

    from lenslab.render import instancing
    from lenslab.render.bsp import build_kdtree
    from lenslab.scene.flatten import flatten_scene
    from lenslab.scene.io import mesh_materials
    from lenslab.scene.io.meshes import load_mesh_parts
    from lenslab.scene.scene import Node, Scene
    from lenslab.scene.shapes import MeshFile

    ball = bumpy_ball(args.triangles)
    count = len(ball.faces)
    folder = Path(tempfile.mkdtemp(prefix="lenslab-mesh-open-"))
    print(f"a bumpy ball of {count:,} triangles ({len(ball.vertices):,} vertices); best of {args.repeat}")
    header = f"{'step':<28} {'seconds':>8} {'M triangles/s':>14}"
    print(header)
    print("-" * len(header))

    def line(step: str, seconds: float) -> None:
        print(f"{step:<28} {seconds:>8.4f} {count / seconds / 1e6:>14.3g}")
        sys.stdout.flush()

    ply = None
    for kind in args.formats.split(","):
        path = write(ball, folder, kind)
        ply = ply or (path if kind == "ply" else None)

        def read():
            mesh_materials._load_cached.cache_clear()
            return load_mesh_parts(path)

        seconds, loaded = best_of(args.repeat, read)
        assert sum(part.mesh.triangle_count for part in loaded.parts) == count, kind
        line(f"read {kind}", seconds)
        if kind in ("ply-ascii", "obj"):  # what reading them took before the compiled reader: trimesh's parser
            import trimesh

            seconds, _ = best_of(1, lambda: trimesh.load(str(path), process=False, force="scene"))
            line(f"  trimesh's parser alone", seconds)

    path = ply or write(ball, folder, "ply")
    scene = Scene(nodes=[Node("ball", shape=MeshFile(path.name))], source_path=folder / "scene.json")
    load_mesh_parts(path)  # read once: what follows is placing, not reading
    seconds, flat = best_of(args.repeat, lambda: flatten_scene(scene, instance_min_triangles=1))
    line("place (a mesh group)", seconds)
    group = flat.groups[0]
    tris = group.triangles
    bounds = np.stack([tris.min(axis=1), tris.max(axis=1)], axis=1)
    build_kdtree(bounds[:1000], triangles=tris[:1000], builder="compiled")  # load the compiled code first
    seconds, tree = best_of(args.repeat, lambda: build_kdtree(bounds, triangles=tris, builder="compiled"))
    line("kd-tree, compiled build", seconds)
    seconds, _ = best_of(1, lambda: build_kdtree(bounds, triangles=tris, builder="levels"))
    line("kd-tree, levels build", seconds)
    seconds, _ = best_of(args.repeat, lambda: instancing.triangle_rows(
        tris, group.triangle_normals, group.triangle_uvs, np.full(count, -1, np.int32), np.full(count, -1, np.int32)))
    line("pack rows", seconds)
    print(f"kd-tree: {tree.node_count:,} nodes, {tree.refs_per_prim:.2f} references per triangle, "
          f"SAH cost {tree.sah_cost:.1f}")


if __name__ == "__main__":
    main()
