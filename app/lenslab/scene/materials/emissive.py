"""Emissive: a light source, with an optional surface that reflects. GLSL: glsl/material_emissive.glsl."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from lenslab.scene.materials.base import RGB, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind


@dataclass
class Emissive(Material):
    """A light source: emits ``radiance`` from the front face (both faces if ``two_sided``). Its ``surface``
    says how it also reflects the light that falls on it (a lamp's white diffuser, Mitsuba's area light with a
    BSDF); none, the default, is a black surface that reflects nothing.

    ``unit`` says what ``radiance`` gives (scene/light_units.py): ``nits``, the default, the radiance itself
    (luminance in cd/m^2; a scene in arbitrary units, a Mitsuba import); ``lumens``, the light's colour scaled so
    that its luminance is the total flux of every shape carrying the material, which the renderer spreads over
    their world-space area (radiance = flux / (pi area), half that for a two-sided light)."""

    type_name: ClassVar[str] = "emissive"
    radiance: RGB = field(default=(1.0, 1.0, 1.0), metadata={
        "range": (0.0, 1e6), "doc": "cd/m^2 (nits) per channel, or lumens: see unit"})
    unit: str = field(default="nits", metadata={
        "choices": ("nits", "lumens"),
        "doc": "what radiance's luminance gives: nits (cd/m^2), or lumens (the total flux of the shapes carrying "
               "the material, spread over their area)"})
    two_sided: bool = field(default=False, metadata={"doc": "emit from the back face too"})
    surface: Material | None = field(default=None, metadata={"doc": "how the light's surface reflects; none: black"})

    @property
    def emits(self) -> bool:
        return max(self.radiance) > 0.0


def pack(material: Emissive, record: np.ndarray, ctx: PackContext) -> None:
    """Row 1 (radiance, two-sided); its surface's record index is row 2, x (-1: black). The radiance is in nits
    by now: flattening converted any other unit (scene/flatten.py)."""
    record[1, :3] = material.radiance
    record[1, 3] = 1.0 if material.two_sided else 0.0


def holds(material: Emissive) -> list[Material]:
    return [material.surface] if material.surface is not None else []


KIND = MaterialKind(Emissive, "MATERIAL_EMISSIVE", pack, "material_emissive.glsl", holds=holds)
