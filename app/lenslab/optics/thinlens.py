"""Thin-lens camera geometry: field of view, aperture and defocus blur.

This module is the numeric twin of the renderer's camera (docs/architecture.md, "The
camera"); if the shader and these formulas ever disagree, one of them is wrong.

The model, in the form used by pbrt-v4 (``PerspectiveCamera``) and Mitsuba 3
(``thinlens``):

* The image is formed as by a pinhole **focused at infinity**: the sensor sits
  one focal length ``f`` behind the lens, so ``fov_x = 2 atan(w / 2f)`` whatever
  the focus distance (real lenses "breathe"; we deliberately do not).
* The entrance pupil is a disk of diameter ``A = f / N`` (``N`` = f-number).
* The plane of focus is a **plane** at distance ``s`` along the view axis.  A
  primary ray leaves a point on the pupil and passes through the point where
  the pinhole ray meets that plane.

Units: focal lengths and sensor sizes in millimetres, distances in the scene in
metres.  Every function says which it takes; conversions happen here, once.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "MM_PER_M",
    "FOCAL_LENGTH_RANGE_MM",
    "FOCAL_LENGTH_CONTROL_RANGE_MM",
    "FOCUS_DISTANCE_RANGE_M",
    "f_number_for_lens_radius",
    "format_camera_settings",
    "format_distance",
    "format_focal_length",
    "field_of_view_x",
    "focal_length_for_fov",
    "lens_radius_m",
    "blur_diameter_mm",
    "textbook_blur_diameter_mm",
]

#: Millimetres in a metre; named so that every unit conversion is greppable.
MM_PER_M = 1000.0

#: The focal lengths the studio's controls offer and a lens preset may have, mm: a 1 mm fisheye-free wide angle
#: to a 2000 mm mirror lens. It limits what the controls offer, never what a scene holds.
FOCAL_LENGTH_CONTROL_RANGE_MM = (1.0, 2000.0)
#: The focal lengths a scene may hold, mm: what scene files, importers, the command line and batch files accept
#: (a Mitsuba sensor's fov becomes a focal length on a 36 mm sensor). Any f > 0 gives a field of view strictly
#: between 0 and 180 degrees; what bounds it is float32 on the GPU, which takes tan(fov / 2) = w / 2v (w the
#: sensor's side, v >= f) and builds each ray's direction as (x tan, y tan, -1): past 2^24 (float32's significand)
#: the -1 is lost beside the image edge's x tan and those rays lie in the sensor's plane (180 degrees). 1e-4 mm
#: keeps tan(fov / 2) under 2.5e6 on the widest sensor (500 mm; fov 179.99998 degrees on it, 179.9997 on 36 mm).
#: The long end is where a lens can no longer focus on anything: its closest focus, four focal lengths, lies
#: beyond the farthest focus distance (FOCUS_DISTANCE_RANGE_M's 1e6 m): 2.5e8 mm (fov 8e-6 degrees on 36 mm).
FOCAL_LENGTH_RANGE_MM = (1e-4, 2.5e8)
#: The focus distances LensLab accepts, metres: 1 cm (macro) to 1000 km (infinity for any lens).
FOCUS_DISTANCE_RANGE_M = (0.01, 1e6)


def require_positive(name: str, value: float) -> float:
    value = float(value)
    if not (value > 0.0 and math.isfinite(value)):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return value


def field_of_view_x(focal_length_mm: float, sensor_width_mm: float) -> float:
    """Horizontal field of view in radians: ``2 atan(w / (2 f))``.

    Pinhole focused at infinity (docs/architecture.md); the same angle pbrt and Mitsuba
    derive from a 35 mm-equivalent focal length.  Example: 50 mm on a 36 mm
    wide sensor gives 39.6 degrees.
    """
    f = require_positive("focal_length_mm", focal_length_mm)
    w = require_positive("sensor_width_mm", sensor_width_mm)
    return 2.0 * math.atan(w / (2.0 * f))


def focal_length_for_fov(fov_x_rad: float, sensor_width_mm: float) -> float:
    """Focal length in mm that gives horizontal field of view ``fov_x_rad``.

    Inverse of :func:`field_of_view_x`: ``f = w / (2 tan(fov_x / 2))``.  Used by
    scene importers whose cameras are specified by angle (Mitsuba ``fov``,
    glTF ``yfov`` after converting to the horizontal axis).
    """
    fov = float(fov_x_rad)
    if not (0.0 < fov < math.pi):
        raise ValueError(f"fov_x_rad must lie in (0, pi), got {fov!r}")
    w = require_positive("sensor_width_mm", sensor_width_mm)
    return w / (2.0 * math.tan(fov / 2.0))


def lens_radius_m(focal_length_mm: float, f_number: float) -> float:
    """Radius of the lens disk the renderer samples, in metres: ``f / (2 N)``.

    The aperture *diameter* is ``f / N`` (definition of the f-number); half of
    it, converted from mm to m because the lens disk lives in scene space.
    Example: 50 mm at f/2 -> 0.0125 m.
    """
    f = require_positive("focal_length_mm", focal_length_mm)
    n = require_positive("f_number", f_number)
    return f / (2.0 * n) / MM_PER_M


def f_number_for_lens_radius(focal_length_mm: float, lens_radius: float) -> float:
    """The f-number whose lens disk has radius ``lens_radius`` metres: ``N = f / (2 r)``.

    Inverse of :func:`lens_radius_m`, for importers whose cameras give an aperture radius (Mitsuba's
    ``aperture_radius``). A zero radius is a pinhole: infinity.
    """
    f = require_positive("focal_length_mm", focal_length_mm)
    r = float(lens_radius)
    if not (r >= 0.0 and math.isfinite(r)):
        raise ValueError(f"lens_radius must be a non-negative finite number, got {lens_radius!r}")
    return math.inf if r == 0.0 else f / MM_PER_M / (2.0 * r)


def blur_diameter_mm(focal_length_mm, f_number, focus_distance_m, depth_m):
    """Diameter on the sensor (mm) of the blur disk of a point at ``depth_m``.

    ``c = (f / N) * |d - s| / d * f / s``   (docs/architecture.md: planar focus, sensor at f)

    Derivation, by similar triangles: the rays from a pupil of diameter
    ``A = f/N`` that converge on a point at depth ``d`` cut the plane of focus
    (depth ``s``) in a disk of diameter ``A |d - s| / d``; the pinhole camera
    images that plane onto the sensor with magnification ``f / s``.

    This is exactly what the renderer draws.  It differs from the textbook
    thin lens (:func:`textbook_blur_diameter_mm`), whose sensor sits at the
    image distance ``f s / (s - f)``, by the factor ``(s - f) / s``: under 1 %
    beyond 100 focal lengths, 50 % at 1:1 macro.

    Vectorised: any argument may be a numpy array (broadcast together); a
    scalar result comes back as a Python float.  ``depth_m`` must be > 0 (in
    front of the lens); a point at infinite depth gives the limit ``A f / s``.
    """
    f = np.asarray(focal_length_mm, dtype=float)
    n = np.asarray(f_number, dtype=float)
    s = np.asarray(focus_distance_m, dtype=float)
    d = np.asarray(depth_m, dtype=float)
    for name, arr in (("focal_length_mm", f), ("f_number", n), ("focus_distance_m", s)):
        if not np.all((arr > 0) & np.isfinite(arr)):
            raise ValueError(f"{name} must be positive and finite")
    if not np.all(d > 0):
        raise ValueError("depth_m must be positive (points in front of the lens)")
    aperture_mm = f / n
    # |d - s| / d written as |1 - s/d| so that d = inf gives 1, not inf/inf.
    defocus = np.abs(1.0 - s / d)
    magnification = f / (s * MM_PER_M)  # mm on sensor per mm on the focus plane
    c = aperture_mm * defocus * magnification
    return float(c) if c.ndim == 0 else c


def textbook_blur_diameter_mm(focal_length_mm, f_number, focus_distance_m, depth_m):
    """Blur diameter (mm) for a real thin lens focused by moving the sensor.

    ``c = (f / N) * |d - s| / d * f / (s - f)``

    The sensor sits at the image distance ``v = f s / (s - f)`` (Gaussian lens
    equation), so the plane of focus is magnified by ``v / s = f / (s - f)``
    instead of ``f / s``.  This is the model behind the usual depth-of-field
    tables (and :func:`lenslab.optics.dof.depth_of_field` with
    ``model="thin_lens"``); the renderer uses :func:`blur_diameter_mm`.
    Requires ``s > f``; vectorised like :func:`blur_diameter_mm`.
    """
    f = np.asarray(focal_length_mm, dtype=float)
    s = np.asarray(focus_distance_m, dtype=float)
    if not np.all(s * MM_PER_M > f):
        raise ValueError("focus_distance_m must exceed the focal length for a real image")
    planar = np.asarray(blur_diameter_mm(focal_length_mm, f_number, focus_distance_m, depth_m))
    s_mm = s * MM_PER_M
    c = planar * s_mm / (s_mm - f)  # swap magnification f/s for f/(s-f)
    return float(c) if c.ndim == 0 else c


def format_focal_length(mm: float) -> str:
    """Text as a lens barrel reads: ``"50 mm"``, ``"31.2 mm"`` (one decimal at most, trailing zeros dropped;
    two significant digits below 1 mm, as a scene may hold: ``"0.16 mm"``)."""
    if float(mm) < 1.0:
        return f"{float(mm):.2g} mm"
    return f"{float(mm):.1f}".rstrip("0").rstrip(".") + " mm"


def format_distance(metres: float) -> str:
    """A distance as a focus scale reads: ``"1.50 m"``, ``"12.5 m"``, ``"120 m"``, ``"45.0 cm"``, ``"∞"``."""
    if math.isinf(metres):
        return "∞"
    if metres >= 100:
        return f"{metres:.0f} m"
    if metres >= 10:
        return f"{metres:.1f} m"
    if metres >= 1:
        return f"{metres:.2f} m"
    return f"{metres * 100:.1f} cm"


def format_camera_settings(focal_length_mm: float, f_number: float, focus_distance_m: float) -> str:
    """The settings a photographer reads off a camera, as the studio's viewport shows them and a contact sheet
    prints them: ``"50 mm · f/2.8 · focus 1.50 m"``."""
    from .stops import format_f_number

    return (f"{format_focal_length(focal_length_mm)} \u00b7 {format_f_number(f_number)} \u00b7 "
            f"focus {format_distance(focus_distance_m)}")


# -- focusing ----------------------------------------------------------------------------------------------
# A thin lens of focal length f images a plane at distance s in front of it sharply on a sensor at the image
# distance v = f s / (s - f) behind it (the Gaussian lens equation 1/s + 1/v = 1/f). A lens's focus scale is
# marked from the sensor plane, so the distance a photographer sets is D = s + v; solving for s gives
# s = D/2 (1 + sqrt(1 - 4 f / D)), real only for D >= 4 f: nearer than four focal lengths from the sensor no
# thin lens can focus (at D = 4 f it images 1:1, s = v = 2 f).

#: What a focus distance may be measured from: the sensor plane (as lens scales are marked) or the lens.
FOCUS_REFERENCES = ("sensor", "lens")


def image_distance_mm(focal_length_mm: float, object_distance_m: float) -> float:
    """Lens-to-sensor distance (mm) that focuses a plane ``object_distance_m`` in front of the lens:
    ``v = f s / (s - f)``. 50 mm focused at 1 m: 52.6 mm. Needs ``s > f``."""
    f = require_positive("focal_length_mm", focal_length_mm)
    s = require_positive("object_distance_m", object_distance_m) * MM_PER_M
    if s <= f:
        raise ValueError(f"a plane {format_distance(s / MM_PER_M)} from the lens is not beyond the focal length "
                         f"{format_focal_length(f)}: no lens can focus on it")
    return f * s / (s - f)


def object_distance_m(focal_length_mm: float, sensor_distance_m: float) -> float:
    """Distance (m) from the lens to the plane in focus when the focus scale, measured from the sensor plane,
    reads ``sensor_distance_m``: ``s = D/2 (1 + sqrt(1 - 4 f / D))``. Needs ``D >= 4 f``."""
    f = require_positive("focal_length_mm", focal_length_mm) / MM_PER_M
    d = require_positive("sensor_distance_m", sensor_distance_m)
    if d < 4.0 * f * (1.0 - 1e-12):
        raise ValueError(f"focus {format_distance(d)} from the sensor is nearer than a "
                         f"{format_focal_length(f * MM_PER_M)} lens can focus (four focal lengths, "
                         f"{format_distance(4.0 * f)})")
    return 0.5 * d * (1.0 + math.sqrt(max(0.0, 1.0 - 4.0 * f / d)))


def sensor_distance_m(focal_length_mm: float, object_distance: float) -> float:
    """The focus scale's reading (from the sensor plane, m) that puts the plane of focus ``object_distance`` m in
    front of the lens: ``s + v``. The inverse of :func:`object_distance_m`."""
    return object_distance + image_distance_mm(focal_length_mm, object_distance) / MM_PER_M


def closest_focus_m(focal_length_mm: float, focus_from: str = "sensor") -> float:
    """The nearest focus distance a thin lens of this focal length can set: life size (1:1), the plane of focus two
    focal lengths ahead of the lens and the sensor two behind it, so four focal lengths from the sensor. Both
    references meet the same limit: nearer than 2f from the lens the sensor would have to go further back than 2f
    (ten metres behind a 100 mm lens focused at 101 mm), a bellows no lens has."""
    f = require_positive("focal_length_mm", focal_length_mm) / MM_PER_M
    return 4.0 * f if focus_from == "sensor" else 2.0 * f
