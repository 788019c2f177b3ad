"""The viewport's framing (ThinLensCamera.view_frame), render regions and resizing a RenderSession, and the camera
moves of lenslab.scene.navigation."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from lenslab.scene import navigation
from lenslab.scene.camera import ThinLensCamera


def _camera(**changes) -> ThinLensCamera:
    base = ThinLensCamera(position=(0.3, 1.2, 4.0), look_at=(0.0, 0.9, 0.0), focal_length_mm=35.0, f_number=2.0,
                          focus_distance_m=3.5, resolution=(300, 200), barrel_clipping=0.6)
    return dataclasses.replace(base, **changes)


@pytest.mark.parametrize("fit", ["auto", "horizontal", "vertical", "fill", "overscan"])
@pytest.mark.parametrize("view", [(500, 200), (200, 400), (300, 200)])
def test_the_view_shows_the_export_frame_inside_its_gate_with_the_same_rays(fit, view):
    camera = _camera(sensor_fit=fit)
    export = camera.frame()
    shown = camera.view_frame(*view, margin=0.05)
    x, y, w, h = shown.gate_pixels
    # The gate has the export's shape and lies inside the picture with at least the margin to spare.
    assert w / h == pytest.approx(300 / 200, rel=1e-9)
    assert x >= -1e-9 and y >= -1e-9
    assert min(x / w, y / h) == pytest.approx(0.05, rel=1e-6)
    # The same points of the frame (corners, centre, an arbitrary point) give the same rays, lens samples too.
    fractions = np.array([[0.0, 0.0], [1.0, 1.0], [0.5, 0.5], [0.13, 0.77], [1.0, 0.0]])
    export_pixels = fractions * [export.width, export.height]
    shown_pixels = [x, y] + fractions * [w, h]
    lens = np.array([[0.1, 0.9], [0.95, 0.5], [0.5, 0.5], [0.3, 0.2], [0.99, 0.99]])
    o1, d1, w1 = export.rays(export_pixels, lens, with_weights=True)
    o2, d2, w2 = shown.rays(shown_pixels, lens, with_weights=True)
    np.testing.assert_allclose(d2, d1, atol=1e-9)
    np.testing.assert_allclose(o2, o1, atol=1e-12)
    np.testing.assert_array_equal(w2, w1)  # the barrel clips the same rays: cat's eyes match the export's


def test_the_gate_is_the_whole_picture_when_framed_as_the_export():
    frame = _camera().frame(300, 200)
    assert frame.gate_pixels == (0.0, 0.0, 300.0, 200.0)


# -- the camera moves ---------------------------------------------------------------------------------------------
def test_orbit_turns_about_the_plane_of_focus_and_keeps_it_sharp():
    camera = _camera()
    centre = navigation.pivot(camera)
    for dx, dy in [(120, 0), (0, -80), (300, 200), (-50, 1000)]:
        moved = dataclasses.replace(camera, **navigation.orbit(camera, dx, dy))
        # Same distance to the pivot, which stays on the view axis at the plane of focus.
        assert np.linalg.norm(np.subtract(moved.position, centre)) == pytest.approx(
            np.linalg.norm(np.subtract(camera.position, centre)), rel=1e-9)
        np.testing.assert_allclose(navigation.pivot(moved), centre, atol=1e-9)
        # Never straight over the top: the image's up would turn over.
        _right, _up, back = moved.basis()
        assert abs(back @ np.asarray(camera.up)) <= math.cos(math.radians(navigation.POLE_MARGIN_DEGREES)) + 1e-9


def test_orbit_direction_follows_the_mouse():
    camera = ThinLensCamera(position=(0.0, 1.0, 5.0), look_at=(0.0, 1.0, 0.0))
    right = navigation.orbit(camera, 100, 0)
    down = navigation.orbit(camera, 0, 100)
    assert right["position"][0] < 0  # dragging right swings the camera to the subject's left side
    assert down["position"][1] > 1.0  # dragging down raises the camera


def test_pan_moves_camera_and_target_together_across_the_view():
    camera = _camera()
    moved = navigation.pan(camera, 0.5, -0.25)
    shift = np.subtract(moved["position"], camera.position)
    np.testing.assert_allclose(np.subtract(moved["look_at"], camera.look_at), shift)
    right, up, back = camera.basis()
    assert shift @ back == pytest.approx(0.0, abs=1e-12)
    assert shift @ right == pytest.approx(-0.5) and shift @ up == pytest.approx(-0.25)


def test_dolly_walks_along_the_axis_and_never_through_the_pivot():
    camera = _camera()
    centre = navigation.pivot(camera)
    start = np.linalg.norm(np.subtract(camera.position, centre))
    closer = navigation.dolly(camera, -navigation.DOLLY_PIXELS_PER_DOUBLING)
    assert np.linalg.norm(np.subtract(closer["position"], centre)) == pytest.approx(start / 2)
    far_in = navigation.dolly(camera, -1e6)
    assert np.linalg.norm(np.subtract(far_in["position"], centre)) == pytest.approx(
        start * navigation.DOLLY_NEAREST_FRACTION)
    np.testing.assert_allclose(dataclasses.replace(camera, **closer).basis()[2], camera.basis()[2], atol=1e-12)


def test_frame_bounds_fits_the_box_in_the_frame():
    camera = _camera()
    lower, upper = np.array([1.0, 0.0, -2.0]), np.array([2.0, 0.5, -1.0])
    framed = dataclasses.replace(camera, **navigation.frame_bounds(camera, lower, upper))
    frame = framed.frame()
    corners = np.array([[x, y, z] for x in (lower[0], upper[0]) for y in (lower[1], upper[1])
                        for z in (lower[2], upper[2])])
    local = (corners - frame.position) @ frame.to_world
    depth = -local[:, 2]
    assert (depth > 0).all()
    assert (np.abs(local[:, 0] / depth) <= frame.tan_half_fov[0]).all()
    assert (np.abs(local[:, 1] / depth) <= frame.tan_half_fov[1]).all()


# -- a session resized, and a render region --------------------------------------------------------------------
@pytest.fixture
def cornell(renderer):
    from lenslab.scene.io.loader import open_scene

    scene = open_scene("cornell_box")
    scene.camera = dataclasses.replace(scene.camera, resolution=(40, 30))
    scene.render = dataclasses.replace(scene.render, pixel_filter="box", max_depth=3)
    return scene


def _render(renderer, scene, spp, *, size=None, resize_from=None, region=None, margin=None):
    from lenslab.render.tracer import RenderSession
    from tests.helpers import render_to_spp

    w, h = size or scene.camera.resolution
    first = resize_from or (w, h)
    session = RenderSession(renderer, scene, width=first[0], height=first[1])
    try:
        session.set_view(w, h, margin)
        if region is not None:
            session.set_region(region)
        return render_to_spp(session, spp).accumulation()
    finally:
        session.release()


def test_a_resized_session_renders_what_a_new_one_does(renderer, cornell):
    """The worker shrinks a session for its preview pass and grows it back: the camera must be framed again
    for the new size (it once kept the old size's frame, rendering the wrong pixels)."""
    fresh = _render(renderer, cornell, 2)
    resized = _render(renderer, cornell, 2, resize_from=(10, 8))
    np.testing.assert_array_equal(resized, fresh)


def test_a_render_region_renders_only_its_pixels_and_the_same_samples(renderer, cornell):
    full = _render(renderer, cornell, 3)
    part = _render(renderer, cornell, 3, region=(7, 5, 13, 9))
    inside = np.zeros((30, 40), bool)
    inside[5:14, 7:20] = True
    assert (part[inside, 3] == 3).all() and (part[~inside] == 0).all()
    # Same seed, same pixel, same sample indices: the region's pixels are the full render's.
    np.testing.assert_array_equal(part[inside], full[inside])


def test_a_region_outside_the_picture_is_clipped(renderer, cornell):
    part = _render(renderer, cornell, 1, region=(35, 25, 100, 100))
    assert (part[25:, 35:, 3] == 1).all() and part[:25, :, 3].sum() == 0 and part[:, :35, 3].sum() == 0


def test_the_view_framing_renders_the_export_inside_the_gate(renderer, cornell):
    """Rendered at a wider shape with a margin, the gate's pixels hold the export's picture (same rays; the
    pixels sample the same frame region at the same density when the gate is the same size)."""
    from lenslab.render import film

    export = film.resolve(_render(renderer, cornell, 64))
    # A 60 x 34 view whose gate is exactly 40 x 30 pixels: margin such that the height 30 * (1 + 2m) = 34.
    margin = (34 / 30 - 1) / 2
    camera = cornell.camera
    view = camera.view_frame(60, 34, margin)
    x, y, w, h = view.gate_pixels
    assert (w, h) == pytest.approx((40.0, 30.0)) and (x, y) == pytest.approx((10.0, 2.0))
    shown = film.resolve(_render(renderer, cornell, 64, size=(60, 34), margin=margin))
    gate = shown[2:32, 10:50]
    # Different pixels sample different sequences: compare the converging means, not the bits.
    assert abs(gate.mean() - export.mean()) / export.mean() < 0.03
    np.testing.assert_allclose(gate.reshape(6, 5, 8, 5, 3).mean(axis=(1, 3)),
                               export.reshape(6, 5, 8, 5, 3).mean(axis=(1, 3)), rtol=0.25, atol=0.02)
