"""The relief shape (fractal ground made in code) and the million-triangle scene built on it."""

from __future__ import annotations

import numpy as np
import pytest

from lenslab.cli import main
from lenslab.render.film import read_image
from lenslab.resources import scenes_dir
from lenslab.scene import flatten
from lenslab.scene.io.native import load_scene, save_scene
from lenslab.scene.scene import Node, Scene
from lenslab.scene.shapes import Relief


def face_normals(mesh) -> np.ndarray:
    corners = mesh.vertices[mesh.faces]
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_a_relief_is_a_grid_of_front_facing_triangles_within_its_height():
    relief = Relief(size=(2.0, 1.0), height=0.1, feature_size=0.3, octaves=6, resolution=(81, 41), seed=3)
    mesh = relief.mesh()
    assert mesh.triangle_count == 2 * 80 * 40
    x, y, z = mesh.vertices.T
    assert (x.min(), x.max(), y.min(), y.max()) == pytest.approx((-1.0, 1.0, -0.5, 0.5))
    # About `height` from lowest to highest point, centred on the plane.
    assert 0.4 * relief.height < np.ptp(z) < 1.5 * relief.height
    assert abs(z.mean()) < 0.25 * relief.height
    assert face_normals(mesh)[:, 2].min() > 0.0  # every face towards +Z, as a rectangle's
    assert mesh.uvs.min() == 0.0 and mesh.uvs.max() == 1.0


def test_relief_normals_follow_its_slopes():
    mesh = Relief(size=(1.0, 1.0), height=0.2, feature_size=0.4, octaves=3, resolution=(201, 201)).mesh()
    # Each vertex normal against the mean of the faces around it (interior vertices: six faces each).
    around = np.zeros_like(mesh.vertices)
    np.add.at(around, mesh.faces.reshape(-1), np.repeat(face_normals(mesh), 3, axis=0))
    around /= np.linalg.norm(around, axis=1, keepdims=True)
    cosines = np.einsum("ij,ij->i", around, mesh.normals)
    assert np.percentile(cosines, 1) > np.cos(np.radians(2.0))
    assert mesh.normals[:, 2].min() < np.cos(np.radians(10.0))  # the test has slopes to follow


def test_the_seed_picks_the_landscape_and_the_same_seed_gives_the_same_one():
    a, b, c = (Relief(resolution=(32, 32), seed=s).mesh() for s in (1, 1, 2))
    assert np.array_equal(a.vertices, b.vertices)
    assert not np.allclose(a.vertices[:, 2], c.vertices[:, 2])


def test_a_relief_survives_saving_and_loading(tmp_path):
    relief = Relief(size=(3.0, 2.0), height=0.05, feature_size=0.2, octaves=4, resolution=(64, 48), seed=9)
    save_scene(Scene(nodes=[Node("ground", shape=relief)]), tmp_path / "scene.json")
    loaded = load_scene(tmp_path / "scene.json").nodes[0].shape
    assert loaded == relief
    assert np.array_equal(loaded.mesh().vertices, relief.mesh().vertices)


@pytest.mark.parametrize("key, value, message", [
    ("resolution", [1, 64], r"nodes\[0\]\.shape\.resolution.*2"),
    ("octaves", 40, r"nodes\[0\]\.shape\.octaves.*16"),
    ("height", -1.0, r"nodes\[0\]\.shape\.height"),
])
def test_nonsense_relief_parameters_name_the_key(tmp_path, key, value, message):
    import json

    from lenslab.scene.scene import SceneError

    save_scene(Scene(nodes=[Node("ground", shape=Relief())]), tmp_path / "scene.json")
    data = json.loads((tmp_path / "scene.json").read_text())
    data["nodes"][0]["shape"][key] = value
    (tmp_path / "scene.json").write_text(json.dumps(data))
    with pytest.raises(SceneError, match=message):
        load_scene(tmp_path / "scene.json")


@pytest.mark.slow
def test_the_shipped_sand_holds_a_million_triangles_and_is_made_once_per_edit_session():
    scene = load_scene(scenes_dir() / "marbles_on_sand" / "scene.json")
    flatten._relief_mesh.cache_clear()
    flat = scene.flatten()
    assert flat.triangle_count >= 1_000_000
    scene.camera.f_number = 4.0  # an edit that leaves the sand as it was
    again = scene.flatten()
    assert flatten._relief_mesh.cache_info().hits == 1
    assert np.array_equal(again.triangles, flat.triangles)


@pytest.mark.slow
@pytest.mark.gl
def test_the_million_triangle_scene_renders_headless(renderer, tmp_path, capsys):
    out = tmp_path / "sand.exr"
    status = main([str(scenes_dir() / "marbles_on_sand" / "scene.json"), "--headless", "-o", str(out),
                   "--spp", "1", "--width", "48", "--height", "32"])
    err = capsys.readouterr().err
    assert status == 0, err
    pixels, _ = read_image(out)
    assert pixels.shape == (32, 48, 3) and np.isfinite(pixels).all()
    # Sunlit sand fills the frame: no pixel is the bare sky or black.
    assert np.percentile(pixels.mean(axis=2), 5) > 0.05
