"""Dielectric: glass and water, smooth or rough, with absorption inside. GLSL: glsl/material_dielectric.glsl."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from lenslab.scene.io import mitsuba_props as mp
from lenslab.scene.materials.base import RELATIVE_IOR_RANGE, DISTRIBUTION_FIELD, RGB, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, Props


@dataclass
class Dielectric(Material):
    """Glass and water: Fresnel reflection and Snell refraction, smooth or rough, with Beer-Lambert absorption.

    Absorption is given the way an artist sees it (Bouguer's law): light that travels ``absorption_distance_m``
    through the material keeps ``absorption_color`` of itself; white means clear.
    """

    type_name: ClassVar[str] = "dielectric"
    ior: float = field(default=1.5, metadata={"range": RELATIVE_IOR_RANGE, "doc": (
        "index of refraction inside over outside; below 1 for a bubble (air in water: 0.75)")})
    roughness: float = field(default=0.0, metadata={"range": (0.0, 1.0)})
    distribution: str = field(default="ggx", metadata=DISTRIBUTION_FIELD)
    tint: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1.0), "doc": "scales reflection and transmission"})
    absorption_color: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (1e-6, 1.0)})
    absorption_distance_m: float = field(default=0.1, metadata={"range": (1e-6, 1e6)})

    def absorption_coefficient(self) -> RGB:
        """sigma_a per metre, from exp(-sigma_a d) = colour."""
        return tuple(-math.log(c) / self.absorption_distance_m for c in self.absorption_color)


def pack(material: Dielectric, record: np.ndarray, ctx: PackContext) -> None:
    """Row 2, x the index of refraction, row 4 the tint, row 5 the absorption per metre."""
    record[2, 0] = material.ior
    record[4, :3] = material.tint
    record[5, :3] = material.absorption_coefficient()


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's dielectric and roughdielectric (its thindielectric is a ThinDielectric)."""
    notes: list[str] = []
    kind = p.node.type
    roughness, distribution = mp.roughness(p, notes) if kind == "roughdielectric" else (0.0, "ggx")
    transmit = mp.transmittance_tint(p, notes)
    ior = mp.relative_ior(p, notes, RELATIVE_IOR_RANGE)
    return mp.Mapped(Dielectric(ior=ior, roughness=roughness, distribution=distribution, tint=transmit),
                     mp.joined_notes(notes))


KIND = MaterialKind(Dielectric, "MATERIAL_DIELECTRIC", pack, "material_dielectric.glsl", glsl_prefix="dielectric",
                    mitsuba_plugins=("dielectric", "roughdielectric"), from_mitsuba=from_mitsuba)
