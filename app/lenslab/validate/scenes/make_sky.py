"""Write sky.exr, the procedural panorama of the environment_depths validation scene (run: python make_sky.py).

A 128 x 64 lat-long image in Mitsuba's layout (u = atan2(x, -z) / 2pi, v = acos(y) / pi; LensLab reads it
with rotation_deg 180, which the importer sets). A blue-to-white sky gradient, a brownish ground, a sun
(a small bright blob), a red patch at azimuth +90 degrees (towards +X) and a blue one towards -Z: each
landmark is at a known direction, so a panorama turned the wrong way shows in the images at once.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

WIDTH, HEIGHT = 128, 64


def sky(width: int = WIDTH, height: int = HEIGHT) -> np.ndarray:
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi, theta = np.meshgrid(2 * np.pi * u, np.pi * v)
    d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)
    up = d[..., 1:2]
    horizon = np.array([0.9, 0.95, 1.0])
    zenith = np.array([0.25, 0.45, 0.9])
    ground = np.array([0.25, 0.2, 0.15])
    t = np.clip(up, 0, 1) ** 0.5
    image = np.where(up > 0, (1 - t) * horizon + t * zenith, ground * (0.6 + 0.4 * np.exp(8 * up)))

    def blob(direction, size):
        direction = np.asarray(direction, float) / np.linalg.norm(direction)
        return np.exp((d @ direction - 1) / size ** 2)[..., None]

    image = image + 40.0 * blob((0.6, 0.5, 0.3), 0.12) * np.array([1.0, 0.9, 0.75])  # the sun
    image = image + 2.0 * blob((1.0, 0.15, 0.0), 0.25) * np.array([1.0, 0.1, 0.05])  # red, towards +X
    image = image + 2.0 * blob((0.0, 0.2, -1.0), 0.25) * np.array([0.05, 0.2, 1.0])  # blue, towards -Z
    return image.astype(np.float32)


def write(path: Path) -> None:
    import OpenImageIO as oiio

    image = sky()
    spec = oiio.ImageSpec(image.shape[1], image.shape[0], 3, oiio.HALF)
    spec.attribute("compression", "zip")
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), spec)
    out.write_image(image)
    out.close()


if __name__ == "__main__":
    write(Path(__file__).with_name("sky.exr"))
