"""Mitsuba BSDFs onto LensLab materials: one mapping per Mitsuba plugin name, in :data:`BSDF_MAPPINGS`.

A mapping receives the BSDF element's properties (``p``: ``p.color(name, default)``, ``p.float``,
``p.string``, ``p.take``, nested BSDFs in ``p.objects``; see ``mitsuba_xml.Props``) and the importer (``imp``,
whose ``imp.map_bsdf(node)`` maps a nested BSDF), and returns a :class:`Mapped`: the material, and a ``note``
when it is an approximation (the importer reports the note once per BSDF element, with its file and line).
Every property a mapping does not read is reported as unsupported, so read (``p.take``) what you
deliberately ignore.

Today only ``Diffuse`` and ``Emissive`` render, so conductors, plastics and glass are approximated by diffuse
surfaces; when their material classes land, replacing an entry of the table is the whole change.
Mitsuba's defaults (``src/bsdfs/*.cpp``): diffuse reflectance 0.5; conductor material "none" (a perfect
mirror); plastic diffuse_reflectance 0.5, int_ior 1.49; dielectric int_ior 1.5046 (bk7), ext_ior 1.000277.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

from lenslab.scene.materials import Diffuse, Material

from . import mitsuba_values as mv

if TYPE_CHECKING:
    from .mitsuba_xml import Props, _Importer

RGB = tuple[float, float, float]


@dataclass
class Mapped:
    """What a BSDF became; ``note`` (if any) says how it was approximated, and is reported as a warning."""

    material: Material
    note: str | None = None


BsdfMapping = Callable[["Props", "_Importer"], Mapped]


def _clip_albedo(rgb) -> RGB:
    return tuple(float(min(max(c, 0.0), 1.0)) for c in rgb)  # type: ignore[return-value]


def _grey_note(kind: str, what: str) -> str:
    return f"{kind} is not renderable yet: approximated by a diffuse surface with {what}"


def _map_diffuse(p: Props, imp: "_Importer") -> Mapped:
    return Mapped(Diffuse(_clip_albedo(p.color("reflectance", 0.5))))


def _map_roughdiffuse(p: Props, imp: "_Importer") -> Mapped:
    p.float("alpha")
    return Mapped(Diffuse(_clip_albedo(p.color("reflectance", 0.5))), "rough diffuse (Oren-Nayar) is rendered as Lambertian")


def _map_conductor(p: Props, imp: "_Importer") -> Mapped:
    for key in ("alpha", "alpha_u", "alpha_v", "distribution", "sample_visible"):
        p.take(key)
    if p.has("eta") or p.has("k"):
        eta, k = p.color("eta", 0.0), p.color("k", 1.0)
        f0, what = mv.conductor_f0(eta, k), "its normal-incidence reflectance (from eta, k)"
    else:
        name = p.string("material", "none")
        f0, what = mv.CONDUCTOR_F0.get(name, (0.9, 0.9, 0.9)), f'the normal-incidence reflectance of "{name}"'
    tint = p.color("specular_reflectance", 1.0)
    albedo = _clip_albedo(a * b for a, b in zip(f0, tint))
    return Mapped(Diffuse(albedo), _grey_note(p.node.type, what))


def _map_plastic(p: Props, imp: "_Importer") -> Mapped:
    for key in ("int_ior", "ext_ior", "alpha", "distribution", "nonlinear", "sample_visible", "specular_reflectance"):
        p.take(key)
    albedo = _clip_albedo(p.color("diffuse_reflectance", 0.5))
    return Mapped(Diffuse(albedo), _grey_note(p.node.type, "its diffuse reflectance (no specular coat)"))


def _map_dielectric(p: Props, imp: "_Importer") -> Mapped:
    for key in ("int_ior", "ext_ior", "alpha", "alpha_u", "alpha_v", "distribution", "sample_visible",
                "specular_reflectance"):
        p.take(key)
    tint = p.color("specular_transmittance", 1.0)
    albedo = _clip_albedo(0.8 * c for c in tint)
    return Mapped(Diffuse(albedo), _grey_note(p.node.type, "80% of its transmittance (no refraction)"))


def _map_principled(p: Props, imp: "_Importer") -> Mapped:
    for key in list(p.values):
        if key != "base_color":
            p.take(key)
    albedo = _clip_albedo(p.color("base_color", 0.5))
    return Mapped(Diffuse(albedo), _grey_note(p.node.type, "its base colour"))


def _map_wrapper(p: Props, imp: "_Importer") -> Mapped:
    """twosided, mask, bumpmap, normalmap, blendbsdf: the (first) nested BSDF, unwrapped."""
    kind = p.node.type
    for key in list(p.values):
        if p.values[key].tag != "bsdf":
            p.take(key)
    inner = [n for n in p.objects if n.tag == "bsdf"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "bsdf"]
    if not inner:
        return Mapped(Diffuse((0.5, 0.5, 0.5)), f"{kind} holds no BSDF: Mitsuba's default diffuse used")
    mapped = imp.map_bsdf(inner[0])
    notes = [mapped.note] if mapped.note else []
    if kind == "twosided":
        if len(inner) > 1:
            notes.append("its back-side BSDF is dropped (LensLab surfaces look the same from both sides)")
    elif kind == "mask":
        notes.append("the opacity mask is ignored")
    elif kind in ("bumpmap", "normalmap"):
        notes.append(f"the {kind} is ignored")
    elif kind == "blendbsdf":
        notes.append("only its first BSDF is used")
    return Mapped(mapped.material, "; ".join(notes) or None)


BSDF_MAPPINGS: dict[str, BsdfMapping] = {
    "diffuse": _map_diffuse,
    "roughdiffuse": _map_roughdiffuse,
    "conductor": _map_conductor,
    "roughconductor": _map_conductor,
    "plastic": _map_plastic,
    "roughplastic": _map_plastic,
    "dielectric": _map_dielectric,
    "roughdielectric": _map_dielectric,
    "thindielectric": _map_dielectric,
    "principled": _map_principled,
    "principledthin": _map_principled,
    "twosided": _map_wrapper,
    "mask": _map_wrapper,
    "bumpmap": _map_wrapper,
    "normalmap": _map_wrapper,
    "blendbsdf": _map_wrapper,
}
"""Mitsuba BSDF plugin name -> mapping onto a LensLab material. Approximations return a ``note``."""
