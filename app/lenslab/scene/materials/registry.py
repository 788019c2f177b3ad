"""The material kinds, in one place and in registration order: a kind's place is its type code.

Everything else is made from :data:`KINDS`: the scene format's ``type`` names (:data:`MATERIAL_TYPES`), the
``MATERIAL_*`` codes render/gpu_layout.py re-exports and every shader gets as #defines
(:data:`MATERIAL_CODES`), packing (:func:`pack_record`, called by render/buffers.py), the kernel's feature
bits (:attr:`MaterialKind.feature_bit`, render/features.py), and the GLSL that includes each kind's shader
file and dispatches evaluation and sampling to it (:func:`glsl_dispatch`, the include "material_kinds.glsl"
that render/gl.py makes for glsl/bsdf.glsl), and the Mitsuba BSDF plugins that map onto each kind
(:attr:`MaterialKind.mitsuba_plugins` and ``from_mitsuba``: scene/io/mitsuba_bsdfs.py's BSDF_MAPPINGS).

Adding a kind: write its module (dataclass, ``pack``, ``KIND``, its Mitsuba mapping if a Mitsuba plugin maps
onto it), its glsl/material_<name>.glsl, and register
it at the end of :data:`KINDS` (docs/architecture.md, "Adding a material kind").
"""

from __future__ import annotations

import dataclasses
from typing import Iterator, Sequence

import numpy as np

from lenslab.scene.materials import (blend, bump_map, conductor, dielectric, diffuse, emissive, mask, normal_map,
                                     plastic, thin_dielectric)
from lenslab.scene.materials.base import MATERIAL_ROWS, MICROFACET_CODES, Material, PackContext
from lenslab.scene.materials.spec import MaterialKind


def _register(*kinds: MaterialKind) -> tuple[MaterialKind, ...]:
    return tuple(dataclasses.replace(kind, code=code) for code, kind in enumerate(kinds))


KINDS: tuple[MaterialKind, ...] = _register(
    diffuse.KIND,
    emissive.KIND,
    conductor.KIND,
    plastic.KIND,
    dielectric.KIND,
    thin_dielectric.KIND,
    # Materials that hold materials: row 0 (parameter, its texture, -, type), row 2 the indices of the
    # records they hold. (An Emissive holds its surface too, its index in row 2, x; -1: black.)
    blend.KIND,
    mask.KIND,
    bump_map.KIND,
    normal_map.KIND,
)

KIND_OF_NAME: dict[str, MaterialKind] = {kind.name: kind for kind in KINDS}
KIND_OF_CLASS: dict[type, MaterialKind] = {kind.cls: kind for kind in KINDS}
#: The scene format's ``type`` name -> material class.
MATERIAL_TYPES: dict[str, type[Material]] = {kind.name: kind.cls for kind in KINDS}
#: ``MATERIAL_DIFFUSE`` ... -> type code, for render/gpu_layout.py and the shaders' #defines.
MATERIAL_CODES: dict[str, int] = {kind.constant: kind.code for kind in KINDS}
WRAPPER_TYPES: tuple[type[Material], ...] = tuple(kind.cls for kind in KINDS if kind.wrapper)
WRAPPER_CODES: tuple[int, ...] = tuple(kind.code for kind in KINDS if kind.wrapper)  # parameter and texture in row 0
HOLDING_CODES: tuple[int, ...] = tuple(kind.code for kind in KINDS if kind.holds is not None)  # row 2 names records


def kind_of(material: Material | type) -> MaterialKind | None:
    """The registered kind of a material (or material class), through its base classes; None if none."""
    cls = material if isinstance(material, type) else type(material)
    for base in cls.__mro__:
        kind = KIND_OF_CLASS.get(base)
        if kind is not None:
            return kind
    return None


def inner_materials(material: Material) -> list[Material]:
    """The materials a material holds (none for a plain one)."""
    kind = kind_of(material)
    return kind.holds(material) if kind is not None and kind.holds is not None else []


def walk_materials(material: Material) -> Iterator[Material]:
    """The material and every material it holds, outermost first."""
    yield material
    for inner in inner_materials(material):
        yield from walk_materials(inner)


def pack_record(material: Material, ctx: PackContext, inner: Sequence[int] = ()) -> np.ndarray:
    """The material's MATERIAL_ROWS x 4 GPU record (base.py describes the rows): the rows every kind shares
    (type code, no textures, white tint, the records it holds, alpha and distribution for a kind that
    scatters), then the kind's own ``pack``."""
    kind = KIND_OF_CLASS.get(type(material))
    if kind is None:
        raise TypeError(f"no GPU packing for material type {type(material).__name__}")
    record = np.zeros((MATERIAL_ROWS, 4), np.float32)
    record[0, 3] = kind.code
    record[3, 3] = record[4, 3] = -1.0  # no textures
    record[4, :3] = 1.0
    if kind.holds is not None:
        record[2, :2] = -1.0  # holds no material
    for slot, index in enumerate(inner):
        record[2, slot] = index
    if not kind.wrapper:
        roughness = getattr(material, "roughness", 0.0)
        record[2, 3] = roughness**2  # microfacet alpha from perceptual roughness
        record[5, 3] = MICROFACET_CODES[getattr(material, "distribution", "ggx")]
    kind.pack(material, record, ctx)
    return record


# -- GLSL ----------------------------------------------------------------------------------------------------
#: The include glsl/bsdf.glsl names; render/gl.py's load_shader_source makes it with glsl_dispatch().
GLSL_DISPATCH_INCLUDE = "material_kinds.glsl"

_EVAL_ARGS = "Bsdf b, vec3 wo, vec3 wi, bool same_side, inout float pdf"
_SAMPLE_ARGS = ("SurfaceHit s, Bsdf b, vec3 u, vec3 wo, inout vec3 wi, inout bool transmit, inout vec3 wi_world, "
                "inout vec3 weight, inout float pdf, inout bool delta")


def glsl_dispatch(kinds: Sequence[MaterialKind] = KINDS) -> str:
    """GLSL that includes every kind's file and defines material_eval and material_sample, which call the
    kind's ``<prefix>_eval`` / ``<prefix>_sample`` for the Bsdf's type (each test a compile-time false for
    kinds the scene lacks: glsl/features.glsl's HAS_MATERIAL, through is_type)."""
    lines = ["// Generated from lenslab.scene.materials.registry (glsl_dispatch): one include per material kind,",
             "// and the dispatch of evaluation and sampling to the kinds that scatter."]
    lines += [f'#include "{kind.glsl}"' for kind in kinds]
    lines += ["", f"vec3 material_eval({_EVAL_ARGS}) {{"]
    for kind in kinds:
        if kind.glsl_prefix and kind.glsl_eval:
            lines.append(f"    if (is_type(b, {kind.constant})) return {kind.glsl_prefix}_eval(b, wo, wi, same_side, pdf);")
    lines += ["    return vec3(0.0);", "}", "", f"int material_sample({_SAMPLE_ARGS}) {{"]
    for kind in kinds:
        if kind.glsl_prefix and kind.glsl_sample:
            lines.append(f"    if (is_type(b, {kind.constant})) "
                         f"return {kind.glsl_prefix}_sample(s, b, u, wo, wi, transmit, wi_world, weight, pdf, delta);")
    lines += ["    return BSDF_SAMPLE_FAILED;", "}", ""]
    return "\n".join(lines)
