"""Textures: colours and roughness that vary over a surface, looked up by the surface's (u, v).

Image textures are read through OpenImageIO when the scene is packed for the renderer; colour maps in 8-bit
formats are taken as sRGB and linearised, EXR/HDR files as linear. A procedural checkerboard needs no file,
which makes it the usual way to see focus and blur on a test chart.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

RGB = tuple[float, float, float]


@dataclass
class Texture:
    type_name: ClassVar[str] = ""


@dataclass
class ImageTexture(Texture):
    type_name: ClassVar[str] = "image"
    file: str = field(default="", metadata={"required": True, "doc": "PNG, JPEG, EXR, HDR...; relative to the scene"})
    color_space: str = field(default="auto", metadata={"choices": ("auto", "srgb", "linear"),
                                                        "doc": "auto: 8/16-bit files are sRGB, float files linear"})
    tiles: tuple[float, float] = field(default=(1.0, 1.0), metadata={"range": (1e-6, 1e6), "doc": "repeats per unit uv"})


@dataclass
class Checkerboard(Texture):
    type_name: ClassVar[str] = "checker"
    color_a: RGB = field(default=(0.9, 0.9, 0.9), metadata={"range": (0.0, 1.0)})
    color_b: RGB = field(default=(0.1, 0.1, 0.1), metadata={"range": (0.0, 1.0)})
    tiles: tuple[float, float] = field(default=(8.0, 8.0), metadata={"range": (1e-6, 1e6), "doc": "squares per unit uv"})


@dataclass(eq=False)
class InlineImageTexture(Texture):
    """Pixels that came inside another file (a GLB's embedded images): linear float RGB, (H, W, 3).

    Not written to scene files: it is re-read from the mesh file that holds it whenever the scene loads.
    """

    type_name: ClassVar[str] = "inline_image"
    pixels: object = None  # numpy array; `object` keeps the scene format's reader away from it
    name: str = ""
    tiles: tuple[float, float] = (1.0, 1.0)


TEXTURE_TYPES: dict[str, type[Texture]] = {cls.type_name: cls for cls in (ImageTexture, Checkerboard)}
