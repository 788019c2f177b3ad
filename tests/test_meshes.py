"""Triangle meshes come in through trimesh in every format the scene format promises."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.scene import Node, Scene
from lenslab.scene.shapes import MeshFile
from lenslab.scene.transform import Transform


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl", ".glb", ".gltf", ".off"])
def test_mesh_formats_load_with_their_triangles(tmp_path, suffix):
    source = trimesh.creation.icosphere(subdivisions=2, radius=0.5)
    path = tmp_path / f"ball{suffix}"
    source.export(path)
    scene = Scene(camera=ThinLensCamera(), nodes=[Node("ball", Transform(translate=(0, 1, 0)), MeshFile(path.name))],
                  source_path=tmp_path / "scene.json")
    flat = scene.flatten()
    assert flat.triangle_count == len(source.faces)
    centre = flat.triangles.reshape(-1, 3).mean(axis=0)
    assert np.allclose(centre, (0, 1, 0), atol=1e-3)
    radii = np.linalg.norm(flat.triangles.reshape(-1, 3) - (0, 1, 0), axis=1)
    assert np.allclose(radii, 0.5, atol=1e-4)
    # Smooth shading normals point outwards, along the radius.
    normals = flat.triangle_normals.reshape(-1, 3)
    outward = (flat.triangles.reshape(-1, 3) - (0, 1, 0)) / 0.5
    assert np.einsum("ij,ij->i", normals, outward).min() > 0.95


def test_mirroring_transform_keeps_front_faces_in_front(tmp_path):
    from lenslab.scene.shapes import Box

    plain = Scene(nodes=[Node("box", shape=Box())]).flatten()
    mirrored = Scene(nodes=[Node("box", Transform(scale=(-1, 1, 1)), Box())]).flatten()

    def outward_fraction(flat):
        tri = flat.triangles
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        return np.mean(np.einsum("ij,ij->i", n, tri.mean(axis=1)) > 0)

    assert outward_fraction(plain) == 1.0
    assert outward_fraction(mirrored) == 1.0


def test_disk_keeps_the_area_of_the_circle():
    from lenslab.scene.shapes import Disk

    mesh = Disk(radius=0.7, segments=12).mesh()
    tri = mesh.vertices[mesh.faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    assert area.sum() == pytest.approx(np.pi * 0.7**2, rel=1e-9)
    assert np.all(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2] > 0)  # front face towards +Z


def test_a_whole_mesh_file_reads_as_one_mesh_with_its_texture_coordinates(tmp_path):
    # The studio's import and the Mitsuba importer's framing read a file whole. A PLY with texture coordinates
    # once failed there (trimesh wanted PIL for them); an OBJ with two materials joins its parts.
    from lenslab.scene.io.meshes import load_mesh

    ply = tmp_path / "uv.ply"
    ply.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "property float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_indices\n"
                   "end_header\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n")
    mesh = load_mesh(ply)
    assert mesh.faces.tolist() == [[0, 1, 2]] and mesh.uvs.tolist() == [[0, 0], [1, 0], [0, 1]]
    (tmp_path / "two.mtl").write_text("newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n")
    obj = tmp_path / "two.obj"
    obj.write_text("mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 2 4 3\n")
    joined = load_mesh(obj)
    assert len(joined.faces) == 2 and joined.faces.max() < len(joined.vertices)
    assert sorted(map(tuple, joined.vertices[joined.faces].reshape(-1, 3).round(6).tolist())) == sorted(
        [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])


@pytest.mark.parametrize("compiled", [False, True])
def test_smooth_normals_are_trimeshs_angle_weighted_normals(compiled, monkeypatch):
    """A file without normals gets the normals trimesh (and Mitsuba) would make, made faster here; faces of zero
    area add nothing, and a vertex only they use gets none."""
    from lenslab.scene.io import meshes

    monkeypatch.setattr(meshes, "COMPILED_NORMALS_MIN_FACES", 0 if compiled else 1 << 40)
    ball = trimesh.creation.icosphere(subdivisions=3)
    rng = np.random.default_rng(4)
    vertices = ball.vertices * (1 + 0.2 * rng.uniform(-1, 1, (len(ball.vertices), 1)))
    faces = np.concatenate([ball.faces, [[0, 0, 1]], [[len(vertices), len(vertices) + 1, len(vertices)]]])
    vertices = np.concatenate([vertices, [[5.0, 5.0, 5.0], [6.0, 6.0, 6.0]]])  # two vertices of a degenerate face
    expected = trimesh.Trimesh(vertices[: len(ball.vertices)], ball.faces, process=False).vertex_normals
    normals = meshes.smooth_normals(vertices, faces)
    assert normals.shape == vertices.shape
    assert np.abs(normals[: len(ball.vertices)] - expected).max() < 1e-5
    assert (normals[len(ball.vertices):] == 0).all()
