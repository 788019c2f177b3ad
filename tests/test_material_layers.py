"""Materials that hold materials, against closed-form answers: a light whose surface also reflects, a blend,
a cut-out mask, bump and normal maps (scene/materials.py, glsl/bsdf.glsl's resolve_material, glsl/mask.glsl).
Mitsuba's images of the same features are compared in `lenslab validate` (light_bsdf, materials)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenslab.render.buffers import MaterialTable, held_materials, pack_scene
from lenslab.render.features import scene_features
from lenslab.render.gpu_layout import MATERIAL_NESTING, MATERIAL_ROWS
from lenslab.render.textures import TextureTable
from lenslab.render.tracer import RenderSession
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.lights import SunLight
from lenslab.scene.materials import Blend, BumpMap, Conductor, Diffuse, Emissive, Mask, NormalMap
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene, SceneError
from lenslab.scene.shapes import Rectangle, Sphere
from lenslab.scene.textures import Checkerboard, ImageTexture
from lenslab.scene.transform import Transform
from tests.helpers import render_to_spp
from tests.scenes import FIXED_SENSOR

SUN = 3.0  # irradiance on a surface facing the sun


def render(renderer, scene, spp, specialise=True):
    session = RenderSession(renderer, scene, specialise=specialise)
    accumulation = render_to_spp(session, spp).accumulation()
    session.release()
    return accumulation[..., :3] / accumulation[..., 3:4]


def facing_a_square(material, sun_towards=(0.0, 0.0, 1.0), sky=0.0, resolution=(24, 24)) -> Scene:
    """A 2 m square facing the camera (+Z, u along +X, v along +Y), filling the central part of the view, lit by
    a sun: a diffuse square of albedo a shows a SUN cos(n, sun) / pi."""
    return Scene(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 0, 4), look_at=(0, 0, 0), focal_length_mm=120,
                              f_number=16, focus_distance_m=4, resolution=resolution),
        environment=ConstantEnvironment((sky, sky, sky)),
        render=RenderSettings(max_depth=2, sampler="independent"),
        lights=[SunLight(name="sun", direction=sun_towards, irradiance=(SUN, SUN, SUN), angular_diameter_deg=0.0)],
        materials={"square": material},
        nodes=[Node("square", Transform(), Rectangle((2.0, 2.0)), "square")],
    )


def centre(image, fraction=0.5):
    h, w = image.shape[:2]
    dy, dx = int(h * fraction / 2), int(w * fraction / 2)
    return image[h // 2 - dy: h // 2 + dy, w // 2 - dx: w // 2 + dx]


def write_exr(path, pixels):
    import OpenImageIO as oiio

    pixels = np.ascontiguousarray(pixels, np.float32)
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(pixels.shape[1], pixels.shape[0], 3, oiio.FLOAT))
    out.write_image(pixels)
    out.close()
    return str(path)


# -- lights that reflect ---------------------------------------------------------------------------------
@pytest.mark.parametrize("albedo", [0.0, 0.5, 0.8])
def test_inside_a_glowing_diffuse_sphere_radiance_is_emission_over_one_minus_albedo(renderer, albedo):
    # Every point of the sphere's inside emits Le and reflects albedo times what it receives, which is the
    # same radiance L from everywhere: L = Le + albedo L, so L = Le / (1 - albedo) (an infinite sum of
    # bounces). Next-event estimation aims at the light the path stands on, and MIS and Russian roulette
    # must still weigh every bounce right.
    light = Emissive(radiance=(1.0, 1.0, 1.0), two_sided=True, surface=Diffuse((albedo,) * 3) if albedo else None)
    scene = Scene(
        camera=ThinLensCamera(position=(0, 0, 0), look_at=(0, 0, -1), focal_length_mm=35, f_number=8,
                              focus_distance_m=1.0, resolution=(16, 16)),
        environment=ConstantEnvironment((0.0, 0.0, 0.0)),
        render=RenderSettings(max_depth=1024, rr_depth=3),
        materials={"glow": light},
        nodes=[Node("room", Transform(), Sphere(1.0), "glow")],
    )
    image = render(renderer, scene, 128)
    assert image.mean() == pytest.approx(1.0 / (1.0 - albedo), rel=0.02)


def test_a_light_without_a_surface_reflects_nothing(renderer):
    # The same light under a sun, seen from its back where it does not emit: black without a surface,
    # lit like any diffuse surface with one.
    dark = render(renderer, facing_a_square(Emissive(radiance=(5.0, 5.0, 5.0)), sun_towards=(0, 0, 1)), 16)
    lit = render(renderer, facing_a_square(Emissive(radiance=(0.0, 0.0, 0.0), surface=Diffuse((0.6, 0.6, 0.6)))), 16)
    # The camera sees the front (+Z), which emits: 5 with no surface, the sun's light with one.
    assert centre(dark).mean() == pytest.approx(5.0, rel=1e-4)
    assert centre(lit).mean() == pytest.approx(0.6 * SUN / math.pi, rel=0.01)


# -- blends ---------------------------------------------------------------------------------------------------
def test_a_blend_shades_as_the_weighted_mean_of_its_two_materials(renderer):
    blend = Blend(first=Diffuse((0.2, 0.2, 0.2)), second=Diffuse((0.8, 0.4, 0.0)), weight=0.25)
    image = centre(render(renderer, facing_a_square(blend), 256))
    expected = (0.75 * np.array([0.2, 0.2, 0.2]) + 0.25 * np.array([0.8, 0.4, 0.0])) * SUN / math.pi
    np.testing.assert_allclose(image.mean(axis=(0, 1)), expected, rtol=0.02, atol=1e-3)


def test_a_blends_weight_texture_picks_per_point(renderer):
    # A checkerboard weight: 0 on one colour's squares (all first material), 1 on the other's (all second).
    weight = Checkerboard(color_a=(0.0, 0.0, 0.0), color_b=(1.0, 1.0, 1.0), tiles=(2.0, 2.0))
    blend = Blend(first=Diffuse((0.2, 0.2, 0.2)), second=Diffuse((0.9, 0.9, 0.9)), weight_texture=weight)
    image = render(renderer, facing_a_square(blend, resolution=(32, 32)), 16)[..., 0]
    lit = image[image > 0]
    levels = np.array([0.2, 0.9]) * SUN / math.pi
    nearest = np.abs(lit[:, None] - levels[None]).min(axis=1)
    assert np.mean(nearest < 0.01 * levels.max()) > 0.9  # every pixel is one of the two (edges blur a few)
    assert (np.abs(lit - levels[0]) < 0.01).sum() > 50 and (np.abs(lit - levels[1]) < 0.03).sum() > 50


# -- masks ----------------------------------------------------------------------------------------------------
def test_a_mask_lets_the_sky_through_in_proportion(renderer):
    # A black square of opacity 0.3 in front of a sky of radiance 1: 70% of the rays reach the sky.
    image = centre(render(renderer, facing_a_square(Mask(material=Diffuse((0.0, 0.0, 0.0)), opacity=0.3),
                                                    sky=1.0), 256))
    assert image.mean() == pytest.approx(0.7, abs=0.01)


def test_a_mask_casts_a_partial_shadow(renderer):
    # A masked black pane of opacity 0.4 between the sun and a white floor passes 60% of the sunlight:
    # shadow rays see the cut-out as camera rays do.
    def scene(opacity):
        s = facing_a_square(Diffuse((1.0, 1.0, 1.0)))
        s.materials["pane"] = Mask(material=Diffuse((0.0, 0.0, 0.0)), opacity=opacity)
        # The pane sits between the square and the sun (+Z) but outside the camera's view (behind it).
        s.nodes.append(Node("pane", Transform(translate=(0.0, 0.0, 6.0)), Rectangle((50.0, 50.0)), "pane"))
        s.camera.position = (0, 0, 4)
        return s

    open_sky = centre(render(renderer, scene(0.0), 64)).mean()
    shadowed = centre(render(renderer, scene(0.4), 256)).mean()
    assert open_sky == pytest.approx(SUN / math.pi, rel=1e-3)
    assert shadowed == pytest.approx(0.6 * SUN / math.pi, rel=0.02)


# -- bump and normal maps ------------------------------------------------------------------------------------
def tilted_normal(slope_u: float, width_m: float = 2.0) -> np.ndarray:
    """The shading normal of the square (+Z, dp/du = width along +X) under a height of slope dh/du: the
    tangent dp/du + n dh/du crossed with dp/dv tilts n towards -X by atan(slope / width)."""
    n = np.array([-slope_u, 0.0, width_m])
    return n / np.linalg.norm(n)


@pytest.mark.parametrize("sun", [(-1.0, 0.0, 2.0), (0.0, 0.0, 1.0), (1.0, 0.0, 2.0)])
def test_a_bump_map_tilts_the_shading_normal_by_the_heights_slope(renderer, tmp_path, sun):
    # A height ramp h = u (texel i holds (i + 1/2) / 64: exactly u between texel centres) with scale 1.
    ramp = np.broadcast_to(((np.arange(64) + 0.5) / 64)[None, :, None], (8, 64, 3))
    texture = ImageTexture(file=write_exr(tmp_path / "ramp.exr", ramp), color_space="linear")
    bumped = BumpMap(material=Diffuse((1.0, 1.0, 1.0)), texture=texture, scale=1.0)
    image = centre(render(renderer, facing_a_square(bumped, sun_towards=sun), 4), 0.6)
    d = np.array(sun) / np.linalg.norm(sun)
    expected = SUN / math.pi * max(0.0, float(tilted_normal(1.0) @ d))
    assert image.mean() == pytest.approx(expected, rel=0.01)


@pytest.mark.parametrize("sun", [(-1.0, 0.0, 2.0), (1.0, 0.0, 2.0)])
def test_a_normal_map_sets_the_shading_normal_in_the_tangent_frame(renderer, tmp_path, sun):
    n = tilted_normal(1.0)  # in the tangent frame (x along dp/du, z out of the surface) = world here
    colour = np.broadcast_to(((n + 1) / 2)[None, None, :], (4, 4, 3))
    texture = ImageTexture(file=write_exr(tmp_path / "normals.exr", colour), color_space="linear")
    mapped = NormalMap(material=Diffuse((1.0, 1.0, 1.0)), texture=texture)
    image = centre(render(renderer, facing_a_square(mapped, sun_towards=sun), 4))
    d = np.array(sun) / np.linalg.norm(sun)
    assert image.mean() == pytest.approx(SUN / math.pi * max(0.0, float(n @ d)), rel=0.01)


def test_a_flat_normal_map_changes_nothing(renderer, tmp_path):
    flat = np.broadcast_to(np.array([0.5, 0.5, 1.0])[None, None, :], (4, 4, 3))
    texture = ImageTexture(file=write_exr(tmp_path / "flat.exr", flat), color_space="linear")
    plain = centre(render(renderer, facing_a_square(Diffuse((0.5, 0.5, 0.5)), sun_towards=(1, 0, 2)), 4))
    mapped = centre(render(renderer, facing_a_square(NormalMap(material=Diffuse((0.5, 0.5, 0.5)), texture=texture),
                                                     sun_towards=(1, 0, 2)), 4))
    np.testing.assert_allclose(mapped, plain, rtol=1e-4)


# -- packing -----------------------------------------------------------------------------------------------
def test_held_materials_follow_their_holders_and_the_kernel_knows_them(tmp_path):
    inner = Conductor(roughness=0.3, distribution="beckmann")
    outer = Mask(material=Blend(first=Diffuse(), second=inner), opacity=0.5)
    table = MaterialTable([outer, Diffuse()], TextureTable(base_dir=tmp_path))
    rows = table.rows().reshape(-1, MATERIAL_ROWS, 4)
    assert len(rows) == 5  # the two named, then the blend, its first and its second
    assert held_materials(rows, [0]) == {0, 2, 3, 4} and held_materials(rows, [1]) == {1}
    scene = facing_a_square(outer)
    features = scene_features(pack_scene(scene.flatten(), scene.environment))
    assert features.nested_materials
    plain = facing_a_square(Diffuse())
    assert not scene_features(pack_scene(plain.flatten(), plain.environment)).nested_materials


def test_materials_nested_too_deep_are_refused_by_name(tmp_path):
    material = Diffuse()
    for _ in range(MATERIAL_NESTING):
        material = Mask(material=material, opacity=1.0)
    with pytest.raises(SceneError, match="material 'deep': materials nest more than"):
        MaterialTable([material], TextureTable(base_dir=tmp_path), ["deep"])


@pytest.mark.slow  # compiles the general kernel: minutes on llvmpipe with a cold shader cache
def test_specialised_and_general_kernels_agree_on_layered_materials(renderer):
    blend = Blend(first=Mask(material=Diffuse((0.7, 0.2, 0.2)), opacity=0.6),
                  second=Conductor(roughness=0.5, distribution="beckmann"), weight=0.4)
    scene = facing_a_square(blend, sun_towards=(0.3, 0.2, 1.0), sky=0.5)
    a, b = render(renderer, scene, 8, True), render(renderer, scene, 8, False)
    assert a.mean() > 0
    assert np.mean(np.abs(a - b) > 1e-4 * (1 + np.abs(b))) < 0.02
