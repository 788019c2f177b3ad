"""Photometric light units: every conversion from the unit an emitter is written in to what the renderer carries
(docs/colour.md, "Light units").

The convention: scene-linear values are photometric. An RGB whose luminance (in the scene's working space) is 1
means 1 cd/m^2 (a nit) as a radiance, 1 cd as a point or spot light's intensity, 1 lux as a sun's irradiance. An
emitter written in another unit gives its amount as the luminance of its RGB, the RGB being the light's colour
scaled to it: an area light of (1361, 961, 320) "lumens" emits 1000 lm of a warm white. Legacy scenes name no
unit and keep their numbers (nits, candela, a map's plain scale), and so does every Mitsuba import: a scene in
arbitrary units renders as it always did in the compensated exposure.

Each emitter is converted once, when the scene is flattened for the renderer (area lights: scene/flatten.py, which
knows the world-space area) or packed (lights and the environment: render/buffers.py, which reads the map). The
formulas and where they come from:

* area light in lumens, flux Phi over world-space area A: L = Phi / (pi A) for a Lambertian emitter, whose flux
  is pi L A from each side it emits from (two-sided: L = Phi / (2 pi A)). Unity HDRP's rectangle and disc lights.
* point light in lumens: I = Phi / (4 pi), the flux spread over the whole sphere (HDRP, Unreal, Blender).
* spot light in lumens: I = Phi / Omega, Omega the cone's falloff integrated over the sphere
  (SpotLight.weighted_solid_angle): all of the flux leaves through the cone, so narrowing the cone brightens it,
  as a reflector behind the bulb would. Unity HDRP's spot "reflector" option does the same; without it HDRP
  divides by 4 pi, as a bare bulb in a shade that absorbs the rest.
* a sun's irradiance is lux already (on a surface facing the sun), the unit daylight is measured in.
* sky (constant environment) as an EV: EV100 is an exposure value at ISO 100, and the luminance a reflected-light
  meter reads for it is L = (K / 100) 2^EV, K = 12.5 cd s/m^2 (ISO 2720; HDRP's ConvertEvToLuminance,
  2^(EV - 3)). EV 0 is 0.125 cd/m^2, EV 15 (a sunlit scene) 4096 cd/m^2.
* environment map in nits or EV: the image is scaled so that its mean luminance over the sphere (weighted by
  solid angle) is the nits given, or the luminance of the EV given.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE, luminance
from lenslab.optics.exposure import ev100_to_luminance
from lenslab.scene.fields import declared_choices
from lenslab.scene.lights import Light, PointLight, SpotLight
from lenslab.scene.materials import Emissive, Material, inner_materials
from lenslab.scene.scene import ConstantEnvironment, Environment, EnvironmentMap

RGB = tuple[float, float, float]

#: The units each emitter may be written in, as its ``unit`` field declares them; the first is the default (what a
#: legacy or imported scene means).
EMISSIVE_UNITS = declared_choices(Emissive, "unit")
POINT_UNITS = declared_choices(PointLight, "unit")
SPOT_UNITS = declared_choices(SpotLight, "unit")
CONSTANT_ENVIRONMENT_UNITS = declared_choices(ConstantEnvironment, "unit")
ENVIRONMENT_MAP_UNITS = declared_choices(EnvironmentMap, "unit")


# -- the formulas -------------------------------------------------------------------------------------------------
def area_lumens_to_nits(rgb: RGB, area_m2: float, two_sided: bool = False) -> RGB:
    """The radiance (cd/m^2) of a Lambertian emitter of total flux ``rgb`` (lm) over ``area_m2``: Phi / (pi A),
    halved when it emits from both faces (each side then carries half the flux)."""
    sides = 2.0 if two_sided else 1.0
    return _scaled(rgb, 1.0 / (sides * math.pi * area_m2))


def point_lumens_to_candela(rgb: RGB) -> RGB:
    """The intensity (cd) of a point light of flux ``rgb`` (lm): Phi / (4 pi)."""
    return _scaled(rgb, 1.0 / (4.0 * math.pi))


def spot_lumens_to_candela(rgb: RGB, weighted_solid_angle_sr: float) -> RGB:
    """The intensity (cd) on the axis of a spot of flux ``rgb`` (lm) whose falloff integrates to
    ``weighted_solid_angle_sr`` over the sphere: Phi / Omega (the whole flux leaves through the cone)."""
    return _scaled(rgb, 1.0 / weighted_solid_angle_sr)


def ev_colour_to_nits(rgb: RGB, space: str = DEFAULT_WORKING_SPACE) -> RGB:
    """The radiance (cd/m^2) of a sky written as an EV: the colour ``rgb`` normalised to luminance 1, times
    ev100_to_luminance of its luminance. A colour of no luminance gives no light (an EV of 0 is 0.125 cd/m^2:
    write so dim a sky in nits)."""
    ev = float(luminance(rgb, space))
    if ev <= 0.0:
        return (0.0, 0.0, 0.0)
    return _scaled(rgb, ev100_to_luminance(ev) / ev)


def sphere_mean_luminance(pixels: np.ndarray, rows: str = "centred", space: str = DEFAULT_WORKING_SPACE) -> float:
    """The mean luminance over the sphere of a lat-long image (H, W, 3), each pixel weighted by its solid angle:
    row i covers the band of polar angles theta_i -+ d/2 (clipped to the poles), cos(top) - cos(bottom) of the
    sphere; theta_i = pi (i + 1/2) / H, d = pi / H for ``centred`` rows (the weight is then sin theta_i, as
    render/environment.py's power), theta_i = pi i / (H - 1), d = pi / (H - 1) for ``pole_to_pole``."""
    height = pixels.shape[0]
    if rows == "pole_to_pole" and height > 1:
        centres, width = math.pi * np.arange(height) / (height - 1), math.pi / (height - 1)
    else:
        centres, width = math.pi * (np.arange(height) + 0.5) / height, math.pi / height
    top, bottom = np.clip(centres - width / 2, 0.0, math.pi), np.clip(centres + width / 2, 0.0, math.pi)
    band = np.cos(top) - np.cos(bottom)
    row_means = luminance(np.asarray(pixels, np.float64)[..., :3], space).mean(axis=1)
    return float((row_means * band).sum() / band.sum())


def environment_map_scale(strength: float, unit: str, mean_luminance: float) -> float:
    """What an environment map's pixels are multiplied by: ``strength`` itself (``scale``), or the factor that
    makes the map's ``mean_luminance`` (sphere_mean_luminance) ``strength`` cd/m^2 (``nits``) or the luminance
    of EV ``strength`` (``ev``). A black map stays black."""
    _check_unit("environment map", unit, ENVIRONMENT_MAP_UNITS)
    if unit == "scale":
        return float(strength)
    target = ev100_to_luminance(strength) if unit == "ev" else float(strength)
    return target / mean_luminance if mean_luminance > 0.0 else 0.0


def areas_by_material(triangles: np.ndarray, triangle_material: np.ndarray, spheres: np.ndarray,
                      sphere_material: np.ndarray, count: int) -> np.ndarray:
    """(count,) world-space area (m^2) of the triangles (T, 3, 3) and spheres (S, 4: centre, radius) that carry
    each material: what an area light's lumens are spread over."""
    t = np.asarray(triangles, np.float64).reshape(-1, 3, 3)
    triangle_area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    sphere_area = 4.0 * math.pi * np.asarray(spheres, np.float64).reshape(-1, 4)[:, 3] ** 2
    return (np.bincount(np.asarray(triangle_material, np.int64), triangle_area, minlength=count)[:count]
            + np.bincount(np.asarray(sphere_material, np.int64), sphere_area, minlength=count)[:count])


# -- the scene's emitters, converted --------------------------------------------------------------------------------
def emissive_in_nits(material: Material, area_m2: float) -> Material:
    """``material`` with every light it is or holds in nits, a light in lumens spread over ``area_m2`` (the area
    of all the shapes carrying the material). One carried by no surface emits nothing, in any unit."""
    if isinstance(material, Emissive) and material.unit != "nits":
        _check_unit("emissive", material.unit, EMISSIVE_UNITS)
        radiance = area_lumens_to_nits(material.radiance, area_m2, material.two_sided) if area_m2 > 0 else (0.0,) * 3
        material = dataclasses.replace(material, radiance=radiance, unit="nits")
    if not inner_materials(material):
        return material
    held = {f.name: getattr(material, f.name) for f in dataclasses.fields(material)
            if isinstance(getattr(material, f.name), Material)}
    changed = {name: converted for name, inner in held.items()
               if (converted := emissive_in_nits(inner, area_m2)) is not inner}
    return dataclasses.replace(material, **changed) if changed else material  # untouched where nothing changed


def light_in_candela(light: Light) -> Light:
    """A point or spot light with its intensity in candela; any other light as it is."""
    if isinstance(light, PointLight) and light.unit != "candela":
        _check_unit(f"point light '{light.name}'", light.unit, POINT_UNITS)
        return dataclasses.replace(light, intensity=point_lumens_to_candela(light.intensity), unit="candela")
    if isinstance(light, SpotLight) and light.unit != "candela":
        _check_unit(f"spot light '{light.name}'", light.unit, SPOT_UNITS)
        intensity = spot_lumens_to_candela(light.intensity, light.weighted_solid_angle())
        return dataclasses.replace(light, intensity=intensity, unit="candela")
    return light


def environment_in_nits(environment: Environment, space: str = DEFAULT_WORKING_SPACE) -> Environment:
    """A constant environment with its radiance in nits; a map as it is (its scale needs its image:
    environment_map_scale), once its strength is checked against its unit."""
    if isinstance(environment, ConstantEnvironment) and environment.unit != "nits":
        _check_unit("environment", environment.unit, CONSTANT_ENVIRONMENT_UNITS)
        return dataclasses.replace(environment, radiance=ev_colour_to_nits(environment.radiance, space), unit="nits")
    if isinstance(environment, EnvironmentMap):
        check_environment_map(environment)
    return environment


def check_environment_map(environment: EnvironmentMap) -> None:
    """A ValueError for a strength its unit cannot take: only an EV may be negative."""
    _check_unit("environment", environment.unit, ENVIRONMENT_MAP_UNITS)
    if environment.unit != "ev" and not environment.strength >= 0.0:
        raise ValueError(f"environment strength {environment.strength:g} is negative: only an EV (unit 'ev') may be "
                         f"(a strength in '{environment.unit}' is at least 0)")


def _check_unit(what: str, unit: str, units: tuple[str, ...]) -> None:
    """Scenes made in code skip the file reader's check of the choices: name the unit here too."""
    if unit not in units:
        raise ValueError(f"{what}: unknown unit '{unit}' (choose from {', '.join(units)})")


def _scaled(rgb, factor: float) -> RGB:
    return tuple(float(c) * factor for c in rgb)  # type: ignore[return-value]
