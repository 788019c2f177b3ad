"""The trace kernel specialised to a scene's features renders what the general kernel renders."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lenslab.render.buffers import MATERIAL_CODES, pack_scene
from lenslab.render.bsp import build_kdtree
from lenslab.render.features import FLAT_MAX_PRIMITIVES, GENERAL, renders_flat, scene_features
from lenslab.render.tracer import RenderSession
from lenslab.scene.io.loader import open_scene
from lenslab.scene.materials import Conductor, Dielectric, Diffuse, Emissive
from tests.helpers import render_to_spp

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
    image = render_to_spp(session, spp).image()
    session.release()
    return image


@pytest.mark.slow  # compiles the general kernel: minutes on llvmpipe with a cold shader cache
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


def test_small_scenes_test_every_primitive_and_larger_ones_walk_their_tree():
    assert features_of("cornell_box").flat_primitives == 36  # its walls span the box: the tree saves little
    assert features_of("cornell_caustic").flat_primitives == 14
    assert features_of("dof_chart").flat_primitives == 0  # 70 primitives, which its tree spreads well
    assert features_of("product_shot").flat_primitives == 0  # thousands
    assert GENERAL.flat_primitives == 0


def boxes_in_a_row(count, spacing):
    """``count`` unit boxes' bounds along x, ``spacing`` apart: far apart, a tree separates them well."""
    lo = np.stack([np.arange(count) * spacing, np.zeros(count), np.zeros(count)], axis=1).astype(np.float32)
    return np.stack([lo, lo + 1.0], axis=1)


def test_a_scene_renders_flat_only_when_its_tree_saves_little_and_it_is_small():
    crowded = build_kdtree(boxes_in_a_row(20, 0.1))  # overlapping boxes: little to split
    spread = build_kdtree(boxes_in_a_row(20, 100.0))  # one box per leaf, reached in a few steps
    assert renders_flat(crowded, 20)
    assert not renders_flat(spread, 20)
    many = FLAT_MAX_PRIMITIVES + 1
    assert not renders_flat(build_kdtree(boxes_in_a_row(many, 0.01)), many)
    assert not renders_flat(crowded, 0)


@pytest.mark.slow  # compiles the general kernel: minutes on llvmpipe with a cold shader cache
def test_cut_outs_and_spheres_render_the_same_flat_as_through_the_tree(renderer):
    from tests.test_material_layers import facing_a_square
    from lenslab.scene.materials import Mask
    from lenslab.scene.scene import Node
    from lenslab.scene.shapes import Sphere
    from lenslab.scene.transform import Transform

    scene = facing_a_square(Mask(material=Diffuse((0.8, 0.8, 0.8)), opacity=0.5), sky=1.0)
    scene.materials["ball"] = Diffuse((0.2, 0.6, 0.3))
    scene.nodes.append(Node("ball", Transform(translate=(0.3, 0.2, 1.0)), Sphere(0.4), "ball"))
    scene = dataclasses.replace(scene, render=dataclasses.replace(scene.render, seed=5, max_depth=4))
    packed = pack_scene(scene.flatten(), scene.environment, lights=scene.lights)
    assert scene_features(packed).flat_primitives == packed.prim_count
    flat = render(renderer, scene, 16, True)
    tree = render(renderer, scene, 16, False)
    assert flat.mean() > 0.0
    assert np.isclose(flat, tree, rtol=1e-3, atol=1e-5).all(axis=-1).mean() > 0.99
