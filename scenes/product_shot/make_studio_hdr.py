"""Writes studio.exr: a small procedural HDR panorama of a photo studio (two softboxes, a strip light, a
warm floor and a dark grey cyclorama), so the product-shot scene needs no downloaded HDRI.

Run from this folder: python make_studio_hdr.py
"""

import numpy as np

from lenslab.render.environment import uv_to_direction
from lenslab.render.film import write_image

H, W = 128, 256
v, u = (np.mgrid[0:H, 0:W] + 0.5) / np.array([H, W])[:, None, None]
d = uv_to_direction(np.stack([u, v], axis=-1))

sky = np.full((H, W, 3), 0.03, np.float32) + 0.05 * np.clip(d[..., 1:2], 0, 1)  # dark cyclorama, lighter up
sky[d[..., 1] < 0] = (0.06, 0.05, 0.04)  # warm floor


def softbox(centre, half_width, half_height, radiance):
    """A rectangle of light facing the scene centre, given by its centre direction and angular size."""
    c = np.asarray(centre, float) / np.linalg.norm(centre)
    right = np.cross(c, (0, 1, 0))
    right /= np.linalg.norm(right)
    up = np.cross(right, c)
    inside = (d @ c > 0) & (np.abs(d @ right) < half_width) & (np.abs(d @ up) < half_height)
    sky[inside] = radiance


softbox((-1.0, 0.6, 0.8), 0.35, 0.25, (14.0, 13.5, 13.0))  # key, camera left
softbox((1.2, 0.3, 0.4), 0.2, 0.3, (4.0, 4.2, 4.6))  # fill, camera right
softbox((0.0, 0.4, -1.0), 0.6, 0.05, (9.0, 9.0, 9.0))  # strip light behind, for rims on the glass

write_image("studio.exr", sky.astype(np.float32))
