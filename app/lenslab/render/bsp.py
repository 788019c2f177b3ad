"""SAH kd-tree (axis-aligned BSP) built level by level in numpy, flattened for a GPU traversal.

A kd-tree splits space, not primitives: every interior node cuts its box in two with an axis-aligned
plane, and a primitive that straddles the plane is referenced by both children. Rays walk the tree front
to back and can stop at the first leaf that holds a hit closer than the leaf's far end, which makes
kd-trees the fastest acceleration structure for static scenes traced on a GPU with a short stack.

The flat layout (a contract with ``glsl/bsp.glsl``)
---------------------------------------------------
``nodes`` is an (M, 2) uint32 array, one 8-byte node per row, root at row 0, in depth-first order:

* interior node: ``nodes[i, 0]`` holds the float32 bits of the split position,
  ``nodes[i, 1] = (above_child << 2) | axis`` with ``axis`` in {0, 1, 2}. The *below* child, the region
  with ``p[axis] < split``, is always row ``i + 1``; ``above_child`` is the row of the region with
  ``p[axis] >= split``.
* leaf: ``nodes[i, 1] = (prim_count << 2) | 3`` and ``nodes[i, 0]`` is the offset of the leaf's first
  entry in ``prim_refs``; the leaf's primitives are ``prim_refs[offset : offset + prim_count]``.

``bounds`` is the root box. The depth of the tree never exceeds ``max_depth_limit``. The GPU traversal
(glsl/bsp.glsl) needs no stack of that depth: it keeps a short one and restarts from the root when it runs dry.

Which side gets a primitive
---------------------------
The below region is open at the plane and the above region is closed: a point exactly on the plane
belongs above. A primitive (with box ``[lo, hi]`` on the split axis) goes below when ``lo < split`` and
above when ``hi > split`` or ``lo >= split``. Hence a box that only touches the plane from below stays
below alone, and a flat primitive lying in the plane (``lo == hi == split``) goes above alone, which is
where a ray travelling inside the plane (direction component 0, origin on the plane) is sent.

The build
---------
The surface area heuristic (MacDonald and Booth 1990; pbrt-v3 section 4.4) estimates the cost of a
split as ``C_trav + C_isect * (1 - bonus) * (P_below N_below + P_above N_above)`` where ``P`` is the
child's surface area over the node's, and compares it with the leaf cost ``C_isect * N``. ``bonus`` is
pbrt's empty-space bonus, granted to cuts that leave one side empty: cutting away empty space is what
makes kd-trees fast. Candidate planes are the boundaries of a few bins per axis (binned SAH, Wald and
Havran 2006) rather than all primitive edges, so one level costs a handful of whole-array passes.

A per-node recursive build in Python costs minutes per million triangles, so the build here works one
*level* at a time: all references of all nodes of a level live in flat arrays, grouped by node, and
every step (binning, prefix sums, choosing the best plane, partitioning) is a whole-array numpy
operation over (node, axis, bin) keys. Python loops run over levels and axes, and over bins where a
step is one operation on a whole row of nodes; never over primitives or nodes one at a time.

Per level: count references per (node, axis, bin) with ``bincount`` over flat keys, sweep prefix
sums over the bins for every node at once, pick each node's cheapest plane, make leaves of nodes whose
best split does not beat the leaf cost, and partition the references into the next level. A node
with at most ``leaf_prims`` references, or at the depth cap, is a leaf without asking the SAH. A
cut that leaves one side empty is moved from its bin boundary onto the geometry, as an exact-edge
SAH would place it.

When a triangle straddles a plane, each copy gets the bounds of the part of the triangle on its own
side, intersected with its previous (already clipped) bounds. That keeps the references tight (a
triangle crossing one corner of a node does not drag the whole node into the next SAH decisions) and
drops the reference entirely when the triangle's box crosses the plane but the triangle does not.
Spheres, and all primitives when no triangles are given, are clipped as boxes.

Bounded work
------------
Some inputs make every split copy references without end: ten coplanar disks of 4,096 thin fan triangles
all meeting at one centre grew by 40% per level, 32 M references at depth 23 from 41 k triangles,
and the build died of memory. So the tree holds at most ``reference_budget(N)`` references, about
``REFS_PER_PRIM_LIMIT`` per primitive plus ``REFS_FLOOR`` and fewer where memory is short (checked before
the build allocates anything large). Each level counts the references its splits would add (the binned SAH
knows how many references each child gets); while they fit in what is left of the budget they all go ahead,
and when they do not, the splits that save the most SAH cost per added reference go ahead and the rest
become leaves. A leaf is always a correct answer, only a slower one: the tree degrades, it never fails.
Splits that add no reference (empty cuts, clean partitions) are never held back. Per level the work is
bounded by the budget and the depth by ``max_depth_limit``, so the whole build is too. Shipped scenes stay
far below the budget (``marbles_on_sand``: 4.4 references per triangle) and build the same tree as before.

Large levels are cut into runs of whole nodes handled by worker threads (numpy releases the GIL in
its loops); the result does not depend on the number of threads. Finally the level-order tree is
renumbered depth first with prefix sums over subtree sizes.

Measured on this project's 2-core machine (``benchmarks/bsp_build.py``, a 1M-triangle terrain and
a 1M-triangle bumpy torus): 7.5 to 10 s of CPU per build, 3.6 to 4 references per triangle, and in a
Python replica of the GLSL traversal about 55 traversal steps and 8 triangle tests per ray.
"""

from __future__ import annotations

import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import nullcontext
from dataclasses import dataclass, field

import numpy as np

from lenslab.render.gpu_layout import KD_LEAF as LEAF  # the two low bits of nodes[i, 1] of a leaf (axes: 0-2)
from lenslab.limits import SceneTooLarge, available_memory_bytes, format_bytes

# Default SAH constants, in units of one traversal step.
#
# INTERSECTION_COST: a triangle test reads three vec4s and does about twenty flops; a traversal step
# reads one 8-byte node, branches and may touch the stack. On llvmpipe, whose eight lanes run in
# lockstep like a GPU's, a step measured about as dear as two triangle tests (114 M tests/s brute
# force, about 50 M steps/s in a kd-tree kernel), so 1.5 rather than pbrt's CPU-tuned 80.
#
# EMPTY_BONUS: with the depth cap below, pbrt's 0.5 spends the depth on thin empty slices: at 1M
# triangles its leaves hold dozens of triangles (64 triangle tests per ray against 13 with 0.3, in a
# Python replica of the GLSL traversal). Wald and Havran's 0.2 saves a few more tests per ray but
# costs about 50% more references and three times the build time at 1M triangles.
#
# LEAF_PRIMS: nodes with this many references or fewer are leaves without asking the SAH. 6 rather
# than 4: the same steps plus tests per ray (within 1%), 15% fewer references, a faster build.
TRAVERSAL_COST = 1.0
INTERSECTION_COST = 1.5
EMPTY_BONUS = 0.3
LEAF_PRIMS = 6

# The reference budget (see "Bounded work"): REFS_PER_PRIM_LIMIT per primitive plus REFS_FLOOR. Twice the
# 4.4 per triangle of a million-triangle terrain (scenes/marbles_on_sand), so real scenes never meet it; the
# floor lets small scenes split freely, and a million references build in about a second.
REFS_PER_PRIM_LIMIT = 8
REFS_FLOOR = 1 << 20
# Peak memory of the build per reference of the budget: a level's references (32 bytes each), the indices,
# masks and clipped bounds of their partition, the next level's copy, the SAH's keys and the leaves' runs.
# Measured with tracemalloc: 206 bytes on ten coplanar disks of 4,096 segments (the budget reached, nearly
# every reference clipped at every level), 140 on marbles_on_sand's million triangles; rounded up.
BUILD_BYTES_PER_REF = 256

# The builders (build_kdtree's ``builder``). The compiled one costs a fraction of a second to load its machine code
# from numba's cache (seconds to compile it the first time on a machine), which the numpy build of a small scene
# does not take: 20,000 primitives build in about 0.2 s either way.
BUILDERS = ("auto", "levels", "compiled")
COMPILED_MIN_PRIMITIVES = 20_000

MIN_REFS_PER_THREAD = 100_000  # smaller levels are not worth handing to threads
MIN_EXTENT = np.float32(1e-30)  # nodes thinner than this are not split along that axis


@dataclass(frozen=True)
class KdTree:
    """A flattened kd-tree; see the module docstring for the layout of ``nodes`` and ``prim_refs``."""

    nodes: np.ndarray  # (M, 2) uint32
    prim_refs: np.ndarray  # (R,) int32
    bounds: np.ndarray  # (2, 3) float32, [min, max] of the root
    max_depth: int  # deepest level reached, root = 0
    max_depth_limit: int  # the cap the build honoured
    build_seconds: float
    node_count: int
    leaf_count: int
    empty_leaf_count: int
    refs_per_prim: float  # R / N
    sah_cost: float  # expected cost of a ray through the root, in traversal-step units
    reference_limit: int  # the budget the build honoured (see "Bounded work")
    budget_leaves: int  # nodes the SAH would have split that became leaves to stay within it (0: none)
    params: dict = field(default_factory=dict, compare=False)
    from_cache: bool = field(default=False, compare=False)  # read back by render/kdtree_cache.py, not built


def default_depth_limit(prim_count: int) -> int:
    """The depth cap: ``min(40, round(8 + 1.3 log2 N))``. The GPU stack is sized from it."""
    return int(min(40, round(8 + 1.3 * math.log2(max(prim_count, 1)))))


def reference_budget(prim_count: int, memory_bytes: int | None = None) -> int:
    """The most references a tree of ``prim_count`` primitives may hold: ``REFS_PER_PRIM_LIMIT`` per primitive
    plus ``REFS_FLOOR``, or what ``memory_bytes`` holds at ``BUILD_BYTES_PER_REF`` each when that is less.

    Raises SceneTooLarge when the memory cannot hold even one reference per primitive: no tree fits then.
    """
    wanted = REFS_PER_PRIM_LIMIT * prim_count + REFS_FLOOR
    if memory_bytes is None:
        return wanted
    fits = int(memory_bytes // BUILD_BYTES_PER_REF)
    if fits < prim_count:
        raise SceneTooLarge(
            f"building the kd-tree of {prim_count:,} primitives needs at least "
            f"{format_bytes(prim_count * BUILD_BYTES_PER_REF)} of memory, and {format_bytes(memory_bytes)} "
            "is available; simplify the meshes or free memory"
        )
    return min(wanted, fits)


def build_kdtree(
    prim_bounds: np.ndarray,
    *,
    triangles: np.ndarray | None = None,
    traversal_cost: float = TRAVERSAL_COST,
    intersection_cost: float = INTERSECTION_COST,
    empty_bonus: float = EMPTY_BONUS,
    max_bins: int = 64,
    min_bins: int = 4,
    leaf_prims: int = LEAF_PRIMS,
    max_depth_limit: int | None = None,
    max_refs: int | None = None,
    memory_bytes: int | None = None,
    threads: int | None = None,
    builder: str = "auto",
) -> KdTree:
    """Build an SAH kd-tree over primitives given by their boxes.

    prim_bounds: (N, 2, 3) float32 boxes ``[min, max]``, one per primitive; the row is the primitive
        index stored in ``prim_refs``. Flat boxes (a triangle in an axis plane) are fine.
    triangles: optional (T, 3, 3) vertices of the first T primitives; used to clip straddling triangles
        exactly to each side of a split, which keeps references per triangle low.
    traversal_cost, intersection_cost, empty_bonus: the SAH constants (see module docstring).
    max_bins, min_bins: split candidates per axis and node are the inner boundaries of about one
        equal bin per reference, at least ``min_bins`` and at most ``max_bins``.
    leaf_prims: a node with this many references or fewer becomes a leaf without evaluating the SAH.
    max_depth_limit: depth cap (root = 0); ``default_depth_limit(N)`` when None.
    max_refs: the most references the tree may hold (at least N); ``reference_budget(N, memory_bytes)``
        when None. Splits that would pass it become leaves (see "Bounded work").
    memory_bytes: what the build may allocate; the memory available now (``limits.available_memory_bytes``)
        when None. SceneTooLarge when it cannot hold even the references of an unsplit tree.
    threads: worker threads (numpy and the compiled build release the GIL); default: the usable CPU cores.
    builder: ``"levels"`` (this module's numpy build, the reference), ``"compiled"`` (render/bsp_compiled.py,
        node by node in numba: several times faster on large scenes) or ``"auto"``: compiled from
        ``COMPILED_MIN_PRIMITIVES`` primitives, where it pays for loading its compiled code.
    """
    start = time.perf_counter()
    prim_bounds = np.ascontiguousarray(prim_bounds, dtype=np.float32).reshape(-1, 2, 3)
    prim_count = len(prim_bounds)
    if not np.isfinite(prim_bounds).all() or (prim_bounds[:, 0] > prim_bounds[:, 1]).any():
        raise ValueError("primitive boxes must be finite with min <= max")
    if triangles is not None:
        triangles = np.ascontiguousarray(triangles, dtype=np.float32).reshape(-1, 3, 3)
        if len(triangles) > prim_count:
            raise ValueError("more triangles than primitive boxes")
    depth_limit = default_depth_limit(prim_count) if max_depth_limit is None else int(max_depth_limit)
    if not 0 <= depth_limit <= 64:
        raise ValueError("max_depth_limit must lie in [0, 64]")
    if not 2 <= min_bins <= max_bins:
        raise ValueError("need 2 <= min_bins <= max_bins")
    if memory_bytes is None:
        memory_bytes = available_memory_bytes()
    limit = reference_budget(prim_count, memory_bytes) if max_refs is None else int(max_refs)
    if limit < prim_count:
        raise ValueError(f"max_refs ({limit:,}) must be at least the number of primitives ({prim_count:,})")
    costs = _Costs(float(traversal_cost), float(intersection_cost), float(empty_bonus))
    workers = _worker_count(threads)
    params = _Params(costs, int(leaf_prims), int(min_bins), int(max_bins), depth_limit, workers)
    budget = _RefBudget(limit, prim_count)

    if builder not in BUILDERS:
        raise ValueError(f"builder must be one of {', '.join(BUILDERS)}, not {builder!r}")
    root = root_bounds(prim_bounds)
    params_record = dict(traversal_cost=costs.traversal, intersection_cost=costs.intersection,
                         empty_bonus=costs.empty_bonus, max_bins=max_bins, min_bins=min_bins, leaf_prims=leaf_prims)
    if builder == "compiled" or (builder == "auto" and prim_count >= COMPILED_MIN_PRIMITIVES and compiled_available()):
        tree = _build_compiled(prim_bounds, triangles, root, costs, params, limit, min_bins, max_bins, start,
                               params_record)
        # The compiled build keeps the budget node by node, depth first; when it binds (rare: geometry piled up
        # in one place), the levels build spends it where it saves most, near the root (see "Bounded work").
        if builder == "compiled" or tree.budget_leaves == 0:
            return tree
    refs = _Refs(
        node=np.zeros(prim_count, np.int32),
        prim=np.arange(prim_count, dtype=np.int32),
        lo=np.ascontiguousarray(prim_bounds[:, 0].T),
        hi=np.ascontiguousarray(prim_bounds[:, 1].T),
    )

    with ThreadPoolExecutor(params.workers) if params.workers > 1 else nullcontext() as pool:
        levels = _build_levels(refs, root, triangles, params, budget, pool)

    nodes, prim_refs = _flatten(levels)
    leaf_counts = np.concatenate([lv.counts[lv.is_leaf] for lv in levels])
    return KdTree(
        nodes=nodes,
        prim_refs=prim_refs,
        bounds=root,
        max_depth=len(levels) - 1,
        max_depth_limit=depth_limit,
        build_seconds=time.perf_counter() - start,
        node_count=len(nodes),
        leaf_count=len(leaf_counts),
        empty_leaf_count=int(np.count_nonzero(leaf_counts == 0)),
        refs_per_prim=len(prim_refs) / max(prim_count, 1),
        sah_cost=_tree_sah_cost(levels, root, costs),
        reference_limit=limit,
        budget_leaves=budget.leaves_made,
        params={**params_record, "builder": "levels"},
    )


def compiled_available() -> bool:
    """Whether numba (a dependency, but a device machine may be sent the project without it) can be imported:
    ``builder="auto"`` builds with numpy where it cannot."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def _build_compiled(prim_bounds, triangles, root, costs: _Costs, params: _Params, limit: int, min_bins: int,
                    max_bins: int, start: float, params_record: dict) -> KdTree:
    """The same tree's build in render/bsp_compiled.py (numba)."""
    from lenslab.render import bsp_compiled

    sizes = np.unique(np.clip(_Slots.SIZES, min_bins, max_bins))
    nodes, prim_refs, deepest, leaf_count, empty_leaves, budget_leaves, sah_cost = bsp_compiled.build(
        prim_bounds, triangles, root, traversal_cost=costs.traversal, intersection_cost=costs.intersection,
        empty_bonus=costs.empty_bonus, leaf_prims=params.leaf_prims, sizes=sizes, depth_limit=params.depth_limit,
        max_refs=limit, workers=params.workers, leaf_code=LEAF)
    if len(prim_refs) >= 2**30 or len(nodes) >= 2**30:
        raise ValueError("tree too large for 30-bit child indices and counts")
    prim_count = len(prim_bounds)
    return KdTree(nodes=nodes, prim_refs=prim_refs, bounds=root, max_depth=deepest,
                  max_depth_limit=params.depth_limit, build_seconds=time.perf_counter() - start,
                  node_count=len(nodes), leaf_count=leaf_count, empty_leaf_count=empty_leaves,
                  refs_per_prim=len(prim_refs) / max(prim_count, 1), sah_cost=sah_cost, reference_limit=limit,
                  budget_leaves=budget_leaves, params={**params_record, "builder": "compiled"})


def _build_levels(refs: _Refs, root: np.ndarray, triangles, params: _Params, budget: _RefBudget,
                  pool) -> list[_Level]:
    """The build proper: one iteration per tree level, each a few whole-array passes.

    ``refs`` always holds the references of the current level's nodes that are not leaves yet; the
    references of a leaf go to its level's ``leaf_chunks`` as soon as the leaf is known. ``budget``
    turns splits into leaves where their new references would pass the reference budget.
    """
    costs = params.costs
    counts = np.array([len(refs)])
    level = _Level(root[0][:, None].copy(), root[1][:, None].copy(), counts, params.forced_leaves(counts, 0))
    levels = [level]
    if level.is_leaf[0]:
        level.leaf_chunks.append((refs.node, refs.prim))
        return levels
    while True:
        # The SAH decides for the nodes still open. Runs of whole nodes go to the worker threads.
        parts = _node_parts(refs.node, len(level.counts), params.workers)

        def best_splits(part):
            k0, k1, r0, r1 = part
            in_part = refs.slice(r0, r1, node_offset=k0)
            return _best_splits(in_part, level.lo[:, k0:k1], level.hi[:, k0:k1], params)

        best = zip(*_map(pool, best_splits, parts))
        cost, level.axis, level.split, child_refs = (np.concatenate(c) for c in best)
        level.is_leaf |= ~(cost < costs.intersection * level.counts)
        level.is_leaf |= budget.held_back(level, cost, child_refs, costs)
        if level.is_leaf.all():
            level.leaf_chunks.append((refs.node, refs.prim))
            return levels

        # Partition the references into the children, in three steps (see _PartSplit).
        child = np.cumsum(~level.is_leaf, dtype=np.int32) - 1  # below child's index; above is S + child
        next_counts = np.zeros(2 * (int(child[-1]) + 1), np.int64)

        def split_part(part):
            return _PartSplit(refs.slice(part[2], part[3]), level, child, next_counts, triangles)

        splits = _map(pool, split_part, parts)
        budget.spend(int(next_counts.sum()) - int(level.counts[~level.is_leaf].sum()))
        next_is_leaf = params.forced_leaves(next_counts, len(levels))
        remaining = np.array(_map(pool, lambda split: split.drop_leaf_refs(next_is_leaf), splits))
        # All parts' below references first, then all above ones: the next level in node order.
        sizes = np.concatenate([remaining[:, 0], remaining[:, 1]])
        starts = np.cumsum(sizes) - sizes
        refs = _Refs.empty(int(sizes.sum()))
        _map(pool, lambda i: splits[i].write(refs, starts[i], starts[len(splits) + i]), range(len(splits)))

        next_level = _Level(*_child_boxes(level), next_counts, next_is_leaf)
        for split in splits:
            level.leaf_chunks.append(split.leaf_chunk)
            next_level.leaf_chunks.extend(split.next_leaf_chunks)
        level = next_level
        levels.append(level)
        if len(refs) == 0:
            return levels


def _worker_count(threads: int | None) -> int:
    """Threads to use: as asked, or the CPU cores this process may run on (at most 8)."""
    if threads is not None:
        return max(1, int(threads))
    try:
        return max(1, min(8, len(os.sched_getaffinity(0))))
    except AttributeError:  # not on Linux
        return max(1, min(8, os.cpu_count() or 1))


def _node_parts(ref_node: np.ndarray, node_count: int, workers: int):
    """Cut a level into about equal runs of references that never split a node's run.

    Returns (first node, end node, first ref, end ref) per part; the parts cover all nodes.
    """
    ref_count = len(ref_node)
    wanted = max(1, min(workers, ref_count // MIN_REFS_PER_THREAD))
    cuts = np.searchsorted(ref_node, ref_node[np.arange(1, wanted) * ref_count // wanted])
    ref_cuts = np.unique(np.concatenate([[0], cuts, [ref_count]]))
    node_cuts = np.concatenate([[0], ref_node[ref_cuts[1:-1]], [node_count]])
    return [
        (int(node_cuts[i]), int(node_cuts[i + 1]), int(ref_cuts[i]), int(ref_cuts[i + 1]))
        for i in range(len(ref_cuts) - 1)
    ]


def _map(pool, function, items):
    """``[function(item) for item in items]``, on the pool's threads when there is more than one."""
    if pool is None or len(items) == 1:
        return [function(item) for item in items]
    return list(pool.map(function, items))


def root_bounds(prim_bounds: np.ndarray) -> np.ndarray:
    """Union of the primitive boxes, padded so that no axis has zero extent.

    Every axis grows by a few ulps, so that geometry on the root's faces stays strictly inside it under
    the rounding of a ray-box test; an axis of zero extent (a ground plane of flat triangles) grows by
    1e-4 of the largest extent, or by 1e-4 when the whole scene is a point.
    """
    if len(prim_bounds) == 0:
        lo = np.zeros(3, np.float32)
        hi = np.zeros(3, np.float32)
    else:
        lo = prim_bounds[:, 0].min(axis=0)
        hi = prim_bounds[:, 1].max(axis=0)
    extent = hi - lo
    largest = float(extent.max())
    flat_pad = 1e-4 * largest if largest > 0 else 1e-4
    pad = np.where(extent > 0, 0, flat_pad).astype(np.float32)
    pad += 4 * np.maximum(np.spacing(np.abs(lo)), np.spacing(np.abs(hi)))
    return np.stack([lo - pad, hi + pad]).astype(np.float32)


# --------------------------------------------------------------------------------------------------
# Build state


@dataclass(frozen=True)
class _Costs:
    traversal: float
    intersection: float
    empty_bonus: float


@dataclass(frozen=True)
class _Params:
    costs: _Costs
    leaf_prims: int
    min_bins: int
    max_bins: int
    depth_limit: int
    workers: int

    def forced_leaves(self, counts: np.ndarray, depth: int) -> np.ndarray:
        """Nodes that are leaves whatever the SAH says: few references, or at the depth cap."""
        return (counts <= self.leaf_prims) | (depth >= self.depth_limit)


class _RefBudget:
    """What is left of the reference budget (see "Bounded work") as the levels are built.

    ``used`` counts the references the tree holds so far: those of the leaves made and of the nodes still
    open, one per primitive at the root. A level's splits add what their children get beyond their own.
    """

    def __init__(self, limit: int, prim_count: int):
        self.limit = limit
        self.used = prim_count
        self.leaves_made = 0  # nodes made leaves to stay within the budget

    def held_back(self, level: _Level, cost, child_refs, costs: _Costs) -> np.ndarray:
        """Which nodes of the level become leaves rather than split, so that the new references fit.

        Splits that add none always go ahead. When those that add some overrun what is left, they go
        ahead in order of SAH cost saved (weighted by the node's area, the chance a ray visits it) per
        added reference while they fit; the rest are held back.
        """
        added = np.where(level.is_leaf, 0, np.rint(child_refs).astype(np.int64) - level.counts)
        adds = np.flatnonzero(added > 0)
        room = self.limit - self.used
        held = np.zeros(len(added), bool)
        if int(added[adds].sum()) <= room:
            return held
        area = _half_area((level.hi - level.lo)[:, adds].astype(np.float64))
        saving = (costs.intersection * level.counts[adds] - cost[adds]) * area
        order = adds[np.argsort(-saving / added[adds], kind="stable")]
        fits = np.cumsum(added[order]) <= room  # a prefix: every entry adds at least one reference
        held[order[~fits]] = True
        self.leaves_made += int(np.count_nonzero(held))
        return held

    def spend(self, added: int) -> None:
        """Count the references a level's partition added (exact; the binned counts can be off by a few)."""
        self.used += added


class _Refs:
    """The primitive references of one level, grouped by node (``node`` is non-decreasing).

    ``lo`` and ``hi`` are (3, R) so that one axis is one contiguous row; they are the reference's
    bounds clipped to its node's box (and, for triangles, to the part of the triangle inside it).
    """

    __slots__ = ("node", "prim", "lo", "hi")

    def __init__(self, node, prim, lo, hi):
        self.node, self.prim, self.lo, self.hi = node, prim, lo, hi

    def __len__(self) -> int:
        return len(self.node)

    def slice(self, start: int, end: int, node_offset: int = 0) -> _Refs:
        node = self.node[start:end]
        if node_offset:
            node = node - node_offset
        return _Refs(node, self.prim[start:end], self.lo[:, start:end], self.hi[:, start:end])

    @staticmethod
    def empty(count: int) -> _Refs:
        bounds = (np.empty((3, count), np.float32), np.empty((3, count), np.float32))
        return _Refs(np.empty(count, np.int32), np.empty(count, np.int32), *bounds)


class _Level:
    """One level of the tree in level order: node boxes, decisions, and the references of its leaves.

    The i-th interior node (in node order) has its below child at index i of the next level and its
    above child at index ``S + i``, S being the number of interior nodes. With that numbering, keeping
    the order of the references when partitioning leaves the next level grouped by node again.
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray, counts: np.ndarray, is_leaf: np.ndarray):
        self.lo, self.hi, self.counts, self.is_leaf = lo, hi, counts, is_leaf
        self.axis = np.zeros(len(counts), np.int8)
        self.split = np.zeros(len(counts), np.float32)
        self.leaf_chunks: list[tuple[np.ndarray, np.ndarray]] = []  # (node, prim), grouped by node


# --------------------------------------------------------------------------------------------------
# Choosing the split planes of one level


def _best_splits(refs: _Refs, node_lo, node_hi, params: _Params):
    """Binned SAH for every node (boxes ``node_lo``, ``node_hi``, (3, K)) of a level at once.

    Returns per node the best split's cost (inf where there is none), axis, position, and how many
    references its two children get together (more than the node's where references straddle the plane).
    """
    costs = params.costs
    node_count = node_lo.shape[1]
    slots = _Slots(np.bincount(refs.node, minlength=node_count), params.min_bins, params.max_bins)
    extent = node_hi - node_lo
    half_area = _half_area(extent)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_area = np.where(half_area > 0, 1 / half_area, np.nan).astype(np.float32)

    ref_first = slots.first[refs.node]
    ref_origin = np.take(node_lo, refs.node, axis=1)  # all three axes in one gather
    axis_cost = np.full((3, node_count), np.inf, np.float32)
    axis_bin = np.zeros((3, node_count), np.int64)
    axis_empty = np.zeros((3, node_count), np.int8)
    axis_children = np.zeros((3, node_count), np.float32)
    for axis in range(3):
        e = extent[axis]
        splittable = e > MIN_EXTENT
        with np.errstate(divide="ignore", invalid="ignore"):
            # Shrunk by 2^-20 so that the node's far face, where bounds may lie, still falls in the
            # last bin despite rounding: no clamping needed, as bounds never leave their node.
            bins_per_unit = np.where(splittable, slots.bins / e * (1 - 2.0**-20), 0).astype(np.float32)
        origin, scale = ref_origin[axis], bins_per_unit[refs.node]
        starts = _bin_histogram(refs.lo[axis], origin, scale, ref_first, slots.count)
        ends = _bin_histogram(refs.hi[axis], origin, scale, ref_first, slots.count)
        for group in slots.groups:
            nodes = group.nodes
            u, v = extent[(axis + 1) % 3, nodes], extent[(axis + 2) % 3, nodes]
            with np.errstate(invalid="ignore"):
                side = u * v * inv_area[nodes]
                spread = np.where(splittable[nodes], e[nodes] * (u + v) * inv_area[nodes], np.nan)
            cost, bin_, empty, children = _cheapest_planes(group, starts, ends, side, spread, costs.empty_bonus)
            axis_cost[axis, nodes], axis_bin[axis, nodes], axis_empty[axis, nodes] = cost, bin_, empty
            axis_children[axis, nodes] = children

    axis = np.argmin(np.where(np.isnan(axis_cost), np.inf, axis_cost), axis=0)  # first axis on ties
    nodes = np.arange(node_count)
    best, bin_ = axis_cost[axis, nodes], axis_bin[axis, nodes]
    lo, hi = node_lo[axis, nodes], node_hi[axis, nodes]
    split = (lo + (bin_ + 1) * ((hi - lo) / slots.bins)).astype(np.float32)
    # Rounding can put the plane of a tiny node on its face; such a split would be useless.
    inside = (split > lo) & (split < hi) & (slots.bins > 1) & np.isfinite(best)
    cost = costs.traversal + costs.intersection * best.astype(np.float64)
    split = _snap_empty_cuts(refs, axis, split, axis_empty[axis, nodes], lo, hi, slots.refs_per_node)
    return np.where(inside, cost, np.inf), axis.astype(np.int8), split, axis_children[axis, nodes]


def _snap_empty_cuts(refs: _Refs, axis, split, empty, lo, hi, refs_per_node):
    """Move the planes of cuts that leave one side empty onto the geometry.

    A bin boundary leaves a sliver of empty space next to the geometry that a later level would cut
    away again. Snapped to the references' lowest ``lo`` (below side empty: all of them have
    ``lo >= split`` and go above) or just past their highest ``hi`` (above side empty), one cut
    removes all of it: tighter empty cuts leave more of the depth budget for real splits (measured:
    about 10% fewer traversal steps plus triangle tests per ray). ``empty`` is 1 where the below side
    is empty, 2 where the above side is, per node.
    """
    if not empty.any():
        return split
    nodes = np.flatnonzero(refs_per_node > 0)
    first = (np.cumsum(refs_per_node) - refs_per_node)[nodes]
    geometry_lo = np.full(len(split), np.inf, np.float32)
    geometry_hi = np.full(len(split), -np.inf, np.float32)
    geometry_lo[nodes] = np.minimum.reduceat(refs.lo, first, axis=1)[axis[nodes], np.arange(len(nodes))]
    geometry_hi[nodes] = np.maximum.reduceat(refs.hi, first, axis=1)[axis[nodes], np.arange(len(nodes))]
    past_hi = np.nextafter(geometry_hi, np.float32(np.inf))
    split = np.where((empty == 1) & (geometry_lo > lo) & (geometry_lo < hi), geometry_lo, split)
    split = np.where((empty == 2) & (past_hi > lo) & (past_hi < hi), past_hi, split)
    return split.astype(np.float32)


class _SlotGroup:
    """Nodes with the same number of bins; their counts form a (bins, nodes) block of the histogram."""

    def __init__(self, bins: int, nodes: np.ndarray, start: int):
        self.bins, self.nodes, self.start = bins, nodes, start

    def block(self, histogram: np.ndarray) -> np.ndarray:
        """The group's counters as a float32 (bins, nodes) array with contiguous rows."""
        end = self.start + self.bins * len(self.nodes)
        node_major = histogram[self.start : end].reshape(len(self.nodes), self.bins)
        return np.ascontiguousarray(node_major.T, dtype=np.float32)


class _Slots:
    """Where the (node, bin) counters of a level live in one flat histogram.

    Node k gets ``B_k`` bins per axis, about one per reference (within [min_bins, max_bins]) and
    rounded down to one of a few sizes. The counter of (node k, bin b) is ``first[k] + b``, so the
    bin of every reference is one integer key and counting is one ``bincount`` (references are
    grouped by node, so its writes stay local). Nodes of the same size form a group whose counters,
    transposed to a (bins, nodes) block, let the SAH sweep over bins with whole-row operations and
    per-node values broadcast along the rows.
    """

    SIZES = np.array([1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32, 40, 48, 64, 96, 128, 192, 256])

    def __init__(self, refs_per_node: np.ndarray, min_bins: int, max_bins: int):
        self.refs_per_node = refs_per_node
        sizes = np.unique(np.clip(self.SIZES, min_bins, max_bins))
        wanted = np.clip(refs_per_node, min_bins, max_bins)
        size_index = np.searchsorted(sizes, wanted, side="right") - 1
        size_index[refs_per_node == 0] = -1  # no references: no counters, no split
        self.bins = np.where(refs_per_node > 0, sizes[np.maximum(size_index, 0)], 1)
        self.first = np.zeros(len(refs_per_node), np.int64)
        self.groups: list[_SlotGroup] = []
        start = 0
        for index, bins in enumerate(sizes):
            nodes = np.flatnonzero(size_index == index)
            if len(nodes):
                self.first[nodes] = start + bins * np.arange(len(nodes))
                self.groups.append(_SlotGroup(int(bins), nodes, start))
                start += int(bins) * len(nodes)
        self.count = start


def _cheapest_planes(group: _SlotGroup, starts, ends, side, spread, empty_bonus):
    """Best plane of every node of a group along one axis: (relative cost, bin below the plane,
    1 or 2 where the plane leaves the below or the above side empty, else 0, references of the two
    children together).

    The relative cost is ``(cost - C_trav) / C_isect``, i.e. ``P_below n_below + P_above n_above``
    (times ``1 - empty_bonus`` when one side is empty), NaN where the axis cannot be split. With e
    the node's extent along the axis and u, v the others, half its area is e (u + v) + u v, and the
    below child has e scaled by frac, so with side = u v / A and spread = e (u + v) / A:
    P_below = side + frac spread and P_above = 1 - frac spread.
    """
    bins = group.bins
    if bins < 2:
        nothing = np.zeros(len(group.nodes), np.int64)
        return np.full(len(group.nodes), np.nan, np.float32), nothing, nothing.astype(np.int8), nothing
    # Running sums over the bins: references starting at or below bin b are below the plane after
    # it, those ending above bin b are above it. Exact in float32 (per-node counts).
    n_below = group.block(starts)
    n_ended = group.block(ends)
    for b in range(1, bins):
        n_below[b] += n_below[b - 1]
        n_ended[b] += n_ended[b - 1]
    n_below, n_above = n_below[:-1], n_ended[-1] - n_ended[:-1]  # the far face is no candidate

    frac = (np.arange(1, bins, dtype=np.float32) / bins)[:, None]
    with np.errstate(invalid="ignore"):
        x = n_below - n_above
        x *= frac * spread.astype(np.float32)
        x += n_above
        x += side.astype(np.float32) * n_below
        empty = np.minimum(n_below, n_above) == 0
        np.multiply(x, np.float32(1 - empty_bonus), out=x, where=empty)
    cheapest = x.min(axis=0)
    # The first bin reaching the minimum (a loop over bins, each step a whole row).
    at = np.zeros(len(group.nodes), np.int64)
    for b in range(bins - 2, -1, -1):
        np.copyto(at, b, where=x[b] == cheapest)
    columns = np.arange(len(at))
    below, above = n_below[at, columns], n_above[at, columns]
    empty = np.where(below == 0, 1, np.where(above == 0, 2, 0))
    return cheapest, at, empty.astype(np.int8), below + above


def _bin_histogram(coord, origin, scale, first, slot_count) -> np.ndarray:
    """Count references per (node, bin) counter for one bound (min or max) on one axis."""
    t = coord - origin  # >= 0: bounds never leave their node's box
    t *= scale
    key = t.astype(np.int64)
    key += first
    return np.bincount(key, minlength=slot_count)


def _half_area(extent: np.ndarray) -> np.ndarray:
    """Half the surface area of boxes with extents (3, K)."""
    x, y, z = extent
    return x * y + y * z + z * x


# --------------------------------------------------------------------------------------------------
# Partitioning the references of one level into the next


class _PartSplit:
    """Sends the references of one part of a level (runs of whole nodes) on to the next level.

    Three steps, so that parts can run in threads and still fill one next-level array in node order:
    the constructor picks each reference's side(s), clips the straddlers and counts references per
    child; ``drop_leaf_refs`` sets aside those of children that are leaves from the start (few
    references, or the depth cap); ``write`` copies the others into place.
    """

    def __init__(self, refs: _Refs, level: _Level, child, next_counts, triangles):
        self.refs = refs
        in_leaf = level.is_leaf[refs.node]  # decided by the SAH: the references stop here
        leaf = np.flatnonzero(in_leaf)
        self.leaf_chunk = (refs.node[leaf], refs.prim[leaf])

        axis = level.axis[refs.node].astype(np.intp)
        split = level.split[refs.node]
        lo, hi = _pick_rows(refs.lo, axis), _pick_rows(refs.hi, axis)
        starts_below = lo < split
        reaches_above = hi > split
        above = (reaches_above | ~starts_below) & ~in_leaf
        below = starts_below & ~in_leaf
        straddle = np.flatnonzero(below & reaches_above)

        clipped = _clip_straddlers(refs, straddle, axis[straddle], split[straddle], triangles)
        below_lo, below_hi, below_ok, above_lo, above_hi, above_ok = clipped
        below[straddle[~below_ok]] = False
        above[straddle[~above_ok]] = False

        # This part's children are contiguous ranges of the next level: count into those slices.
        # (child[k] is the number of interior nodes before k, for interior k; none has no refs.)
        first_child = child[refs.node[0]] + level.is_leaf[refs.node[0]]
        end_child = child[refs.node[-1]] + 1
        interior_count = len(next_counts) // 2
        self.sides = []
        for goes, part_lo, part_hi, ok, offset in (
            (below, below_lo, below_hi, below_ok, 0),
            (above, above_lo, above_hi, above_ok, interior_count),
        ):
            index = np.flatnonzero(goes)
            node = child[refs.node[index]] + np.int32(offset)
            clip_at = np.searchsorted(index, straddle[ok])  # where the straddlers are in ``index``
            self.sides.append([index, node, clip_at, part_lo[:, ok], part_hi[:, ok]])
            lo_child = offset + first_child
            counts = np.bincount(node - lo_child, minlength=end_child - first_child)
            next_counts[lo_child : offset + end_child] = counts

    def drop_leaf_refs(self, next_is_leaf: np.ndarray):
        """Set aside the references of children that are leaves; returns how many remain per side."""
        self.next_leaf_chunks = []
        remaining = []
        for side in self.sides:
            index, node, clip_at, clip_lo, clip_hi = side
            to_leaf = next_is_leaf[node]
            if to_leaf.any():
                self.next_leaf_chunks.append((node[to_leaf], self.refs.prim[index[to_leaf]]))
                kept = ~to_leaf
                new_position = np.cumsum(kept) - 1
                clip_kept = kept[clip_at]
                clip_at = new_position[clip_at[clip_kept]]
                side[:] = [index[kept], node[kept], clip_at, clip_lo[:, clip_kept], clip_hi[:, clip_kept]]
            remaining.append(len(side[0]))
        return remaining

    def write(self, out: _Refs, below_start: int, above_start: int):
        """Copy the remaining references into ``out`` from the given positions, clipped bounds too."""
        refs = self.refs
        for (index, node, clip_at, clip_lo, clip_hi), start in zip(self.sides, (below_start, above_start)):
            where = slice(start, start + len(index))
            out.node[where] = node
            np.take(refs.prim, index, out=out.prim[where], mode="clip")
            for axis in range(3):
                np.take(refs.lo[axis], index, out=out.lo[axis, where], mode="clip")
                np.take(refs.hi[axis], index, out=out.hi[axis, where], mode="clip")
            out.lo[:, start + clip_at] = clip_lo
            out.hi[:, start + clip_at] = clip_hi


def _pick_rows(rows: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """``rows[axis[i], i]`` for a (3, R) array whose rows are contiguous (maybe a column slice).

    One ``take`` from a flat view of the rows' memory; twice as fast as fancy indexing or choose.
    """
    item = rows.itemsize
    assert rows.strides[1] == item and rows.strides[0] % item == 0
    row_stride = rows.strides[0] // item
    flat = np.lib.stride_tricks.as_strided(rows, shape=(2 * row_stride + rows.shape[1],), strides=(item,))
    return flat.take(axis * row_stride + np.arange(rows.shape[1]))


def _child_boxes(level: _Level):
    """Boxes of the next level's nodes: the interior nodes' boxes cut at their planes."""
    interior = ~level.is_leaf
    count = int(interior.sum())
    axis = level.axis[interior].astype(np.intp)
    split = level.split[interior]
    columns = np.arange(count)
    node_lo = np.concatenate([level.lo[:, interior], level.lo[:, interior]], axis=1)
    node_hi = np.concatenate([level.hi[:, interior], level.hi[:, interior]], axis=1)
    node_hi[axis, columns] = split
    node_lo[axis, count + columns] = split
    return node_lo, node_hi


def _clip_straddlers(refs: _Refs, index, axis, split, triangles):
    """Bounds of the below and above parts of the references ``index`` that straddle their plane.

    Boxes are simply cut at the plane. Triangles are cut exactly (see ``_triangle_half_bounds``) and
    the result intersected with the box they had, which may leave one side empty: the triangle's box
    crossed the plane but the triangle, inside this node, does not.
    Returns (below_lo, below_hi, below_ok, above_lo, above_hi, above_ok), bounds as (3, S).
    """
    columns = np.arange(len(index))
    below_lo, above_hi = np.take(refs.lo, index, axis=1), np.take(refs.hi, index, axis=1)
    above_lo, below_hi = below_lo.copy(), above_hi.copy()
    below_hi[axis, columns] = split
    above_lo[axis, columns] = split
    if triangles is not None and len(index):
        prim = refs.prim[index]
        is_triangle = prim < len(triangles)
        tri = slice(None) if is_triangle.all() else np.flatnonzero(is_triangle)
        parts = _triangle_half_bounds(triangles[prim[tri]], axis[tri], split[tri])
        for bound, part, keep in zip(
            (below_lo, below_hi, above_lo, above_hi), parts, (np.maximum, np.minimum) * 2
        ):
            if isinstance(tri, slice):
                keep(bound, part, out=bound)
            else:
                bound[:, tri] = keep(bound[:, tri], part)
    below_ok = (below_lo <= below_hi).all(axis=0)  # False where NaN marks an empty part
    above_ok = (above_lo <= above_hi).all(axis=0)
    return below_lo, below_hi, below_ok, above_lo, above_hi, above_ok


def _triangle_half_bounds(vertices, axis, split):
    """Bounds (3, m) of the parts of m triangles below and above their planes ``p[axis] = split``.

    The part of a triangle on one side is the polygon made of its vertices on that side and the points
    where its edges cross the plane; its bounds are those points' bounds. The below part is empty
    unless a vertex lies strictly below; the above part is empty unless a vertex lies strictly above,
    or the triangle lies in the plane (which belongs to the above region). Crossing points are
    computed in float32, so all bounds are padded by a few ulps to stay conservative. Empty parts get
    NaN bounds.
    """
    m = len(vertices)
    # (vertex, coordinate, triangle): the last axis is long, so reductions over the others are cheap.
    v = np.ascontiguousarray(vertices.transpose(1, 2, 0))
    dist = np.take_along_axis(v, np.broadcast_to(axis, (3, 1, m)), axis=1)[:, 0] - split  # (3, m)
    v_next, dist_next = np.roll(v, -1, axis=0), np.roll(dist, -1, axis=0)  # edge i runs i -> i + 1
    crosses = ((dist < 0) & (dist_next > 0)) | ((dist > 0) & (dist_next < 0))
    with np.errstate(divide="ignore", invalid="ignore"):  # garbage where no edge crosses; unused
        t = dist / (dist - dist_next)
        crossing = v + t[:, None] * (v_next - v)
    points = np.concatenate([v, crossing])  # (6, 3, m)

    has_below = (dist < 0).any(axis=0)
    in_plane = (dist == 0).all(axis=0)
    has_above = (dist > 0).any(axis=0) | in_plane
    use_below = np.concatenate([(dist <= 0) & has_below, crosses])  # (6, m)
    use_above = np.concatenate([(dist >= 0) & has_above, crosses])

    pad = np.abs(v).max(axis=0) * np.float32(2.0**-20)  # (3, m), about 8 ulps

    def bounds(use):
        # NaN for the points not used: fmin and fmax skip them, and give NaN when all are.
        masked = np.where(use[:, None], points, np.float32(np.nan))
        return np.fmin.reduce(masked, axis=0) - pad, np.fmax.reduce(masked, axis=0) + pad

    return (*bounds(use_below), *bounds(use_above))


# --------------------------------------------------------------------------------------------------
# Flattening


def _flatten(levels: list[_Level]):
    """Renumber the level-order tree depth first and write the node and reference arrays."""
    # Subtree sizes, bottom up: an interior node is itself plus its two children's subtrees.
    sizes = [None] * len(levels)
    below_size = [None] * len(levels)
    next_size = np.zeros(0, np.int64)
    for d in range(len(levels) - 1, -1, -1):
        lv = levels[d]
        size = np.ones(len(lv.counts), np.int64)
        split_count = int((~lv.is_leaf).sum())
        if split_count:
            below_size[d] = next_size[:split_count]
            size[~lv.is_leaf] += next_size[:split_count] + next_size[split_count:]
        sizes[d] = next_size = size
    node_total = int(sizes[0][0])

    # Depth-first indices, top down: below child right after its parent, above child after the
    # below child's whole subtree.
    dfs = [np.zeros(1, np.int64)]
    for d, lv in enumerate(levels[:-1]):
        parent = dfs[d][~lv.is_leaf]
        dfs.append(np.concatenate([parent + 1, parent + 1 + below_size[d]]))

    nodes = np.zeros((node_total, 2), np.uint32)
    for d, lv in enumerate(levels):
        interior = ~lv.is_leaf
        if interior.any():
            above = dfs[d + 1][int(interior.sum()) :]
            at = dfs[d][interior]
            nodes[at, 0] = lv.split[interior].view(np.uint32)
            nodes[at, 1] = (above.astype(np.uint32) << 2) | lv.axis[interior].astype(np.uint32)

    # Leaves: reference runs laid out in depth-first order.
    leaf_at = np.concatenate([dfs[d][lv.is_leaf] for d, lv in enumerate(levels)])
    leaf_count = np.concatenate([lv.counts[lv.is_leaf] for lv in levels]).astype(np.int64)
    order = np.argsort(leaf_at)
    offset_of_node = np.zeros(node_total, np.int64)
    offsets = np.cumsum(leaf_count[order]) - leaf_count[order]
    offset_of_node[leaf_at[order]] = offsets
    if leaf_count.sum() >= 2**30 or node_total >= 2**30:
        raise ValueError("tree too large for 30-bit child indices and counts")
    nodes[leaf_at, 0] = offset_of_node[leaf_at].astype(np.uint32)
    nodes[leaf_at, 1] = (leaf_count.astype(np.uint32) << 2) | LEAF

    prim_refs = np.empty(int(leaf_count.sum()), np.int32)
    for d, lv in enumerate(levels):
        for node, prim in lv.leaf_chunks:
            prim_refs[offset_of_node[dfs[d][node]] + _rank_in_group(node)] = prim
    return nodes, prim_refs


def _rank_in_group(sorted_keys: np.ndarray) -> np.ndarray:
    """For a non-decreasing array, the position of each element within its run of equal keys."""
    n = len(sorted_keys)
    if n == 0:
        return np.zeros(0, np.int64)
    starts = np.flatnonzero(np.concatenate([[True], sorted_keys[1:] != sorted_keys[:-1]]))
    lengths = np.diff(np.concatenate([starts, [n]]))
    return np.arange(n) - np.repeat(starts, lengths)


def _tree_sah_cost(levels: list[_Level], root: np.ndarray, costs: _Costs) -> float:
    """SAH cost of the finished tree relative to its root area (what a random ray is expected to pay)."""
    root_area = float(_half_area((root[1] - root[0])[:, None].astype(np.float64))[0])
    total = 0.0
    for lv in levels:
        area = _half_area((lv.hi - lv.lo).astype(np.float64))
        per_node = np.where(lv.is_leaf, costs.intersection * lv.counts, costs.traversal)
        total += float((area * per_node).sum())
    return total / root_area if root_area > 0 else 0.0
