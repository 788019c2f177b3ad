"""Materials: how a surface scatters or emits light.

Each material kind is one module here, holding its dataclass (registered under the ``type`` name that the
scene file uses), the function that packs it into its GPU record, its Mitsuba mapping (``from_mitsuba``, for
the Mitsuba BSDF plugins that map onto it) and its kind entry (``KIND``) naming its type code, its GLSL file
(glsl/material_<name>.glsl) and its Mitsuba plugins. :mod:`.registry` lists the kinds in one place; the
renderer's type codes, packing, kernel features and shader dispatch, and the Mitsuba importer's BSDF table,
are all made from it (docs/architecture.md, "Adding a material kind").

Roughness is the artist's "perceptual" roughness r in [0, 1]; the microfacet width is alpha = r^2 (as in
Disney's and glTF's conventions). Zero means a perfectly smooth surface (a mirror-like delta lobe). The
microfacet distribution is GGX by default, or Beckmann (Mitsuba's default for its rough BSDFs).

Some materials hold other materials (docs/scene-format.md, "Materials that hold materials"): a light whose
surface also reflects (``Emissive.surface``), a blend of two, a cut-out (``Mask``), and bump and normal maps
that tilt the shading normal of the material they hold. The renderer resolves the chain at every hit, from the
outside in, down to the material that scatters (glsl/bsdf.glsl, resolve_material).
"""

from __future__ import annotations

from lenslab.scene.materials.base import COATINGS, MICROFACET_DISTRIBUTIONS, RGB, Material, DISTRIBUTION_FIELD
from lenslab.scene.materials.blend import Blend
from lenslab.scene.materials.bump_map import BumpMap
from lenslab.scene.materials.conductor import METALS, Conductor
from lenslab.scene.materials.dielectric import Dielectric
from lenslab.scene.materials.diffuse import Diffuse
from lenslab.scene.materials.emissive import Emissive
from lenslab.scene.materials.mask import Mask
from lenslab.scene.materials.normal_map import NormalMap
from lenslab.scene.materials.plastic import Plastic
from lenslab.scene.materials.thin_dielectric import ThinDielectric
from lenslab.scene.materials.registry import MATERIAL_TYPES, WRAPPER_TYPES, inner_materials, walk_materials

__all__ = ["COATINGS", "MICROFACET_DISTRIBUTIONS", "RGB", "METALS", "Material", "Diffuse", "Emissive", "Conductor",
           "Plastic", "Dielectric", "ThinDielectric", "Blend", "Mask", "BumpMap", "NormalMap", "WRAPPER_TYPES",
           "inner_materials", "walk_materials", "MATERIAL_TYPES", "DISTRIBUTION_FIELD"]
