"""One material kind, as the registry (registry.py) holds it: everything the rest of LensLab needs to know
about it besides its dataclass's own fields."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

import numpy as np

from lenslab.scene.materials.base import Material, PackContext

if TYPE_CHECKING:
    from lenslab.scene.io.mitsuba_props import BsdfMapping

Packer = Callable[[Material, np.ndarray, PackContext], None]


@dataclass(frozen=True)
class MaterialKind:
    """A material kind: its dataclass (whose ``type_name`` is its name in scene files), the name of its type
    code (``MATERIAL_DIFFUSE``: render/gpu_layout.py and every shader see it under that name), the function
    that fills its GPU record's rows after the shared ones (:func:`registry.pack_record`), and its GLSL
    include (in glsl/), whose ``<glsl_prefix>_eval`` and ``<glsl_prefix>_sample`` the generated dispatch
    calls where ``glsl_eval`` / ``glsl_sample`` say it has them.

    ``holds`` names the materials a material of this kind holds (a blend's two, a light's surface); a
    ``wrapper`` keeps its parameter and texture in row 0 and is resolved away before shading
    (glsl/bsdf.glsl's resolve_material).

    ``mitsuba_plugins`` names the Mitsuba BSDF plugins that map onto this kind, and ``from_mitsuba`` (the
    kind's module's ``from_mitsuba(p, imp)``, a ``mitsuba_props.BsdfMapping``) maps one of them: it reads the
    plugin's properties (``p``; ``p.node.type`` is the plugin's name) and returns a ``mitsuba_props.Mapped``.
    scene/io/mitsuba_bsdfs.py's ``BSDF_MAPPINGS`` is made from them.

    ``code`` is its place in the registry, given at registration."""

    cls: type[Material]
    constant: str
    pack: Packer
    glsl: str
    glsl_prefix: str | None = None
    glsl_eval: bool = True
    glsl_sample: bool = True
    holds: Callable[[Material], list[Material]] | None = None
    wrapper: bool = False
    mitsuba_plugins: tuple[str, ...] = ()
    from_mitsuba: BsdfMapping | None = None
    code: int = -1

    @property
    def name(self) -> str:
        return self.cls.type_name

    @property
    def feature_bit(self) -> int:
        """Its bit in the kernel's MATERIAL_TYPES mask (glsl/features.glsl's HAS_MATERIAL)."""
        return 1 << self.code
