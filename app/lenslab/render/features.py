"""Which parts of the trace kernel a scene needs: the kernel is compiled once per set of features.

On a SIMD device every lane pays for both sides of a branch that any of its lanes takes; Mesa 22's llvmpipe
(the CPU renderer) pays for both sides of *every* branch, taken or not, and llvmpipe runs the body of every
loop at least once, needed or not. A general kernel therefore costs a Cornell box the code for textures,
spheres, an environment map and five material models it never uses (12-16% of its speed on Mesa 25's
llvmpipe, up to 64% on Mesa 22's: docs/performance.md).
:func:`scene_features` reads the packed scene and names what it uses; :meth:`KernelFeatures.defines` turns
that into the #defines glsl/features.glsl declares, so the compiler drops everything else. The general
kernel (:data:`GENERAL`) keeps it all; tests check that both render the same image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lenslab.render.bsp import INTERSECTION_COST, KdTree
from lenslab.render.buffers import HOLDING_CODES, WRAPPER_CODES, PackedScene, held_materials
from lenslab.render.gpu_layout import (ENV_MAP, GEOMETRY_ROWS, LIGHT_AREA, LIGHT_ENVIRONMENT, LIGHT_POINT, LIGHT_ROWS,
                                       LIGHT_SPOT, LIGHT_SUN, MATERIAL_ROWS,
                                       MICROFACET_BECKMANN)
from lenslab.scene.materials.registry import KINDS

# Every registered material kind's type code (scene/materials/registry.py); each kind's feature bit in the
# MATERIAL_TYPES mask is 1 << code (MaterialKind.feature_bit, glsl/features.glsl's HAS_MATERIAL).
ALL_MATERIAL_TYPES = frozenset(kind.code for kind in KINDS)

# Small scenes. Lanes of a SIMD group that walk a kd-tree each read their own nodes and wait for the lane
# with the longest walk; a loop over every primitive reads each one once for all lanes and never diverges.
# On llvmpipe a divergent tree step costs about three uniform primitive tests, so a scene whose tree saves
# less than that over testing everything renders faster flat (docs/performance.md, "Where the time goes,
# and small scenes": dof_lights +40%, cornell_caustic +50%, the Cornell box +7%; dof_chart, whose tree
# saves eleven-fold, 34% slower flat). A scene renders flat when it has at most FLAT_MAX_PRIMITIVES
# primitives and its tree's SAH cost is at least FLAT_SAH_FRACTION of the cost of testing them all.
FLAT_MAX_PRIMITIVES = 64
FLAT_SAH_FRACTION = 0.35


@dataclass(frozen=True)
class KernelFeatures:
    """What a kernel can handle. Every field True (and every material type) is the general kernel."""

    spheres: bool = True
    textures: bool = True  # image or checker textures on materials (an environment map is separate)
    environment_map: bool = True
    environment_light: bool = True  # next-event estimation may choose the environment
    area_lights: bool = True
    point_lights: bool = True
    spot_lights: bool = True
    sun: bool = True
    # How next-event estimation chooses a light (glsl/lights.glsl): by what each brings to the shading point
    # (a few lights), or by power (many). The general kernel has both and asks the uniform lights_at_point.
    lights_at_point: bool = True
    lights_by_power: bool = True
    material_types: frozenset[int] = ALL_MATERIAL_TYPES  # type codes: scene/materials/registry.py's KINDS
    # Materials that hold materials (a light with a surface, blends, masks, bump and normal maps): the
    # resolve loop of glsl/bsdf.glsl.
    nested_materials: bool = True
    beckmann: bool = True  # a rough material with the Beckmann distribution (else GGX alone)
    # 0: rays walk the kd-tree. N > 0: the scene's N primitives are tested in one loop (a small scene).
    flat_primitives: int = 0
    instances: bool = True  # mesh groups placed by instances (render/instancing.py): two levels to walk

    def defines(self) -> dict[str, int]:
        return {
            "FLAT_PRIMITIVES": int(self.flat_primitives),
            "HAS_INSTANCES": int(self.instances),
            "HAS_SPHERES": int(self.spheres),
            "HAS_TEXTURES": int(self.textures),
            "HAS_ENVIRONMENT_MAP": int(self.environment_map),
            "HAS_ENVIRONMENT_LIGHT": int(self.environment_light),
            "HAS_AREA_LIGHTS": int(self.area_lights),
            "HAS_POINT_LIGHTS": int(self.point_lights),
            "HAS_SPOT_LIGHTS": int(self.spot_lights),
            "HAS_SUN": int(self.sun),
            "HAS_LIGHTS_AT_POINT": int(self.lights_at_point),
            "HAS_LIGHTS_BY_POWER": int(self.lights_by_power),
            "HAS_NESTED_MATERIALS": int(self.nested_materials),
            "HAS_BECKMANN": int(self.beckmann),
            "MATERIAL_TYPES": sum(KINDS[code].feature_bit for code in self.material_types),
        }


GENERAL = KernelFeatures()


def scene_features(packed: PackedScene) -> KernelFeatures:
    """The features the packed scene uses (materials only as far as some primitive uses them)."""
    uniforms, arrays = packed.uniforms, packed.arrays
    prim_count, triangle_count = packed.prim_count, int(uniforms["triangle_count"])
    materials = arrays["materials"][: int(uniforms["texture_base"])].reshape(-1, MATERIAL_ROWS, 4)
    # The world's primitives name their materials; a mesh group's triangles take their instance's.
    world_rows = packed.world_geometry()[:, 1, 3]
    world_prims = prim_count - packed.first_world_prim
    used = np.union1d(np.unique(world_rows.view(np.int32)), np.asarray(packed.instance_materials, np.int32))
    # The records primitives name, and every record those hold (a blend's two, a light's surface ...).
    records = materials[np.asarray(sorted(held_materials(materials, used)), dtype=np.int64)]
    # A scene without lights still has a row (GL refuses empty buffers).
    light_rows = arrays["lights"].reshape(-1, 4)[0::LIGHT_ROWS][: int(uniforms["light_count"])]
    light_kinds = set(light_rows[:, 0].astype(int).tolist())
    return KernelFeatures(
        spheres=prim_count > triangle_count,
        textures=bool((records[:, 3, 3] >= 0).any() or (records[:, 4, 3] >= 0).any()
                      or (np.isin(records[:, 0, 3], WRAPPER_CODES) & (records[:, 0, 1] >= 0)).any()),
        environment_map=int(uniforms["env_type"]) == ENV_MAP,
        environment_light=LIGHT_ENVIRONMENT in light_kinds,
        area_lights=LIGHT_AREA in light_kinds,
        point_lights=LIGHT_POINT in light_kinds,
        spot_lights=LIGHT_SPOT in light_kinds,
        sun=LIGHT_SUN in light_kinds,
        lights_at_point=bool(uniforms["lights_at_point"]),
        lights_by_power=not uniforms["lights_at_point"],
        material_types=frozenset(int(code) for code in records[:, 0, 3]),
        nested_materials=bool(((records[:, 2, 0] >= 0) & np.isin(records[:, 0, 3], HOLDING_CODES)).any()),
        beckmann=bool(((records[:, 5, 3] == MICROFACET_BECKMANN) & ~np.isin(records[:, 0, 3], HOLDING_CODES)).any()),
        flat_primitives=world_prims if renders_flat(packed.kdtree, world_prims) else 0,
        instances=bool(packed.instance_materials),
    )


def renders_flat(kdtree: KdTree, prim_count: int) -> bool:
    """Whether testing every primitive beats walking this tree (see FLAT_MAX_PRIMITIVES)."""
    if not 0 < prim_count <= FLAT_MAX_PRIMITIVES:
        return False
    test_all = prim_count * kdtree.params.get("intersection_cost", INTERSECTION_COST)
    return kdtree.sah_cost >= FLAT_SAH_FRACTION * test_all
