"""Write the textures of the ``relief`` validation scene (run: python make_relief.py).

* ``relief_height.exr``: a 64 x 64 height field of soft bumps (linear float), for a bump map;
* ``relief_normals.exr``: the same bumps as a tangent-space normal map ((n + 1) / 2, linear float), with
  +X along u and +Y along v of the image as Mitsuba reads it;
* ``relief_stencil.png``: a 64 x 64 8-bit opacity stencil: solid discs on a clear ground with a half-opaque
  band, for a mask.

Float EXRs keep the height and the normals exact, so the bump and normal maps are compared with Mitsuba's
without any 8-bit rounding.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

SIZE = 64


def height(size: int = SIZE) -> np.ndarray:
    """Bumps that repeat across the image: h = (sin 2pi 3u sin 2pi 2v + 1) / 2."""
    u = (np.arange(size) + 0.5) / size
    uu, vv = np.meshgrid(u, u)
    return 0.5 * (np.sin(2 * np.pi * 3 * uu) * np.sin(2 * np.pi * 2 * vv) + 1.0)


def normals(size: int = SIZE, strength: float = 0.6) -> np.ndarray:
    """The tangent-space normals of ``strength`` times those bumps: n ~ (-dh/du, -dh/dv, 1)."""
    u = (np.arange(size) + 0.5) / size
    uu, vv = np.meshgrid(u, u)
    dh_du = 0.5 * 2 * np.pi * 3 * np.cos(2 * np.pi * 3 * uu) * np.sin(2 * np.pi * 2 * vv)
    dh_dv = 0.5 * 2 * np.pi * 2 * np.sin(2 * np.pi * 3 * uu) * np.cos(2 * np.pi * 2 * vv)
    n = np.stack([-strength * dh_du, -strength * dh_dv, np.ones_like(uu)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return 0.5 * (n + 1.0)


def stencil(size: int = SIZE) -> np.ndarray:
    u = (np.arange(size) + 0.5) / size
    uu, vv = np.meshgrid(u, u)
    discs = (((uu * 4) % 1 - 0.5) ** 2 + ((vv * 4) % 1 - 0.5) ** 2) < 0.12
    band = np.abs(vv - 0.5) < 0.1
    return np.where(discs, 1.0, np.where(band, 0.5, 0.0))


def _write(path: Path, pixels: np.ndarray, fmt: str) -> None:
    import OpenImageIO as oiio

    from lenslab.render.film import write_pixels

    pixels = np.ascontiguousarray(pixels)
    write_pixels(path, pixels, oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], fmt))


def write(folder: Path) -> None:
    _write(folder / "relief_height.exr", np.repeat(height()[..., None], 3, axis=2).astype(np.float32), "float")
    _write(folder / "relief_normals.exr", normals().astype(np.float32), "float")
    _write(folder / "relief_stencil.png", (np.repeat(stencil()[..., None], 3, axis=2) * 255).round().astype(np.uint8),
           "uint8")


if __name__ == "__main__":
    write(Path(__file__).resolve().parent)
