"""Materials: how a surface scatters or emits light.

Each material is a small dataclass registered under the ``type`` name that the scene file uses. The renderer
packs each type into its own GPU record (``lenslab.render.buffers``); adding a material means adding a class
here, a packer there and a branch in ``glsl/bsdf.glsl``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

RGB = tuple[float, float, float]


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


@dataclass
class Emissive(Material):
    """A light source: emits ``radiance`` from the front face (both faces if ``two_sided``) and reflects nothing."""

    type_name: ClassVar[str] = "emissive"
    radiance: RGB = field(default=(1.0, 1.0, 1.0), metadata={"range": (0.0, 1e6), "doc": "W/(m^2 sr) per channel"})
    two_sided: bool = field(default=False, metadata={"doc": "emit from the back face too"})

    @property
    def emits(self) -> bool:
        return max(self.radiance) > 0.0


MATERIAL_TYPES: dict[str, type[Material]] = {cls.type_name: cls for cls in (Diffuse, Emissive)}
