"""Triangle meshes from files (OBJ, PLY, glTF/GLB, STL and whatever else trimesh reads).

Loaded meshes are cached by (path, modification time, smooth) so that re-flattening a scene after an edit
does not re-read a large file.
"""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

import numpy as np

from dataclasses import dataclass, field

from lenslab.limits import LARGEST_NUMBER
from lenslab.scene.materials import Material
from lenslab.scene.shapes import TriangleMesh

MESH_SUFFIXES = (".obj", ".ply", ".gltf", ".glb", ".stl", ".off")


class MeshLoadError(ValueError):
    pass


@dataclass(frozen=True)
class MeshPart:
    """One piece of a mesh file with one material: the file's own material mapped onto ours, or None."""

    mesh: TriangleMesh
    material: Material | None = None
    name: str = ""


@dataclass(frozen=True)
class LoadedMesh:
    parts: tuple[MeshPart, ...]
    warnings: tuple[str, ...] = field(default=())  # what of the file's materials could not be mapped


def check_geometry(vertices: np.ndarray, faces: np.ndarray, path: Path | str) -> None:
    """Refuse what a broken exporter writes and a renderer would index out of bounds or turn into NaN:
    faces that point past the vertices, and coordinates that are not finite or absurdly large."""
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        bad = int(np.count_nonzero((faces < 0) | (faces >= len(vertices))))
        raise MeshLoadError(f"{path}: {bad} face {'index points' if bad == 1 else 'indices point'} outside the "
                            f"{len(vertices)} vertices")
    finite = np.isfinite(vertices).all(axis=-1)
    if not finite.all():
        raise MeshLoadError(f"{path}: {np.count_nonzero(~finite)} vertices have coordinates that are not "
                            f"finite numbers")
    if len(vertices) and np.abs(vertices).max() > LARGEST_NUMBER:
        raise MeshLoadError(f"{path}: coordinates up to {np.abs(vertices).max():.3g}, beyond the "
                            f"{LARGEST_NUMBER:g} a scene can hold")


def load_mesh_parts(path: Path, smooth: bool = True, shape_index: int = 0) -> LoadedMesh:
    """The mesh file as parts, one per material it uses (geometry without one: a part each, material None).

    The file's materials (OBJ+MTL, glTF 2.0) are mapped onto ours by ``mesh_materials``, which says in
    ``warnings`` what it could not map, once per material. ``shape_index`` picks one mesh of a Mitsuba
    ``.serialized`` file, the one kind that holds several.
    """
    from lenslab.scene.io.mesh_materials import load_parts  # it imports this module's MeshPart and LoadedMesh

    return load_parts(path, smooth, shape_index)


def load_mesh(path: Path, smooth: bool = True) -> TriangleMesh:
    path = Path(path)
    if not os.path.isfile(path):
        raise MeshLoadError(f"{path}: mesh file not found")
    return _load_cached(str(path.resolve()), path.stat().st_mtime_ns, smooth)


@lru_cache(maxsize=32)
def _load_cached(path: str, mtime_ns: int, smooth: bool) -> TriangleMesh:
    import trimesh  # imported here: a scene without mesh files never pays for it

    try:
        mesh = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many kinds; all mean the same to the user
        raise MeshLoadError(f"{path}: cannot read mesh ({exc})") from exc
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise MeshLoadError(f"{path}: no triangles in file")
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    check_geometry(vertices, faces, path)
    normals = np.asarray(mesh.vertex_normals, dtype=np.float64) if smooth else None
    uvs = None
    visual_uv = getattr(mesh.visual, "uv", None)
    if visual_uv is not None and len(visual_uv) == len(vertices):
        uvs = np.asarray(visual_uv, dtype=np.float64)
    return TriangleMesh(vertices, faces, normals, uvs)
