"""BumpMap: a height texture tilts the shading normal of the material it holds. GLSL:
glsl/material_bump_map.glsl (the tilt is applied in glsl/bsdf.glsl's resolve_material)."""

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
class BumpMap(Material):
    """Relief without geometry: a height texture tilts the shading normal of ``material`` (Mitsuba's bumpmap:
    the surface is displaced by ``scale`` times the texture's luminance along its normal)."""

    type_name: ClassVar[str] = "bump_map"
    material: Material = field(default_factory=Diffuse)
    texture: Texture | None = field(default=None, metadata={"doc": "height, as luminance"})
    scale: float = field(default=1.0, metadata={"range": (-1e3, 1e3), "doc": "height per unit of texture value"})
    shadowing: bool = field(default=True, metadata={
        "doc": "soften the hard shadow line tilted normals leave (Estevez et al. 2019; Mitsuba's default)"})


def pack(material: BumpMap, record: np.ndarray, ctx: PackContext) -> None:
    """Row 0 (scale, height texture, shadowing); row 2, x the record it holds."""
    record[0, 0] = material.scale
    record[0, 1] = ctx.index_of(material.texture, data=True)
    record[0, 2] = float(material.shadowing)


def holds(material: BumpMap) -> list[Material]:
    return [material.material]


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's bumpmap: the BSDF it holds, under its height texture (flat, with a note, when LensLab cannot
    look the texture up)."""
    notes: list[str] = []
    scale = p.float("scale", 1.0)
    shadowing = mp.tilt_options(p, notes)
    node, texture = mp.texture_property(p, imp, None)
    material = mp.held(p, imp, notes)
    if texture is None:
        notes.append(f"its texture at line {node.line} cannot be looked up: the bump map is flat")
    return mp.Mapped(BumpMap(material=material, texture=texture, scale=scale, shadowing=shadowing),
                     mp.joined_notes(notes))


KIND = MaterialKind(BumpMap, "MATERIAL_BUMP_MAP", pack, "material_bump_map.glsl", holds=holds, wrapper=True,
                    mitsuba_plugins=("bumpmap",), from_mitsuba=from_mitsuba)
