"""Blend: a mix of two materials, one picked per hit. GLSL: glsl/material_blend.glsl (the pick itself is in
glsl/bsdf.glsl's resolve_material)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from lenslab.scene.io import mitsuba_props as mp
from lenslab.scene.materials.base import Material, PackContext
from lenslab.scene.materials.conductor import Conductor
from lenslab.scene.materials.diffuse import Diffuse
from lenslab.scene.materials.spec import MaterialKind
from lenslab.scene.textures import Texture

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, Props


@dataclass
class Blend(Material):
    """A mix of two materials: ``first`` weighted by 1 - weight, ``second`` by ``weight`` (Mitsuba's
    blendbsdf). The renderer picks one of the two at each hit with those odds: unbiased, as pbrt-v4's mix."""

    type_name: ClassVar[str] = "blend"
    first: Material = field(default_factory=Diffuse, metadata={"doc": "weighted by 1 - weight"})
    second: Material = field(default_factory=lambda: Conductor(), metadata={"doc": "weighted by weight"})
    weight: float = field(default=0.5, metadata={"range": (0.0, 1.0), "doc": "share of the second material"})
    weight_texture: Texture | None = field(default=None, metadata={"doc": "overrides weight (luminance) where given"})


def pack(material: Blend, record: np.ndarray, ctx: PackContext) -> None:
    """Row 0 (weight, its texture, 0); row 2 the two records it holds."""
    record[0, 0] = material.weight
    record[0, 1] = ctx.index_of(material.weight_texture, data=True)
    record[0, 2] = 0.0


def holds(material: Blend) -> list[Material]:
    return [material.first, material.second]


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's blendbsdf: its two BSDFs, mixed by its weight (a number, a colour or a texture)."""
    from lenslab.scene.materials.mask import Mask
    from lenslab.scene.materials.registry import walk_materials  # the registry imports this module

    notes: list[str] = []
    weight, texture = mp.scalar_or_texture(p, imp, "weight", 0.5, notes)
    inner = mp.nested_bsdfs(p)
    if len(inner) != 2:
        raise p.node.error(f"blendbsdf needs two BSDFs, not {len(inner)}")
    first, second = (mp.noted_material(imp.map_bsdf(node), notes) for node in inner)
    if any(isinstance(held, Mask) for part in (first, second) for held in walk_materials(part)):
        notes.append("a mask inside a blend does not cut the surface in LensLab: it is solid there")
    return mp.Mapped(Blend(first=first, second=second, weight=min(max(weight, 0.0), 1.0), weight_texture=texture),
                     mp.joined_notes(notes))


KIND = MaterialKind(Blend, "MATERIAL_BLEND", pack, "material_blend.glsl", holds=holds, wrapper=True,
                    mitsuba_plugins=("blendbsdf",), from_mitsuba=from_mitsuba)
