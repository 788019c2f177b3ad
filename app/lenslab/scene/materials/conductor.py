"""Conductor: a metal, smooth or rough. GLSL: glsl/material_conductor.glsl."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from lenslab.scene.materials.base import DISTRIBUTION_FIELD, RGB, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind
from lenslab.scene.textures import Texture

# Complex refractive indices (eta, k) of common metals at red, green and blue (about 650, 550 and 450 nm),
# from the measured spectra that pbrt and Mitsuba ship, reduced to RGB.
METALS: dict[str, tuple[RGB, RGB]] = {
    "gold": ((0.143, 0.374, 1.442), (3.983, 2.386, 1.603)),
    "silver": ((0.155, 0.117, 0.138), (4.828, 3.122, 2.147)),
    "copper": ((0.200, 0.924, 1.102), (3.912, 2.452, 2.142)),
    "aluminium": ((1.657, 0.880, 0.521), (9.224, 6.270, 4.837)),
}


@dataclass
class Conductor(Material):
    """A metal: Fresnel reflection with a complex index of refraction, smooth or GGX-rough."""

    type_name: ClassVar[str] = "conductor"
    metal: str = field(default="aluminium", metadata={"choices": (*METALS, "custom"), "doc": "preset, or custom eta/k"})
    eta: RGB = field(default=(1.657, 0.880, 0.521), metadata={"range": (0.0, 100.0), "doc": "used when metal is custom"})
    k: RGB = field(default=(9.224, 6.270, 4.837), metadata={"range": (0.0, 100.0), "doc": "used when metal is custom"})
    tint: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1.0), "doc": "scales the reflectance"})
    roughness: float = field(default=0.0, metadata={"range": (0.0, 1.0), "doc": "0 = polished mirror"})
    roughness_texture: Texture | None = None
    distribution: str = field(default="ggx", metadata=DISTRIBUTION_FIELD)

    def complex_ior(self) -> tuple[RGB, RGB]:
        return (self.eta, self.k) if self.metal == "custom" else METALS[self.metal]


def pack(material: Conductor, record: np.ndarray, ctx: PackContext) -> None:
    """Rows 2, 3 and 4: eta, k and tint; row 4, w the roughness texture."""
    record[4, 3] = ctx.index_of(material.roughness_texture)
    eta, k = material.complex_ior()
    record[2, :3], record[3, :3], record[4, :3] = eta, k, material.tint


KIND = MaterialKind(Conductor, "MATERIAL_CONDUCTOR", pack, "material_conductor.glsl", glsl_prefix="conductor")
