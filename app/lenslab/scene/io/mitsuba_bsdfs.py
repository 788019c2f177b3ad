"""Mitsuba BSDFs onto LensLab materials: one mapping per Mitsuba plugin name, in :data:`BSDF_MAPPINGS`.

Each material kind's module holds the mappings onto that kind (``from_mitsuba``, for the plugins its
``KIND.mitsuba_plugins`` names, e.g. scene/materials/conductor.py for conductor and roughconductor), and the
table is made from the registry. What maps onto no one kind stays here: ``twosided`` (unwrapped to the BSDF it
holds) and ``principled`` / ``principledthin`` (approximated by a diffuse surface, with a note).

The mappings' contract (``Mapped``, what ``p`` and ``imp`` are, Mitsuba's defaults) and the property readers
they share are in :mod:`.mitsuba_props`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from lenslab.scene.materials import Diffuse
from lenslab.scene.materials.registry import KINDS

from .mitsuba_props import BsdfMapping, Mapped, clip_unit, joined_notes, nested_bsdfs, noted_material

if TYPE_CHECKING:
    from .mitsuba_xml import Props, MitsubaImporter

__all__ = ["BSDF_MAPPINGS", "BsdfMapping", "Mapped"]


def _grey_note(kind: str, what: str) -> str:
    return f"{kind} is not renderable yet: approximated by a diffuse surface with {what}"


def _map_principled(p: "Props", imp: "MitsubaImporter") -> Mapped:
    for key in list(p.values):
        if key != "base_color":
            p.take(key)
    albedo = clip_unit(p.color("base_color", 0.5))
    return Mapped(Diffuse(albedo), _grey_note(p.node.type, "its base colour"))


def _map_twosided(p: "Props", imp: "MitsubaImporter") -> Mapped:
    """Our surfaces look the same from both sides already: the front BSDF, unwrapped."""
    notes: list[str] = []
    inner = nested_bsdfs(p)
    if not inner:
        return Mapped(Diffuse((0.5, 0.5, 0.5)), "twosided holds no BSDF: Mitsuba's default diffuse used")
    material = noted_material(imp.map_bsdf(inner[0]), notes)
    if len(inner) > 1:
        notes.append("its back-side BSDF is dropped (LensLab surfaces look the same from both sides)")
    return Mapped(material, joined_notes(notes))


#: The plugins that map onto no one material kind.
UNWRAPPED_OR_APPROXIMATED: dict[str, BsdfMapping] = {
    "principled": _map_principled,
    "principledthin": _map_principled,
    "twosided": _map_twosided,
}


def _bsdf_mappings() -> dict[str, BsdfMapping]:
    table: dict[str, BsdfMapping] = {}
    for plugin, mapping in [(plugin, kind.from_mitsuba) for kind in KINDS for plugin in kind.mitsuba_plugins] + \
            list(UNWRAPPED_OR_APPROXIMATED.items()):
        if plugin in table:
            raise RuntimeError(f'Mitsuba plugin "{plugin}" is mapped twice')
        table[plugin] = mapping
    return table


BSDF_MAPPINGS: dict[str, BsdfMapping] = _bsdf_mappings()
"""Mitsuba BSDF plugin name -> mapping onto a LensLab material: the registered kinds' ``from_mitsuba`` (for
their ``mitsuba_plugins``), then :data:`UNWRAPPED_OR_APPROXIMATED`. Approximations return a ``note``."""
