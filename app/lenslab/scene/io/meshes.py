"""Triangle meshes from files (OBJ, PLY, glTF/GLB, STL and whatever else trimesh reads).

Loaded meshes are cached by (path, modification time, smooth) so that re-flattening a scene after an edit
does not re-read a large file.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from dataclasses import dataclass, field

from lenslab.image_files import not_a_file
from lenslab.limits import LARGEST_NUMBER
from lenslab.scene.materials import Material
from lenslab.scene.shapes import TriangleMesh

MESH_SUFFIXES = (".obj", ".ply", ".gltf", ".glb", ".stl", ".off")
COMPILED_NORMALS_MIN_FACES = 200_000


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


def smooth_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit vertex normals, each the mean of its faces' normals weighted by the face's angle at the vertex
    (Thuermer and Wuethrich 1998, as trimesh and Mitsuba make them). Faces of zero area add nothing; a vertex
    that only such faces use gets a zero normal (glsl/surface.glsl then shades with the face's own).

    Whole-array numpy in float32 (the precision the GPU shades with): one gather, one bincount per coordinate;
    several times faster than trimesh's vertex_normals, which builds a sparse matrix and hashes its arrays. Meshes
    of ``COMPILED_NORMALS_MIN_FACES`` or more go to the same sum in compiled code (normals_compiled.py), which
    is faster again once numba's machine code is loaded (a fraction of a second, once a process).
    """
    if len(faces) >= COMPILED_NORMALS_MIN_FACES:
        try:
            from lenslab.scene.io.normals_compiled import smooth_normals as compiled
        except ImportError:  # numba missing (a device machine sent the project without it): numpy's way below
            pass
        else:
            return compiled(np.ascontiguousarray(vertices), np.ascontiguousarray(faces))
    corners = np.asarray(vertices, np.float32)[faces]  # (F, 3, 3)
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, bc, ca = b - a, c - b, a - c  # edge k runs from corner k to corner k + 1
    normal = np.cross(ab, -ca)
    length = np.sqrt(np.einsum("fc,fc->f", normal, normal))
    with np.errstate(invalid="ignore", divide="ignore"):
        normal /= np.where(length > 0, length, np.inf)[:, None]
    # The angle at each corner, between the edges leaving and arriving there: atan2(|a x b|, a . b), where
    # |a x b| is twice the face's area at every corner.
    angles = np.arctan2(length[:, None], -np.stack([np.einsum("fc,fc->f", ab, ca), np.einsum("fc,fc->f", bc, ab),
                                                    np.einsum("fc,fc->f", ca, bc)], axis=1))
    summed = np.empty((len(vertices), 3), np.float32)
    index = faces.ravel()
    for k in range(3):
        weights = (angles * normal[:, k, None]).ravel()
        summed[:, k] = np.bincount(index, weights=weights, minlength=len(vertices))
    norm = np.sqrt(np.einsum("vc,vc->v", summed, summed))
    with np.errstate(invalid="ignore", divide="ignore"):
        summed /= np.where(norm > 0, norm, np.inf)[:, None]
    return summed


def load_mesh_parts(path: Path, smooth: bool = True, shape_index: int = 0) -> LoadedMesh:
    """The mesh file as parts, one per material it uses (geometry without one: a part each, material None).

    The file's materials (OBJ+MTL, glTF 2.0) are mapped onto ours by ``mesh_materials``, which says in
    ``warnings`` what it could not map, once per material. ``shape_index`` picks one mesh of a Mitsuba
    ``.serialized`` file, the one kind that holds several.
    """
    from lenslab.scene.io.mesh_materials import load_parts  # it imports this module's MeshPart and LoadedMesh

    return load_parts(path, smooth, shape_index)


def load_mesh(path: Path, smooth: bool = True, shape_index: int = 0) -> TriangleMesh:
    """The whole file as one triangle mesh, its parts joined (for its extent, and for the studio's import).
    It is read as a scene reads it (load_mesh_parts): a PLY with texture coordinates once needed PIL here."""
    path = Path(path)
    if not os.path.isfile(path):
        raise MeshLoadError(f"{path}: {not_a_file(path) or 'mesh file not found'}")
    return join_parts([part.mesh for part in load_mesh_parts(path, smooth, shape_index).parts])


def join_parts(meshes: list[TriangleMesh]) -> TriangleMesh:
    """One mesh of several: normals and texture coordinates kept where every part has them."""
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    vertices = np.concatenate([m.vertices for m in meshes])
    faces = np.concatenate([m.faces + offset for m, offset in zip(meshes, offsets)])
    normals = (np.concatenate([m.normals for m in meshes]) if all(m.normals is not None for m in meshes) else None)
    uvs = np.concatenate([m.uvs for m in meshes]) if all(m.uvs is not None for m in meshes) else None
    return TriangleMesh(vertices, faces, normals, uvs)
