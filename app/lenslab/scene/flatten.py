"""Resolve a scene's node tree into world-space primitive arrays, the form the renderer and ray queries use.

Primitives are numbered triangles first, then spheres; ``prim_node`` maps each back to the node that made it
(so a click in the viewport can select a node).

Large meshes may instead stay in their own space (``instance_min_triangles``): each becomes a ``MeshGroup``
(its triangles once, however often it is placed) and a ``MeshInstance`` per placement (a transform), so that the
renderer keeps a kd-tree per group and moving an object, or any edit elsewhere, never rebuilds it
(docs/architecture.md, "Two levels"). The world-space arrays then hold everything else.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np

from lenslab.limits import LARGEST_NUMBER
from lenslab.scene.light_units import areas_by_material, emissive_in_nits
from lenslab.scene.materials import Emissive, Mask, Material, walk_materials
from lenslab.scene.scene import DEFAULT_MATERIAL, Node, Scene, SceneError
from lenslab.scene.shapes import Box, Cylinder, Disk, MeshFile, Rectangle, Relief, Sphere, TriangleMesh
from lenslab.scene.io.meshes import LoadedMesh, MeshLoadError, MeshPart
from lenslab.scene.transform import transform_normals, transform_points


@dataclass(frozen=True)
class MeshGroup:
    """Triangles in their own object space, placed in the world by one or more MeshInstances."""

    key: tuple  # the same key, the same triangles: (id of the source mesh, smooth); see ``source``
    triangles: np.ndarray  # (T, 3, 3) float32 object-space corners
    triangle_normals: np.ndarray  # (T, 3, 3) float32 object-space shading normals at the corners
    triangle_uvs: np.ndarray  # (T, 3, 2) float32
    object_bounds: np.ndarray  # (2, 3) float32 box around the triangles in object space
    source: object = field(repr=False, compare=False)  # the mesh it was made from, kept alive: its id is in key

    @property
    def triangle_count(self) -> int:
        return len(self.triangles)


@dataclass(frozen=True)
class MeshInstance:
    """One placement of a MeshGroup: object to world, the material of all its triangles, the node it belongs to."""

    group: int  # index into FlatScene.groups
    matrix: np.ndarray  # (4, 4) float64, object space to world
    material: int  # index into FlatScene.materials
    node: int  # index into FlatScene.nodes
    bounds: np.ndarray  # (2, 3) float32 world box (the object box's corners, transformed)


@dataclass(frozen=True)
class FlatScene:
    triangles: np.ndarray  # (T, 3, 3) float32 world-space corners
    triangle_normals: np.ndarray  # (T, 3, 3) float32 shading normals at the corners
    triangle_uvs: np.ndarray  # (T, 3, 2) float32
    triangle_material: np.ndarray  # (T,) int32 index into materials
    spheres: np.ndarray  # (S, 4) float32 centre xyz, radius
    sphere_material: np.ndarray  # (S,) int32
    materials: list[Material]
    material_names: list[str]
    prim_node: np.ndarray  # (T + S,) int32 index into nodes
    nodes: list[Node]  # every node, depth first
    warnings: tuple[str, ...] = ()  # what could not be mapped from mesh files, once per material
    # Large meshes kept in their own space (flatten_scene's instance_min_triangles); the arrays above are the rest.
    groups: tuple[MeshGroup, ...] = ()
    instances: tuple[MeshInstance, ...] = ()

    @property
    def triangle_count(self) -> int:
        """Triangles in the world-space arrays (not those of the groups: see ``placed_triangle_count``)."""
        return len(self.triangles)

    @property
    def stored_triangle_count(self) -> int:
        """Triangles the renderer stores: the world-space ones and each group's once."""
        return self.triangle_count + sum(group.triangle_count for group in self.groups)

    @property
    def placed_triangle_count(self) -> int:
        """Every triangle as the camera sees it: the world-space ones and each instance's."""
        return self.triangle_count + sum(self.groups[i.group].triangle_count for i in self.instances)

    def node_boxes(self) -> tuple[np.ndarray, np.ndarray]:
        """World boxes of every primitive and instance, (N, 2, 3), and the node of each, (N,)."""
        boxes = [self.prim_bounds()] + [i.bounds[None] for i in self.instances]
        owners = [self.prim_node] + [np.array([i.node], np.int32) for i in self.instances]
        return np.concatenate(boxes).astype(np.float32), np.concatenate(owners).astype(np.int32)

    @property
    def sphere_count(self) -> int:
        return len(self.spheres)

    @property
    def prim_count(self) -> int:
        return self.triangle_count + self.sphere_count

    def prim_bounds(self) -> np.ndarray:
        """(N, 2, 3) axis-aligned boxes, triangles then spheres."""
        tri = np.stack([self.triangles.min(axis=1), self.triangles.max(axis=1)], axis=1)
        c, r = self.spheres[:, :3], self.spheres[:, 3:4]
        sph = np.stack([c - r, c + r], axis=1)
        return np.concatenate([tri, sph]).astype(np.float32)

    def bounds(self) -> np.ndarray:
        """(2, 3) box around every primitive: the union of prim_bounds, without making them (a million
        triangles' boxes take a fifth of a second)."""
        if self.prim_count == 0 and not self.instances:
            return np.zeros((2, 3), np.float32)
        corners = self.triangles.reshape(-1, 3)
        c, r = self.spheres[:, :3], self.spheres[:, 3:4]
        placed = np.array([i.bounds for i in self.instances], np.float32).reshape(-1, 2, 3)
        low = np.concatenate([corners, c - r, placed[:, 0]]).astype(np.float32)
        high = np.concatenate([corners, c + r, placed[:, 1]]).astype(np.float32)
        return np.stack([low.min(axis=0), high.max(axis=0)])


def _flat_normals(corners: np.ndarray) -> np.ndarray:
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    return np.repeat(n[:, None, :], 3, axis=1)


def _mesh_parts(scene: Scene, node: Node, loader) -> LoadedMesh:
    shape = node.shape
    if isinstance(shape, Relief):
        fields = (tuple(v) if isinstance(v, list) else v for v in dataclasses.astuple(shape))  # hashable
        return LoadedMesh((MeshPart(_relief_mesh(*fields)),))
    if isinstance(shape, (Rectangle, Disk, Cylinder, Box)):
        return LoadedMesh((MeshPart(shape.mesh()),))
    assert isinstance(shape, MeshFile)
    path = Path(shape.file)
    if not path.is_absolute():
        path = scene.base_dir() / path
    try:
        return loader(path, shape.smooth, shape.shape_index)
    except MeshLoadError as exc:
        where = scene.source_path or "scene"
        raise SceneError(f"{where}: node '{node.name}': {exc}") from None


@lru_cache(maxsize=4)
def _relief_mesh(*fields) -> TriangleMesh:
    """A relief's mesh, kept for the next flatten: millions of triangles take a second to make, and the
    studio flattens the scene again after every edit, most of which leave the relief as it was."""
    return Relief(*fields).mesh()


def made_triangles(scene: Scene) -> tuple[int, str]:
    """How many triangles the shapes made in code (rectangles, disks, cylinders, boxes, reliefs) will have, counted
    without making them (mesh files are not read here), and which node makes the most ("" for none)."""
    counts = [(node.shape.triangle_count, node.name) for node, _ in scene.walk()
              if isinstance(node.shape, (Rectangle, Disk, Cylinder, Box, Relief))]
    return sum(count for count, _ in counts), max(counts)[1] if counts else ""


def flatten_scene(scene: Scene, mesh_loader=None, instance_min_triangles: int | None = None,
                  known_groups: dict | None = None) -> FlatScene:
    """The scene's primitives in world space; with ``instance_min_triangles``, meshes of at least that many
    triangles whose material neither emits nor cuts out stay in their own space as groups and instances
    (emitters are sampled from world-space triangles, and cut-outs are tested while the tree is walked).
    ``known_groups`` (key -> MeshGroup, from an earlier call) lends groups whose arrays need not be made again."""
    if mesh_loader is None:
        from lenslab.scene.io.meshes import load_mesh_parts as mesh_loader

    material_names = list(scene.materials)
    materials = [scene.materials[n] for n in material_names]
    default_index = None

    file_materials: dict[int, int] = {}  # id(material from a mesh file) -> index
    warnings: list[str] = []

    def material_index(node: Node, part: MeshPart | None = None) -> int:
        nonlocal default_index
        if not node.material and part is not None and part.material is not None:
            # The mesh file's own material, unless the node names one of the scene's.
            if id(part.material) not in file_materials:
                material_names.append(f"{node.name}: {part.name}" if part.name else node.name)
                materials.append(part.material)
                file_materials[id(part.material)] = len(materials) - 1
            return file_materials[id(part.material)]
        if node.material:
            if node.material not in scene.materials:
                raise SceneError(f"node '{node.name}': unknown material '{node.material}'")
            return material_names.index(node.material)
        if default_index is None:  # nodes without a material get a neutral grey
            material_names.append("(default)")
            materials.append(DEFAULT_MATERIAL)
            default_index = len(materials) - 1
        return default_index

    tris, tri_normals, tri_uvs, tri_mat, tri_node = [], [], [], [], []
    groups: list[MeshGroup] = []
    group_index: dict[tuple, int] = {}
    instances: list[MeshInstance] = []

    def instanced(mesh: TriangleMesh, matrix: np.ndarray, mat: int, node_index: int) -> bool:
        """Place a large mesh as an instance of its group, when it may be one."""
        if instance_min_triangles is None or mesh.triangle_count < instance_min_triangles:
            return False
        if any(isinstance(m, Mask) or m.emits for m in walk_materials(materials[mat])):
            return False
        key = (id(mesh), mesh.normals is not None)
        if key not in group_index:
            group = (known_groups or {}).get(key) or _mesh_group(key, mesh, nodes[node_index])
            group_index[key] = len(groups)
            groups.append(group)
        group = group_index[key]
        box = groups[group].object_bounds.astype(np.float64)
        corners = np.array([[box[i, 0], box[j, 1], box[k, 2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
        with np.errstate(over="ignore", invalid="ignore"):
            placed = transform_points(matrix, corners)
        _check_in_world(placed, nodes[node_index])
        bounds = np.stack([placed.min(axis=0), placed.max(axis=0)]).astype(np.float32)
        instances.append(MeshInstance(group, np.asarray(matrix, np.float64), mat, node_index, bounds))
        return True

    def add_mesh(mesh: TriangleMesh, matrix: np.ndarray, mat: int, node_index: int) -> None:
        if instanced(mesh, matrix, mat, node_index):
            return
        with np.errstate(over="ignore", invalid="ignore"):  # overflow is found and named just below
            corners = transform_points(matrix, mesh.vertices)[mesh.faces]
        _check_in_world(corners, nodes[node_index])
        if np.linalg.det(matrix[:3, :3]) < 0:  # a mirroring transform flips winding: keep the front face in front
            corners = corners[:, ::-1]
            faces = mesh.faces[:, ::-1]
        else:
            faces = mesh.faces
        if mesh.normals is not None:
            normals = transform_normals(matrix, mesh.normals)[faces]
        else:
            normals = _flat_normals(corners)
        uvs = mesh.uvs[faces] if mesh.uvs is not None else np.zeros((len(faces), 3, 2))
        tris.append(corners)
        tri_normals.append(normals)
        tri_uvs.append(uvs)
        tri_mat.append(np.full(len(faces), mat))
        tri_node.append(np.full(len(faces), node_index))

    spheres, sph_mat, sph_node = [], [], []
    nodes: list[Node] = []
    for node, matrix in scene.walk():
        node_index = len(nodes)
        nodes.append(node)
        if node.shape is None:
            continue
        if isinstance(node.shape, Sphere):
            mat = material_index(node)
            scale = np.linalg.norm(matrix[:3, :3], axis=0)
            if np.ptp(scale) > 1e-6 * scale.max():
                scale_text = ", ".join(f"{float(v):.6g}" for v in scale)
                raise SceneError(f"node '{node.name}': a sphere needs a uniform scale, not ({scale_text}); "
                                 "use a mesh for an ellipsoid")
            sphere = np.array([*matrix[:3, 3], node.shape.radius * scale[0]])
            _check_in_world(sphere, node)
            spheres.append(sphere)
            sph_mat.append(mat)
            sph_node.append(node_index)
            continue
        loaded = _mesh_parts(scene, node, mesh_loader)
        warnings.extend(w for w in loaded.warnings if w not in warnings)
        for part in loaded.parts:
            add_mesh(part.mesh, matrix, material_index(node, part), node_index)

    for name, material in zip(material_names, materials):
        _check_finite_material(name, material)

    def cat(parts, shape, dtype):
        return np.concatenate(parts).astype(dtype) if parts else np.zeros(shape, dtype)

    triangle_node = cat(tri_node, (0,), np.int32)
    for what, parts in (("normals", tri_normals), ("texture coordinates", tri_uvs)):
        _check_finite_attribute(what, parts, triangle_node, nodes)
    triangles, triangle_material = cat(tris, (0, 3, 3), np.float32), cat(tri_mat, (0,), np.int32)
    sphere_rows, sphere_material = np.asarray(spheres, np.float32).reshape(-1, 4), np.asarray(sph_mat, np.int32)

    return FlatScene(
        triangles=triangles,
        triangle_normals=cat(tri_normals, (0, 3, 3), np.float32),
        triangle_uvs=cat(tri_uvs, (0, 3, 2), np.float32),
        triangle_material=triangle_material,
        spheres=sphere_rows,
        sphere_material=sphere_material,
        materials=_lights_in_nits(material_names, materials, triangles, triangle_material, sphere_rows,
                                  sphere_material),
        material_names=material_names,
        prim_node=np.concatenate([triangle_node, np.asarray(sph_node, np.int32)]),
        nodes=nodes,
        warnings=tuple(warnings),
        groups=tuple(groups),
        instances=tuple(instances),
    )


def _lights_in_nits(names: list[str], materials: list[Material], triangles: np.ndarray,
                    triangle_material: np.ndarray, spheres: np.ndarray, sphere_material: np.ndarray) -> list[Material]:
    """The materials with every area light's radiance in nits: one given in lumens is spread over the world-space
    area of the shapes that carry it, known only now (scene/light_units.py). Emitters are never instanced, so the
    world-space arrays hold all of their shapes."""
    if not any(isinstance(m, Emissive) and m.unit != "nits" for held in materials for m in walk_materials(held)):
        return materials
    areas = areas_by_material(triangles, triangle_material, spheres, sphere_material, len(materials))
    converted = []
    for name, material, area in zip(names, materials, areas):
        try:
            converted.append(emissive_in_nits(material, float(area)))
        except ValueError as exc:  # a unit no file reader checked: a scene made in code
            raise SceneError(f"material '{name}': {exc}") from None
    return converted


def _mesh_group(key: tuple, mesh: TriangleMesh, node: Node) -> MeshGroup:
    """A mesh's triangles in its own space, as flatten_scene's add_mesh makes them in the world's. The checks run
    on the vertices (each once) and the arrays are gathered straight into float32: a million triangles take a
    few tenths of a second less than through float64 corners."""
    vertices = np.asarray(mesh.vertices)
    _check_in_world(vertices, node)
    for what, values in (("normals", mesh.normals), ("texture coordinates", mesh.uvs)):
        if values is not None:
            _check_finite_attribute(what, [values[mesh.faces]], np.zeros(len(mesh.faces), np.int32), [node])
    corners = vertices.astype(np.float32)[mesh.faces]
    normals = (np.asarray(mesh.normals, np.float32)[mesh.faces] if mesh.normals is not None else
               _flat_normals(corners).astype(np.float32))
    uvs = (np.asarray(mesh.uvs, np.float32)[mesh.faces] if mesh.uvs is not None else
           np.zeros((len(mesh.faces), 3, 2), np.float32))
    referenced = np.zeros(len(vertices), bool)
    referenced[mesh.faces.ravel()] = True  # vertices no face uses stay out of the box
    used = vertices[referenced] if len(mesh.faces) else np.zeros((1, 3))
    bounds = np.stack([used.min(axis=0), used.max(axis=0)]).astype(np.float32)
    return MeshGroup(key, corners, normals, uvs, bounds, source=mesh)


def _check_in_world(values: np.ndarray, node: Node) -> None:
    """Name the node whose transform carries its geometry out of what float32 can hold (or to NaN)."""
    if not np.isfinite(values).all() or np.abs(values).max(initial=0.0) > LARGEST_NUMBER:
        raise SceneError(f"node '{node.name}': its transform puts the geometry beyond the {LARGEST_NUMBER:g} "
                         f"a scene can hold (or makes it not a number)")


def _check_finite_material(name: str, material: Material) -> None:
    """A material's numbers, whichever reader they came through (a glTF's factors are JSON, which allows NaN):
    one that is not finite would turn every pixel the material touches into NaN. Materials it holds too."""
    for held in walk_materials(material):
        for f in dataclasses.fields(held):
            value = getattr(held, f.name)
            numbers = value if isinstance(value, tuple) else (value,)
            if any(isinstance(v, float) and not abs(v) <= LARGEST_NUMBER for v in numbers):
                raise SceneError(f"material '{name}': {f.name} {value} is not a finite number")


def _check_finite_attribute(what: str, parts: list[np.ndarray], triangle_node: np.ndarray, nodes: list[Node]) -> None:
    """A mesh file's own normals (OBJ ``vn``) and texture coordinates (``vt``) are read as written: name the
    node of the first triangle whose value is not a finite number, before it reaches the GPU as a NaN."""
    if not parts:
        return
    values = np.concatenate(parts) if len(parts) > 1 else parts[0]
    if np.isfinite(values).all():  # one pass over the whole array; the rows are looked at only to name one
        return
    bad = ~np.isfinite(values.reshape(len(values), -1)).all(axis=1)
    if bad.any():
        node = nodes[int(triangle_node[int(np.argmax(bad))])]
        count = int(np.count_nonzero(bad))
        raise SceneError(f"node '{node.name}': {count} {'triangle has' if count == 1 else 'triangles have'} {what} "
                         "that are not finite numbers")
