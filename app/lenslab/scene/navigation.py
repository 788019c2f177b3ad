"""Moving the camera as a studio's viewport does: orbit, pan, dolly and frame (docs/studio.md, "Moving the camera").

Each move is a function of the camera a gesture started from and how far the mouse has gone since, never of the
last step, so a drag has no drift, goes as far however many mouse events described it, and can be recomputed at any
point of it. A move changes only where the camera stands and looks (``position`` and ``look_at``): the lens, the
aperture and the focus ring stay as they were, as on a real camera carried around a set. Moves turn about and
scale with a *pivot*: the point where the view axis meets the plane of focus, so what is sharp stays sharp and
stays in the middle of the frame, or the selection's centre when something is selected, which then keeps its place
in the picture.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from lenslab.scene.camera import ThinLensCamera

#: Degrees of orbit per pixel of mouse travel (a drag across a 900-pixel viewport turns the camera 270 degrees).
ORBIT_DEGREES_PER_PIXEL = 0.3
#: A dolly halves or doubles the distance to the pivot every this many pixels of vertical travel.
DOLLY_PIXELS_PER_DOUBLING = 150.0
#: The closest a dolly brings the lens to the pivot, as a fraction of where it started.
DOLLY_NEAREST_FRACTION = 0.02
#: An orbit stops this many degrees short of looking straight along the camera's up (where "up" turns over).
POLE_MARGIN_DEGREES = 1.0
#: Mouse travel made while the fine modifier is held counts this much (a tenth: Blender's and Maya's fine drag).
FINE_SPEED = 0.1
#: A selection nearer the lens's plane than this (or behind it) is no pivot: the plane of focus is used instead.
NEAREST_PIVOT_M = 1e-3


def pivot(camera: ThinLensCamera) -> np.ndarray:
    """The point orbits turn about when nothing is selected: where the view axis meets the plane of focus."""
    right, up, back = camera.basis()
    return np.asarray(camera.position, float) - back * camera.plane_of_focus_m


def gesture_pivot(camera: ThinLensCamera, selection_centre: Sequence[float] | None = None) -> np.ndarray:
    """The point a gesture turns about and scales with: the selection's centre when there is one in front of the
    lens (Blender's "orbit around selection"), else the plane of focus on the view axis."""
    if selection_centre is not None and pivot_depth(camera, selection_centre) > NEAREST_PIVOT_M:
        return np.asarray(selection_centre, float)
    return pivot(camera)


def pivot_depth(camera: ThinLensCamera, centre: Sequence[float]) -> float:
    """How far ahead of the lens ``centre`` lies, along the view axis: the distance pans and dollies scale with."""
    _right, _up, back = camera.basis()
    return float(np.dot(np.asarray(camera.position, float) - np.asarray(centre, float), back))


@dataclass
class MouseTravel:
    """How far the mouse has gone in one gesture, each stretch of it counted at the speed it was made at (a tenth
    while the fine modifier is held). The total is a function of the path, not of how many events described it:
    a drag reported in one event or in a hundred gives the same camera."""

    x: float  # where the mouse is now
    y: float
    dx: float = 0.0  # the travel so far, weighted
    dy: float = 0.0

    def move_to(self, x: float, y: float, fine: bool = False) -> tuple[float, float]:
        """The mouse is at (x, y), having come from where it was with the fine modifier held or not; returns the
        travel since the gesture began."""
        speed = FINE_SPEED if fine else 1.0
        self.dx += (x - self.x) * speed
        self.dy += (y - self.y) * speed
        self.x, self.y = x, y
        return self.dx, self.dy


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """``v`` turned by ``angle`` radians about the unit ``axis`` (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * np.dot(axis, v) * (1.0 - c)


def _placed(position: np.ndarray, forward: np.ndarray, distance_to_look_at: float) -> dict:
    return {"position": tuple(float(v) for v in position),
            "look_at": tuple(float(v) for v in position + forward * distance_to_look_at)}


def orbit(camera: ThinLensCamera, dx_pixels: float, dy_pixels: float,
          centre: Sequence[float] | None = None) -> dict:
    """``position`` and ``look_at`` after turning the camera about ``centre`` (by default the plane of focus on
    the view axis): dragging right swings the camera to the left around the subject (the subject turns with the
    mouse), dragging down raises it. The camera turns as a rigid whole, so the centre keeps its place in the
    picture and its distance, on the view axis or off it."""
    centre = pivot(camera) if centre is None else np.asarray(centre, float)
    right, up, back = camera.basis()
    world_up = np.asarray(camera.up, float)
    world_up = world_up / np.linalg.norm(world_up)
    offset = np.asarray(camera.position, float) - centre
    # Yaw about the world's up (a positive angle would swing the camera to its right); then pitch about the
    # camera's right axis, which by the right-hand rule lowers the camera for a positive angle; the elevation is
    # held short of the poles, where the image's up would turn over. The right axis is level, so the pitch
    # changes the view's elevation by exactly its angle.
    yaw = -math.radians(dx_pixels * ORBIT_DEGREES_PER_PIXEL)
    elevation = math.asin(float(np.clip(np.dot(back, world_up), -1.0, 1.0)))
    limit = math.radians(90.0 - POLE_MARGIN_DEGREES)
    raised = float(np.clip(elevation + math.radians(dy_pixels * ORBIT_DEGREES_PER_PIXEL), -limit, limit))
    pitch = -(raised - elevation)
    offset = _rotate(_rotate(offset, right, pitch), world_up, yaw)
    back = _rotate(_rotate(back, right, pitch), world_up, yaw)
    return _placed(centre + offset, -back / np.linalg.norm(back), _look_distance(camera))


def pan(camera: ThinLensCamera, dx_metres: float, dy_metres: float) -> dict:
    """``position`` and ``look_at`` moved together across the view: the scene follows the mouse (dragging right
    moves the camera left). Distances are in metres in the plane of the pivot."""
    right, up, _back = camera.basis()
    shift = -right * dx_metres + up * dy_metres
    return {"position": tuple(float(v) for v in np.asarray(camera.position, float) + shift),
            "look_at": tuple(float(v) for v in np.asarray(camera.look_at, float) + shift)}


def dolly(camera: ThinLensCamera, dy_pixels: float, centre: Sequence[float] | None = None) -> dict:
    """``position`` moved along the view axis: dragging up (negative dy) walks towards the pivot's depth (the
    plane of focus by default), halving the distance every DOLLY_PIXELS_PER_DOUBLING pixels; never through it."""
    depth = camera.plane_of_focus_m if centre is None else pivot_depth(camera, centre)
    _right, _up, back = camera.basis()
    new_depth = max(depth * 2.0 ** (dy_pixels / DOLLY_PIXELS_PER_DOUBLING), depth * DOLLY_NEAREST_FRACTION)
    position = np.asarray(camera.position, float) - back * (depth - new_depth)
    return _placed(position, -back, _look_distance(camera))


def pan_metres_per_pixel(camera: ThinLensCamera, view_width_pixels: float, view_tan_half_fov_x: float,
                         centre: Sequence[float] | None = None) -> float:
    """How far the pivot's plane (the plane of focus by default) moves for one pixel of mouse travel, so what
    lies there follows the mouse."""
    depth = camera.plane_of_focus_m if centre is None else pivot_depth(camera, centre)
    return 2.0 * depth * view_tan_half_fov_x / max(view_width_pixels, 1.0)


def frame_bounds(camera: ThinLensCamera, lower: Sequence[float], upper: Sequence[float],
                 fill: float = 0.8) -> dict:
    """``position`` and ``look_at`` that frame the box (lower, upper) in the export's frame: the camera keeps its
    direction and backs off (or closes in) along it until the box's bounding sphere fills ``fill`` of the
    frame's shorter field of view, looking at the box's centre."""
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    centre = (lo + hi) / 2.0
    radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 1e-3)
    frame = camera.frame()
    half_angle = math.atan(min(frame.tan_half_fov)) * fill
    distance = radius / math.sin(max(half_angle, 1e-3))
    _right, _up, back = camera.basis()
    position = centre + back * distance
    return {"position": tuple(float(v) for v in position), "look_at": tuple(float(v) for v in centre)}


def _look_distance(camera: ThinLensCamera) -> float:
    """How far ahead ``look_at`` sits: kept, so the file's camera reads as it did."""
    distance = float(np.linalg.norm(np.asarray(camera.look_at, float) - np.asarray(camera.position, float)))
    return distance if distance > 1e-6 else 1.0
