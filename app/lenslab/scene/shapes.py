"""Shapes: what a node draws. Triangle meshes (from files or built in) and analytic spheres.

Built-in shapes (rectangle, disk, box, relief) are meshes made in code so that a scene like the Cornell box needs no
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

    triangle_count: ClassVar[int] = 2

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

    @property
    def triangle_count(self) -> int:
        return int(self.segments)

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
    triangle_count: ClassVar[int] = 12

    def mesh(self) -> TriangleMesh:
        corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
        corners *= np.asarray(self.size, dtype=float)
        # Each face as a quad of corner indices (bit 2 = x, bit 1 = y, bit 0 = z), counter-clockwise seen from outside.
        quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        faces = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])
        return TriangleMesh(corners, faces, None, None)


@dataclass
class Relief(Shape):
    """A rectangle in the local XY plane raised towards +Z by fractal noise: ground, rock, sand, hammered metal.

    A mesh made in code, a grid of ``resolution`` vertices (2 (nx - 1)(ny - 1) triangles, smooth normals), so
    a scene can hold millions of triangles without a mesh file. The relief is fractal Brownian motion of
    gradient noise (Perlin 1985; Musgrave's fBm): ``octaves`` layers, each of half the feature size and half
    the height of the one before, the first with features of ``feature_size``. ``seed`` picks the landscape.
    """

    type_name: ClassVar[str] = "relief"
    size: tuple[float, float] = field(default=(1.0, 1.0), metadata={"range": (1e-9, 1e9), "doc": "width, height in metres"})
    height: float = field(default=0.02, metadata={"range": (0.0, 1e9), "doc": "metres from the lowest to the highest point, about"})
    feature_size: float = field(default=0.1, metadata={"range": (1e-9, 1e9), "doc": "metres across the largest bumps"})
    octaves: int = field(default=5, metadata={"range": (1, 16), "doc": "layers of ever finer detail"})
    resolution: tuple[int, int] = field(default=(256, 256), metadata={"range": (2, 8192), "doc": "vertices along X and Y"})
    seed: int = field(default=0, metadata={"range": (0, 2**31 - 1), "doc": "which landscape"})

    @property
    def triangle_count(self) -> int:
        """Known before the mesh is made (which at 8192 x 8192 would take minutes and tens of GB)."""
        nx, ny = (int(n) for n in self.resolution)
        return 2 * (nx - 1) * (ny - 1)

    def mesh(self) -> TriangleMesh:
        nx, ny = (int(n) for n in self.resolution)
        x = np.linspace(-self.size[0] / 2, self.size[0] / 2, nx)
        y = np.linspace(-self.size[1] / 2, self.size[1] / 2, ny)
        gx, gy = np.meshgrid(x, y)  # (ny, nx)
        z = self.height * relief_height(gx / self.feature_size, gy / self.feature_size, self.octaves, self.seed)
        # Smooth normals from the height field's slopes: n ~ (-dz/dx, -dz/dy, 1).
        dz_dy, dz_dx = np.gradient(z, y, x) if nx > 1 and ny > 1 else (np.zeros_like(z), np.zeros_like(z))
        normals = np.stack([-dz_dx, -dz_dy, np.ones_like(z)], axis=-1)
        normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
        vertices = np.stack([gx, gy, z], axis=-1).reshape(-1, 3)
        index = np.arange(nx * ny).reshape(ny, nx)
        a, b, c, d = index[:-1, :-1], index[:-1, 1:], index[1:, 1:], index[1:, :-1]  # a cell, counter-clockwise
        faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
        u, v = np.meshgrid(np.linspace(0.0, 1.0, nx), np.linspace(0.0, 1.0, ny))
        return TriangleMesh(vertices, faces, normals.reshape(-1, 3), np.stack([u, v], -1).reshape(-1, 2))


def relief_height(x: np.ndarray, y: np.ndarray, octaves: int, seed: int) -> np.ndarray:
    """fBm of 2D gradient noise at (x, y) in units of the largest feature, scaled to span about [-1/2, 1/2]."""
    total, amplitude, frequency, norm = np.zeros(np.shape(x)), 1.0, 1.0, 0.0
    for octave in range(int(octaves)):
        total += amplitude * _gradient_noise(x * frequency, y * frequency, seed * 131 + octave)
        norm += amplitude
        amplitude, frequency = amplitude * 0.5, frequency * 2.0
    return total / norm  # gradient noise lies within about [-0.5, 0.5] (at most sqrt(2)/2 at worst)


def _gradient_noise(x: np.ndarray, y: np.ndarray, seed: int) -> np.ndarray:
    """Perlin's gradient noise: a random unit gradient at every integer lattice point, blended with his
    quintic fade so that the surface has continuous slope and curvature."""
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    ix, iy = x0.astype(np.int64), y0.astype(np.int64)

    def corner(dx: int, dy: int) -> np.ndarray:
        angle = 2.0 * np.pi * _lattice_hash(ix + dx, iy + dy, seed)
        return np.cos(angle) * (fx - dx) + np.sin(angle) * (fy - dy)

    def fade(t: np.ndarray) -> np.ndarray:
        return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)

    sx, sy = fade(fx), fade(fy)
    c00, c10, c01, c11 = corner(0, 0), corner(1, 0), corner(0, 1), corner(1, 1)
    bottom = c00 + sx * (c10 - c00)
    top = c01 + sx * (c11 - c01)
    return bottom + sy * (top - bottom)


def _lattice_hash(ix: np.ndarray, iy: np.ndarray, seed: int) -> np.ndarray:
    """A uniform number in [0, 1) per lattice point (a 64-bit integer mix, SplitMix64's finaliser)."""
    with np.errstate(over="ignore"):
        h = (ix.astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15)) ^ (iy.astype(np.uint64) * np.uint64(0xC2B2AE3D27D4EB4F))
        h ^= np.uint64(seed & 0xFFFFFFFF) * np.uint64(0x165667B19E3779F9)
        h ^= h >> np.uint64(30)
        h *= np.uint64(0xBF58476D1CE4E5B9)
        h ^= h >> np.uint64(27)
        h *= np.uint64(0x94D049BB133111EB)
        h ^= h >> np.uint64(31)
    return (h >> np.uint64(11)).astype(np.float64) / float(1 << 53)


@dataclass
class MeshFile(Shape):
    """A triangle mesh read from a file (OBJ, PLY, glTF/GLB, STL through trimesh; Mitsuba's .serialized, which
    holds several meshes, ``shape_index`` picking one); path relative to the scene."""

    type_name: ClassVar[str] = "mesh"
    file: str = field(default="", metadata={"doc": "path to the mesh, relative to the scene file", "required": True})
    smooth: bool = field(default=True, metadata={"doc": "interpolate vertex normals (false: flat facets)"})
    shape_index: int = field(default=0, metadata={"range": (0, 2**31 - 1),
                                                  "doc": "which mesh of a Mitsuba .serialized file (0: the first); "
                                                         "other files hold one"})


SHAPE_TYPES: dict[str, type[Shape]] = {cls.type_name: cls for cls in (Sphere, Rectangle, Disk, Box, Relief, MeshFile)}
