"""Lights that are not shapes: a point light and the sun. (An emissive material turns any shape into an
area light; the sky is the scene's environment.)"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

RGB = tuple[float, float, float]
Vec3 = tuple[float, float, float]


@dataclass
class Light:
    type_name: ClassVar[str] = ""
    name: str = field(default="light", metadata={"required": True})


@dataclass
class PointLight(Light):
    """Light from a single point, equally in all directions: ``intensity`` in W/sr per channel."""

    type_name: ClassVar[str] = "point"
    position: Vec3 = (0.0, 2.0, 0.0)
    intensity: RGB = field(default=(10.0, 10.0, 10.0), metadata={"range": (0.0, 1e9)})


@dataclass
class SunLight(Light):
    """A distant disk of light: ``irradiance`` (W/m^2 on a surface facing it) arriving from ``direction``
    (pointing towards the sun) over a cone of ``angular_diameter_deg`` (0.53 for our sun; 0 for a point at
    infinity, whose shadows are razor sharp)."""

    type_name: ClassVar[str] = "sun"
    direction: Vec3 = field(default=(0.3, 1.0, 0.2), metadata={"nonzero_vector": True})
    irradiance: RGB = field(default=(3.0, 3.0, 3.0), metadata={"range": (0.0, 1e9)})
    angular_diameter_deg: float = field(default=0.53, metadata={"range": (0.0, 30.0)})

    def unit_direction(self) -> tuple[float, float, float]:
        n = math.sqrt(sum(c * c for c in self.direction))
        if n == 0:
            raise ValueError(f"sun '{self.name}': direction must not be zero")
        return tuple(c / n for c in self.direction)

    def radiance(self) -> RGB:
        """Radiance of the disk: irradiance over the cosine-weighted solid angle pi sin^2(theta_max)."""
        theta = math.radians(self.angular_diameter_deg) / 2
        if theta == 0:
            return self.irradiance  # a delta light: the irradiance itself is what is carried
        return tuple(e / (math.pi * math.sin(theta) ** 2) for e in self.irradiance)


LIGHT_TYPES: dict[str, type[Light]] = {cls.type_name: cls for cls in (PointLight, SunLight)}
