"""Scene -> GPU storage buffers.

:func:`pack_scene` turns a flattened scene into the plain arrays that glsl/common.glsl declares (pure numpy,
testable without a GPU); :class:`GpuScene` uploads them to a context, checks them against the device's
storage-block limit and owns the buffers until :meth:`GpuScene.release`.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from lenslab.color import luminance
from lenslab.render import kdtree_cache
from lenslab.render.bsp import KdTree
from lenslab.render import fresnel
from lenslab.render.environment import EnvironmentDistribution, environment_power, infinite_light_power
from lenslab.render.gl import make_current
from lenslab.limits import SceneTooLarge, format_bytes  # SceneTooLarge: raised here, imported from here
from lenslab.render.gpu_layout import (ENV_CONSTANT, ENV_MAP, GEOMETRY_BINDING, GEOMETRY_ROWS,
                                       IMAGE_DATA_BINDING, KD_NODES_BINDING, LIGHT_AREA, LIGHT_CHOICE_BINDING,
                                       LIGHT_ENVIRONMENT, LIGHT_PLACES, LIGHT_POINT, LIGHT_ROWS, LIGHT_SUN,
                                       LIGHTS_BINDING, MATERIAL_NESTING, MATERIAL_ROWS, MATERIALS_BINDING,
                                       PRIM_REFS_BINDING, SHADING_BINDING, SHADING_ROWS, INSTANCES_BINDING)
from lenslab.render.instancing import GroupCache, PackedGroup, join_layers, triangle_rows
from lenslab.render.textures import TextureTable, read_texture_image
from lenslab.colour_management.config import DEFAULT_SOURCE, ColourConfigError
from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE
from lenslab.scene.flatten import FlatScene
from lenslab.scene.light_units import (environment_in_nits, environment_map_scale, light_in_candela,
                                       sphere_mean_luminance)
from lenslab.scene.materials import Emissive, Material, inner_materials
from lenslab.scene.materials.base import MICROFACET_CODES  # noqa: F401 (imported from here)
from lenslab.scene.materials.registry import HOLDING_CODES, KINDS, WRAPPER_CODES, pack_record
from lenslab.render.gpu_layout import LIGHT_SPOT, SPOT_PARAMS
from lenslab.scene.lights import Light, PointLight, SpotLight, SunLight
from lenslab.scene.scene import ConstantEnvironment, Environment, EnvironmentMap, SceneError
from lenslab.scene.textures import Checkerboard, InlineImageTexture

# Each material class's type code in its GPU record (its place in scene/materials/registry.py).
MATERIAL_CODES = {kind.cls: kind.code for kind in KINDS}

# Where each of the packed scene's arrays is bound.
BINDINGS = {"kd_nodes": KD_NODES_BINDING, "prim_refs": PRIM_REFS_BINDING, "geometry": GEOMETRY_BINDING,
            "shading": SHADING_BINDING, "materials": MATERIALS_BINDING, "lights": LIGHTS_BINDING,
            "image_data": IMAGE_DATA_BINDING, "instances": INSTANCES_BINDING}
UNIFORM_BINDINGS = {"light_choice": LIGHT_CHOICE_BINDING}  # uniform blocks (glsl/lights.glsl's LightPlaces)
MISSING_SKY = (0.2, 0.0, 0.2)  # what a scene whose environment map cannot be read is lit by


class _PackContext:
    """What a material kind's packing function may ask for (scene/materials/base.py's PackContext): the
    texture table's records and float tables, and the Fresnel tables of render/fresnel.py."""

    fresnel = fresnel

    def __init__(self, textures: TextureTable):
        self.index_of = textures.index_of
        self.add_floats = textures.add_floats


def pack_material(material: Material, textures: TextureTable, inner: Sequence[int] = ()) -> np.ndarray:
    """MATERIAL_ROWS (eight) vec4 rows, read by glsl/bsdf.glsl's bsdf_at(): the rows every kind shares, then
    the kind's own (scene/materials/registry.py's pack_record; scene/materials/base.py lists the rows). A
    material that holds others (``inner``: the indices of their records, see :class:`MaterialTable`) keeps its
    parameter and texture in row 0 and those indices in row 2."""
    return pack_record(material, _PackContext(textures), inner)


class MaterialTable:
    """Every material's GPU record: the scene's own first, at the indices the geometry names, then the
    materials they hold (a blend's two, a light's surface ...), each after its holder's list, referred to by
    index from the holder's row 2."""

    def __init__(self, materials: Sequence[Material], textures: TextureTable, names: Sequence[str] = ()):
        self._textures = textures
        self._records: list[np.ndarray | None] = [None] * len(materials)
        for index, material in enumerate(materials):
            name = names[index] if index < len(names) else str(index)
            self._records[index] = self._pack(material, name, depth=1)

    def _pack(self, material: Material, name: str, depth: int) -> np.ndarray:
        if depth > MATERIAL_NESTING:
            raise SceneError(f"material '{name}': materials nest more than {MATERIAL_NESTING} deep")
        inner = [self._add(held, name, depth + 1) for held in inner_materials(material)]
        return pack_material(material, self._textures, inner)

    def _add(self, material: Material, name: str, depth: int) -> int:
        self._records.append(None)
        index = len(self._records) - 1
        self._records[index] = self._pack(material, name, depth)
        return index

    def rows(self) -> np.ndarray:
        records = self._records or [np.zeros((MATERIAL_ROWS, 4), np.float32)]  # GL refuses empty buffers
        return np.concatenate(records)


def held_materials(records: np.ndarray, used: Sequence[int]) -> set[int]:
    """Indices of the records ``used`` and every record they hold, from the packed rows (MATERIAL_ROWS x 4
    each): the materials a kernel must be able to shade."""
    seen: set[int] = set()
    todo = [int(i) for i in used]
    while todo:
        index = todo.pop()
        if index in seen or not 0 <= index < len(records):
            continue
        seen.add(index)
        todo.extend(int(i) for i in records[index, 2, :2] if i >= 0 and records[index, 0, 3] in HOLDING_CODES)
    return seen


# WRAPPER_CODES (parameter and texture in row 0) and HOLDING_CODES (row 2 names records they hold) come from
# the registry, imported above: render/features.py imports them from here.


def _emitted_power(flat: FlatScene) -> np.ndarray:
    """Power (luminance-weighted, up to a constant) of every primitive; zero for non-emitters.

    A Lambertian emitter of radiance L and area A emits pi L A per side: the weights for choosing a light.
    """
    power = np.zeros(flat.prim_count, np.float64)
    for index, material in enumerate(flat.materials):
        if not (isinstance(material, Emissive) and material.emits):
            continue
        sides = 2.0 if material.two_sided else 1.0
        radiance = luminance(material.radiance) * sides * math.pi
        tri = np.flatnonzero(flat.triangle_material == index)
        if len(tri):
            t = flat.triangles[tri].astype(np.float64)
            area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
            power[tri] = radiance * area
        sph = np.flatnonzero(flat.sphere_material == index)
        if len(sph):
            power[flat.triangle_count + sph] = radiance * 4.0 * math.pi * flat.spheres[sph, 3].astype(np.float64) ** 2
    return power


# Next-event estimation chooses among at most this many lights by what each brings to the shading point
# (glsl/lights.glsl, "Choosing a light"), which costs a pass over the table per choice; more lights (an
# emissive mesh) are chosen by power alone. No more than the LightPlaces block holds.
LIGHTS_AT_POINT_LIMIT = LIGHT_PLACES


@dataclass
class _LightEntry:
    """A row of the light table. ``falloff`` and ``reach2`` give the irradiance a light of power P brings to
    a point at distance d, roughly: P falloff / max(d^2, reach2) about ``vector``, or P falloff for a light
    at infinity (``reach2`` < 0). Roughly means averaged over the ways a surface at the point may face, as
    infinite_light_power (render/environment.py) measures the sky: a quarter of the irradiance on a surface
    facing a small light squarely. Measured alike, a lamp and the sky compete fairly; measured on a surface
    facing the lamp, lamps took shadow rays the sky needed (glass_metal_envmap in benchmarks/: 27% more
    noise than choosing by power)."""

    kind: int
    power: float
    prim: int = 0
    vector: tuple = (0.0, 0.0, 0.0)
    rgb: tuple = (0.0, 0.0, 0.0)
    falloff: float = 1.0 / (16.0 * math.pi)  # a point light: intensity P / 4 pi over d^2, facing it
    reach2: float = 1e-12
    w: tuple = (0.0, 0.0)  # the fourth values of rows 1 and 2 (a spot's cosines)


def _spot_light_entry(light: SpotLight, textures: TextureTable) -> _LightEntry:
    """A spot's row: (position, cos cutoff) in row 1, (intensity, cos beam) in row 2, and its SPOT_PARAMS in
    image_data at the offset row 0 holds where an area light holds its primitive (glsl/lights.glsl's
    spot_intensity).

    Its power is the intensity times the falloff integrated over the sphere (SpotLight.weighted_solid_angle),
    times the texture's mean where that is known without reading an image file again (only a weight for
    choosing lights: any positive value stays unbiased). In its cone it brings a surface facing it I / d^2, as
    a point light of the same intensity does, so its falloff is a quarter of that per unit of power."""
    right, top, axis = light.frame()
    cutoff, beam = light.cutoff_and_beam_rad()
    slope = 1.0 / (cutoff - beam) if cutoff > beam else 0.0  # a hard edge never reaches the ramp
    params = np.array([*axis, *right, *top, cutoff, slope, 0.5 / math.tan(cutoff), textures.index_of(light.texture)],
                      np.float32)
    assert params.size == SPOT_PARAMS
    solid_angle = light.weighted_solid_angle()
    power = luminance(light.intensity) * solid_angle * _texture_mean(light.texture)
    return _LightEntry(LIGHT_SPOT, power, prim=textures.add_floats(params), vector=tuple(light.position),
                       rgb=tuple(light.intensity), falloff=0.25 / solid_angle,
                       w=(math.cos(cutoff), math.cos(beam)))


def _texture_mean(texture) -> float:
    """The mean luminance of a spot's texture where it is at hand (a checkerboard, pixels in memory); 1 for an
    image file, which the texture table reads."""
    if isinstance(texture, Checkerboard):
        return 0.5 * (luminance(texture.color_a) + luminance(texture.color_b))
    if isinstance(texture, InlineImageTexture) and texture.pixels is not None:
        pixels = np.asarray(texture.pixels, np.float64)[..., :3]
        return float(luminance(pixels.reshape(-1, 3).mean(axis=0)))
    return 1.0


def _area_light_entries(flat: FlatScene, power: np.ndarray) -> list[_LightEntry]:
    """One entry per emissive primitive: its power, and its centre and extent for the irradiance estimate."""
    prims = np.flatnonzero(power > 0)
    tri, sph = prims[prims < flat.triangle_count], prims[prims >= flat.triangle_count] - flat.triangle_count
    t = flat.triangles[tri].astype(np.float64)
    centroids = t.mean(axis=1)
    centres = np.concatenate([centroids, flat.spheres[sph, :3].astype(np.float64)])
    reach2 = np.concatenate([((t - centroids[:, None]) ** 2).sum(-1).max(-1),
                             flat.spheres[sph, 3].astype(np.float64) ** 2])
    # On its axis, a one-sided Lambertian emitter of power P gives a surface facing it irradiance
    # P / (pi d^2); a two-sided one spends half its power on the far side; a sphere spreads it over all
    # directions, P / (4 pi d^2). A quarter of each: the average over the ways the surface may face.
    two_sided = np.array([flat.materials[m].two_sided for m in flat.triangle_material[tri]], bool)
    falloff = 0.25 * np.concatenate([np.where(two_sided, 0.5, 1.0) / math.pi, np.full(len(sph), 0.25 / math.pi)])
    return [_LightEntry(LIGHT_AREA, float(power[prim]), prim=int(prim), vector=tuple(centre), falloff=float(f),
                        reach2=float(r2))
            for prim, centre, f, r2 in zip(np.concatenate([tri, sph + flat.triangle_count]), centres, falloff, reach2)]


def _environment_uniforms(environment: Environment, textures: TextureTable, scene_radius: float,
                          importance: bool = True, working_space: str = DEFAULT_WORKING_SPACE):
    """(uniform values, power for light selection, sampling tables to append to image_data). A map's strength
    becomes the scale of its pixels here, where its image is read (scene/light_units.py)."""
    uniforms = {"env_type": ENV_CONSTANT, "env_radiance": (0.0, 0.0, 0.0), "env_strength": 1.0, "env_texture": -1,
                "env_world_to_map": _mat3_uniform(np.eye(3)), "env_dist_offset": 0, "env_size": (1, 1),
                "env_table_size": (1, 1), "env_rows_pole_to_pole": 0}
    if isinstance(environment, ConstantEnvironment):
        uniforms["env_radiance"] = tuple(float(v) for v in environment.radiance)
        return uniforms, infinite_light_power(4.0 * math.pi * luminance(environment.radiance), scene_radius)
    if isinstance(environment, EnvironmentMap):
        path = Path(environment.file)
        path = path if path.is_absolute() else textures.base_dir / path
        try:  # a colour, in the working space: a float file's linear Rec.709, an 8-bit file's sRGB (as Mitsuba)
            rgb = read_texture_image(path, "auto", textures.working_space, config_source=textures.colour_config)
        except (OSError, ColourConfigError) as exc:
            message = str(exc) if os.path.exists(path) else f"{path}: environment map not found"
            textures.warnings.append(f"{message}; lighting with a dim magenta sky instead")
            uniforms["env_radiance"] = MISSING_SKY
            return uniforms, infinite_light_power(4.0 * math.pi * luminance(MISSING_SKY), scene_radius)
        # Without importance sampling (for comparisons) the tables describe a uniform image.
        distribution = EnvironmentDistribution.from_image(rgb if importance else np.ones_like(rgb))
        scale = _environment_map_scale(environment, rgb, working_space)
        uniforms.update(
            env_type=ENV_MAP, env_strength=scale,
            env_texture=textures.index_of(InlineImageTexture(pixels=rgb, name=str(path), color_space="raw")),
            env_world_to_map=_mat3_uniform(environment.world_from_map().T),
            env_dist_offset=textures.add_floats(distribution.packed()), env_size=(rgb.shape[1], rgb.shape[0]),
            env_table_size=(distribution.pdf.shape[1], distribution.pdf.shape[0]),
            env_rows_pole_to_pole=int(environment.rows == "pole_to_pole"),
        )
        return uniforms, environment_power(rgb, scale, scene_radius)
    raise TypeError(f"no GPU packing for environment type {type(environment).__name__}")


def _environment_map_scale(environment: EnvironmentMap, rgb: np.ndarray, working_space: str) -> float:
    """What the map's pixels are multiplied by: its strength in its unit (a plain scale needs no mean)."""
    if environment.unit == "scale":
        return float(environment.strength)
    mean = sphere_mean_luminance(rgb, environment.rows, working_space)
    return environment_map_scale(environment.strength, environment.unit, mean)


def _mat3_uniform(matrix: np.ndarray) -> tuple[float, ...]:
    """A 3x3 matrix as a GLSL mat3 uniform takes it: nine floats, column by column."""
    return tuple(float(v) for v in np.asarray(matrix, float).flatten(order="F"))


def _reference_budget_warning(kdtree: KdTree) -> str:
    """What a user should hear when the kd-tree met its reference budget (render/bsp.py, "Bounded work")."""
    return (f"the kd-tree reached its limit of {kdtree.reference_limit:,} primitive references "
            f"({kdtree.refs_per_prim:.0f} per primitive; geometry piled up in one place, such as coplanar copies "
            "of a shape, makes every split copy them): the image is right but renders more slowly")


@dataclass(frozen=True)
class PackedScene:
    """Everything the trace kernel reads about the scene, as arrays and uniform values. A buffer made of parts
    laid one after another (the mesh groups' and the world's, render/instancing.py) is a tuple of arrays."""

    arrays: dict[str, np.ndarray | tuple[np.ndarray, ...]]
    uniforms: dict[str, object]
    kdtree: KdTree  # the world's own primitives' tree
    prim_count: int  # rows of the geometry buffer: the groups' triangles, the world's, its spheres
    warnings: tuple[str, ...] = ()  # problems the render survives (a missing texture): show them to the user
    group_trees: tuple[KdTree, ...] = ()  # the mesh groups' trees (render/instancing.py)
    first_world_prim: int = 0  # the world's own primitive i is row first_world_prim + i of the geometry buffer
    instance_materials: tuple[int, ...] = ()  # the material of each instance

    @property
    def trees(self) -> tuple[KdTree, ...]:
        """Every kd-tree the scene holds: the groups', then the world's."""
        return (*self.group_trees, self.kdtree)

    @property
    def nbytes(self) -> int:
        return sum(buffer_bytes(a) for a in self.arrays.values())

    def world_geometry(self) -> np.ndarray:
        """The world's own primitives' geometry rows, (P, GEOMETRY_ROWS, 4)."""
        rows = self.arrays["geometry"]
        rows = rows[-1] if isinstance(rows, tuple) else rows
        count = self.prim_count - self.first_world_prim
        return rows.reshape(-1, 4)[: GEOMETRY_ROWS * count].reshape(count, GEOMETRY_ROWS, 4)


def buffer_parts(value) -> tuple[np.ndarray, ...]:
    """A packed buffer as its parts (one, or the tuple it is)."""
    return value if isinstance(value, tuple) else (value,)


def buffer_bytes(value) -> int:
    return sum(part.nbytes for part in buffer_parts(value))


def pack_scene(flat: FlatScene, environment: Environment, kdtree: KdTree | None = None,
               base_dir: Path | None = None, lights: Sequence[Light] = (),
               environment_importance: bool = True, packed_groups: Sequence[PackedGroup] | None = None,
               group_cache: GroupCache | None = None, working_space: str = DEFAULT_WORKING_SPACE,
               colour_config: str = DEFAULT_SOURCE) -> PackedScene:
    """Arrays and uniforms for the trace kernel; ``base_dir`` resolves relative texture paths.
    ``environment_importance=False`` samples an environment map uniformly (to measure what importance
    sampling gains). ``kdtree`` is the world's own primitives' tree (built here when None); ``packed_groups`` are
    the mesh groups' trees and rows (render/instancing.py; ``group_cache``, a GroupCache, keeps them and their
    moved trees from one edit to the next), packed here when None. Lights and the environment given in
    photometric units other than the renderer's (lumens, an EV) are converted here (scene/light_units.py), with the
    luminance of ``working_space``, the scene's (flattening converted the area lights). Image textures and the
    environment map are read into ``working_space`` through the OCIO config ``colour_config`` (empty: $OCIO, else
    the built-in one; colour_management/texture_spaces.py)."""
    if kdtree is None:
        kdtree = kdtree_cache.kdtree(flat.prim_bounds(), triangles=flat.triangles)
    group_cache = group_cache or GroupCache()
    if packed_groups is None:
        packed_groups = group_cache.packed_groups(flat)
    first_world_prim = sum(len(g.geometry) for g in packed_groups)
    n_tri, n_prim = flat.triangle_count, flat.prim_count
    material_ids = np.concatenate([flat.triangle_material, flat.sphere_material]).astype(np.int32)

    textures = TextureTable(base_dir or Path.cwd(), working_space=working_space, colour_config=colour_config)
    bounds = flat.bounds()
    scene_radius = max(0.5 * float(np.linalg.norm(bounds[1] - bounds[0])), 1e-3)

    # Every light, with its power: next-event estimation chooses among them in proportion to it.
    entries = _area_light_entries(flat, _emitted_power(flat))
    # Light from infinity reaches every point alike: its irradiance is its power over the disk of the
    # scene's radius that the power was measured through. The sky's power (environment.infinite_light_power)
    # is already the average over the ways a surface may face; the sun's is pbrt's, for a surface facing it,
    # so it takes the quarter that averaging gives every small light (_LightEntry).
    at_infinity = {"falloff": 1.0 / (math.pi * scene_radius**2), "reach2": -1.0}
    sun_at_infinity = {**at_infinity, "falloff": 0.25 / (math.pi * scene_radius**2)}
    sun_uniforms = {"sun_direction": (0.0, 1.0, 0.0), "sun_one_minus_cos": 0.0, "sun_radiance": (0.0, 0.0, 0.0)}
    lights = [light_in_candela(light) for light in lights]
    environment = environment_in_nits(environment, working_space)
    suns = [light.name for light in lights if isinstance(light, SunLight)]
    if len(suns) > 1:
        raise ValueError(f"lights: only one sun per scene (found {', '.join(repr(name) for name in suns)})")
    for light in lights:
        if isinstance(light, PointLight):
            entries.append(_LightEntry(LIGHT_POINT, 4.0 * math.pi * luminance(light.intensity),
                                       vector=light.position, rgb=light.intensity))
        elif isinstance(light, SpotLight):
            entries.append(_spot_light_entry(light, textures))
        elif isinstance(light, SunLight):
            half_angle = math.radians(light.angular_diameter_deg) / 2
            sun_uniforms = {"sun_direction": light.unit_direction(), "sun_one_minus_cos": 2 * math.sin(half_angle / 2) ** 2,
                            "sun_radiance": tuple(float(v) for v in light.radiance())}
            # pbrt-v4's DistantLight::Phi: the irradiance falling on a disk of the scene's radius.
            entries.append(_LightEntry(LIGHT_SUN, math.pi * scene_radius**2 * luminance(light.irradiance),
                                       vector=light.unit_direction(), rgb=light.radiance(), **sun_at_infinity))
    env_uniforms, env_power = _environment_uniforms(environment, textures, scene_radius, environment_importance,
                                                    working_space)
    if env_power > 0:
        entries.append(_LightEntry(LIGHT_ENVIRONMENT, env_power, **at_infinity))
    total = sum(e.power for e in entries)
    pmfs = np.array([e.power / total for e in entries]) if total > 0 else np.zeros(len(entries))
    light_of_prim = np.full(n_prim, -1, np.int32)  # each primitive's row in the light table, or -1
    lights_table = np.zeros((len(entries), LIGHT_ROWS, 4), np.float32)
    for row, (entry, pmf, cdf) in enumerate(zip(entries, pmfs, np.cumsum(pmfs))):
        # An area light's primitive as the geometry buffer numbers it: after the mesh groups' triangles.
        prim_row = entry.prim + first_world_prim if entry.kind == LIGHT_AREA else entry.prim
        lights_table[row, 0] = (entry.kind, np.int32(prim_row).view(np.float32), cdf, pmf)
        lights_table[row, 1, :3], lights_table[row, 2, :3] = entry.vector, entry.rgb
        lights_table[row, 1, 3], lights_table[row, 2, 3] = entry.w
        if entry.kind == LIGHT_AREA:
            light_of_prim[entry.prim] = row
    if len(entries):
        lights_table[-1, 0, 2] = 1.0  # the last cumulative value is exactly 1, whatever the rounding
    # glsl/lights.glsl's LightPlaces block: (centre, reach^2) per light, then power share x falloff, four
    # lights to a row. Left empty when there are too many lights to choose among at each point.
    choose_at_point = len(entries) <= LIGHTS_AT_POINT_LIMIT
    light_choice = np.zeros((LIGHT_PLACES + LIGHT_PLACES // 4, 4), np.float32)
    if choose_at_point:
        for row, (entry, pmf) in enumerate(zip(entries, pmfs)):
            light_choice[row] = (*entry.vector, entry.reach2)
            light_choice[LIGHT_PLACES + row // 4, row % 4] = pmf * entry.falloff
    env_row = next((row for row, e in enumerate(entries) if e.kind == LIGHT_ENVIRONMENT), -1)
    sun_row = next((row for row, e in enumerate(entries) if e.kind == LIGHT_SUN), -1)

    triangle_geometry, shading = triangle_rows(flat.triangles, flat.triangle_normals, flat.triangle_uvs,
                                               material_ids[:n_tri], light_of_prim[:n_tri])
    geometry = np.zeros((n_prim, GEOMETRY_ROWS, 4), np.float32)
    geometry[:n_tri] = triangle_geometry
    geometry[n_tri:, 0] = flat.spheres
    geometry[n_tri:, 1, 3] = material_ids[n_tri:].view(np.float32)
    geometry[n_tri:, 2, 3] = light_of_prim[n_tri:].view(np.float32)
    layers = join_layers(packed_groups, flat, kdtree, geometry, shading, group_cache)

    material_rows = MaterialTable(flat.materials, textures, flat.material_names).rows()

    def at_least_one(a):  # GL refuses zero-sized buffers
        if isinstance(a, tuple):
            parts = tuple(np.ascontiguousarray(part) for part in a)
            return parts if sum(part.nbytes for part in parts) else (np.zeros(4, parts[-1].dtype),)
        return a if a.size else np.zeros(4, a.dtype)

    arrays = {
        "kd_nodes": layers.kd_nodes,
        "prim_refs": layers.prim_refs,
        "geometry": layers.geometry,
        "shading": layers.shading,
        "instances": layers.instances,
        "materials": np.concatenate([material_rows, textures.records()]).astype(np.float32),
        "lights": lights_table.reshape(-1, 4),
        "light_choice": light_choice,
        "image_data": textures.texels(),
    }
    arrays = {name: at_least_one(a if isinstance(a, tuple) else np.ascontiguousarray(a)) for name, a in arrays.items()}
    uniforms = {
        "triangle_count": layers.triangle_count,
        "scene_min": tuple(float(v) for v in kdtree.bounds[0]),
        "scene_max": tuple(float(v) for v in kdtree.bounds[1]),
        "world_root": layers.world_root,
        "instance_root": layers.instance_root,
        "instances_min": tuple(float(v) for v in (layers.instance_tree.bounds[0] if layers.instance_tree else (0, 0, 0))),
        "instances_max": tuple(float(v) for v in (layers.instance_tree.bounds[1] if layers.instance_tree else (0, 0, 0))),
        "instance_count": len(flat.instances),
        "light_count": len(entries),
        "env_light": env_row,
        "sun_light": sun_row,
        "lights_at_point": int(choose_at_point),
        "texture_base": len(material_rows),
        **env_uniforms,
        **sun_uniforms,
    }
    tree_warnings = [_reference_budget_warning(tree) for tree in (*(g.tree for g in packed_groups), kdtree)
                     if tree.budget_leaves]
    return PackedScene(arrays, uniforms, kdtree, sum(len(part) for part in layers.geometry),
                       (*tree_warnings, *textures.warnings),
                       group_trees=tuple(g.tree for g in packed_groups), first_world_prim=layers.first_world_prim,
                       instance_materials=tuple(i.material for i in flat.instances))


class GpuScene:
    """The packed scene uploaded to a GL context; releases its buffers when done.

    Made from the ``previous`` GpuScene of the same session (an edit), it keeps each buffer whose parts are the
    same arrays as before and rewrites only the parts from the first that changed, in place where the buffer is
    large enough: after a material edit or a move, a mesh group's rows and tree are not uploaded again."""

    def __init__(self, ctx, packed: PackedScene, max_block_bytes: int, previous: GpuScene | None = None):
        too_big = {name: buffer_bytes(a) for name, a in packed.arrays.items() if buffer_bytes(a) > max_block_bytes}
        if too_big:
            name, size = max(too_big.items(), key=lambda item: item[1])
            raise SceneTooLarge(
                f"the scene needs {format_bytes(size)} of {name.replace('_', ' ')} in one storage buffer, "
                f"more than this GL device allows ({format_bytes(max_block_bytes)}); "
                + ("use smaller image textures or environment map" if name == "image_data" else
                   f"simplify the meshes ({packed.uniforms['triangle_count']:,} triangles now)")
            )
        self.packed = packed
        self.ctx = ctx
        make_current(ctx)
        self.buffers = {}
        self.uploaded_bytes = 0  # what this scene sent to the device (the rest was kept from the previous one)
        try:
            for name, value in packed.arrays.items():
                self.buffers[name] = self._upload(name, buffer_parts(value), previous)
        except Exception:
            # Some of the previous scene's buffers may be this one's now, or half rewritten: neither is usable.
            self.release()
            if previous is not None:
                previous.release()
            raise

    def _upload(self, name: str, parts: tuple[np.ndarray, ...], previous: GpuScene | None):
        total = sum(part.nbytes for part in parts)
        kept = 0  # leading parts that are the very arrays the previous scene uploaded
        if previous is not None and name in previous.buffers:
            old = buffer_parts(previous.packed.arrays[name])
            while kept < min(len(parts), len(old)) and parts[kept] is old[kept]:
                kept += 1
            buffer = previous.buffers[name]
            if kept == len(parts) == len(old):
                return previous.buffers.pop(name)
            if kept and buffer.size >= total:
                previous.buffers.pop(name)
                self._write(buffer, parts, kept)
                return buffer
        buffer = self.ctx.buffer(reserve=total)
        self._write(buffer, parts, 0)
        return buffer

    def _write(self, buffer, parts: tuple[np.ndarray, ...], first: int) -> None:
        offset = sum(part.nbytes for part in parts[:first])
        for part in parts[first:]:
            if part.nbytes:
                buffer.write(part, offset=offset)  # pack_scene made every part contiguous
            offset += part.nbytes
            self.uploaded_bytes += part.nbytes

    def bind(self) -> None:  # callers (RenderSession.step, cast_rays) have made the context current
        for name, buffer in self.buffers.items():
            if name in UNIFORM_BINDINGS:
                buffer.bind_to_uniform_block(UNIFORM_BINDINGS[name])
            else:
                buffer.bind_to_storage_buffer(BINDINGS[name])

    def release(self) -> None:
        if self.buffers:
            make_current(self.ctx)
        for buffer in self.buffers.values():
            buffer.release()
        self.buffers = {}
