"""OBJ and ASCII PLY read in compiled code, twenty to forty times faster than trimesh's parsers (which split the
text line by line in Python): a scanned product of a million triangles saved as text opens in a fraction of a
second instead of five (benchmarks/mesh_open.py).

The compiled reader (text_compiled.py) takes the subset of each format that exporters write:

- OBJ: ``v`` (three numbers), ``vt`` (two or three), ``vn``, ``f`` with corners ``p``, ``p/t``, ``p//n`` or
  ``p/t/n`` (1-based or negative, counted back from the last element so far, as the format says), polygons fanned
  around their first corner, ``usemtl``; ``o``, ``g``, ``s`` and ``mtllib`` carry nothing the geometry needs
  (mesh_materials.py reads the libraries). Faces are grouped by material, one piece each, as trimesh groups them.
  A vertex is one (position, texture coordinate, normal) triple, so that a seam in the UVs or the normals stays
  a seam.
- ASCII PLY: a ``vertex`` element of ``x y z`` and optionally ``nx ny nz``, then a ``face`` element of one list
  of corners.

A file outside the subset (vertex colours, a ``w``, a line continued with a backslash, a forward reference, PLY
texture coordinates or extra elements, numba missing) comes back as None and is read by trimesh, as before.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lenslab.image_files import read_file_bytes


@dataclass(frozen=True)
class TextMeshPiece:
    """The faces of one material (an OBJ's ``usemtl`` name; None before any), with their own vertices."""

    material: str | None
    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int64
    normals: np.ndarray | None  # (V, 3), the file's
    uvs: np.ndarray | None  # (V, 2)


def _compiled():
    try:
        from lenslab.scene.io import text_compiled
    except ImportError:  # numba missing (a device machine sent the project without it): trimesh reads the file
        return None
    return text_compiled


# ---------------------------------------------------------------------------------------------------------
# OBJ
# ---------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TextObj:
    pieces: list[TextMeshPiece]  # one per material, in the order they are first used
    libraries: list[str]  # the values of the mtllib statements


def read_obj(text: bytes) -> TextObj | None:
    """An OBJ file's faces as pieces, one per material, and its material libraries; None where the file is outside
    the subset read here."""
    compiled = _compiled()
    if compiled is None:
        return None
    data = np.frombuffer(text, np.uint8)
    status, _offset, nv, nvt, nvn, ntri, nmtl = compiled.obj_counts(data)
    if status != compiled.READ:
        return None
    status, _offset, positions, uvs, normals, corners, materials, spans = compiled.obj_parse(
        data, nv, nvt, nvn, ntri, nmtl, compiled.POWERS_OF_TEN)
    if status != compiled.READ:
        return None
    values = [text[start:end].decode("utf-8", "replace") for start, end, _kind in spans]
    libraries = [value for value, (_s, _e, kind) in zip(values, spans) if kind == compiled.MTLLIB]
    # One piece per material name (a name used in several usemtl statements is one material).
    unique = list(dict.fromkeys(value for value, (_s, _e, kind) in zip(values, spans) if kind == compiled.USEMTL))
    statement_piece = np.array([unique.index(value) if kind == compiled.USEMTL else -1
                                for value, (_s, _e, kind) in zip(values, spans)] + [-1], np.int64)
    piece_of_triangle = statement_piece[materials]  # -1 (no usemtl yet) indexes the appended -1
    pieces = []
    for piece in [-1] + list(range(len(unique))):
        one_piece = len(piece_of_triangle) and piece_of_triangle[0] == piece == piece_of_triangle[-1] and \
            (piece_of_triangle == piece).all()
        chosen = corners if one_piece else corners[piece_of_triangle == piece]
        if len(chosen) == 0:
            continue
        mesh = _indexed(chosen, positions, uvs, normals)
        if mesh is None:
            return None
        vertices, faces, piece_normals, piece_uvs = mesh
        pieces.append(TextMeshPiece(None if piece < 0 else unique[piece], vertices, faces, piece_normals,
                                    piece_uvs))
    return TextObj(pieces, libraries)


def _indexed(corners: np.ndarray, positions: np.ndarray, uvs: np.ndarray, normals: np.ndarray):
    """Vertices and faces from triangles' corners (T, 3, [position, uv, normal] index, -1 for none): one vertex
    per distinct triple, in order of position. None where some corners have a uv or normal and others not."""
    p, t, n = corners[..., 0], corners[..., 1], corners[..., 2]
    has_uv, has_normal = bool((t >= 0).any()), bool((n >= 0).any())
    if (has_uv and (t < 0).any()) or (has_normal and (n < 0).any()):
        return None  # mixed corners: trimesh's rules decide
    if (not has_uv or np.array_equal(t, p)) and (not has_normal or np.array_equal(n, p)):
        # Each position has one uv and one normal of the same index (what most exporters write): the positions
        # the faces use, in the file's order.
        used = np.zeros(len(positions), bool)
        used[p] = True
        new_index = np.cumsum(used) - 1
        kept = np.flatnonzero(used)  # also the uv and normal indices (there may be fewer of those than positions)
        return (positions[kept], new_index[p].astype(np.int64), normals[kept] if has_normal else None,
                uvs[kept] if has_uv else None)
    uv_count, normal_count = len(uvs) + 1, len(normals) + 1
    if len(positions) * uv_count * normal_count < 2 ** 62:
        keys = (p.astype(np.int64) * uv_count + (t + 1)) * normal_count + (n + 1)
        _keys, first, faces = np.unique(keys.ravel(), return_index=True, return_inverse=True)
    else:
        _rows, first, faces = np.unique(corners.reshape(-1, 3), axis=0, return_index=True, return_inverse=True)
    triples = corners.reshape(-1, 3)[first]
    return (positions[triples[:, 0]], faces.reshape(-1, 3).astype(np.int64),
            normals[triples[:, 2]] if has_normal else None, uvs[triples[:, 1]] if has_uv else None)


# ---------------------------------------------------------------------------------------------------------
# ASCII PLY
# ---------------------------------------------------------------------------------------------------------
_PLY_NUMBER_TYPES = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8",
                     "int16", "uint16", "int32", "uint32", "float32", "float64"}


def read_ascii_ply(path: Path) -> TextMeshPiece | None:
    """The ASCII PLY file's triangles; None where it is binary or outside the subset read here."""
    compiled = _compiled()
    if compiled is None:
        return None
    raw = read_file_bytes(path)
    header_end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or header_end < 0:
        return None
    body_start = raw.find(b"\n", header_end)
    body_start = len(raw) if body_start < 0 else body_start + 1
    layout = _ply_layout(raw[:header_end].decode("ascii", "replace"))
    if layout is None:
        return None
    vertex_count, columns, face_count = layout
    status, numbers = compiled.read_numbers(np.frombuffer(raw, np.uint8), body_start, compiled.POWERS_OF_TEN)
    if status == compiled.LONG_NUMBERS:  # numbers of 16 digits or more: numpy's strtod rounds them exactly
        numbers = np.fromstring(raw[body_start:], dtype=np.float64, sep=" ")
        status = compiled.READ
    vertex_numbers = vertex_count * len(columns)
    if status != compiled.READ or len(numbers) < vertex_numbers:
        return None
    rows = numbers[:vertex_numbers].reshape(vertex_count, len(columns))
    status, faces, end = compiled.fan_polygons(numbers, vertex_numbers, face_count)
    if status != compiled.READ or end != len(numbers):
        return None
    if len(faces) and ((faces < 0).any() or (faces >= vertex_count).any()):
        return None  # trimesh, then meshes.check_geometry, say what is wrong
    column = {name: k for k, name in enumerate(columns)}

    def values(names: str) -> np.ndarray:
        picked = np.ascontiguousarray(rows[:, [column[name] for name in names.split()]])
        for k, name in enumerate(names.split()):
            if columns[name] in _PLY_SINGLE:  # a float property holds what a float32 holds, as in a binary file
                picked[:, k] = picked[:, k].astype(np.float32)
        return picked

    vertices = values("x y z")
    normals = values("nx ny nz") if {"nx", "ny", "nz"} <= column.keys() else None
    return TextMeshPiece(None, vertices, faces, normals, None)


_PLY_SINGLE = ("float", "float32")


def _ply_layout(header: str) -> tuple[int, dict[str, str], int] | None:
    """(vertex count, the vertex element's property names, face count) of an ASCII PLY header whose elements are
    exactly ``vertex`` (scalar x y z, optionally nx ny nz) and then ``face`` (one list property of corners)."""
    lines = [line.split() for line in header.splitlines()[1:]]
    lines = [words for words in lines if words and words[0] not in ("comment", "obj_info")]
    if not lines or lines[0] != ["format", "ascii", "1.0"]:
        return None
    elements: list[tuple[str, int, list[list[str]]]] = []
    for words in lines[1:]:
        if words[0] == "element" and len(words) == 3 and words[2].isdigit():
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and elements:
            elements[-1][2].append(words[1:])
        else:
            return None
    if [name for name, _count, _props in elements] != ["vertex", "face"]:
        return None
    (_v, vertex_count, vertex_props), (_f, face_count, face_props) = elements
    if any(len(prop) != 2 or prop[0] not in _PLY_NUMBER_TYPES for prop in vertex_props):
        return None
    names = [prop[1] for prop in vertex_props]
    columns = {prop[1]: prop[0] for prop in vertex_props}  # name -> type, in the file's order
    if len(set(names)) != len(names) or not set(columns) <= {"x", "y", "z", "nx", "ny", "nz"} or \
            not {"x", "y", "z"} <= set(columns) or len({"nx", "ny", "nz"} & set(columns)) not in (0, 3):
        return None
    if len(face_props) != 1 or face_props[0][0] != "list" or face_props[0][-1] not in ("vertex_indices",
                                                                                       "vertex_index"):
        return None
    return vertex_count, columns, face_count
