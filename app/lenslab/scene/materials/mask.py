"""Mask: a cut-out. GLSL: glsl/material_mask.glsl (the cut itself happens during traversal: glsl/mask.glsl)."""

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
class Mask(Material):
    """A cut-out: where ``opacity`` is below 1 the surface is partly absent, and light passes straight
    through it (leaves, fences, a printed stencil; Mitsuba's mask). Rays pass with probability 1 - opacity,
    shadow rays included."""

    type_name: ClassVar[str] = "mask"
    material: Material = field(default_factory=Diffuse, metadata={"doc": "the surface where it is present"})
    opacity: float = field(default=0.5, metadata={"range": (0.0, 1.0), "doc": "1: solid, 0: absent"})
    opacity_texture: Texture | None = field(default=None, metadata={"doc": "overrides opacity (luminance) where given"})


def pack(material: Mask, record: np.ndarray, ctx: PackContext) -> None:
    """Row 0 (opacity, its texture, 0); row 2, x the record it holds."""
    record[0, 0] = material.opacity
    record[0, 1] = ctx.index_of(material.opacity_texture, data=True)
    record[0, 2] = 0.0


def holds(material: Mask) -> list[Material]:
    return [material.material]


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's mask: the BSDF it holds, cut by its opacity (a number, a colour or a texture)."""
    notes: list[str] = []
    opacity, texture = mp.scalar_or_texture(p, imp, "opacity", 0.5, notes)
    material = mp.held(p, imp, notes)
    return mp.Mapped(Mask(material=material, opacity=min(max(opacity, 0.0), 1.0), opacity_texture=texture),
                     mp.joined_notes(notes))


KIND = MaterialKind(Mask, "MATERIAL_MASK", pack, "material_mask.glsl", holds=holds, wrapper=True,
                    mitsuba_plugins=("mask",), from_mitsuba=from_mitsuba)
