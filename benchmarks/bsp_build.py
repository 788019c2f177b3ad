"""kd-tree build time and tree quality for realistic meshes of 10k, 100k and 1M triangles.

For each mesh prints the build's wall and CPU seconds, nodes, leaves (empty ones), references per
triangle, SAH cost, depth reached and the cap, and peak memory so far; with --rays N also the mean
traversal steps and triangle tests per ray, measured with a Python replica of glsl/bsp.glsl's
front-to-back traversal (rays from a sphere around the mesh towards random points of its box).

The meshes: a fractal height-field terrain (large flat-ish triangles in a wide box, like a landscape)
and a displaced torus (a closed curved surface with bumps at several scales, like a scanned object).

Usage: python benchmarks/bsp_build.py [--sizes 10000 100000 1000000] [--rays 0] [--threads N]
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from lenslab.render.bsp import build_kdtree

LEAF = 3


def terrain(triangle_count: int, seed: int = 0) -> np.ndarray:
    """A 10 x 10 m height field with seven octaves of ridges, as (T, 3, 3) float32."""
    rng = np.random.default_rng(seed)
    cells = max(1, round((triangle_count / 2) ** 0.5))
    x, z = np.meshgrid(np.linspace(0, 10, cells + 1), np.linspace(0, 10, cells + 1), indexing="ij")
    y = np.zeros_like(x)
    for octave in range(7):
        f, phase = 0.3 * 2**octave, rng.uniform(0, 2 * np.pi, 3)
        ridges = np.sin(f * x + phase[0]) * np.cos(1.3 * f * z + phase[1]) + 0.5 * np.sin(0.7 * f * (x + z) + phase[2])
        y += ridges / 2**octave
    vertices = np.stack([x, y, z], -1).reshape(-1, 3)
    i = (np.arange(cells)[:, None] * (cells + 1) + np.arange(cells)[None, :]).ravel()
    faces = np.concatenate([np.stack([i, i + 1, i + cells + 2], 1), np.stack([i, i + cells + 2, i + cells + 1], 1)])
    return vertices[faces].astype(np.float32)


def bumpy_torus(triangle_count: int, seed: int = 0) -> np.ndarray:
    """A torus (radii 1 and 0.35) displaced along its normals by bumps at several scales."""
    rng = np.random.default_rng(seed)
    minor = max(3, round((triangle_count / 4) ** 0.5))
    major = max(3, round(triangle_count / (2 * minor)))
    angles = (np.linspace(0, 2 * np.pi, n, endpoint=False) for n in (major, minor))
    u, v = np.meshgrid(*angles, indexing="ij")
    bumps = sum(
        np.sin(k * u + rng.uniform(0, 6)) * np.sin(m * v + rng.uniform(0, 6)) / (k + m)
        for k, m in rng.integers(1, 40, (12, 2))
    )
    r = 0.35 * (1 + 0.6 * bumps + 0.01 * rng.uniform(-1, 1, u.shape))
    ring = 1 + r * np.cos(v)
    vertices = np.stack([ring * np.cos(u), r * np.sin(v), ring * np.sin(u)], -1).reshape(-1, 3)
    a = np.arange(major)[:, None] * minor
    b = (np.arange(major)[:, None] + 1) % major * minor
    c, d = np.arange(minor)[None, :], (np.arange(minor)[None, :] + 1) % minor
    faces = np.concatenate([np.stack(f, -1).reshape(-1, 3) for f in ([a + c, b + c, b + d], [a + c, b + d, a + d])])
    return vertices[faces].astype(np.float32)


def ray_cost(tree, triangles: np.ndarray, ray_count: int, seed: int = 1):
    """Mean traversal steps (nodes visited, leaves included) and triangle tests per ray."""
    rng = np.random.default_rng(seed)
    lo, hi = triangles.reshape(-1, 3).min(0), triangles.reshape(-1, 3).max(0)
    origins = rng.normal(size=(ray_count, 3))
    origins *= 0.75 * np.linalg.norm(hi - lo) / np.linalg.norm(origins, axis=1, keepdims=True)
    origins += (lo + hi) / 2
    directions = lo + (hi - lo) * rng.uniform(size=(ray_count, 3)) - origins
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    steps = tests = 0
    for o, d in zip(origins.astype(float), directions.astype(float)):
        s, t = _trace(tree, triangles, o, d)
        steps, tests = steps + s, tests + t
    return steps / ray_count, tests / ray_count


def _trace(tree, triangles, o, d):
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (tree.bounds[0] - o) / d, (tree.bounds[1] - o) / d
    t_min, t_max = max(np.nanmax(np.minimum(t0, t1)), 0.0), np.nanmin(np.maximum(t0, t1))
    if t_min > t_max:
        return 0, 0
    best, steps, tests, stack, node = np.inf, 0, 0, [], 0
    while True:
        steps += 1
        word0, word1 = int(tree.nodes[node, 0]), int(tree.nodes[node, 1])
        if word1 & 3 == LEAF:
            prims = tree.prim_refs[word0 : word0 + (word1 >> 2)]
            tests += len(prims)
            if len(prims):
                best = min(best, _nearest(triangles[prims].astype(float), o, d))
            if best <= t_max or not stack:
                return steps, tests
            node, t_min, t_max = stack.pop()
            continue
        axis, below, above = word1 & 3, node + 1, word1 >> 2
        split = float(np.uint32(word0).view(np.float32))
        below_first = o[axis] < split or (o[axis] == split and d[axis] < 0)
        near, far = (below, above) if below_first else (above, below)
        t_split = (split - o[axis]) / d[axis] if d[axis] != 0 else np.inf
        if t_split > t_max or t_split <= 0:
            node = near
        elif t_split < t_min:
            node = far
        else:
            stack.append((far, t_split, t_max))
            node, t_max = near, t_split


def _nearest(v, o, d) -> float:
    e1, e2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = o - v[:, 0]
        u = np.einsum("ij,ij->i", s, p) / det
        q = np.cross(s, e1)
        w = q @ d / det
        t = np.einsum("ij,ij->i", e2, q) / det
    t = np.where((u >= 0) & (w >= 0) & (u + w <= 1) & (t > 0), t, np.inf)
    return float(t.min())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--rays", type=int, default=0, help="also measure traversal cost with this many rays")
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args()

    columns = [("mesh", 8), ("triangles", 9), ("wall s", 7), ("cpu s", 6), ("nodes", 9), ("leaves", 9), ("empty", 8)]
    columns += [("refs/tri", 8), ("SAH", 7), ("depth", 6), ("peak MB", 8)]
    header = " ".join(f"{name:<{width}}" if name == "mesh" else f"{name:>{width}}" for name, width in columns)
    if args.rays:
        header += f" {'steps/ray':>9} {'tests/ray':>9}"
    print(header)
    for size in args.sizes:
        for name, make in (("terrain", terrain), ("torus", bumpy_torus)):
            triangles = make(size)
            bounds = np.stack([triangles.min(axis=1), triangles.max(axis=1)], axis=1)
            cpu = time.process_time()
            tree = build_kdtree(bounds, triangles=triangles, threads=args.threads)
            cpu = time.process_time() - cpu
            peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
            line = (
                f"{name:<8} {len(triangles):>9} {tree.build_seconds:>7.2f} {cpu:>6.2f} {tree.node_count:>9} "
                f"{tree.leaf_count:>9} {tree.empty_leaf_count:>8} {tree.refs_per_prim:>8.2f} {tree.sah_cost:>7.1f} "
                f"{tree.max_depth:>2}/{tree.max_depth_limit:<3} {peak:>8.0f}"
            )
            if args.rays:
                steps, tests = ray_cost(tree, triangles, args.rays)
                line += f" {steps:>9.1f} {tests:>9.1f}"
            print(line, flush=True)


if __name__ == "__main__":
    main()
