"""ThinDielectric: a pane of glass too thin to model. GLSL: glsl/material_thin_dielectric.glsl."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from lenslab.scene.io import mitsuba_props as mp
from lenslab.scene.materials.base import RELATIVE_IOR_RANGE, RGB, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, Props


@dataclass
class ThinDielectric(Material):
    """A pane of glass too thin to model: reflects, and lets light through without bending it."""

    type_name: ClassVar[str] = "thin_dielectric"
    ior: float = field(default=1.5, metadata={"range": RELATIVE_IOR_RANGE})
    tint: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1.0)})


def pack(material: ThinDielectric, record: np.ndarray, ctx: PackContext) -> None:
    """Row 2, x the index of refraction, row 4 the tint."""
    record[2, 0] = material.ior
    record[4, :3] = material.tint


def from_mitsuba(p: "Props", imp: "MitsubaImporter") -> mp.Mapped:
    """Mitsuba's thindielectric."""
    notes: list[str] = []
    transmit = mp.transmittance_tint(p, notes)
    return mp.Mapped(ThinDielectric(ior=mp.relative_ior(p, notes, RELATIVE_IOR_RANGE), tint=transmit), mp.joined_notes(notes))


# Only a Dirac lobe: evaluation is never asked of it (glsl/bsdf.glsl's bsdf_is_delta), so it has no _eval.
KIND = MaterialKind(ThinDielectric, "MATERIAL_THIN_DIELECTRIC", pack, "material_thin_dielectric.glsl",
                    glsl_prefix="thin_dielectric", glsl_eval=False, mitsuba_plugins=("thindielectric",),
                    from_mitsuba=from_mitsuba)
