"""Textures: colours and roughness that vary over a surface, looked up by the surface's (u, v).

Image textures are read through OpenImageIO when the scene is packed for the renderer; colour maps in 8-bit
formats are taken as sRGB and linearised, EXR/HDR files as linear. A procedural checkerboard needs no file,
which makes it the usual way to see focus and blur on a test chart.

Every texture places itself on the surface by the same affine map of the surface's (u, v) to texture
coordinates (s, t) (docs/scene-format.md, "Textures"): shear, then ``tiles``, then ``rotation_deg``, then
``offset``::

    (s, t) = offset + R(rotation_deg) . (tiles_u (u + shear v), tiles_v v)

With the defaults that is ``tiles`` alone, as before the other three existed. Every invertible affine map of
the plane has exactly one such form (a QR decomposition: :func:`uv_fields`), so Mitsuba's ``to_uv`` imports
exactly. An image spans (s, t) in [0, 1]^2 with its top row at t = 1; a checkerboard has unit squares in (s, t).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from lenslab.colour_management.texture_spaces import KEYWORDS, colour_space_problem

RGB = tuple[float, float, float]

UV_LIMIT = 1e6  # beyond any real repeat count or offset; keeps (s, t) well inside float32's exact integers
WRAP_MODES = ("repeat", "mirror", "clamp")
FILTERS = ("bilinear", "nearest")


def _tiles_field(default: tuple[float, float], doc: str):
    return field(default=default, metadata={"range": (-UV_LIMIT, UV_LIMIT), "nonzero": True,
                                            "doc": doc + "; a negative count mirrors the texture"})


def _shear_field():
    return field(default=0.0, metadata={"range": (-UV_LIMIT, UV_LIMIT),
                                        "doc": "u moves by this much per unit v before tiling (a slanted texture)"})


def _rotation_field():
    return field(default=0.0, metadata={"range": (-360.0, 360.0),
                                        "doc": "degrees, counter-clockwise in (u, v), after tiling"})


def _offset_field():
    return field(default=(0.0, 0.0), metadata={"range": (-UV_LIMIT, UV_LIMIT),
                                               "doc": "added last, in repeats (1 moves the texture by one whole copy)"})


@dataclass
class Texture:
    type_name: ClassVar[str] = ""

    def uv_matrix(self) -> np.ndarray:
        """The 2 x 3 matrix that takes (u, v, 1) to the texture's (s, t): see the module's docstring."""
        return uv_matrix_of(getattr(self, "tiles", (1.0, 1.0)), getattr(self, "shear", 0.0),
                            getattr(self, "rotation_deg", 0.0), getattr(self, "offset", (0.0, 0.0)))


def uv_matrix_of(tiles, shear: float, rotation_deg: float, offset) -> np.ndarray:
    """(s, t) = offset + R(rotation_deg) . (tiles_u (u + shear v), tiles_v v), as a 2 x 3 matrix."""
    angle = math.radians(rotation_deg)
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    linear = rotation @ np.diag(np.asarray(tiles, float)) @ np.array([[1.0, shear], [0.0, 1.0]])
    return np.column_stack([linear, np.asarray(offset, float)])


def uv_fields(matrix) -> dict:
    """``tiles``, ``shear``, ``rotation_deg`` and ``offset`` that make :meth:`Texture.uv_matrix` equal
    ``matrix`` (2 x 3, or the top of a 3 x 3 homogeneous one), exact up to rounding.

    The linear part is a rotation R times an upper triangular U (QR), with R a proper rotation and U's first
    diagonal entry positive, so a mirroring map shows as a negative v tile. Raises ValueError for a map that
    squashes the plane onto a line, which no tiles describe."""
    m = np.asarray(matrix, float)[:2]
    linear, offset = m[:, :2], m[:, 2]
    scale = max(float(abs(linear).max()), 1e-300)
    q, r = np.linalg.qr(linear)
    if abs(r[0, 0]) <= 1e-12 * scale or abs(r[1, 1]) <= 1e-12 * scale:
        raise ValueError("the uv transform squashes the texture onto a line")
    signs = np.where(np.diag(r) < 0, -1.0, 1.0)  # U's diagonal positive (Q's columns turn with it) ...
    q, r = q * signs, r * signs[:, None]
    if np.linalg.det(q) < 0:  # ... then a mirror moves from Q into U's second row: R is a rotation
        q, r = q * np.array([1.0, -1.0]), r * np.array([[1.0], [-1.0]])
    exact = {"tiles": (float(r[0, 0]), float(r[1, 1])), "shear": float(r[0, 1] / r[0, 0]),
             "rotation_deg": math.degrees(math.atan2(q[1, 0], q[0, 0])), "offset": (float(offset[0]), float(offset[1]))}
    return _tidied(exact, m)


def _tidied(fields: dict, matrix: np.ndarray) -> dict:
    """``fields`` with each number that is within rounding of one of 7 significant digits (or 0) replaced by
    it, where the map they make stays within 1e-9 of ``matrix`` (relative to its largest entry): a scene file
    then shows 30 and 0.2 where arithmetic left 29.999999999999986 and 0.199999999995. The change is far
    below float32's, in which the renderer works, and does not grow when maps are composed again."""
    size = float(abs(matrix).max())
    flat = [*fields["tiles"], fields["shear"], fields["rotation_deg"], *fields["offset"]]

    def as_fields(v: list[float]) -> dict:
        return {"tiles": (v[0], v[1]), "shear": v[2], "rotation_deg": v[3], "offset": (v[4], v[5])}

    for i, value in enumerate(flat):  # one number at a time, each kept only where the map stays put
        nice = float(f"{value:.7g}") if i < 2 or abs(value) >= 1e-12 * max(size, 1.0) else 0.0
        trial = flat[:i] + [nice] + flat[i + 1:]
        if np.abs(uv_matrix_of(**as_fields(trial)) - matrix).max() <= 1e-9 * size:
            flat = trial
    return as_fields([v + 0.0 for v in flat])


@dataclass
class ImageTexture(Texture):
    type_name: ClassVar[str] = "image"
    file: str = field(default="", metadata={"required": True, "doc": "PNG, JPEG, EXR, HDR...; relative to the scene"})
    # Not "choices": any colour space of the OCIO config is a value too, so the reader asks "check" instead.
    color_space: str = field(default="auto", metadata={
        "check": colour_space_problem, "suggestions": KEYWORDS,
        "doc": "auto (8/16-bit files sRGB, float files linear Rec.709; raw in a data slot), srgb, linear (Rec.709), "
               "raw (data: never converted), or any OCIO colour space's name (docs/colour.md)"})
    tiles: tuple[float, float] = _tiles_field((1.0, 1.0), "repeats per unit uv")
    shear: float = _shear_field()
    rotation_deg: float = _rotation_field()
    offset: tuple[float, float] = _offset_field()
    wrap: str = field(default="repeat", metadata={"choices": WRAP_MODES,
                                                  "doc": "beyond the image: repeat it, mirror it, or extend its edges"})
    filter: str = field(default="bilinear", metadata={
        "choices": FILTERS, "doc": "bilinear: blend the four nearest texels; nearest: sharp texels"})


@dataclass
class Checkerboard(Texture):
    type_name: ClassVar[str] = "checker"
    color_a: RGB = field(default=(0.9, 0.9, 0.9), metadata={"range": (0.0, 1.0)})
    color_b: RGB = field(default=(0.1, 0.1, 0.1), metadata={"range": (0.0, 1.0)})
    tiles: tuple[float, float] = _tiles_field((8.0, 8.0), "squares per unit uv")
    shear: float = _shear_field()
    rotation_deg: float = _rotation_field()
    offset: tuple[float, float] = _offset_field()


@dataclass(eq=False)
class InlineImageTexture(Texture):
    """Pixels that came inside another file (a GLB's embedded images): float RGB, (H, W, 3), linear Rec.709 unless
    ``color_space`` says otherwise.

    Not written to scene files: it is re-read from the mesh file that holds it whenever the scene loads.
    """

    type_name: ClassVar[str] = "inline_image"
    pixels: object = None  # numpy array; `object` keeps the scene format's reader away from it
    name: str = ""
    color_space: str = "linear"  # as ImageTexture's; "raw" for pixels already in the working space
    tiles: tuple[float, float] = (1.0, 1.0)
    shear: float = 0.0
    rotation_deg: float = 0.0
    offset: tuple[float, float] = (0.0, 0.0)
    wrap: str = "repeat"
    filter: str = "bilinear"


TEXTURE_TYPES: dict[str, type[Texture]] = {cls.type_name: cls for cls in (ImageTexture, Checkerboard)}
