"""The trace kernel specialised to a scene's features renders what the general kernel renders."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lenslab.render.buffers import MATERIAL_CODES, pack_scene
from lenslab.render.features import GENERAL, scene_features
from lenslab.render.tracer import RenderSession
from lenslab.scene.io.loader import open_scene
from lenslab.scene.materials import Conductor, Dielectric, Diffuse, Emissive

SHIPPED = ("cornell_box", "dof_chart", "product_shot", "cornell_caustic")


def features_of(name):
    scene = open_scene(name)
    packed = pack_scene(scene.flatten(), scene.environment, base_dir=scene.base_dir(), lights=scene.lights)
    return scene_features(packed)


def test_the_cornell_box_needs_only_triangles_diffuse_walls_and_its_ceiling_light():
    features = features_of("cornell_box")
    assert features.material_types == {MATERIAL_CODES[Diffuse], MATERIAL_CODES[Emissive]}
    assert features.area_lights
    assert not (features.spheres or features.textures or features.environment_map or features.point_lights
                or features.sun or features.environment_light)


def test_the_product_shot_keeps_its_environment_map_and_every_material_it_uses():
    scene = open_scene("product_shot")
    features = features_of("product_shot")
    assert features.environment_map and features.environment_light
    used = {MATERIAL_CODES[type(scene.materials[name])] for name in scene.materials}
    assert used <= features.material_types  # every type the scene declares and uses is compiled in
    assert {MATERIAL_CODES[Dielectric], MATERIAL_CODES[Conductor]} <= features.material_types
    assert features != GENERAL


def render(renderer, scene, spp, specialise):
    session = RenderSession(renderer, scene, width=48, height=32, specialise=specialise)
    while not session.done(spp):
        session.step(10.0, spp)
    image = session.image()
    session.release()
    return image


@pytest.mark.parametrize("name", SHIPPED)
def test_specialised_and_general_kernels_render_the_same_image(renderer, name):
    # The same seed draws the same random numbers in both kernels, so the images agree pixel by pixel up to
    # float rounding (a rounding can flip a Russian-roulette decision, so allow a few pixels to differ).
    scene = open_scene(name)
    scene = dataclasses.replace(scene, render=dataclasses.replace(scene.render, seed=3))
    specialised = render(renderer, scene, 8, True)
    general = render(renderer, scene, 8, False)
    assert specialised.mean() > 0.0
    close = np.isclose(specialised, general, rtol=1e-3, atol=1e-5).all(axis=-1)
    assert close.mean() > 0.99
    assert specialised.mean() == pytest.approx(general.mean(), rel=0.01)


def test_a_scene_without_lights_or_shapes_still_gets_a_kernel():
    from lenslab.scene.scene import Scene

    scene = Scene()
    packed = pack_scene(scene.flatten(), scene.environment, lights=scene.lights)
    features = scene_features(packed)
    assert not (features.area_lights or features.point_lights or features.sun or features.spheres)
    assert features.material_types == frozenset()
