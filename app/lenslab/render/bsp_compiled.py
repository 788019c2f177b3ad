"""The SAH kd-tree of render/bsp.py built node by node in compiled code (numba), for large scenes.

The level-by-level numpy build (render/bsp.py) avoids Python loops over primitives, but each level still makes
a dozen passes over every reference through temporary arrays: four seconds per million triangles on two cores.
A compiled build does the same work in one pass per node over references that stay in the cache, and makes the
same kind of tree: the same flat layout (documented in render/bsp.py, a contract with glsl/bsp.glsl), the same
side rule for a primitive on a plane, the same binned SAH with the same constants and bin counts, the same
empty cuts snapped onto the geometry and the same exact clipping of straddling triangles. The trees are not
identical bit for bit (the levels build decides its reference budget a level at a time, this one a node at a
time), so tests compare what matters: every leaf holds what its region must hold, and rays find the same hits.

How it works
------------
Depth first, with an explicit stack of pending nodes (numba compiles loops, not deep recursion, well). The
references of the nodes waiting on the stack live in one arena: a node's references are a run of it, and
splitting the node writes its children's runs over its own (the above child's first, then the below child's),
so the arena holds only the pending nodes' references, about twice the primitives. The below child is visited
next and so lands in the row after its parent, as the layout wants; the above child patches its row number
into its parent when it is popped.

Large trees are built by two or more threads (numba releases the GIL): the top of the tree is built first,
until it has a subtree per thread and some, then the subtrees are built on a pool of threads, each into arrays of
its own, and joined with their row numbers and reference offsets moved. The tree does not depend on the number
of threads (unless the reference budget binds: each subtree then builds within its share of what is left).

The reference budget (render/bsp.py, "Bounded work") is kept per node: a split whose new references would pass
what is left becomes a leaf. Subtrees built in parallel each get a share of what is left in proportion to their
references, so the sum never passes the budget.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit

KD_LEAF = 3  # as render/gpu_layout.KD_LEAF; passed in by bsp.py, checked equal there
MIN_EXTENT = 1e-30
PAD = 2.0**-20  # triangle part bounds grow by this fraction of the coordinates' size (a few ulps)
BIN_SHRINK = 1.0 - 2.0**-20  # as bsp.py: the far face falls in the last bin despite rounding
PARALLEL_MIN_PRIMITIVES = 200_000  # below this the top's bookkeeping costs more than a second thread saves

# Build statistics, one slot each in the ``stats`` array the kernel fills.
STAT_NODES, STAT_REFS, STAT_LEAVES, STAT_EMPTY, STAT_DEPTH, STAT_BUDGET_LEAVES, STAT_USED = range(7)
STAT_COUNT = 7


# --------------------------------------------------------------------------------------------------
# Growing arrays (numba has no list of arrays that is cheap to append to)


@njit(cache=True, nogil=True)
def _grown_rows(array, needed):
    """``array`` with at least ``needed`` rows (doubled when it grows), its contents kept."""
    if needed <= array.shape[0]:
        return array
    size = max(needed, 2 * array.shape[0], 16)
    out = np.empty((size,) + array.shape[1:], array.dtype)
    out[: array.shape[0]] = array
    return out


# --------------------------------------------------------------------------------------------------
# Clipping a straddling triangle to each side of a plane


@njit(cache=True, nogil=True)
def _triangle_halves(v, axis, split, bounds):
    """Bounds of the parts of triangle ``v`` (3, 3) below and above the plane ``p[axis] = split``, into
    ``bounds`` (4, 3): below lo, below hi, above lo, above hi. Returns (below part exists, above part exists).

    As bsp._triangle_half_bounds: a part is made of the triangle's vertices on its side and the points where its
    edges cross the plane; the below part needs a vertex strictly below, the above part a vertex strictly above
    or the whole triangle in the plane (which belongs above). Padded by a few ulps to stay conservative.
    """
    d0 = v[0, axis] - split
    d1 = v[1, axis] - split
    d2 = v[2, axis] - split
    has_below = d0 < 0 or d1 < 0 or d2 < 0
    has_above = d0 > 0 or d1 > 0 or d2 > 0 or (d0 == 0 and d1 == 0 and d2 == 0)
    for c in range(3):
        bounds[0, c] = np.inf
        bounds[1, c] = -np.inf
        bounds[2, c] = np.inf
        bounds[3, c] = -np.inf
    dists = (d0, d1, d2)
    for i in range(3):
        d = dists[i]
        if d <= 0:
            for c in range(3):
                bounds[0, c] = min(bounds[0, c], v[i, c])
                bounds[1, c] = max(bounds[1, c], v[i, c])
        if d >= 0:
            for c in range(3):
                bounds[2, c] = min(bounds[2, c], v[i, c])
                bounds[3, c] = max(bounds[3, c], v[i, c])
        j = (i + 1) % 3
        dn = dists[j]
        if (d < 0 and dn > 0) or (d > 0 and dn < 0):  # the edge crosses: its point belongs to both parts
            t = d / (d - dn)
            for c in range(3):
                p = v[i, c] + t * (v[j, c] - v[i, c])
                bounds[0, c] = min(bounds[0, c], p)
                bounds[1, c] = max(bounds[1, c], p)
                bounds[2, c] = min(bounds[2, c], p)
                bounds[3, c] = max(bounds[3, c], p)
    for c in range(3):
        pad = max(abs(v[0, c]), abs(v[1, c]), abs(v[2, c])) * PAD
        bounds[0, c] -= pad
        bounds[1, c] += pad
        bounds[2, c] -= pad
        bounds[3, c] += pad
    return has_below, has_above


# --------------------------------------------------------------------------------------------------
# The binned SAH of one node


@njit(cache=True, nogil=True)
def _bin_count(count, sizes):
    """Bins per axis for a node of ``count`` references: the largest of ``sizes`` (sorted, already clipped to
    [min_bins, max_bins]) not above ``count`` clipped the same way, as bsp._Slots."""
    wanted = min(max(count, sizes[0]), sizes[-1])
    bins = sizes[0]
    for s in sizes:
        if s <= wanted:
            bins = s
    return bins


@njit(cache=True, nogil=True)
def _best_split(prim_lo, prim_hi, start, count, box_lo, box_hi, sizes, empty_bonus, starts, ends):
    """The cheapest binned SAH plane of the node whose references are ``[start, start + count)``.

    Returns (relative cost, axis, split, references of the two children together); the relative cost is
    ``P_below n_below + P_above n_above`` (times ``1 - empty_bonus`` for an empty side), inf for no split.
    Ties go to the lower axis and the lower bin, as in bsp.py.
    """
    bins = _bin_count(count, sizes)
    ex, ey, ez = box_hi[0] - box_lo[0], box_hi[1] - box_lo[1], box_hi[2] - box_lo[2]
    half_area = ex * ey + ey * ez + ez * ex
    best, best_axis, best_bin, best_empty, best_children = np.inf, -1, 0, 0, 0.0
    if bins < 2 or not half_area > 0:
        return best, 0, np.float32(0), 0.0
    inv_area = 1.0 / half_area
    # One pass over the references counts the bins of all three axes: starts[axis, b] references begin in bin
    # b, ends[axis, b] end there. An axis too thin to split gets scale 0 (all in bin 0) and is skipped below.
    x0, y0, z0 = box_lo[0], box_lo[1], box_lo[2]
    sx = np.float32(bins / ex * BIN_SHRINK) if ex > MIN_EXTENT else np.float32(0)
    sy = np.float32(bins / ey * BIN_SHRINK) if ey > MIN_EXTENT else np.float32(0)
    sz = np.float32(bins / ez * BIN_SHRINK) if ez > MIN_EXTENT else np.float32(0)
    top = bins - 1
    # Counted into two sets of counters, alternate references to each: neighbouring references tend to fall in
    # the same bin, and one set would make each count wait for the last (measured: a third faster).
    for b in range(bins):
        for axis in range(6):
            starts[axis, b] = 0
            ends[axis, b] = 0
    for r in range(start, start + count):
        k = 3 * (r & 1)
        starts[k, min(max(int(np.float32(prim_lo[r, 0] - x0) * sx), 0), top)] += 1
        starts[k + 1, min(max(int(np.float32(prim_lo[r, 1] - y0) * sy), 0), top)] += 1
        starts[k + 2, min(max(int(np.float32(prim_lo[r, 2] - z0) * sz), 0), top)] += 1
        ends[k, min(max(int(np.float32(prim_hi[r, 0] - x0) * sx), 0), top)] += 1
        ends[k + 1, min(max(int(np.float32(prim_hi[r, 1] - y0) * sy), 0), top)] += 1
        ends[k + 2, min(max(int(np.float32(prim_hi[r, 2] - z0) * sz), 0), top)] += 1
    step = 1.0 / bins
    for axis in range(3):
        e = box_hi[axis] - box_lo[axis]
        if not e > MIN_EXTENT:
            continue
        u = box_hi[(axis + 1) % 3] - box_lo[(axis + 1) % 3]
        w = box_hi[(axis + 2) % 3] - box_lo[(axis + 2) % 3]
        side = u * w * inv_area
        spread = e * (u + w) * inv_area
        n_below = 0
        n_ended = 0
        for b in range(bins - 1):  # the plane after bin b; the far face is no candidate
            n_below += starts[axis, b] + starts[axis + 3, b]
            n_ended += ends[axis, b] + ends[axis + 3, b]
            n_above = count - n_ended
            cut = (b + 1) * step * spread
            x = (side + cut) * n_below + (1 - cut) * n_above
            empty = 0
            if n_below == 0:
                empty = 1
            elif n_above == 0:
                empty = 2
            if empty:
                x *= 1 - empty_bonus
            if x < best:
                best, best_axis, best_bin, best_empty = x, axis, b, empty
                best_children = n_below + n_above
    if best_axis < 0:
        return np.inf, 0, np.float32(0), 0.0
    lo, hi = box_lo[best_axis], box_hi[best_axis]
    split = np.float32(lo + (best_bin + 1) * ((hi - lo) / bins))
    # A cut that leaves a side empty moves from its bin boundary onto the geometry (bsp._snap_empty_cuts).
    if best_empty == 1:
        geometry_lo = np.float32(np.inf)
        for r in range(start, start + count):
            geometry_lo = min(geometry_lo, prim_lo[r, best_axis])
        if lo < geometry_lo < hi:
            split = geometry_lo
    elif best_empty == 2:
        geometry_hi = np.float32(-np.inf)
        for r in range(start, start + count):
            geometry_hi = max(geometry_hi, prim_hi[r, best_axis])
        past_hi = np.nextafter(geometry_hi, np.float32(np.inf))
        if lo < past_hi < hi:
            split = past_hi
    if not (lo < split < hi):  # rounding put the plane of a tiny node on its face: useless
        return np.inf, 0, np.float32(0), 0.0
    return best, best_axis, split, best_children


# --------------------------------------------------------------------------------------------------
# Partitioning a node's references into its children


@njit(cache=True, nogil=True, inline="always")
def _put(prim, prim_lo, prim_hi, out, r, straddles, axis, split, below, exact, halves):
    """Copy reference ``r`` to row ``out`` for one side of the plane: cut at the plane when it straddles it, and
    intersected with its triangle's part on that side when ``exact`` (``halves``: _triangle_halves). Returns
    whether anything is left of it there. ``out`` may be ``r`` itself (the above side is compacted in place)."""
    p = prim[r]
    lo0, lo1, lo2 = prim_lo[r, 0], prim_lo[r, 1], prim_lo[r, 2]
    hi0, hi1, hi2 = prim_hi[r, 0], prim_hi[r, 1], prim_hi[r, 2]
    prim[out] = p
    prim_lo[out, 0], prim_lo[out, 1], prim_lo[out, 2] = lo0, lo1, lo2
    prim_hi[out, 0], prim_hi[out, 1], prim_hi[out, 2] = hi0, hi1, hi2
    if not straddles:
        return True
    if below:
        prim_hi[out, axis] = split
    else:
        prim_lo[out, axis] = split
    if not exact:
        return True
    row = 0 if below else 2
    ok = True
    for c in range(3):
        prim_lo[out, c] = max(prim_lo[out, c], halves[row, c])
        prim_hi[out, c] = min(prim_hi[out, c], halves[row + 1, c])
        ok = ok and prim_lo[out, c] <= prim_hi[out, c]
    return ok


@njit(cache=True, nogil=True)
def _partition(prim, prim_lo, prim_hi, start, count, axis, split, triangles, triangle_count, halves):
    """Split the run ``[start, start + count)`` at the plane: afterwards the above child's references are
    ``[start, start + n_above)`` and the below child's follow. Straddlers are clipped (boxes at the plane,
    triangles exactly) and dropped from a side the triangle does not reach. The arrays must have room for
    ``2 count`` rows past ``start``. Returns (n_below, n_above).

    The above child is compacted in place (each reference gives at most one above reference, so the write never
    overtakes the read); the below child is written past the run and then moved down after the above one.
    """
    below_at = start + count
    n_below = 0
    n_above = 0
    for r in range(start, start + count):
        p = prim[r]
        lo_a, hi_a = prim_lo[r, axis], prim_hi[r, axis]
        goes_below = lo_a < split
        goes_above = hi_a > split or not goes_below
        straddles = goes_below and goes_above
        exact = straddles and p < triangle_count  # a triangle: each side gets the bounds of its own part
        if exact:
            goes_below, goes_above = _triangle_halves(triangles[p], axis, split, halves)
        if goes_below and _put(prim, prim_lo, prim_hi, below_at + n_below, r, straddles, axis, split, True, exact,
                             halves):
            n_below += 1
        if goes_above and _put(prim, prim_lo, prim_hi, start + n_above, r, straddles, axis, split, False, exact,
                             halves):
            n_above += 1
    # The below run moves down after the above one: to lower or equal positions, so a forward copy is safe.
    to = start + n_above
    for k in range(n_below):
        prim[to + k] = prim[below_at + k]
        for c in range(3):
            prim_lo[to + k, c] = prim_lo[below_at + k, c]
            prim_hi[to + k, c] = prim_hi[below_at + k, c]
    return n_below, n_above


# --------------------------------------------------------------------------------------------------
# The build


@njit(cache=True, nogil=True)
def _build(prim, prim_lo, prim_hi, count, box_lo, box_hi, first_depth, triangles, triangle_count,
           traversal_cost, intersection_cost, empty_bonus, leaf_prims, sizes, depth_limit, budget,
           stop_at_refs, stats, sah):
    """Build the subtree over references ``[0, count)`` of the arena (``prim``, ``prim_lo``, ``prim_hi``),
    whose node box is ``box_lo``..``box_hi`` at depth ``first_depth``.

    ``stop_at_refs`` > 0 builds only the top of the tree: a node of at most that many references that the SAH
    would split is left open, written as a leaf of zero references whose row is listed in ``open_rows`` with its
    references (copied to ``open_prim`` ...) for another call to build. Returns (nodes, prim_refs, arena
    arrays, open node rows, their box, depth and reference runs); ``stats`` and ``sah`` (SAH cost times the root
    area, summed over nodes) are filled in.
    """
    nodes = np.empty((max(16, 4 * count // max(leaf_prims, 1)), 2), np.uint32)
    refs_out = np.empty(max(16, 2 * count), np.int32)
    node_total = 0
    ref_total = 0
    leaf_total = 0
    empty_total = 0
    deepest = 0
    budget_leaves = 0
    used = count
    area_sum = 0.0

    stack_size = 2 * (depth_limit + 2) + 2
    st_start = np.empty(stack_size, np.int64)
    st_count = np.empty(stack_size, np.int64)
    st_depth = np.empty(stack_size, np.int64)
    st_parent = np.empty(stack_size, np.int64)
    st_lo = np.empty((stack_size, 3), np.float32)
    st_hi = np.empty((stack_size, 3), np.float32)
    st_start[0], st_count[0], st_depth[0], st_parent[0] = 0, count, first_depth, -1
    st_lo[0] = box_lo
    st_hi[0] = box_hi
    top = 1  # nodes waiting on the stack: the root

    open_rows = np.empty(16, np.int64)
    open_lo = np.empty((16, 3), np.float32)
    open_hi = np.empty((16, 3), np.float32)
    open_depth = np.empty(16, np.int64)
    open_start = np.empty(16, np.int64)
    open_count = np.empty(16, np.int64)
    open_total = 0
    open_prim = np.empty(max(16, count), np.int32)
    open_lo_refs = np.empty((max(16, count), 3), np.float32)
    open_hi_refs = np.empty((max(16, count), 3), np.float32)
    open_refs = 0

    starts = np.zeros((6, sizes[-1]), np.int32)
    ends = np.zeros((6, sizes[-1]), np.int32)
    halves = np.empty((4, 3), np.float32)
    split_bits = np.empty(1, np.float32)
    lo = np.empty(3, np.float32)
    hi = np.empty(3, np.float32)

    while top > 0:
        top -= 1
        start, n, depth, parent = st_start[top], st_count[top], st_depth[top], st_parent[top]
        for c in range(3):
            lo[c] = st_lo[top, c]
            hi[c] = st_hi[top, c]
        row = node_total
        node_total += 1
        if node_total > nodes.shape[0]:
            nodes = _grown_rows(nodes, node_total)
        if parent >= 0:
            nodes[parent, 1] |= np.uint32(row << 2)
        deepest = max(deepest, depth)
        ex, ey, ez = float(hi[0] - lo[0]), float(hi[1] - lo[1]), float(hi[2] - lo[2])
        node_area = ex * ey + ey * ez + ez * ex

        split_it = n > leaf_prims and depth < depth_limit
        axis, split, children = 0, np.float32(0), 0.0
        if split_it:
            best, axis, split, children = _best_split(prim_lo, prim_hi, start, n, lo, hi, sizes, empty_bonus,
                                                      starts, ends)
            cost = traversal_cost + intersection_cost * best
            split_it = cost < intersection_cost * n
        if split_it and children > n and used + (children - n) > budget:
            split_it = False  # the new references would pass the budget: a leaf, slower but right
            budget_leaves += 1
        if split_it and stop_at_refs > 0 and n <= stop_at_refs:
            # Left for another thread: a placeholder row, and the node's references kept aside.
            if open_total == open_rows.shape[0]:
                open_rows = _grown_rows(open_rows, open_total + 1)
                open_lo = _grown_rows(open_lo, open_total + 1)
                open_hi = _grown_rows(open_hi, open_total + 1)
                open_depth = _grown_rows(open_depth, open_total + 1)
                open_start = _grown_rows(open_start, open_total + 1)
                open_count = _grown_rows(open_count, open_total + 1)
            open_prim = _grown_rows(open_prim, open_refs + n)
            open_lo_refs = _grown_rows(open_lo_refs, open_refs + n)
            open_hi_refs = _grown_rows(open_hi_refs, open_refs + n)
            open_prim[open_refs : open_refs + n] = prim[start : start + n]
            open_lo_refs[open_refs : open_refs + n] = prim_lo[start : start + n]
            open_hi_refs[open_refs : open_refs + n] = prim_hi[start : start + n]
            open_rows[open_total] = row
            open_lo[open_total] = lo
            open_hi[open_total] = hi
            open_depth[open_total] = depth
            open_start[open_total] = open_refs
            open_count[open_total] = n
            open_total += 1
            open_refs += n
            nodes[row, 0] = 0
            nodes[row, 1] = np.uint32(KD_LEAF)
            continue
        if not split_it:
            nodes[row, 0] = np.uint32(ref_total)
            nodes[row, 1] = np.uint32((n << 2) | KD_LEAF)
            if ref_total + n > refs_out.shape[0]:
                refs_out = _grown_rows(refs_out, ref_total + n)
            for k in range(n):
                refs_out[ref_total + k] = prim[start + k]
            ref_total += n
            leaf_total += 1
            if n == 0:
                empty_total += 1
            area_sum += node_area * intersection_cost * n
            continue

        area_sum += node_area * traversal_cost
        split_bits[0] = split
        nodes[row, 0] = split_bits.view(np.uint32)[0]
        nodes[row, 1] = np.uint32(axis)
        needed = start + 2 * n
        if needed > prim.shape[0]:
            prim = _grown_rows(prim, needed)
            prim_lo = _grown_rows(prim_lo, needed)
            prim_hi = _grown_rows(prim_hi, needed)
        n_below, n_above = _partition(prim, prim_lo, prim_hi, start, n, axis, split, triangles, triangle_count,
                                      halves)
        used += n_below + n_above - n
        # Above waits on the stack (its row patched into this one when it is popped); below is next.
        for side in range(2):  # 0: above, 1: below
            st_start[top] = start if side == 0 else start + n_above
            st_count[top] = n_above if side == 0 else n_below
            st_depth[top] = depth + 1
            st_parent[top] = row if side == 0 else -1
            for c in range(3):
                st_lo[top, c] = lo[c]
                st_hi[top, c] = hi[c]
            if side == 0:
                st_lo[top, axis] = split
            else:
                st_hi[top, axis] = split
            top += 1

    stats[STAT_NODES] = node_total
    stats[STAT_REFS] = ref_total
    stats[STAT_LEAVES] = leaf_total
    stats[STAT_EMPTY] = empty_total
    stats[STAT_DEPTH] = deepest
    stats[STAT_BUDGET_LEAVES] = budget_leaves
    stats[STAT_USED] = used
    sah[0] = area_sum
    return (nodes[:node_total], refs_out[:ref_total], open_rows[:open_total], open_lo[:open_total],
            open_hi[:open_total], open_depth[:open_total], open_start[:open_total], open_count[:open_total],
            open_prim[:open_refs], open_lo_refs[:open_refs], open_hi_refs[:open_refs])


@njit(cache=True, nogil=True)
def _join(top_nodes, top_refs, open_rows, sub_nodes, sub_refs, sub_node_counts, sub_ref_counts):
    """Join the subtrees built apart into the top's placeholders, depth first.

    Each placeholder row is replaced by its subtree, whose rows and reference offsets are moved; rows after a
    placeholder move down by the subtree's size less one. ``sub_nodes`` and ``sub_refs`` are the subtrees'
    arrays one after another, ``sub_*_counts`` their lengths, in the order of ``open_rows`` (increasing).
    """
    total_nodes = top_nodes.shape[0] + sub_nodes.shape[0] - open_rows.shape[0]
    nodes = np.empty((total_nodes, 2), np.uint32)
    refs = np.empty(top_refs.shape[0] + sub_refs.shape[0], np.int32)
    # New row of every top row: shifted by the subtrees inserted before it.
    top_count = top_nodes.shape[0]
    new_row = np.empty(top_count + 1, np.int64)
    shift = 0
    k = 0
    for r in range(top_count + 1):
        new_row[r] = r + shift
        if k < open_rows.shape[0] and open_rows[k] == r:
            shift += sub_node_counts[k] - 1
            k += 1
    # The top's rows, its interior links renumbered; its leaves' references laid out in depth-first order
    # with each subtree's references where its placeholder stood.
    ref_at = 0
    k = 0
    sub_node_first = 0
    sub_ref_first = 0
    for r in range(top_count):
        w0, w1 = top_nodes[r, 0], top_nodes[r, 1]
        at = new_row[r]
        if k < open_rows.shape[0] and open_rows[k] == r:
            sn, sr = sub_node_counts[k], sub_ref_counts[k]
            for i in range(sn):
                v0, v1 = sub_nodes[sub_node_first + i, 0], sub_nodes[sub_node_first + i, 1]
                if (v1 & 3) == KD_LEAF:
                    nodes[at + i, 0] = np.uint32(v0 + ref_at)
                    nodes[at + i, 1] = v1
                else:
                    nodes[at + i, 0] = v0
                    nodes[at + i, 1] = np.uint32((((v1 >> 2) + at) << 2) | (v1 & 3))
            refs[ref_at : ref_at + sr] = sub_refs[sub_ref_first : sub_ref_first + sr]
            ref_at += sr
            sub_node_first += sn
            sub_ref_first += sr
            k += 1
        elif (w1 & 3) == KD_LEAF:
            count = w1 >> 2
            nodes[at, 0] = np.uint32(ref_at)
            nodes[at, 1] = w1
            refs[ref_at : ref_at + count] = top_refs[w0 : w0 + count]
            ref_at += count
        else:
            nodes[at, 0] = w0
            nodes[at, 1] = np.uint32((new_row[w1 >> 2] << 2) | (w1 & 3))
    return nodes, refs


def build(prim_bounds, triangles, root, *, traversal_cost, intersection_cost, empty_bonus, leaf_prims, sizes,
          depth_limit, max_refs, workers, leaf_code):
    """Build the tree; returns (nodes, prim_refs, max_depth, leaf_count, empty_leaf_count, budget_leaves,
    SAH cost relative to the root's area). See render/bsp.build_kdtree for the parameters."""
    assert leaf_code == KD_LEAF
    count = len(prim_bounds)
    arena = max(16, 2 * count)
    prim = np.empty(arena, np.int32)
    prim[:count] = np.arange(count, dtype=np.int32)
    prim_lo = np.empty((arena, 3), np.float32)
    prim_hi = np.empty((arena, 3), np.float32)
    prim_lo[:count] = prim_bounds[:, 0]
    prim_hi[:count] = prim_bounds[:, 1]
    tris = triangles if triangles is not None else np.zeros((0, 3, 3), np.float32)
    sizes = np.asarray(sizes, np.int64)
    constants = (float(traversal_cost), float(intersection_cost), float(empty_bonus), int(leaf_prims), sizes,
                 int(depth_limit))
    root_lo, root_hi = root[0].astype(np.float32), root[1].astype(np.float32)
    # With threads: the top of the tree first, leaving open the nodes of at most a slice of the references,
    # so that there are several subtrees per thread to even out their sizes.
    stop_at = max(1, count // (4 * workers)) if workers > 1 and count >= PARALLEL_MIN_PRIMITIVES else 0
    stats = np.zeros(STAT_COUNT, np.int64)
    sah = np.zeros(1)
    top = _build(prim, prim_lo, prim_hi, count, root_lo, root_hi, 0, tris, len(tris), *constants,
                 int(max_refs), stop_at, stats, sah)
    nodes, refs, open_rows, open_lo, open_hi, open_depth, open_start, open_count, open_prim, open_los, open_his = top
    leaves, empty, deepest, budget_leaves = int(stats[STAT_LEAVES]), int(stats[STAT_EMPTY]), int(stats[STAT_DEPTH]), \
        int(stats[STAT_BUDGET_LEAVES])
    area_sum = float(sah[0])
    if len(open_rows):
        # What is left of the budget, shared in proportion to the subtrees' references.
        left = int(max_refs) - int(stats[STAT_USED])
        total_open = int(open_count.sum())

        def subtree(k):
            start, n = int(open_start[k]), int(open_count[k])
            room = max(16, 2 * n)
            sub_prim = np.empty(room, np.int32)
            sub_lo = np.empty((room, 3), np.float32)
            sub_hi = np.empty((room, 3), np.float32)
            sub_prim[:n] = open_prim[start : start + n]
            sub_lo[:n] = open_los[start : start + n]
            sub_hi[:n] = open_his[start : start + n]
            share = n + left * n // max(total_open, 1)
            sub_stats = np.zeros(STAT_COUNT, np.int64)
            sub_sah = np.zeros(1)
            result = _build(sub_prim, sub_lo, sub_hi, n, open_lo[k], open_hi[k], int(open_depth[k]), tris, len(tris),
                            *constants, share, 0, sub_stats, sub_sah)
            return result[0], result[1], sub_stats, float(sub_sah[0])

        # Largest first, so that the last subtree to start is a small one.
        order = np.argsort(-open_count, kind="stable")
        with ThreadPoolExecutor(workers) as pool:
            built = dict(zip(order.tolist(), pool.map(subtree, order.tolist())))
        parts = [built[k] for k in range(len(open_rows))]
        for _, _, sub_stats, sub_area in parts:
            leaves += int(sub_stats[STAT_LEAVES])
            empty += int(sub_stats[STAT_EMPTY])
            deepest = max(deepest, int(sub_stats[STAT_DEPTH]))
            budget_leaves += int(sub_stats[STAT_BUDGET_LEAVES])
            area_sum += sub_area
        nodes, refs = _join(nodes, refs, open_rows, np.concatenate([p[0] for p in parts]),
                            np.concatenate([p[1] for p in parts]),
                            np.array([len(p[0]) for p in parts], np.int64),
                            np.array([len(p[1]) for p in parts], np.int64))
    extent = (root[1] - root[0]).astype(np.float64)
    root_area = float(extent[0] * extent[1] + extent[1] * extent[2] + extent[2] * extent[0])
    sah_cost = area_sum / root_area if root_area > 0 else 0.0
    return np.ascontiguousarray(nodes), np.ascontiguousarray(refs), deepest, leaves, empty, budget_leaves, sah_cost

