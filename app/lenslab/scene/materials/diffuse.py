"""Diffuse: Lambertian reflection. GLSL: glsl/material_diffuse.glsl."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from lenslab.scene.io import mitsuba_props as mp
from lenslab.scene.materials.base import RGB, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind
from lenslab.scene.textures import Texture

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, Props


@dataclass
class Diffuse(Material):
    """Lambertian reflection: radiance scattered equally in every direction of the hemisphere."""

    type_name: ClassVar[str] = "diffuse"
    albedo: RGB = field(default=(0.8, 0.8, 0.8), metadata={"range": (0.0, 1.0), "doc": "reflectance per channel"})
    albedo_texture: Texture | None = field(default=None, metadata={"doc": "overrides albedo where given"})


def pack(material: Diffuse, record: np.ndarray, ctx: PackContext) -> None:
    """Row 0 the albedo, row 3, w its texture."""
    record[0, :3] = material.albedo
    record[3, 3] = ctx.index_of(material.albedo_texture)


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's diffuse, and its roughdiffuse (Oren-Nayar), rendered as Lambertian with a note."""
    if p.node.type == "roughdiffuse":
        p.float("alpha")
        albedo, texture = mp.reflectance(p, imp, "reflectance", 0.5)
        return mp.Mapped(Diffuse(albedo, albedo_texture=texture),
                         "rough diffuse (Oren-Nayar) is rendered as Lambertian")
    albedo, texture = mp.reflectance(p, imp, "reflectance", 0.5)
    return mp.Mapped(Diffuse(albedo, albedo_texture=texture))


KIND = MaterialKind(Diffuse, "MATERIAL_DIFFUSE", pack, "material_diffuse.glsl", glsl_prefix="diffuse",
                    mitsuba_plugins=("diffuse", "roughdiffuse"), from_mitsuba=from_mitsuba)
