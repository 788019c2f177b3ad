"""The compiled OBJ and ASCII PLY readers (scene/io/text_meshes.py) against trimesh's parsers and Python's own
float(): the same triangles, corner for corner, the same numbers, and trimesh's reading wherever a file is
outside the compiled subset."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
import trimesh

import lenslab.scene.io
from lenslab.scene.io import mesh_materials, text_meshes
from lenslab.scene.io.meshes import load_mesh_parts

pytest.importorskip("numba")
from lenslab.scene.io import text_compiled  # noqa: E402  (after the skip: it needs numba)


# -- numbers ------------------------------------------------------------------------------------------------
def read_numbers(text: str) -> tuple[int, np.ndarray]:
    return text_compiled.read_numbers(np.frombuffer(text.encode(), np.uint8), 0, text_compiled.POWERS_OF_TEN)


def test_numbers_are_those_python_reads():
    rng = np.random.default_rng(3)
    values = np.concatenate([rng.uniform(-2, 2, 300), rng.normal(0, 1e4, 100)])
    written = ([f"{v:.6f}" for v in values] + [f"{v:.9g}" for v in values] + [f"{v:e}" for v in values]
               + [f"{v:.15g}" for v in values] + ["0", "-0", "+1.5", ".5", "5.", "1E3", "2e-5", "007", "-0.000001",
                                                  "1e22", "1e-22", "0e99"])
    status, got = read_numbers(" \t".join(written[:500]) + "\n" + "\r\n".join(written[500:]))
    assert status == text_compiled.READ
    assert np.array_equal(got, [float(w) for w in written])  # rounded correctly, as strtod does


@pytest.mark.parametrize("number", ["0.12345678901234567", "123456789012345678", "1e23", "1.5e-30",
                                    "0.0000000000000000001"])
def test_longer_numbers_are_left_to_an_exact_reader(number):
    status, _ = read_numbers(f"1 {number} 2")
    assert status == text_compiled.LONG_NUMBERS


@pytest.mark.parametrize("text", ["1 2 x", "1 2 nan", "1 - 2", "1e", "1.2.3", "0x10"])
def test_a_token_that_is_no_decimal_is_outside_the_subset(text):
    status, _ = text_compiled.read_numbers(np.frombuffer(text.encode(), np.uint8), 0, text_compiled.POWERS_OF_TEN)
    assert status == text_compiled.OUTSIDE_SUBSET


# -- OBJ ----------------------------------------------------------------------------------------------------
def read_obj(path):
    reading = text_meshes.read_obj(path.read_bytes())
    return None if reading is None else reading.pieces


def corner_table(vertices, faces, normals=None, uvs=None) -> np.ndarray:
    """Each triangle's corners as rows of (position, uv, normal), each triangle rotated to start at its least
    corner (the winding kept) and the triangles sorted: two readings of a file compare equal when they hold the
    same triangles, whatever order they list them and their vertices in."""
    columns = [np.asarray(vertices, float)]
    columns += [np.asarray(uvs, float)] if uvs is not None else []
    columns += [np.asarray(normals, float)] if normals is not None else []
    corner = np.concatenate(columns, axis=1)[np.asarray(faces)]  # (F, 3, C)
    rotated = []
    for triangle in corner:
        keys = [tuple(row) for row in triangle]
        first = keys.index(min(keys))
        rotated.append(np.roll(triangle, -first, axis=0).ravel())
    table = np.array(rotated)
    return table[np.lexsort(table.T[::-1])]


def trimesh_pieces(path):
    scene = trimesh.load(str(path), process=False, force="scene")
    return list(scene.geometry.values())


def cube_obj(corner_form: str, *, polygons=True, relative=False, crlf=False, clutter=False) -> str:
    """A cube with separate uv and normal streams (so that vertices split at seams), quads or triangles."""
    positions = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    uv = [(0, 0), (1, 0), (1, 1), (0, 1)]
    normals = [(-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), (0, 0, -1), (0, 0, 1)]
    lines = ["# a cube", "mtllib cube.mtl", "o Cube"] if clutter else []
    lines += [f"v {x:.6f} {y:+.6f} {z:.3e}" for x, y, z in positions]
    lines += [f"vt {u} {v}" + (" 0" if clutter else "") for u, v in uv]
    lines += [f"vn {a} {b} {c}" for a, b, c in normals]
    for k, quad in enumerate(quads):
        if clutter and k % 2 == 0:
            lines += ["g side", "s 1", f"usemtl {'red' if k < 3 else 'blue'}"]

        def corner(j, i):
            p, t, n = quad[i] + 1, i + 1, k + 1
            if relative:
                p, t, n = p - 9, t - 5, n - 7
            return corner_form.format(p=p, t=t, n=n)
        if polygons:
            lines.append("f " + " ".join(corner(j, i) for j, i in enumerate(range(4))))
        else:
            lines.append("f " + " ".join(corner(j, i) for j, i in enumerate((0, 1, 2))) + ("  # tri" if clutter else ""))
            lines.append("f " + " ".join(corner(j, i) for j, i in enumerate((0, 2, 3))))
    return ("\r\n" if crlf else "\n").join(lines) + "\n"


@pytest.mark.parametrize("form", ["{p}", "{p}/{t}", "{p}//{n}", "{p}/{t}/{n}"])
@pytest.mark.parametrize("variant", [dict(), dict(polygons=False), dict(relative=True), dict(crlf=True),
                                     dict(clutter=True, polygons=False)])
def test_obj_reads_the_triangles_trimesh_reads(tmp_path, form, variant):
    path = tmp_path / "cube.obj"
    path.write_text(cube_obj(form, **variant), newline="")
    pieces = read_obj(path)
    assert pieces is not None
    if variant.get("clutter"):
        assert [piece.material for piece in pieces] == ["red", "blue"]
        assert text_meshes.read_obj(path.read_bytes()).libraries == ["cube.mtl"]
    plain = tmp_path / "plain.obj"  # trimesh reads no comment at the end of a face's line
    plain.write_text(cube_obj(form, **variant).replace("  # tri", ""), newline="")
    theirs = trimesh_pieces(plain)
    assert sum(len(p.faces) for p in pieces) == 12
    ours = np.concatenate([corner_table(p.vertices, p.faces, p.normals if "{n}" in form else None,
                                        p.uvs if "{t}" in form else None) for p in pieces])
    reference = np.concatenate([corner_table(g.vertices, g.faces,
                                             g._cache.cache.get("vertex_normals") if "{n}" in form else None,
                                             g.visual.uv if "{t}" in form else None) for g in theirs])
    if variant.get("relative"):  # trimesh takes a negative index from the end of the whole file, not the line
        reference = None
    if reference is not None:
        ours, reference = ours[np.lexsort(ours.T[::-1])], reference[np.lexsort(reference.T[::-1])]
        assert np.array_equal(ours, reference)
    # Seams stay seams: a vertex is one (position, uv, normal) triple.
    for piece in pieces:
        table = np.concatenate([c for c in (piece.vertices, piece.uvs, piece.normals) if c is not None], axis=1)
        assert len(np.unique(table, axis=0)) == len(table)


def test_relative_indices_count_back_from_the_line(tmp_path):
    path = tmp_path / "two.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf -3 -2 -1\n")
    (piece,) = read_obj(path)
    assert np.array_equal(piece.vertices[piece.faces][1], [[5, 5, 5], [6, 5, 5], [5, 6, 5]])


def test_an_exported_ball_reads_as_trimesh_reads_it(tmp_path):
    ball = trimesh.creation.icosphere(subdivisions=5)
    ball.vertices = ball.vertices * (1 + 0.1 * np.sin(7 * ball.vertices[:, :1]))
    path = tmp_path / "ball.obj"
    path.write_text(trimesh.exchange.obj.export_obj(ball, include_normals=True))
    (piece,) = read_obj(path)
    (theirs,) = trimesh_pieces(path)
    assert np.array_equal(piece.vertices, theirs.vertices) and np.array_equal(piece.faces, theirs.faces)
    assert np.array_equal(piece.normals, theirs._cache.cache["vertex_normals"])


@pytest.mark.parametrize("text", [
    "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 1 0 0\nf 1 2 3\n",  # vertex colours
    "v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 1\nf 1 2 3\n",  # a w
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nf 1 2 3\n",  # a line
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n3\n",  # a continued line
    "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",  # faces before their vertices
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3\n",  # some corners with a uv, some without
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",  # a face of two corners
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",  # past the vertices
])
def test_what_is_outside_the_subset_goes_to_trimesh(tmp_path, text):
    path = tmp_path / "odd.obj"
    path.write_text(text)
    assert read_obj(path) is None


def test_vertex_colours_are_still_reported(tmp_path, compiled_for_every_size):
    path = tmp_path / "coloured.obj"
    path.write_text("v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 1 0 0\nf 1 2 3\n")
    loaded = load_mesh_parts(path)
    assert loaded.parts[0].mesh.triangle_count == 1
    assert any("vertex colours" in w for w in loaded.warnings)


@pytest.fixture
def compiled_for_every_size(monkeypatch):
    """Small files are left to trimesh (mesh_materials.TEXT_COMPILED_MIN_BYTES); these tests read theirs compiled."""
    monkeypatch.setattr(mesh_materials, "TEXT_COMPILED_MIN_BYTES", 0)
    mesh_materials._load_cached.cache_clear()
    yield
    mesh_materials._load_cached.cache_clear()


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "trimesh"])
def test_obj_materials_come_from_every_library(tmp_path, monkeypatch, compiled):
    if compiled:
        monkeypatch.setattr(mesh_materials, "TEXT_COMPILED_MIN_BYTES", 0)
    (tmp_path / "a.mtl").write_text("newmtl red\nKd 1 0 0\n")
    (tmp_path / "b.mtl").write_text("newmtl blue\nKd 0 0 1\n")
    path = tmp_path / "two.obj"
    path.write_text("mtllib a.mtl\nmtllib b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl blue\n"
                    "f 1 3 2\nusemtl red\nf 2 3 1\n")
    loaded = load_mesh_parts(path)
    assert [part.name for part in loaded.parts] == ["red", "blue"]
    assert [part.mesh.triangle_count for part in loaded.parts] == [2, 1]
    assert loaded.parts[0].material.albedo == (1.0, 0.0, 0.0)
    assert loaded.parts[1].material.albedo == (0.0, 0.0, 1.0)


# -- ASCII PLY ----------------------------------------------------------------------------------------------
def ascii_ply(mesh, *, normals=False, types="float") -> str:
    props = "".join(f"property {types} {c}\n" for c in "xyz")
    if normals:
        props += "".join(f"property {types} n{c}\n" for c in "xyz")
    rows = np.hstack([mesh.vertices, mesh.vertex_normals]) if normals else mesh.vertices
    body = "".join(" ".join(repr(float(x)) for x in row) + "\n" for row in rows)
    faces = "".join(f"3 {a} {b} {c}\n" for a, b, c in mesh.faces)
    return (f"ply\nformat ascii 1.0\ncomment made by a test\nelement vertex {len(rows)}\n{props}"
            f"element face {len(mesh.faces)}\nproperty list uchar int vertex_indices\nend_header\n{body}{faces}")


@pytest.mark.parametrize("normals", [False, True])
@pytest.mark.parametrize("types", ["float", "double"])
def test_ascii_ply_reads_as_trimesh_reads_it(tmp_path, normals, types):
    ball = trimesh.creation.icosphere(subdivisions=3)
    path = tmp_path / "ball.ply"
    path.write_text(ascii_ply(ball, normals=normals, types=types))
    piece = text_meshes.read_ascii_ply(path)
    (theirs,) = trimesh_pieces(path)
    assert np.array_equal(piece.vertices, theirs.vertices)
    assert np.array_equal(piece.faces, theirs.faces)
    if normals:
        assert np.array_equal(piece.normals, theirs._cache.cache["vertex_normals"])
    else:
        assert piece.normals is None
    if types == "float":  # what a float property holds is a float32
        assert np.array_equal(piece.vertices, piece.vertices.astype(np.float32))


def test_ascii_ply_polygons_are_fanned(tmp_path):
    path = tmp_path / "quad.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 2\nproperty list uchar int vertex_index\nend_header\n"
                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 2 2\n4 0 1 2 3\n3 1 4 2\n")
    piece = text_meshes.read_ascii_ply(path)
    assert piece.faces.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 2]]


@pytest.mark.parametrize("header, body", [
    ("property float x\nproperty float y\nproperty float z\nproperty uchar red\n", "0 0 0 1\n1 0 0 1\n0 1 0 1\n"),
    ("property float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\n",
     "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n"),
    ("property float x\nproperty float y\nproperty float z\n", "0 0 0\n1 0 0\n0 1 0 7\n"),  # a stray number
    ("property float x\nproperty float y\nproperty float z\n", "0 0 0\n1 0 0\n0 1 zero\n"),
])
def test_ascii_ply_outside_the_subset_goes_to_trimesh(tmp_path, header, body):
    path = tmp_path / "odd.ply"
    path.write_text(f"ply\nformat ascii 1.0\nelement vertex 3\n{header}element face 1\n"
                    f"property list uchar int vertex_indices\nend_header\n{body}3 0 1 2\n")
    assert text_meshes.read_ascii_ply(path) is None


def test_binary_ply_is_not_for_the_text_reader(tmp_path, compiled_for_every_size):
    path = tmp_path / "ball.ply"
    path.write_bytes(trimesh.exchange.ply.export_ply(trimesh.creation.icosphere(subdivisions=1)))
    assert text_meshes.read_ascii_ply(path) is None
    assert load_mesh_parts(path).parts[0].mesh.triangle_count == 80


# -- without numba ------------------------------------------------------------------------------------------
def test_without_numba_trimesh_reads_the_text_formats(tmp_path, hide_package, monkeypatch, compiled_for_every_size):
    hide_package("numba")
    monkeypatch.delitem(sys.modules, "lenslab.scene.io.text_compiled")
    monkeypatch.delattr(lenslab.scene.io, "text_compiled")
    mesh_materials._load_cached.cache_clear()
    path = tmp_path / "cube.obj"
    path.write_text(cube_obj("{p}/{t}/{n}"))
    assert read_obj(path) is None
    loaded = load_mesh_parts(path)
    assert sum(part.mesh.triangle_count for part in loaded.parts) == 12
    assert math.isfinite(float(loaded.parts[0].mesh.vertices.sum()))


def test_a_file_trimesh_reads_keeps_its_materials(tmp_path, compiled_for_every_size):
    (tmp_path / "a.mtl").write_text("newmtl red\nKd 1 0 0\n")
    path = tmp_path / "lines.obj"  # a line statement: outside the compiled subset
    path.write_text("mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nusemtl red\nf 1 2 3\n")
    assert read_obj(path) is None
    (part,) = load_mesh_parts(path).parts
    assert part.name == "red" and part.material.albedo == (1.0, 0.0, 0.0)
