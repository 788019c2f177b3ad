"""Plastic: a diffuse base under a smooth or rough dielectric coating. GLSL: glsl/material_plastic.glsl."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from lenslab.scene.io import mitsuba_props as mp
from lenslab.scene.materials.base import DISTRIBUTION_FIELD, COATINGS, RGB, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind
from lenslab.scene.textures import Texture

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, Props


@dataclass
class Plastic(Material):
    """A diffuse base under a smooth or rough dielectric coating (Mitsuba's plastic and roughplastic)."""

    type_name: ClassVar[str] = "plastic"
    albedo: RGB = field(default=(0.5, 0.5, 0.5), metadata={"range": (0.0, 1.0), "doc": "colour of the base"})
    albedo_texture: Texture | None = None
    ior: float = field(default=1.49, metadata={"range": (1.0, 4.0), "doc": "index of refraction of the coating"})
    roughness: float = field(default=0.0, metadata={"range": (0.0, 1.0)})
    roughness_texture: Texture | None = None
    distribution: str = field(default="ggx", metadata=DISTRIBUTION_FIELD)
    coating: str = field(default="energy_conserving", metadata={
        "choices": COATINGS,
        "doc": "how much light a rough coating lets through to the base: all it does not reflect "
               "(energy_conserving), or only what refracts unshadowed by its microfacets (single_scattering: "
               "Mitsuba's roughplastic, darker when very rough)"})


def pack(material: Plastic, record: np.ndarray, ctx: PackContext) -> None:
    """Row 0 the albedo (row 3, w its texture), row 4, w the roughness texture; row 2 the coating's index, its
    internal diffuse reflectance and, when rough, the offset of its transmittance table in image_data."""
    record[0, :3] = material.albedo
    record[3, 3] = ctx.index_of(material.albedo_texture)
    record[4, 3] = ctx.index_of(material.roughness_texture, data=True)
    fresnel = ctx.fresnel
    alpha = float(record[2, 3])
    record[2, 0] = material.ior
    if alpha > 0:
        # A rough coating lets through a different share than Fresnel alone says: tabulate it, so the
        # diffuse base gets exactly what the coating lets through (Plastic.coating says which share).
        distribution = material.distribution
        record[2, 1] = fresnel.rough_internal_reflectance(material.ior, alpha, distribution)
        if material.coating == "single_scattering":
            through = fresnel.rough_transmittance_table(material.ior, alpha, distribution)
        else:
            through = 1.0 - fresnel.rough_reflectance_table(material.ior, alpha, distribution)
        table = ctx.add_floats(through.astype(np.float32))
        record[2, 2] = np.int32(table).view(np.float32)
    else:
        record[2, 1] = fresnel.internal_diffuse_reflectance(material.ior)


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's plastic and roughplastic (its coating passes on what refracts unshadowed)."""
    notes: list[str] = []
    roughness, distribution = mp.roughness(p, notes) if p.node.type == "roughplastic" else (0.0, "ggx")
    albedo, texture = mp.reflectance(p, imp, "diffuse_reflectance", 0.5)
    ior = mp.ior_value(p, "int_ior", 1.49) / mp.ior_value(p, "ext_ior", 1.000277)
    if not 1.0 <= ior <= 4.0:
        notes.append(f"relative index of refraction {ior:.4g} is outside LensLab's 1-4: clamped")
        ior = min(max(ior, 1.0), 4.0)
    if p.color("specular_reflectance", 1.0) != (1.0, 1.0, 1.0):
        notes.append("specular_reflectance is not supported: the coat reflects as clear plastic")
    if p.bool("nonlinear", False):
        notes.append("nonlinear colour shift is not supported")
    # Mitsuba's roughplastic passes to its base only what refracts unshadowed (its eval_transmittance).
    return mp.Mapped(Plastic(albedo=albedo, albedo_texture=texture, ior=ior, roughness=roughness,
                             distribution=distribution, coating="single_scattering"), mp.joined_notes(notes))


KIND = MaterialKind(Plastic, "MATERIAL_PLASTIC", pack, "material_plastic.glsl", glsl_prefix="plastic",
                    mitsuba_plugins=("plastic", "roughplastic"), from_mitsuba=from_mitsuba)
