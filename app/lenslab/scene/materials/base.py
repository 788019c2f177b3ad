"""What every material kind shares: the base class, the GPU record's size and the codes of the microfacet
distributions, and what packing a record may ask of the renderer (:class:`PackContext`).

A material's GPU record is MATERIAL_ROWS vec4 rows (read by glsl/bsdf.glsl): row 0 (albedo, type), 1 (emission,
two-sided), 2 (eta rgb | ior, internal reflectance, reflectance table, alpha), 3 (k rgb, albedo texture),
4 (specular tint, roughness texture), 5 (absorption per metre, distribution), 6-7 spare. A material that
holds others keeps its parameter and texture in row 0 and the indices of the records it holds in row 2.
render/gpu_layout.py re-exports these numbers under the same names, and every shader gets them as #defines.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

RGB = tuple[float, float, float]
#: The relative indices of refraction a dielectric may have, inside over outside: below 1 a bubble (air in water,
#: 0.75), above 1 glass or diamond (2.42); the kernel's Fresnel and Snell terms take either (glsl/microfacet.glsl).
RELATIVE_IOR_RANGE = (0.25, 4.0)

# vec4 rows per material record, and how deep materials may hold one another (glsl/bsdf.glsl's resolve loop
# runs at most this many steps).
MATERIAL_ROWS = 8
MATERIAL_NESTING = 8
# A microfacet material's distribution (row 5, w).
MICROFACET_GGX = 0
MICROFACET_BECKMANN = 1
MICROFACET_CODES = {"ggx": MICROFACET_GGX, "beckmann": MICROFACET_BECKMANN}

MICROFACET_DISTRIBUTIONS = ("ggx", "beckmann")
COATINGS = ("energy_conserving", "single_scattering")  # Plastic.coating
DISTRIBUTION_FIELD = {"choices": MICROFACET_DISTRIBUTIONS,
                 "doc": "microfacet distribution of a rough surface: GGX (long tails) or Beckmann"}


@dataclass
class Material:
    type_name: ClassVar[str] = ""

    @property
    def emits(self) -> bool:
        return False


class PackContext(Protocol):
    """What a kind's packing function may ask of the renderer while it fills a record (render/buffers.py
    provides it): texture records and float tables in the texture table, and the Fresnel tables of a rough
    coating (render/fresnel.py). Packing itself stays plain numpy."""

    # A texture's record, -1 for None. ``data``: the slot holds numbers (roughness, normals, heights, opacity, a
    # weight), read as stored; else a colour, read into the working space (colour_management/texture_spaces.py).
    def index_of(self, texture: Any, data: bool = False) -> int: ...

    def add_floats(self, values: Any) -> int: ...  # floats appended to image_data: their offset

    fresnel: Any  # render/fresnel.py: internal_diffuse_reflectance, rough_* tables
