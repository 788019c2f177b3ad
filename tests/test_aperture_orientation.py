"""Which way round an aperture image comes out in the bokeh, with a shape that shows it: an L.

The convention (docs/scene-format.md, "aperture_image"): the image as an image viewer shows it is the stop seen from
behind the camera, as blade stops are (their rotation counts counter-clockwise from +x seen from behind). A light
beyond the plane of focus makes bokeh of the stop the right way up; one in front of it, rotated by 180 degrees,
because its rays have not yet crossed when they reach the sensor. Blade stops and images must agree on both.
"""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio
import pytest

from lenslab.render.job import RenderJob
from lenslab.scene.aperture_images import read_aperture_image

from .scenes import axis_camera, point_light_scene

pytestmark = pytest.mark.gl

PIXELS = 48


def write_l(path) -> np.ndarray:
    """An L as an image viewer shows it: the upright down the left third, the foot along the bottom third. Written
    through an ImageBuf with explicit channels: OpenImageIO 3.2's ImageOutput.write_image turns a 2-D array round
    by 180 degrees, which is how an "upside-down L" can come to be in the file itself."""
    image = np.zeros((9, 9, 1), np.float32)
    image[:, 0:3] = 1.0
    image[6:9, :] = 1.0
    buf = oiio.ImageBuf(oiio.ImageSpec(9, 9, 1, oiio.UINT8))
    buf.set_pixels(oiio.ROI(0, 9, 0, 9, 0, 1, 0, 1), image)
    assert buf.write(str(path))
    return image[..., 0]


def bokeh(renderer, lamp_m: float, focus_m: float, lamp_radius_m: float, **stop) -> np.ndarray:
    """The lit pixels of a small lamp on the axis, out of focus (the sensor held at f, focus from the lens)."""
    camera = axis_camera(focal_length_mm=50.0, f_number=2.0, focus_distance_m=focus_m, sensor_mm=(7.5, 7.5),
                         resolution=(PIXELS, PIXELS), **stop)
    job = RenderJob(renderer, point_light_scene(lamp_m, lamp_radius_m, camera), spp=1024)
    image = job.run()[..., 0]
    job.release()
    plateau = np.median(image[image > 0.2 * image.max()])
    return image > 0.5 * plateau


def heavy_sides(mask: np.ndarray) -> tuple[str, str]:
    """Which half of the lit area holds its widest row ("top" or "bottom") and its tallest column ("left" or
    "right"): an L the right way up has its foot at the bottom and its upright on the left."""
    rows, cols = np.nonzero(mask.any(axis=1))[0], np.nonzero(mask.any(axis=0))[0]
    widest = rows[np.argmax(mask[rows].sum(axis=1))]
    tallest = cols[np.argmax(mask[:, cols].sum(axis=0))]
    return ("bottom" if widest > rows.mean() else "top", "left" if tallest < cols.mean() else "right")


BEYOND = dict(lamp_m=5.0, focus_m=0.25, lamp_radius_m=0.02)  # bokeh about 30 pixels across
IN_FRONT = dict(lamp_m=0.3, focus_m=5.0, lamp_radius_m=0.003)  # about 25 pixels across


def test_the_l_is_read_as_written(tmp_path):
    written = write_l(tmp_path / "L.png")
    assert np.array_equal(read_aperture_image(str(tmp_path / "L.png")) > 0.5, written > 0.5)


def test_beyond_the_plane_of_focus_the_bokeh_is_the_image_the_right_way_up(renderer, tmp_path):
    write_l(tmp_path / "L.png")
    assert heavy_sides(bokeh(renderer, **BEYOND, aperture_image=str(tmp_path / "L.png"))) == ("bottom", "left")
    # A triangle with a corner straight up (blade rotation 90 degrees): its wide edge is at the bottom.
    assert heavy_sides(bokeh(renderer, **BEYOND, aperture_blades=3, blade_rotation_deg=90.0))[0] == "bottom"


def test_in_front_of_the_plane_of_focus_image_and_blades_turn_round_together(renderer, tmp_path):
    write_l(tmp_path / "L.png")
    assert heavy_sides(bokeh(renderer, **IN_FRONT, aperture_image=str(tmp_path / "L.png"))) == ("top", "right")
    assert heavy_sides(bokeh(renderer, **IN_FRONT, aperture_blades=3, blade_rotation_deg=90.0))[0] == "top"
