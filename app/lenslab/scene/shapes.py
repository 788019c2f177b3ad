"""Shapes: what a node draws. Triangle meshes (from files or built in) and analytic spheres.

Built-in shapes (rectangle, box) are meshes made in code so that a scene like the Cornell box needs no
mesh files. Mesh files are read through trimesh (``lenslab.scene.io.meshes``) when the scene is flattened,
and cached by path and modification time.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np


@dataclass(frozen=True)
class TriangleMesh:
    """Indexed triangles in local space; normals per vertex (None = flat shading)."""

    vertices: np.ndarray  # (V, 3) float
    faces: np.ndarray  # (F, 3) int
    normals: np.ndarray | None = None  # (V, 3) float
    uvs: np.ndarray | None = None  # (V, 2) float

    @property
    def triangle_count(self) -> int:
        return len(self.faces)


@dataclass
class Shape:
    type_name: ClassVar[str] = ""


@dataclass
class Sphere(Shape):
    """An analytic sphere centred at the node's origin."""

    type_name: ClassVar[str] = "sphere"
    radius: float = field(default=1.0, metadata={"range": (1e-9, 1e9), "doc": "metres"})


@dataclass
class Rectangle(Shape):
    """A rectangle in the local XY plane, centred at the origin, its front face towards +Z."""

    type_name: ClassVar[str] = "rectangle"
    size: tuple[float, float] = field(default=(1.0, 1.0), metadata={"range": (1e-9, 1e9), "doc": "width, height in metres"})

    def mesh(self) -> TriangleMesh:
        w, h = self.size[0] / 2, self.size[1] / 2
        vertices = np.array([[-w, -h, 0], [w, -h, 0], [w, h, 0], [-w, h, 0]], dtype=float)
        faces = np.array([[0, 1, 2], [0, 2, 3]])
        uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
        return TriangleMesh(vertices, faces, None, uvs)


@dataclass
class Disk(Shape):
    """A disk in the local XY plane, centred at the origin, its front face towards +Z (as Mitsuba's disk)."""

    type_name: ClassVar[str] = "disk"
    radius: float = field(default=0.5, metadata={"range": (1e-9, 1e9), "doc": "metres"})
    segments: int = field(default=128, metadata={"range": (3, 4096), "doc": "edges of the polygon that stands in for it"})

    def mesh(self) -> TriangleMesh:
        # A polygon with the disk's area (not inscribed in it), so that an emitting disk keeps its power.
        n = self.segments
        r = self.radius * np.sqrt(2 * np.pi / (n * np.sin(2 * np.pi / n)))
        angles = 2 * np.pi * np.arange(n) / n
        rim = np.stack([r * np.cos(angles), r * np.sin(angles), np.zeros(n)], axis=1)
        vertices = np.vstack([[0.0, 0.0, 0.0], rim])
        faces = np.stack([np.zeros(n, int), 1 + np.arange(n), 1 + (np.arange(n) + 1) % n], axis=1)
        uvs = 0.5 + 0.5 * vertices[:, :2] / max(r, 1e-30)
        return TriangleMesh(vertices, faces, None, uvs)


@dataclass
class Box(Shape):
    """An axis-aligned box centred at the origin, faces pointing outwards."""

    type_name: ClassVar[str] = "box"
    size: tuple[float, float, float] = field(default=(1.0, 1.0, 1.0), metadata={"range": (1e-9, 1e9)})

    def mesh(self) -> TriangleMesh:
        corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
        corners *= np.asarray(self.size, dtype=float)
        # Each face as a quad of corner indices (bit 2 = x, bit 1 = y, bit 0 = z), counter-clockwise seen from outside.
        quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        faces = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])
        return TriangleMesh(corners, faces, None, None)


@dataclass
class MeshFile(Shape):
    """A triangle mesh read from a file (OBJ, PLY, glTF/GLB, STL) through trimesh; path relative to the scene."""

    type_name: ClassVar[str] = "mesh"
    file: str = field(default="", metadata={"doc": "path to the mesh, relative to the scene file", "required": True})
    smooth: bool = field(default=True, metadata={"doc": "interpolate vertex normals (false: flat facets)"})


SHAPE_TYPES: dict[str, type[Shape]] = {cls.type_name: cls for cls in (Sphere, Rectangle, Disk, Box, MeshFile)}
