"""An independent reference tracer for real (thick, multi-element) camera lenses.

This module is written from the physics alone, as a yardstick that the product's own lens code is tested against.
It deliberately does everything the slow, obvious way: explicit ray-sphere intersection, the vector form of Snell's
law, and brute-force integration over many rays. Nothing in it uses ray-transfer (ABCD) matrices, so that a
mistake in a matrix implementation cannot hide in here as well.

Conventions
-----------
A lens is a list of surfaces from the FRONT element (scene side) to the REAR (sensor side), each a tuple
``(radius_mm, thickness_mm, ior, aperture_diameter_mm)``:

* ``radius_mm``: the signed radius of curvature. It is positive when the sphere's centre lies behind the vertex
  (toward the sensor), so a surface that bulges toward the scene has R > 0. ``0`` marks the aperture stop: a flat
  opening of diameter ``aperture_diameter_mm``. (``math.inf`` is accepted too, as a flat *refracting* surface, for
  plano-convex lenses and plates; a flat surface refracts by Snell's law whenever the index changes across it, and a
  stop in air, with air on both sides, leaves rays alone.)
* ``thickness_mm``: the axial distance from this vertex to the next one; for the last surface, the distance to the
  sensor (:func:`default_sensor_z`). Most functions here take the sensor position separately.
* ``ior``: the refractive index of the medium BEHIND this surface (between it and the next); 1 for air. The medium
  in front of the first surface is air.
* A ray is lost when it misses a sphere, meets a surface outside its clear aperture (the distance from the axis at
  the intersection point exceeds diameter / 2), or is totally internally reflected.

Coordinates: ``z`` runs along the optical axis and increases toward the sensor; the front vertex is at ``z = 0``, the
vertex of surface ``i`` at ``z_i = thickness_0 + ... + thickness_{i-1}`` (:func:`vertex_z`), and the sensor plane at
``z = z_sensor``. All lengths are in millimetres; angles in radians.
"""

from __future__ import annotations

import math
from typing import NamedTuple, Optional

import numpy as np

# The Fraunhofer lines at which glass catalogues quote the refractive index n_d and the Abbe number
# V_d = (n_d - 1) / (n_F - n_C).
LAMBDA_D_NM = 587.56  # helium d line (yellow): where n_d is measured
LAMBDA_F_NM = 486.13  # hydrogen F line (blue)
LAMBDA_C_NM = 656.27  # hydrogen C line (red)

# A ray may meet a surface this far (mm) *behind* its origin and still count: only rounding can put it there.
_T_EPS = 1e-9


# --------------------------------------------------------------------------------------------------------------------
# The lens as arrays
# --------------------------------------------------------------------------------------------------------------------


class _Lens(NamedTuple):
    radius: np.ndarray  # signed radius of curvature; 0 (stop) or inf means a plane
    z: np.ndarray  # axial position of each vertex
    ior: np.ndarray  # index of the medium behind each surface
    semi: np.ndarray  # clear semi-aperture (radius of the clear opening)

    def __len__(self) -> int:
        return len(self.radius)


def _lens(surfaces, wavelength_ior=None) -> _Lens:
    """The surfaces as arrays, with the optional per-surface index override applied."""
    table = [tuple(float(v) for v in s) for s in surfaces]
    if not table:
        raise ValueError("a lens needs at least one surface")
    if any(len(s) != 4 for s in table):
        raise ValueError("each surface is (radius_mm, thickness_mm, ior, aperture_diameter_mm)")
    radius, thickness, ior, diameter = (np.array(col, dtype=float) for col in zip(*table))
    if wavelength_ior is not None:
        if len(wavelength_ior) != len(table):
            raise ValueError("wavelength_ior needs one entry (or None) per surface")
        for i, n in enumerate(wavelength_ior):
            if n is not None:
                ior[i] = float(n)
    z = np.concatenate([[0.0], np.cumsum(thickness[:-1])])
    return _Lens(radius, z, ior, diameter / 2.0)


def _is_flat(radius: float) -> bool:
    return radius == 0.0 or not math.isfinite(radius)


def vertex_z(surfaces) -> np.ndarray:
    """The axial position of each surface's vertex (the front vertex at z = 0)."""
    return _lens(surfaces).z


def default_sensor_z(surfaces) -> float:
    """The sensor position the prescription itself gives: the sum of all thicknesses (the last one included)."""
    return float(sum(float(s[1]) for s in surfaces))


def stop_index(surfaces) -> int:
    """The index of the aperture stop: the first surface with radius 0."""
    for i, s in enumerate(surfaces):
        if float(s[0]) == 0.0:
            return i
    raise ValueError("the lens has no aperture stop (a surface with radius 0)")


# --------------------------------------------------------------------------------------------------------------------
# Intersection and refraction
# --------------------------------------------------------------------------------------------------------------------


def refract(d, normal, eta):
    """Snell's law in vector form.

    ``d``: unit incident directions (N, 3); ``normal``: unit surface normals (N, 3), either orientation;
    ``eta = n1 / n2``, the index on the incident side over the index on the far side.

    With the normal turned to face the incoming ray, cos i = -n.d, and Snell's law n1 sin i = n2 sin t gives
    sin^2 t = eta^2 (1 - cos^2 i). The refracted direction is t = eta d + (eta cos i - cos t) n. When
    sin^2 t > 1 there is no refracted ray: total internal reflection. Returns (t, ok).
    """
    d = np.atleast_2d(np.asarray(d, dtype=float))
    n = np.atleast_2d(np.asarray(normal, dtype=float))
    eta = np.asarray(eta, dtype=float)
    cos_i = -np.sum(n * d, axis=-1)
    # Turn the normal against the incident ray, so that cos i >= 0.
    n = np.where((cos_i < 0.0)[..., None], -n, n)
    cos_i = np.abs(cos_i)
    sin2_t = eta**2 * (1.0 - cos_i**2)
    ok = sin2_t <= 1.0
    cos_t = np.sqrt(np.clip(1.0 - sin2_t, 0.0, None))
    t = eta[..., None] * d + (eta * cos_i - cos_t)[..., None] * n
    t /= np.linalg.norm(t, axis=-1, keepdims=True)  # unit already, up to rounding
    return t, ok


def _intersect(o, d, z_vertex: float, radius: float):
    """Where rays o + t d (t >= 0) first meet one surface.

    A flat surface is the plane z = z_vertex. A curved surface is the part of the sphere of radius |R| centred at
    (0, 0, z_vertex + R) on the vertex's side of the plane through the centre (the lens's cap; a clear aperture is
    always smaller than |R|). Returns the points, the unit normals there (either orientation) and a mask of rays
    that meet the surface at all (the clear aperture is checked by the caller).
    """
    ox, oy, oz = o[:, 0], o[:, 1], o[:, 2]
    dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
    if _is_flat(radius):
        t = (z_vertex - oz) / dz
        hit = np.isfinite(t) & (t >= -_T_EPS)
        p = o + t[:, None] * d
        normal = np.broadcast_to(np.array([0.0, 0.0, 1.0]), p.shape)
        return p, normal, hit

    # |o + t d - c|^2 = R^2 with c = (0, 0, z_vertex + R) and |d| = 1 gives t^2 + 2 b t + cc = 0, where
    # b = (o - c).d and cc = |o - c|^2 - R^2. With w = oz - z_vertex (the origin's axial offset from the vertex),
    # o - c = (ox, oy, w - R), so cc = ox^2 + oy^2 + w^2 - 2 w R: written this way it does not lose digits to the
    # difference of two large numbers when R is large.
    R = radius
    w = oz - z_vertex
    b = ox * dx + oy * dy + (w - R) * dz
    cc = ox * ox + oy * oy + w * w - 2.0 * w * R
    disc = b * b - cc
    meets_sphere = disc >= 0.0
    sq = np.sqrt(np.where(meets_sphere, disc, 0.0))
    # The roots are -b +- sqrt(disc); the stable pair is q = -(b + sign(b) sqrt(disc)) and cc / q (their product
    # is cc).
    q = -(b + np.copysign(sq, b))
    t1 = q
    t2 = np.where(q != 0.0, cc / np.where(q != 0.0, q, 1.0), 0.0)
    t_lo, t_hi = np.minimum(t1, t2), np.maximum(t1, t2)

    def on_cap(t):
        pz = oz + t * dz
        # The vertex side of the centre: (pz - z_vertex) / R < 1, i.e. (pz - z_vertex - R) R < 0.
        return (t >= -_T_EPS) & ((pz - z_vertex - R) * R < 0.0)

    lo_ok, hi_ok = on_cap(t_lo), on_cap(t_hi)
    t = np.where(lo_ok, t_lo, t_hi)  # the first meeting with the cap along the ray
    hit = meets_sphere & (lo_ok | hi_ok)
    p = o + t[:, None] * d
    normal = (p - np.array([0.0, 0.0, z_vertex + R])) / abs(R)
    return p, normal, hit


def _trace(lens: _Lens, o, d, *, from_sensor: bool, clip: bool = True, last: Optional[int] = None):
    """Sequential trace through the surfaces in the order light meets them; ``last`` stops after that surface
    (it is still intersected, clipped and refracted). Returns (points, directions, ok)."""
    o = np.array(o, dtype=float)
    d = np.array(d, dtype=float)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    ok = np.ones(len(o), dtype=bool)
    n_behind = lens.ior
    n_front = np.concatenate([[1.0], lens.ior[:-1]])  # air in front of the first surface
    order = range(len(lens) - 1, -1, -1) if from_sensor else range(len(lens))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for i in order:
            p, normal, hit = _intersect(o, d, lens.z[i], lens.radius[i])
            ok &= hit
            if clip:
                ok &= p[:, 0] ** 2 + p[:, 1] ** 2 <= lens.semi[i] ** 2
            n1, n2 = (n_behind[i], n_front[i]) if from_sensor else (n_front[i], n_behind[i])
            d, refracted = refract(d, normal, np.full(len(o), n1 / n2))
            ok &= refracted
            o = p
            if last is not None and i == last:
                break
    return o, d, ok


def trace(surfaces, origins, directions, wavelength_ior=None, *, from_sensor: bool = True, apertures: bool = True):
    """Trace rays through the lens.

    ``from_sensor=True``: the rays start behind the lens (typically on the sensor, heading toward -z) and meet the
    surfaces from the rear one to the front one. ``from_sensor=False``: they start in the scene, heading toward +z,
    and meet them front to rear. ``origins`` and ``directions`` are (N, 3) arrays (or one ray of shape (3,));
    directions need not be normalised. ``wavelength_ior``: an optional sequence, one entry per surface, that
    replaces each surface's ``ior`` (None keeps it) -- the indices at some wavelength. ``apertures=False`` ignores
    the clear apertures (misses and total internal reflection still lose rays).

    Returns ``(exit_origins, exit_directions, ok)``: the points where the rays leave the last surface they meet,
    their unit directions there, and a mask of the rays that got through. Lost rays' entries are NaN.
    """
    lens = _lens(surfaces, wavelength_ior)
    o = np.asarray(origins, dtype=float)
    single = o.ndim == 1
    o = np.atleast_2d(o)
    d = np.atleast_2d(np.asarray(directions, dtype=float))
    o, d = np.broadcast_arrays(o, d)
    p, t, ok = _trace(lens, o, d, from_sensor=from_sensor, clip=apertures)
    p = np.where(ok[:, None], p, np.nan)
    t = np.where(ok[:, None], t, np.nan)
    if single:
        return p[0], t[0], bool(ok[0])
    return p, t, ok


# --------------------------------------------------------------------------------------------------------------------
# Focal lengths and cardinal points, from real rays at a tiny height
# --------------------------------------------------------------------------------------------------------------------


def _parallel_ray(lens: _Lens, from_sensor: bool):
    """A real ray parallel to the axis, at a height of 1e-4 of the smallest clear semi-aperture, traced through the
    whole lens. At such a height the ray is paraxial to about (1e-4)^2: aberrations do not show. Returns
    (h, point, direction) of the emerging ray."""
    h = 1e-4 * float(np.min(lens.semi))
    if from_sensor:
        o = np.array([[0.0, h, lens.z[-1] + 1.0]])
        d = np.array([[0.0, 0.0, -1.0]])
    else:
        o = np.array([[0.0, h, lens.z[0] - 1.0]])
        d = np.array([[0.0, 0.0, 1.0]])
    p, t, ok = _trace(lens, o, d, from_sensor=from_sensor)
    if not ok[0]:
        raise ValueError("a paraxial ray does not get through the lens")
    return h, p[0], t[0]


def _axis_crossing_z(p, t) -> float:
    """Where the line through p along t (in the y-z plane) crosses the axis (y = 0); inf when it is parallel."""
    slope = t[1] / t[2]  # dy/dz along the ray
    return float(p[2] - p[1] / slope) if slope != 0.0 else math.inf


def paraxial_focal_length(surfaces, wavelength_ior=None) -> float:
    """The effective focal length, from a real ray parallel to the axis at a tiny height h, traced from the scene:
    EFL = h / tan(u'), with u' the angle of the emerging ray toward the axis; positive for a converging lens."""
    lens = _lens(surfaces, wavelength_ior)
    h, _, t = _parallel_ray(lens, from_sensor=False)
    slope = t[1] / t[2]  # a converging lens bends the ray down toward the axis: slope < 0
    return float(-h / slope) if slope != 0.0 else math.inf


def back_focal_distance(surfaces, wavelength_ior=None) -> float:
    """The distance from the rear vertex to the rear focal point (where the parallel ray of
    :func:`paraxial_focal_length` crosses the axis); positive when the focus lies behind the rear vertex."""
    lens = _lens(surfaces, wavelength_ior)
    _, p, t = _parallel_ray(lens, from_sensor=False)
    return float(_axis_crossing_z(p, t) - lens.z[-1])


def front_focal_distance(surfaces, wavelength_ior=None) -> float:
    """The same from the sensor side: a ray parallel to the axis coming from behind the lens crosses the axis at
    the front focal point; the distance from that point to the front vertex, positive when it lies in front of
    the vertex (on the scene side)."""
    lens = _lens(surfaces, wavelength_ior)
    _, p, t = _parallel_ray(lens, from_sensor=True)
    return float(lens.z[0] - _axis_crossing_z(p, t))


def front_focal_length(surfaces, wavelength_ior=None) -> float:
    """The focal length measured from the sensor side (h / tan u of the ray of :func:`front_focal_distance`). With
    air on both sides it equals :func:`paraxial_focal_length`."""
    lens = _lens(surfaces, wavelength_ior)
    h, _, t = _parallel_ray(lens, from_sensor=True)
    slope = t[1] / t[2]  # heading toward -z and toward the axis: dy/dz > 0
    return float(h / slope) if slope != 0.0 else math.inf


class CardinalPoints(NamedTuple):
    efl: float  # effective focal length (rear side)
    efl_front: float  # focal length measured from the front side (equal to efl with air on both sides)
    bfd: float  # rear vertex -> rear focal point
    ffd: float  # front focal point -> front vertex
    z_rear_focal: float  # F'
    z_front_focal: float  # F
    z_rear_principal: float  # H' = F' - f
    z_front_principal: float  # H = F + f


def cardinal_points(surfaces, wavelength_ior=None) -> CardinalPoints:
    """The focal points and principal planes (z coordinates), all from the real-ray traces above."""
    lens = _lens(surfaces, wavelength_ior)
    f = paraxial_focal_length(surfaces, wavelength_ior)
    f_front = front_focal_length(surfaces, wavelength_ior)
    bfd = back_focal_distance(surfaces, wavelength_ior)
    ffd = front_focal_distance(surfaces, wavelength_ior)
    z_rf = lens.z[-1] + bfd
    z_ff = lens.z[0] - ffd
    return CardinalPoints(f, f_front, bfd, ffd, z_rf, z_ff, z_rf - f, z_ff + f_front)


# --------------------------------------------------------------------------------------------------------------------
# Best focus of an on-axis point
# --------------------------------------------------------------------------------------------------------------------


def _disk_grid(radius: float, n_points: int):
    """A square grid of cell centres inside a disk of the given radius, about n_points of them; returns (x, y, cell
    area). A regular grid gives deterministic, low-noise integrals (a midpoint rule)."""
    n_side = max(3, int(math.ceil(math.sqrt(n_points * 4.0 / math.pi))))
    step = 2.0 * radius / n_side
    c = -radius + step * (np.arange(n_side) + 0.5)
    x, y = np.meshgrid(c, c, indexing="ij")
    inside = x**2 + y**2 <= radius**2
    return x[inside], y[inside], step * step


def _sag(radius: float, semi: float) -> float:
    """How far the edge of a surface's clear aperture lies from its vertex plane (axially)."""
    if _is_flat(radius):
        return 0.0
    return abs(radius) - math.sqrt(max(radius * radius - semi * semi, 0.0))


def _stopped_down(surfaces, fraction: float):
    if fraction == 1.0:
        return list(surfaces)
    if not 0.0 < fraction <= 1.0:
        raise ValueError("f_number_aperture_fraction must be in (0, 1]")
    i = stop_index(surfaces)
    out = [tuple(float(v) for v in s) for s in surfaces]
    r, t, n, dia = out[i]
    out[i] = (r, t, n, dia * fraction)
    return out


def _focus_rays(surfaces, object_distance_mm: float, fraction: float, n_rays: int, wavelength_ior):
    """The rays from an on-axis object point through the lens, as lines x = A + B z in the image space (A, B: (M, 2)
    arrays, one row per ray that gets through). The rays fill the front element: they are aimed at a square grid
    over a disk on the front vertex plane large enough to cover its clear aperture (the lens clips them)."""
    lens = _lens(_stopped_down(surfaces, fraction), wavelength_ior)
    a0, sag0 = lens.semi[0], _sag(lens.radius[0], lens.semi[0])
    if math.isinf(object_distance_mm):
        # An object at infinity: parallel rays over the disk.
        x, y, _ = _disk_grid(a0 * 1.01, n_rays)
        o = np.stack([x, y, np.full_like(x, lens.z[0] - sag0 - 1.0)], axis=1)
        d = np.broadcast_to(np.array([0.0, 0.0, 1.0]), o.shape)
    else:
        z_obj = lens.z[0] - float(object_distance_mm)
        if object_distance_mm <= sag0:
            raise ValueError("the object point must lie in front of the front element")
        # A ray that meets the cap at radius <= a0 (at most sag0 from the vertex plane) crosses the vertex plane
        # within a0 + sag0 * tan(angle) of the axis.
        cover = (a0 + sag0 * a0 / (object_distance_mm - sag0)) * 1.01
        x, y, _ = _disk_grid(cover, n_rays)
        o = np.broadcast_to(np.array([0.0, 0.0, z_obj]), (len(x), 3))
        d = np.stack([x, y, np.full_like(x, lens.z[0] - z_obj)], axis=1)
    p, t, ok = _trace(lens, o, d, from_sensor=False)
    ok &= t[:, 2] > 0.0
    p, t = p[ok], t[ok]
    if len(p) < 3:
        raise ValueError("too few rays get through the lens")
    B = t[:, :2] / t[:, 2:3]  # lateral displacement per unit z
    A = p[:, :2] - p[:, 2:3] * B  # position at z = 0
    return A, B


class BestFocus(NamedTuple):
    z_sensor: float  # sensor z of the smallest RMS spot
    rms_radius_mm: float  # RMS distance of the ray hits from their centroid there
    max_radius_mm: float  # largest distance of a hit from the centroid there (the geometric spot radius)


def spot_size(surfaces, object_distance_mm, z_sensor, f_number_aperture_fraction=1.0, *, n_rays=40_000,
              wavelength_ior=None):
    """The (RMS, max) spot radius, about the centroid, of an on-axis point's image on the plane z = z_sensor."""
    A, B = _focus_rays(surfaces, object_distance_mm, f_number_aperture_fraction, n_rays, wavelength_ior)
    hits = A + B * float(z_sensor)
    r = np.linalg.norm(hits - hits.mean(axis=0), axis=1)
    return float(np.sqrt(np.mean(r**2))), float(r.max())


def best_focus_sensor_z(surfaces, object_distance_mm, f_number_aperture_fraction=1.0, *, n_rays=40_000,
                        wavelength_ior=None) -> BestFocus:
    """The sensor position at which an on-axis point at ``object_distance_mm`` in front of the front vertex
    (z = -object_distance_mm; ``math.inf`` for a point at infinity) has the smallest RMS spot radius.

    ``f_number_aperture_fraction`` stops the lens down: it scales the aperture stop's diameter (1 = wide open).
    The rays come from the point through a dense square grid that fills the front element.

    The minimisation over z is exact rather than a search: every ray in image space is a straight line, so its hit
    on the plane z is x_i(z) = A_i + B_i z, linear in z, and the spot's variance about its centroid,
    V(z) = mean |dA_i + dB_i z|^2 (dA_i = A_i - mean A, dB_i = B_i - mean B), is a quadratic in z with its minimum
    at z* = -mean(dA_i . dB_i) / mean |dB_i|^2. (:func:`spot_size` at nearby z shows that it is the minimum.)
    """
    A, B = _focus_rays(surfaces, object_distance_mm, f_number_aperture_fraction, n_rays, wavelength_ior)
    dA = A - A.mean(axis=0)
    dB = B - B.mean(axis=0)
    curvature = np.mean(np.sum(dB * dB, axis=1))
    if curvature == 0.0:
        raise ValueError("the rays leave the lens parallel: no focus")
    z = -np.mean(np.sum(dA * dB, axis=1)) / curvature
    hits = A + B * z
    r = np.linalg.norm(hits - hits.mean(axis=0), axis=1)
    return BestFocus(float(z), float(np.sqrt(np.mean(r**2))), float(r.max()))


# --------------------------------------------------------------------------------------------------------------------
# Relative illumination, by brute force
# --------------------------------------------------------------------------------------------------------------------


class Illumination(NamedTuple):
    relative: np.ndarray  # E(r) / E(0), one per film radius asked for
    irradiance: np.ndarray  # E(r) for unit scene radiance
    irradiance_on_axis: float  # E(0)


def _rear_cover_radius(lens: _Lens, z_sensor: float, film_radius: float) -> float:
    """The radius of a disk, centred on the axis in the plane of the rear vertex, that every ray from the film
    (within film_radius of the axis) that gets through the rear element crosses. Such a ray meets the rear surface
    within its clear semi-aperture a, at most `sag` from the vertex plane, at a slope of at most
    (film_radius + a) / (d - sag); so it crosses the vertex plane within a + sag * slope of the axis."""
    a = lens.semi[-1]
    sag = _sag(lens.radius[-1], a)
    d = z_sensor - lens.z[-1]
    if d - sag <= 0.0:
        raise ValueError("the sensor must lie behind the rear element")
    return (a + sag * (film_radius + a) / (d - sag)) * 1.01


def relative_illumination(surfaces, z_sensor, film_radius_mm, n_rays=250_000, *, disk_radius_mm=None,
                          wavelength_ior=None) -> Illumination:
    """Irradiance on the film at distance ``film_radius_mm`` (a number or an array) from the axis, relative to the
    centre, for a uniform Lambertian scene of unit radiance, by brute force.

    The camera measurement equation gives the irradiance at a film point as E = L * integral of cos^4(theta) / d^2
    dA over any plane between the film and the lens, counting only the points whose ray from the film point gets
    through the lens (theta: that ray's angle with the axis; d: the axial distance from the film to the plane;
    dA cos(theta) / (d / cos(theta))^2 is the solid angle of dA and another cos(theta) is the film's foreshortening).
    Here the plane is that of the rear vertex, covered by a square grid of N points over a disk of area A_disk that
    surely covers the rear element's aperture, and E = (1 / N) * sum over the rays that get through of
    cos^4(theta) * A_disk / d^2. The grid makes the result deterministic.
    """
    lens = _lens(surfaces, wavelength_ior)
    radii = np.atleast_1d(np.asarray(film_radius_mm, dtype=float))
    z_sensor = float(z_sensor)
    d_axial = z_sensor - lens.z[-1]
    cover = disk_radius_mm
    if cover is None:
        cover = _rear_cover_radius(lens, z_sensor, float(np.max(np.abs(radii))))
    x, y, cell = _disk_grid(float(cover), n_rays)  # A_disk / N == cell
    aim = np.stack([x, y, np.full_like(x, lens.z[-1])], axis=1)

    def irradiance(r: float) -> float:
        film = np.array([r, 0.0, z_sensor])
        d = aim - film
        _, _, ok = _trace(lens, np.broadcast_to(film, aim.shape), d, from_sensor=True)
        cos_theta = d_axial / np.linalg.norm(d, axis=1)
        return float(np.sum(cos_theta[ok] ** 4) * cell / d_axial**2)

    e0 = irradiance(0.0)
    e = np.array([irradiance(r) for r in radii])
    rel = e / e0
    if np.ndim(film_radius_mm) == 0:
        return Illumination(rel[0], e[0], e0)
    return Illumination(rel, e, e0)


# --------------------------------------------------------------------------------------------------------------------
# The chief ray: field angle
# --------------------------------------------------------------------------------------------------------------------


class ChiefRay(NamedTuple):
    angle: float  # radians between the object-space ray and the axis
    aim_x: float  # where the ray from the film crosses the rear vertex plane (x; y = 0)
    origin: np.ndarray  # where it leaves the front surface
    direction: np.ndarray  # its unit direction in object space (toward -z)


def chief_ray(surfaces, z_sensor, film_radius_mm, *, wavelength_ior=None) -> ChiefRay:
    """The ray from the film point (film_radius_mm, 0, z_sensor) that passes through the centre of the aperture
    stop. It is found by a root search on its aim point x_a on the rear vertex plane: the ray toward
    (x_a, 0, z_rear) is traced back to the stop, and x_a is adjusted until it crosses the stop plane on the axis.
    Clear apertures are ignored here (the chief ray defines the field angle even where vignetting clips it)."""
    lens = _lens(surfaces, wavelength_ior)
    stop = stop_index(surfaces)
    r = float(film_radius_mm)
    film = np.array([r, 0.0, float(z_sensor)])

    def x_at_stop(aims):
        aims = np.asarray(aims, dtype=float)
        target = np.stack([aims, np.zeros_like(aims), np.full_like(aims, lens.z[-1])], axis=1)
        p, _, ok = _trace(lens, np.broadcast_to(film, target.shape), target - film, from_sensor=True, clip=False,
                          last=stop)
        return np.where(ok, p[:, 0], np.nan)

    # A scan over aim points brackets the root; repeated subdivision of the bracket (a vectorised bisection,
    # 32 parts a round) narrows it to rounding.
    span = 2.0 * abs(r) + 2.0 * float(np.max(lens.semi))
    lo, hi = -span, span
    for _ in range(40):
        aims = np.linspace(lo, hi, 2049 if lo == -span else 33)
        f = x_at_stop(aims)
        exact = np.flatnonzero(f == 0.0)
        if len(exact):
            lo = hi = aims[exact[np.argmin(np.abs(aims[exact] - r))]]
            break
        change = np.flatnonzero(np.isfinite(f[:-1]) & np.isfinite(f[1:]) & (np.sign(f[:-1]) != np.sign(f[1:])))
        if not len(change):
            raise ValueError("no ray from this film point reaches the centre of the stop")
        k = change[np.argmin(np.abs(f[change]) + np.abs(f[change + 1]))]
        lo, hi = aims[k], aims[k + 1]
        if hi - lo <= 4e-16 * max(1.0, abs(lo)):
            break
    aim = 0.5 * (lo + hi)
    target = np.array([[aim, 0.0, lens.z[-1]]])
    p, t, ok = _trace(lens, film[None, :], target - film, from_sensor=True, clip=False)
    if not ok[0]:
        raise ValueError("the chief ray does not get through the lens")
    angle = math.atan2(math.hypot(t[0, 0], t[0, 1]), -t[0, 2])
    return ChiefRay(angle, float(aim), p[0], t[0])


def chief_ray_angle(surfaces, z_sensor, film_radius_mm, *, wavelength_ior=None) -> float:
    """The lens's true field angle (radians, to the axis, in object space) at a film height: that of the chief ray
    (:func:`chief_ray`). Twice it at the film's half-diagonal is the diagonal field of view; comparing
    tan(angle) with film_radius / f gives the distortion."""
    return chief_ray(surfaces, z_sensor, film_radius_mm, wavelength_ior=wavelength_ior).angle


# --------------------------------------------------------------------------------------------------------------------
# Dispersion
# --------------------------------------------------------------------------------------------------------------------


def dispersed_ior(n_d, abbe, wavelength_nm):
    """The refractive index at a wavelength, from the glass's n_d and Abbe number V_d, by the two-term Cauchy formula
    n(lambda) = A + B / lambda^2 (lambda in nm).

    The two constants follow from the two catalogue numbers:
      n(lambda_d) = n_d                                      (lambda_d = 587.56 nm, helium d line)
      n(lambda_F) - n(lambda_C) = (n_d - 1) / V_d            (lambda_F = 486.13 nm, lambda_C = 656.27 nm, hydrogen)
    so B = (n_d - 1) / (V_d (1/lambda_F^2 - 1/lambda_C^2)) and A = n_d - B / lambda_d^2. A glass without dispersion
    (V_d infinite, or given as 0 or None) has n = n_d everywhere; so has air (n_d = 1).
    """
    lam = np.asarray(wavelength_nm, dtype=float)
    if abbe is None or abbe == 0 or not math.isfinite(abbe):
        return np.full_like(lam, float(n_d)) if lam.ndim else float(n_d)
    b = (n_d - 1.0) / (abbe * (1.0 / LAMBDA_F_NM**2 - 1.0 / LAMBDA_C_NM**2))
    a = n_d - b / LAMBDA_D_NM**2
    n = a + b / lam**2
    return n if lam.ndim else float(n)
