"""Scene -> GPU storage buffers.

:func:`pack_scene` turns a flattened scene into the plain arrays that glsl/common.glsl declares (pure numpy,
testable without a GPU); :class:`GpuScene` uploads them to a context, checks them against the device's
storage-block limit and owns the buffers until :meth:`GpuScene.release`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lenslab.render.bsp import KdTree, build_kdtree
from lenslab.render.fresnel import internal_diffuse_reflectance
from lenslab.render.textures import TextureTable
from lenslab.scene.flatten import FlatScene
from lenslab.scene.materials import Conductor, Diffuse, Dielectric, Emissive, Material, Plastic, ThinDielectric
from lenslab.scene.scene import ConstantEnvironment, Environment

# glsl/bsdf.glsl's material type codes and record size.
MATERIAL_CODES = {Diffuse: 0, Emissive: 1, Conductor: 2, Plastic: 3, Dielectric: 4, ThinDielectric: 5}
MATERIAL_ROWS = 8

# Binding points, as declared in glsl/common.glsl, glsl/textures.glsl and glsl/trace.comp.
BINDINGS = {"kd_nodes": 0, "prim_refs": 1, "geometry": 2, "shading": 3, "materials": 4, "lights": 5, "image_data": 7}
ACCUMULATION_BINDING = 6


class SceneTooLarge(RuntimeError):
    """The scene's buffers exceed what the GL device allows in one storage block."""


def _size(nbytes: int) -> str:
    return f"{nbytes / 2**20:.1f} MiB" if nbytes >= 2**20 else f"{nbytes / 2**10:.0f} KiB"


def _luminance(rgb) -> float:
    r, g, b = rgb
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def pack_material(material: Material, textures: TextureTable) -> np.ndarray:
    """Eight vec4 rows, read by glsl/bsdf.glsl's bsdf_at():
    0 (albedo, type), 1 (emission, two-sided), 2 (eta rgb | ior, internal reflectance, -, alpha),
    3 (k rgb, albedo texture), 4 (specular tint, roughness texture), 5 (absorption per metre), 6-7 spare."""
    record = np.zeros((MATERIAL_ROWS, 4), np.float32)
    code = MATERIAL_CODES.get(type(material))
    if code is None:
        raise TypeError(f"no GPU packing for material type {type(material).__name__}")
    record[0, 3] = code
    record[3, 3] = record[4, 3] = -1.0  # no textures
    record[4, :3] = 1.0
    roughness = getattr(material, "roughness", 0.0)
    record[2, 3] = roughness**2  # GGX alpha from perceptual roughness
    if isinstance(material, (Diffuse, Plastic)):
        record[0, :3] = material.albedo
        record[3, 3] = textures.index_of(material.albedo_texture)
    if isinstance(material, (Conductor, Plastic)):
        record[4, 3] = textures.index_of(material.roughness_texture)
    if isinstance(material, Emissive):
        record[1, :3] = material.radiance
        record[1, 3] = 1.0 if material.two_sided else 0.0
    elif isinstance(material, Conductor):
        eta, k = material.complex_ior()
        record[2, :3], record[3, :3], record[4, :3] = eta, k, material.tint
    elif isinstance(material, Plastic):
        record[2, 0], record[2, 1] = material.ior, internal_diffuse_reflectance(material.ior)
    elif isinstance(material, Dielectric):
        record[2, 0] = material.ior
        record[4, :3] = material.tint
        record[5, :3] = material.absorption_coefficient()
    elif isinstance(material, ThinDielectric):
        record[2, 0] = material.ior
        record[4, :3] = material.tint
    return record


def _emitted_power(flat: FlatScene) -> np.ndarray:
    """Power (luminance-weighted, up to a constant) of every primitive; zero for non-emitters.

    A Lambertian emitter of radiance L and area A emits pi L A per side: the weights for choosing a light.
    """
    power = np.zeros(flat.prim_count, np.float64)
    for index, material in enumerate(flat.materials):
        if not (isinstance(material, Emissive) and material.emits):
            continue
        sides = 2.0 if material.two_sided else 1.0
        radiance = _luminance(material.radiance) * sides * math.pi
        tri = np.flatnonzero(flat.triangle_material == index)
        if len(tri):
            t = flat.triangles[tri].astype(np.float64)
            area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
            power[tri] = radiance * area
        sph = np.flatnonzero(flat.sphere_material == index)
        if len(sph):
            power[flat.triangle_count + sph] = radiance * 4.0 * math.pi * flat.spheres[sph, 3].astype(np.float64) ** 2
    return power


def _environment_power(environment: Environment, scene_radius: float) -> float:
    # pbrt-v4's UniformInfiniteLight::Phi: 4 pi^2 r^2 L for a scene of bounding radius r.
    if isinstance(environment, ConstantEnvironment):
        return 4.0 * math.pi**2 * scene_radius**2 * _luminance(environment.radiance)
    return 0.0


@dataclass(frozen=True)
class PackedScene:
    """Everything the trace kernel reads about the scene, as arrays and uniform values."""

    arrays: dict[str, np.ndarray]
    uniforms: dict[str, object]
    kdtree: KdTree
    warnings: tuple[str, ...] = ()  # problems the render survives (a missing texture): show them to the user

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in self.arrays.values())


def pack_scene(flat: FlatScene, environment: Environment, kdtree: KdTree | None = None,
               base_dir: Path | None = None) -> PackedScene:
    """Arrays and uniforms for the trace kernel; ``base_dir`` resolves relative texture paths."""
    if kdtree is None:
        kdtree = build_kdtree(flat.prim_bounds(), triangles=flat.triangles)
    n_tri, n_prim = flat.triangle_count, flat.prim_count
    material_ids = np.concatenate([flat.triangle_material, flat.sphere_material]).astype(np.int32)

    # Light selection: environment by its power against the sum of the area lights'.
    power = _emitted_power(flat)
    bounds = flat.bounds()
    scene_radius = max(0.5 * float(np.linalg.norm(bounds[1] - bounds[0])), 1e-3)
    env_power = _environment_power(environment, scene_radius)
    total = env_power + power.sum()
    env_pmf = env_power / total if total > 0 else 0.0
    prim_pmf = power / total if total > 0 else power

    geometry = np.zeros((n_prim, 3, 4), np.float32)
    tris = flat.triangles
    geometry[:n_tri, 0, :3] = tris[:, 0]
    geometry[:n_tri, 1, :3] = tris[:, 1] - tris[:, 0]
    geometry[:n_tri, 2, :3] = tris[:, 2] - tris[:, 0]
    geometry[n_tri:, 0] = flat.spheres
    geometry[:, 1, 3] = material_ids.view(np.float32)
    geometry[:, 2, 3] = prim_pmf

    shading = np.zeros((n_tri, 4, 4), np.float32)
    shading[:, :3, :3] = flat.triangle_normals
    uv = flat.triangle_uvs.reshape(n_tri, 6)  # u0 v0 u1 v1 u2 v2
    shading[:, 0, 3], shading[:, 1, 3], shading[:, 2, 3] = uv[:, 0], uv[:, 1], uv[:, 2]
    shading[:, 3, :3] = uv[:, 3:6]

    emitters = np.flatnonzero(power > 0).astype(np.int32)
    lights = np.zeros((len(emitters), 4), np.float32)
    lights[:, 0] = emitters.view(np.float32)
    lights[:, 1] = np.cumsum(prim_pmf[emitters])
    lights[:, 2] = prim_pmf[emitters]

    textures = TextureTable(base_dir or Path.cwd())
    materials = [pack_material(m, textures) for m in flat.materials] or [np.zeros((MATERIAL_ROWS, 4), np.float32)]
    material_rows = np.concatenate(materials)
    env_radiance = environment.radiance if isinstance(environment, ConstantEnvironment) else (0.0, 0.0, 0.0)

    def at_least_one(a: np.ndarray) -> np.ndarray:  # GL refuses zero-sized buffers
        return a if a.size else np.zeros(4, a.dtype)

    arrays = {
        "kd_nodes": kdtree.nodes.astype(np.uint32),
        "prim_refs": kdtree.prim_refs.astype(np.int32),
        "geometry": geometry,
        "shading": shading,
        "materials": np.concatenate([material_rows, textures.records()]).astype(np.float32),
        "lights": lights,
        "image_data": textures.texels(),
    }
    arrays = {name: at_least_one(np.ascontiguousarray(a)) for name, a in arrays.items()}
    uniforms = {
        "triangle_count": n_tri,
        "prim_count": n_prim,
        "scene_min": tuple(float(v) for v in kdtree.bounds[0]),
        "scene_max": tuple(float(v) for v in kdtree.bounds[1]),
        "light_count": len(emitters),
        "env_select_pmf": float(env_pmf),
        "env_radiance": tuple(float(v) for v in env_radiance),
        "texture_base": len(material_rows),
    }
    return PackedScene(arrays, uniforms, kdtree, tuple(textures.warnings))


class GpuScene:
    """The packed scene uploaded to a GL context; releases its buffers when done."""

    def __init__(self, ctx, packed: PackedScene, max_block_bytes: int):
        too_big = {name: a.nbytes for name, a in packed.arrays.items() if a.nbytes > max_block_bytes}
        if too_big:
            name, size = max(too_big.items(), key=lambda item: item[1])
            raise SceneTooLarge(
                f"the scene needs {_size(size)} of {name.replace('_', ' ')} in one storage buffer, "
                f"more than this GL device allows ({_size(max_block_bytes)}); "
                f"simplify the meshes ({packed.uniforms['triangle_count']:,} triangles now)"
            )
        self.packed = packed
        self.buffers = {name: ctx.buffer(a.tobytes()) for name, a in packed.arrays.items()}

    def bind(self) -> None:
        for name, buffer in self.buffers.items():
            buffer.bind_to_storage_buffer(BINDINGS[name])

    def release(self) -> None:
        for buffer in self.buffers.values():
            buffer.release()
        self.buffers = {}
