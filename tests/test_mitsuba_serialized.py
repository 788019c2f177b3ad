"""Mitsuba's ``.serialized`` meshes (``lenslab.scene.io.mitsuba_serialized``): read as Mitsuba reads them, several
to a file, in the importer, the native format and a headless render, and every damaged file one line.

The files are written here by :func:`write_serialized`, from the format as ``src/shapes/serialized.cpp``
(Mitsuba 3.9.1) reads it. That Mitsuba reads these files as LensLab does is checked by
``test_mitsuba_reads_the_same_meshes`` where Mitsuba 3 is installed.
"""

from __future__ import annotations

import json
import random
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from lenslab.scene.io import mitsuba_serialized
from lenslab.scene.io.meshes import MeshLoadError, load_mesh_parts
from lenslab.scene.io.mitsuba_serialized import read_serialized
from lenslab.scene.io.mitsuba_xml import load_mitsuba_scene
from lenslab.scene.io.native import load_scene, save_scene
from lenslab.scene.scene import Node, Scene, SceneError
from lenslab.scene.shapes import MeshFile


def mesh_stream(vertices, faces, normals=None, uvs=None, colours=None, *, version=4, double=False,
                name="mesh", extra_flags=0, level=-1) -> bytes:
    """One mesh as Mitsuba writes it: the header, then a zlib stream (uvs in Mitsuba's convention, v down)."""
    flags = extra_flags | (0x2000 if double else 0x1000)
    flags |= (0x1 if normals is not None else 0) | (0x2 if uvs is not None else 0) | (0x8 if colours is not None else 0)
    real = "<f8" if double else "<f4"
    body = struct.pack("<I", flags) + (name.encode() + b"\0" if version == 4 else b"")
    body += struct.pack("<QQ", len(vertices), len(faces))
    body += b"".join(np.asarray(a, real).tobytes() for a in (vertices, normals, uvs, colours) if a is not None)
    body += np.asarray(faces, "<u4").tobytes()
    return struct.pack("<HH", 0x041C, version) + zlib.compress(body, level)


def write_serialized(path: Path, meshes: list[dict], version: int = 4, table: bool = True) -> Path:
    """A file of several meshes (each a dict of mesh_stream's arguments) and the table of where each starts."""
    data, offsets = b"", []
    for mesh in meshes:
        offsets.append(len(data))
        data += mesh_stream(**mesh, version=version)
    if table:
        data += np.asarray(offsets, "<u8" if version == 4 else "<u4").tobytes() + struct.pack("<I", len(meshes))
    path.write_bytes(data)
    return path


def random_mesh(rng: np.random.Generator, vertices: int, faces: int, **with_what) -> dict:
    mesh = {"vertices": rng.normal(size=(vertices, 3)), "faces": rng.integers(0, vertices, size=(faces, 3))}
    if with_what.get("normals"):
        normals = rng.normal(size=(vertices, 3))
        mesh["normals"] = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    if with_what.get("uvs"):
        mesh["uvs"] = rng.random((vertices, 2))
    if with_what.get("colours"):
        mesh["colours"] = rng.random((vertices, 3))
    mesh["double"] = bool(with_what.get("double"))
    return mesh


def four_meshes() -> list[dict]:
    rng = np.random.default_rng(7)
    return [random_mesh(rng, 5, 4), random_mesh(rng, 7, 6, normals=True, uvs=True, colours=True),
            random_mesh(rng, 4, 2, uvs=True, double=True), random_mesh(rng, 6, 3, normals=True, colours=True, double=True)]


# A unit square in the XY plane (two triangles, normals +Z, uvs at the corners) and a tetrahedron: the meshes
# of a small material preview, a floor and an object on it.
SQUARE = {"vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], "faces": [[0, 1, 2], [0, 2, 3]],
          "normals": [[0, 0, 1]] * 4, "uvs": [[0, 1], [1, 1], [1, 0], [0, 0]]}
TETRA = {"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], "faces": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}


# ---------------------------------------------------------------------------------------------------------
# The reader
# ---------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("version", [3, 4])
def test_each_mesh_of_a_file_reads_back_as_written(tmp_path, version):
    meshes = four_meshes()
    path = write_serialized(tmp_path / "m.serialized", meshes, version=version)
    for index, written in enumerate(meshes):
        mesh = read_serialized(path, index)
        assert mesh.vertices.dtype == np.float64 and mesh.faces.dtype == np.int64
        assert np.allclose(mesh.vertices, written["vertices"], atol=1e-6)  # float32 unless written double
        assert np.array_equal(mesh.faces, written["faces"])
        if "normals" in written:
            assert np.allclose(mesh.normals, written["normals"], atol=1e-6)
        else:
            assert mesh.normals is None
        if "uvs" in written:  # Mitsuba's v runs down the image, ours up
            assert np.allclose(mesh.uvs, np.c_[written["uvs"][:, 0], 1.0 - written["uvs"][:, 1]], atol=1e-6)
        else:
            assert mesh.uvs is None
    if version == 4:  # float64 arrays are read whole, not rounded through float32
        assert np.array_equal(read_serialized(path, 2).vertices, meshes[2]["vertices"])


def test_the_first_mesh_needs_no_table_as_in_mitsuba(tmp_path):
    path = write_serialized(tmp_path / "one.serialized", [TETRA], table=False)
    assert np.array_equal(read_serialized(path).faces, TETRA["faces"])
    with pytest.raises(MeshLoadError):  # a second mesh is looked up in the table, which this file lacks
        read_serialized(path, 1)


@pytest.mark.slow  # a comparison with Mitsuba 3: the full validation
def test_mitsuba_reads_the_same_meshes(tmp_path):
    """Mitsuba 3's own reader, on the same files: positions, indices, normals, texture coordinates (v flipped)."""
    mi = pytest.importorskip("mitsuba", reason="Mitsuba 3 is not installed (pip install 'lenslab[validate]')")
    meshes = four_meshes()
    previous = mi.variant()  # (variant_context cannot restore "none yet")
    mi.set_variant("scalar_rgb")
    try:
        for version in (3, 4):
            path = write_serialized(tmp_path / f"v{version}.serialized", meshes, version=version)
            for index, written in enumerate(meshes):
                params = mi.traverse(mi.load_dict({"type": "serialized", "filename": str(path), "shape_index": index}))
                ours = read_serialized(path, index)
                assert np.allclose(np.array(params["vertex_positions"]).reshape(-1, 3), ours.vertices, atol=1e-6)
                assert np.array_equal(np.array(params["faces"]).reshape(-1, 3), ours.faces)
                if "normals" in written:
                    assert np.allclose(np.array(params["vertex_normals"]).reshape(-1, 3), ours.normals, atol=1e-6)
                if "uvs" in written:
                    theirs = np.array(params["vertex_texcoords"]).reshape(-1, 2)
                    assert np.allclose(np.c_[theirs[:, 0], 1.0 - theirs[:, 1]], ours.uvs, atol=1e-6)
    finally:
        if previous:
            mi.set_variant(previous)


# ---------------------------------------------------------------------------------------------------------
# As a mesh file: the loader, the importer, the native format, a render
# ---------------------------------------------------------------------------------------------------------
def test_loader_computes_smooth_normals_where_the_file_has_none_and_keeps_the_files_own(tmp_path):
    path = write_serialized(tmp_path / "m.serialized", [SQUARE, TETRA])
    (square,) = load_mesh_parts(path, True, 0).parts
    assert np.allclose(square.mesh.normals, [[0, 0, 1]] * 4) and square.material is None
    (tetra,) = load_mesh_parts(path, True, 1).parts
    corner = tetra.mesh.normals[0]  # at the origin: the three faces around it, weighted by angle, point out
    assert np.allclose(corner, -np.ones(3) / np.sqrt(3), atol=1e-6)
    assert load_mesh_parts(path, False, 1).parts[0].mesh.normals is None
    assert load_mesh_parts(path, True, 1) is load_mesh_parts(path, True, 1)  # cached, per mesh of the file


def test_shape_index_belongs_to_serialized_files_only(tmp_path):
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(MeshLoadError, match=r"tri\.obj: shape_index 2: only a Mitsuba \.serialized file holds"):
        load_mesh_parts(tmp_path / "tri.obj", True, 2)


def matpreview_xml(file="preview.serialized", interior_index=1, extra="") -> str:
    """A material preview laid out as Mitsuba's matpreview scene: a floor and an object, meshes of one file."""
    return f"""<?xml version="1.0"?>
<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="4, -4, 3" target="0, 0, 0.5" up="0, 0, 1"/></transform>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <bsdf type="diffuse" id="floor"><rgb name="reflectance" value="0.4"/></bsdf>
    <bsdf type="plastic" id="paint"><rgb name="diffuse_reflectance" value="0.9, 0.3, 0.4"/></bsdf>
    <shape type="serialized" id="shape-plane">
        <string name="filename" value="{file}"/>
        <integer name="shape_index" value="0"/>
        <transform name="to_world"><scale value="3"/><rotate z="1" angle="30"/></transform>
        <ref id="floor"/>
    </shape>
    <shape type="serialized" id="shape-object">
        <string name="filename" value="{file}"/>
        <integer name="shape_index" value="{interior_index}"/>
        <boolean name="face_normals" value="true"/>
        <transform name="to_world"><translate z="0.01"/></transform>
        <ref id="paint"/>{extra}
    </shape>
</scene>
"""


def test_a_matpreview_like_scene_opens_with_its_meshes(tmp_path):
    write_serialized(tmp_path / "preview.serialized", [SQUARE, TETRA])
    (tmp_path / "scene.xml").write_text(matpreview_xml())
    warnings: list[str] = []
    scene = load_mitsuba_scene(tmp_path / "scene.xml", warn=warnings.append)
    assert warnings == []
    plane, thing = scene.nodes
    assert plane.shape == MeshFile(file="preview.serialized", smooth=True, shape_index=0)
    assert thing.shape == MeshFile(file="preview.serialized", smooth=False, shape_index=1)  # face_normals
    flat = scene.flatten()
    assert flat.triangle_count == 2 + 4
    floor = flat.triangles[flat.prim_node[:flat.triangle_count] == 0].reshape(-1, 3)
    turn = np.radians(30)
    corner = 3 * np.array([np.cos(turn) - np.sin(turn), np.sin(turn) + np.cos(turn), 0])  # (1, 1, 0) placed
    assert np.isclose(np.linalg.norm(floor - corner, axis=1).min(), 0, atol=1e-5)
    assert np.allclose(flat.triangle_normals[:2], [0, 0, 1])
    tetra = flat.triangles[2:].reshape(-1, 3)
    assert np.isclose(tetra[:, 2].min(), 0.01) and np.isclose(tetra[:, 2].max(), 1.01)
    assert np.allclose(flat.triangle_uvs[0], [[0, 0], [1, 0], [1, 1]])  # the file's (0,1),(1,1),(1,0) with v up


def test_shape_index_out_of_the_file_names_the_node_and_the_count(tmp_path):
    write_serialized(tmp_path / "preview.serialized", [SQUARE, TETRA])
    (tmp_path / "scene.xml").write_text(matpreview_xml(interior_index=5))
    scene = load_mitsuba_scene(tmp_path / "scene.xml")
    with pytest.raises(SceneError, match=r"node 'shape-object': .*preview\.serialized: shape_index 5 is out of "
                                         r"range: the file holds 2 meshes \(0 to 1\)"):
        scene.flatten()
    (tmp_path / "scene.xml").write_text(matpreview_xml(interior_index=-1))
    with pytest.raises(SceneError, match=r'line 17: <shape type="serialized" id="shape-object">: shape_index must be'):
        load_mitsuba_scene(tmp_path / "scene.xml")
    (tmp_path / "scene.xml").write_text(matpreview_xml(file="gone.serialized"))
    with pytest.raises(SceneError, match=r"mesh file not found: .*gone\.serialized"):
        load_mitsuba_scene(tmp_path / "scene.xml")


def test_the_native_format_keeps_which_mesh_of_the_file(tmp_path):
    write_serialized(tmp_path / "preview.serialized", [SQUARE, TETRA])
    scene = Scene(nodes=[Node("thing", shape=MeshFile("preview.serialized", smooth=False, shape_index=1))],
                  source_path=tmp_path / "scene.json")
    save_scene(scene, tmp_path / "scene.json")
    shape = json.loads((tmp_path / "scene.json").read_text())["nodes"][0]["shape"]
    assert shape == {"type": "mesh", "file": "preview.serialized", "smooth": False, "shape_index": 1}
    again = load_scene(tmp_path / "scene.json")
    assert again.nodes[0].shape == scene.nodes[0].shape and again.flatten().triangle_count == 4


@pytest.mark.gl
def test_a_matpreview_like_scene_renders_headless(renderer, tmp_path, capsys):
    from lenslab.cli import main
    from lenslab.render.film import read_image

    write_serialized(tmp_path / "preview.serialized", [SQUARE, TETRA])
    (tmp_path / "scene.xml").write_text(matpreview_xml())
    status = main([str(tmp_path / "scene.xml"), "--headless", "-o", str(tmp_path / "out.exr"), "--spp", "4"])
    assert status == 0, capsys.readouterr().err
    pixels, _ = read_image(tmp_path / "out.exr")
    assert pixels.shape == (16, 24, 3) and np.isfinite(pixels).all()
    assert pixels[-1].mean() < 0.9 * pixels[0].mean()  # the floor, below the white sky, is darker than it


# ---------------------------------------------------------------------------------------------------------
# Damaged files: one MeshLoadError naming the file, never another exception, never a huge allocation
# ---------------------------------------------------------------------------------------------------------
def test_each_kind_of_damage_is_one_line(tmp_path, monkeypatch):
    good = mesh_stream(**TETRA)

    def refused(data: bytes, pattern: str, index: int = 0) -> None:
        path = tmp_path / "bad.serialized"
        path.write_bytes(data)
        with pytest.raises(MeshLoadError, match=pattern) as caught:
            read_serialized(path, index)
        assert str(caught.value).startswith(str(path)) and "\n" not in str(caught.value)

    refused(b"ply\nformat ascii 1.0\n", r"not a Mitsuba \.serialized mesh \(it starts with 0x6c70, not 0x041c\)")
    refused(b"\x1c\x04", "no Mitsuba .serialized header: the file ends after 2 bytes")
    refused(struct.pack("<HH", 0x041C, 5) + good[4:], "format version 5 .* not readable yet: LensLab reads versions 3 and 4")
    refused(struct.pack("<HH", 0x041C, 9) + good[4:], "format version 9: LensLab, like Mitsuba 3, reads versions 3 and 4")
    refused(good[:40], r"mesh 0 is (cut short \(in its \w+|damaged)")
    refused(good[:4] + bytes(len(good) - 4), r"mesh 0 is damaged \(Error -3")
    refused(good + struct.pack("<QI", 0, 1), r"shape_index 1 is out of range: the file holds 1 mesh$", index=1)
    refused(good + struct.pack("<QQI", 0, 999, 2), r"table of meshes is damaged \(mesh 1 at byte 999", index=1)
    refused(good + struct.pack("<QQI", 0, 0, 2**31), r"table of meshes is damaged \(it claims 2,147,483,648 meshes", index=1)
    refused(good + good.replace(b"\x04\x00", b"\x03\x00", 1) + struct.pack("<QQI", 0, len(good), 2),
            r"mesh 1 \(at byte \d+\): format version 3", index=1)
    stored = bytearray(mesh_stream(**TETRA, level=0))  # deflate's stored blocks: bytes as they are
    stored[40] ^= 0x10  # a position's byte: inflates without complaint, only the stream's checksum tells
    refused(bytes(stored), r"mesh 0 is damaged \(Error -3 .*incorrect data check\)")
    unterminated = struct.pack("<HH", 0x041C, 4) + zlib.compress(struct.pack("<I", 0x1000) + b"n" * 70_000)
    refused(unterminated, r"its name runs past 65,536 bytes")
    # Counts that no file could back: refused before a byte of the arrays is inflated.
    claims = struct.pack("<HH", 0x041C, 3) + zlib.compress(struct.pack("<IQQ", 0x1000, 2**32 + 1, 1))
    refused(claims, r"4,294,967,297 vertices, more than its 32-bit indices can name")
    monkeypatch.setattr(mitsuba_serialized, "available_memory_bytes", lambda: 10 * 2**20)
    bomb = struct.pack("<HH", 0x041C, 3) + zlib.compress(struct.pack("<IQQ", 0x1000, 10**6, 10**6) + bytes(10**7))
    refused(bomb, r"1,000,000 vertices and 1,000,000 triangles need .* MiB to read, more than the 10.0 MiB available")


def test_truncated_and_flipped_files_never_raise_anything_else(tmp_path):
    """Every truncation of a two-mesh file, and a few hundred byte flips: a mesh or a MeshLoadError."""
    rng = random.Random(11)
    data = write_serialized(tmp_path / "m.serialized", [SQUARE, TETRA]).read_bytes()
    cases = [data[:n] for n in range(len(data))]
    for _ in range(300):
        flipped = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            flipped[rng.randrange(len(flipped))] ^= 1 << rng.randrange(8)
        cases.append(bytes(flipped))
    path = tmp_path / "broken.serialized"
    for case in cases:
        path.write_bytes(case)
        for index in (0, 1):
            try:
                mesh = read_serialized(path, index)
            except MeshLoadError as exc:
                assert str(exc).startswith(str(path)) and "\n" not in str(exc)
            else:
                assert mesh.vertices.shape[1] == 3 and mesh.faces.shape[1] == 3


def test_a_stream_that_ends_before_its_counts_is_cut_short_not_an_endless_loop(tmp_path, monkeypatch):
    """A mesh whose zlib stream is whole but holds less than its counts, followed by the next mesh: zlib keeps the
    bytes after the stream's end in ``unconsumed_tail`` for ever, and the reader once asked for them again without
    end. Every call to inflate must take input or give output: counted here, bounded by the file's size."""
    body = struct.pack("<I", 0x1000) + b"mesh\0" + struct.pack("<QQ", 4, 4) + np.zeros(12, "<f4").tobytes()
    short = struct.pack("<HH", 0x041C, 4) + zlib.compress(body[:40])  # the stream ends in the positions
    path = tmp_path / "early.serialized"
    path.write_bytes(short + mesh_stream(**SQUARE) + struct.pack("<QQI", 0, len(short), 2))
    calls = []
    real = zlib.decompressobj

    class Counted:
        def __init__(self):
            self._inner = real()

        def decompress(self, data, limit=0):
            calls.append(len(data))
            assert len(calls) <= path.stat().st_size, "inflation that takes no input and gives no output"
            return self._inner.decompress(data, limit)

        def __getattr__(self, name):
            return getattr(self._inner, name)

    monkeypatch.setattr(mitsuba_serialized.zlib, "decompressobj", Counted)
    with pytest.raises(MeshLoadError, match=r"early\.serialized: mesh 0 is cut short \(in its positions\)"):
        read_serialized(path, 0)
    assert read_serialized(path, 1).faces.shape == (2, 3)  # the mesh after it reads as written


def test_every_early_end_of_either_mesh_s_stream_is_one_line(tmp_path):
    """A stream ended early at every byte of the body, in a file of two meshes: a MeshLoadError naming the file."""
    body = (struct.pack("<I", 0x1000) + b"mesh\0" + struct.pack("<QQ", 4, 4) + np.zeros(12, "<f4").tobytes()
            + np.asarray(TETRA["faces"], "<u4").tobytes())
    path = tmp_path / "early.serialized"
    for cut in range(len(body)):
        first = struct.pack("<HH", 0x041C, 4) + zlib.compress(body[:cut])
        path.write_bytes(first + mesh_stream(**SQUARE) + struct.pack("<QQI", 0, len(first), 2))
        with pytest.raises(MeshLoadError) as caught:
            read_serialized(path, 0)
        assert str(caught.value).startswith(f"{path}: ") and "\n" not in str(caught.value)


def test_a_named_pipe_is_refused_not_waited_on(tmp_path):
    from tests.malformed_inputs import fifo_read_as_empty

    with fifo_read_as_empty(tmp_path / "pipe.serialized") as pipe, \
            pytest.raises(MeshLoadError, match=r"pipe\.serialized: cannot read mesh \(a named pipe \(FIFO\), not a "
                                               r"regular file\)"):
        read_serialized(pipe)
