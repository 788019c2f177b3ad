"""CPU tests of the SAH kd-tree builders (lenslab.render.bsp: the levels build in numpy, and the compiled one
in render/bsp_compiled.py).

The tests walk the flat arrays in Python, exactly as the GLSL traversal does, and check them against
brute force: which primitives must be in which leaf, and which triangle a ray hits first. Every test runs
against both builders (the ``builder`` fixture makes ``build_kdtree``'s automatic choice pick each in turn).
"""

from __future__ import annotations

import numpy as np
import pytest

import lenslab.render.bsp as bsp
from lenslab.render.bsp import KdTree, build_kdtree, default_depth_limit

LEAF = 3


@pytest.fixture(autouse=True, params=["levels", "compiled"])
def builder(request, monkeypatch):
    """Every test twice: with the levels build, and with the compiled build for scenes of any size (its threads
    too, from a few hundred primitives on, so that the subtrees built apart and joined are tested)."""
    from lenslab.render import bsp_compiled

    compiled = request.param == "compiled"
    monkeypatch.setattr(bsp, "COMPILED_MIN_PRIMITIVES", 0 if compiled else 1 << 62)
    monkeypatch.setattr(bsp_compiled, "PARALLEL_MIN_PRIMITIVES", 300)
    return request.param


# --------------------------------------------------------------------------------------------------
# Scenes


def triangle_bounds(tris: np.ndarray) -> np.ndarray:
    return np.stack([tris.min(axis=1), tris.max(axis=1)], axis=1).astype(np.float32)


def sphere_bounds(spheres: np.ndarray) -> np.ndarray:
    c, r = spheres[:, :3], spheres[:, 3:4]
    return np.stack([c - r, c + r], axis=1).astype(np.float32)


def noisy_sphere(rng, subdivisions=3, center=(0, 0, 0), radius=1.0, noise=0.05) -> np.ndarray:
    """An icosphere with its vertices pushed in and out: a small closed mesh with shared edges."""
    t = (1 + 5**0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    v = np.array(verts, float)
    f = np.array(faces)
    for _ in range(subdivisions):
        a, b, c = f[:, 0], f[:, 1], f[:, 2]
        edges = np.sort(np.concatenate([np.stack([a, b], 1), np.stack([b, c], 1), np.stack([c, a], 1)]), 1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        mid = len(v) + inv.reshape(3, -1)
        v = np.concatenate([v, (v[uniq[:, 0]] + v[uniq[:, 1]]) / 2])
        ab, bc, ca = mid
        f = np.concatenate([np.stack(x, 1) for x in ([a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca])])
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v *= radius * (1 + noise * rng.uniform(-1, 1, (len(v), 1)))
    return (v[f] + np.asarray(center)).astype(np.float32)


def ground_plane(n=8, size=4.0, y=0.0) -> np.ndarray:
    """A grid of 2 n^2 triangles lying exactly in the plane y = const: flat boxes."""
    xs = np.linspace(-size / 2, size / 2, n + 1)
    x0, z0 = np.meshgrid(xs[:-1], xs[:-1], indexing="ij")
    x1, z1 = x0 + size / n, z0 + size / n
    x0, z0, x1, z1 = (a.ravel() for a in (x0, z0, x1, z1))
    yy = np.full_like(x0, y)
    t1 = np.stack([np.stack([x0, yy, z0], 1), np.stack([x1, yy, z0], 1), np.stack([x1, yy, z1], 1)], 1)
    t2 = np.stack([np.stack([x0, yy, z0], 1), np.stack([x1, yy, z1], 1), np.stack([x0, yy, z1], 1)], 1)
    return np.concatenate([t1, t2]).astype(np.float32)


def triangle_soup(rng, n, size_range=(0.02, 0.6), extent=2.0) -> np.ndarray:
    centers = rng.uniform(-extent, extent, (n, 1, 3))
    sizes = np.exp(rng.uniform(*np.log(size_range), (n, 1, 1)))
    return (centers + sizes * rng.normal(size=(n, 3, 3))).astype(np.float32)


def mixed_scene(rng):
    """Triangles (a noisy sphere, a ground plane, a soup, axis-aligned box faces) followed by spheres."""
    box = np.array(
        [[[-2, -1, -2], [2, -1, -2], [2, 3, -2]], [[-2, -1, -2], [2, 3, -2], [-2, 3, -2]],
         [[-2, -1, -2], [-2, 3, -2], [-2, 3, 2]], [[-2, -1, -2], [-2, 3, 2], [-2, -1, 2]]],
        np.float32,
    )
    tris = np.concatenate([
        noisy_sphere(rng, 3, center=(0.3, 0.8, -0.2)),
        ground_plane(10, 4.0, 0.0),
        triangle_soup(rng, 300),
        box,
    ])
    spheres = np.concatenate([rng.uniform(-1.8, 1.8, (12, 3)), rng.uniform(0.05, 0.5, (12, 1))], 1)
    return tris, spheres.astype(np.float32)


# --------------------------------------------------------------------------------------------------
# Walking the flat arrays


def walk(tree: KdTree):
    """Yield (depth, region_lo, region_hi, prims) for every leaf, checking the node links on the way.

    A region is [lo, hi) per axis; sides not cut by any split are +-inf.
    """
    nodes = tree.nodes
    assert nodes.dtype == np.uint32 and nodes.ndim == 2 and nodes.shape[1] == 2
    assert tree.prim_refs.dtype == np.int32
    visited = np.zeros(len(nodes), int)
    stack = [(0, 0, np.full(3, -np.inf), np.full(3, np.inf))]
    runs = []
    while stack:
        i, depth, lo, hi = stack.pop()
        visited[i] += 1
        assert depth <= tree.max_depth
        word0, word1 = int(nodes[i, 0]), int(nodes[i, 1])
        if word1 & 3 == LEAF:
            count, offset = word1 >> 2, word0
            assert offset + count <= len(tree.prim_refs)
            runs.append((offset, count))
            yield depth, lo, hi, tree.prim_refs[offset : offset + count]
            continue
        axis, above = word1 & 3, word1 >> 2
        split = float(np.uint32(word0).view(np.float32))
        assert i + 1 < len(nodes) and i + 1 < above < len(nodes)
        assert lo[axis] < split < hi[axis]
        below_hi, above_lo = hi.copy(), lo.copy()
        below_hi[axis], above_lo[axis] = split, split
        stack.append((above, depth + 1, above_lo, hi))
        stack.append((i + 1, depth + 1, lo, below_hi))
    assert (visited == 1).all(), "every node is reached exactly once"
    # The leaves' runs tile prim_refs exactly.
    covered = np.zeros(len(tree.prim_refs), int)
    for offset, count in runs:
        covered[offset : offset + count] += 1
    assert (covered == 1).all()


def leaves(tree):
    return list(walk(tree))


def box_rule(bounds, lo, hi):
    """Which boxes a leaf region [lo, hi) must hold under the build's rule (see bsp's docstring)."""
    a, b = bounds[:, 0].astype(float), bounds[:, 1].astype(float)
    return ((a < hi) & ((b > lo) | (a >= lo))).all(axis=1)


def triangle_meets_box(tri, lo, hi) -> bool:
    """Does the triangle meet the closed box? Sutherland-Hodgman clipping in float64."""
    poly = [np.asarray(p, float) for p in tri]
    for axis in range(3):
        for bound, sign in ((lo[axis], 1.0), (hi[axis], -1.0)):
            if not np.isfinite(bound):
                continue
            out = []
            for k in range(len(poly)):
                p, q = poly[k], poly[(k + 1) % len(poly)]
                dp, dq = sign * (p[axis] - bound), sign * (q[axis] - bound)
                if dp >= 0:
                    out.append(p)
                if dp * dq < 0:
                    out.append(p + (q - p) * (dp / (dp - dq)))
            poly = out
            if not poly:
                return False
    return True


def check_leaf_contents(tree, bounds, triangles=None):
    """Every primitive that reaches into a leaf's region is in the leaf, and nothing else is.

    Boxes (and spheres) follow the box rule exactly. Triangles may be left out where the triangle
    itself misses the region, so for them: the leaf holds every triangle that meets the region shrunk
    by a hair, and only triangles whose box passes the box rule.
    """
    tri_count = 0 if triangles is None else len(triangles)
    scale = float(np.abs(tree.bounds).max()) + 1.0
    total = 0
    for _, lo, hi, prims in walk(tree):
        total += len(prims)
        assert len(np.unique(prims)) == len(prims), "no primitive twice in a leaf"
        assert ((prims >= 0) & (prims < len(bounds))).all()
        must = box_rule(bounds, lo, hi)
        held = np.zeros(len(bounds), bool)
        held[prims] = True
        assert not (held & ~must).any(), "leaf holds a primitive outside its region"
        missing = np.flatnonzero(must & ~held)
        assert (missing < tri_count).all(), "a non-triangle primitive is missing from a leaf"
        eps = 1e-5 * scale
        for p in missing:
            assert not triangle_meets_box(triangles[p], lo + eps, hi - eps), (
                f"triangle {p} meets the leaf region but is not in the leaf"
            )
    return total


# --------------------------------------------------------------------------------------------------
# Ray casting: brute force and through the tree


def cross(a, b):
    """Cross product over the last axis, with elementwise operations only."""
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        axis=-1,
    )


def dot(a, b):
    """Dot product over the last axis, always summed in the same order (unlike np.dot or einsum)."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def intersect(o, d, tris, spheres, prims):
    """Nearest positive hit distance of one ray with the given primitives (inf where none), float64.

    Triangles by Moller-Trumbore, spheres analytically. Written with elementwise operations only, so
    the same primitive gives bit-identical results whichever subset it is tested in.
    """
    prims = np.asarray(prims)
    t = np.full(len(prims), np.inf)
    is_tri = prims < len(tris)
    if is_tri.any():
        v = tris[prims[is_tri]].astype(float)
        e1, e2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
        p = cross(np.broadcast_to(d, e2.shape), e2)
        det = dot(e1, p)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            inv = 1.0 / det
            s = o - v[:, 0]
            u = dot(s, p) * inv
            q = cross(s, e1)
            w = dot(np.broadcast_to(d, q.shape), q) * inv
            th = dot(e2, q) * inv
            ok = (det != 0) & (u >= 0) & (w >= 0) & (u + w <= 1) & (th > 1e-9)
        t[is_tri] = np.where(ok, th, np.inf)
    if (~is_tri).any():
        sp = spheres[prims[~is_tri] - len(tris)].astype(float)
        oc = o - sp[:, :3]
        b = oc[:, 0] * d[0] + oc[:, 1] * d[1] + oc[:, 2] * d[2]
        c = oc[:, 0] ** 2 + oc[:, 1] ** 2 + oc[:, 2] ** 2 - sp[:, 3] ** 2
        dd = d[0] ** 2 + d[1] ** 2 + d[2] ** 2
        disc = b * b - dd * c
        root = np.sqrt(np.maximum(disc, 0))
        t0, t1 = (-b - root) / dd, (-b + root) / dd
        th = np.where(t0 > 1e-9, t0, np.where(t1 > 1e-9, t1, np.inf))
        t[~is_tri] = np.where(disc >= 0, th, np.inf)
    return t


def trace_tree(tree, o, d, tris, spheres):
    """Front-to-back kd-tree traversal with a (node, tmin, tmax) stack, as the GLSL kernel does it."""
    lo, hi = tree.bounds.astype(float)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t0, t1 = (lo - o) * inv, (hi - o) * inv
    t0 = np.where(d == 0, np.where((o >= lo) & (o <= hi), -np.inf, np.inf), t0)
    t1 = np.where(d == 0, np.where((o >= lo) & (o <= hi), np.inf, -np.inf), t1)
    tmin = max(np.minimum(t0, t1).max(), 0.0)
    tmax = np.maximum(t0, t1).min()
    best_t, best = np.inf, -1
    if tmin > tmax:
        return best_t, best
    nodes, stack, node = tree.nodes, [], 0
    while True:
        word0, word1 = int(nodes[node, 0]), int(nodes[node, 1])
        if word1 & 3 == LEAF:
            prims = tree.prim_refs[word0 : word0 + (word1 >> 2)]
            if len(prims):
                t = intersect(o, d, tris, spheres, prims)
                k = int(np.argmin(t))
                if t[k] < best_t:
                    best_t, best = t[k], int(prims[k])
            if best_t <= tmax or not stack:
                return best_t, best
            node, tmin, tmax = stack.pop()
            continue
        axis, above, below = word1 & 3, word1 >> 2, node + 1
        split = float(np.uint32(word0).view(np.float32))
        if d[axis] == 0:  # parallel to the plane: stays on the side of its origin; on it is above
            node = below if o[axis] < split else above
            continue
        t_split = (split - o[axis]) / d[axis]
        below_first = o[axis] < split or (o[axis] == split and d[axis] < 0)
        near, far = (below, above) if below_first else (above, below)
        if t_split > tmax or t_split <= 0:
            node = near
        elif t_split < tmin:
            node = far
        else:
            stack.append((far, t_split, tmax))
            assert len(stack) <= tree.max_depth
            node, tmax = near, t_split


def random_rays(rng, n, extent=2.5):
    o = rng.uniform(-extent, extent, (n, 3))
    d = rng.normal(size=(n, 3))
    # A quarter of the rays run parallel to one or two axis planes: the d == 0 paths.
    k = n // 4
    d[:k, 1] = 0
    d[k // 2 : k, 0] = 0
    # Some rays graze the ground plane from just above, and some start exactly on it.
    d[k : k + k // 2, 1] = -0.05
    o[k + k // 2 : 2 * k, 1] = 0.0
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


def aimed_rays(rng, n, radius=3.0, target=0.8):
    """Rays from a sphere around the scene towards points near its centre: most of them hit."""
    o = rng.normal(size=(n, 3))
    o *= radius / np.linalg.norm(o, axis=1, keepdims=True)
    d = rng.uniform(-target, target, (n, 3)) - o
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


def check_rays(tree, tris, spheres, rng, n=300, rays=random_rays):
    prims = np.arange(len(tris) + len(spheres))
    o_all, d_all = rays(rng, n)
    hits = 0
    for o, d in zip(o_all, d_all):
        t_brute = intersect(o, d, tris, spheres, prims)
        k = int(np.argmin(t_brute))
        t_tree, p_tree = trace_tree(tree, o, d, tris, spheres)
        assert t_tree == t_brute[k], f"ray {o}, {d}: tree hit {p_tree} at {t_tree}, brute {k} at {t_brute[k]}"
        hits += np.isfinite(t_tree)
    assert hits > n // 4  # the rays test something


# --------------------------------------------------------------------------------------------------
# Tests


def test_empty_scene_is_one_empty_leaf():
    tree = build_kdtree(np.zeros((0, 2, 3), np.float32))
    assert tree.nodes.shape == (1, 2)
    assert int(tree.nodes[0, 1]) == (0 << 2) | LEAF
    assert len(tree.prim_refs) == 0 and tree.max_depth == 0 and tree.leaf_count == 1
    assert tree.empty_leaf_count == 1 and tree.bounds.shape == (2, 3)
    assert (tree.bounds[1] > tree.bounds[0]).all()
    assert len(leaves(tree)) == 1


def test_single_primitive():
    bounds = np.array([[[0, 1, 2], [1, 1, 3]]], np.float32)  # flat in y
    tree = build_kdtree(bounds)
    assert tree.node_count == 1 and list(tree.prim_refs) == [0]
    assert (tree.bounds[0] <= bounds[0, 0]).all() and (tree.bounds[1] >= bounds[0, 1]).all()
    assert tree.bounds[1, 1] > tree.bounds[0, 1], "a zero-extent axis is padded"


def test_identical_boxes_make_one_leaf():
    bounds = np.tile(np.array([[[0, 0, 0], [1, 2, 3]]], np.float32), (50, 1, 1))
    tree = build_kdtree(bounds)
    assert tree.node_count == 1 and sorted(tree.prim_refs) == list(range(50))
    check_leaf_contents(tree, bounds)


def test_identical_points():
    bounds = np.zeros((20, 2, 3), np.float32) + 5
    tree = build_kdtree(bounds)
    assert sorted(tree.prim_refs) == list(range(20))
    assert (tree.bounds[0] < 5).all() and (tree.bounds[1] > 5).all()


def test_default_depth_limit():
    assert default_depth_limit(0) == 8 and default_depth_limit(1) == 8
    assert default_depth_limit(1_000_000) == round(8 + 1.3 * np.log2(1e6))
    assert default_depth_limit(10**12) == 40


def test_box_mode_leaves_follow_the_split_rule_exactly():
    rng = np.random.default_rng(1)
    lo = rng.uniform(-10, 10, (3000, 3))
    size = np.exp(rng.uniform(np.log(0.01), np.log(3), (3000, 3)))
    size[::7, rng.integers(0, 3)] = 0  # some flat boxes
    bounds = np.stack([lo, lo + size], 1).astype(np.float32)
    tree = build_kdtree(bounds)
    assert tree.max_depth <= tree.max_depth_limit == default_depth_limit(3000)
    assert tree.node_count > 100
    total = 0
    for _, lo_r, hi_r, prims in walk(tree):
        expect = np.flatnonzero(box_rule(bounds, lo_r, hi_r))
        assert sorted(prims) == list(expect)
        total += len(prims)
    assert total == len(tree.prim_refs) == round(tree.refs_per_prim * 3000)


def test_depth_cap_is_honoured():
    rng = np.random.default_rng(2)
    tris = triangle_soup(rng, 2000, (0.01, 0.05))
    for cap in (0, 1, 3, 6):
        tree = build_kdtree(triangle_bounds(tris), triangles=tris, max_depth_limit=cap)
        assert tree.max_depth == cap
        assert max(depth for depth, *_ in walk(tree)) == cap
        check_leaf_contents(tree, triangle_bounds(tris), tris)


def test_ground_plane_of_flat_triangles():
    tris = ground_plane(16, 4.0, 0.0)
    bounds = triangle_bounds(tris)
    assert (bounds[:, 0, 1] == bounds[:, 1, 1]).all()
    tree = build_kdtree(bounds, triangles=tris)
    assert tree.bounds[0, 1] < 0 < tree.bounds[1, 1]
    assert tree.leaf_count > 16, "a flat ground plane is still split in x and z"
    check_leaf_contents(tree, bounds, tris)
    rng = np.random.default_rng(3)
    o = rng.uniform(-2, 2, (100, 3))
    o[:, 1] = 1.0
    d = rng.normal(size=(100, 3)) * 0.3
    d[:, 1] = -1.0
    for oo, dd in zip(o, d):
        t_brute = intersect(oo, dd, tris, np.zeros((0, 4)), np.arange(len(tris))).min()
        assert trace_tree(tree, oo, dd, tris, np.zeros((0, 4)))[0] == t_brute


def test_mixed_scene_leaf_contents_and_rays():
    rng = np.random.default_rng(4)
    tris, spheres = mixed_scene(rng)
    bounds = np.concatenate([triangle_bounds(tris), sphere_bounds(spheres)])
    tree = build_kdtree(bounds, triangles=tris)
    assert tree.max_depth <= tree.max_depth_limit
    assert tree.empty_leaf_count > 0, "the empty-space bonus cuts off empty space"
    total = check_leaf_contents(tree, bounds, tris)
    assert total == len(tree.prim_refs)
    assert set(np.unique(tree.prim_refs)) == set(range(len(bounds))), "every primitive is somewhere"
    check_rays(tree, tris, spheres, rng, n=300)


def test_rays_through_a_box_mode_tree():
    """Without the triangles, the tree is built from boxes alone and must still be correct."""
    rng = np.random.default_rng(5)
    tris, spheres = mixed_scene(rng)
    bounds = np.concatenate([triangle_bounds(tris), sphere_bounds(spheres)])
    tree = build_kdtree(bounds)
    check_rays(tree, tris, spheres, rng, n=150)


def test_triangle_clipping_keeps_references_low():
    """A closed mesh: clipped triangles cost fewer references than box-only splitting."""
    rng = np.random.default_rng(6)
    tris = noisy_sphere(rng, 5, noise=0.02)  # 20480 triangles
    bounds = triangle_bounds(tris)
    clipped = build_kdtree(bounds, triangles=tris)
    boxes = build_kdtree(bounds)
    assert clipped.refs_per_prim < 0.8 * boxes.refs_per_prim
    assert clipped.sah_cost < boxes.sah_cost
    check_rays(clipped, tris, np.zeros((0, 4)), rng, n=100, rays=aimed_rays)


def test_statistics_are_consistent():
    rng = np.random.default_rng(7)
    tris = triangle_soup(rng, 1000)
    tree = build_kdtree(triangle_bounds(tris), triangles=tris)
    is_leaf = (tree.nodes[:, 1] & 3) == LEAF
    counts = tree.nodes[is_leaf, 1] >> 2
    assert tree.node_count == len(tree.nodes)
    assert tree.leaf_count == is_leaf.sum() == (tree.node_count + 1) // 2
    assert tree.empty_leaf_count == (counts == 0).sum()
    assert counts.sum() == len(tree.prim_refs)
    assert tree.refs_per_prim == pytest.approx(len(tree.prim_refs) / 1000)
    assert tree.build_seconds > 0
    # The SAH cost of a tree beats that of a single leaf holding everything.
    assert 1.0 < tree.sah_cost < tree.params["intersection_cost"] * 1000 / 4


def test_threads_build_the_same_tree(monkeypatch):
    """Levels cut into parts for worker threads, or subtrees built apart, give exactly the single-threaded tree."""
    rng = np.random.default_rng(8)
    tris, spheres = mixed_scene(rng)
    bounds = np.concatenate([triangle_bounds(tris), sphere_bounds(spheres)])
    single = build_kdtree(bounds, triangles=tris, threads=1)
    monkeypatch.setattr(bsp, "MIN_REFS_PER_THREAD", 50)
    threaded = build_kdtree(bounds, triangles=tris, threads=3)
    assert np.array_equal(single.nodes, threaded.nodes)
    assert np.array_equal(single.prim_refs, threaded.prim_refs)
    check_leaf_contents(threaded, bounds, tris)


def clip_to_half_space(tri, axis, split, sign):
    """Vertices of the part of a triangle with sign * (p[axis] - split) >= 0 (closed), in float64."""
    poly = [np.asarray(p, float) for p in tri]
    out = []
    for k in range(3):
        p, q = poly[k], poly[(k + 1) % 3]
        dp, dq = sign * (p[axis] - split), sign * (q[axis] - split)
        if dp >= 0:
            out.append(p)
        if dp * dq < 0:
            out.append(p + (q - p) * (dp / (dp - dq)))
    return np.array(out)


def test_triangle_halves_are_bounded_tightly_and_conservatively():
    """The clipped bounds of straddling triangles, against exact clipping, vertices on the plane included."""
    from lenslab.render.bsp import _triangle_half_bounds

    rng = np.random.default_rng(9)
    m = 3000
    tris = rng.uniform(-3, 3, (m, 3, 3)).astype(np.float32)
    axis = rng.integers(0, 3, m)
    split = rng.uniform(-2, 2, m).astype(np.float32)
    # Put one, two or all three vertices exactly on the plane in some of the triangles.
    for k in range(m):
        on_plane = rng.permutation(3)[: [0, 0, 1, 1, 2, 3][k % 6]]
        tris[k, on_plane, axis[k]] = split[k]
    below_lo, below_hi, above_lo, above_hi = _triangle_half_bounds(tris, axis, split)
    for k in range(m):
        d = tris[k, :, axis[k]].astype(float) - split[k]
        for sign, lo, hi, present in (
            (-1, below_lo[:, k], below_hi[:, k], (d < 0).any()),
            (1, above_lo[:, k], above_hi[:, k], (d > 0).any() or (d == 0).all()),
        ):
            if not present:
                assert np.isnan(lo).all() and np.isnan(hi).all()
                continue
            part = clip_to_half_space(tris[k], axis[k], split[k], sign)
            exact_lo, exact_hi = part.min(axis=0), part.max(axis=0)
            assert (lo <= exact_lo).all() and (hi >= exact_hi).all(), f"triangle {k} side {sign}"
            assert np.allclose(lo, exact_lo, atol=1e-4) and np.allclose(hi, exact_hi, atol=1e-4)


def test_empty_cuts_lie_on_the_geometry():
    """Cuts that leave one side empty sit on a primitive's bound, not on a bin boundary nearby."""
    rng = np.random.default_rng(10)
    lo = np.concatenate([rng.uniform(0, 1, (200, 3)), rng.uniform(40, 41, (200, 3))])
    bounds = np.stack([lo, lo + rng.uniform(0.01, 0.1, (400, 3))], 1).astype(np.float32)
    tree = build_kdtree(bounds)
    interior = (tree.nodes[:, 1] & 3) != LEAF
    splits = tree.nodes[interior, 0].view(np.float32)
    just_past = np.nextafter(bounds[:, 1].ravel(), np.float32(np.inf))
    on_geometry = np.concatenate([bounds[:, 0].ravel(), just_past])
    assert np.isin(splits, on_geometry).sum() >= 6, "the two clusters are cut free on all sides"
    check_leaf_contents(tree, bounds)


def test_bad_input_is_refused():
    good = np.array([[[0, 0, 0], [1, 1, 1]]], np.float32)
    with pytest.raises(ValueError):
        build_kdtree(np.array([[[0, 0, 0], [np.nan, 1, 1]]], np.float32))
    with pytest.raises(ValueError):
        build_kdtree(np.array([[[1, 0, 0], [0, 1, 1]]], np.float32))  # min > max
    with pytest.raises(ValueError):
        build_kdtree(good, triangles=np.zeros((2, 3, 3), np.float32))
    with pytest.raises(ValueError):
        build_kdtree(good, max_depth_limit=65)


def test_the_builders_make_trees_of_the_same_quality_with_the_same_hits(builder):
    """The compiled build against the reference levels build: the same SAH cost and references within a hair
    (their bins and rules are the same), and rays find the same first hits in both."""
    if builder != "compiled":
        pytest.skip("one comparison of the two builders")
    rng = np.random.default_rng(21)
    tris, spheres = mixed_scene(rng)
    tris = np.concatenate([tris, noisy_sphere(rng, 4, center=(0.5, 0.2, -0.3), radius=0.6)])
    bounds = np.concatenate([triangle_bounds(tris), sphere_bounds(spheres)])
    reference = build_kdtree(bounds, triangles=tris, builder="levels")
    compiled = build_kdtree(bounds, triangles=tris, builder="compiled", threads=2)
    assert reference.params["builder"] == "levels" and compiled.params["builder"] == "compiled"
    assert compiled.sah_cost <= 1.02 * reference.sah_cost
    assert compiled.refs_per_prim <= 1.02 * reference.refs_per_prim
    assert compiled.max_depth <= compiled.max_depth_limit == reference.max_depth_limit
    o_all, d_all = aimed_rays(rng, 300)
    for o, d in zip(o_all, d_all):
        assert trace_tree(compiled, o, d, tris, spheres) == trace_tree(reference, o, d, tris, spheres)


def test_the_compiled_build_stays_within_a_small_budget_and_is_exact(builder):
    if builder != "compiled":
        pytest.skip("the levels build's budget is tested in test_bounded_work.py")
    rng = np.random.default_rng(22)
    tris = np.concatenate([noisy_sphere(rng, 3)] * 4)  # four copies in one place: every split copies them
    bounds = triangle_bounds(tris)
    for threads in (1, 2):
        tree = build_kdtree(bounds, triangles=tris, builder="compiled", max_refs=2 * len(tris), threads=threads)
        assert len(tree.prim_refs) <= 2 * len(tris) and tree.budget_leaves > 0
        assert check_leaf_contents(tree, bounds, tris) == len(tree.prim_refs)
        check_rays(tree, tris, np.zeros((0, 4)), rng, n=100, rays=aimed_rays)


def test_an_unknown_builder_is_refused():
    with pytest.raises(ValueError, match="builder"):
        build_kdtree(np.zeros((1, 2, 3), np.float32), builder="fast")


def test_without_numba_the_automatic_choice_builds_with_numpy(builder, monkeypatch, hide_package):
    """A machine sent the project without numba still builds trees (and makes normals), the numpy way."""
    from lenslab.scene.io import meshes

    hide_package("numba")
    monkeypatch.setattr(bsp, "COMPILED_MIN_PRIMITIVES", 0)
    monkeypatch.setattr(meshes, "COMPILED_NORMALS_MIN_FACES", 0)
    rng = np.random.default_rng(23)
    tris = triangle_soup(rng, 200)
    assert build_kdtree(triangle_bounds(tris), triangles=tris).params["builder"] == "levels"
    normals = meshes.smooth_normals(tris.reshape(-1, 3), np.arange(3 * len(tris)).reshape(-1, 3))
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
