"""Conductor: a metal, smooth or rough. GLSL: glsl/material_conductor.glsl."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from lenslab.scene.io import mitsuba_props as mp
from lenslab.scene.io import mitsuba_values as mv
from lenslab.scene.materials.base import DISTRIBUTION_FIELD, RGB, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind
from lenslab.scene.textures import Texture

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, Props

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
    record[4, 3] = ctx.index_of(material.roughness_texture, data=True)
    eta, k = material.complex_ior()
    record[2, :3], record[3, :3], record[4, :3] = eta, k, material.tint


# Mitsuba's conductor names that are one of our metal presets (same measured data, reduced to RGB).
MITSUBA_METALS = {"Au": "gold", "Ag": "silver", "Cu": "copper", "Al": "aluminium"}


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's conductor and roughconductor: a preset metal, Mitsuba's own measured data, eta and k as
    given, or a metal matched at normal incidence (with a note)."""
    notes: list[str] = []
    rough = p.node.type == "roughconductor"
    roughness, distribution = mp.roughness(p, notes) if rough else (0.0, "ggx")
    tint = mp.clip_unit(p.color("specular_reflectance", 1.0))
    if p.has("eta") or p.has("k"):
        if p.has("material"):
            p.take("material")
            notes.append("both material and eta/k given: eta/k used")
        eta, k = p.color("eta", 0.0), p.color("k", 1.0)
        material = Conductor(metal="custom", eta=mp.clip_rgb(eta, 0, 100), k=mp.clip_rgb(k, 0, 100), tint=tint,
                             roughness=roughness, distribution=distribution)
    else:
        name = p.string("material", "none")
        if name in MITSUBA_METALS:
            material = Conductor(metal=MITSUBA_METALS[name], tint=tint, roughness=roughness, distribution=distribution)
        elif name == "none":  # Mitsuba's default: a perfect mirror, which eta 0, k 1 gives at every angle
            material = Conductor(metal="custom", eta=(0.0, 0.0, 0.0), k=(1.0, 1.0, 1.0), tint=tint, roughness=roughness,
                                 distribution=distribution)
        elif name in mv.MITSUBA_CONDUCTOR_IORS:  # Mitsuba 3's own data: exact
            eta, k = mv.MITSUBA_CONDUCTOR_IORS[name]
            material = Conductor(metal="custom", eta=eta, k=k, tint=tint, roughness=roughness, distribution=distribution)
        else:
            f0 = mv.CONDUCTOR_F0.get(name)
            if f0 is None:
                raise p.node.error(f'unknown conductor material "{name}"')
            # eta 1 and k = 2 sqrt(F0 / (1 - F0)) reflect F0 at normal incidence
            k = tuple(min(2 * math.sqrt(f / (1 - f)), 100.0) for f in f0)
            material = Conductor(metal="custom", eta=(1.0, 1.0, 1.0), k=k, tint=tint, roughness=roughness,
                                 distribution=distribution)
            notes.append(f'"{name}" is not a LensLab metal preset: matched at normal incidence only')
    return mp.Mapped(material, mp.joined_notes(notes))


KIND = MaterialKind(Conductor, "MATERIAL_CONDUCTOR", pack, "material_conductor.glsl", glsl_prefix="conductor",
                    mitsuba_plugins=("conductor", "roughconductor"), from_mitsuba=from_mitsuba)
