"""Two levels: each mesh group's kd-tree and GPU rows made once, the instance table that places them.

A scene's large meshes stay in their own space (scene/flatten.py's MeshGroup and MeshInstance), as OptiX's
geometry acceleration structures and pbrt-v4's instances do: each group's kd-tree is built over its own
triangles, and an instance is a transform, a material and the group it places. Moving, hiding or re-materialling
an object, or any edit elsewhere, then never rebuilds a group's tree nor re-packs its rows: a ``GroupCache``
keeps them from one version of the scene to the next, by the group's key (docs/architecture.md, "Two levels").

Layout in the scene's buffers (glsl/common.glsl): the groups' triangles come first in the geometry and shading
buffers, then the world's own triangles, then its spheres (a primitive is a sphere when its index is at least
``triangle_count``); the groups' trees come first in ``kd_nodes`` and ``prim_refs``, each moved to its place (its
child rows, leaf offsets and primitive numbers offset), then the world's tree, whose root is ``world_root``, then,
for a scene of many instances, a tree over the instances' world boxes whose references are instance numbers
(``instance_root``; -1 without one). The instance table (``INSTANCE_ROWS`` vec4 each) is a buffer of its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lenslab.render import kdtree_cache
from lenslab.render.bsp import KdTree, build_kdtree
from lenslab.render.gpu_layout import GEOMETRY_ROWS, INSTANCE_ROWS, INSTANCE_TREE_DEPTH, KD_LEAF, SHADING_ROWS
from lenslab.scene.flatten import FlatScene, MeshGroup

# Meshes of at least this many triangles become groups. Smaller ones join the world's own tree, where small
# scenes keep their one-level walk (and the loop over every primitive of render/features.py); a large mesh's tree
# takes long enough to build (about 10 ms per 10,000 triangles) that keeping it is worth a second tree to walk.
INSTANCE_MIN_TRIANGLES = 10_000
# From this many instances on, rays find them through a kd-tree over their world boxes instead of testing each
# (glsl/bsp.glsl's walk_instance_tree); below it the loop over all of them, which never diverges, is cheaper.
INSTANCE_TREE_MIN_INSTANCES = 8
NO_MATERIAL = -1  # a group triangle's material field: the instance's material is used (glsl/surface.glsl)
NO_LIGHT = -1


@dataclass(frozen=True)
class PackedGroup:
    """A mesh group's tree and rows, in the group's own numbering (primitive 0 is its first triangle)."""

    tree: KdTree
    geometry: np.ndarray  # (T, GEOMETRY_ROWS, 4) float32
    shading: np.ndarray  # (T, SHADING_ROWS, 4) float32


def triangle_rows(triangles: np.ndarray, normals: np.ndarray, uvs: np.ndarray, material: np.ndarray,
                  light: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The geometry rows (v0, e1 and material, e2 and light) and shading rows (normals and uvs) of triangles,
    as glsl/common.glsl reads them. ``material`` and ``light`` are per triangle (int32)."""
    count = len(triangles)
    geometry = np.empty((count, GEOMETRY_ROWS, 4), np.float32)
    geometry[:, 0, :3] = triangles[:, 0]
    geometry[:, 0, 3] = 0.0
    np.subtract(triangles[:, 1], triangles[:, 0], out=geometry[:, 1, :3])
    np.subtract(triangles[:, 2], triangles[:, 0], out=geometry[:, 2, :3])
    geometry[:, 1, 3] = np.asarray(material, np.int32).view(np.float32)
    geometry[:, 2, 3] = np.asarray(light, np.int32).view(np.float32)
    shading = np.empty((count, SHADING_ROWS, 4), np.float32)
    shading[:, :3, :3] = normals
    uv = uvs.reshape(count, 6)  # u0 v0 u1 v1 u2 v2
    shading[:, 0, 3], shading[:, 1, 3], shading[:, 2, 3] = uv[:, 0], uv[:, 1], uv[:, 2]
    shading[:, 3, :3] = uv[:, 3:6]
    shading[:, 3, 3] = 0.0
    return geometry, shading


def pack_group(group: MeshGroup) -> PackedGroup:
    """Build a group's tree (or read it from the kd-tree cache) and pack its rows."""
    tris = group.triangles
    bounds = np.stack([tris.min(axis=1), tris.max(axis=1)], axis=1) if len(tris) else np.zeros((0, 2, 3), np.float32)
    tree = kdtree_cache.kdtree(bounds, triangles=tris)
    count = len(tris)
    geometry, shading = triangle_rows(tris, group.triangle_normals, group.triangle_uvs,
                                      np.full(count, NO_MATERIAL, np.int32), np.full(count, NO_LIGHT, np.int32))
    return PackedGroup(tree, geometry, shading)


@dataclass(frozen=True)
class PlacedGroup:
    """A packed group's tree as it reads from its place in the scene's buffers (moved_tree)."""

    place: tuple[int, int, int]  # first node, first reference, first primitive
    nodes: np.ndarray
    refs: np.ndarray


class GroupCache:
    """Packed groups by key, kept from one version of a scene to the next (a RenderSession holds one).

    ``packed_groups(flat)`` packs the groups it has not seen and forgets those the scene no longer has, so that a
    removed mesh's rows do not outlive it. ``new_trees`` are the trees of the groups packed by the last call, built
    or read back from the kd-tree cache (none after an edit that moved or re-materialled objects: what tests and
    benchmarks check), ``built`` how many.
    """

    def __init__(self):
        self._packed: dict[tuple, PackedGroup] = {}
        self._groups: dict[tuple, MeshGroup] = {}
        self._placed: dict[int, PlacedGroup] = {}  # by id of the PackedGroup, while it is in _packed
        self.new_trees: list[KdTree] = []

    @property
    def built(self) -> int:
        return len(self.new_trees)

    def known_groups(self) -> dict[tuple, MeshGroup]:
        """The groups of the last scene, for flatten_scene to lend out instead of making their arrays again."""
        return dict(self._groups)

    def packed_groups(self, flat: FlatScene) -> list[PackedGroup]:
        packed, groups, self.new_trees = {}, {}, []
        for group in flat.groups:
            if group.key not in self._packed:
                self._packed[group.key] = pack_group(group)
                self.new_trees.append(self._packed[group.key].tree)
            packed[group.key], groups[group.key] = self._packed[group.key], group
        self._packed, self._groups = packed, groups
        kept = {id(group) for group in packed.values()}
        self._placed = {key: placed for key, placed in self._placed.items() if key in kept}
        return [packed[group.key] for group in flat.groups]

    def placed(self, group: PackedGroup, place: tuple[int, int, int]) -> PlacedGroup:
        """The group's tree moved to ``place``: the same arrays as last time where the place is the same."""
        placed = self._placed.get(id(group))
        if placed is None or placed.place != place:
            placed = PlacedGroup(place, *moved_tree(group.tree, *place))
            if id(group) in {id(g) for g in self._packed.values()}:
                self._placed[id(group)] = placed
        return placed


@dataclass(frozen=True)
class Layers:
    """The scene's trees and rows in the buffers' layout (see the module docstring), each buffer as its parts in
    order: a part per group, then the world's. A group's parts are the same arrays from one edit to the next
    while the groups before it are the same, so GpuScene uploads only the parts that changed."""

    kd_nodes: tuple[np.ndarray, ...]  # (M_i, 2) uint32 each
    prim_refs: tuple[np.ndarray, ...]  # (R_i,) int32 each
    geometry: tuple[np.ndarray, ...]  # (P_i, GEOMETRY_ROWS, 4) float32: the groups' triangles, the world's, its spheres
    shading: tuple[np.ndarray, ...]  # (T_i, SHADING_ROWS, 4) float32
    instances: np.ndarray  # (I, INSTANCE_ROWS, 4) float32
    instance_tree: KdTree | None  # over the instances' world boxes, when there are many (its root: instance_root)
    instance_root: int  # -1 without an instance tree
    world_root: int
    first_world_prim: int  # the world's own primitive i is row first_world_prim + i
    triangle_count: int


def moved_tree(tree: KdTree, first_node: int, first_ref: int, first_prim: int) -> tuple[np.ndarray, np.ndarray]:
    """A tree's node and reference arrays as they read from row ``first_node`` of kd_nodes, reference
    ``first_ref`` of prim_refs, with its primitives numbered from ``first_prim``."""
    nodes = tree.nodes.astype(np.uint32, copy=True)
    refs = tree.prim_refs.astype(np.int32, copy=True)
    if first_node or first_ref:
        leaf = (nodes[:, 1] & np.uint32(3)) == KD_LEAF
        nodes[leaf, 0] += np.uint32(first_ref)
        nodes[~leaf, 1] += np.uint32(first_node << 2)
    if first_prim:
        refs += np.int32(first_prim)
    return nodes, refs


def instance_rows(flat: FlatScene, roots: list[int], boxes: list[np.ndarray]) -> np.ndarray:
    """The instance table: per instance world to group space, the group's box and root, the material, and group
    space to world (glsl/common.glsl)."""
    rows = np.zeros((max(len(flat.instances), 1), INSTANCE_ROWS, 4), np.float32)
    for k, instance in enumerate(flat.instances):
        to_world = np.asarray(instance.matrix, np.float64)
        to_group = np.linalg.inv(to_world)
        rows[k, 0:3] = to_group[:3]
        rows[k, 3, :3], rows[k, 4, :3] = boxes[instance.group]
        rows[k, 3, 3] = np.int32(roots[instance.group]).view(np.float32)
        rows[k, 4, 3] = np.int32(instance.material).view(np.float32)
        rows[k, 5:8] = to_world[:3]
    return rows


def join_layers(packed_groups: list[PackedGroup], flat: FlatScene, world_tree: KdTree, world_geometry: np.ndarray,
                world_shading: np.ndarray, cache: GroupCache | None = None) -> Layers:
    """The groups' and the world's trees and rows in one set of buffers (see the module docstring). ``cache``
    keeps the groups' moved trees, so that an unchanged group gives the same arrays as last time."""
    cache = cache or GroupCache()
    node_parts, ref_parts, roots, boxes = [], [], [], []
    first_node = first_ref = first_prim = 0
    for group in packed_groups:
        placed = cache.placed(group, (first_node, first_ref, first_prim))
        node_parts.append(placed.nodes)
        ref_parts.append(placed.refs)
        roots.append(first_node)
        boxes.append(group.tree.bounds)
        first_node += len(placed.nodes)
        first_ref += len(placed.refs)
        first_prim += len(group.geometry)
    group_triangles = first_prim
    # The world's primitives follow the groups' triangles, its spheres after its triangles: every world primitive
    # moves by the groups' triangle count.
    nodes, refs = moved_tree(world_tree, first_node, first_ref, group_triangles)
    node_parts.append(nodes)
    ref_parts.append(refs)
    # Many instances: a kd-tree over their world boxes after the world's tree, its references instance numbers.
    instance_tree, instance_root = None, -1
    if len(flat.instances) >= INSTANCE_TREE_MIN_INSTANCES:
        boxes_in_world = np.array([instance.bounds for instance in flat.instances], np.float32)
        instance_tree = build_kdtree(boxes_in_world, max_depth_limit=INSTANCE_TREE_DEPTH, builder="levels")
        instance_root = first_node + len(nodes)
        top_nodes, top_refs = moved_tree(instance_tree, instance_root, first_ref + len(refs), 0)
        node_parts.append(top_nodes)
        ref_parts.append(top_refs)
    return Layers(
        kd_nodes=tuple(node_parts),
        prim_refs=tuple(ref_parts),
        geometry=(*(g.geometry for g in packed_groups), world_geometry),
        shading=(*(g.shading for g in packed_groups), world_shading),
        instances=instance_rows(flat, roots, boxes),
        instance_tree=instance_tree,
        instance_root=instance_root,
        world_root=first_node,
        first_world_prim=group_triangles,
        triangle_count=group_triangles + flat.triangle_count,
    )
