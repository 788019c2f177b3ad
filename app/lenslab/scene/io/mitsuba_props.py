"""What every Mitsuba BSDF mapping shares: :class:`Mapped` (what a mapping returns) and the readers of a BSDF
element's properties (roughness, index of refraction, reflectance, the BSDFs a wrapper holds, ...).

A mapping is a material kind's ``from_mitsuba`` (``scene/materials/<kind>.py``, named by the kind's
``mitsuba_plugins``), or one of the few in ``mitsuba_bsdfs.py`` that map onto no one kind. It receives the BSDF
element's properties (``p``: ``p.color(name, default)``, ``p.float``, ``p.string``, ``p.take``, nested BSDFs in
``p.objects``; see ``mitsuba_xml.Props``) and the importer (``imp``, whose ``imp.map_bsdf(node)`` maps a nested
BSDF), and returns a :class:`Mapped`: the material, and a ``note`` when it is an approximation (the importer
reports the note once per BSDF element, with its file and line). Every property a mapping does not read is
reported as unsupported, so read (``p.take``) what you deliberately ignore.

Mitsuba's defaults (``src/bsdfs/*.cpp``): diffuse reflectance 0.5; conductor material "none" (a perfect
mirror); plastic diffuse_reflectance 0.5, int_ior 1.49; dielectric int_ior 1.5046 (bk7), ext_ior 1.000277;
rough variants alpha 0.1 with the Beckmann distribution. Our microfacet alpha is roughness^2, so
``roughness = sqrt(alpha)``, and the distribution (Beckmann or GGX) is carried over.

This module imports no material at import time (the material modules import it): what it makes, it imports
where it makes it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

from . import mitsuba_values as mv

if TYPE_CHECKING:
    from lenslab.scene.materials.base import Material
    from lenslab.scene.textures import Texture

    from .mitsuba_xml import Props, MitsubaImporter

RGB = tuple[float, float, float]


@dataclass
class Mapped:
    """What a BSDF became; ``note`` (if any) says how it was approximated, and is reported as a warning."""

    material: Material
    note: str | None = None


BsdfMapping = Callable[["Props", "MitsubaImporter"], Mapped]


# -- Colours and notes ----------------------------------------------------------------------------------------
def clip_unit(rgb) -> RGB:
    """A colour (an albedo, a tint) clipped to [0, 1] per channel."""
    return tuple(float(min(max(c, 0.0), 1.0)) for c in rgb)  # type: ignore[return-value]


def clip_rgb(rgb, lo: float, hi: float) -> RGB:
    """A colour clipped to [lo, hi] per channel."""
    return tuple(float(min(max(c, lo), hi)) for c in rgb)  # type: ignore[return-value]


def joined_notes(notes: list[str]) -> str | None:
    """A mapping's notes as its one ``Mapped.note`` (None when there are none)."""
    return "; ".join(notes) or None


def reflectance(p: "Props", imp: "MitsubaImporter", name: str, default: float) -> tuple[RGB, Texture | None]:
    """A reflectance that may vary over the surface: (its colour, None), or, for a texture LensLab can look
    up (nested or referred to), (Mitsuba's default colour, which the texture overrides, the texture)."""
    node = p.values.get(name)
    if node is not None and node.tag == "texture":
        texture = imp.texture_of(node)
        if texture is not None:
            p.take(name)
            return (float(default),) * 3, texture  # type: ignore[return-value]
    return clip_unit(p.color(name, default)), None  # a colour, or a texture's mean (with a warning)


def transmittance_tint(p: "Props", notes: list[str]) -> RGB:
    """A dielectric's tint: its ``specular_transmittance``, which tints reflection too (noted when its
    ``specular_reflectance`` differs)."""
    transmit = clip_unit(p.color("specular_transmittance", 1.0))
    reflect = clip_unit(p.color("specular_reflectance", 1.0))
    if reflect != (1.0, 1.0, 1.0) and reflect != transmit:
        notes.append("a specular_reflectance unlike the transmittance is not supported: the transmittance tints both")
    return transmit


# -- Indices of refraction ------------------------------------------------------------------------------------
# Mitsuba's named indices of refraction (include/mitsuba/render/ior.h).
NAMED_IOR: dict[str, float] = {
    "vacuum": 1.0, "helium": 1.000036, "hydrogen": 1.000132, "air": 1.000277, "carbon dioxide": 1.00045,
    "water": 1.3330, "acetone": 1.36, "ethanol": 1.361, "carbon tetrachloride": 1.461, "glycerol": 1.4729,
    "benzene": 1.501, "silicone oil": 1.52045, "bromine": 1.661, "water ice": 1.31, "fused quartz": 1.458,
    "pyrex": 1.470, "acrylic glass": 1.49, "polypropylene": 1.49, "bk7": 1.5046, "sodium chloride": 1.544,
    "amber": 1.55, "pet": 1.5750, "diamond": 2.419,
}


def ior_value(p: "Props", name: str, default: float) -> float:
    """An index of refraction: a positive number, or one of Mitsuba's names (:data:`NAMED_IOR`)."""
    node = p.take(name)
    if node is None:
        return default
    if node.tag == "string":
        key = node.attrs.get("value", "").strip().lower()
        if key not in NAMED_IOR:
            raise node.error(f'unknown index of refraction "{key}" (expected a number or one of {", ".join(NAMED_IOR)})')
        return NAMED_IOR[key]
    if node.tag not in ("float", "integer"):
        raise node.error("expected a <float> or a named <string> index of refraction")
    text = node.attrs.get("value", "")
    try:
        ior = mv.parse_number(text)
    except mv.NumberTooLarge as exc:
        raise node.error(str(exc)) from None
    except ValueError:
        raise node.error(f'could not parse "{text}" as a finite floating point value') from None
    if ior <= 0:
        raise node.error(f"an index of refraction must be positive, not {text}")
    return ior


#: Within this of 1 a boundary is index-matched: it bends nothing, and a rough one's half vector is undefined.
INDEX_MATCHED = 1e-4


def relative_ior(p: "Props", notes: list[str], bounds: tuple[float, float]) -> float:
    """A dielectric's int_ior / ext_ior (Mitsuba's defaults: bk7 in air) as it is, less than 1 included; outside
    ``bounds`` (the material's range), or index-matched, the nearest index LensLab draws, with a note."""
    lo, hi = bounds
    ior = ior_value(p, "int_ior", 1.5046) / ior_value(p, "ext_ior", 1.000277)
    if abs(ior - 1.0) < INDEX_MATCHED:
        notes.append(f"relative index of refraction {ior:.6g} is index-matched (no boundary to draw): "
                     f"{1.0 + INDEX_MATCHED:g} used")
        return 1.0 + INDEX_MATCHED
    if not lo <= ior <= hi:
        clamped = min(max(ior, lo), hi)
        notes.append(f"relative index of refraction {ior:.4g} is outside LensLab's {lo:g}-{hi:g}: {clamped:g} used")
        ior = clamped
    return ior


# -- Roughness ------------------------------------------------------------------------------------------------
def roughness(p: "Props", notes: list[str]) -> tuple[float, str]:
    """Our perceptual roughness r from Mitsuba's microfacet alpha (ours is alpha = r^2), and the distribution.
    ``sample_visible`` only changes how Mitsuba samples, not what it renders: taken and left."""
    distribution = p.string("distribution", "beckmann").strip().lower()
    if distribution not in ("beckmann", "ggx"):
        raise p.node.error(f'unknown microfacet distribution "{distribution}" (expected beckmann or ggx)')
    p.take("sample_visible")
    if p.has("alpha_u") or p.has("alpha_v"):
        au, av = alpha_value(p, "alpha_u", notes), alpha_value(p, "alpha_v", notes)
        alpha = math.sqrt(au * av)
        if abs(au - av) > 1e-6:
            notes.append(f"anisotropic roughness ({au:g}, {av:g}) is rendered isotropic (alpha {alpha:.3g})")
    else:
        alpha = alpha_value(p, "alpha", notes)
    if alpha > 1:
        notes.append(f"alpha {alpha:g} is rougher than LensLab allows: 1 used")
        alpha = 1.0
    return math.sqrt(max(alpha, 0.0)), distribution


def alpha_value(p: "Props", name: str, notes: list[str]) -> float:
    """One of Mitsuba's microfacet alphas (default 0.1); a textured one is noted and 0.1 used."""
    node = p.values.get(name)
    if node is not None and node.tag not in ("float", "integer"):
        p.take(name)
        notes.append(f"a textured {name} is not supported: 0.1 used")
        return 0.1
    alpha = p.float(name, 0.1)
    if alpha < 0:
        raise node.error(f"{name} must not be negative, not {alpha:g}")
    return alpha


# -- BSDFs that hold BSDFs ------------------------------------------------------------------------------------
def nested_bsdfs(p: "Props") -> list:
    """The BSDF elements a BSDF holds, named or not, in document order."""
    return [n for n in p.objects if n.tag == "bsdf"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "bsdf"]


def held(p: "Props", imp: "MitsubaImporter", notes: list[str]) -> Material:
    """The one BSDF a wrapper holds, mapped (Mitsuba's default diffuse when it holds none)."""
    from lenslab.scene.materials.diffuse import Diffuse

    inner = nested_bsdfs(p)
    if not inner:
        notes.append(f"{p.node.type} holds no BSDF: Mitsuba's default diffuse used")
        return Diffuse((0.5, 0.5, 0.5))
    for extra in inner[1:]:
        notes.append(f"{p.node.type} holds one BSDF: the one at line {extra.line} is ignored")
    return noted_material(imp.map_bsdf(inner[0]), notes)


def noted_material(mapped: Mapped, notes: list[str]) -> Material:
    """A nested BSDF's material, its note (if any) added to the holder's notes."""
    if mapped.note:
        notes.append(mapped.note)
    return mapped.material


# -- Textured parameters --------------------------------------------------------------------------------------
def scalar_or_texture(p: "Props", imp: "MitsubaImporter", name: str, default: float,
                      notes: list[str]) -> tuple[float, Texture | None]:
    """A property Mitsuba reads with eval_1: a number, a colour (its luminance) or a texture (its luminance,
    looked up where the ray hits)."""
    node = p.values.get(name)
    if node is None or node.tag in ("float", "integer"):
        return p.float(name, default), None
    return texture_or_mean(imp, p.take(name), notes)


def texture_or_mean(imp: "MitsubaImporter", node, notes: list[str]) -> tuple[float, Texture | None]:
    """As Mitsuba's eval_1 reads it: a bitmap's luminance (the renderer's texture_value), a checkerboard with
    its colours swapped (texture_of's scalar form), a plain colour's channel mean."""
    if node.tag == "texture":
        texture = imp.texture_of(node, scalar=True)
        if texture is not None:
            return 0.0, texture
    r, g, b = imp.color_of(node)  # a colour, or a texture LensLab cannot look up (averaged, with a warning)
    return (r + g + b) / 3.0, None


def texture_property(p: "Props", imp: "MitsubaImporter", name: str | None) -> tuple[object, Texture | None]:
    """The texture a bumpmap (unnamed, or any name) or normalmap (``normalmap``) holds, and its element."""
    if name is not None:
        node = p.take(name)
        candidates = [node] if node is not None else []
    else:
        candidates = [n for n in p.objects if n.tag == "texture"]
        candidates += [p.take(k) for k in list(p.values) if p.values[k].tag == "texture"]
    if not candidates:
        raise p.node.error(f"{p.node.type} needs a <texture>")
    node = candidates[0]
    return node, imp.texture_of(node) if node.tag == "texture" else None


def tilt_options(p: "Props", notes: list[str]) -> bool:
    """Mitsuba's bump and normal map switches: the shadowing term (kept), and flip_invalid_normals, which
    LensLab always does."""
    if not p.bool("flip_invalid_normals", True):
        notes.append("flip_invalid_normals false is not supported: tilted normals facing away are flipped")
    return p.bool("use_shadowing_function", True)
