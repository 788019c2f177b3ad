"""Aperture images (a star, a heart: custom bokeh) read from disk, once per file version.

The camera names its image relative to the scene's folder; every frame the renderer and the studio build asks
for it, so the pixels are cached by absolute path and modification time: an edited file is read again.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from lenslab.color import luminance, srgb_to_linear
from lenslab.image_files import read_pixels


def resolve(name: str, base_dir: Path | None) -> Path:
    path = Path(name).expanduser()
    return path if path.is_absolute() else (base_dir or Path.cwd()) / path


def read_aperture_image(name: str, base_dir: Path | None = None) -> np.ndarray:
    """The image's transmission as (H, W) float64 in [0, 1]: its luminance (alpha where it has one). Raises
    ValueError naming the file when it is missing, unreadable or black."""
    path = resolve(name, base_dir)
    try:
        stamp = path.stat().st_mtime_ns
    except OSError:
        raise ValueError(f"aperture image not found: {path}") from None
    return _read(str(path), stamp)


@lru_cache(maxsize=8)
def _read(path: str, stamp: int) -> np.ndarray:
    try:
        pixels, is_float = read_pixels(path)
    except OSError as exc:  # the callers' errors are ValueErrors, naming the camera's key
        raise ValueError(str(exc)) from None
    pixels = pixels.astype(np.float64)
    if not is_float:  # 8 and 16-bit files hold sRGB-encoded values
        pixels = srgb_to_linear(np.clip(pixels, 0.0, 1.0))
    channels = pixels.shape[2]
    if channels in (2, 4):  # alpha is the transmission
        transmission = pixels[..., -1]
    elif channels >= 3:  # luminance (Rec. 709)
        transmission = luminance(pixels[..., :3])
    else:
        transmission = pixels[..., 0]
    transmission = np.clip(np.nan_to_num(transmission, nan=0.0), 0.0, 1.0)
    if not transmission.any():
        raise ValueError(f"{path}: the aperture image is black everywhere: it lets no light through")
    transmission.setflags(write=False)
    return transmission
