"""Write slide.png, the image the textured spot of the ``spot`` validation scene projects (run: python make_slide.py).

A 16 x 16 sRGB PNG: an orange "F" on a dim blue ground with a green corner at the top left. The "F" reads
wrongly when mirrored or turned, so an image projected the wrong way round shows at once.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

SIZE = 16


def slide(size: int = SIZE) -> np.ndarray:
    image = np.empty((size, size, 3), np.uint8)
    image[:] = (30, 40, 90)  # the ground
    image[2:14, 4:7] = (250, 160, 40)  # the F's stem
    image[2:5, 4:13] = (250, 160, 40)  # its top bar
    image[7:9, 4:11] = (250, 160, 40)  # its middle bar
    image[0:2, 0:2] = (40, 220, 60)  # the top left corner
    return image


def write(path: Path) -> None:
    import OpenImageIO as oiio

    from lenslab.render.film import write_pixels

    image = slide()
    write_pixels(path, image, oiio.ImageSpec(image.shape[1], image.shape[0], 3, oiio.UINT8))


if __name__ == "__main__":
    write(Path(__file__).resolve().parent / "slide.png")
