"""Textures for the GPU: image files read through OpenImageIO, brought from their colour space into the scene's
working space (colour) or read as stored (data: colour_management/texture_spaces.py says which is which), packed as
half floats (or as 32-bit floats where a value is beyond the half-float range, as the sun in an HDR panorama can be).

A texture that cannot be read is not fatal: the render goes on with a magenta-and-black checkerboard in its
place (hard to miss in a picture) and a warning naming the file, so one broken path never costs the user
the rest of the scene.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lenslab.colour_management.config import DEFAULT_SOURCE, ColourConfigError
from lenslab.colour_management.texture_spaces import colour_space_problem, data_slot_note, to_working_space
from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE
from lenslab.image_files import read_pixels
from lenslab.render.gpu_layout import (TEXELS_FLOAT, TEXELS_HALF, TEXTURE_CHECKER, TEXTURE_FILTER_BILINEAR,
                                       TEXTURE_FILTER_NEAREST, TEXTURE_IMAGE, TEXTURE_ROWS, TEXTURE_WRAP_CLAMP,
                                       TEXTURE_WRAP_MIRROR, TEXTURE_WRAP_REPEAT)
from lenslab.scene.textures import Checkerboard, ImageTexture, InlineImageTexture, Texture

log = logging.getLogger("lenslab.textures")

HALF_MAX = 65504.0
#: The sun's disk in an HDR panorama reaches 1e5 to 1e9; a texel beyond this is a broken file, not a light.
BRIGHTEST = 1e10
MAX_SIDE = 4096  # larger images are downsampled: one storage buffer holds all texels
MISSING = Checkerboard(color_a=(1.0, 0.0, 1.0), color_b=(0.0, 0.0, 0.0), tiles=(16.0, 16.0))
WRAP_CODES = {"repeat": TEXTURE_WRAP_REPEAT, "mirror": TEXTURE_WRAP_MIRROR, "clamp": TEXTURE_WRAP_CLAMP}
FILTER_CODES = {"bilinear": TEXTURE_FILTER_BILINEAR, "nearest": TEXTURE_FILTER_NEAREST}


def read_texture_image(path: Path, color_space: str = "auto", working_space: str = DEFAULT_WORKING_SPACE, *,
                       data: bool = False, config_source: str = DEFAULT_SOURCE) -> np.ndarray:
    """(H, W, 3) float32: a colour texture's texels in ``working_space``, a data texture's (``data``) as stored
    (texture_spaces.to_working_space). Raises OSError naming the file when it cannot be read, ColourConfigError
    when OCIO cannot convert it."""
    pixels, is_float = read_pixels(path)
    height, width = pixels.shape[:2]
    if max(width, height) > MAX_SIDE:
        pixels = _reduced(pixels, MAX_SIDE / max(width, height))
        log.warning("%s: %dx%d texture reduced to %dx%d", path, width, height, pixels.shape[1], pixels.shape[0])
    channels = pixels.shape[2]
    rgb = np.repeat(pixels[..., :1], 3, axis=2) if channels < 3 else pixels[..., :3]
    rgb = to_working_space(rgb, color_space, is_float, working_space, data=data, config_source=config_source)
    return _sane_texels(rgb, path)


def _sane_texels(rgb: np.ndarray, path: Path | str) -> np.ndarray:
    """``rgb`` with what no texel may be replaced, each kind with one warning naming the file."""
    if not np.isfinite(rgb).all():  # NaN or infinity in a float file: black, or every path that sees it is lost
        bad = int((~np.isfinite(rgb)).any(axis=2).sum())
        log.warning("%s: %d texel%s NaN or infinite: read as black", path, bad, " is" if bad == 1 else "s are")
        rgb = np.where(np.isfinite(rgb), rgb, 0.0)
    # No colour or radiance is negative; one would subtract light from the image. (A colour beyond the working
    # space's gamut, converted into it, is negative too: a P3 texture's pure red in linear Rec.709. ACEScg, wider,
    # holds P3's colours.)
    if rgb.min(initial=0.0) < 0.0:
        bad = int((rgb < 0.0).any(axis=2).sum())
        log.warning("%s: %d texel%s negative: read as 0", path, bad, " is" if bad == 1 else "s are")
        rgb = np.maximum(rgb, 0.0)
    if rgb.max(initial=0.0) > BRIGHTEST:  # sums over the map (its power, its sampling table) would overflow
        bad = int((rgb > BRIGHTEST).any(axis=2).sum())
        log.warning("%s: %d texel%s brighter than %g, beyond any light: clamped", path, bad,
                    " is" if bad == 1 else "s are", BRIGHTEST)
        rgb = np.minimum(rgb, BRIGHTEST)
    return np.ascontiguousarray(rgb, dtype=np.float32)


def _reduced(pixels: np.ndarray, scale: float) -> np.ndarray:
    """``pixels`` resampled to ``scale`` of their size, with OpenImageIO's filtered resize; its filter's
    negative lobes can ring below zero beside a sharp edge, and no colour or radiance is negative."""
    import OpenImageIO as oiio

    height, width, channels = pixels.shape
    roi = oiio.ROI(0, max(1, round(width * scale)), 0, max(1, round(height * scale)), 0, 1, 0, channels)
    reduced = oiio.ImageBufAlgo.resize(oiio.ImageBuf(np.ascontiguousarray(pixels)), roi=roi)
    reduced = np.asarray(reduced.get_pixels(oiio.FLOAT), dtype=np.float32).reshape(roi.height, roi.width, channels)
    return np.maximum(reduced, 0.0)


@dataclass
class TextureTable:
    """Collects the textures a scene's materials and lights use, each once per use (colour or data), as GPU
    records and packed texels: colour textures in ``working_space``, through the OCIO config ``colour_config``."""

    base_dir: Path
    warnings: list[str] = field(default_factory=list)
    working_space: str = DEFAULT_WORKING_SPACE
    colour_config: str = DEFAULT_SOURCE
    _records: list[np.ndarray] = field(default_factory=list)
    _texels: list[np.ndarray] = field(default_factory=list)
    _texel_count: int = 0  # in uints
    _index: dict[tuple[int, bool], int] = field(default_factory=dict)
    # The textures indexed, kept alive: a temporary one (the sky's pixels) freed would leave its id to another.
    _held: list[Texture] = field(default_factory=list)

    def index_of(self, texture: Texture | None, data: bool = False) -> int:
        """The record index of ``texture`` (added on first use), or -1 for none. ``data``: the slot holds numbers
        (roughness, normals, heights, opacity, a weight), read as stored rather than as a colour."""
        if texture is None:
            return -1
        key = (id(texture), data)  # a texture used both ways is read both ways
        if key not in self._index:
            self._index[key] = self._add(texture, data)
            self._held.append(texture)
        return self._index[key]

    def warn(self, message: str) -> None:
        """A problem the render survives, said once (the caller reports them)."""
        if message not in self.warnings:
            self.warnings.append(message)

    def _add(self, texture: Texture, data: bool = False) -> int:
        record = np.zeros((TEXTURE_ROWS, 4), np.float32)
        if isinstance(texture, ImageTexture):
            path = Path(texture.file)
            path = path if path.is_absolute() else self.base_dir / path
            try:
                rgb = self._read(path, texture.color_space, data)
            except ColourConfigError as exc:
                self.warn(f"{path}: {exc}; showing a magenta checkerboard instead")
                return self._add(MISSING)
            except OSError as exc:
                message = str(exc) if os.path.exists(path) else f"{path}: texture file not found"
                self.warn(f"{message}; showing a magenta checkerboard instead")
                return self._add(MISSING)
            self._add_texels(record, rgb, texture)
        elif isinstance(texture, InlineImageTexture):
            try:
                rgb = self._inline_pixels(texture, data)
            except ColourConfigError as exc:
                self.warn(f"{texture.name}: {exc}; showing a magenta checkerboard instead")
                return self._add(MISSING)
            self._add_texels(record, rgb, texture)
        elif isinstance(texture, Checkerboard):  # its colours are typed in the working space, as every colour is
            record[0, 0] = TEXTURE_CHECKER
            record[3, :3], record[4, :3] = texture.color_a, texture.color_b
        else:
            raise TypeError(f"no GPU packing for texture type {type(texture).__name__}")
        record[1:3, :3] = texture.uv_matrix()  # (s, t) = rows 1 and 2 . (u, v, 1)
        self._records.append(record)
        return len(self._records) - 1

    def _read(self, path: Path, color_space: str, data: bool) -> np.ndarray:
        self._check_colour_space(color_space, path, data)
        return read_texture_image(path, color_space, self.working_space, data=data, config_source=self.colour_config)

    def _inline_pixels(self, texture: InlineImageTexture, data: bool) -> np.ndarray:
        rgb = np.asarray(texture.pixels, np.float32)[..., :3]
        self._check_colour_space(texture.color_space, texture.name, data)
        return to_working_space(rgb, texture.color_space, True, self.working_space, data=data,
                                config_source=self.colour_config)

    def _check_colour_space(self, color_space: str, where: Path | str, data: bool) -> None:
        """A ColourConfigError for a colour space that is none (a scene file's reader refuses it; one set in the
        studio or by a script reaches here); a warning naming the texture where a data slot reads it raw."""
        problem = colour_space_problem(color_space, self.colour_config)
        if problem:
            raise ColourConfigError(f"color_space {problem}")
        note = data_slot_note(color_space, self.colour_config) if data else None
        if note:
            self.warn(f"{where}: {note}")

    def _add_texels(self, record: np.ndarray, rgb: np.ndarray, texture: ImageTexture | InlineImageTexture) -> None:
        height, width = rgb.shape[:2]
        rgb = np.asarray(rgb, np.float32)
        if np.abs(rgb).max(initial=0.0) <= HALF_MAX:
            halves = np.zeros((height, width, 4), np.float16)
            halves[..., :3] = rgb
            packed = halves.view(np.uint32).reshape(-1)  # two uints per texel: (r, g), (b, 0)
            texel_format = TEXELS_HALF
        else:  # an HDR sun brighter than half floats hold (65504) would turn infinite, and then black
            packed = np.ascontiguousarray(rgb).view(np.uint32).reshape(-1)  # three uints per texel: r, g, b
            texel_format = TEXELS_FLOAT
        record[0] = (TEXTURE_IMAGE, np.int32(self._texel_count).view(np.float32), width, height)
        record[3, :3] = (texel_format, WRAP_CODES[texture.wrap], FILTER_CODES[texture.filter])
        self._texels.append(packed)
        self._texel_count += packed.size

    def add_floats(self, values: np.ndarray) -> int:
        """Append raw float32 data (sampling tables) to the texel buffer; returns its offset in uints."""
        offset = self._texel_count
        self._texels.append(np.asarray(values, np.float32).view(np.uint32))
        self._texel_count += len(values)
        return offset

    def records(self) -> np.ndarray:
        return np.concatenate(self._records) if self._records else np.zeros((0, 4), np.float32)

    def texels(self) -> np.ndarray:
        return np.concatenate(self._texels) if self._texels else np.zeros(0, np.uint32)
