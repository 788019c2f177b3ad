"""Materials: how a surface scatters or emits light.

Each material is a small dataclass registered under the ``type`` name that the scene file uses. The renderer
packs each type into its own GPU record (``lenslab.render.buffers``); adding a material means adding a class
here, a packer there and a branch in ``glsl/bsdf.glsl``.

Roughness is the artist's "perceptual" roughness r in [0, 1]; the microfacet width is alpha = r^2 (as in
Disney's and glTF's conventions). Zero means a perfectly smooth surface (a mirror-like delta lobe). The
microfacet distribution is GGX by default, or Beckmann (Mitsuba's default for its rough BSDFs).

Some materials hold other materials (docs/scene-format.md, "Materials that hold materials"): a light whose
surface also reflects (``Emissive.surface``), a blend of two, a cut-out (``Mask``), and bump and normal maps
that tilt the shading normal of the material they hold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

from lenslab.scene.textures import Texture

RGB = tuple[float, float, float]

MICROFACET_DISTRIBUTIONS = ("ggx", "beckmann")
COATINGS = ("energy_conserving", "single_scattering")  # Plastic.coating
_DISTRIBUTION = {"choices": MICROFACET_DISTRIBUTIONS,
                 "doc": "microfacet distribution of a rough surface: GGX (long tails) or Beckmann"}

# Complex refractive indices (eta, k) of common metals at red, green and blue (about 650, 550 and 450 nm),
# from the measured spectra that pbrt and Mitsuba ship, reduced to RGB.
METALS: dict[str, tuple[RGB, RGB]] = {
    "gold": ((0.143, 0.374, 1.442), (3.983, 2.386, 1.603)),
    "silver": ((0.155, 0.117, 0.138), (4.828, 3.122, 2.147)),
    "copper": ((0.200, 0.924, 1.102), (3.912, 2.452, 2.142)),
    "aluminium": ((1.657, 0.880, 0.521), (9.224, 6.270, 4.837)),
}


@dataclass
class Material:
    type_name: ClassVar[str] = ""

    @property
    def emits(self) -> bool:
        return False


@dataclass
class Diffuse(Material):
    """Lambertian reflection: radiance scattered equally in every direction of the hemisphere."""

    type_name: ClassVar[str] = "diffuse"
    albedo: RGB = field(default=(0.8, 0.8, 0.8), metadata={"range": (0.0, 1.0), "doc": "reflectance per channel"})
    albedo_texture: Texture | None = field(default=None, metadata={"doc": "overrides albedo where given"})


@dataclass
class Emissive(Material):
    """A light source: emits ``radiance`` from the front face (both faces if ``two_sided``). Its ``surface``
    says how it also reflects the light that falls on it (a lamp's white diffuser, Mitsuba's area light with a
    BSDF); none, the default, is a black surface that reflects nothing."""

    type_name: ClassVar[str] = "emissive"
    radiance: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1e6), "doc": "W/(m^2 sr) per channel"})
    two_sided: bool = field(default=False, metadata={"doc": "emit from the back face too"})
    surface: Material | None = field(default=None, metadata={"doc": "how the light's surface reflects; none: black"})

    @property
    def emits(self) -> bool:
        return max(self.radiance) > 0.0


@dataclass
class Conductor(Material):
    """A metal: Fresnel reflection with a complex index of refraction, smooth or GGX-rough."""

    type_name: ClassVar[str] = "conductor"
    metal: str = field(default="aluminium", metadata={"choices": (*METALS, "custom"), "doc": "preset, or custom eta/k"})
    eta: RGB = field(default=(1.657, 0.880, 0.521), metadata={"range": (0.0, 100.0), "doc": "used when metal is custom"})
    k: RGB = field(default=(9.224, 6.270, 4.837), metadata={"range": (0.0, 100.0), "doc": "used when metal is custom"})
    tint: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1.0), "doc": "scales the reflectance"})
    roughness: float = field(default=0.0, metadata={"range": (0.0, 1.0), "doc": "0 = polished mirror"})
    roughness_texture: Texture | None = None
    distribution: str = field(default="ggx", metadata=_DISTRIBUTION)

    def complex_ior(self) -> tuple[RGB, RGB]:
        return (self.eta, self.k) if self.metal == "custom" else METALS[self.metal]


@dataclass
class Plastic(Material):
    """A diffuse base under a smooth or rough dielectric coating (Mitsuba's plastic and roughplastic)."""

    type_name: ClassVar[str] = "plastic"
    albedo: RGB = field(default=(0.5, 0.5, 0.5), metadata={"range": (0.0, 1.0), "doc": "colour of the base"})
    albedo_texture: Texture | None = None
    ior: float = field(default=1.49, metadata={"range": (1.0, 4.0), "doc": "index of refraction of the coating"})
    roughness: float = field(default=0.0, metadata={"range": (0.0, 1.0)})
    roughness_texture: Texture | None = None
    distribution: str = field(default="ggx", metadata=_DISTRIBUTION)
    coating: str = field(default="energy_conserving", metadata={
        "choices": COATINGS,
        "doc": "how much light a rough coating lets through to the base: all it does not reflect "
               "(energy_conserving), or only what refracts unshadowed by its microfacets (single_scattering: "
               "Mitsuba's roughplastic, darker when very rough)"})


@dataclass
class Dielectric(Material):
    """Glass and water: Fresnel reflection and Snell refraction, smooth or rough, with Beer-Lambert absorption.

    Absorption is given the way an artist sees it (Bouguer's law): light that travels ``absorption_distance_m``
    through the material keeps ``absorption_color`` of itself; white means clear.
    """

    type_name: ClassVar[str] = "dielectric"
    ior: float = field(default=1.5, metadata={"range": (1.0001, 4.0), "doc": "index of refraction inside"})
    roughness: float = field(default=0.0, metadata={"range": (0.0, 1.0)})
    distribution: str = field(default="ggx", metadata=_DISTRIBUTION)
    tint: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1.0), "doc": "scales reflection and transmission"})
    absorption_color: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (1e-6, 1.0)})
    absorption_distance_m: float = field(default=0.1, metadata={"range": (1e-6, 1e6)})

    def absorption_coefficient(self) -> RGB:
        """sigma_a per metre, from exp(-sigma_a d) = colour."""
        return tuple(-math.log(c) / self.absorption_distance_m for c in self.absorption_color)


@dataclass
class ThinDielectric(Material):
    """A pane of glass too thin to model: reflects, and lets light through without bending it."""

    type_name: ClassVar[str] = "thin_dielectric"
    ior: float = field(default=1.5, metadata={"range": (1.0001, 4.0)})
    tint: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1.0)})


# -- Materials that hold materials ------------------------------------------------------------------------
# Each wraps one or two materials. The renderer resolves the chain at every hit, from the outside in, down to
# the material that scatters (glsl/bsdf.glsl, resolve_material).


@dataclass
class Blend(Material):
    """A mix of two materials: ``first`` weighted by 1 - weight, ``second`` by ``weight`` (Mitsuba's
    blendbsdf). The renderer picks one of the two at each hit with those odds: unbiased, as pbrt-v4's mix."""

    type_name: ClassVar[str] = "blend"
    first: Material = field(default_factory=Diffuse, metadata={"doc": "weighted by 1 - weight"})
    second: Material = field(default_factory=lambda: Conductor(), metadata={"doc": "weighted by weight"})
    weight: float = field(default=0.5, metadata={"range": (0.0, 1.0), "doc": "share of the second material"})
    weight_texture: Texture | None = field(default=None, metadata={"doc": "overrides weight (luminance) where given"})


@dataclass
class Mask(Material):
    """A cut-out: where ``opacity`` is below 1 the surface is partly absent, and light passes straight
    through it (leaves, fences, a printed stencil; Mitsuba's mask). Rays pass with probability 1 - opacity,
    shadow rays included."""

    type_name: ClassVar[str] = "mask"
    material: Material = field(default_factory=Diffuse, metadata={"doc": "the surface where it is present"})
    opacity: float = field(default=0.5, metadata={"range": (0.0, 1.0), "doc": "1: solid, 0: absent"})
    opacity_texture: Texture | None = field(default=None, metadata={"doc": "overrides opacity (luminance) where given"})


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


@dataclass
class NormalMap(Material):
    """A tangent-space normal map (RGB = (n + 1) / 2, linear, +Z out of the surface, +X along u) gives the
    shading normal of ``material`` (Mitsuba's normalmap)."""

    type_name: ClassVar[str] = "normal_map"
    material: Material = field(default_factory=Diffuse)
    texture: Texture | None = field(default=None, metadata={"doc": "read as linear: set its colour space to linear"})
    shadowing: bool = field(default=True, metadata={
        "doc": "soften the hard shadow line tilted normals leave (Estevez et al. 2019; Mitsuba's default)"})


WRAPPER_TYPES = (Blend, Mask, BumpMap, NormalMap)


def inner_materials(material: Material) -> list[Material]:
    """The materials a material holds (none for a plain one)."""
    if isinstance(material, Blend):
        return [material.first, material.second]
    if isinstance(material, (Mask, BumpMap, NormalMap)):
        return [material.material]
    if isinstance(material, Emissive) and material.surface is not None:
        return [material.surface]
    return []


def walk_materials(material: Material):
    """The material and every material it holds, outermost first."""
    yield material
    for inner in inner_materials(material):
        yield from walk_materials(inner)


MATERIAL_TYPES: dict[str, type[Material]] = {
    cls.type_name: cls for cls in (Diffuse, Emissive, Conductor, Plastic, Dielectric, ThinDielectric,
                                   Blend, Mask, BumpMap, NormalMap)
}
