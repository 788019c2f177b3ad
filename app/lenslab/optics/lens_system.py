"""A real lens, element by element: its paraxial constants, rays traced through its glass, focusing, and the exit
pupil the camera samples (docs/lenses.md; Kolb, Mitchell and Hanrahan 1995; pbrt-v4's RealisticCamera).

**Coordinates.** Lengths in millimetres, in the camera's own frame: it looks down -z, so light from the scene
travels towards +z and the sensor lies at the largest z. The sensor plane is at ``z = efl`` and the lens's rear
principal point, at infinity focus, at ``z = 0``: where a thin lens of the same focal length would sit, so that a
scene framed through the thin lens keeps its framing through the glass. Focusing moves the whole lens forward
(unit focusing) by ``shift`` mm; the sensor stays where it is.

**Surfaces** are spheres (a radius of 0 is the aperture stop, a flat opening), listed from the front element to
the rear; ``ior[i]`` is the medium behind surface ``i``. A ray is lost where it misses a sphere, lands outside a
surface's clear aperture or the stop's opening, or is totally reflected inside the glass.

**Colour.** A glass with an Abbe number disperses: its index at a wavelength follows a two-term Cauchy formula fitted
to n_d and V_d (:func:`dispersed_ior`). The renderer traces each camera sample at one of three wavelengths, one per
colour channel (:data:`CHANNEL_WAVELENGTHS_NM`); a lens without Abbe numbers is traced once, achromatic.

glsl/real_lens.glsl mirrors :meth:`LensSetting.rays` step by step; tests/test_real_lens.py runs both on the same
numbers, and tests/reference_lens.py is an independent tracer the optics here are checked against.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .aperture import Aperture, sample_concentric_disk
from .stops import exact_f_number, stop_scale
from .prescription import LensPrescription

__all__ = ["CHANNEL_WAVELENGTHS_NM", "LensSystem", "LensSetting", "PUPIL_BINS", "dispersed_ior", "refract",
           "surface_crossing", "trace_from_film", "trace_from_scene", "trace_path_from_scene"]

#: The Fraunhofer lines the Abbe number is defined on, nm: V_d = (n_d - 1) / (n_F - n_C).
D_LINE_NM, F_LINE_NM, C_LINE_NM = 587.56, 486.13, 656.27
#: The wavelength each colour channel's camera samples are traced at, nm: the dominant wavelengths of the sRGB
#: (Rec. 709) primaries, so that a fringe has the colour the channel shows.
CHANNEL_WAVELENGTHS_NM = (612.0, 549.0, 465.0)
#: The exact third stops, which a lens's widest aperture is marked by.
THIRD_STOPS_EXACT = tuple(stop_scale("third").exact)
#: Steps of the chief rays' table, from the centre of the image to its corner; aims tried across the rear element
#: to bracket each chief ray before bisection closes in on it.
CHIEF_RAY_STEPS = 512
CHIEF_RAY_SCAN = 256
#: Radial bins of the exit-pupil table, from the centre of the image to its corner (pbrt-v4 uses 64).
PUPIL_BINS = 64
#: Rear-plane points per side of the grids each bin's pupil is found with: over the whole rear element (where no
#: earlier bin says where to look: fine enough for the pupil of a lens stopped down to f/22), over where the last
#: bin's pupil was, and the fine one over the box that finds; and film positions inside each bin (its two edges
#: besides).
PUPIL_SEARCH_GRID = 96
PUPIL_COARSE_GRID = 16
PUPIL_GRID = 32
PUPIL_FILM_STEPS = 1


def dispersed_ior(n_d: float, abbe: float | None, wavelength_nm) -> np.ndarray | float:
    """The index of a glass at ``wavelength_nm`` from its index at the d line and its Abbe number, by Cauchy's
    n = A + B / lambda^2 with n(d) = n_d and n(F) - n(C) = (n_d - 1) / V_d. No Abbe number: no dispersion."""
    if abbe is None or n_d == 1.0:
        return np.full(np.shape(wavelength_nm), float(n_d)) if np.ndim(wavelength_nm) else float(n_d)
    b = (n_d - 1.0) / abbe / (F_LINE_NM ** -2 - C_LINE_NM ** -2)
    a = n_d - b * D_LINE_NM ** -2
    return a + b * np.asarray(wavelength_nm, dtype=float) ** -2


@dataclass(frozen=True)
class Paraxial:
    """First-order constants of a lens at infinity focus, from a paraxial (y, n u) trace at the d line, mm."""

    efl: float  # effective focal length
    back_focal: float  # rear vertex to the rear focal point
    front_focal: float  # front focal point to the front vertex
    track: float  # front vertex to rear vertex
    entrance_pupil_z: float  # from the front vertex (positive: behind it)
    entrance_pupil_diameter: float  # of the full stop

    @property
    def f_number(self) -> float:
        """The widest aperture the glass allows: focal length over the entrance pupil's diameter."""
        return self.efl / self.entrance_pupil_diameter


def refract(d: np.ndarray, normal: np.ndarray, eta: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """Snell's law for unit directions ``d`` (N, 3) at unit normals facing against them; ``eta`` = n_in / n_out.
    Returns the refracted directions and which rays were not totally reflected."""
    cos_in = -np.einsum("ij,ij->i", d, normal)
    sin2_out = eta * eta * np.maximum(0.0, 1.0 - cos_in * cos_in)
    ok = sin2_out <= 1.0
    cos_out = np.sqrt(np.maximum(0.0, 1.0 - sin2_out))
    eta = np.asarray(eta)[..., None] if np.ndim(eta) else eta
    out = eta * d + (eta * cos_in - cos_out)[:, None] * normal
    return out, ok


class LensSystem:
    """A lens prescription made ready to trace: vertex positions, indices, paraxial constants, focusing."""

    def __init__(self, prescription: LensPrescription):
        self.prescription = prescription
        surfaces = prescription.surfaces
        self.radius = np.array([s.radius_mm for s in surfaces], float)
        self.thickness = np.array([s.thickness_mm for s in surfaces], float)
        self.ior_d = np.array([s.ior for s in surfaces], float)
        self.abbe = [s.abbe for s in surfaces]
        self.aperture_radius = np.array([s.aperture_mm / 2.0 for s in surfaces], float)
        self.stop = prescription.stop_index
        # Vertex positions from the front vertex (the last surface's own thickness is the film distance, which the
        # paraxial rear focus replaces).
        self.vertex_from_front = np.concatenate([[0.0], np.cumsum(self.thickness[:-1])])

    @property
    def name(self) -> str:
        return self.prescription.name

    @property
    def dispersive(self) -> bool:
        return any(a is not None for a in self.abbe)

    def ior(self, wavelength_nm: float = D_LINE_NM) -> np.ndarray:
        """The index behind each surface at ``wavelength_nm``."""
        return np.array([float(dispersed_ior(n, v, wavelength_nm)) for n, v in zip(self.ior_d, self.abbe)])

    def channel_iors(self) -> np.ndarray:
        """(surfaces, 3): each surface's index at each channel's wavelength (all three alike without dispersion)."""
        if not self.dispersive:
            return np.repeat(self.ior_d[:, None], 3, axis=1)
        return np.stack([self.ior(w) for w in CHANNEL_WAVELENGTHS_NM], axis=1)

    # -- first order ---------------------------------------------------------------------------------------
    def paraxial_trace(self, y: float, nu: float, ior: np.ndarray) -> tuple[float, float, list[float]]:
        """A paraxial ray entering at height y with reduced angle n u, through the surfaces with the indices
        ``ior`` (one wavelength's): its height on the rear vertex's plane, its reduced angle after the last
        surface, and its height at each surface."""
        n_before, heights = 1.0, []
        for i, (radius, n_after) in enumerate(zip(self.radius, ior)):
            heights.append(y)
            power = 0.0 if radius == 0.0 else (n_after - n_before) / radius
            nu = nu - y * power
            if i < len(self.radius) - 1:
                y = y + self.thickness[i] * nu / n_after
            n_before = n_after
        return y, nu, heights

    @cached_property
    def paraxial(self) -> Paraxial:
        ior = self.ior_d
        y, nu, _ = self.paraxial_trace(1.0, 0.0, ior)  # a ray from infinity at unit height
        if nu == 0.0:
            raise ValueError(f"lens '{self.name}' has no power: it is afocal, it cannot form an image")
        efl = -1.0 / nu
        back_focal = -y / nu
        # The front focal distance from a ray traced backwards: reverse the lens (radii negated, order reversed).
        reversed_system = _reversed(self)
        yr, nur, _ = reversed_system.paraxial_trace(1.0, 0.0, reversed_system.ior_d)
        front_focal = -yr / nur
        track = float(self.vertex_from_front[-1])
        # The entrance pupil: the stop's image in the glass in front of it (its position and size fix the f-number).
        pupil_z, pupil_diameter = self._entrance_pupil()
        return Paraxial(efl=efl, back_focal=back_focal, front_focal=front_focal, track=track,
                        entrance_pupil_z=pupil_z, entrance_pupil_diameter=pupil_diameter)

    def _entrance_pupil(self) -> tuple[float, float]:
        """Position (from the front vertex, + behind it) and diameter of the stop's paraxial image through the
        glass in front of it. Paraxial rays are linear in (y, n u): a ray entering at height y with slope u
        crosses the stop at y h_a + u h_b, h_a and h_b the heights of the rays (1, 0) and (0, 1). The chief ray
        (stop height 0) crosses the axis at z = h_b / h_a; a beam parallel to the axis fills the stop at
        height r_stop / h_a."""
        _, _, unit_height = self.paraxial_trace(1.0, 0.0, self.ior_d)
        _, _, unit_slope = self.paraxial_trace(0.0, 1.0, self.ior_d)
        h_a, h_b = unit_height[self.stop], unit_slope[self.stop]
        return float(h_b / h_a), float(2.0 * self.aperture_radius[self.stop] / abs(h_a))

    @property
    def efl(self) -> float:
        return self.paraxial.efl

    @property
    def widest_f_number(self) -> float:
        """The f-number of the full stop, paraxially: focal length over the entrance pupil's diameter."""
        return self.paraxial.f_number

    @property
    def marked_f_number(self) -> float:
        """The widest f-number the lens is set to: as its source marks it (an f/2 design is f/2 even where
        paraxial optics says f/2.03; the stop opens no further than the glass allows), else the third stop the
        glass's is within 3% of, else the glass's own."""
        marked = self.prescription.published_f_number
        if marked:
            return exact_f_number(marked)
        # No mark given: the third stop within 3% of the glass's (f/2.03 is an f/2 lens), else the glass's own.
        glass = self.widest_f_number
        nearest = min(THIRD_STOPS_EXACT, key=lambda stop: abs(stop / glass - 1.0))
        return nearest if abs(nearest / glass - 1.0) <= 0.03 else round(glass, 2)

    def stop_radius_for(self, f_number: float) -> float:
        """The stop's radius, mm, that gives ``f_number``: the stop scales, the rest of the glass stays."""
        return float(self.aperture_radius[self.stop] * min(1.0, self.widest_f_number / f_number))

    def vertex_z(self, shift: float = 0.0) -> np.ndarray:
        """Each surface's vertex, camera z in mm, with the lens moved ``shift`` mm forward from infinity focus."""
        rear = self.efl - self.paraxial.back_focal - shift
        return rear - (self.vertex_from_front[-1] - self.vertex_from_front)

    # -- focusing ------------------------------------------------------------------------------------------
    @property
    def hiatus_to_focal_points(self) -> float:
        """Front focal point to rear focal point at infinity focus, mm."""
        p = self.paraxial
        return p.front_focal + p.track + p.back_focal

    @property
    def closest_focus_mm(self) -> float:
        """The nearest object distance (from the sensor) unit focusing can reach, paraxially: life size, where
        the lens has moved one focal length forward."""
        return self.hiatus_to_focal_points + 2.0 * self.efl

    def paraxial_shift_for(self, distance_mm: float) -> float:
        """How far the lens moves forward to focus on a point ``distance_mm`` in front of the sensor: Newton's
        x x' = f^2 with x' = shift (the rear focal point leaves the sensor by it) and x the object's distance
        from the front focal point."""
        if not math.isfinite(distance_mm):
            return 0.0
        f, span = self.efl, distance_mm - self.hiatus_to_focal_points
        disc = span * span - 4.0 * f * f
        if disc < 0.0:
            raise ValueError(f"{distance_mm / 1000.0:g} m from the sensor is nearer than the {self.name} "
                             f"can focus ({self.closest_focus_mm / 1000.0:.4g} m)")
        return 0.5 * (span - math.sqrt(disc))

    def setting(self, f_number: float, focus_distance_mm: float, film_mm: tuple[float, float], *,
                aperture: Aperture | None = None, film_radius_mm: float | None = None,
                dispersion: bool = True) -> "LensSetting":
        """The lens set to ``f_number`` and focused on ``focus_distance_mm`` from the sensor (found by tracing:
        the paraxial shift refined to the smallest spot at this aperture), making an image of ``film_mm``."""
        stop_radius = self.stop_radius_for(f_number)
        shift = self.best_focus_shift(focus_distance_mm, stop_radius)
        return LensSetting(self, f_number=float(f_number), shift=shift, stop_radius=stop_radius,
                           aperture=aperture or Aperture(), film_mm=film_mm,
                           film_radius_mm=film_radius_mm or 0.5 * math.hypot(*film_mm), dispersion=dispersion)

    def best_focus_shift(self, distance_mm: float, stop_radius: float, rays: int = 24) -> float:
        """The shift that images a point on the axis ``distance_mm`` from the sensor into the smallest (RMS)
        spot on the sensor, through a stop of ``stop_radius``: the paraxial shift, refined by golden section over
        real rays through the pupil (spherical aberration moves the best focus off the paraxial one)."""
        paraxial = self.paraxial_shift_for(distance_mm)
        # A fan of rays from the point on the axis across the entrance pupil (d line), one plane is enough: the
        # point is on the axis.
        heights = (np.arange(rays) + 0.5) / rays
        span = max(0.02 * self.efl, 0.01)

        def spot(shift: float) -> float:
            z = self.vertex_z(shift)
            origin_z = self.efl - distance_mm if math.isfinite(distance_mm) else None
            pupil_z = z[0] + self.paraxial.entrance_pupil_z
            pupil_r = 0.5 * self.paraxial.entrance_pupil_diameter * stop_radius / self.aperture_radius[self.stop]
            target = np.stack([heights * pupil_r, np.zeros(rays), np.full(rays, pupil_z)], axis=-1)
            if origin_z is None:
                directions = np.tile([0.0, 0.0, 1.0], (rays, 1))
            else:
                directions = target - np.array([0.0, 0.0, origin_z])
                directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
            # Each ray starts just in front of the lens, found back from its target: a point a thousand kilometres
            # out would lose the rays' few micrometres to rounding in the spheres' intersections.
            start_z = z[0] - self.aperture_radius[0] - 1.0
            origins = target - directions * ((target[:, 2] - start_z) / directions[:, 2])[:, None]
            o, d, ok = trace_from_scene(self, origins, directions, shift, stop_radius, self.ior_d)
            if ok.sum() < 2:
                return math.inf
            t = (self.efl - o[ok, 2]) / d[ok, 2]
            x = o[ok, 0] + t * d[ok, 0]
            w = heights[ok]  # each ray stands for a ring of the pupil: weight by its radius
            return float(np.sum(w * x * x) / np.sum(w))

        best = paraxial
        for _ in range(4):  # a best focus found at the search's edge may lie beyond it: search again round it
            low, high = best - span, best + span
            best = _golden_section_minimum(spot, low, high)
            if min(best - low, high - best) > 0.05 * span:
                break
        return best if math.isfinite(spot(best)) else paraxial


def _golden_section_minimum(f, low: float, high: float, steps: int = 40) -> float:
    """Where the unimodal ``f`` is least on [low, high], by golden-section search."""
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = high - ratio * (high - low), low + ratio * (high - low)
    fa, fb = f(a), f(b)
    for _ in range(steps):
        if fa < fb:
            high, b, fb = b, a, fa
            a = high - ratio * (high - low)
            fa = f(a)
        else:
            low, a, fa = a, b, fb
            b = low + ratio * (high - low)
            fb = f(b)
    return 0.5 * (low + high)


def _reversed(system: LensSystem) -> LensSystem:
    """The lens turned round (for the front focal distance): surfaces in reverse order, radii negated, each
    medium now behind the surface that was in front of it."""
    from .prescription import LensSurface

    surfaces = system.prescription.surfaces
    n = len(surfaces)
    flipped = []
    for k in range(n):
        i = n - 1 - k
        medium_behind = 1.0 if i == 0 else surfaces[i - 1].ior
        abbe = None if i == 0 else surfaces[i - 1].abbe
        thickness = surfaces[i - 1].thickness_mm if i > 0 else 0.0
        flipped.append(LensSurface(radius_mm=-surfaces[i].radius_mm, thickness_mm=thickness, ior=medium_behind,
                                   abbe=abbe, aperture_mm=surfaces[i].aperture_mm))
    clone = object.__new__(LensSystem)
    clone.prescription = system.prescription
    clone.radius = np.array([s.radius_mm for s in flipped])
    clone.thickness = np.array([s.thickness_mm for s in flipped])
    clone.ior_d = np.array([s.ior for s in flipped])
    clone.abbe = [s.abbe for s in flipped]
    clone.aperture_radius = np.array([s.aperture_mm / 2.0 for s in flipped])
    clone.stop = n - 1 - system.stop
    clone.vertex_from_front = np.concatenate([[0.0], np.cumsum(clone.thickness[:-1])])
    return clone


def surface_crossing(system: LensSystem, i: int, z_vertex: float, o: np.ndarray, d: np.ndarray):
    """Where rays (o, d) meet surface ``i`` (vertex at ``z_vertex``): the points, the unit normals facing the
    rays, and which rays hit it at all. The part of the sphere near its vertex is the surface."""
    radius = system.radius[i]
    if radius == 0.0:
        t = (z_vertex - o[:, 2]) / d[:, 2]
        p = o + t[:, None] * d
        normal = np.tile([0.0, 0.0, 1.0], (len(o), 1))
        hit = t > 0.0
    else:
        centre = np.array([0.0, 0.0, z_vertex + radius])
        oc = o - centre
        b = np.einsum("ij,ij->i", oc, d)
        c = np.einsum("ij,ij->i", oc, oc) - radius * radius
        disc = b * b - c
        hit = disc >= 0.0
        root = np.sqrt(np.maximum(disc, 0.0))
        # Of the two crossings, the one on the vertex's side of the centre: the nearer one when the ray travels
        # from the vertex towards the centre, else the farther.
        towards_centre = (d[:, 2] > 0.0) == (radius > 0.0)
        t = np.where(towards_centre, -b - root, -b + root)
        hit &= t > 0.0
        p = o + t[:, None] * d
        normal = (p - centre) / radius
    normal = np.where((np.einsum("ij,ij->i", normal, d) > 0.0)[:, None], -normal, normal)
    return p, normal, hit


def _trace(system: LensSystem, order, o, d, shift, stop_radius, ior, stop_inside=None, entering=True, clip=True):
    """Rays through the surfaces ``order``: their last points, directions and which got through; ``clip`` False:
    through the glass's spheres alone, no clear aperture or stop stopping them (the chief rays' geometry)."""
    return _trace_surfaces(system, order, o, d, shift, stop_radius, ior, stop_inside, entering, clip)[:3]


def _trace_surfaces(system, order, o, d, shift, stop_radius, ior, stop_inside, entering, clip, crossings=None):
    """:func:`_trace`, and for each ray how many surfaces of ``order`` it crosses before it is lost (a ray that
    misses a sphere ends before it; one that lands outside an opening or is totally reflected ends on it).
    ``crossings``, a list, receives each surface's points in turn."""
    z = system.vertex_z(shift)
    ok = np.ones(len(o), bool)
    ends = np.full(len(o), len(order))
    # A lost ray's numbers run off to infinity or NaN in the surfaces after it is lost: masked, not warned of.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for k, i in enumerate(order):
            p, normal, hit = surface_crossing(system, i, z[i], o, d)
            ends[ok & ~hit] = k
            ok &= hit
            if crossings is not None:
                crossings.append(p)
            r2 = p[:, 0] ** 2 + p[:, 1] ** 2
            if system.radius[i] == 0.0:
                inside = stop_inside(p[:, :2]) if stop_inside is not None else r2 <= stop_radius * stop_radius
            else:
                inside = r2 <= system.aperture_radius[i] ** 2
            if clip:
                ends[ok & ~inside] = k + 1
                ok &= inside
            if system.radius[i] != 0.0:
                # Media either side of surface i: ior[i] behind it (towards the sensor), ior[i - 1] (or air) in front.
                n_front = 1.0 if i == 0 else ior[i - 1]
                n_back = ior[i]
                eta = n_back / n_front if not entering else n_front / n_back
                d, not_reflected = refract(d, normal, eta)
                ends[ok & ~not_reflected] = k + 1
                ok &= not_reflected
            o = p
    return o, d, ok, ends


def trace_path_from_scene(system: LensSystem, o, d, shift, stop_radius, *, clip=True, last: int | None = None):
    """Rays from the scene through surfaces 0 to ``last`` (all by default), at the d line, surface by surface (the
    studio's side view draws them): each surface's points (surfaces, N, 3), the directions after the last, how
    many of those points each ray reaches before it is lost, and which got through."""
    order = range((len(system.radius) - 1 if last is None else last) + 1)
    crossings: list[np.ndarray] = []
    _, d, ok, ends = _trace_surfaces(system, order, np.asarray(o, float), np.asarray(d, float), shift, stop_radius,
                                     system.ior_d, None, True, clip, crossings)
    return np.stack(crossings), d, ends, ok


def trace_from_scene(system: LensSystem, o, d, shift, stop_radius, ior, stop_inside=None):
    """Rays from the scene through the lens towards the sensor: exit points, directions and which got through."""
    return _trace(system, range(len(system.radius)), np.asarray(o, float), np.asarray(d, float), shift,
                  stop_radius, ior, stop_inside, entering=True)


def trace_from_film(system: LensSystem, o, d, shift, stop_radius, ior, stop_inside=None):
    """Rays from the sensor out through the lens into the scene: exit points on the front element, directions
    and which got through (the renderer's direction, glsl/real_lens.glsl)."""
    return _trace(system, range(len(system.radius) - 1, -1, -1), np.asarray(o, float), np.asarray(d, float),
                  shift, stop_radius, ior, stop_inside, entering=False)


def _grown(box: np.ndarray, fraction: float) -> np.ndarray:
    """A box (x0, y0, x1, y1) grown on every side by ``fraction`` of its width and height."""
    box = np.asarray(box, float)
    margin = fraction * (box[2:] - box[:2])
    return np.concatenate([box[:2] - margin, box[2:] + margin])


@dataclass(frozen=True, eq=False)
class LensSetting:
    """A lens at one f-number and focus, making one image: what the renderer's camera rays are made from."""

    system: LensSystem
    f_number: float
    shift: float  # mm the lens has moved forward from infinity focus
    stop_radius: float  # mm
    aperture: Aperture  # the iris's shape (round, blades, rounded blades), in units of the stop's radius
    film_mm: tuple[float, float]  # the sensor area the image shows
    film_radius_mm: float  # the pupil table reaches this far from the centre
    dispersion: bool = True  # False: every channel traced at the d line (an achromatic preview of dispersive glass)

    @property
    def dispersive(self) -> bool:
        """Each sample traced at one channel's wavelength: the glass disperses and dispersion is on."""
        return self.system.dispersive and self.dispersion

    @cached_property
    def channel_iors(self) -> np.ndarray:
        """(surfaces, 3): the index behind each surface for each colour channel's rays."""
        if self.dispersive:
            return self.system.channel_iors()
        return np.repeat(self.system.ior_d[:, None], 3, axis=1)

    @cached_property
    def distinct_iors(self) -> np.ndarray:
        """(wavelengths, surfaces): the channels' indices, once each (one row when achromatic)."""
        return np.ascontiguousarray(np.unique(self.channel_iors.T, axis=0))

    @property
    def sensor_z(self) -> float:
        return self.system.efl

    @property
    def rear_z(self) -> float:
        return float(self.system.vertex_z(self.shift)[-1])

    @property
    def image_distance_mm(self) -> float:
        """Rear principal point to sensor: the focal length plus the focusing extension (what breathes)."""
        return self.system.efl + self.shift

    def stop_contains(self, points_mm: np.ndarray) -> np.ndarray:
        return self.aperture.contains(np.asarray(points_mm) / self.stop_radius)

    @property
    def pupil_bounds(self) -> np.ndarray:
        """(PUPIL_BINS, 4): each radial bin's box round its exit pupil (x0, y0, x1, y1) (:meth:`_pupil_tables`)."""
        return self._pupil_tables[0]

    @property
    def pupil_disks(self) -> np.ndarray:
        """(PUPIL_BINS, 4): each radial bin's disk round its exit pupil (centre x, y, radius) and 1 where the disk
        is sampled rather than the box, being the smaller (:meth:`_pupil_tables`)."""
        return self._pupil_tables[1]

    @cached_property
    def _pupil_tables(self) -> tuple[np.ndarray, np.ndarray]:
        """For film points at radii in each bin along +x, the box (x0, y0, x1, y1) on the rear vertex's plane that
        every ray which gets through the lens crosses (the exit pupil, seen from there), and the disk round the
        same rays; an empty box where no ray gets through. Every sample outside the pupil is wasted, so each bin is
        sampled over the smaller of the two: the disk where the pupil is round (pi / 4 of its box), the box where
        vignetting has cut it to a cat's eye.

        Found, as pbrt does, by tracing grids of rays from points across each bin (its edges and middle, at every
        channel's wavelength) to the rear plane. The pupil moves and shrinks smoothly across the image, so each
        bin is searched where the last one's pupil was (the whole rear element for the first, finely, so that
        the small pupil of a stopped-down lens is not missed between grid points), widening the search while the
        rays found reach its edge; a fine grid over what is found then draws it tight, one fine cell wider on
        every side so that no ray between the grid's points is lost."""
        rear_radius = self.system.aperture_radius[-1]
        radii = np.linspace(0.0, self.film_radius_mm, PUPIL_BINS + 1)
        film_x = (radii[:-1, None] + (np.arange(PUPIL_FILM_STEPS) + 0.5) / PUPIL_FILM_STEPS
                  * (radii[1:] - radii[:-1])[:, None])
        film_x = np.concatenate([film_x, radii[:-1, None], radii[1:, None]], axis=1)  # the bin's edges too
        whole = np.array([-1.5, -1.5, 1.5, 1.5]) * rear_radius
        boxes, disks = np.zeros((PUPIL_BINS, 4)), np.zeros((PUPIL_BINS, 4))
        search = None
        for b in range(PUPIL_BINS):
            found = self._search_pupil(film_x[b], search, whole)
            if found is None:
                search = None  # beyond the image circle: look everywhere again further out
                continue
            xs, ys, cell_x, cell_y = self._scan(film_x[b], _grown(found, 1.0 / PUPIL_COARSE_GRID), PUPIL_GRID)
            box = np.array([xs.min() - cell_x, ys.min() - cell_y, xs.max() + cell_x, ys.max() + cell_y])
            centre = 0.5 * (box[:2] + box[2:])
            radius = float(np.sqrt(((xs - centre[0]) ** 2 + (ys - centre[1]) ** 2).max())) + math.hypot(cell_x, cell_y)
            boxes[b] = box
            disks[b] = (*centre, radius, float(math.pi * radius * radius < (box[2] - box[0]) * (box[3] - box[1])))
            search = _grown(box, 0.5)
        return boxes, disks

    def _search_pupil(self, film_x: np.ndarray, search, whole: np.ndarray) -> np.ndarray | None:
        """The box round the coarse grid's points whose rays get through, searching ``search`` (None: the whole
        rear element, on a grid fine enough for a stopped-down pupil) and widening it while they reach its edge."""
        while True:
            region = whole if search is None else search
            grid = PUPIL_SEARCH_GRID if search is None else PUPIL_COARSE_GRID
            xs, ys, cell_x, cell_y = self._scan(film_x, region, grid)
            if not len(xs):
                if search is None:
                    return None
                search = None
                continue
            box = np.array([xs.min() - cell_x, ys.min() - cell_y, xs.max() + cell_x, ys.max() + cell_y])
            at_edge = (box[:2] <= region[:2] + cell_x).any() or (box[2:] >= region[2:] - cell_x).any()
            if search is None or not at_edge:
                return box
            search = None if (_grown(box, 1.0)[2:] - _grown(box, 1.0)[:2] >= whole[2:] - whole[:2]).any() \
                else _grown(box, 1.0)

    def _scan(self, film_x: np.ndarray, region: np.ndarray, grid: int):
        """The points of a ``grid`` x ``grid`` grid over ``region`` whose rays from any of ``film_x`` (on the
        +x axis of the sensor) get out of the lens, and the grid's cell."""
        from .pupil_trace import rays_through  # numba, loaded when a table is first made, not with every import

        system = self.system
        x0, y0, x1, y1 = region
        steps = (np.arange(grid) + 0.5) / grid
        gx, gy = np.meshgrid(x0 + steps * (x1 - x0), y0 + steps * (y1 - y0))
        gx, gy = gx.ravel(), gy.ravel()
        # The stop as the circle round its corners: a bladed stop's corners reach past the round stop's radius.
        passed = rays_through(film_x, gx, gy, self.sensor_z, system.vertex_z(self.shift), system.radius,
                              system.aperture_radius, self.distinct_iors,
                              self.stop_radius * self.aperture.scale).any(axis=0)
        return gx[passed], gy[passed], (x1 - x0) / grid, (y1 - y0) / grid

    @cached_property
    def ideal_irradiance(self) -> float:
        """What an ideal lens at this f-number gives the centre of the image from a unit radiance: pi / (4 N^2).
        Camera weights are divided by it, so that the real lens's image sits where the thin lens's does and shows
        only what the glass adds: vignetting, cos^4 falloff, the pupil's aberrations, the light lost focusing close."""
        return math.pi / (4.0 * self.f_number ** 2)

    @property
    def weight_scale(self) -> float:
        """What a camera sample's cos^4(theta) times the pupil region's area is multiplied by: the camera
        measurement's 1 / d^2 (d: the sensor to the rear vertex's plane, where the regions lie) over the ideal
        lens's irradiance. glsl/real_lens.glsl's lens_weight_scale."""
        depth = self.sensor_z - self.rear_z
        return 1.0 / (depth * depth * self.ideal_irradiance)

    def film_points(self, pixels: np.ndarray, width: int, height: int) -> np.ndarray:
        """Points on the sensor (camera frame, mm) that pixels (N, 2) image. The lens turns the image round, so
        the top-right of the picture lies at the bottom-left of the sensor."""
        ndc_x = 2.0 * pixels[:, 0] / width - 1.0
        ndc_y = 1.0 - 2.0 * pixels[:, 1] / height
        return np.stack([-ndc_x * self.film_mm[0] / 2.0, -ndc_y * self.film_mm[1] / 2.0,
                         np.full(len(pixels), self.sensor_z)], axis=-1)

    def sample_pupil(self, film: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points on the rear vertex's plane towards the exit pupil of each film point, and their densities
        (1 / the area sampled): the box or disk for the point's radius, turned to the point's direction (the lens is
        round). A disk is sampled by the concentric map, which keeps a stratified pattern stratified."""
        r = np.hypot(film[:, 0], film[:, 1])
        index = np.minimum((r / self.film_radius_mm * PUPIL_BINS).astype(int), PUPIL_BINS - 1)
        box, disk = self.pupil_bounds[index], self.pupil_disks[index]
        on_disk = disk[:, 3] > 0.0
        area = np.where(on_disk, math.pi * disk[:, 2] ** 2, (box[:, 2] - box[:, 0]) * (box[:, 3] - box[:, 1]))
        in_disk = disk[:, :2] + disk[:, 2:3] * sample_concentric_disk(u)
        x = np.where(on_disk, in_disk[:, 0], box[:, 0] + u[:, 0] * (box[:, 2] - box[:, 0]))
        y = np.where(on_disk, in_disk[:, 1], box[:, 1] + u[:, 1] * (box[:, 3] - box[:, 1]))
        safe_r = np.where(r > 0.0, r, 1.0)
        cos_a = np.where(r > 0.0, film[:, 0] / safe_r, 1.0)
        sin_a = np.where(r > 0.0, film[:, 1] / safe_r, 0.0)
        points = np.stack([cos_a * x - sin_a * y, sin_a * x + cos_a * y, np.full(len(x), self.rear_z)], axis=-1)
        return points, area

    def rays(self, pixels, width: int, height: int, lens_samples=None):
        """Camera-frame origins (mm, on the front element), unit directions and colour weights (N, 3) of the rays
        the pixels ``pixels`` (N, 2) send out, with ``lens_samples`` (N, 2) choosing each one's point on the
        exit pupil (the renderer's lens sample). A dispersive lens traces each sample at one channel's
        wavelength, chosen by the first third of u.x (the rest of u.x, stretched, still places it on the pupil),
        and weighs that channel three times. Without lens samples: the chief rays, through the centre of the stop
        (d line), weight 1 where they get through."""
        pixels = np.asarray(pixels, float).reshape(-1, 2)
        film = self.film_points(pixels, width, height)
        iors = self.channel_iors
        if lens_samples is None:
            origins, directions, passed = self.chief_rays(film)
            return origins, directions, np.repeat(passed[:, None], 3, axis=1)
        u = np.array(lens_samples, float).reshape(-1, 2)
        if self.dispersive:
            channels = np.minimum(np.floor(3.0 * u[:, 0]), 2.0)
            u[:, 0] = 3.0 * u[:, 0] - channels
            channels = channels.astype(int)
            colour = np.zeros((len(u), 3))
            colour[np.arange(len(u)), channels] = 3.0
        else:
            channels = np.ones(len(u), int)
            colour = np.ones((len(u), 3))
        targets, area = self.sample_pupil(film, u)
        directions = targets - film
        directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
        origins = np.empty_like(film)
        out = np.empty_like(film)
        passed = np.zeros(len(film), bool)
        for channel in range(3):
            chosen = channels == channel
            if chosen.any():
                o, d, ok = trace_from_film(self.system, film[chosen], directions[chosen], self.shift,
                                           self.stop_radius, iors[:, channel], self.stop_contains)
                origins[chosen], out[chosen], passed[chosen] = o, d, ok
        cos_theta = -directions[:, 2]
        weight = np.where(passed & (area > 0.0), cos_theta ** 4 * area * self.weight_scale, 0.0)
        return origins, out, weight[:, None] * colour

    @cached_property
    def chief_ray_table(self) -> np.ndarray:
        """(CHIEF_RAY_STEPS + 1, 4): for film points at evenly spaced radii along +x out to the table's reach, the
        chief ray as it leaves the front element: its exit point's x and z, its direction's x and z (NaN where
        no ray through the stop's centre gets out). The lens is round, so every film point's chief ray is the
        one of its radius turned to its direction; a table of radii makes a whole image's rays cheap."""
        radii = np.linspace(0.0, self.film_radius_mm, CHIEF_RAY_STEPS + 1)
        film = np.stack([radii, np.zeros_like(radii), np.full_like(radii, self.sensor_z)], axis=-1)
        o, d, ok = self._aim_through_stop_centre(film)
        table = np.stack([o[:, 0], o[:, 2], d[:, 0], d[:, 2]], axis=-1)
        table[~ok.astype(bool)] = np.nan
        return table

    def chief_rays(self, film: np.ndarray):
        """The rays from film points through the centre of the stop: where each pixel looks (picking, depth,
        placing objects). Camera-frame exit points and directions, and 1 where such a ray gets out (else 0),
        interpolated from :attr:`chief_ray_table` and turned to each point's direction."""
        table = self.chief_ray_table
        r = np.hypot(film[:, 0], film[:, 1])
        position = np.clip(r / self.film_radius_mm * CHIEF_RAY_STEPS, 0.0, CHIEF_RAY_STEPS)
        below = np.minimum(position.astype(int), CHIEF_RAY_STEPS - 1)
        t = (position - below)[:, None]
        row = (1.0 - t) * table[below] + t * table[below + 1]
        safe_r = np.where(r > 0.0, r, 1.0)
        # The film point at +x looks towards -x in the scene: its chief ray's radial coordinates are along it.
        cos_a = np.where(r > 0.0, film[:, 0] / safe_r, 1.0)
        sin_a = np.where(r > 0.0, film[:, 1] / safe_r, 0.0)
        origins = np.stack([row[:, 0] * cos_a, row[:, 0] * sin_a, row[:, 1]], axis=-1)
        directions = np.stack([row[:, 2] * cos_a, row[:, 2] * sin_a, row[:, 3]], axis=-1)
        ok = np.isfinite(row).all(axis=1)
        origins[~ok], directions[~ok] = 0.0, (0.0, 0.0, -1.0)
        directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
        return origins, directions, ok.astype(float)

    def _aim_through_stop_centre(self, film: np.ndarray):
        """Rays from film points through the centre of the stop, aimed by the glass's geometry alone (a rim may
        clip the rays between a film point and the stop's centre that the search tries). Each is aimed at a point of the rear vertex's plane along its
        film point's direction: a scan brackets the aim where the ray crosses the stop's plane at height 0 (the
        bracket nearest the straight line to the stop's centre), bisection closes it. Where no ray through the
        spheres reaches the stop's centre (beyond a fisheye's image circle) the point has no chief ray."""
        system = self.system
        r = np.hypot(film[:, 0], film[:, 1])
        safe_r = np.where(r > 0.0, r, 1.0)
        along = np.stack([np.where(r > 0.0, film[:, 0] / safe_r, 1.0), np.where(r > 0.0, film[:, 1] / safe_r, 0.0)],
                         axis=-1)
        z = system.vertex_z(self.shift)
        behind = range(len(system.radius) - 1, system.stop, -1)

        def stop_height(aim: np.ndarray) -> np.ndarray:
            """(N, K) heights along each film point's direction at which rays aimed at ``aim`` (N, K) cross the
            stop's plane; NaN where a ray misses a sphere or is totally reflected."""
            shape = aim.shape
            origins = np.repeat(film, shape[1], axis=0)
            directions_2d = np.repeat(along, shape[1], axis=0)
            flat = aim.reshape(-1)
            target = np.stack([flat * directions_2d[:, 0], flat * directions_2d[:, 1],
                               np.full(len(flat), self.rear_z)], axis=-1)
            d = (target - origins) / np.linalg.norm(target - origins, axis=-1, keepdims=True)
            o, d, ok = _trace(system, behind, origins, d, self.shift, self.stop_radius, system.ior_d, entering=False,
                              clip=False)
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                t = (z[system.stop] - o[:, 2]) / d[:, 2]
                h = (o[:, 0] + t * d[:, 0]) * directions_2d[:, 0] + (o[:, 1] + t * d[:, 1]) * directions_2d[:, 1]
            return np.where(ok & np.isfinite(h), h, np.nan).reshape(shape)

        reach = self.film_radius_mm + 1.5 * system.aperture_radius.max()
        scan = np.linspace(-reach, reach, CHIEF_RAY_SCAN)
        heights = stop_height(np.tile(scan, (len(film), 1)))
        with np.errstate(invalid="ignore"):
            crossing = (heights[:, :-1] * heights[:, 1:] <= 0.0) & np.isfinite(heights[:, :-1] + heights[:, 1:])
        straight = r * (self.rear_z - z[system.stop]) / max(self.sensor_z - z[system.stop], 1e-9)
        distance = np.where(crossing, np.abs(scan[:-1][None, :] - straight[:, None]), np.inf)
        k = np.argmin(distance, axis=1)
        found = np.isfinite(distance[np.arange(len(film)), k])
        low, high = scan[k], scan[k + 1]
        h_low = heights[np.arange(len(film)), k]
        for _ in range(48):
            middle = 0.5 * (low + high)
            h_middle = stop_height(middle[:, None])[:, 0]
            same_side = (h_middle * h_low > 0.0) & np.isfinite(h_middle)
            low, h_low = np.where(same_side, middle, low), np.where(same_side, h_middle, h_low)
            high = np.where(same_side, high, middle)
        aim = 0.5 * (low + high)
        # A bracket whose end fell off the glass (a ray missing a sphere) narrows onto that edge, not onto a
        # crossing of the axis: only a ray that does cross the stop's centre is a chief ray.
        found &= np.abs(stop_height(aim[:, None])[:, 0]) < 1e-6 * max(1.0, self.stop_radius)
        target = np.stack([aim * along[:, 0], aim * along[:, 1], np.full(len(aim), self.rear_z)], axis=-1)
        d = (target - film) / np.linalg.norm(target - film, axis=-1, keepdims=True)
        # Through every rim too: past the last one that passes light (a fisheye's image circle), no pixel looks out.
        o, d, ok = _trace(system, range(len(system.radius) - 1, -1, -1), film, d, self.shift, self.stop_radius,
                          system.ior_d, entering=False)
        return o, d, (ok & found).astype(float)
