"""The native scene format: lossless round trip, strict validation with one-line errors naming file and key."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from lenslab.resources import scenes_dir
from lenslab.scene.io.loader import open_scene, shipped_scene_names
from lenslab.scene.io.native import FORMAT_VERSION, load_scene, save_scene, scene_to_dict
from lenslab.scene.scene import SceneError
from lenslab.scene.shapes import MeshFile


@pytest.mark.parametrize("name", ["cornell_box", "dof_chart"])
def test_shipped_scenes_round_trip_losslessly(tmp_path, name):
    scene = open_scene(name)
    save_scene(scene, tmp_path / "copy.json")
    again = load_scene(tmp_path / "copy.json")
    assert again == scene
    assert scene_to_dict(again) == scene_to_dict(scene)
    assert json.loads((tmp_path / "copy.json").read_text())["lenslab_scene"] == FORMAT_VERSION == 4


def test_a_version_2_scene_reads_as_written_and_saves_as_the_newest_version(tmp_path):
    # Versions 3 and 4 added keys only: a version 2 file reads with their defaults (a light's radiance in nits).
    path = tmp_path / "v2.json"
    path.write_text(json.dumps({"lenslab_scene": 2, "materials": {"lamp": {"type": "emissive", "radiance": [2, 2, 2]}}}))
    scene = load_scene(path)
    assert scene.materials["lamp"].surface is None and scene.materials["lamp"].unit == "nits"
    save_scene(scene, tmp_path / "v4.json")
    saved = json.loads((tmp_path / "v4.json").read_text())
    assert saved["lenslab_scene"] == FORMAT_VERSION and saved["materials"]["lamp"]["surface"] is None
    assert saved["materials"]["lamp"]["unit"] == "nits"


def test_shipped_scenes_are_listed():
    assert {"cornell_box", "dof_chart"} <= set(shipped_scene_names())


def test_dof_chart_has_an_object_exactly_at_the_focus_distance():
    scene = open_scene("dof_chart")
    flat = scene.flatten()
    forward = np.subtract(scene.camera.look_at, scene.camera.position)
    forward = forward / np.linalg.norm(forward)
    depths = (flat.triangles.reshape(-1, 3) - scene.camera.position) @ forward
    plane = scene.camera.plane_of_focus_m  # the chart's focus reading is from the sensor: 3.087 m puts it at 3 m
    assert np.isclose(depths, plane, atol=2e-4).any()
    assert depths.min() < plane / 2 and depths.max() > 2 * plane


def test_round_trip_with_a_mesh_file(tmp_path):
    import trimesh

    trimesh.creation.icosphere(subdivisions=2).export(tmp_path / "ball.ply")
    scene = open_scene("cornell_box")
    walls_only = scene.flatten().triangle_count
    scene.nodes[0].children.append(type(scene.nodes[0])("ball", shape=MeshFile("ball.ply"), material="white"))
    save_scene(scene, tmp_path / "scene.json")
    again = load_scene(tmp_path / "scene.json")
    assert again == scene
    # The mesh path is relative to the scene file, so the copy finds the mesh beside it.
    assert again.flatten().triangle_count == walls_only + 320


def _write_broken(tmp_path, edit):
    data = json.loads((scenes_dir() / "cornell_box" / "scene.json").read_text())
    edit(data)
    path = tmp_path / "broken.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda d: d["camera"].update(f_stop=2.8), r"broken\.json: camera\.f_stop: unknown key"),
        (lambda d: d["camera"].update(f_number="2.8"), r"broken\.json: camera\.f_number: expected a number, got \"2\.8\""),
        (lambda d: d["camera"].update(f_number=0), r"broken\.json: camera\.f_number: 0 is out of range \[1e-06, 1e\+06\]"),
        (lambda d: d["camera"].update(resolution=[640]), r"camera\.resolution: expected a list of 2 numbers"),
        (lambda d: d["camera"].update(aperture_blades=2), r"camera: aperture_blades must be 0 \(round\) or at least 3"),
        (lambda d: d["camera"].update(look_at=d["camera"]["position"]), r"camera: camera look_at equals its position"),
        (lambda d: d["materials"]["white"].update(albedo=[1.2, 0, 0]), r"materials\.white\.albedo\[0\]: 1\.2 is out of range \[0, 1\]"),
        (lambda d: d["materials"]["white"].update(type="velvet"), r"materials\.white\.type: unknown type \"velvet\"; expected one of diffuse, emissive"),
        (lambda d: d["nodes"][1].update(material="chrome"), r"nodes\[1\]\.material: unknown material 'chrome'"),
        (lambda d: d["nodes"][1].update(shape={"type": "mesh", "file": "nowhere.obj"}), r"nodes\[1\]\.shape\.file: mesh file not found: .*nowhere\.obj"),
        (lambda d: d["nodes"][0]["children"][0]["transform"].update(scale=[1, 0, 1]), r"nodes\[0\]\.children\[0\]\.transform\.scale\[1\]: must not be zero"),
        (lambda d: d["render"].update(sampler="halton"), r"render\.sampler: 'halton' is not one of sobol, independent"),
        (lambda d: d.update(lenslab_scene=7), r"lenslab_scene: version 7 is not supported"),
        (lambda d: d.pop("lenslab_scene"), r"lenslab_scene: missing: this is not a LensLab scene"),
        (lambda d: d.update(cameras=[]), r"broken\.json: cameras: unknown key"),
    ],
)
def test_invalid_scene_is_one_line_naming_file_and_key(tmp_path, edit, message):
    path = _write_broken(tmp_path, edit)
    with pytest.raises(SceneError, match=message) as info:
        load_scene(path)
    assert "\n" not in str(info.value)


def test_malformed_json_names_the_line(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text('{\n  "lenslab_scene": 1,\n  "camera": {,}\n}\n')
    with pytest.raises(SceneError, match=r"bad\.json: line 3 column 14: not valid JSON"):
        load_scene(path)


def test_missing_scene_file_is_named(tmp_path):
    with pytest.raises(SceneError, match=r"nothing\.json: no such scene file"):
        open_scene(tmp_path / "nothing.json")


def test_unreadable_mesh_names_the_scene_and_the_node(tmp_path):
    shutil.copytree(scenes_dir() / "cornell_box", tmp_path / "box")
    (tmp_path / "box" / "junk.obj").write_text("this is not a mesh\n")
    data = json.loads((tmp_path / "box" / "scene.json").read_text())
    data["nodes"].append({"name": "junk", "shape": {"type": "mesh", "file": "junk.obj"}})
    (tmp_path / "box" / "scene.json").write_text(json.dumps(data))
    scene = load_scene(tmp_path / "box" / "scene.json")
    with pytest.raises(SceneError, match=r"scene\.json: node 'junk': .*junk\.obj: (no triangles|cannot read)"):
        scene.flatten()


def test_saving_is_atomic(tmp_path, monkeypatch):
    scene = open_scene("cornell_box")
    target = tmp_path / "scene.json"
    save_scene(scene, target)
    before = target.read_text()

    def explode(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr("os.replace", explode)
    scene.camera.f_number = 8.0
    with pytest.raises(OSError):
        save_scene(scene, target)
    assert target.read_text() == before
    assert [p.name for p in tmp_path.iterdir()] == ["scene.json"]  # no temporary left behind


def test_saved_files_get_ordinary_permissions(tmp_path):
    import os
    import stat

    mask = os.umask(0o022)
    try:
        save_scene(open_scene("cornell_box"), tmp_path / "scene.json")
    finally:
        os.umask(mask)
    assert stat.S_IMODE((tmp_path / "scene.json").stat().st_mode) == 0o644  # not the temporary file's 0600
