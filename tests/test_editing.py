"""The editing operations and the editable scene, without Qt: where new things go, an imported mesh's node,
focusing on a selection, re-parenting, rebasing mesh paths for a save, and the events an edit announces.

The expected numbers are worked out by hand from the camera below: at (0, 1, 5) looking down -Z, 50 mm on a
36 mm wide sensor, focused at 2.5 m, so the image spans 2 * 2.5 * 18 / 50 = 1.8 m at the plane of focus,
whose centre is (0, 1, 2.5).
"""

import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tests.scenes import FIXED_SENSOR

from lenslab.scene import editing
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.editable import EditableScene, unique_name
from lenslab.scene.events import SceneChange
from lenslab.scene.lights import PointLight, SpotLight, SunLight
from lenslab.scene.materials import Diffuse, Emissive
from lenslab.scene.scene import EnvironmentMap, Node, Scene
from lenslab.scene.shapes import Box, MeshFile, Rectangle, Sphere
from lenslab.scene.textures import Checkerboard, ImageTexture
from lenslab.scene.transform import Transform

VIEW_WIDTH = 1.8
FOCUS_POINT = (0.0, 1.0, 2.5)


def camera(**changes) -> ThinLensCamera:
    settings = dict(position=(0.0, 1.0, 5.0), look_at=(0.0, 1.0, 0.0), focal_length_mm=50.0,
                    focus_distance_m=2.5, sensor_mm=(36.0, 24.0), resolution=(640, 480), **FIXED_SENSOR)
    settings.update(changes)
    return ThinLensCamera(**settings)


def model_of(*nodes: Node, **scene_fields) -> EditableScene:
    return EditableScene(Scene(camera=camera(), nodes=list(nodes), **scene_fields))


def test_the_editing_modules_load_no_qt_and_an_edit_is_heard_without_it():
    code = (
        "import sys\n"
        "from lenslab.scene import editing\n"
        "from lenslab.scene.editable import EditableScene\n"
        "from lenslab.scene.scene import Scene\n"
        "model = EditableScene(Scene())\n"
        "heard = []\n"
        "model.events.changed.connect(heard.append)\n"
        "new = editing.new_primitive(model, 'sphere')\n"
        "model.scene.nodes.append(new.node)\n"
        "model.apply_value(('node', (0,)), ('transform', 'scale'), (2.0, 2.0, 2.0))\n"
        "assert [(c.kind, c.target, c.field) for c in heard] == [('node', ('node', (0,)), ('transform', 'scale'))]\n"
        "print(sorted(m for m in sys.modules if m.startswith(('PySide6', 'shiboken6', 'lenslab.gui'))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


# -- the editable scene ------------------------------------------------------------------------------------------
def test_setting_a_value_stores_a_copy_and_announces_what_changed():
    model = model_of(Node("ball", Transform(), Sphere(radius=0.1)))
    heard = []
    model.events.changed.connect(heard.append)
    translate = [0.1, 0.2, 0.3]
    model.apply_value(("node", (0,)), ("transform", "translate"), translate)
    translate[0] = 9.0  # the caller's object is not the scene's
    assert model.scene.nodes[0].transform.translate == [0.1, 0.2, 0.3]
    model.apply_value(("camera",), ("f_number",), 4.0)
    model.apply_value(("node", (0,)), ("name",), "quiet", notify=False)
    assert heard == [SceneChange("node", ("node", (0,)), ("transform", "translate")),
                     SceneChange("camera", ("camera",), ("f_number",))]
    assert model.get_value(("camera",), ("f_number",)) == 4.0 and model.node((0,)).name == "quiet"


def test_replacing_the_scene_keeps_the_listeners_and_announces_it():
    model = model_of()
    heard = []
    model.events.changed.connect(heard.append)
    other = Scene(nodes=[Node("other")])
    model.replace(other)
    assert model.scene is other and [c.kind for c in heard] == ["scene"]
    model.notify_target(("material", "red"), ("albedo",))
    assert heard[-1] == SceneChange("material", ("material", "red"), ("albedo",))


def test_node_paths_walk_depth_first_and_subtrees_cover_the_children():
    model = model_of(Node("a"), Node("b", children=[Node("b1"), Node("b2", children=[Node("b21")])]), Node("c"))
    assert model.node_paths() == [(0,), (1,), (1, 0), (1, 1), (1, 1, 0), (2,)]
    assert [n.name for _p, n in model.walk_nodes()] == ["a", "b", "b1", "b2", "b21", "c"]
    assert model.subtree_indices((1,)) == [1, 2, 3, 4]
    assert model.subtree_indices((1, 1)) == [3, 4]
    assert model.children_of(()) is model.scene.nodes
    assert not model.exists(("node", (5,))) and model.exists(("node", (1, 1, 0)))


def test_unique_names_count_up_from_the_stem():
    assert unique_name("box", {"sphere"}) == "box"
    assert unique_name("box", {"box"}) == "box.001"
    assert unique_name("box", {"box", "box.001"}) == "box.002"
    assert unique_name("box.001", {"box", "box.001"}) == "box.002"  # a copy of a copy is not box.001.001
    model = model_of(Node("sphere"), materials={"light": Emissive()})
    assert model.unique_node_name("sphere") == "sphere.001"
    assert model.unique_material_name("light") == "light.001"


# -- adding -----------------------------------------------------------------------------------------------------
def test_a_new_primitive_stands_at_the_point_of_focus_sized_to_the_view():
    model = model_of(Node("sphere"))
    new = editing.new_primitive(model, "sphere")
    size = round(0.12 * VIEW_WIDTH, 3)
    assert new.material is None
    assert new.node.name == "sphere.001"
    assert new.node.transform.translate == pytest.approx(FOCUS_POINT)
    assert new.node.shape == Sphere(radius=size / 2)
    assert editing.new_primitive(model, "box").node.shape == Box(size=(size, size, size))
    assert editing.new_primitive(model, "rectangle").node.shape == Rectangle(size=(size, size))
    group = editing.new_primitive(model, "group").node
    assert group.shape is None and group.transform == Transform()
    assert len(model.scene.nodes) == 1  # deciding is not doing
    with pytest.raises(ValueError, match="expected one of"):
        editing.new_primitive(model, "teapot")


def test_a_longer_lens_makes_smaller_new_objects_and_a_tiny_view_still_gets_five_centimetres():
    model = model_of()
    model.scene.camera = camera(focal_length_mm=100.0)
    assert editing.new_primitive(model, "sphere").node.shape.radius == pytest.approx(0.12 * VIEW_WIDTH / 4)
    model.scene.camera = camera(focus_distance_m=0.1)
    assert editing.new_primitive(model, "box").node.shape.size == (0.05, 0.05, 0.05)


def test_an_area_light_comes_with_its_own_emissive_material_above_the_point_of_focus():
    model = model_of(materials={"light": Emissive()})
    new = editing.new_primitive(model, "light")
    size = round(0.12 * VIEW_WIDTH, 3)
    name, material = new.material
    assert name == "light.001" and isinstance(material, Emissive) and max(material.radiance) > 1
    assert new.node.material == name and new.node.name == "area light"
    assert new.node.transform.translate == pytest.approx((0.0, 1.0 + 3 * size, 2.5))
    assert new.node.transform.rotate_deg == (90.0, 0.0, 0.0)  # the rectangle's normal turned to face down
    assert new.node.shape == Rectangle(size=(2 * size, 2 * size))


def test_a_point_light_goes_above_the_point_of_focus_and_a_sun_shines_over_the_cameras_shoulder():
    model = model_of()
    point = editing.new_light(model, "point")
    size = 0.12 * VIEW_WIDTH
    assert isinstance(point, PointLight) and point.name == "point light"
    assert point.position == pytest.approx((0.0, 1.0 + 4 * size, 2.5))
    assert point.intensity == pytest.approx((40 * size,) * 3)
    sun = editing.new_light(model, "sun")
    assert isinstance(sun, SunLight) and sun.name == "sun"
    # Right of the camera (+x), above (+y), behind it (+z, the camera looks down -z).
    assert sun.direction == pytest.approx((0.5, 1.0, 0.7))
    model.scene.lights.append(sun)
    assert editing.new_light(model, "sun").name == "sun.001"
    spot = editing.new_light(model, "spot")  # where the point light goes, aimed down at the point of focus
    assert isinstance(spot, SpotLight) and spot.position == pytest.approx(point.position)
    assert spot.direction == pytest.approx((0.0, -1.0, 0.0))
    with pytest.raises(ValueError):
        editing.new_light(model, "projector")


def test_new_objects_go_into_a_selected_group_and_a_new_material_is_a_grey_diffuse():
    model = model_of(Node("group"), Node("ball", shape=Sphere()))
    assert editing.insertion_parent(model, [(0,)]) == (0,)
    assert editing.insertion_parent(model, [(1,)]) == ()  # a shape is no container
    assert editing.insertion_parent(model, [(0,), (1,)]) == ()
    assert editing.insertion_parent(model, []) == ()
    assert editing.new_material(model) == ("material", Diffuse())


def test_a_duplicate_is_a_deep_copy_under_its_own_name():
    model = model_of(Node("group", children=[Node("ball", shape=Sphere())]))
    copy = editing.duplicate(model, (0,))
    assert copy.name == "group.001" and copy.children == model.node((0,)).children
    copy.children[0].shape.radius = 5.0
    assert model.node((0, 0)).shape.radius != 5.0


# -- importing a mesh -------------------------------------------------------------------------------------------
def test_a_mesh_in_millimetres_is_scaled_to_fit_and_stands_at_the_point_of_focus(tmp_path):
    model = model_of()
    box_mm = np.array([[0.0, 0.0, -20.0], [100.0, 50.0, 20.0]])  # 10 cm wide, modelled in millimetres
    node, scale = editing.mesh_node(model, tmp_path / "part.obj", box_mm)
    assert scale == pytest.approx(0.4 * VIEW_WIDTH / 100.0)
    assert node.transform.scale == (scale, scale, scale)
    world = box_mm * scale + np.asarray(node.transform.translate)
    assert world[:, 1].min() == pytest.approx(FOCUS_POINT[1])  # standing at the focus point's height
    assert world[:, [0, 2]].mean(axis=0) == pytest.approx([FOCUS_POINT[0], FOCUS_POINT[2]])  # on the view axis
    assert node.name == "part" and node.shape == MeshFile(file=str((tmp_path / "part.obj").resolve()), smooth=True)


def test_a_mesh_of_a_sensible_size_keeps_it_and_is_named_relative_to_the_scene_file(tmp_path):
    model = model_of()
    half_metre = np.array([[-0.25, 0.0, -0.25], [0.25, 0.5, 0.25]])
    scene_file = tmp_path / "shots" / "scene.json"
    node, scale = editing.mesh_node(model, tmp_path / "meshes" / "vase.obj", half_metre, scene_file)
    assert scale == 1.0 and node.transform.scale == (1.0, 1.0, 1.0)
    assert node.shape.file == str(Path("..") / "meshes" / "vase.obj")


# -- focusing on a selection -------------------------------------------------------------------------------------
def focus_scene() -> EditableScene:
    return model_of(Node("near", Transform(translate=(0.0, 1.0, 1.0)), Sphere()),  # 4 m ahead of the camera
                    Node("far", Transform(translate=(0.0, 1.0, -1.0)), Box(), children=[Node("far child")]),
                    Node("behind", Transform(translate=(0.0, 1.0, 6.0)), Sphere()))


def test_focusing_on_a_selection_uses_the_median_depth_of_what_the_camera_sees_of_it():
    model = focus_scene()
    inf = np.inf
    gbuffer = SimpleNamespace(node_index=np.array([[0, 0, 0, 1], [1, 2, 2, -1]], np.int32),
                              depth=np.array([[3.9, 4.1, 4.6, 6.0], [6.2, 7.0, 7.4, inf]], np.float32))
    assert editing.focus_distance_for(model, [(0,)], gbuffer) == pytest.approx(4.1, abs=1e-4)
    # A group counts its children's pixels: 6.0, 6.2, 7.0 and 7.4.
    assert editing.focus_distance_for(model, [(1,)], gbuffer) == pytest.approx(6.6, abs=1e-4)
    # Several nodes: the median of all their pixels (3.9, 4.1, 4.6, 7.0, 7.4).
    assert editing.focus_distance_for(model, [(0,), (1, 0)], gbuffer) == pytest.approx(4.6, abs=1e-4)


def test_focusing_on_something_out_of_view_uses_its_origin_and_refuses_what_is_behind_the_camera():
    model = focus_scene()
    nowhere = SimpleNamespace(node_index=np.full((2, 2), -1, np.int32), depth=np.full((2, 2), np.inf))
    assert editing.focus_distance_for(model, [(0,)]) == 4.0
    assert editing.focus_distance_for(model, [(1,)], nowhere) == 6.0
    assert editing.focus_distance_for(model, [(2,)]) is None
    assert editing.focus_distance_for(model, []) is None


# -- re-parenting -----------------------------------------------------------------------------------------------
def test_a_reparented_node_keeps_its_place_in_the_world():
    group = Node("group", Transform(translate=(1.0, 0.0, 0.0), rotate_deg=(0.0, 30.0, 0.0), scale=(2.0, 2.0, 2.0)))
    ball = Node("ball", Transform(translate=(0.5, 1.0, 0.0), rotate_deg=(10.0, 0.0, 0.0)), Sphere())
    model = model_of(group, ball)
    before = editing.world_matrix(model, (1,))
    local = editing.reparented_transform(model, (1,), (0,))
    assert np.allclose(group.transform.matrix() @ local.matrix(), before, atol=1e-9)
    assert editing.reparented_transform(model, (1,), ()) is None  # same parent: its own transform stays
    assert np.allclose(editing.world_matrix(model, ()), np.eye(4))


def test_a_node_cannot_move_into_itself_or_onto_its_own_place():
    assert not editing.can_move((1,), (1,), 0)
    assert not editing.can_move((1,), (1, 0), 0)
    assert not editing.can_move((1,), (), 1) and not editing.can_move((1,), (), 2)
    assert editing.can_move((1,), (), 0) and editing.can_move((1,), (), 3) and editing.can_move((1,), (0,), 0)


def test_decomposing_a_sheared_matrix_gives_none():
    shear = np.eye(4)
    shear[0, 1] = 0.5
    assert editing.decompose(shear) is None
    t = Transform(translate=(1.0, 2.0, 3.0), rotate_deg=(10.0, 20.0, 30.0), scale=(1.0, 2.0, 3.0))
    assert np.allclose(editing.decompose(t.matrix()).matrix(), t.matrix())


# -- saving -----------------------------------------------------------------------------------------------------
def test_saving_elsewhere_renames_relative_file_names_in_a_copy_only(tmp_path):
    absolute = str((tmp_path / "library" / "statue.obj").resolve())
    model = model_of(Node("vase", shape=MeshFile(file="meshes/vase.obj")),
                     Node("group", children=[Node("statue", shape=MeshFile(file=absolute)),
                                             Node("cup", shape=MeshFile(file="../cups/cup.obj"))]))
    model.scene.materials["wood"] = Diffuse(albedo_texture=ImageTexture(file="textures/wood.png"))
    model.scene.materials["checks"] = Diffuse(albedo_texture=Checkerboard())
    model.scene.environment = EnvironmentMap(file="sky.exr")
    model.scene.source_path = tmp_path / "shots" / "a" / "scene.json"
    new_folder = tmp_path / "shots" / "b" / "c"
    moved = editing.rebased_file_paths(model, new_folder)
    # The absolute path stays as it is; a checkerboard names no file.
    assert set(moved) == {(("node", (0,)), ("shape", "file")), (("node", (1, 1)), ("shape", "file")),
                          (("material", "wood"), ("albedo_texture", "file")), (("environment",), ("file",))}
    for (target, field), name in moved.items():
        before = (tmp_path / "shots" / "a" / model.get_value(target, field)).resolve()
        assert (new_folder / name).resolve() == before  # the same file, named from the new folder
    copy = editing.with_file_paths(model.scene, moved)
    assert copy.nodes[0].shape.file == "../../a/meshes/vase.obj"
    assert copy.nodes[1].children[1].shape.file == "../../cups/cup.obj"
    assert copy.materials["wood"].albedo_texture.file == "../../a/textures/wood.png"
    assert copy.environment.file == "../../a/sky.exr"
    assert copy.source_path == model.scene.source_path
    # The open scene is as it was.
    assert model.node((0,)).shape.file == "meshes/vase.obj" and model.node((1, 1)).shape.file == "../cups/cup.obj"
    assert model.scene.materials["wood"].albedo_texture.file == "textures/wood.png"
    assert model.scene.environment.file == "sky.exr"
    assert editing.rebased_file_paths(model, tmp_path / "shots" / "a") == {}
