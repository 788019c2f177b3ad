"""Mitsuba 3's textures and cylinder onto LensLab's (docs/mitsuba-import.md, "Textures and uv").

``bitmap`` and ``checkerboard`` (``src/textures/*.cpp``) become :class:`ImageTexture` and :class:`Checkerboard`
whose uv transform holds Mitsuba's ``to_uv`` exactly; :func:`texture_from_element` is what
``MitsubaImporter.texture_of`` calls.

**Which (u, v) a texture expects.** Mitsuba looks an image up with its first row at v = 0 (Dr.Jit's texture:
texel row = v H); LensLab with its first row at v = 1. Mitsuba's OBJ reader flips v as it loads
(``flip_tex_coords``, default true), so a mesh's own uvs meet the image the same way in both, and a texture
made here expects exactly those: w = F(si.uv) with F(a, b) = (a, 1 - b) and si.uv Mitsuba's. Hence::

    bitmap:        (s, t) = F . to_uv . F (w)
    checkerboard:  (s, t) = 2 to_uv . F (w)    (Mitsuba's squares are half a unit of to_uv's output)

A shape whose LensLab uvs are not w (a rectangle's are si.uv itself; a sphere's follow the world's axes)
says how to get w from them (:func:`shape_uv`), and the importer gives it a copy of its material with that
map composed into every texture (:func:`on_shape`). Each convention here was measured against Mitsuba 3.9's
``si.uv`` (tests/test_textures_uv.py).
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from lenslab.image_files import holds_floats, not_found
from lenslab.limits import LARGEST_NUMBER
from lenslab.scene.materials import Material
from lenslab.scene.shapes import Cylinder
from lenslab.scene.textures import FILTERS, WRAP_MODES, Checkerboard, ImageTexture, Texture, uv_fields

if TYPE_CHECKING:
    from .mitsuba_xml import Props, XNode, MitsubaImporter

RGB = tuple[float, float, float]

FLIP_V = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, 1.0]])  # (a, b) -> (a, 1 - b)
IDENTITY = np.eye(3)
CHECKER_SQUARES = np.diag([2.0, 2.0, 1.0])  # Mitsuba: colour changes at every half unit of to_uv's output
#: Mitsuba's bitmap filter_type and wrap_mode, by LensLab's name (the same words).
BITMAP_CHOICES = {"filter_type": FILTERS, "wrap_mode": WRAP_MODES}
CYLINDER_SEGMENTS = 128  # silhouette within 0.02% of the radius (scene/shapes.Cylinder)
#: Mitsuba's own uv convention for mesh files: OBJ flips v on loading unless told not to, PLY only when told
#: (src/shapes/obj.cpp, ply.cpp); LensLab reads both files' uvs as they are written.
FLIP_TEX_COORDS_DEFAULT = {"obj": True, "ply": False}
AXIS_TOLERANCE = 1e-6


def _props(imp: "MitsubaImporter", node: "XNode") -> "Props":
    from .mitsuba_xml import Props  # imported here: mitsuba_xml imports this module

    return Props(imp, node)


def _homogeneous(matrix: np.ndarray) -> np.ndarray:
    return np.vstack([np.asarray(matrix, float)[:2], (0.0, 0.0, 1.0)])


def to_uv(p: "Props") -> np.ndarray:
    """``to_uv`` as the 3 x 3 homogeneous map Mitsuba uses: a 4 x 4 ``<transform>`` loses its z row and
    column (``Transform::extract``: the top-left 2 x 2, and rows 0-1 of the translation column)."""
    full = p.transform("to_uv")
    return _homogeneous(full[np.ix_([0, 1], [0, 1, 3])])


def _texture_fields(imp: "MitsubaImporter", node: "XNode", matrix: np.ndarray) -> dict:
    try:
        return uv_fields(matrix)
    except ValueError:
        imp.warn(node, "to_uv squashes the texture onto a line (Mitsuba shows a single texel row there): "
                 "no uv transform used")
        return uv_fields(IDENTITY)


def _choice(p: "Props", name: str, default: str) -> str:
    value = p.string(name, default)
    choices = BITMAP_CHOICES[name]
    if value not in choices:
        raise p.node.error(f'invalid {name} "{value}", must be one of: "{", ".join(choices)}"')
    return value


def read_bitmap(imp: "MitsubaImporter", node: "XNode") -> ImageTexture:
    """Mitsuba's bitmap: ``raw`` true reads the file's values as stored ("raw"); raw false decodes 8- and 16-bit
    files as sRGB and reads float files as linear, in whatever slot the bitmap sits (a mask's opacity included),
    so it becomes an explicit "srgb" or "linear" (:func:`bitmap_colour_space`). A file that is not there is
    LensLab's usual magenta checkerboard at render time, warned here with the scene file's line (Mitsuba refuses
    the scene)."""
    p = _props(imp, node)
    filename = p.string("filename")
    raw = p.bool("raw", False)
    filter_type = _choice(p, "filter_type", "bilinear")
    wrap_mode = _choice(p, "wrap_mode", "repeat")
    matrix = FLIP_V @ to_uv(p) @ FLIP_V
    p.take("format")  # how Mitsuba stores the texels (8 bit, half, float): the same values when looked up
    p.take("accel")  # CUDA's hardware filtering: the same lookup
    p.finish()
    if not filename:
        raise node.error('a bitmap needs a "filename"')
    path = imp.resolve_file(node, filename)
    if not os.path.isfile(path):
        imp.warn(node, f"{not_found('texture file', path)}; LensLab shows a magenta checkerboard in its place")
    return ImageTexture(file=imp.scene_relative_path(path), color_space=bitmap_colour_space(path, raw),
                        wrap=wrap_mode, filter=filter_type, **_texture_fields(imp, node, matrix))


def bitmap_colour_space(path: str | os.PathLike, raw: bool) -> str:
    """The colour space that reads a bitmap as Mitsuba does. Not "auto" for raw false: in a data slot "auto" means
    raw, and Mitsuba decodes an 8-bit file's sRGB curve there too. "auto" only for a file whose header cannot be
    read (it shows as the magenta checkerboard in any case)."""
    if raw:
        return "raw"
    floats = holds_floats(path)
    return "auto" if floats is None else ("linear" if floats else "srgb")


def _unit_colour(imp: "MitsubaImporter", p: "Props", name: str, default: float) -> RGB:
    rgb = p.color(name, default)
    clipped = tuple(float(min(max(c, 0.0), 1.0)) for c in rgb)
    if clipped != tuple(rgb):
        imp.warn(p.values[name], f"{name} beyond [0, 1] cannot be a reflectance: clipped")
    return clipped  # type: ignore[return-value]


def read_checkerboard(imp: "MitsubaImporter", node: "XNode") -> Checkerboard:
    """Mitsuba's checkerboard: color0 where the fractional parts of (s, t) = to_uv(uv) are both below 1/2 or
    both above, color1 elsewhere."""
    p = _props(imp, node)
    color0, color1 = _unit_colour(imp, p, "color0", 0.4), _unit_colour(imp, p, "color1", 0.2)
    matrix = CHECKER_SQUARES @ to_uv(p) @ FLIP_V
    p.finish()
    return Checkerboard(color_a=color0, color_b=color1, **_texture_fields(imp, node, matrix))


READERS = {"bitmap": read_bitmap, "checkerboard": read_checkerboard}


def texture_from_element(imp: "MitsubaImporter", node: "XNode") -> Texture | None:
    """The LensLab texture for a ``<texture>`` element, or None for a kind LensLab cannot look up."""
    reader = READERS.get(node.type)
    return reader(imp, node) if reader is not None else None


def as_scalar(texture: Texture) -> Texture:
    """The texture as Mitsuba's ``eval_1`` reads it (a blend's weight, a mask's opacity): a bitmap's
    luminance, which our texture_value takes too; but a checkerboard's eval_1 gives color1 where its eval
    gives color0 and back (Mitsuba 3.9's checkerboard.cpp), each colour as the mean of its channels (what an
    RGB colour's eval_1 is)."""
    if not isinstance(texture, Checkerboard):
        return texture
    grey_a, grey_b = (float(np.mean(c)) for c in (texture.color_b, texture.color_a))
    return dataclasses.replace(texture, color_a=(grey_a,) * 3, color_b=(grey_b,) * 3)


def mean_colour(imp: "MitsubaImporter", node: "XNode", texture: Texture | None) -> RGB | None:
    """Mitsuba's ``mean()`` of a texture, for a property LensLab cannot texture: the checkerboard's two
    colours' mean, a bitmap's mean linear texel; None where it cannot be had."""
    if isinstance(texture, Checkerboard):
        return tuple((a + b) / 2 for a, b in zip(texture.color_a, texture.color_b))  # type: ignore[return-value]
    if isinstance(texture, ImageTexture):
        from lenslab.colour_management.texture_spaces import to_working_space
        from lenslab.image_files import read_pixels

        path = imp.resolve_file(node, texture.file)
        try:
            pixels, is_float = read_pixels(path)
        except (OSError, ValueError):
            return None
        rgb = pixels[..., :3] if pixels.shape[2] >= 3 else np.repeat(pixels[..., :1], 3, axis=2)
        rgb = to_working_space(rgb, texture.color_space, is_float)  # a Mitsuba scene's colours are linear Rec.709
        return tuple(float(v) for v in rgb.reshape(-1, 3).mean(axis=0))  # type: ignore[return-value]
    return None


# ---------------------------------------------------------------------------------------------------------
# Shapes: how a LensLab shape's (u, v) give w
# ---------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ShapeUv:
    """w = matrix . (u, v, 1) on the LensLab shape. ``modulo_u``: only modulo 1 in w's u (a sphere turned
    about its pole moves Mitsuba's seam), exact for a texture that repeats with period 1 in u."""

    matrix: tuple[tuple[float, ...], ...]
    modulo_u: bool = False

    @property
    def is_identity(self) -> bool:
        return not self.modulo_u and np.allclose(self.matrix, IDENTITY[:2], atol=1e-12)


UNMAPPED = ShapeUv(((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)))  # a shape whose uvs are w already


def _shape_uv(matrix: np.ndarray, modulo_u: bool = False) -> ShapeUv:
    rounded = np.round(np.asarray(matrix, float)[:2], 12) + 0.0
    return ShapeUv(tuple(tuple(float(v) for v in row) for row in rounded), modulo_u)


def shape_uv(kind: str, matrix: np.ndarray, flip_tex_coords: bool | None = None,
             flip_normals: bool = False) -> ShapeUv | str:
    """How the LensLab shape imported for a Mitsuba ``kind`` gives w from its own (u, v), or the reason it
    cannot. ``matrix``: the shape's node's matrix (a sphere's uvs depend on it); ``flip_tex_coords``: the
    mesh's, None for Mitsuba's default; ``flip_normals``: the Mitsuba shape's."""
    if kind == "rectangle":  # ours has Mitsuba's si.uv; a flipped one is ours turned half about x, v -> 1 - v
        return _shape_uv(IDENTITY if flip_normals else FLIP_V)
    if kind == "cylinder":  # ours has Mitsuba's si.uv, flipped or not
        return _shape_uv(FLIP_V)
    if kind == "cube":  # our Box lays its faces out as Mitsuba's cube, in w
        return _shape_uv(IDENTITY)
    if kind in FLIP_TEX_COORDS_DEFAULT:
        flipped = FLIP_TEX_COORDS_DEFAULT[kind] if flip_tex_coords is None else flip_tex_coords
        return _shape_uv(IDENTITY if flipped else FLIP_V)
    if kind == "serialized":  # its reader (mitsuba_serialized.py) turns Mitsuba's v into ours already
        return _shape_uv(IDENTITY)
    if kind == "stl":  # no uvs: Mitsuba's (0, 0) is our (0, 1)
        return _shape_uv(FLIP_V)
    if kind == "sphere":
        return _sphere_uv(matrix)
    if kind == "disk":
        return ("Mitsuba's disk has polar uvs (u the radius, v the angle) and LensLab's lie flat across it: "
                "the texture lands differently")
    return _shape_uv(IDENTITY)


def _sphere_uv(matrix: np.ndarray) -> ShapeUv | str:
    """Mitsuba's sphere: v = theta / pi from its local +Z, u = phi / 2 pi from its local +X towards +Y.
    Ours: v from the world's +Y, u = atan2(z, x) / 2 pi + 1/2 (glsl/texcoords.glsl), whatever the node's turn.
    The two agree up to an affine map only when Mitsuba's pole lies along the world's Y axis."""
    axes = np.asarray(matrix, float)[:3, :3]
    ex, ey, ez = (axes[:, i] / np.linalg.norm(axes[:, i]) for i in range(3))
    pole = ez[1]
    if abs(abs(pole) - 1.0) > AXIS_TOLERANCE:
        return ("LensLab's sphere has its texture's poles on the world's Y axis, and this sphere's to_world "
                "puts Mitsuba's (its local Z) elsewhere: the texture lands differently (turn the sphere so that "
                "its local Z is the world's Y)")
    # n = (cos a sin th, cos th, sin a sin th), a = 2 pi (u - 1/2). With ex at angle alpha in the XZ plane,
    # Mitsuba's phi = sigma (a - alpha), sigma = +1 when ey is ex turned a quarter of the way towards +a.
    alpha = math.atan2(ex[2], ex[0])
    sigma = 1.0 if np.dot(ey, (-math.sin(alpha), 0.0, math.cos(alpha))) > 0 else -1.0
    shift = (-sigma * (0.5 + alpha / (2 * math.pi))) % 1.0  # u_m = sigma u + shift (mod 1)
    if abs(shift - round(shift)) < AXIS_TOLERANCE:
        shift, modulo = (1.0 if sigma < 0 else 0.0), False  # the seams meet: exact for every texture
    else:
        modulo = True
    # w = (u_m, 1 - v_m), v_m = v when Mitsuba's pole is +Y, 1 - v when it is -Y.
    v_row = (0.0, -1.0, 1.0) if pole > 0 else (0.0, 1.0, 0.0)
    return _shape_uv(np.array([(sigma, 0.0, shift), v_row]), modulo)


def textures_of(material: Material) -> list[Texture]:
    """Every texture a material holds, its nested materials' included."""
    found: list[Texture] = []
    for f in dataclasses.fields(material):
        value = getattr(material, f.name)
        if isinstance(value, Texture):
            found.append(value)
        elif isinstance(value, Material):
            found.extend(textures_of(value))
    return found


def _repeats_along_u(texture: Texture, step: np.ndarray) -> bool:
    """Whether moving w by one unit of u (``step`` in (s, t)) shows the same texture."""
    if isinstance(texture, Checkerboard):  # the pattern repeats by whole squares whose count is even
        return bool(np.allclose(step, np.round(step), atol=1e-6) and round(step.sum()) % 2 == 0)
    period = {"repeat": 1, "mirror": 2}.get(getattr(texture, "wrap", "repeat"))
    return period is not None and bool(np.allclose(step / period, np.round(step / period), atol=1e-6))


def on_shape(material: Material, uv: ShapeUv, cache: dict) -> tuple[Material, bool]:
    """A copy of ``material`` whose textures take the shape's own (u, v): each texture's map composed with
    ``uv``; and whether every texture lands exactly as in Mitsuba (False where a sphere's turned seam cuts a
    texture that does not repeat with it). ``cache`` keeps one copy per texture and map."""
    c = _homogeneous(np.array(uv.matrix))
    exact = True

    def moved(texture: Texture) -> Texture:
        nonlocal exact
        a = _homogeneous(texture.uv_matrix())
        if uv.modulo_u and not _repeats_along_u(texture, a[:2, 0]):
            exact = False
        key = (id(texture), uv)
        if key not in cache:
            cache[key] = (texture, dataclasses.replace(texture, **uv_fields(a @ c)))
        return cache[key][1]

    def copy(m: Material) -> Material:
        changes = {}
        for f in dataclasses.fields(m):
            value = getattr(m, f.name)
            if isinstance(value, Texture):
                changes[f.name] = moved(value)
            elif isinstance(value, Material):
                changes[f.name] = copy(value)
        return dataclasses.replace(m, **changes) if changes else m

    return copy(material), exact


# ---------------------------------------------------------------------------------------------------------
# The cylinder
# ---------------------------------------------------------------------------------------------------------
def coordinate_system(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mitsuba's ``coordinate_system`` (Duff et al. 2017, include/mitsuba/core/vector.h): the s and t of
    ``Frame3f(n)``, which decide where a cylinder's u = 0 lies."""
    x, y, z = (float(v) for v in n)
    sign = 1.0 if z >= 0 else -1.0  # dr::sign: +1 at zero
    a = -1.0 / (sign + z)
    b = x * y * a
    mulsign = math.copysign(1.0, z)  # dr::mulsign follows the sign bit
    s = np.array([x * x * a * mulsign + 1.0, b * mulsign, -x * mulsign])
    t = np.array([b, y * y * a + sign, -y])
    return s, t


def cylinder_matrix(p0, p1, radius: float, to_world: np.ndarray) -> np.ndarray:
    """The matrix that takes LensLab's ``Cylinder(radius=1, height=1)`` (z in [-1/2, 1/2]) onto Mitsuba's
    cylinder: ``to_world . translate(p0) . to_frame(Frame(d / |d|)) . scale(r, r, |d|)`` of the unit tube
    z in [0, 1] (src/shapes/cylinder.cpp), after moving ours up by half."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    with np.errstate(over="ignore"):  # an axis too long for float64 is refused below
        length = float(np.linalg.norm(d))
    if length == 0:
        raise ValueError("p0 and p1 must differ")
    if not math.isfinite(length):
        raise ValueError("the cylinder's p0, p1, radius and to_world place it beyond any scene")
    n = d / length
    s, t = coordinate_system(n)
    frame = np.eye(4)
    frame[:3, :3] = np.column_stack([s, t, n])
    place = np.eye(4)
    place[:3, 3] = p0
    scale = np.diag([radius, radius, length, 1.0])
    lift = np.eye(4)
    lift[2, 3] = 0.5
    with np.errstate(over="ignore", invalid="ignore"):  # found just below, and named
        matrix = np.asarray(to_world, float) @ place @ frame @ scale @ lift
    if not np.isfinite(matrix).all() or np.abs(matrix).max() > LARGEST_NUMBER:
        raise ValueError("the cylinder's p0, p1, radius and to_world place it beyond any scene")
    return matrix


def cylinder_shape(matrix: np.ndarray, flip_normals: bool) -> tuple[Cylinder, np.ndarray]:
    """The cylinder and its node's matrix: radius and height in the shape when the matrix is a rotation and
    translation after scales (r, r, h), as ``p0``/``p1``/``radius`` give; otherwise (an elliptical or sheared
    tube, which Mitsuba warns of but renders) a unit cylinder under the whole matrix, which is as exact."""
    linear = matrix[:3, :3]
    widths = np.linalg.norm(linear, axis=0)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflowing square is no orthogonality test: the
        gram = linear.T @ linear  # unit tube under the whole matrix then, which flatten checks
    orthogonal = np.allclose(gram, np.diag(np.diag(gram)), atol=1e-9 * max(widths.max(), 1e-300) ** 2)
    if orthogonal and abs(widths[0] - widths[1]) <= 1e-9 * widths.max() and widths.min() > 0:
        shape = Cylinder(radius=float(widths[0]), height=float(widths[2]), segments=CYLINDER_SEGMENTS,
                         flip_normals=flip_normals)
        return shape, matrix @ np.diag([1 / widths[0], 1 / widths[1], 1 / widths[2], 1.0])
    return Cylinder(radius=1.0, height=1.0, segments=CYLINDER_SEGMENTS, flip_normals=flip_normals), matrix
