"""Lights that are not shapes: a point light, a spot and the sun. (An emissive material turns any shape into an
area light; the sky is the scene's environment.)"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from lenslab.scene.textures import Texture

RGB = tuple[float, float, float]
Vec3 = tuple[float, float, float]

#: The smallest angular diameter (degrees) of a sun that is a disk; 0 is a point at infinity. Between them the
#: disk's radiance (irradiance over pi sin^2 of its angular radius) leaves the range of float32 on the GPU, and
#: then of Python's floats (1e-200 degrees: a division by zero); from here on it stays within both.
SMALLEST_SUN_DEG = 1e-6


@dataclass
class Light:
    type_name: ClassVar[str] = ""
    name: str = field(default="light", metadata={"required": True})


@dataclass
class PointLight(Light):
    """Light from a single point, equally in all directions: ``intensity`` in candela per channel (its luminance
    in cd), or with ``unit`` "lumens" the light's colour scaled so that its luminance is the total flux, which
    spreads over the sphere: intensity = flux / (4 pi) (scene/light_units.py)."""

    type_name: ClassVar[str] = "point"
    position: Vec3 = (0.0, 2.0, 0.0)
    intensity: RGB = field(default=(10.0, 10.0, 10.0), metadata={"range": (0.0, 1e9),
                                                                 "doc": "candela per channel, or lumens: see unit"})
    unit: str = field(default="candela", metadata={
        "choices": ("candela", "lumens"),
        "doc": "what intensity's luminance gives: candela, or lumens (the flux over the whole sphere)"})


@dataclass
class SunLight(Light):
    """A distant disk of light: ``irradiance`` (lux on a surface facing it: the luminance of the RGB; clear
    midday sun gives about 100,000 lux) arriving from ``direction`` (pointing towards the sun) over a cone of
    ``angular_diameter_deg`` (0.53 for our sun; 0 for a point at infinity, whose shadows are razor sharp).
    Lux is the one unit a sun is written in (scene/light_units.py): a legacy scene's numbers read as lux too."""

    type_name: ClassVar[str] = "sun"
    direction: Vec3 = field(default=(0.3, 1.0, 0.2), metadata={"nonzero_vector": True})
    irradiance: RGB = field(default=(3.0, 3.0, 3.0), metadata={"range": (0.0, 1e9),
                                                               "doc": "lux per channel on a surface facing the sun"})
    angular_diameter_deg: float = field(default=0.53, metadata={"range": (0.0, 30.0),
                                                                "zero_or_at_least": SMALLEST_SUN_DEG})

    def unit_direction(self) -> tuple[float, float, float]:
        n = math.sqrt(sum(c * c for c in self.direction))
        if n == 0:
            raise ValueError(f"sun '{self.name}': direction must not be zero")
        return tuple(c / n for c in self.direction)

    def radiance(self) -> RGB:
        """Radiance of the disk: irradiance over the cosine-weighted solid angle pi sin^2(theta_max)."""
        if self.angular_diameter_deg == 0:
            return self.irradiance  # a delta light: the irradiance itself is what is carried
        if not abs(self.angular_diameter_deg) >= SMALLEST_SUN_DEG:
            raise ValueError(sun_size_problem(self))
        theta = math.radians(self.angular_diameter_deg) / 2
        return tuple(e / (math.pi * math.sin(theta) ** 2) for e in self.irradiance)


@dataclass
class SpotLight(Light):
    """Light from one point into a cone, as Mitsuba 3's ``spot`` (``src/emitters/spot.cpp``): ``intensity``
    in candela along ``direction``, the same out to ``beam_width_deg`` from the axis, then falling linearly in the
    angle to zero at ``cutoff_angle_deg`` (both measured from the axis: half the cone's opening). A beam wider
    than the cutoff is the cutoff (a hard edge), as in Mitsuba.

    With ``unit`` "lumens" the intensity's luminance is the spot's total flux, and all of it leaves through the
    cone: intensity = flux / weighted_solid_angle() (scene/light_units.py), so narrowing the cone brightens the
    beam, as a reflector behind a bulb does (Unity HDRP's "reflector" option does the same).

    An optional ``texture`` is projected through the cone like a slide: the image fills the square that the
    cutoff cone's tangent spans, u = 1/2 + x / (2 z tan(cutoff)), v = 1/2 + y / (2 z tan(cutoff)), with
    (x, y, z) the direction along the image's right edge, its top edge (``up``, made perpendicular to the
    axis) and the axis, right = axis x top. Where the image is black the spot gives no light.
    """

    type_name: ClassVar[str] = "spot"
    position: Vec3 = (0.0, 2.0, 0.0)
    direction: Vec3 = field(default=(0.0, -1.0, 0.0), metadata={"nonzero_vector": True,
                                                                "doc": "the cone's axis, where the light goes"})
    intensity: RGB = field(default=(10.0, 10.0, 10.0), metadata={"range": (0.0, 1e9),
                                                                 "doc": "candela per channel, or lumens: see unit"})
    unit: str = field(default="candela", metadata={
        "choices": ("candela", "lumens"),
        "doc": "what intensity's luminance gives: candela on the axis, or lumens (the flux, all of it through "
               "the cone)"})
    cutoff_angle_deg: float = field(default=20.0, metadata={"range": (0.01, 180.0),
                                                            "doc": "no light beyond this angle from the axis"})
    beam_width_deg: float = field(default=15.0, metadata={"range": (0.0, 180.0),
                                                          "doc": "full intensity within this angle from the axis"})
    texture: Texture | None = field(default=None, metadata={"doc": "an image projected through the cone"})
    up: Vec3 = field(default=(0.0, 0.0, -1.0), metadata={
        "nonzero_vector": True, "doc": "where the projected texture's top edge points (only a texture shows it)"})

    def frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(right, top, axis): the orthonormal frame the texture is projected in. An ``up`` along the axis
        picks any perpendicular (no texture orientation is then implied)."""
        axis = _unit(self.direction, f"spot '{self.name}': direction")
        up = np.asarray(self.up, float)
        top = up - np.dot(up, axis) * axis
        if np.linalg.norm(top) < 1e-9 * max(np.linalg.norm(up), 1e-300):
            helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            top = helper - np.dot(helper, axis) * axis
        top = top / np.linalg.norm(top)
        return np.cross(axis, top), top, axis

    def cutoff_and_beam_rad(self) -> tuple[float, float]:
        cutoff = math.radians(self.cutoff_angle_deg)
        return cutoff, min(math.radians(self.beam_width_deg), cutoff)

    def falloff(self, cos_theta) -> np.ndarray:
        """Mitsuba's falloff_curve at cos(angle from the axis): 1 within the beam, (cutoff - angle) /
        (cutoff - beam) between, 0 from the cutoff on."""
        cos_theta = np.clip(np.asarray(cos_theta, float), -1.0, 1.0)
        cutoff, beam = self.cutoff_and_beam_rad()
        with np.errstate(divide="ignore", invalid="ignore"):
            ramp = (cutoff - np.arccos(cos_theta)) / (cutoff - beam)
        inside = np.where(cos_theta >= math.cos(beam), 1.0, ramp)
        return np.where(cos_theta > math.cos(cutoff), inside, 0.0)

    def weighted_solid_angle(self) -> float:
        """The falloff integrated over all directions (sr): the spot's power is this times its intensity.
        2 pi [(1 - cos b) + integral from b to c of (c - t)/(c - b) sin t dt] = 2 pi [1 - (sin c - sin b)/(c - b)]."""
        cutoff, beam = self.cutoff_and_beam_rad()
        if cutoff - beam < 1e-6:  # a hard edge: the plain cone
            return 2.0 * math.pi * (1.0 - math.cos(cutoff))
        return 2.0 * math.pi * (1.0 - (math.sin(cutoff) - math.sin(beam)) / (cutoff - beam))


def sun_size_problem(sun: SunLight) -> str:
    """The words for a sun whose angular diameter is neither 0 nor at least SMALLEST_SUN_DEG."""
    return (f"sun '{sun.name}': angular_diameter_deg {sun.angular_diameter_deg:g} is too small to be a disk: give 0 "
            f"(a point at infinity, sharp shadows) or at least {SMALLEST_SUN_DEG:g}")


def _unit(vector, what: str) -> np.ndarray:
    v = np.asarray(vector, float)
    n = float(np.linalg.norm(v))
    if n == 0 or not math.isfinite(n):
        raise ValueError(f"{what} must be a nonzero vector")
    return v / n


LIGHT_TYPES: dict[str, type[Light]] = {cls.type_name: cls for cls in (PointLight, SpotLight, SunLight)}
