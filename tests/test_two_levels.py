"""Two levels (render/instancing.py): large meshes keep their own trees in their own space, placed by instances.

Checked against the one-level scene (every triangle in world space, one tree), which the rest of the suite holds
to brute force and to Mitsuba: the same hits for the same rays, the same image for the same seed; and edits that
must not rebuild a mesh's tree do not.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import trimesh

from tests.helpers import render_to_spp
from tests.scenes import FIXED_SENSOR
from lenslab.render import instancing
from lenslab.render.buffers import GpuScene, pack_scene
from lenslab.render.features import scene_features
from lenslab.render.raycast import cast_rays
from lenslab.render.tracer import RenderSession
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.flatten import flatten_scene
from lenslab.scene.materials import Diffuse, Emissive, Plastic
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
from lenslab.scene.shapes import Box, MeshFile, Relief, Sphere
from lenslab.scene.transform import Transform


@pytest.fixture(scope="module")
def bumpy_ball(tmp_path_factory):
    """A closed, bumpy mesh of 5,120 triangles in a file: one mesh that several nodes can place."""
    folder = tmp_path_factory.mktemp("ball")
    ball = trimesh.creation.icosphere(subdivisions=4, radius=0.5)
    rng = np.random.default_rng(3)
    ball.vertices *= 1 + 0.05 * rng.uniform(-1, 1, (len(ball.vertices), 1))
    ball.export(folder / "ball.ply")
    return folder


def placed_balls(folder, transforms, material="clay") -> Scene:
    """The ball placed by each transform, a box and a sphere beside them, under a grey sky."""
    balls = [Node(f"ball {k}", transform, MeshFile("ball.ply"), material=material)
             for k, transform in enumerate(transforms)]
    return Scene(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 0.3, 4), look_at=(0, 0, 0), focal_length_mm=35,
                              f_number=8, focus_distance_m=4, resolution=(64, 48)),
        environment=ConstantEnvironment((0.8, 0.8, 0.8)),
        render=RenderSettings(max_depth=3, spp=4),
        materials={"clay": Diffuse(albedo=(0.7, 0.5, 0.4)), "paint": Plastic(), "grey": Diffuse()},
        nodes=[*balls,
               Node("box", Transform(translate=(0, -0.8, 0), scale=(3, 0.1, 3)), Box(), material="grey"),
               Node("marble", Transform(translate=(0.9, -0.5, 0.6)), Sphere(radius=0.2), material="paint")],
        source_path=folder / "scene.json",
    )


TRANSFORMS = [
    Transform(translate=(-0.8, 0, 0), rotate_deg=(20, 35, -10), scale=(1.0, 0.6, 1.3)),  # turned, squashed
    Transform(translate=(0.7, 0.1, -0.3), scale=(-1.0, 1.0, 1.0)),  # mirrored
    Transform(translate=(0.0, 0.5, -1.0), scale=(0.5, 0.5, 0.5)),
]


def rays_at(scene: Scene, rng, count=4000):
    """Rays from around the scene towards its middle: most of them hit something."""
    origins = rng.normal(size=(count, 3))
    origins *= 3.5 / np.linalg.norm(origins, axis=1, keepdims=True)
    directions = rng.uniform(-1.2, 1.2, (count, 3)) - origins
    return origins, directions / np.linalg.norm(directions, axis=1, keepdims=True)


def cast(renderer, flat, scene, origins, directions):
    packed = pack_scene(flat, scene.environment, base_dir=scene.base_dir())
    gpu = GpuScene(renderer.ctx, packed, renderer.limits.max_storage_block_bytes)
    try:
        hits = cast_rays(renderer, gpu, origins, directions)
    finally:
        gpu.release()
    return hits, hits.nodes(flat, packed.first_world_prim)


def test_a_mesh_placed_three_times_is_stored_once_and_hit_where_the_world_space_scene_is(renderer, bumpy_ball):
    scene = placed_balls(bumpy_ball, TRANSFORMS)
    one_level = flatten_scene(scene)
    two_levels = flatten_scene(scene, instance_min_triangles=1000)
    assert not one_level.instances and one_level.triangle_count == 3 * 5120 + 12
    assert len(two_levels.groups) == 1 and len(two_levels.instances) == 3, "one mesh, three placements"
    assert two_levels.triangle_count == 12 and two_levels.placed_triangle_count == one_level.triangle_count
    outer, inner = two_levels.bounds(), one_level.bounds()  # an instance's box: its group's box, turned
    assert (outer[0] <= inner[0] + 1e-6).all() and (outer[1] >= inner[1] - 1e-6).all()

    origins, directions = rays_at(scene, np.random.default_rng(5))
    expected, expected_nodes = cast(renderer, one_level, scene, origins, directions)
    hits, nodes = cast(renderer, two_levels, scene, origins, directions)
    hit = np.isfinite(expected.t)
    assert hit.sum() > 2000 and (nodes[hit] < 3).sum() > 500, "the rays hit the balls, and other things"
    assert np.array_equal(np.isfinite(hits.t), hit)
    assert np.allclose(hits.t[hit], expected.t[hit], rtol=1e-5, atol=1e-6)
    # The same node, except where a ray grazes the seam between two objects within rounding.
    assert (nodes[hit] == expected_nodes[hit]).mean() > 0.999
    assert set(np.unique(hits.instance[hit])) == {-1, 0, 1, 2}


def render(renderer, scene, instance_min_triangles, monkeypatch, spp=4):
    monkeypatch.setattr(instancing, "INSTANCE_MIN_TRIANGLES", instance_min_triangles)
    import lenslab.render.tracer as tracer

    monkeypatch.setattr(tracer, "INSTANCE_MIN_TRIANGLES", instance_min_triangles)
    session = RenderSession(renderer, scene)
    try:
        return render_to_spp(session, spp).image()[..., :3], session
    finally:
        session.release()


def test_two_levels_render_the_same_image_as_one(renderer, bumpy_ball, monkeypatch):
    """Placed where the mesh file has it, the ball's instance gives the one-level image to rounding; turned,
    squashed and mirrored, the same image within a sliver of noise (rounding moves a few paths' hits)."""
    for transforms, tolerance in (([Transform()], 1e-5), (TRANSFORMS, 0.02)):
        scene = placed_balls(bumpy_ball, transforms)
        one_level, session = render(renderer, scene, 10**9, monkeypatch)
        assert not session.flat_scene.instances
        two_levels, session = render(renderer, scene, 1000, monkeypatch)
        assert len(session.flat_scene.instances) == len(transforms)
        assert session.features.instances
        assert one_level.mean() > 0.05
        difference = np.abs(two_levels - one_level).mean() / one_level.mean()
        assert difference < tolerance, (len(transforms), difference)


def test_edits_that_leave_a_mesh_as_it_was_rebuild_no_tree(renderer, bumpy_ball, monkeypatch):
    monkeypatch.setattr(instancing, "INSTANCE_MIN_TRIANGLES", 1000)
    import lenslab.render.tracer as tracer

    monkeypatch.setattr(tracer, "INSTANCE_MIN_TRIANGLES", 1000)
    scene = placed_balls(bumpy_ball, TRANSFORMS[:2])
    session = RenderSession(renderer, scene)
    try:
        assert session._groups.built == 1
        first = session.gpu_scene.packed
        moved = dataclasses.replace(scene, nodes=[dataclasses.replace(scene.nodes[0], transform=Transform(
            translate=(-0.5, 0.2, 0.1), rotate_deg=(0, 90, 0))), *scene.nodes[1:]])
        session.set_scene(moved)
        assert session._groups.built == 0, "moving an object keeps its mesh's tree"
        assert session.gpu_scene.packed.group_trees[0] is first.group_trees[0]
        group_bytes = sum(part.nbytes for name in ("kd_nodes", "prim_refs", "geometry", "shading")
                          for part in session.gpu_scene.packed.arrays[name][:1])
        recoloured = dataclasses.replace(moved, materials={**moved.materials, "clay": Diffuse(albedo=(0.1, 0.2, 0.9))})
        session.set_scene(recoloured)
        assert session._groups.built == 0, "a material edit keeps every tree"
        assert session.load.uploaded_bytes < group_bytes / 10, "and sends none of the mesh's rows to the device"
        reassigned = dataclasses.replace(recoloured, nodes=[dataclasses.replace(recoloured.nodes[0], material="paint"),
                                                            *recoloured.nodes[1:]])
        session.set_scene(reassigned)
        assert session._groups.built == 0, "so does giving an object another material"
        packed = session.gpu_scene.packed
        assert packed.instance_materials[0] != packed.instance_materials[1]
        hidden = dataclasses.replace(reassigned, nodes=reassigned.nodes[1:])
        session.set_scene(hidden)
        assert session._groups.built == 0 and len(session.flat_scene.instances) == 1
        smooth_off = dataclasses.replace(hidden, nodes=[dataclasses.replace(hidden.nodes[0], shape=MeshFile(
            "ball.ply", smooth=False)), *hidden.nodes[1:]])
        session.set_scene(smooth_off)
        assert session._groups.built == 1, "another mesh is another tree"
    finally:
        session.release()


def test_picking_an_instance_names_its_node(renderer, bumpy_ball, monkeypatch):
    monkeypatch.setattr(instancing, "INSTANCE_MIN_TRIANGLES", 1000)
    import lenslab.render.tracer as tracer

    monkeypatch.setattr(tracer, "INSTANCE_MIN_TRIANGLES", 1000)
    scene = placed_balls(bumpy_ball, [Transform(translate=(-0.6, 0, 0)), Transform(translate=(0.6, 0, 0))])
    scene = dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, position=(0, 0, 4), look_at=(0, 0, 0)))
    session = RenderSession(renderer, scene)
    try:
        width = session.width
        left, right = session.pick(0.37 * width, session.height / 2), session.pick(0.63 * width, session.height / 2)
        assert left.node.name == "ball 0" and right.node.name == "ball 1"
        assert left.point[0] < -0.2 and right.point[0] > 0.2
        assert left.depth == pytest.approx(right.depth, rel=0.05)
    finally:
        session.release()


def test_emitting_and_cut_out_meshes_stay_in_the_world(bumpy_ball):
    scene = placed_balls(bumpy_ball, TRANSFORMS[:1])
    glowing = dataclasses.replace(scene, materials={**scene.materials, "clay": Emissive(radiance=(2.0, 2.0, 2.0))})
    assert not flatten_scene(glowing, instance_min_triangles=1000).instances, "emitters are sampled in world space"
    assert len(flatten_scene(scene, instance_min_triangles=1000).instances) == 1


def test_a_relief_moved_keeps_its_tree_and_small_scenes_stay_one_level(renderer):
    relief = Node("ground", Transform(rotate_deg=(-90, 0, 0)), Relief(size=(4, 4), resolution=(120, 120)))
    scene = Scene(camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 1, 3), look_at=(0, 0, 0), resolution=(32, 24)),
                  environment=ConstantEnvironment((1.0, 1.0, 1.0)), nodes=[relief])
    session = RenderSession(renderer, scene)
    try:
        assert len(session.flat_scene.groups) == 1 and session._groups.built == 1
        raised = dataclasses.replace(relief, transform=Transform(translate=(0, 0.1, 0), rotate_deg=(-90, 0, 0)))
        session.set_scene(dataclasses.replace(scene, nodes=[raised]))
        assert session._groups.built == 0
        session.set_scene(dataclasses.replace(scene, nodes=[dataclasses.replace(raised, shape=Relief(
            size=(4, 4), resolution=(120, 120), seed=7))]))
        assert session._groups.built == 1, "another landscape is another mesh"
    finally:
        session.release()
    small = dataclasses.replace(scene, nodes=[Node("box", shape=Box())])
    session = RenderSession(renderer, small)
    try:
        assert not session.flat_scene.groups and not scene_features(session.gpu_scene.packed).instances
    finally:
        session.release()


def test_an_edited_session_renders_what_a_new_one_does(renderer, bumpy_ball, monkeypatch):
    """Buffers kept or rewritten in part after an edit (buffers.GpuScene) hold what a new session would upload:
    the same image, sample for sample."""
    monkeypatch.setattr(instancing, "INSTANCE_MIN_TRIANGLES", 1000)
    import lenslab.render.tracer as tracer

    monkeypatch.setattr(tracer, "INSTANCE_MIN_TRIANGLES", 1000)
    scene = placed_balls(bumpy_ball, TRANSFORMS[:2])
    edited = replace_marble(scene, Transform(translate=(-0.3, -0.4, 0.9)))  # a world sphere moved
    edited = dataclasses.replace(edited, materials={**edited.materials, "clay": Diffuse(albedo=(0.2, 0.6, 0.3))})

    def image(session):
        return render_to_spp(session, 2).image()

    session = RenderSession(renderer, scene)
    try:
        image(session)
        session.set_scene(edited)
        assert session.load.uploaded_bytes < session.gpu_scene.packed.nbytes / 4
        kept = image(session)
    finally:
        session.release()
    fresh = RenderSession(renderer, edited)
    try:
        assert np.array_equal(kept, image(fresh))
    finally:
        fresh.release()


def replace_marble(scene: Scene, transform: Transform) -> Scene:
    return dataclasses.replace(scene, nodes=[dataclasses.replace(node, transform=transform) if node.name == "marble"
                                             else node for node in scene.nodes])


def test_many_instances_are_found_through_their_own_tree(renderer, bumpy_ball, monkeypatch):
    """Past INSTANCE_TREE_MIN_INSTANCES, rays find instances through a kd-tree over their boxes: the same hits as
    the one-level scene, and the same image as the loop over every instance."""
    grid = [Transform(translate=(0.55 * i - 1.4, 0.3 * ((i + j) % 3) - 0.3, -0.6 * j), rotate_deg=(0, 37 * i, 0),
                      scale=(0.25, 0.25 + 0.05 * j, 0.25)) for i in range(6) for j in range(3)]
    scene = placed_balls(bumpy_ball, grid)
    one_level = flatten_scene(scene)
    two_levels = flatten_scene(scene, instance_min_triangles=1000)
    assert len(two_levels.instances) == 18 >= instancing.INSTANCE_TREE_MIN_INSTANCES
    origins, directions = rays_at(scene, np.random.default_rng(8))
    expected, expected_nodes = cast(renderer, one_level, scene, origins, directions)
    hits, nodes = cast(renderer, two_levels, scene, origins, directions)
    hit = np.isfinite(expected.t)
    assert (nodes[hit] < 18).sum() > 300, "many rays hit a ball"
    assert np.array_equal(np.isfinite(hits.t), hit)
    assert np.allclose(hits.t[hit], expected.t[hit], rtol=1e-5, atol=1e-6)
    assert (nodes[hit] == expected_nodes[hit]).mean() > 0.999

    assert pack_scene(two_levels, scene.environment, base_dir=scene.base_dir()).uniforms["instance_root"] >= 0
    through_tree, _ = render(renderer, scene, 1000, monkeypatch)
    monkeypatch.setattr(instancing, "INSTANCE_TREE_MIN_INSTANCES", 1000)
    assert pack_scene(two_levels, scene.environment, base_dir=scene.base_dir()).uniforms["instance_root"] == -1
    every_one, _ = render(renderer, scene, 1000, monkeypatch)
    assert np.array_equal(through_tree, every_one)


def test_a_mitsuba_shapegroup_placed_three_times_is_one_mesh_group(bumpy_ball, tmp_path):
    """Mitsuba's shapegroup and instance (and any nodes that name the same mesh file) store the mesh once."""
    from lenslab.scene.io.mitsuba_xml import load_mitsuba_scene

    instances = "".join(f'<shape type="instance"><ref id="balls"/><transform name="to_world"><translate x="{x}"/>'
                        f'<rotate y="1" angle="{20 * x}"/></transform></shape>' for x in (-1, 0, 1))
    path = tmp_path / "scene.xml"
    path.write_text(f'''<scene version="3.0.0">
        <shape type="shapegroup" id="balls">
            <shape type="ply"><string name="filename" value="{bumpy_ball / 'ball.ply'}"/></shape>
        </shape>
        {instances}
    </scene>''')
    scene = load_mitsuba_scene(path)
    flat = flatten_scene(scene, instance_min_triangles=1000)
    assert len(flat.groups) == 1 and len(flat.instances) == 3
    assert flat.stored_triangle_count == 5120 and flat.placed_triangle_count == 3 * 5120
