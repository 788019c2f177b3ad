"""NormalMap: a tangent-space normal map gives the shading normal of the material it holds. GLSL:
glsl/material_normal_map.glsl (the tilt is applied in glsl/bsdf.glsl's resolve_material)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from lenslab.scene.io import mitsuba_props as mp
from lenslab.scene.materials.base import Material, PackContext
from lenslab.scene.materials.diffuse import Diffuse
from lenslab.scene.materials.spec import MaterialKind
from lenslab.scene.textures import Texture

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, Props


@dataclass
class NormalMap(Material):
    """A tangent-space normal map (RGB = (n + 1) / 2, linear, +Z out of the surface, +X along u) gives the
    shading normal of ``material`` (Mitsuba's normalmap)."""

    type_name: ClassVar[str] = "normal_map"
    material: Material = field(default_factory=Diffuse)
    texture: Texture | None = field(default=None, metadata={"doc": "data: read as stored (color_space auto or raw)"})
    shadowing: bool = field(default=True, metadata={
        "doc": "soften the hard shadow line tilted normals leave (Estevez et al. 2019; Mitsuba's default)"})


def pack(material: NormalMap, record: np.ndarray, ctx: PackContext) -> None:
    """Row 0 (0, normal texture, shadowing); row 2, x the record it holds."""
    record[0, 0] = 0.0
    record[0, 1] = ctx.index_of(material.texture, data=True)
    record[0, 2] = float(material.shadowing)


def holds(material: NormalMap) -> list[Material]:
    return [material.material]


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's normalmap: the BSDF it holds, under its ``normalmap`` texture (flat, with a note, when LensLab
    cannot look the texture up)."""
    notes: list[str] = []
    node, texture = mp.texture_property(p, imp, "normalmap")
    shadowing = mp.tilt_options(p, notes)
    material = mp.held(p, imp, notes)
    if texture is None:
        notes.append(f"its texture at line {node.line} cannot be looked up: the normal map is flat")
    return mp.Mapped(NormalMap(material=material, texture=texture, shadowing=shadowing), mp.joined_notes(notes))


KIND = MaterialKind(NormalMap, "MATERIAL_NORMAL_MAP", pack, "material_normal_map.glsl", holds=holds, wrapper=True,
                    mitsuba_plugins=("normalmap",), from_mitsuba=from_mitsuba)
