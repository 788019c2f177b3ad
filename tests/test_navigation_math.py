"""The camera moves of lenslab.scene.navigation (no Qt): the mouse's travel counted the same however many events
carried it, orbits about a point off the view axis (the selection's centre), and pans and dollies that scale with
the pivot's distance. tests/test_viewport_framing.py holds the moves about the plane of focus."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lenslab.scene import navigation
from lenslab.scene.camera import ThinLensCamera


def _camera(**changes) -> ThinLensCamera:
    base = ThinLensCamera(position=(0.3, 1.2, 4.0), look_at=(0.0, 0.9, 0.0), focal_length_mm=35.0,
                          focus_distance_m=3.5, resolution=(300, 200))
    return dataclasses.replace(base, **changes)


def _in_camera(camera: ThinLensCamera, point) -> np.ndarray:
    """A world point in the camera's frame (right, up, back): the same numbers are the same place in the picture
    at the same distance."""
    return camera.basis() @ (np.asarray(point, float) - np.asarray(camera.position, float))


@pytest.mark.parametrize("events", [1, 2, 7, 100])
def test_the_travel_is_the_same_however_many_events_carry_it(events):
    travel = navigation.MouseTravel(10.0, 20.0)
    for i in range(1, events + 1):
        total = travel.move_to(10.0 + 100.0 * i / events, 20.0 - 40.0 * i / events)
    assert total == pytest.approx((100.0, -40.0), abs=1e-9)


@pytest.mark.parametrize("events", [2, 10, 100])
def test_travel_made_with_the_fine_modifier_counts_a_tenth(events):
    # Out 100 pixels at full speed, back 100 slowly: 90 pixels ahead whatever the events' rate.
    travel = navigation.MouseTravel(0.0, 0.0)
    for i in range(1, events + 1):
        travel.move_to(100.0 * i / events, 0.0)
    for i in range(1, events + 1):
        total = travel.move_to(100.0 - 100.0 * i / events, 0.0, fine=True)
    assert total == pytest.approx((100.0 - 100.0 * navigation.FINE_SPEED, 0.0), abs=1e-9)


def test_an_orbit_about_a_point_off_the_axis_keeps_its_place_in_the_picture():
    camera = _camera()
    centre = np.array([-0.6, 0.4, 0.5])  # left of and below the view axis, nearer than the plane of focus
    before = _in_camera(camera, centre)
    assert np.linalg.norm(before[:2]) > 0.3
    for dx, dy in [(120, 0), (0, -80), (300, 200), (-50, 1000)]:
        moved = dataclasses.replace(camera, **navigation.orbit(camera, dx, dy, centre))
        np.testing.assert_allclose(_in_camera(moved, centre), before, atol=1e-9)
        _right, _up, back = moved.basis()  # never over the top, about any point
        assert abs(back @ np.asarray(camera.up)) <= np.cos(np.radians(navigation.POLE_MARGIN_DEGREES)) + 1e-9


def test_an_orbit_about_the_plane_of_focus_is_the_orbit_about_that_point():
    camera = _camera()
    for dx, dy in [(120, 0), (-40, 65)]:
        about_focus = navigation.orbit(camera, dx, dy)
        about_point = navigation.orbit(camera, dx, dy, navigation.pivot(camera))
        for key in ("position", "look_at"):
            np.testing.assert_allclose(about_point[key], about_focus[key], atol=1e-12)


def test_the_pivot_is_the_selection_in_front_of_the_lens_else_the_plane_of_focus():
    camera = _camera()
    ahead = np.array([-0.6, 0.4, 0.5])
    np.testing.assert_allclose(navigation.gesture_pivot(camera, ahead), ahead)
    np.testing.assert_allclose(navigation.gesture_pivot(camera, None), navigation.pivot(camera))
    behind = np.asarray(camera.position) + camera.basis()[2]  # a metre behind the lens
    np.testing.assert_allclose(navigation.gesture_pivot(camera, behind), navigation.pivot(camera))
    assert navigation.pivot_depth(camera, navigation.pivot(camera)) == pytest.approx(camera.plane_of_focus_m)


def test_pan_and_dolly_scale_with_the_pivots_distance():
    camera = _camera()
    near = np.asarray(camera.position) - camera.basis()[2] * 1.0  # 1 m ahead on the axis
    far = np.asarray(camera.position) - camera.basis()[2] * 4.0
    assert navigation.pan_metres_per_pixel(camera, 300, 0.5, far) == pytest.approx(
        4 * navigation.pan_metres_per_pixel(camera, 300, 0.5, near))
    for centre, depth in ((near, 1.0), (far, 4.0)):
        moved = dataclasses.replace(camera, **navigation.dolly(camera, -navigation.DOLLY_PIXELS_PER_DOUBLING, centre))
        assert navigation.pivot_depth(moved, centre) == pytest.approx(depth / 2)
        np.testing.assert_allclose(moved.basis(), camera.basis(), atol=1e-12)  # along the axis, not turned
        never_through = dataclasses.replace(camera, **navigation.dolly(camera, -1e6, centre))
        assert navigation.pivot_depth(never_through, centre) == pytest.approx(
            depth * navigation.DOLLY_NEAREST_FRACTION)
