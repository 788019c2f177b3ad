"""The side view of a real lens: its elements in profile, the stop at its current opening, the sensor, and two fans
of rays traced through the glass at the lens's current focus (docs/lenses.md).

What it draws is the lens the renderer traces: the same surfaces, standing where unit focusing has moved them
(``LensSystem.vertex_z``), and rays through the renderer's own tracer, which keeps each surface's points for a
drawing (``lens_system.trace_path_from_scene``).

Coordinates are the camera frame's, in millimetres: light travels towards +z, the sensor lies at ``z = efl``. The
side view is the y-z plane (the meridional plane), +y drawn up, the scene on the left. A film point below the axis
images the scene above it, so the off-axis fan, which comes from the top of the picture, lands below the axis.

The geometry is plain numpy, cached per lens, focus and stop (:func:`lens_view`); painting only maps it to pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from PySide6.QtCore import QPointF, QSize, Qt
from PySide6.QtGui import QColor, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QSizePolicy, QWidget

from lenslab.gui import theme
from lenslab.optics.aperture import Aperture
from lenslab.optics.lens_system import LensSetting, LensSystem, trace_path_from_scene

__all__ = ["LensDiagram", "LensView", "RayPath", "lens_view"]

#: Where each fan's rays cross the stop, as fractions of its current radius (the middle one is the chief ray of
#: its fan): near the rim, so that the cone the stop lets through reads at a glance. The fan from the frame's corner
#: has more rays: the glass's rims cut its cone down (vignetting), and a few inner rays still show what gets through.
ON_AXIS_FAN = (-0.92, -0.5, 0.0, 0.5, 0.92)
OFF_AXIS_FAN = (-0.92, -0.6, -0.3, 0.0, 0.3, 0.6, 0.92)
#: Points along each surface's arc.
ARC_POINTS = 25
#: Colours: the glass a pale blue-grey (as lens drawings colour it), the on-axis fan the studio's focus green, the
#: off-axis fan its amber.
GLASS_FILL = QColor(158, 188, 222, 100)
GLASS_EDGE = QColor(196, 218, 240, 210)
ON_AXIS = QColor(theme.FOCUS)
OFF_AXIS = QColor(theme.ACCENT)
STOP = QColor("#e6e6e6")
SENSOR = QColor("#c8c8c8")
AXIS = QColor("#6c6f74")


@dataclass(frozen=True)
class RayPath:
    """One drawn ray: its points in the side view, (k, 2) as (z, y) mm, from where it enters the drawing to where
    it ends: on the sensor, or where the glass (a rim, the stop) stops it."""

    points: np.ndarray
    on_axis: bool
    reached_sensor: bool


@dataclass(frozen=True)
class LensView:
    """Everything the side view shows of one lens at one focus and stop, in mm (camera frame)."""

    system: LensSystem
    shift: float  # how far the lens has moved forward from infinity focus
    stop_radius: float
    rays: tuple[RayPath, ...]
    front_z: float  # where the drawing begins: a little in front of the front element
    sensor_z: float
    half_height: float  # the drawing's half height: the largest element or the sensor's half diagonal
    sensor_half_diagonal: float
    #: The chief ray's angle to the axis at the frame's corner, degrees: half the traced diagonal field of view.
    #: None where no ray from the corner gets through (the corner lies outside the lens's image circle).
    corner_half_angle_deg: float | None
    #: The farthest film radius a chief ray reaches (the image circle's radius, where it is smaller than the
    #: frame's half diagonal) and its angle, degrees.
    covered_radius_mm: float
    covered_half_angle_deg: float


# -- tracing, surface by surface ------------------------------------------------------------------------------------
def _stop_height(system: LensSystem, origins, directions, shift: float) -> np.ndarray:
    """The height (y) at which rays cross the plane of the stop, through the glass in front of it, openings
    ignored; NaN where a ray misses a surface on the way."""
    points, _, _, alive = trace_path_from_scene(system, origins, directions, shift, math.inf, clip=False,
                                                last=system.stop)
    return np.where(alive, points[-1][:, 1], np.nan)


class _Family:
    """A one-parameter family of rays in the side view, from one object point (or one direction, for a point at
    infinity): ``rays(a)`` gives origins and directions. From a point the parameter is the ray's angle to the
    axis; from infinity, the ray's offset across the beam."""

    def __init__(self, point: np.ndarray | None, direction: np.ndarray, base: np.ndarray | None = None):
        self.point, self.direction = point, direction / np.linalg.norm(direction)
        self.base = base  # from infinity: a point on the family's own ray, in front of the lens

    def rays(self, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a = np.asarray(a, float)
        if self.point is not None:
            d = np.stack([np.zeros_like(a), np.sin(a), np.cos(a)], axis=-1)
            return np.tile(self.point, (len(a), 1)), d
        u = self.direction
        across = np.array([0.0, u[2], -u[1]])
        return self.base + a[:, None] * across, np.tile(u, (len(a), 1))

    def start(self) -> float:
        """The parameter of the ray along ``direction``."""
        return math.atan2(self.direction[1], self.direction[2]) if self.point is not None else 0.0


def _aim(system: LensSystem, family: _Family, targets: np.ndarray, shift: float) -> np.ndarray:
    """The family's parameters whose rays cross the stop's plane at heights ``targets``: Newton's method from the
    family's own ray (which passes near the stop's centre), with the slope by a small difference."""
    a = np.full(len(targets), family.start())
    # The difference for the slope, and the longest step (so that a ray missing the glass does not fling the next
    # guess away): radians from a point, millimetres across a beam from infinity.
    eps, longest = (1e-5, 0.2) if family.point is not None else (1e-3, 50.0)
    for _ in range(10):
        h = _stop_height(system, *family.rays(a), shift)
        slope = (_stop_height(system, *family.rays(a + eps), shift) - h) / eps
        usable = np.isfinite(h) & np.isfinite(slope) & (np.abs(slope) > 1e-12)
        a = a - np.clip(np.where(usable, (h - targets) / np.where(usable, slope, 1.0), 0.0), -longest, longest)
    return a


def _fan(system: LensSystem, family: _Family, shift: float, stop_radius: float, front_z: float,
         on_axis: bool) -> list[RayPath]:
    targets = np.array(ON_AXIS_FAN if on_axis else OFF_AXIS_FAN) * stop_radius
    origins, directions = family.rays(_aim(system, family, targets, shift))
    # Each ray enters the drawing at its left edge (or at its object point, where that lies inside it).
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(origins[:, 2] < front_z, (front_z - origins[:, 2]) / directions[:, 2], 0.0)
    starts = origins + t[:, None] * directions
    points, out, ends, alive = trace_path_from_scene(system, origins, directions, shift, stop_radius)
    sensor_z = system.efl
    paths = []
    for k in range(len(origins)):
        chain = [starts[k]] + [points[i, k] for i in range(ends[k])]
        reached = bool(alive[k]) and out[k, 2] > 0.0
        if reached:
            last = points[-1, k]
            chain.append(last + (sensor_z - last[2]) / out[k, 2] * out[k])
        paths.append(RayPath(np.array([(p[2], p[1]) for p in chain]), on_axis, reached))
    return paths


def _chief_angles(system: LensSystem, shift: float, radii: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                                   np.ndarray]:
    """Chief rays from film points at ``radii`` below the axis: their points on the front element, their
    directions out into the scene, and which get through (the renderer's own aiming, ``LensSetting.chief_rays``)."""
    setting = LensSetting(system, f_number=system.widest_f_number, shift=shift,
                          stop_radius=float(system.aperture_radius[system.stop]), aperture=Aperture(),
                          film_mm=(1.0, 1.0), film_radius_mm=max(float(radii.max()), 1e-6))
    film = np.stack([np.zeros_like(radii), -radii, np.full(len(radii), setting.sensor_z)], axis=-1)
    origins, directions, passed = setting.chief_rays(film)
    return origins, directions, passed > 0.0


@lru_cache(maxsize=64)
def lens_view(system: LensSystem, shift: float, stop_radius: float, focus_mm: float,
              film_mm: tuple[float, float]) -> LensView:
    """The side view of ``system`` moved ``shift`` mm forward, its stop open to ``stop_radius`` mm, focused
    ``focus_mm`` from the sensor (inf: at infinity), imaging ``film_mm`` of sensor. Kept: the panel asks again at
    every refresh, and the aiming costs a few milliseconds."""
    z = system.vertex_z(shift)
    track = float(z[-1] - z[0])
    biggest = float(system.aperture_radius.max())
    front_z = float(z[0]) - max(0.35 * track, 0.8 * biggest)
    sensor_z = float(system.efl)
    half_diagonal = 0.5 * math.hypot(*film_mm)
    object_z = sensor_z - focus_mm if math.isfinite(focus_mm) else None

    # The frame's corner and, where no ray reaches it, the edge of the image circle: the chief rays from a row of
    # film points along the diagonal, the corner last.
    radii = np.linspace(0.0, half_diagonal, 49)[1:]
    fronts, outs, passed = _chief_angles(system, shift, radii)
    angles = np.degrees(np.arccos(np.clip(-outs[:, 2], -1.0, 1.0)))
    corner = float(angles[-1]) if passed[-1] else None
    reach = int(np.nonzero(passed)[0].max()) if passed.any() else 0
    covered_radius, covered_angle = (float(radii[reach]), float(angles[reach])) if passed.any() else (0.0, 0.0)

    axis = np.array([0.0, 0.0, 1.0])
    if object_z is not None:
        on_axis = _Family(np.array([0.0, 0.0, object_z]), axis)
    else:
        on_axis = _Family(None, axis, base=np.array([0.0, 0.0, front_z - 1.0]))
    rays = _fan(system, on_axis, shift, stop_radius, front_z, True)
    if passed.any():
        front, out = fronts[reach], outs[reach]
        incoming = -out
        if object_z is not None and out[2] < 0.0:
            point = front + (object_z - front[2]) / out[2] * out
            field = _Family(point, incoming)
        else:
            field = _Family(None, incoming,
                            base=front - incoming * (front[2] - front_z + 1.0) / max(incoming[2], 1e-3))
        rays += _fan(system, field, shift, stop_radius, front_z, False)
    return LensView(system=system, shift=float(shift), stop_radius=float(stop_radius), rays=tuple(rays),
                    front_z=front_z, sensor_z=sensor_z,
                    half_height=max(biggest, half_diagonal) * 1.12, sensor_half_diagonal=half_diagonal,
                    corner_half_angle_deg=corner, covered_radius_mm=covered_radius,
                    covered_half_angle_deg=covered_angle)


# -- the elements' outlines -----------------------------------------------------------------------------------------
def _sag(radius: float, y: np.ndarray) -> np.ndarray:
    """How far a sphere of ``radius`` departs from its vertex plane at heights ``y`` (towards +z for radius > 0)."""
    if radius == 0.0:
        return np.zeros_like(y)
    return radius - np.sign(radius) * np.sqrt(np.maximum(radius * radius - y * y, 0.0))


def _arc(radius: float, vertex_z: float, semi_aperture: float) -> np.ndarray:
    """A surface's profile, (ARC_POINTS, 2) as (z, y), from its clear aperture's top to its bottom."""
    y = np.linspace(semi_aperture, -semi_aperture, ARC_POINTS)
    return np.stack([vertex_z + _sag(radius, y), y], axis=-1)


@lru_cache(maxsize=16)
def _profile(system: LensSystem) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """Each spherical surface's arc and each element's outline (closed, (k, 2) as (z, y)) at infinity focus.

    An element is the glass between surface i and i + 1 (index behind i above 1). Where its two faces' clear
    apertures differ, the smaller face ends in a flat annulus out to the larger one, as lens drawings show an
    element's edge."""
    z = system.vertex_z(0.0)
    arcs = tuple(_arc(system.radius[i], z[i], system.aperture_radius[i])
                 for i in range(len(system.radius)) if system.radius[i] != 0.0)
    elements = []
    for i in range(len(system.radius) - 1):
        if system.ior_d[i] <= 1.0 or system.radius[i] == 0.0 or system.radius[i + 1] == 0.0:
            continue
        edge = max(system.aperture_radius[i], system.aperture_radius[i + 1])
        front = _arc(system.radius[i], z[i], system.aperture_radius[i])
        back = _arc(system.radius[i + 1], z[i + 1], system.aperture_radius[i + 1])[::-1]
        outline = [[front[0, 0], edge], *front, [front[-1, 0], -edge], [back[0, 0], -edge], *back,
                   [back[-1, 0], edge]]
        elements.append(np.array(outline))
    return arcs, tuple(elements)


# -- the widget -----------------------------------------------------------------------------------------------------
class LensDiagram(QWidget):
    """A real lens in profile with two fans of rays (see the module's docstring). ``show_view`` gives it a
    :class:`LensView`; it keeps its proportions (1 mm across is 1 mm up) and fits the lens, from a little in front
    of the front element to the sensor, into its width or its height, whichever is tighter."""

    MARGIN = 6.0

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setObjectName("lensDiagram")
        policy = QSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        policy.setHeightForWidth(True)
        self.setSizePolicy(policy)
        self.setMinimumSize(180, 100)
        self.view: LensView | None = None

    # -- what tests and the readout read --------------------------------------------------------------------------
    def stop_opening_mm(self) -> float:
        """The stop's opening as drawn: its diameter, mm (0 with no lens)."""
        return 2.0 * self.view.stop_radius if self.view is not None else 0.0

    def ray_paths(self) -> list[RayPath]:
        return list(self.view.rays) if self.view is not None else []

    # -- state ------------------------------------------------------------------------------------------------------
    def show_view(self, view: LensView | None) -> None:
        if view is not self.view:
            self.view = view
            self.update()

    def sizeHint(self) -> QSize:
        return QSize(260, 120)

    def hasHeightForWidth(self) -> bool:
        return True

    def heightForWidth(self, width: int) -> int:
        # Wide and low, as a lens lies: about half as tall as wide, within a panel's reason.
        return int(min(max(0.52 * width, 110), 190))

    # -- painting ---------------------------------------------------------------------------------------------------
    def _mapping(self, view: LensView):
        """Scale (px per mm) and offsets: mm (z, y) to widget pixels (x, y down)."""
        w, h = self.width() - 2 * self.MARGIN, self.height() - 2 * self.MARGIN
        span_z = view.sensor_z + 0.04 * (view.sensor_z - view.front_z) - view.front_z
        scale = min(w / span_z, h / (2.0 * view.half_height))
        left = self.MARGIN + 0.5 * (w - scale * span_z) - scale * view.front_z
        middle = self.height() / 2.0
        return scale, left, middle

    def paintEvent(self, event) -> None:
        view = self.view
        if view is None:
            return
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        scale, left, middle = self._mapping(view)

        def to_px(points: np.ndarray, dz: float = 0.0) -> QPolygonF:
            xs = left + scale * (points[:, 0] - dz)
            ys = middle - scale * points[:, 1]
            return QPolygonF([QPointF(x, y) for x, y in zip(xs, ys)])

        def point(z: float, y: float) -> QPointF:
            return QPointF(left + scale * z, middle - scale * y)

        p.setClipRect(self.rect())
        # The optical axis, dashed, from the drawing's left edge to the sensor.
        p.setPen(QPen(AXIS, 1, Qt.DashLine))
        p.drawLine(point(view.front_z, 0.0), point(view.sensor_z, 0.0))
        # The elements: glass filled, every surface outlined. The profile is kept at infinity focus; focusing
        # moves the whole lens forward by ``shift``.
        arcs, elements = _profile(view.system)
        p.setPen(Qt.NoPen)
        p.setBrush(GLASS_FILL)
        for outline in elements:
            p.drawPolygon(to_px(outline, view.shift))
        p.setBrush(Qt.NoBrush)
        p.setPen(QPen(GLASS_EDGE, 1.1))
        for outline in elements:
            p.drawPolygon(to_px(outline, view.shift))
        for arc in arcs:
            p.drawPolyline(to_px(arc, view.shift))
        # The rays, thin, under the stop and the sensor.
        for ray in view.rays:
            colour = QColor(ON_AXIS if ray.on_axis else OFF_AXIS)
            colour.setAlpha(220)
            p.setPen(QPen(colour, 1.0))
            p.drawPolyline(to_px(ray.points))
            if not ray.reached_sensor:  # where the glass stopped it: a dot at the ray's end
                end = ray.points[-1]
                p.drawEllipse(point(end[0], end[1]), 1.6, 1.6)
        # The stop: two bars from its opening out past its full size; they close in as the f-number grows.
        system = view.system
        stop_z = float(system.vertex_z(view.shift)[system.stop])
        full = float(system.aperture_radius[system.stop])
        outer = max(full * 1.18, view.stop_radius + 1.0)
        p.setPen(QPen(STOP, 2.2, Qt.SolidLine, Qt.FlatCap))
        for sign in (1.0, -1.0):
            p.drawLine(point(stop_z, sign * view.stop_radius), point(stop_z, sign * outer))
        # The sensor: its diagonal, seen edge on.
        p.setPen(QPen(SENSOR, 2.0, Qt.SolidLine, Qt.FlatCap))
        p.drawLine(point(view.sensor_z, view.sensor_half_diagonal), point(view.sensor_z, -view.sensor_half_diagonal))
        p.end()
