"""Mitsuba BSDFs onto LensLab materials: one mapping per Mitsuba plugin name, in :data:`BSDF_MAPPINGS`.

A mapping receives the BSDF element's properties (``p``: ``p.color(name, default)``, ``p.float``,
``p.string``, ``p.take``, nested BSDFs in ``p.objects``; see ``mitsuba_xml.Props``) and the importer (``imp``,
whose ``imp.map_bsdf(node)`` maps a nested BSDF), and returns a :class:`Mapped`: the material, and a ``note``
when it is an approximation (the importer reports the note once per BSDF element, with its file and line).
Every property a mapping does not read is reported as unsupported, so read (``p.take``) what you
deliberately ignore.

Mitsuba's defaults (``src/bsdfs/*.cpp``): diffuse reflectance 0.5; conductor material "none" (a perfect
mirror); plastic diffuse_reflectance 0.5, int_ior 1.49; dielectric int_ior 1.5046 (bk7), ext_ior 1.000277;
rough variants alpha 0.1 with the Beckmann distribution. Our microfacet alpha is roughness^2, so
``roughness = sqrt(alpha)``, and the distribution (Beckmann or GGX) is carried over.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

from lenslab.scene.materials import (Blend, BumpMap, Conductor, Dielectric, Diffuse, Mask, Material, NormalMap, Plastic,
                                     ThinDielectric, walk_materials)
from lenslab.scene.textures import Texture

from . import mitsuba_values as mv

if TYPE_CHECKING:
    from .mitsuba_xml import Props, MitsubaImporter

RGB = tuple[float, float, float]


@dataclass
class Mapped:
    """What a BSDF became; ``note`` (if any) says how it was approximated, and is reported as a warning."""

    material: Material
    note: str | None = None


BsdfMapping = Callable[["Props", "MitsubaImporter"], Mapped]


def _clip_albedo(rgb) -> RGB:
    return tuple(float(min(max(c, 0.0), 1.0)) for c in rgb)  # type: ignore[return-value]


def _grey_note(kind: str, what: str) -> str:
    return f"{kind} is not renderable yet: approximated by a diffuse surface with {what}"


def _reflectance(p: "Props", imp: "MitsubaImporter", name: str, default: float) -> tuple[RGB, Texture | None]:
    """A reflectance that may vary over the surface: (its colour, None), or, for a texture LensLab can look
    up (nested or referred to), (Mitsuba's default colour, which the texture overrides, the texture)."""
    node = p.values.get(name)
    if node is not None and node.tag == "texture":
        texture = imp.texture_of(node)
        if texture is not None:
            p.take(name)
            return (float(default),) * 3, texture  # type: ignore[return-value]
    return _clip_albedo(p.color(name, default)), None  # a colour, or a texture's mean (with a warning)


def _map_diffuse(p: "Props", imp: "MitsubaImporter") -> Mapped:
    albedo, texture = _reflectance(p, imp, "reflectance", 0.5)
    return Mapped(Diffuse(albedo, albedo_texture=texture))


def _map_roughdiffuse(p: "Props", imp: "MitsubaImporter") -> Mapped:
    p.float("alpha")
    albedo, texture = _reflectance(p, imp, "reflectance", 0.5)
    return Mapped(Diffuse(albedo, albedo_texture=texture), "rough diffuse (Oren-Nayar) is rendered as Lambertian")


# Mitsuba's named indices of refraction (include/mitsuba/render/ior.h).
NAMED_IOR: dict[str, float] = {
    "vacuum": 1.0, "helium": 1.000036, "hydrogen": 1.000132, "air": 1.000277, "carbon dioxide": 1.00045,
    "water": 1.3330, "acetone": 1.36, "ethanol": 1.361, "carbon tetrachloride": 1.461, "glycerol": 1.4729,
    "benzene": 1.501, "silicone oil": 1.52045, "bromine": 1.661, "water ice": 1.31, "fused quartz": 1.458,
    "pyrex": 1.470, "acrylic glass": 1.49, "polypropylene": 1.49, "bk7": 1.5046, "sodium chloride": 1.544,
    "amber": 1.55, "pet": 1.5750, "diamond": 2.419,
}

# Mitsuba's conductor names that are one of our metal presets (same measured data, reduced to RGB).
MITSUBA_METALS = {"Au": "gold", "Ag": "silver", "Cu": "copper", "Al": "aluminium"}


def _ior(p: "Props", name: str, default: float) -> float:
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
    except ValueError:
        raise node.error(f'could not parse "{text}" as a finite floating point value') from None
    if ior <= 0:
        raise node.error(f"an index of refraction must be positive, not {text}")
    return ior


def _roughness(p: "Props", notes: list[str]) -> tuple[float, str]:
    """Our perceptual roughness r from Mitsuba's microfacet alpha (ours is alpha = r^2), and the distribution.
    ``sample_visible`` only changes how Mitsuba samples, not what it renders: taken and left."""
    distribution = p.string("distribution", "beckmann").strip().lower()
    if distribution not in ("beckmann", "ggx"):
        raise p.node.error(f'unknown microfacet distribution "{distribution}" (expected beckmann or ggx)')
    p.take("sample_visible")
    if p.has("alpha_u") or p.has("alpha_v"):
        au, av = _alpha(p, "alpha_u", notes), _alpha(p, "alpha_v", notes)
        alpha = math.sqrt(au * av)
        if abs(au - av) > 1e-6:
            notes.append(f"anisotropic roughness ({au:g}, {av:g}) is rendered isotropic (alpha {alpha:.3g})")
    else:
        alpha = _alpha(p, "alpha", notes)
    if alpha > 1:
        notes.append(f"alpha {alpha:g} is rougher than LensLab allows: 1 used")
        alpha = 1.0
    return math.sqrt(max(alpha, 0.0)), distribution


def _alpha(p: "Props", name: str, notes: list[str]) -> float:
    node = p.values.get(name)
    if node is not None and node.tag not in ("float", "integer"):
        p.take(name)
        notes.append(f"a textured {name} is not supported: 0.1 used")
        return 0.1
    alpha = p.float(name, 0.1)
    if alpha < 0:
        raise node.error(f"{name} must not be negative, not {alpha:g}")
    return alpha


def _unit(rgb) -> RGB:
    return tuple(float(min(max(c, 0.0), 1.0)) for c in rgb)  # type: ignore[return-value]


def _note(notes: list[str]) -> str | None:
    return "; ".join(notes) or None


def _map_conductor(p: "Props", imp: "MitsubaImporter") -> Mapped:
    notes: list[str] = []
    rough = p.node.type == "roughconductor"
    roughness, distribution = _roughness(p, notes) if rough else (0.0, "ggx")
    tint = _unit(p.color("specular_reflectance", 1.0))
    if p.has("eta") or p.has("k"):
        if p.has("material"):
            p.take("material")
            notes.append("both material and eta/k given: eta/k used")
        eta, k = p.color("eta", 0.0), p.color("k", 1.0)
        material = Conductor(metal="custom", eta=_clip(eta, 0, 100), k=_clip(k, 0, 100), tint=tint, roughness=roughness,
                             distribution=distribution)
    else:
        name = p.string("material", "none")
        if name in MITSUBA_METALS:
            material = Conductor(metal=MITSUBA_METALS[name], tint=tint, roughness=roughness, distribution=distribution)
        elif name == "none":  # Mitsuba's default: a perfect mirror, which eta 0, k 1 gives at every angle
            material = Conductor(metal="custom", eta=(0.0, 0.0, 0.0), k=(1.0, 1.0, 1.0), tint=tint, roughness=roughness,
                                 distribution=distribution)
        elif name in mv.MITSUBA_CONDUCTOR_IORS:  # Mitsuba 3's own data: exact
            eta, k = mv.MITSUBA_CONDUCTOR_IORS[name]
            material = Conductor(metal="custom", eta=eta, k=k, tint=tint, roughness=roughness, distribution=distribution)
        else:
            f0 = mv.CONDUCTOR_F0.get(name)
            if f0 is None:
                raise p.node.error(f'unknown conductor material "{name}"')
            # eta 1 and k = 2 sqrt(F0 / (1 - F0)) reflect F0 at normal incidence
            k = tuple(min(2 * math.sqrt(f / (1 - f)), 100.0) for f in f0)
            material = Conductor(metal="custom", eta=(1.0, 1.0, 1.0), k=k, tint=tint, roughness=roughness,
                                 distribution=distribution)
            notes.append(f'"{name}" is not a LensLab metal preset: matched at normal incidence only')
    return Mapped(material, _note(notes))


def _clip(rgb, lo: float, hi: float) -> RGB:
    return tuple(float(min(max(c, lo), hi)) for c in rgb)  # type: ignore[return-value]


def _relative_ior(p: "Props", notes: list[str], lo: float) -> float:
    ior = _ior(p, "int_ior", 1.5046) / _ior(p, "ext_ior", 1.000277)
    if not lo <= ior <= 4.0:
        clamped = min(max(ior, lo), 4.0)
        notes.append(f"relative index of refraction {ior:.4g} is outside LensLab's {lo:g}-4: {clamped:g} used")
        ior = clamped
    return ior


def _map_plastic(p: "Props", imp: "MitsubaImporter") -> Mapped:
    notes: list[str] = []
    roughness, distribution = _roughness(p, notes) if p.node.type == "roughplastic" else (0.0, "ggx")
    albedo, texture = _reflectance(p, imp, "diffuse_reflectance", 0.5)
    ior = _ior(p, "int_ior", 1.49) / _ior(p, "ext_ior", 1.000277)
    if not 1.0 <= ior <= 4.0:
        notes.append(f"relative index of refraction {ior:.4g} is outside LensLab's 1-4: clamped")
        ior = min(max(ior, 1.0), 4.0)
    if p.color("specular_reflectance", 1.0) != (1.0, 1.0, 1.0):
        notes.append("specular_reflectance is not supported: the coat reflects as clear plastic")
    if p.bool("nonlinear", False):
        notes.append("nonlinear colour shift is not supported")
    # Mitsuba's roughplastic passes to its base only what refracts unshadowed (its eval_transmittance).
    return Mapped(Plastic(albedo=albedo, albedo_texture=texture, ior=ior, roughness=roughness, distribution=distribution,
                          coating="single_scattering"), _note(notes))


def _map_dielectric(p: "Props", imp: "MitsubaImporter") -> Mapped:
    notes: list[str] = []
    kind = p.node.type
    roughness, distribution = _roughness(p, notes) if kind == "roughdielectric" else (0.0, "ggx")
    transmit = _unit(p.color("specular_transmittance", 1.0))
    reflect = _unit(p.color("specular_reflectance", 1.0))
    if reflect != (1.0, 1.0, 1.0) and reflect != transmit:
        notes.append("a specular_reflectance unlike the transmittance is not supported: the transmittance tints both")
    if kind == "thindielectric":
        return Mapped(ThinDielectric(ior=_relative_ior(p, notes, 1.0001), tint=transmit), _note(notes))
    ior = _relative_ior(p, notes, 1.0001)
    return Mapped(Dielectric(ior=ior, roughness=roughness, distribution=distribution, tint=transmit), _note(notes))


def _map_principled(p: "Props", imp: "MitsubaImporter") -> Mapped:
    for key in list(p.values):
        if key != "base_color":
            p.take(key)
    albedo = _clip_albedo(p.color("base_color", 0.5))
    return Mapped(Diffuse(albedo), _grey_note(p.node.type, "its base colour"))


def _nested_bsdfs(p: "Props") -> list:
    """The BSDF elements a BSDF holds, named or not, in document order."""
    return [n for n in p.objects if n.tag == "bsdf"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "bsdf"]


def _held(p: "Props", imp: "MitsubaImporter", notes: list[str]) -> Material:
    """The one BSDF a wrapper holds, mapped (Mitsuba's default diffuse when it holds none)."""
    inner = _nested_bsdfs(p)
    if not inner:
        notes.append(f"{p.node.type} holds no BSDF: Mitsuba's default diffuse used")
        return Diffuse((0.5, 0.5, 0.5))
    for extra in inner[1:]:
        notes.append(f"{p.node.type} holds one BSDF: the one at line {extra.line} is ignored")
    return _mapped(imp.map_bsdf(inner[0]), notes)


def _mapped(mapped: Mapped, notes: list[str]) -> Material:
    if mapped.note:
        notes.append(mapped.note)
    return mapped.material


def _scalar_or_texture(p: "Props", imp: "MitsubaImporter", name: str, default: float,
                       notes: list[str]) -> tuple[float, Texture | None]:
    """A property Mitsuba reads with eval_1: a number, a colour (its luminance) or a texture (its luminance,
    looked up where the ray hits)."""
    node = p.values.get(name)
    if node is None or node.tag in ("float", "integer"):
        return p.float(name, default), None
    return _texture_or_mean(imp, p.take(name), notes)


def _texture_or_mean(imp: "MitsubaImporter", node, notes: list[str]) -> tuple[float, Texture | None]:
    """As Mitsuba's eval_1 reads it: a bitmap's luminance (the renderer's texture_value), a checkerboard with
    its colours swapped (texture_of's scalar form), a plain colour's channel mean."""
    if node.tag == "texture":
        texture = imp.texture_of(node, scalar=True)
        if texture is not None:
            return 0.0, texture
    r, g, b = imp.color_of(node)  # a colour, or a texture LensLab cannot look up (averaged, with a warning)
    return (r + g + b) / 3.0, None


def _texture_property(p: "Props", imp: "MitsubaImporter", name: str | None) -> tuple[object, Texture | None]:
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


def _map_twosided(p: "Props", imp: "MitsubaImporter") -> Mapped:
    """Our surfaces look the same from both sides already: the front BSDF, unwrapped."""
    notes: list[str] = []
    inner = _nested_bsdfs(p)
    if not inner:
        return Mapped(Diffuse((0.5, 0.5, 0.5)), "twosided holds no BSDF: Mitsuba's default diffuse used")
    material = _mapped(imp.map_bsdf(inner[0]), notes)
    if len(inner) > 1:
        notes.append("its back-side BSDF is dropped (LensLab surfaces look the same from both sides)")
    return Mapped(material, _note(notes))


def _map_mask(p: "Props", imp: "MitsubaImporter") -> Mapped:
    notes: list[str] = []
    opacity, texture = _scalar_or_texture(p, imp, "opacity", 0.5, notes)
    material = _held(p, imp, notes)
    return Mapped(Mask(material=material, opacity=min(max(opacity, 0.0), 1.0), opacity_texture=texture), _note(notes))


def _map_blendbsdf(p: "Props", imp: "MitsubaImporter") -> Mapped:
    notes: list[str] = []
    weight, texture = _scalar_or_texture(p, imp, "weight", 0.5, notes)
    inner = _nested_bsdfs(p)
    if len(inner) != 2:
        raise p.node.error(f"blendbsdf needs two BSDFs, not {len(inner)}")
    first, second = (_mapped(imp.map_bsdf(node), notes) for node in inner)
    if any(isinstance(held, Mask) for part in (first, second) for held in walk_materials(part)):
        notes.append("a mask inside a blend does not cut the surface in LensLab: it is solid there")
    return Mapped(Blend(first=first, second=second, weight=min(max(weight, 0.0), 1.0), weight_texture=texture),
                  _note(notes))


def _tilt_options(p: "Props", notes: list[str]) -> bool:
    """Mitsuba's bump and normal map switches: the shadowing term (kept), and flip_invalid_normals, which
    LensLab always does."""
    if not p.bool("flip_invalid_normals", True):
        notes.append("flip_invalid_normals false is not supported: tilted normals facing away are flipped")
    return p.bool("use_shadowing_function", True)


def _map_bumpmap(p: "Props", imp: "MitsubaImporter") -> Mapped:
    notes: list[str] = []
    scale = p.float("scale", 1.0)
    shadowing = _tilt_options(p, notes)
    node, texture = _texture_property(p, imp, None)
    material = _held(p, imp, notes)
    if texture is None:
        notes.append(f"its texture at line {node.line} cannot be looked up: the bump map is flat")
    return Mapped(BumpMap(material=material, texture=texture, scale=scale, shadowing=shadowing), _note(notes))


def _map_normalmap(p: "Props", imp: "MitsubaImporter") -> Mapped:
    notes: list[str] = []
    node, texture = _texture_property(p, imp, "normalmap")
    shadowing = _tilt_options(p, notes)
    material = _held(p, imp, notes)
    if texture is None:
        notes.append(f"its texture at line {node.line} cannot be looked up: the normal map is flat")
    return Mapped(NormalMap(material=material, texture=texture, shadowing=shadowing), _note(notes))


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
    "twosided": _map_twosided,
    "mask": _map_mask,
    "bumpmap": _map_bumpmap,
    "normalmap": _map_normalmap,
    "blendbsdf": _map_blendbsdf,
}
"""Mitsuba BSDF plugin name -> mapping onto a LensLab material. Approximations return a ``note``."""
