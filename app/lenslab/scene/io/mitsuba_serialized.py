"""Mitsuba's ``.serialized`` meshes: indexed triangle meshes, each a zlib stream, several to a file.

The format as Mitsuba 0.4 to 3.9.1 write and read it (``src/shapes/serialized.cpp``), little endian:

* a header, outside the compression: ``uint16`` 0x041C, ``uint16`` version (3 or 4);
* then a zlib stream holding: ``uint32`` flags (0x1 normals, 0x2 texture coordinates, 0x8 vertex colours,
  0x2000 double precision), the shape's name as a null-terminated string (version 4 only), ``uint64``
  vertex count V and triangle count F, the arrays of V positions (3 floats each), normals (3), texture
  coordinates (2) and colours (3) that the flags announce, in float32 or float64, and F triangles of three
  ``uint32`` vertex indices.

A file holding several meshes concatenates them (each with its own header) and ends with a table of where
each starts: ``uint64`` offsets (``uint32`` in version 3), then the ``uint32`` count. ``shape_index`` 0 reads
from the file's start, as Mitsuba does, so a one-mesh file needs no table.

Like Mitsuba 3.9.1, LensLab ignores vertex colours and the 0x10 "face normals" flag (only the scene's
``face_normals`` asks for flat shading), and a mesh without normals gets smooth ones computed from its faces.
Texture coordinates come back in LensLab's convention, v up the image as in OBJ: Mitsuba's v runs down it
(``src/textures/bitmap.cpp`` reads row v * height from the top; its OBJ reader flips OBJ's v to match), so v
becomes 1 - v.
Version 5 (the packed encoding of Mitsuba's development branch after 3.9.1) is refused with a line saying so.

Only the mesh asked for is read: the file is opened, its table looked up and that mesh's stream inflated, so
a file of hundreds of meshes (as exporters write a whole scene) costs each shape its own bytes only.

A damaged file is one :class:`MeshLoadError` naming it: a header that is not Mitsuba's, a table pointing
outside the file, a stream cut short or corrupt (zlib's checksum is read too). The counts are checked against
the memory available before the arrays are inflated, and inflation never runs past what the counts announce,
so a file of a few kilobytes that claims billions of triangles is refused rather than read.
"""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path
from typing import BinaryIO

import numpy as np

from lenslab.image_files import open_file
from lenslab.limits import available_memory_bytes, format_bytes
from lenslab.scene.io.meshes import MeshLoadError
from lenslab.scene.shapes import TriangleMesh

MAGIC = 0x041C
VERSIONS = (3, 4)
HAS_NORMALS, HAS_TEXCOORDS, HAS_COLORS, DOUBLE_PRECISION = 0x0001, 0x0002, 0x0008, 0x2000
#: Longer than any shape name an exporter writes; a name without its terminating zero ends here.
MAX_NAME_BYTES = 65_536
_CHUNK = 1 << 16  # compressed bytes fed to zlib at a time


def read_serialized(path: Path | str, shape_index: int = 0) -> TriangleMesh:
    """Mesh ``shape_index`` of the ``.serialized`` file at ``path``, in its own (object) space.

    Normals and texture coordinates are the file's, None where it has none."""
    path = Path(path)
    if shape_index < 0:
        raise MeshLoadError(f"{path}: shape_index {shape_index} is negative")
    try:
        with open_file(path) as file:  # a named pipe or a device is refused, not waited on
            size = os.fstat(file.fileno()).st_size
            version = _header(file, 0, size, path)
            start = 0 if shape_index == 0 else _offset(file, size, version, shape_index, path)
            if start:
                _header(file, start, size, path, shape_index, version)
            return _mesh(_Inflated(file, start + 4, path, shape_index), version, path, shape_index)
    except OSError as exc:
        raise MeshLoadError(f"{path}: cannot read mesh ({exc.strerror or exc})") from None


def _read_at(file: BinaryIO, at: int, count: int) -> bytes:
    file.seek(at)
    return file.read(count)


def _header(file: BinaryIO, at: int, size: int, path: Path, index: int = 0, version: int | None = None) -> int:
    """The format version in the header at byte ``at``; a MeshLoadError where it is not Mitsuba's."""
    where = "" if index == 0 else f"mesh {index} (at byte {at}): "
    if size < at + 4:
        raise MeshLoadError(f"{path}: {where}no Mitsuba .serialized header: the file ends after {size} bytes")
    magic, found = struct.unpack("<HH", _read_at(file, at, 4))
    if magic != MAGIC:
        raise MeshLoadError(f"{path}: {where}not a Mitsuba .serialized mesh (it starts with {magic:#06x}, not "
                            f"{MAGIC:#06x})")
    if found == 5:
        raise MeshLoadError(f"{path}: format version 5 (the packed encoding of Mitsuba's development branch, "
                            "after 3.9.1) is not readable yet: LensLab reads versions 3 and 4")
    if found not in VERSIONS or (version is not None and found != version):
        raise MeshLoadError(f"{path}: {where}format version {found}: LensLab, like Mitsuba 3, reads versions 3 and 4")
    return found


def _offset(file: BinaryIO, size: int, version: int, index: int, path: Path) -> int:
    """Where mesh ``index`` starts, from the table at the end of the file."""
    width = 8 if version == 4 else 4
    if size < 8:
        raise MeshLoadError(f"{path}: shape_index {index}: the file is too short to hold a table of meshes")
    (count,) = struct.unpack("<I", _read_at(file, size - 4, 4))
    if index >= count:
        raise MeshLoadError(f"{path}: shape_index {index} is out of range: the file holds {count} "
                            f"mesh{'es' if count != 1 else ''}" + (f" (0 to {count - 1})" if count > 1 else ""))
    table = size - 4 - width * count
    if table < 0:
        raise MeshLoadError(f"{path}: its table of meshes is damaged (it claims {count:,} meshes, more than the "
                            f"file's {size:,} bytes can index)")
    (offset,) = struct.unpack("<Q" if width == 8 else "<I", _read_at(file, table + width * index, width))
    if offset + 4 > table:
        raise MeshLoadError(f"{path}: its table of meshes is damaged (mesh {index} at byte {offset}, past the "
                            f"meshes' {table} bytes)")
    return offset


def _mesh(stream: "_Inflated", version: int, path: Path, index: int) -> TriangleMesh:
    (flags,) = struct.unpack("<I", stream.take(4, "flags"))
    if version == 4:
        stream.skip_name()
    vertex_count, face_count = struct.unpack("<QQ", stream.take(16, "counts"))
    real = np.dtype("<f8" if flags & DOUBLE_PRECISION else "<f4")
    layout = [("positions", 3), ("normals", 3 if flags & HAS_NORMALS else 0),
              ("texture coordinates", 2 if flags & HAS_TEXCOORDS else 0), ("colours", 3 if flags & HAS_COLORS else 0)]
    _check_size(vertex_count, face_count, sum(width for _, width in layout) * real.itemsize, path, index)
    arrays = {}
    for what, width in layout:
        if width:  # colours too are read, to reach the triangles after them
            raw = stream.take(vertex_count * width * real.itemsize, what)
            arrays[what] = np.frombuffer(raw, real).reshape(-1, width).astype(np.float64)
    faces = np.frombuffer(stream.take(face_count * 12, "triangles"), "<u4").reshape(-1, 3)
    stream.check_end()
    uvs = arrays.get("texture coordinates")
    if uvs is not None:  # Mitsuba's v runs down the image (bitmap.cpp; its OBJ reader flips OBJ's v), ours up
        uvs[:, 1] = 1.0 - uvs[:, 1]
    return TriangleMesh(vertices=arrays["positions"], faces=faces.astype(np.int64), normals=arrays.get("normals"),
                        uvs=uvs)


def _check_size(vertex_count: int, face_count: int, vertex_bytes: int, path: Path, index: int) -> None:
    """Refuse, from the counts alone, a mesh that cannot be read here: more vertices than its ``uint32``
    indices can name, or more memory than is available (the file's arrays, then LensLab's float64 copies)."""
    if vertex_count > 2**32:
        raise MeshLoadError(f"{path}: mesh {index}: {vertex_count:,} vertices, more than its 32-bit indices can name")
    needed = vertex_count * (vertex_bytes + 8 * 8) + face_count * (12 + 24)  # file's arrays, ours (+ normals, uvs)
    memory = available_memory_bytes()
    if memory is not None and needed > memory:
        raise MeshLoadError(f"{path}: mesh {index}: {vertex_count:,} vertices and {face_count:,} triangles need "
                            f"{format_bytes(needed)} to read, more than the {format_bytes(memory)} available")


class _Inflated:
    """The decompressed bytes of one mesh's zlib stream, taken in order. zlib is fed a chunk of the file at a
    time and never asked for more output than is taken, so a stream that inflates to far more than its counts
    announce (a decompression bomb) costs no more than what is read."""

    def __init__(self, file: BinaryIO, start: int, path: Path, index: int):
        self._file = file
        file.seek(start)
        self._zlib = zlib.decompressobj()
        self._tail = b""  # compressed bytes read from the file and not yet inflated
        self._file_ended = False
        self._ready = bytearray()  # inflated and not yet taken
        self._where = f"{path}: mesh {index}"

    def take(self, count: int, what: str) -> bytes | bytearray:
        """The next ``count`` bytes; a MeshLoadError naming ``what`` where the stream ends or is corrupt first."""
        self._fill(count, what)
        if len(self._ready) == count:  # an array, inflated just for this: handed over without a copy
            taken, self._ready = self._ready, bytearray()
            return taken
        taken = bytes(self._ready[:count])
        del self._ready[:count]
        return taken

    def skip_name(self) -> None:
        """Version 4's shape name, null-terminated (LensLab names nodes after the scene's ids instead). Read
        16 bytes at a time: at least the 16 of the counts follow it."""
        while (end := self._ready.find(0)) < 0:
            if len(self._ready) >= MAX_NAME_BYTES:
                raise MeshLoadError(f"{self._where} is damaged (its name runs past {MAX_NAME_BYTES:,} bytes)")
            self._fill(len(self._ready) + 16, "name")
        del self._ready[:end + 1]

    def check_end(self) -> None:
        """Read on to the stream's end, where zlib checks its Adler-32 sum over the mesh: a damaged byte that
        inflated without complaint is found here. A file that ends before the sum is taken as it is (Mitsuba
        reads no further than the triangles either)."""
        for _ in range(64):  # Mitsuba's streams end with the triangles: anything after them is skipped, briefly
            if self._zlib.eof or self._step(_CHUNK) is None:
                return

    def _fill(self, count: int, what: str) -> None:
        while len(self._ready) < count:
            out = self._step(count - len(self._ready))
            if out is None:
                raise MeshLoadError(f"{self._where} is cut short (in its {what})")
            self._ready += out

    def _step(self, limit: int) -> bytes | None:
        """At most ``limit`` more bytes (perhaps none yet); None where the stream or the file has ended.

        Every call that returns bytes has inflated some or taken compressed bytes from the file, so the loops
        above end within the file's size: a call that would do neither (a stream that ends before its counts
        are met, with bytes after it, which zlib leaves in ``unconsumed_tail`` for ever) is the end."""
        if self._zlib.eof:  # bytes after the stream's end belong to the next mesh or the table, not to this one
            self._tail = b""
            return None
        read = False
        if not self._tail and not self._file_ended:
            self._tail = self._file.read(_CHUNK)
            self._file_ended = len(self._tail) < _CHUNK
            read = bool(self._tail)
        before = len(self._tail)
        try:
            out = self._zlib.decompress(self._tail, limit)
        except zlib.error as exc:
            raise MeshLoadError(f"{self._where} is damaged ({exc})") from None
        self._tail = b"" if self._zlib.eof else self._zlib.unconsumed_tail
        if not out and not read and len(self._tail) >= before:  # no progress: nothing more will come
            return None
        return out
