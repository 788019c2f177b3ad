"""Write label.png, the bitmap of the ``textured`` validation scene (run: python make_label.py).

A 24 x 16 sRGB PNG, wider than tall so that a transposed lookup shows: colour ramps (red grows to the right,
blue downwards) under a white "F" and a black top-left corner. The "F" reads wrongly when mirrored or turned,
so a texture that lands the wrong way round on a shape shows at once.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

WIDTH, HEIGHT = 24, 16


def label(width: int = WIDTH, height: int = HEIGHT) -> np.ndarray:
    x = np.linspace(0.0, 1.0, width)[None, :]
    y = np.linspace(0.0, 1.0, height)[:, None]
    image = np.empty((height, width, 3), np.float64)
    image[..., 0] = 0.2 + 0.7 * x  # red: left to right
    image[..., 1] = 0.45
    image[..., 2] = 0.2 + 0.6 * y  # blue: top to bottom
    image[3:13, 8:11] = 1.0  # the F's stem
    image[3:6, 8:18] = 1.0  # its top bar
    image[7:9, 8:15] = 1.0  # its middle bar
    image[0:3, 0:3] = 0.02  # the top left corner
    return np.round(image * 255).astype(np.uint8)


def write(path: Path) -> None:
    import OpenImageIO as oiio

    from lenslab.render.film import write_pixels

    image = label()
    write_pixels(path, image, oiio.ImageSpec(image.shape[1], image.shape[0], 3, oiio.UINT8))


if __name__ == "__main__":
    write(Path(__file__).resolve().parent / "label.png")
