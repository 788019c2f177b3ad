"""Shapes: what a node draws. Triangle meshes (from files or built in) and analytic spheres.

Built-in shapes (rectangle, disk, cylinder, box, relief) are meshes made in code so that a scene like the Cornell
box needs no mesh files. Mesh files are read through trimesh (``lenslab.scene.io.meshes``) when the scene is flattened,
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
class Cylinder(Shape):
    """An open tube (no caps) around the local Z axis, centred at the origin: Mitsuba's cylinder, whose unit
    tube runs from z = 0 to 1, moved down by half its height.

    A mesh made in code, as Disk: a prism of ``segments`` sides with smooth (radial) normals. Its
    cross-section is a polygon of the circle's perimeter (not inscribed in it), so the tube keeps the
    cylinder's area 2 pi r h and an emitting tube its power; its silhouette then strays from the circle by at
    most pi^2 / (3 n^2) of the radius (0.02% at 128 sides). The uvs are Mitsuba's: u = phi / 2 pi around the
    axis from +X towards +Y, v from 0 at the bottom (z = -h/2) to 1 at the top.
    """

    type_name: ClassVar[str] = "cylinder"
    radius: float = field(default=0.5, metadata={"range": (1e-9, 1e9), "doc": "metres"})
    height: float = field(default=1.0, metadata={"range": (1e-9, 1e9), "doc": "metres, along the local Z axis"})
    segments: int = field(default=128, metadata={"range": (3, 4096),
                                                 "doc": "sides of the prism that stands in for it"})
    flip_normals: bool = field(default=False,
                               metadata={"doc": "normals point into the tube (and a light shines inwards)"})

    @property
    def triangle_count(self) -> int:
        return 2 * int(self.segments)

    def mesh(self) -> TriangleMesh:
        n = int(self.segments)
        # Equal perimeter, hence equal area: n sides of 2 r' sin(pi/n) make 2 pi r.
        r = self.radius * (np.pi / n) / np.sin(np.pi / n)
        angles = 2 * np.pi * np.arange(n + 1) / n  # the seam's column twice: u = 0 and u = 1
        ring = np.stack([np.cos(angles), np.sin(angles), np.zeros(n + 1)], axis=1)
        half = self.height / 2
        vertices = np.concatenate([r * ring + (0.0, 0.0, -half), r * ring + (0.0, 0.0, half)])
        normals = np.concatenate([ring, ring])
        u = np.arange(n + 1) / n
        uvs = np.concatenate([np.stack([u, np.zeros(n + 1)], 1), np.stack([u, np.ones(n + 1)], 1)])
        bottom, top = np.arange(n), n + 1 + np.arange(n)
        # Counter-clockwise seen from outside: along +phi at the bottom, then up.
        faces = np.concatenate([np.stack([bottom, bottom + 1, top + 1], 1), np.stack([bottom, top + 1, top], 1)])
        if self.flip_normals:
            faces, normals = faces[:, ::-1], -normals
        return TriangleMesh(vertices, np.ascontiguousarray(faces), normals, uvs)


# The faces' u and v axes, in the order of Box.mesh's quads (-x, +x, -y, +y, -z, +z).
BOX_UV_AXES = np.array([
    [(0, 1, 0), (0, 0, -1)], [(0, 1, 0), (0, 0, 1)],
    [(0, 0, 1), (-1, 0, 0)], [(-1, 0, 0), (0, 0, 1)],
    [(0, -1, 0), (-1, 0, 0)], [(0, 1, 0), (-1, 0, 0)],
], dtype=float)


@dataclass
class Box(Shape):
    """An axis-aligned box centred at the origin, faces pointing outwards.

    Each face spans [0, 1]^2 in uv, laid out as Mitsuba 3's ``cube`` lays them (its v turned to ours, where an
    image's top row is at v = 1), so that a texture lands on an imported cube where Mitsuba puts it."""

    type_name: ClassVar[str] = "box"
    size: tuple[float, float, float] = field(default=(1.0, 1.0, 1.0), metadata={"range": (1e-9, 1e9)})
    triangle_count: ClassVar[int] = 12

    def mesh(self) -> TriangleMesh:
        corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
        corners *= np.asarray(self.size, dtype=float)
        # Each face as a quad of corner indices (bit 2 = x, bit 1 = y, bit 0 = z), counter-clockwise seen from outside.
        quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        vertices = corners[np.array(quads)].reshape(-1, 3)  # four of its own per face: uvs differ per face
        faces = np.array([tri for f in range(0, 24, 4) for tri in ((f, f + 1, f + 2), (f, f + 2, f + 3))])
        # (u, v) = (1 + a . p, 1 + b . p) / 2 with p the position scaled to [-1, 1]^3 and a, b signed axes per
        # face: Mitsuba 3.9's cube (checked in tests/test_textures_uv.py).
        unit = vertices / (np.asarray(self.size, dtype=float) / 2)
        axes = np.repeat(BOX_UV_AXES, 4, axis=0)  # (24, 2, 3)
        uvs = 0.5 + 0.5 * np.einsum("vij,vj->vi", axes, unit)
        return TriangleMesh(vertices, faces, None, uvs)


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


SHAPE_TYPES: dict[str, type[Shape]] = {cls.type_name: cls for cls in (Sphere, Rectangle, Disk, Cylinder, Box, Relief,
                                                                   MeshFile)}
