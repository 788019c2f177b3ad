"""The Mitsuba 3 XML importer, on small inline documents.

Expected numbers are worked by hand from Mitsuba's source (parser.cpp, transform.h, sensor.h) or, where
marked "Mitsuba 3.9.1", were measured once with ``mitsuba==3.9.1`` (scalar_rgb) and written down here, so
these tests need no Mitsuba installed.
"""

from __future__ import annotations

import logging
import math
import re
from pathlib import Path

import numpy as np
import pytest

from lenslab.scene.io import mitsuba_values as mv
from lenslab.scene.io.mitsuba_xml import BSDF_MAPPINGS, load_mitsuba_scene, load_mitsuba_string
from lenslab.scene.materials import Blend, Conductor, Dielectric, Diffuse, Emissive, Mask, Plastic, ThinDielectric
from lenslab.scene.lights import PointLight, SunLight
from lenslab.scene.scene import ConstantEnvironment, EnvironmentMap, SceneError
from lenslab.scene.shapes import Box, Disk, MeshFile, Rectangle, Sphere
from lenslab.scene.transform import Transform

DATA = Path(__file__).parent / "data" / "mitsuba"
BOX_FILM = '<film type="hdrfilm"><integer name="width" value="{w}"/><integer name="height" value="{h}"/><rfilter type="box"/></film>'


def load(tmp_path: Path, body: str, defines=None, name="scene.xml", version="3.0.0"):
    """Write ``<scene>body</scene>`` to a file, import it; return (scene, warnings)."""
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<scene version="{version}">\n{body}\n</scene>\n')
    warnings: list[str] = []
    scene = load_mitsuba_scene(path, defines=defines, warn=warnings.append)
    return scene, warnings


def camera_xml(kind="perspective", w=64, h=64, params="", lookat='origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"'):
    return (f'<sensor type="{kind}">{params}<transform name="to_world"><lookat {lookat}/></transform>'
            f'{BOX_FILM.format(w=w, h=h)}</sensor>')


def world_matrices(scene) -> dict[str, np.ndarray]:
    """Local-to-world matrix of every node that holds a shape, by the name of its top node."""
    out = {}
    for root in scene.nodes:
        for node, matrix in root.walk():
            if node.shape is not None:
                out[root.name] = matrix
    return out


def only(warnings: list[str], text: str) -> str:
    """The one warning whose message (after "file:line: ") holds ``text``."""
    hits = [w for w in warnings if text in w.split(": ", 1)[-1]]
    assert len(hits) == 1, f"expected one warning with {text!r}, got {warnings}"
    return hits[0]


# ---------------------------------------------------------------------------------------------------------
# Transforms
# ---------------------------------------------------------------------------------------------------------
def shape_matrix(tmp_path, ops: str, shape="cube") -> np.ndarray:
    scene, _ = load(tmp_path, camera_xml() + f'<shape type="{shape}" id="s"><transform name="to_world">{ops}'
                    "</transform></shape>")
    return world_matrices(scene)["s"]


def test_each_transform_operation_matches_a_hand_computed_matrix(tmp_path):
    t = np.eye(4)
    t[:3, 3] = (1, -2, 3)
    assert np.allclose(shape_matrix(tmp_path, '<translate x="1" y="-2" z="3"/>'), t)
    assert np.allclose(shape_matrix(tmp_path, '<translate value="1 -2 3"/>'), t)
    assert np.allclose(shape_matrix(tmp_path, '<scale x="2" z="4"/>'), np.diag([2, 1, 4, 1]))
    assert np.allclose(shape_matrix(tmp_path, '<scale value="3"/>'), np.diag([3, 3, 3, 1]))
    # 90 degrees about +x takes +y to +z (counter-clockwise, right-handed)
    rx = np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1.0]])
    assert np.allclose(shape_matrix(tmp_path, '<rotate x="1" angle="90"/>'), rx)
    assert np.allclose(shape_matrix(tmp_path, '<rotate value="1, 0, 0" angle="90"/>'), rx)
    m16 = np.array([[0, -1, 0, 5], [2, 0, 0, 6], [0, 0, 3, 7], [0, 0, 0, 1.0]])
    assert np.allclose(shape_matrix(tmp_path, '<matrix value="0 -1 0 5  2 0 0 6  0 0 3 7  0 0 0 1"/>'), m16)
    m9 = np.eye(4)
    m9[:3, :3] = [[0, -1, 0], [2, 0, 0], [0, 0, 3]]
    assert np.allclose(shape_matrix(tmp_path, '<matrix value="0,-1,0, 2,0,0, 0,0,3"/>'), m9)
    # lookat: columns are left = up x dir, up' = dir x left, dir, origin
    look = np.array([[-1, 0, 0, 1], [0, 1, 0, 2], [0, 0, -1, 3], [0, 0, 0, 1.0]])
    assert np.allclose(shape_matrix(tmp_path, '<lookat origin="1, 2, 3" target="1, 2, 0" up="0, 1, 0"/>'), look)


def test_operations_compose_in_mitsubas_order_first_listed_first_applied(tmp_path):
    # translate then rotate: the origin goes to (1, 0, 0), then a quarter turn about z takes it to (0, 1, 0)
    m = shape_matrix(tmp_path, '<translate x="1"/><rotate z="1" angle="90"/>')
    rz = np.array([[0, -1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    t = np.eye(4)
    t[0, 3] = 1
    assert np.allclose(m, rz @ t)
    assert np.allclose(m @ [0, 0, 0, 1], [0, 1, 0, 1])
    # the other order leaves the origin at (1, 0, 0)
    m2 = shape_matrix(tmp_path, '<rotate z="1" angle="90"/><translate x="1"/>')
    assert np.allclose(m2, t @ rz)
    assert np.allclose(m2 @ [0, 0, 0, 1], [1, 0, 0, 1])
    # three steps: scale, rotate, translate (the usual object placement)
    m3 = shape_matrix(tmp_path, '<scale x="2"/><rotate z="1" angle="90"/><translate y="5"/>')
    t5 = np.eye(4)
    t5[1, 3] = 5
    assert np.allclose(m3, t5 @ rz @ np.diag([2, 1, 1, 1]))


def test_rotation_axis_is_not_normalised_as_in_mitsuba_3(tmp_path):
    scene, warnings = load(tmp_path, camera_xml() + '<shape type="rectangle" id="r"><transform name="to_world">'
                           '<scale x="0.5" y="2"/><rotate x="1" y="1" angle="33"/><translate x="1" y="-2" z="0.5"/>'
                           "</transform></shape>")
    mitsuba_391 = np.array([[0.5, 0.322659, 0.544639, 1.0], [0.080665, 2.0, -0.544639, -2.0],
                            [-0.27232, 1.089278, 0.838671, 0.5], [0, 0, 0, 1]])
    assert np.allclose(world_matrices(scene)["r"], mitsuba_391, atol=2e-6)
    assert "not of unit length" in only(warnings, "rotation axis")
    assert "scene.xml:3: <rotate>" in only(warnings, "rotation axis")


def random_rotation(rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def test_decomposition_is_one_trs_without_shear_and_round_trips(tmp_path):
    rng = np.random.default_rng(7)
    for i in range(200):
        m = np.eye(4)
        scale = rng.uniform(0.1, 5, 3) * rng.choice([-1, 1], 3)
        m[:3, :3] = random_rotation(rng) @ np.diag(scale)
        m[:3, 3] = rng.normal(size=3) * 10
        transforms = mv.decompose_affine(m)
        assert len(transforms) == 1, i
        assert np.allclose(transforms[0].matrix(), m, atol=1e-6 * np.abs(m).max())
    # gimbal lock: y = +-90 degrees
    for angles in [(30, 90, 0), (10, -90, 40), (0, 90, 0), (180, 0, 180)]:
        m = Transform(rotate_deg=angles, scale=(1, 2, 3)).matrix()
        (t,) = mv.decompose_affine(m)
        assert np.allclose(t.matrix(), m, atol=1e-9)
    # a clean placement stays clean
    (t,) = mv.decompose_affine(Transform((1, 2, 3), (-90, 0, 0), (2, 2, 2)).matrix())
    assert t == Transform((1.0, 2.0, 3.0), (-90.0, 0.0, 0.0), (2.0, 2.0, 2.0))


def test_sheared_matrices_become_two_nested_nodes_exactly(tmp_path):
    rng = np.random.default_rng(3)
    for _ in range(100):
        m = np.eye(4)
        m[:3, :] = rng.normal(size=(3, 4))
        outer, inner = mv.decompose_affine(m)
        assert inner.translate == (0, 0, 0) and inner.scale == (1, 1, 1)
        assert np.allclose(outer.matrix() @ inner.matrix(), m, atol=1e-9)
    scene, warnings = load(tmp_path, camera_xml() + '<shape type="cube" id="c"><transform name="to_world">'
                           '<matrix value="1 0.5 0 1  0 1 0.3 2  0.2 0 1 3  0 0 0 1"/></transform></shape>')
    (node,) = scene.nodes
    assert node.shape is None and len(node.children) == 1 and isinstance(node.children[0].shape, Box)
    expected = np.array([[1, 0.5, 0, 1], [0, 1, 0.3, 2], [0.2, 0, 1, 3], [0, 0, 0, 1]])
    assert np.allclose(world_matrices(scene)["c"], expected, atol=1e-12)
    assert warnings == []


def test_singular_transform_skips_the_shape_with_a_warning(tmp_path):
    scene, warnings = load(tmp_path, camera_xml() + '<shape type="cube" id="flat"><transform name="to_world">'
                           '<scale y="0"/></transform></shape><shape type="sphere" id="ok"/>')
    assert [n.name for n in scene.nodes] == ["ok"]
    assert ':3: <shape type="cube" id="flat">' in only(warnings, "singular")


def test_transform_errors_name_file_and_line(tmp_path):
    with pytest.raises(SceneError, match=r"scene\.xml: line 5: <rotate>: missing attribute \"angle\"$"):
        load(tmp_path, camera_xml() + '\n<shape type="cube"><transform name="to_world">\n<rotate x="1"/>'
             "</transform></shape>")
    with pytest.raises(SceneError, match=r"line 3: <matrix>: matrix must have 9 or 16 values, got 4"):
        load(tmp_path, camera_xml() + '<shape type="cube"><transform name="to_world"><matrix value="1 2 3 4"/>'
             "</transform></shape>")


# ---------------------------------------------------------------------------------------------------------
# Camera
# ---------------------------------------------------------------------------------------------------------
def mitsuba_fov_x(fov: float, axis: str, aspect: float) -> float:
    """parse_fov in Mitsuba's src/render/sensor.cpp, written out again."""
    if axis == "smaller":
        axis = "y" if aspect > 1 else "x"
    if axis == "larger":
        axis = "x" if aspect > 1 else "y"
    t = math.tan(math.radians(fov) / 2)
    if axis == "x":
        return fov
    if axis == "y":
        return math.degrees(2 * math.atan(t * aspect))
    return math.degrees(2 * math.atan(t / math.sqrt(1 + 1 / aspect**2)))  # diagonal


@pytest.mark.parametrize("w,h", [(320, 180), (240, 320), (300, 200)])
@pytest.mark.parametrize("axis", ["x", "y", "diagonal", "smaller", "larger"])
def test_fov_with_every_axis_gives_mitsubas_horizontal_fov(tmp_path, w, h, axis):
    params = f'<float name="fov" value="50"/><string name="fov_axis" value="{axis}"/>'
    scene, _ = load(tmp_path, camera_xml("perspective", w, h, params))
    assert math.degrees(scene.camera.fov_x) == pytest.approx(mitsuba_fov_x(50, axis, w / h), abs=1e-9)
    assert scene.camera.resolution == (w, h)


def test_focal_length_is_35mm_equivalent(tmp_path):
    # on a 3:2 film the 35 mm-equivalent focal length is our focal length on a 36 mm wide sensor
    scene, _ = load(tmp_path, camera_xml("perspective", 300, 200, '<string name="focal_length" value="35mm"/>'))
    assert scene.camera.focal_length_mm == pytest.approx(35.0, rel=1e-12)
    # Mitsuba 3.9.1 prints x_fov = 38.1848 for its default (50mm) on its default 768 x 576 film
    scene, _ = load(tmp_path, '<sensor type="perspective"><film type="hdrfilm"><rfilter type="box"/></film></sensor>')
    assert math.degrees(scene.camera.fov_x) == pytest.approx(38.1848, abs=1e-4)
    with pytest.raises(SceneError, match="line 3: <sensor.*either a focal length"):
        load(tmp_path, camera_xml(params='<float name="fov" value="40"/><string name="focal_length" value="50mm"/>'))


def test_thinlens_gives_the_same_lens_radius_and_focus(tmp_path):
    for radius, focus, fov in [(0.01, 2.5, 50), (0.002, 10.0, 20), (0.005, 0.7, 90)]:
        params = (f'<float name="fov" value="{fov}"/><float name="aperture_radius" value="{radius}"/>'
                  f'<float name="focus_distance" value="{focus}"/>')
        scene, warnings = load(tmp_path, camera_xml("thinlens", 300, 200, params))
        cam = scene.camera
        assert warnings == []
        assert math.degrees(cam.fov_x) == pytest.approx(fov, abs=1e-9)
        assert cam.lens_radius == pytest.approx(radius, rel=1e-12)
        assert cam.focus_distance_m == focus
    with pytest.raises(SceneError, match="line 3: <sensor type=\"thinlens\">.*aperture_radius"):
        load(tmp_path, camera_xml("thinlens"))


def test_tiny_or_huge_apertures_are_kept_as_written(tmp_path):
    # Past the studio's f/128 and f/0.5 alike: the camera takes any lens float32 carries (tests/test_scene_as_written.py).
    scene, warnings = load(tmp_path, camera_xml("thinlens", params='<float name="aperture_radius" value="1e-6"/>'))
    assert scene.camera.lens_radius == pytest.approx(1e-6) and scene.camera.f_number > 128 and warnings == []
    scene, warnings = load(tmp_path, camera_xml("thinlens", params='<float name="aperture_radius" value="1"/>'))
    assert scene.camera.lens_radius == pytest.approx(1.0) and scene.camera.f_number < 0.5 and warnings == []


def mitsuba_direction(to_world: np.ndarray, sx: float, sy: float, fov_x_deg: float, aspect: float) -> np.ndarray:
    """Mitsuba's pinhole ray through film position (sx, sy) (0, 0 = top left), from perspective_projection:
    sample.x = (1 - x/z cot)/2 and sample.y = (1 - aspect y/z cot)/2, so camera +X points to the image's left."""
    t = math.tan(math.radians(fov_x_deg) / 2)
    local = np.array([(1 - 2 * sx) * t, (1 - 2 * sy) * t / aspect, 1.0])
    d = to_world[:3, :3] @ local
    return d / np.linalg.norm(d)


def test_primary_rays_through_the_image_match_mitsubas_convention(tmp_path):
    lookat = 'origin="1, 2, 3" target="-0.5, 0.3, -1" up="0.2, 1, 0.1"'
    params = ('<float name="fov" value="50"/><string name="fov_axis" value="y"/>'
              '<float name="aperture_radius" value="0.01"/><float name="focus_distance" value="2.5"/>')
    scene, _ = load(tmp_path, camera_xml("thinlens", 300, 200, params, lookat))
    cam = scene.camera
    to_world = mv.lookat_matrix((1, 2, 3), (-0.5, 0.3, -1), (0.2, 1, 0.1))
    fov_x = mitsuba_fov_x(50, "y", 1.5)
    # ray directions Mitsuba 3.9.1 returned from sensor.sample_ray for these film positions
    mitsuba_391 = {(0, 0): (-0.743494, 0.129489, -0.656086), (1, 0): (0.268095, -0.04219, -0.962468),
                   (0, 1): (-0.767544, -0.523853, -0.369397), (1, 1): (0.244045, -0.695532, -0.675779),
                   (0.25, 0.8): (-0.607871, -0.51996, -0.600113)}
    frame = cam.frame()
    for (sx, sy), measured in mitsuba_391.items():
        ours = frame.pinhole_directions([(sx * 300, sy * 200)])[0]
        assert np.allclose(ours, mitsuba_direction(to_world, sx, sy, fov_x, 1.5), atol=1e-12)
        assert np.allclose(ours, measured, atol=2e-6)
    assert np.allclose(cam.position, (1, 2, 3))


def test_perspective_is_an_ideal_pinhole(tmp_path):
    body = (camera_xml("perspective", 200, 200, '<float name="fov" value="40"/>')
            + '<shape type="sphere"><point name="center" x="0" y="0" z="-2"/><float name="radius" value="1"/></shape>')
    scene, warnings = load(tmp_path, body)
    assert scene.camera.pinhole and scene.camera.lens_radius == 0.0
    assert scene.camera.fov_x == pytest.approx(math.radians(40))
    assert warnings == []
    scene, _ = load(tmp_path, camera_xml("thinlens", 8, 8, '<float name="aperture_radius" value="0.01"/>'))
    assert not scene.camera.pinhole and scene.camera.lens_radius == pytest.approx(0.01)


def test_camera_with_a_mirror_or_scale_warns(tmp_path):
    body = ('<sensor type="perspective"><transform name="to_world"><scale x="-1"/><lookat origin="0,0,5" '
            'target="0,0,0" up="0,1,0"/></transform>' + BOX_FILM.format(w=8, h=8) + "</sensor>")
    _, warnings = load(tmp_path, body)
    assert "mirrors" in only(warnings, "to_world")


def test_no_sensor_gives_a_camera_that_sees_the_scene(tmp_path):
    scene, warnings = load(tmp_path, '<shape type="sphere"><point name="center" x="1" y="2" z="3"/></shape>')
    cam = scene.camera
    assert np.allclose(cam.position[:2], (1, 2)) and cam.position[2] < 2
    assert np.allclose(cam.frame().pinhole_directions([(cam.resolution[0] / 2, cam.resolution[1] / 2)]), (0, 0, 1))
    assert only(warnings, "no sensor").startswith(f"{tmp_path / 'scene.xml'}:2: <scene>")


# ---------------------------------------------------------------------------------------------------------
# Defaults, substitution, refs, includes
# ---------------------------------------------------------------------------------------------------------
def test_mitsubas_defaults_where_values_are_omitted(tmp_path):
    scene, warnings = load(tmp_path, '<integrator type="path"/><sensor type="perspective"/>'
                           '<shape type="sphere" id="ball"/><shape type="rectangle" id="lamp"><emitter type="area"/>'
                           "</shape>")
    assert scene.camera.resolution == (768, 576)
    assert (scene.render.spp, scene.render.max_depth, scene.render.rr_depth) == (4, 1024, 5)
    assert scene.render.sampler == "independent"
    assert scene.camera.pinhole
    ball, lamp = scene.nodes
    assert isinstance(ball.shape, Sphere) and ball.shape.radius == 1 and ball.transform == Transform()
    assert scene.materials[ball.material] == Diffuse((0.5, 0.5, 0.5))
    assert scene.materials[lamp.material] == Emissive((1.0, 1.0, 1.0), two_sided=False)
    assert scene.environment == ConstantEnvironment((0.0, 0.0, 0.0))
    assert (scene.render.pixel_filter, scene.render.filter_stddev) == ("gaussian", 0.5)  # the default film's
    assert warnings == []


def test_defaults_and_substitution_with_defines_winning(tmp_path):
    body = ('<default name="spp" value="16"/><default name="res" value="40"/><default name="r" value="0.25"/>'
            '<sensor type="perspective"><sampler type="independent"><integer name="sample_count" value="$spp"/>'
            '</sampler><film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" '
            'value="$res"/><rfilter type="box"/></film></sensor>'
            '<shape type="sphere" id="s_$r"><float name="radius" value="$r"/></shape>')
    scene, warnings = load(tmp_path, body)
    assert scene.render.spp == 16 and scene.camera.resolution == (40, 40)
    assert scene.nodes[0].name == "s_0.25" and scene.nodes[0].shape.radius == 0.25
    scene, warnings = load(tmp_path, body, defines={"spp": "3", "r": "2", "unused": "1"})
    assert scene.render.spp == 3 and scene.camera.resolution == (40, 40)
    assert scene.nodes[0].shape.radius == 2
    assert "-D unused=1 is not used" in only(warnings, "unused")


def test_undefined_parameter_is_an_error_with_its_line_and_escapes_are_kept(tmp_path):
    with pytest.raises(SceneError, match=r"scene\.xml: line 4: <float>: undefined parameter \$radius"):
        load(tmp_path, camera_xml() + '\n<shape type="sphere"><float name="radius" value="$radius"/></shape>')
    scene, _ = load(tmp_path, camera_xml() + r'<shape type="sphere" id="cost\$5"/>')
    assert scene.nodes[0].name == "cost$5"


def test_refs_resolve_forwards_and_share_one_material(tmp_path):
    body = (camera_xml() + '<shape type="sphere" id="a"><ref id="gold"/></shape>'
            '<shape type="cube" id="b"><ref name="bsdf" id="gold"/></shape>'
            '<bsdf type="conductor" id="gold"><string name="material" value="Au"/></bsdf>')
    scene, warnings = load(tmp_path, body)
    a, b = scene.nodes
    assert a.material == b.material == "gold"
    assert scene.materials == {"gold": Conductor(metal="gold")}
    assert warnings == []


def test_unknown_ref_and_duplicate_id_are_errors(tmp_path):
    with pytest.raises(SceneError, match=r'scene\.xml: line 5: <ref id="nope">: unresolved reference to "nope"'):
        load(tmp_path, camera_xml() + '\n<shape type="sphere">\n<ref id="nope"/></shape>')
    with pytest.raises(SceneError, match=r'line 4: <bsdf type="diffuse" id="x">: duplicate id "x" \(first at .*scene\.xml:3\)'):
        load(tmp_path, '<bsdf type="diffuse" id="x"/>\n<bsdf type="diffuse" id="x"/>')


def test_include_is_relative_to_the_including_file(tmp_path):
    (tmp_path / "parts" / "meshes").mkdir(parents=True)
    (tmp_path / "parts" / "meshes" / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "parts" / "materials.xml").write_text(
        '<scene version="3.0.0"><bsdf type="diffuse" id="blue"><rgb name="reflectance" value="0.1 0.2 $blue"/>'
        '</bsdf><include filename="shapes.xml"/></scene>')
    (tmp_path / "parts" / "shapes.xml").write_text(
        '<scene version="3.0.0">\n<shape type="obj" id="tri"><string name="filename" value="meshes/tri.obj"/>'
        '<ref id="blue"/></shape>\n<shape type="obj" id="gone"><string name="filename" value="missing.obj"/>'
        "</shape></scene>")
    with pytest.raises(SceneError, match=r"parts/shapes\.xml: line 3: <shape type=\"obj\" id=\"gone\">: mesh file not found"):
        load(tmp_path, '<default name="blue" value="0.9"/>' + camera_xml() + '<include filename="parts/materials.xml"/>')
    (tmp_path / "parts" / "shapes.xml").write_text(
        '<scene version="3.0.0"><shape type="obj" id="tri"><string name="filename" value="meshes/tri.obj"/>'
        '<boolean name="face_normals" value="true"/><ref id="blue"/></shape></scene>')
    scene, warnings = load(tmp_path, '<default name="blue" value="0.9"/>' + camera_xml()
                           + '<include filename="parts/materials.xml"/>')
    (tri,) = scene.nodes
    assert tri.shape == MeshFile(file="parts/meshes/tri.obj", smooth=False)
    assert scene.materials[tri.material] == Diffuse((0.1, 0.2, 0.9))
    assert len(scene.flatten().triangles) == 1
    with pytest.raises(SceneError, match=r"scene\.xml: line 3: <include>: included file not found"):
        load(tmp_path, '<include filename="nope.xml"/>')
    # <path> adds a folder to search
    scene, _ = load(tmp_path, camera_xml() + '<path value="parts/meshes"/><shape type="obj">'
                    '<string name="filename" value="tri.obj"/></shape>')
    assert scene.nodes[0].shape.file == "parts/meshes/tri.obj"


# ---------------------------------------------------------------------------------------------------------
# Shapes, BSDFs, emitters
# ---------------------------------------------------------------------------------------------------------
def test_builtin_shapes_map_onto_ours(tmp_path):
    body = (camera_xml() + '<shape type="rectangle" id="r"/><shape type="cube" id="c"/>'
            '<shape type="sphere" id="s"><point name="center" x="1" y="2" z="3"/><float name="radius" value="0.5"/>'
            '<transform name="to_world"><scale value="2"/></transform></shape><shape type="disk" id="d"/>')
    scene, warnings = load(tmp_path, body)
    r, c, s, d = scene.nodes
    assert r.shape == Rectangle((2.0, 2.0)) and c.shape == Box((2.0, 2.0, 2.0))
    assert s.shape == Sphere(0.5) and s.transform == Transform((2.0, 4.0, 6.0), (0.0, 0.0, 0.0), (2.0, 2.0, 2.0))
    flat = scene.flatten()
    assert np.allclose(flat.spheres[0], [2, 4, 6, 1])
    disk = flat.triangles[flat.prim_node[: flat.triangle_count] == flat.nodes.index(d)]
    area = 0.5 * np.linalg.norm(np.cross(disk[:, 1] - disk[:, 0], disk[:, 2] - disk[:, 0]), axis=1).sum()
    assert area == pytest.approx(math.pi, rel=1e-6)
    assert np.allclose(disk[:, :, 2], 0)
    assert d.shape == Disk(radius=1.0, segments=128) and warnings == []
    _, warnings = load(tmp_path, camera_xml() + '<shape type="disk"><boolean name="flip_normals" value="true"/></shape>')
    assert warnings == []


def test_flip_normals_turns_a_rectangle_light_around(tmp_path):
    body = (camera_xml() + '<shape type="rectangle" id="up"><emitter type="area"/></shape>'
            '<shape type="rectangle" id="down"><boolean name="flip_normals" value="true"/><emitter type="area"/>'
            "</shape>")
    scene, warnings = load(tmp_path, body)
    m = world_matrices(scene)
    assert np.allclose(m["up"][:3, 2], (0, 0, 1)) and np.allclose(m["down"][:3, 2], (0, 0, -1))
    assert warnings == []
    _, warnings = load(tmp_path, camera_xml() + '<shape type="sphere"><boolean name="flip_normals" value="true"/>'
                       '<emitter type="area"/></shape>')
    assert "emits from its outside" in only(warnings, "flip_normals")


def test_each_bsdf_maps_to_a_material_with_one_warning_per_approximation(tmp_path):
    mirror = Conductor(metal="custom", eta=(0.0, 0.0, 0.0), k=(1.0, 1.0, 1.0))
    bsdfs = {  # plugin: (its properties, the material expected, a word of the warning or None)
        "diffuse": ('<rgb name="reflectance" value="0.2, 0.4, 0.6"/>', Diffuse((0.2, 0.4, 0.6)), None),
        "conductor": ("", mirror, None),
        "roughconductor": ('<string name="material" value="Cu"/><string name="distribution" value="ggx"/>'
                           '<float name="alpha" value="0.09"/><rgb name="specular_reflectance" value="0.5"/>',
                           Conductor(metal="copper", tint=(0.5, 0.5, 0.5), roughness=0.3), None),
        "plastic": ('<rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/><string name="int_ior" value="bk7"/>',
                    Plastic((0.1, 0.2, 0.3), ior=1.5046 / 1.000277, coating="single_scattering"), None),
        "roughplastic": ("", Plastic((0.5, 0.5, 0.5), ior=1.49 / 1.000277, roughness=math.sqrt(0.1),
                                     distribution="beckmann", coating="single_scattering"), None),
        "dielectric": ('<float name="int_ior" value="1.33"/><float name="ext_ior" value="1"/>'
                       '<rgb name="specular_transmittance" value="0.9, 1, 1"/>', Dielectric(1.33, tint=(0.9, 1.0, 1.0)), None),
        "roughdielectric": ('<float name="alpha_u" value="0.04"/><float name="alpha_v" value="0.16"/>'
                            '<string name="distribution" value="ggx"/>',
                            Dielectric(1.5046 / 1.000277, roughness=math.sqrt(0.08)), "anisotropic"),
        "thindielectric": ("", ThinDielectric(1.5046 / 1.000277), None),
        "principled": ('<rgb name="base_color" value="0.3"/><float name="metallic" value="1"/>',
                       Diffuse((0.3, 0.3, 0.3)), "not renderable yet"),
    }
    for kind, (inner, expected, warned) in bsdfs.items():
        scene, warnings = load(tmp_path, camera_xml() + f'<shape type="sphere" id="s">\n<bsdf type="{kind}">{inner}'
                               "</bsdf></shape>")
        got = scene.materials[scene.nodes[0].material]
        assert type(got) is type(expected), kind
        for name, value in vars(expected).items():
            if value is None or isinstance(value, str):
                assert getattr(got, name) == value, (kind, name)
            else:
                assert np.allclose(getattr(got, name), value, rtol=1e-9), (kind, name)
        if warned:
            assert f':4: <bsdf type="{kind}">' in only(warnings, warned), kind
        else:
            assert warnings == [], kind
    assert set(bsdfs) | {"twosided"} <= set(BSDF_MAPPINGS)


def test_conductors_without_a_preset_reflect_their_normal_incidence_colour(tmp_path):
    # A name Mitsuba 3 knows (amorphous carbon, chromium) takes Mitsuba's own complex index, with no warning;
    # a name only Mitsuba 0.6 knew (Ti) is matched at normal incidence, with one.
    for name in ("a-C", "Cr"):
        scene, warnings = load(tmp_path, camera_xml() + '<shape type="sphere"><bsdf type="conductor">'
                               f'<string name="material" value="{name}"/></bsdf></shape>')
        metal = scene.materials[scene.nodes[0].material]
        assert metal.complex_ior() == mv.MITSUBA_CONDUCTOR_IORS[name] and warnings == []
    scene, warnings = load(tmp_path, camera_xml() + '<shape type="sphere"><bsdf type="conductor">'
                           '<string name="material" value="Ti"/></bsdf></shape>')
    metal = scene.materials[scene.nodes[0].material]
    assert np.allclose(mv.conductor_f0(*metal.complex_ior()), mv.CONDUCTOR_F0["Ti"])
    assert "normal incidence" in only(warnings, '"Ti"')
    with pytest.raises(SceneError, match='line 3: <string name="int_ior">: unknown index of refraction "glas"'):
        load(tmp_path, camera_xml() + '<shape type="sphere"><bsdf type="plastic"><string name="int_ior" '
             'value="glas"/></bsdf></shape>')


def test_twosided_unwraps_and_unknown_bsdfs_warn(tmp_path):
    scene, warnings = load(tmp_path, camera_xml() + '<shape type="sphere"><bsdf type="twosided"><bsdf type="diffuse">'
                           '<rgb name="reflectance" value="0.3"/></bsdf></bsdf></shape>')
    assert scene.materials[scene.nodes[0].material] == Diffuse((0.3, 0.3, 0.3)) and warnings == []
    scene, warnings = load(tmp_path, camera_xml() + '<shape type="sphere"><bsdf type="hair"/></shape>')
    assert scene.materials[scene.nodes[0].material] == Diffuse((0.5, 0.5, 0.5))
    assert 'BSDF "hair" is not supported' in only(warnings, "hair")


def test_emitters_area_constant_and_unsupported(tmp_path):
    body = (camera_xml() + '<emitter type="constant"><rgb name="radiance" value="0.5, 0.6, 0.7"/></emitter>'
            '<shape type="rectangle" id="lamp"><bsdf type="diffuse"/><emitter type="area">'
            '<rgb name="radiance" value="10, 8, 6"/></emitter></shape>'
            '\n<emitter type="projector"><point name="position" x="0" y="1" z="0"/></emitter>'
            '<shape type="sphere" id="ball"/>')
    scene, warnings = load(tmp_path, body)
    assert scene.environment == ConstantEnvironment((0.5, 0.6, 0.7))
    lamp, ball = scene.nodes
    # The light keeps its BSDF as its surface: it reflects as in Mitsuba.
    assert scene.materials[lamp.material] == Emissive((10.0, 8.0, 6.0), two_sided=False, surface=Diffuse((0.5,) * 3))
    assert ':4: <emitter type="projector">' in only(warnings, 'emitter "projector"')
    assert len(warnings) == 1 and scene.lights == []


def test_point_and_directional_emitters_become_lights(tmp_path):
    body = (camera_xml() + '<emitter type="point" id="bulb"><point name="position" x="1" y="2" z="3"/>'
            '<rgb name="intensity" value="5, 6, 7"/></emitter>'
            '<emitter type="point"><transform name="to_world"><translate x="-1" y="4"/></transform></emitter>'
            '<emitter type="directional"><vector name="direction" x="0" y="-2" z="0"/>'
            '<rgb name="irradiance" value="3, 2, 1"/></emitter>'
            '<emitter type="directional"><transform name="to_world"><lookat origin="0,0,0" target="1,0,0" up="0,1,0"/>'
            "</transform></emitter>")
    scene, warnings = load(tmp_path, body)
    assert warnings == []
    bulb, default_point, sun, default_sun = scene.lights
    assert bulb == PointLight(name="bulb", position=(1.0, 2.0, 3.0), intensity=(5.0, 6.0, 7.0))
    assert default_point.position == (-1.0, 4.0, 0.0) and default_point.intensity == (1.0, 1.0, 1.0)
    # Mitsuba's direction is where the light goes; a SunLight's points back at the sun
    assert isinstance(sun, SunLight) and np.allclose(sun.direction, (0, 1, 0))
    assert sun.irradiance == (3.0, 2.0, 1.0) and sun.angular_diameter_deg == 0.0
    assert np.allclose(default_sun.direction, (-1, 0, 0)) and default_sun.irradiance == (1.0, 1.0, 1.0)


def test_envmap_is_turned_half_a_turn_onto_our_lat_long_convention(tmp_path):
    (tmp_path / "sky.exr").write_bytes(b"not read while importing")
    def env(extra=""):
        scene, warnings = load(tmp_path, camera_xml() + f'<emitter type="envmap"><string name="filename" '
                               f'value="sky.exr"/>{extra}</emitter>')
        return scene.environment, warnings

    environment, warnings = env('<float name="scale" value="2.5"/>')
    assert environment == EnvironmentMap(file="sky.exr", strength=2.5, rotation_deg=180.0, rows="pole_to_pole") and warnings == []
    environment, _ = env('<transform name="to_world"><rotate y="1" angle="30"/></transform>')
    assert environment.rotation_deg == pytest.approx(150.0)
    # our mapping with that rotation sends every direction to the texel Mitsuba reads (u = atan2(x, -z) / 2pi
    # of the direction in the map's frame, the inverse of to_world)
    from lenslab.render.environment import direction_to_uv

    d = np.random.default_rng(1).normal(size=(50, 3))
    local = d @ mv.rotate_matrix((0, 1, 0), 30.0)[:3, :3]  # inverse rotation applied to each row
    u_mitsuba = np.mod(np.arctan2(local[:, 0], -local[:, 2]) / (2 * np.pi), 1.0)
    u_ours = direction_to_uv(d, math.radians(environment.rotation_deg))[:, 0]
    assert np.allclose(np.mod(u_ours - u_mitsuba + 0.5, 1.0), 0.5, atol=1e-9)
    environment, warnings = env('<transform name="to_world"><rotate x="1" angle="90"/></transform>')
    assert warnings == [] and np.allclose(environment.zenith, (0, 0, 1))  # any rotation is kept (a tilt here)
    _, warnings = load(tmp_path, camera_xml() + '<emitter type="constant"/>\n<emitter type="envmap">'
                       '<string name="filename" value="sky.exr"/></emitter>')
    assert only(warnings, "one environment").endswith(":3")
    with pytest.raises(SceneError, match="line 4: <emitter type=\"envmap\">: environment map not found"):
        load(tmp_path, camera_xml() + '\n<emitter type="envmap"><string name="filename" value="nope.exr"/></emitter>')


def test_instances_of_a_shapegroup(tmp_path):
    body = (camera_xml() + '<shape type="shapegroup" id="pair"><shape type="sphere" id="a"/><shape type="cube" id="b">'
            '<transform name="to_world"><translate x="3"/></transform></shape></shape>'
            '<shape type="instance" id="i1"><ref id="pair"/><transform name="to_world"><translate y="10"/></transform>'
            '</shape><shape type="instance" id="i2"><ref id="pair"/></shape>')
    scene, warnings = load(tmp_path, body)
    assert [n.name for n in scene.nodes] == ["i1", "i2"] and warnings == []
    flat = scene.flatten()
    assert np.allclose(sorted(flat.spheres[:, 1]), [0, 10])
    assert flat.triangle_count == 24


def test_unsupported_shapes_and_unknown_things_warn_but_the_rest_loads(tmp_path):
    body = (camera_xml() + '\n<shape type="bsplinecurve"><string name="filename" value="hair.txt"/></shape>'
            '\n<medium type="homogeneous" id="fog"/>'
            '\n<shape type="sphere"><float name="radius" value="2"/><float name="wobble" value="1"/></shape>'
            '\n<frobnicate/>')
    scene, warnings = load(tmp_path, body)
    assert len(scene.nodes) == 1 and scene.nodes[0].shape == Sphere(2.0)
    assert ':4: <shape type="bsplinecurve">' in only(warnings, 'shape "bsplinecurve" is not supported')
    assert ":5: <medium" in only(warnings, "media")
    assert ':6: <float name="wobble">' in only(warnings, '"wobble" is not supported')
    assert ":7: <frobnicate>" in only(warnings, "unknown element")


def test_missing_mesh_file_is_an_error_with_file_and_line(tmp_path):
    with pytest.raises(SceneError, match=r"scene\.xml: line 4: <shape type=\"ply\">: mesh file not found: .*bunny\.ply"):
        load(tmp_path, camera_xml() + '\n<shape type="ply"><string name="filename" value="bunny.ply"/></shape>')


# ---------------------------------------------------------------------------------------------------------
# Values, integrator, film, sampler
# ---------------------------------------------------------------------------------------------------------
def test_rgb_and_spectrum_values(tmp_path):
    def albedo(value_xml):
        scene, _ = load(tmp_path, camera_xml() + f'<shape type="sphere"><bsdf type="diffuse">{value_xml}</bsdf></shape>')
        return np.array(scene.materials[scene.nodes[0].material].albedo)

    assert np.allclose(albedo('<rgb name="reflectance" value="0.25"/>'), 0.25)
    assert np.allclose(albedo('<float name="reflectance" value="0.25"/>'), 0.25)
    assert np.allclose(albedo('<spectrum name="reflectance" value="0.25"/>'), 0.25)  # uniform: grey
    assert np.allclose(albedo('<spectrum name="reflectance" value="360:0.5, 830:0.5"/>'), 0.5, atol=1e-9)
    # Mitsuba 3.9.1 reflectances for these spectra; our CIE fit and daylight stand-in are within 0.015
    for spectrum, mitsuba_391 in [("400:0.1, 500:0.5, 600:0.9, 700:0.2", (0.8338, 0.6891, 0.2652)),
                                  ("400:0.8, 450:0.7, 500:0.2, 700:0.1", (0.1471, 0.1495, 0.6598)),
                                  ("550:1, 600:1", (0.5630, 0.4008, 0.0))]:
        assert np.allclose(albedo(f'<spectrum name="reflectance" value="{spectrum}"/>'), mitsuba_391, atol=0.015)
    # emission spectra are absolute in Mitsuba 3: a uniform 0.3 renders as 0.3 * (1.20, 0.95, 0.91)
    for spectrum, mitsuba_391 in [("0.3", (0.3614, 0.2845, 0.2727)), ("360:0.5, 830:0.5", (0.6024, 0.4741, 0.4546)),
                                  ("400:0.1, 500:0.5, 600:0.9, 700:0.2", (0.9743, 0.6616, 0.2297))]:
        scene, _ = load(tmp_path, camera_xml() + f'<emitter type="constant"><spectrum name="radiance" '
                        f'value="{spectrum}"/></emitter>')
        assert np.allclose(scene.environment.radiance, mitsuba_391, atol=0.015)
    with pytest.raises(SceneError, match="line 3: <rgb.*one or three values"):
        load(tmp_path, camera_xml() + '<shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="1 2"/>'
             "</bsdf></shape>")


def test_integrator_sampler_and_film(tmp_path):
    def settings(integrator, sampler='<sampler type="independent"/>', rfilter='<rfilter type="box"/>'):
        return load(tmp_path, integrator + f'<sensor type="perspective">{sampler}<film type="hdrfilm">'
                    f'<integer name="width" value="32"/><integer name="height" value="24"/>{rfilter}</film></sensor>')

    scene, warnings = settings('<integrator type="path"><integer name="max_depth" value="2"/>'
                               '<integer name="rr_depth" value="9"/></integrator>')
    assert (scene.render.max_depth, scene.render.rr_depth) == (2, 9) and warnings == []
    scene, _ = settings('<integrator type="path"><integer name="max_depth" value="-1"/></integrator>')
    assert scene.render.max_depth == 1024
    scene, _ = settings('<integrator type="direct"/>')
    assert scene.render.max_depth == 2
    scene, warnings = settings('<integrator type="aov"><integrator type="path"><integer name="max_depth" value="3"/>'
                               "</integrator></integrator>")
    assert scene.render.max_depth == 3 and "nested integrator" in only(warnings, "aov")
    scene, _ = settings("", '<sampler type="stratified"><integer name="sample_count" value="64"/>'
                        '<integer name="seed" value="7"/></sampler>')
    assert (scene.render.spp, scene.render.seed, scene.render.sampler) == (64, 7, "sobol")
    assert scene.camera.resolution == (32, 24)
    assert scene.render.pixel_filter == "box"
    scene, warnings = settings("", rfilter='<rfilter type="gaussian"/>')
    assert (scene.render.pixel_filter, scene.render.filter_stddev, warnings) == ("gaussian", 0.5, [])
    scene, warnings = settings("", rfilter='<rfilter type="gaussian"><float name="stddev" value="0.8"/>'
                               '<float name="radius" value="3"/></rfilter>')
    assert (scene.render.pixel_filter, scene.render.filter_stddev, warnings) == ("gaussian", 0.8, [])
    scene, warnings = settings("", rfilter="")  # Mitsuba's default filter: a gaussian, stddev 0.5
    assert (scene.render.pixel_filter, scene.render.filter_stddev, warnings) == ("gaussian", 0.5, [])
    scene, warnings = settings("", rfilter='<rfilter type="tent"/>')
    assert scene.render.pixel_filter == "box" and "box filter" in only(warnings, 'reconstruction filter "tent"')


def test_mitsuba_06_scenes_are_upgraded(tmp_path):
    body = ('<integrator type="path"><integer name="maxDepth" value="5"/></integrator>'
            '<sensor type="perspective"><float name="fov" value="30"/><string name="fovAxis" value="y"/>'
            '<sampler type="independent"><integer name="sampleCount" value="9"/></sampler>'
            + BOX_FILM.format(w=20, h=10) + '</sensor><shape type="sphere"><bsdf type="diffuse">'
            '<rgb name="diffuseReflectance" value="0.1"/></bsdf></shape>')
    scene, warnings = load(tmp_path, body, version="0.6.0")
    assert scene.render.max_depth == 5 and scene.render.spp == 9 and warnings == []
    assert math.degrees(scene.camera.fov_x) == pytest.approx(mitsuba_fov_x(30, "y", 2.0))
    assert scene.materials[scene.nodes[0].material] == Diffuse((0.1, 0.1, 0.1))


# ---------------------------------------------------------------------------------------------------------
# Errors, logging, the loader
# ---------------------------------------------------------------------------------------------------------
def test_malformed_xml_is_one_error_with_file_line_and_column(tmp_path):
    path = tmp_path / "broken.xml"
    path.write_text('<scene version="3.0.0">\n  <shape type="sphere">\n  </shap>\n</scene>\n')
    with pytest.raises(SceneError, match=r"broken\.xml: line 3 column 5: not well-formed XML \(mismatched tag\)"):
        load_mitsuba_scene(path)
    path.write_text('<scene>\n<shape type="sphere"/></scene>')
    with pytest.raises(SceneError, match=r"broken\.xml: line 1: <scene> has no version attribute"):
        load_mitsuba_scene(path)
    with pytest.raises(SceneError, match="line 1: <bsdf.*root element must be <scene>"):
        load_mitsuba_string('<bsdf version="3.0.0" type="diffuse"/>')
    with pytest.raises(SceneError, match="no such scene file"):
        load_mitsuba_scene(tmp_path / "absent.xml")


def test_warnings_go_to_the_lenslab_import_logger_by_default(tmp_path, caplog):
    path = tmp_path / "s.xml"
    path.write_text('<scene version="3.0.0"><shape type="sphere"><bsdf type="principled"/></shape></scene>')
    with caplog.at_level(logging.WARNING, logger="lenslab.import"):
        load_mitsuba_scene(path)
    messages = [r.getMessage() for r in caplog.records if r.name == "lenslab.import"]
    assert any('s.xml:1: <bsdf type="principled">' in m for m in messages)
    assert any("no sensor" in m for m in messages)


def test_open_scene_reads_xml_files():
    from lenslab.scene.io.loader import open_scene

    scene = open_scene(DATA / "cbox.xml")
    assert scene.camera.resolution == (256, 256) and len(scene.nodes) == 8


# ---------------------------------------------------------------------------------------------------------
# End to end
# ---------------------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_imported_cornell_box_renders(renderer):
    from lenslab.render.tracer import RenderSession
    from tests.helpers import render_to_spp

    warnings: list[str] = []
    scene = load_mitsuba_scene(DATA / "cbox.xml", defines={"spp": "1"}, warn=warnings.append)
    assert scene.render.spp == 1 and warnings == []
    session = RenderSession(renderer, scene, width=32, height=32)
    image = render_to_spp(session, 1).image()
    try:
        assert image.shape == (32, 32, 3) and np.isfinite(image).all()
        assert image.mean() > 0.05
        # the red wall is on the left and the green one on the right, as Mitsuba shows them
        left, right = image[8:24, :4].mean(axis=(0, 1)), image[8:24, -4:].mean(axis=(0, 1))
        assert left[0] > left[1] and right[1] > right[0]
    finally:
        session.release()


def test_an_area_emitter_declared_at_the_top_and_referred_to_from_a_shape(tmp_path):
    # Mitsuba's own Cornell box declares its light's emitter at the top level and puts a <ref> in the shape:
    # the light is used, with no warning; one that no shape refers to is reported.
    body = (camera_xml() + '<emitter type="area" id="lamp"><rgb name="radiance" value="4"/></emitter>'
            '<emitter type="area" id="spare"><rgb name="radiance" value="1"/></emitter>'
            '<bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.78"/></bsdf>'
            '<shape type="rectangle" id="light"><ref id="lamp"/><ref id="white"/></shape>')
    scene, warnings = load(tmp_path, body)
    light = scene.materials[scene.nodes[0].material]
    assert light == Emissive((4.0, 4.0, 4.0), two_sided=False, surface=Diffuse((0.78,) * 3))
    assert '<emitter type="area" id="spare">' in only(warnings, "no <shape> refers to")
    assert len(warnings) == 1


def test_wrapping_bsdfs_map_onto_layered_materials(tmp_path):
    body = (camera_xml()
            + '<shape type="sphere" id="a"><bsdf type="blendbsdf"><float name="weight" value="0.3"/>'
              '<bsdf type="diffuse"/><bsdf type="roughconductor"><float name="alpha" value="0.04"/></bsdf></bsdf></shape>'
            + '<shape type="sphere" id="b"><bsdf type="mask"><rgb name="opacity" value="0.25"/>'
              '<bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf></shape>'
            + '<shape type="sphere" id="c"><bsdf type="blendbsdf"><bsdf type="mask"><bsdf type="diffuse"/></bsdf>'
              '<bsdf type="diffuse"/></bsdf></shape>'
            + '<shape type="sphere" id="d"><bsdf type="roughdielectric"><string name="distribution" value="cauchy"/>'
              '</bsdf></shape>')
    with pytest.raises(SceneError, match='unknown microfacet distribution "cauchy"'):
        load(tmp_path, body)
    scene, warnings = load(tmp_path, body.rsplit("<shape", 1)[0])
    blend = scene.materials[scene.nodes[0].material]
    assert isinstance(blend, Blend) and blend.weight == pytest.approx(0.3) and blend.first == Diffuse((0.5,) * 3)
    assert blend.second.roughness == pytest.approx(0.2) and blend.second.distribution == "beckmann"
    mask = scene.materials[scene.nodes[1].material]
    assert isinstance(mask, Mask) and mask.opacity == pytest.approx(0.25) and mask.material == Diffuse((0.5,) * 3)
    assert "a mask inside a blend does not cut" in only(warnings, "inside a blend")
    assert len(warnings) == 1


def test_a_top_level_sampler_referred_to_by_the_sensor_is_used_without_a_warning(tmp_path):
    body = ('<sampler type="stratified" id="s"><integer name="sample_count" value="9"/></sampler>'
            '<sensor type="perspective"><ref id="s"/><film type="hdrfilm"><integer name="width" value="8"/>'
            '<integer name="height" value="8"/></film></sensor><shape type="sphere"/>')
    scene, warnings = load(tmp_path, body)
    assert scene.render.spp == 9 and scene.render.sampler == "sobol"
    assert 'sampler "stratified" is rendered with' in only(warnings, "stratified")
    assert len(warnings) == 1


@pytest.mark.parametrize("transform", [
    '<matrix value="0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0"/>',  # once rendered, every pixel lost, with exit 0
    '<matrix value="0 0 0 1 0 0 0 2 0 0 0 3 0 0 0 1"/>',  # a position, and nothing to look along
    '<scale value="1 1 0"/>',  # +Z flattened
    '<matrix value="1 0 0 0 0 0 1 0 0 0 1 0 0 0 0 1"/>',  # +Y and +Z onto one line
])
def test_a_sensor_to_world_that_gives_no_view_is_refused(tmp_path, transform):
    body = (f'<sensor type="perspective"><transform name="to_world">{transform}</transform>'
            f'{BOX_FILM.format(w=8, h=8)}</sensor><shape type="sphere"/>')
    with pytest.raises(SceneError, match=r"scene\.xml: line 3: <sensor type=\"perspective\">: to_world gives the "
                                         r"camera no direction to look in or no up"):
        load(tmp_path, body)


@pytest.mark.parametrize("element, value", [
    ('<rgb name="radiance" value="{}"/>', "1e308"),  # finite here, infinite in the float32 light tables
    ('<rgb name="radiance" value="1 {} 1"/>', "2e30"),
    ('<float name="radiance" value="{}"/>', "-1e31"),
    ('<spectrum name="radiance" value="400:1 700:{}"/>', "1e40"),
])
def test_a_number_beyond_the_largest_any_scene_holds_is_refused_as_native_scenes_do(tmp_path, element, value):
    from lenslab.limits import LARGEST_NUMBER

    body = camera_xml() + f'<shape type="sphere"><emitter type="area">{element.format(value)}</emitter></shape>'
    with pytest.raises(SceneError, match=re.escape(f"'{value}' is too large (the most any value may be is "
                                                   f"{LARGEST_NUMBER:g})")):
        load(tmp_path, body)
    bound = "-1e30" if value.startswith("-") else "1e30"  # the bound itself is a number a scene may hold
    scene, _ = load(tmp_path, camera_xml() + f'<shape type="sphere"><emitter type="area">{element.format(bound)}'
                                             "</emitter></shape>")
    assert len(scene.nodes) == 1


def test_a_nan_in_a_sampled_spectrum_is_refused(tmp_path):
    body = (camera_xml() + '<shape type="sphere"><emitter type="area">'
            '<spectrum name="radiance" value="400:1 700:nan"/></emitter></shape>')
    with pytest.raises(SceneError, match="'nan' is not a finite number"):
        load(tmp_path, body)


@pytest.mark.parametrize("shape, expected", [
    ('<shape type="sphere"><float name="radius" value="-1"/></shape>', "a sphere's radius must be positive, not -1"),
    ('<shape type="sphere"><float name="radius" value="0"/></shape>', "a sphere's radius must be positive, not 0"),
    ('<shape type="cylinder"><float name="radius" value="-0.5"/></shape>',
     "a cylinder's radius must be positive, not -0.5"),
])
def test_a_radius_that_is_not_positive_is_refused(tmp_path, shape, expected):
    """A negative sphere radius was read as its absolute value without a word."""
    with pytest.raises(SceneError, match=re.escape(f'line 4: <shape type="{shape.split(chr(34))[1]}">: {expected}')):
        load(tmp_path, camera_xml() + "\n" + shape)
