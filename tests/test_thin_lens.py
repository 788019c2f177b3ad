"""The thin-lens camera against the conventions in docs/architecture.md, measured on rendered images.

A point at depth d, with focus at s, blurs to a disk of diameter (f/N) |d - s| / d * f / s on the sensor.
We render a tiny emitting sphere and measure its disk from the image's second moment: a uniform disk of
radius R has E[r^2] = R^2 / 2, and the sphere's own image and the pixel's box filter add their variances.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenslab.optics import blur_diameter_mm
from lenslab.render.tracer import RenderSession
from tests.helpers import render_to_spp
from tests.scenes import axis_camera, point_light_scene

WIDTH = 160
SENSOR = (24.0, 24.0)  # a square sensor for a square image: pixels are square and the axis is centred


def render(renderer, scene, spp, width=WIDTH, height=WIDTH):
    session = RenderSession(renderer, scene, width=width, height=height, dispatch_seconds=0.5)
    image = render_to_spp(session, spp).image().mean(axis=2)
    session.release()
    return image


def moments(image):
    """Centroid and E[r^2] of an intensity image, in pixels (pixel centres at +0.5)."""
    h, w = image.shape
    y, x = np.mgrid[0:h, 0:w] + 0.5
    total = image.sum()
    cx, cy = (image * x).sum() / total, (image * y).sum() / total
    r2 = ((x - cx) ** 2 + (y - cy) ** 2)
    return cx, cy, (image * r2).sum() / total, (x - cx, y - cy)


def measured_blur_diameter_px(image, sphere_image_radius_px):
    _, _, mean_r2, _ = moments(image)
    pixel_filter = 1.0 / 6.0  # a 1-pixel box filter adds 1/12 per axis
    radius2 = 2.0 * (mean_r2 - pixel_filter) - sphere_image_radius_px**2
    return 2.0 * math.sqrt(radius2)


def mm_to_px(mm):
    return mm / SENSOR[0] * WIDTH


def measure_blur(renderer, focal, n, focus, depth, spp=64, **camera_args):
    """(measured, expected) blur-disk diameters in pixels, and the image.

    The emitter is sized so that its own image has a fifth of the blur disk's radius: small enough to
    subtract exactly, big enough that many lens samples see it (a speck would leave the moments to noise).
    """
    camera = axis_camera(focal_length_mm=focal, f_number=n, focus_distance_m=focus, sensor_mm=SENSOR,
                         resolution=(WIDTH, WIDTH), **camera_args)
    expected = mm_to_px(blur_diameter_mm(focal, n, focus, depth))
    sphere_image_radius_px = 0.2 * expected / 2
    angular_radius = math.atan(sphere_image_radius_px / WIDTH * SENSOR[0] / focal)
    radius_m = depth * math.sin(angular_radius)  # the silhouette of a sphere spans asin(r / d)
    image = render(renderer, point_light_scene(depth, radius_m, camera), spp=spp)
    return measured_blur_diameter_px(image, sphere_image_radius_px), expected, image


@pytest.mark.parametrize("focal, n, depth, focus", [(100.0, 1.4, 2.0, 0.5), (100.0, 2.0, 0.25, 0.5)])
def test_blur_disk_diameter_matches_thin_lens_formula(renderer, focal, n, depth, focus):
    measured, expected, _ = measure_blur(renderer, focal, n, focus, depth)
    assert 40 < expected < WIDTH * 0.9  # the setup itself: a disk big enough to measure, small enough to fit
    assert measured == pytest.approx(expected, rel=0.03)


def test_blur_shrinks_by_the_ratio_of_f_numbers(renderer):
    measured = {}
    for n in (1.4, 22.0):
        measured[n], expected, _ = measure_blur(renderer, 100.0, n, 0.35, 10.0)
    assert expected > 6  # still a measurable disk at f/22
    assert measured[1.4] / measured[22.0] == pytest.approx(22.0 / 1.4, rel=0.03)


def _chart(focus_depth, offset):
    """Emitting stripes on a plane at focus_depth + offset, filling the frame."""
    from lenslab.scene.materials import Emissive
    from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
    from lenslab.scene.shapes import Rectangle
    from lenslab.scene.transform import Transform

    z = -(focus_depth + offset)
    half = focus_depth * 0.3
    stripes = [
        Node(f"stripe {i}", Transform(translate=(-half + (i + 0.5) * half / 8, 0.0, z)), Rectangle((half / 16, 2 * half)), "lamp")
        for i in range(16)
    ]
    return stripes, Scene(environment=ConstantEnvironment((0, 0, 0)), render=RenderSettings(max_depth=1),
                          materials={"lamp": Emissive((1.0, 1.0, 1.0))}, nodes=stripes)


def test_plane_in_the_plane_of_focus_is_sharp_across_the_frame(renderer):
    import dataclasses

    focus = 2.0
    pinhole = axis_camera(focal_length_mm=35.0, f_number=128.0, focus_distance_m=focus, resolution=(128, 96))
    wide_open = dataclasses.replace(pinhole, f_number=1.4)
    _, in_focus = _chart(focus, 0.0)
    _, off_focus = _chart(focus, 0.15)

    def shot(scene, camera):
        return render(renderer, dataclasses.replace(scene, camera=camera), spp=32, width=128, height=96)

    sharp_reference = shot(in_focus, pinhole)
    assert sharp_reference.max() == pytest.approx(1.0) and sharp_reference.min() == 0.0  # the chart fills the frame
    # Wide open, a plane exactly at the focus distance renders as sharp as through a pinhole, corners included
    # (a spherical "plane" of focus would blur the corners). A plane 15 cm behind it does not.
    difference_in_focus = np.abs(shot(in_focus, wide_open) - sharp_reference)
    difference_off_focus = np.abs(shot(off_focus, wide_open) - shot(off_focus, pinhole))
    corners = np.zeros_like(sharp_reference, bool)
    corners[:24, :24] = corners[:24, -24:] = corners[-24:, :24] = corners[-24:, -24:] = True
    assert difference_in_focus.mean() < 0.01
    assert difference_in_focus[corners].mean() < 0.01
    assert difference_off_focus.mean() > 10 * difference_in_focus.mean()


def _six_fold_harmonic(image):
    """<r^6 cos 6 theta> / <r^6>: about zero for a disk, positive for a hexagon with a corner on +x."""
    _, _, _, (dx, dy) = moments(image)
    dy = -dy  # image rows grow downwards; angles are measured counter-clockwise from +x
    r6 = (dx**2 + dy**2) ** 3
    theta = np.arctan2(dy, dx)
    return float((image * r6 * np.cos(6 * theta)).sum() / (image * r6).sum())


def _ideal_hexagon_harmonic(emitter_radius=0.2):
    """The same statistic for a uniform hexagon (corner on +x, circumradius 1) blurred by the emitter's own
    round image (radius ``emitter_radius``), from a million random points."""
    rng = np.random.default_rng(1)
    p = rng.uniform(-1, 1, (3_000_000, 2))
    theta = np.arctan2(p[:, 1], p[:, 0])
    from_edge_normal = theta % (np.pi / 3) - np.pi / 6  # edge normals at 30 + 60k degrees
    p = p[np.hypot(p[:, 0], p[:, 1]) * np.cos(from_edge_normal) <= math.cos(math.pi / 6)][:1_000_000]
    r, phi = emitter_radius * np.sqrt(rng.uniform(size=len(p))), rng.uniform(0, 2 * np.pi, len(p))
    x, y = p[:, 0] + r * np.cos(phi), p[:, 1] + r * np.sin(phi)
    r6 = (x**2 + y**2) ** 3
    return float((r6 * np.cos(6 * np.arctan2(y, x))).sum() / r6.sum())


def test_six_blade_aperture_gives_a_hexagonal_bokeh(renderer):
    def harmonic(**aperture):
        _, _, image = measure_blur(renderer, 100.0, 2.0, 2.0, 0.5, spp=256, **aperture)
        return _six_fold_harmonic(image)

    ideal = _ideal_hexagon_harmonic()
    assert harmonic(aperture_blades=6) == pytest.approx(ideal, rel=0.1)
    assert harmonic(aperture_blades=6, blade_rotation_deg=30.0) == pytest.approx(-ideal, rel=0.1)  # blades turn
    assert abs(harmonic(aperture_blades=0)) < 0.1 * ideal


@pytest.mark.parametrize("pixel_filter, method, left, right", [
    ("box", "", 0.0, 1.0),
    ("gaussian", "splat, expected weights", 0.1587, 0.8413),
    ("gaussian", "splat, sampled weights", 0.1587, 0.8413),
    ("gaussian", "importance", 0.1587, 0.8413),  # the fallback for images too large to splat on the device
])
def test_pixel_filter_spreads_an_edge_as_the_filter_says(renderer, monkeypatch, pixel_filter, method, left, right):
    """A sharp edge of light on a pixel boundary: a box filter keeps it, a gaussian of 0.5 px spreads it into
    the neighbouring pixels as its CDF at -+1 stddev (0.159 and 0.841), however its samples are spread."""
    import dataclasses

    from lenslab.render import tracer

    if method == "importance":
        monkeypatch.setattr(tracer, "SPLAT_MEMORY_BYTES", 0)
    weights = "sampled" if "sampled" in method else "expected"

    from lenslab.scene.materials import Emissive
    from lenslab.scene.scene import Node, RenderSettings, Scene
    from lenslab.scene.shapes import Rectangle
    from lenslab.scene.transform import Transform

    camera = axis_camera(focal_length_mm=50.0, sensor_mm=(36.0, 36.0), resolution=(32, 32), pinhole=True)
    half_width = 10.0 * 18.0 / 50.0  # the image half-width at 10 m
    scene = Scene(camera=camera, render=RenderSettings(max_depth=1, pixel_filter=pixel_filter, filter_weights=weights),
                  materials={"lamp": Emissive((1.0, 1.0, 1.0))},
                  nodes=[Node("right half", Transform(translate=(half_width, 0.0, -10.0)),
                              Rectangle((2 * half_width, 4 * half_width)), "lamp")])
    session = RenderSession(renderer, scene, width=32, height=32)
    assert (session.splat_layers > 0) == method.startswith("splat")
    assert any("too large to splat" in w for w in session.warnings) == (method == "importance")
    session.release()
    image = render(renderer, scene, spp=256, width=32, height=32)
    assert camera.lens_radius == 0.0
    columns = image[8:24].mean(axis=0)
    assert columns[15] == pytest.approx(left, abs=0.02) and columns[16] == pytest.approx(right, abs=0.02)
    assert columns[:14].max() < 0.01 and columns[18:].min() > 0.99
