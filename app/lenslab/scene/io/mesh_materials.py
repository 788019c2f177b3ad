"""Materials from mesh files: an OBJ's MTL and a glTF's PBR materials, mapped onto LensLab's materials.

A mesh file comes back as parts, one per material it uses (geometry without a material: one part per piece,
material None, so the node's own material or the default grey applies). Each piece is put where the file's
scene graph puts it (the graph's world transform is baked into the vertices).

What cannot be mapped is never dropped silently: it is said in ``LoadedMesh.warnings``, at most one line per
material, by name ("mesh.glb: material 'Paint': normal map ignored; metallic 0.30 rendered as plastic"),
plus one line per file for what belongs to no material (vertex colours of a PLY, a missing MTL file).

OBJ + MTL. The MTL is parsed here, not taken from trimesh, which keeps neither the path of a texture it
could not open nor the texture options. Ka (ambient), illum and map_Ka have no meaning to a path tracer and
are not reported.

- Ke > 0            -> Emissive(radiance=Ke), front face only, whose surface is what the rest of the
                       statements make of it (below) when they state a reflection (Kd, Ks, map_Kd); else black.
- d < 1 (or Tr > 0) -> Dielectric(ior=Ni, else 1.5; tint=Tf; smooth unless Pr says otherwise).
- Pm >= 0.5, or a black Kd with a noticeable Ks (the classic MTL metal)
                    -> Conductor with F0 = Kd (Pm) or Ks, as complex IOR eta = 1, k = 2 sqrt(F0 / (1 - F0)).
- Ks noticeable (max > 0.01), or Pr given
                    -> Plastic(albedo=Kd, ior=Ni if > 1 else 1.5, roughness from Pr or Ns).
- otherwise         -> Diffuse(albedo=Kd).
Ns (the Blinn-Phong exponent) becomes roughness through Walter et al. 2007's Beckmann equivalence
alpha = sqrt(2 / (Ns + 2)) and our perceptual roughness r = sqrt(alpha): Ns 1000 -> 0.21, 100 -> 0.38,
10 -> 0.64, 0 -> 1. Ks says only whether there is a coating; its strength is the coating's Fresnel term.
map_Kd is an ImageTexture on the file on disk, relative to the MTL (``-s`` becomes tiles); as with Blender,
the map replaces Kd rather than multiplying it (colour space auto: an 8-bit file sRGB, a float one linear).
map_Pr is a roughness texture, data, read as stored (raw). A bump or normal map (bump, map_Bump, norm) is ignored,
with a note; were it read, it would be data too.

glTF 2.0 / GLB. Scalars and extensions are read from the file's own JSON (trimesh drops the KHR extensions);
trimesh reads the geometry. Images are read through OpenImageIO.

- emissiveFactor * KHR_materials_emissive_strength > 0 -> Emissive (two-sided when doubleSided), whose surface is
  the material the rest of it makes (glTF's emission adds to its reflection).
- metallic >= 0.5 -> Conductor: baseColor is F0 at normal incidence, as the complex IOR eta = 1,
  k = 2 sqrt(F0 / (1 - F0)), whose Fresnel curve rises to white at grazing angles as glTF's Schlick term does.
- KHR_materials_transmission > 0 -> Dielectric(ior=KHR_materials_ior or 1.5, roughness, tint=baseColor,
  absorption = KHR_materials_volume attenuationColor at attenuationDistance). It is a solid: the traced
  geometry gives the thickness, so thicknessFactor/Texture are not needed.
- otherwise -> Plastic(albedo=baseColor and its texture, ior=KHR_materials_ior or 1.5, roughness).
metallic and roughness come from the factors times the metallicRoughness texture's B and G channels; the
G channel (times roughnessFactor) becomes a roughness texture of its own, B decides the material (its mean
when it varies, with a warning). A base colour factor other than white is baked into the texture's pixels.
Colour spaces as glTF 2.0 says: baseColorTexture and emissiveTexture are sRGB (decoded, then linear Rec.709, as the
factors are); metallicRoughnessTexture is data, read as stored (raw); normalTexture and occlusionTexture, data too,
are ignored with a note.
"""

from __future__ import annotations

import base64
import copy
import io
import json
import math
import os
import re
import struct
import tempfile
import urllib.parse
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np

from lenslab.color import srgb_to_linear
from lenslab.image_files import check_regular_file, not_a_file, read_file_bytes, read_pixels
from lenslab.limits import number_problem
from lenslab.scene.io.meshes import LoadedMesh, MeshLoadError, MeshPart, check_geometry, smooth_normals
from lenslab.scene.io.mitsuba_serialized import read_serialized
from lenslab.scene.io.text_meshes import TextMeshPiece, read_ascii_ply, read_obj
from lenslab.scene.materials import Conductor, Dielectric, Diffuse, Emissive, Material, Plastic
from lenslab.scene.shapes import TriangleMesh
from lenslab.scene.textures import Checkerboard, ImageTexture, InlineImageTexture, Texture
from lenslab.scene.transform import transform_normals, transform_points

# Text mesh files (OBJ, ASCII PLY) smaller than this are parsed by trimesh: loading the compiled reader's machine code
# takes about half a second in each process (and numba some ten seconds to make it, once a machine), more than
# trimesh spends on a file this small (0.2 s).
TEXT_COMPILED_MIN_BYTES = 4 * 2 ** 20

# What an unreadable embedded image becomes: the renderer's own placeholder for a missing texture file.
PLACEHOLDER = Checkerboard(color_a=(1.0, 0.0, 1.0), color_b=(0.0, 0.0, 0.0), tiles=(16.0, 16.0))


def load_parts(path: Path, smooth: bool = True, shape_index: int = 0) -> LoadedMesh:
    """The mesh file as parts, one per material it uses; cached by path, modification times, ``smooth`` and
    ``shape_index`` (which mesh of a Mitsuba .serialized file; other files hold one, and take only 0)."""
    path = Path(path)
    if not os.path.isfile(path):  # a named pipe or a device is refused, not waited on
        raise MeshLoadError(f"{path}: {not_a_file(path) or 'mesh file not found'}")
    if shape_index and path.suffix.lower() != ".serialized":
        raise MeshLoadError(f"{path}: shape_index {shape_index}: only a Mitsuba .serialized file holds several "
                            "meshes (this file's is 0)")
    path = path.resolve()
    return _load_cached(str(path), path.stat().st_mtime_ns, _sidecar_stamp(path), smooth, shape_index)


def _sidecar_stamp(path: Path) -> tuple:
    """Modification times of the files beside a mesh that its materials live in (an OBJ's MTL, a glTF's .bin)."""
    pattern = {".obj": "*.mtl", ".gltf": "*.bin"}.get(path.suffix.lower())
    if pattern is None:
        return ()
    return tuple(sorted((p.name, p.stat().st_mtime_ns) for p in path.parent.glob(pattern) if p.is_file()))


@lru_cache(maxsize=32)
def _load_cached(path: str, mtime_ns: int, sidecars: tuple, smooth: bool, shape_index: int) -> LoadedMesh:
    return _load(Path(path), smooth, shape_index)


# ---------------------------------------------------------------------------------------------------------
# Geometry: the scene graph, one part per material
# ---------------------------------------------------------------------------------------------------------
def _load(path: Path, smooth: bool, shape_index: int = 0) -> LoadedMesh:
    import trimesh  # imported here: a scene without mesh files never pays for it

    notes = Notes(path.name)
    suffix = path.suffix.lower()
    try:
        if suffix in (".gltf", ".glb"):
            source = GltfMaterials(path, notes)
        elif suffix == ".obj":
            source = ObjMaterials(path, notes)
        elif suffix == ".serialized":
            source = SerializedMesh(path, notes, shape_index)
        else:
            source = NoMaterials(path, notes)
        scene = source.load_trimesh()
    except MeshLoadError:
        raise
    except Exception as exc:  # trimesh raises many kinds; all mean the same to the user
        raise MeshLoadError(f"{path}: cannot read mesh ({exc})") from exc

    groups: dict[tuple, tuple[Material | None, str, list[TriangleMesh]]] = {}
    vertex_colours = False
    for node_name in scene.graph.nodes_geometry:
        matrix, geometry_name = scene.graph[node_name]
        geometry = scene.geometry[geometry_name]
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue
        mapped = source.material_for(geometry)
        visual = geometry.visual
        has_colours = getattr(visual, "kind", None) in ("vertex", "face") or (
            "color" in (getattr(visual, "vertex_attributes", None) or {}))
        if mapped is None:
            vertex_colours |= has_colours
            key, material, name = (1, 0, str(node_name)), None, str(node_name)
        else:
            key, material, name = (0, mapped.order, ""), mapped.material, mapped.name
            if has_colours:
                notes.add(mapped.key, mapped.name, "vertex colours ignored")
        groups.setdefault(key, (material, name, []))[2].append(_baked(geometry, np.asarray(matrix, float), smooth,
                                                                      path))
    if not groups:
        raise MeshLoadError(f"{path}: no triangles in file")
    if vertex_colours:
        notes.add_file("vertex colours ignored (LensLab takes colour from materials and textures only)")
    # Parts in the file's order of materials, then the pieces without one.
    parts = tuple(MeshPart(_concatenate(meshes), material, name)
                  for _, (material, name, meshes) in sorted(groups.items(), key=lambda item: item[0]))
    return LoadedMesh(parts, notes.warnings())


def _baked(geometry, matrix: np.ndarray, smooth: bool, path: Path) -> TriangleMesh:
    faces = np.asarray(geometry.faces, dtype=np.int64)
    vertices = np.asarray(geometry.vertices, dtype=np.float64)
    check_geometry(vertices, faces, path)
    if not np.array_equal(matrix, np.eye(4)):  # a glTF node's transform (most files have none)
        with np.errstate(over="ignore", invalid="ignore"):  # it could still overflow: checked next
            vertices = transform_points(matrix, vertices)
        check_geometry(vertices, faces, path)
    normals = None
    if smooth:
        normals = _file_normals(geometry)
        normals = smooth_normals(vertices, faces) if normals is None else transform_normals(matrix, normals)
    if np.linalg.det(matrix[:3, :3]) < 0:  # a mirroring transform: keep the front faces in front
        faces = faces[:, ::-1]
    uvs = getattr(geometry.visual, "uv", None)
    uvs = np.asarray(uvs, dtype=np.float64) if uvs is not None and len(uvs) == len(vertices) else None
    return TriangleMesh(vertices, faces, normals, uvs)


def _file_normals(geometry) -> np.ndarray | None:
    """The vertex normals the file gave (a PLY's nx ny nz, an OBJ's vn, a glTF's NORMAL), or None.

    trimesh keeps given normals in its cache under the property's name and makes them on demand otherwise; its
    own way is slow on large meshes (a sparse matrix, and hashes of the arrays at every cache look-up), so the
    look-up goes to the cache's dictionary and missing normals are made by meshes.smooth_normals."""
    normals = getattr(getattr(geometry, "_cache", None), "cache", {}).get("vertex_normals")
    if normals is None or np.shape(normals) != np.shape(geometry.vertices):
        return None
    return np.asarray(normals, dtype=np.float64)


def _concatenate(meshes: list[TriangleMesh]) -> TriangleMesh:
    if len(meshes) == 1:
        return meshes[0]
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    faces = np.concatenate([m.faces + o for m, o in zip(meshes, offsets)])
    vertices = np.concatenate([m.vertices for m in meshes])
    normals = None if meshes[0].normals is None else np.concatenate([m.normals for m in meshes])
    uvs = None
    if any(m.uvs is not None for m in meshes):
        uvs = np.concatenate([m.uvs if m.uvs is not None else np.zeros((len(m.vertices), 2)) for m in meshes])
    return TriangleMesh(vertices, faces, normals, uvs)


# ---------------------------------------------------------------------------------------------------------
# Warnings: one line per material
# ---------------------------------------------------------------------------------------------------------
@dataclass
class Notes:
    file_name: str
    _file: list[str] = field(default_factory=list)
    _materials: dict[object, tuple[str, list[str]]] = field(default_factory=dict)

    def add(self, key, name: str, note: str) -> None:
        entries = self._materials.setdefault(key, (name, []))[1]
        if note not in entries:
            entries.append(note)

    def add_file(self, note: str) -> None:
        if note not in self._file:
            self._file.append(note)

    def warnings(self) -> tuple[str, ...]:
        lines = [f"{self.file_name}: {note}" for note in self._file]
        lines += [f"{self.file_name}: material '{name}': {'; '.join(entries)}"
                  for name, entries in self._materials.values() if entries]
        return tuple(lines)


@dataclass(frozen=True)
class Mapped:
    key: object  # identifies the file's material (glTF index, MTL name)
    order: int  # where the file defines it
    name: str
    material: Material


class NoMaterials:
    """PLY, STL, OFF...: geometry only."""

    def __init__(self, path: Path, notes: Notes):
        self.path, self.notes = path, notes

    def load_trimesh(self):
        import trimesh

        if self.path.suffix.lower() == ".ply" and self.path.stat().st_size >= TEXT_COMPILED_MIN_BYTES:
            piece = read_ascii_ply(self.path)  # None for a binary PLY, or one outside the compiled reader's subset
            if piece is not None:
                return _text_scene([piece], self.path)
        return trimesh.load(str(self.path), process=False, force="scene")

    def material_for(self, geometry) -> Mapped | None:
        return None


class SerializedMesh(NoMaterials):
    """Mitsuba's .serialized: mesh ``shape_index`` of the file (``mitsuba_serialized``), geometry only. Handed on
    as trimesh's, so that it is checked, and given smooth normals where it has none, as any other file's."""

    def __init__(self, path: Path, notes: Notes, shape_index: int):
        super().__init__(path, notes)
        self.shape_index = shape_index

    def load_trimesh(self):
        import trimesh

        mesh = read_serialized(self.path, self.shape_index)
        visual = trimesh.visual.TextureVisuals(uv=mesh.uvs) if mesh.uvs is not None else None
        return trimesh.Scene(trimesh.Trimesh(mesh.vertices, mesh.faces, vertex_normals=mesh.normals, visual=visual,
                                             process=False))


def _text_scene(pieces: list[TextMeshPiece], path: Path):
    """The pieces text_meshes read, as the trimesh scene its parsers would have made: one geometry per material,
    named by it (the file's name where there is none), its ``usemtl`` name as the visual's material."""
    import trimesh

    scene = trimesh.Scene()
    for piece in pieces:
        material = trimesh.visual.material.SimpleMaterial(name=piece.material) if piece.material else None
        visual = None
        if material is not None or piece.uvs is not None:
            visual = trimesh.visual.TextureVisuals(uv=piece.uvs, material=material)
        mesh = trimesh.Trimesh(piece.vertices, piece.faces, vertex_normals=piece.normals, visual=visual,
                               process=False, validate=False)
        scene.add_geometry(mesh, geom_name=piece.material or path.name)
    return scene


# ---------------------------------------------------------------------------------------------------------
# Shared helpers
# ---------------------------------------------------------------------------------------------------------
def conductor_from_f0(f0, roughness: float, roughness_texture: Texture | None = None) -> Conductor:
    """A metal whose reflectance at normal incidence is ``f0``: eta = 1, k = 2 sqrt(F0 / (1 - F0)).

    With n = 1, Fresnel at normal incidence is k^2 / (4 + k^2) = F0, and it rises to 1 at grazing angles.
    """
    f0 = np.clip(np.asarray(f0, dtype=np.float64)[:3], 0.0, 0.9995)
    k = np.minimum(2.0 * np.sqrt(f0 / (1.0 - f0)), 100.0)
    return Conductor(metal="custom", eta=(1.0, 1.0, 1.0), k=_rgb(k), roughness=_unit(roughness),
                     roughness_texture=roughness_texture)


def roughness_from_phong(ns: float) -> float:
    """Blinn-Phong exponent -> perceptual roughness: Beckmann alpha = sqrt(2 / (Ns + 2)), r = sqrt(alpha)."""
    return _unit((2.0 / (max(ns, 0.0) + 2.0)) ** 0.25)


def read_image(path: Path) -> np.ndarray:
    """(H, W, C) float32 as stored (0..1 for 8/16-bit files), row 0 at the top. Raises OSError."""
    return read_pixels(path)[0]


def read_image_bytes(data: bytes, suffix: str) -> np.ndarray:
    handle, name = tempfile.mkstemp(suffix=suffix)
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        return read_image(Path(name))
    finally:
        os.unlink(name)


def _not_there(path: Path) -> str:
    """Why a file a material names cannot be read: "not found", or "is a named pipe (FIFO), not a regular file"."""
    other = not_a_file(path)
    return "not found" if other is None else f"is {other}"


def _rgb3(pixels: np.ndarray) -> np.ndarray:
    return np.repeat(pixels[..., :1], 3, axis=2) if pixels.shape[2] < 3 else pixels[..., :3]


def _rgb(values) -> tuple[float, float, float]:
    v = [float(x) for x in values][:3]
    return (v[0], v[1], v[2]) if len(v) == 3 else (v[0], v[0], v[0])


def _unit(x: float) -> float:
    return float(min(max(x, 0.0), 1.0))


def _clamp_rgb(values, low: float = 0.0, high: float = 1.0) -> tuple[float, float, float]:
    return _rgb(np.clip(np.asarray(_rgb(values)), low, high))


def _fmt(x: float) -> str:
    return f"{x:.3g}"


# ---------------------------------------------------------------------------------------------------------
# OBJ + MTL
# ---------------------------------------------------------------------------------------------------------
# Keys the mapping reads (or that mean nothing to a path tracer); any other key is reported as ignored.
MTL_HANDLED = {"newmtl", "ka", "map_ka", "illum", "kd", "map_kd", "ks", "ns", "ni", "d", "tr", "tf", "ke",
               "pr", "map_pr", "pm"}
# Texture statement options and how many arguments each takes (-o, -s, -t take one to three numbers).
MTL_TEXTURE_OPTIONS = {"-blendu": 1, "-blendv": 1, "-boost": 1, "-cc": 1, "-clamp": 1, "-imfchan": 1, "-mm": 2,
                       "-o": 3, "-s": 3, "-t": 3, "-texres": 1, "-bm": 1, "-type": 1}


def parse_mtl(text: str) -> dict[str, dict[str, tuple[str, str]]]:
    """Material name -> {lower-case key: (key as written, rest of the line)}."""
    materials: dict[str, dict[str, tuple[str, str]]] = {}
    current: dict[str, tuple[str, str]] | None = None
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        key, value = (line.split(None, 1) + [""])[:2]
        value = value.strip()
        if key.lower() == "newmtl":
            current = materials.setdefault(" ".join(value.split()), {})  # as trimesh names it
        elif current is not None:
            current[key.lower()] = (key, value)
    return materials


def _floats(value: str) -> list[float]:
    out = []
    for token in value.split():
        try:
            out.append(float(token))
        except ValueError:
            break
    return out


def _mtl_without_effect(key: str, keys: dict[str, tuple[str, str]]) -> bool:
    """A statement that changes nothing: Blender's PBR extension writes Ps 0, Pc 0, aniso 0... for every material."""

    def zero(k: str) -> bool:
        if k not in keys:
            return True
        tokens, values = keys[k][1].split(), _floats(keys[k][1])
        return 0 < len(values) == len(tokens) and not any(values)

    if key in ("pcr", "anisor"):  # clearcoat roughness, anisotropy rotation: nothing without their lobe
        return zero({"pcr": "pc", "anisor": "aniso"}[key])
    return not key.startswith(("map_", "bump", "disp", "decal", "norm", "refl")) and zero(key)


def parse_texture_statement(value: str) -> tuple[str, tuple[float, float], list[str]]:
    """``[-options] file`` -> (file, tiles from -s, options that were not applied)."""
    return _texture_statement(value)[:3]


def _texture_statement(value: str) -> tuple[str, tuple[float, float], list[str], list[float]]:
    """parse_texture_statement's reading, and the numbers of its -o, -s and -t options (to be checked)."""
    tokens = value.split()
    tiles, ignored, i, numbers = (1.0, 1.0), [], 0, []
    while i < len(tokens) and tokens[i].lower() in MTL_TEXTURE_OPTIONS:
        written, option = tokens[i], tokens[i].lower()
        i += 1
        if option in ("-o", "-s", "-t"):
            args: list = []
            while i < len(tokens) and len(args) < 3 and _floats(tokens[i]):
                args.append(float(tokens[i]))
                i += 1
            numbers += args
        else:
            args = tokens[i:i + MTL_TEXTURE_OPTIONS[option]]
            i += MTL_TEXTURE_OPTIONS[option]
        if option == "-s" and args:
            tiles = (args[0], args[1] if len(args) > 1 else 1.0)
        elif option in ("-o", "-t") and not any(args):
            continue
        elif option in ("-blendu", "-blendv") or (option == "-clamp" and [a.lower() for a in args] == ["off"]):
            continue
        else:
            ignored.append(f"{written} {' '.join(_fmt(a) if isinstance(a, float) else a for a in args)}".strip())
    return " ".join(tokens[i:]), tiles, ignored, numbers


def _check_mtl_numbers(library: Path, material: str, keys: dict[str, tuple[str, str]]) -> None:
    """Refuse a statement the mapping reads whose numbers are not finite (Ke nan, Kd 1e999, map_Kd -s nan nan)
    or beyond the bound of every scene's numbers (limits.LARGEST_NUMBER): one would reach the renderer as a
    material or a texture that makes every pixel it touches NaN, or silently be taken as zero."""
    for key, (written, value) in keys.items():
        if key not in MTL_HANDLED or key == "newmtl":
            continue
        for number in _texture_statement(value)[3] if key.startswith("map_") else _floats(value):
            if not math.isfinite(number):
                raise MeshLoadError(f"{library}: material '{material}': {written} {value}: not a finite number")
            problem = number_problem(number)
            if problem:
                raise MeshLoadError(f"{library}: material '{material}': {written} {value}: {problem}")


def _checked_resolver_class():
    """trimesh's resolver of the files beside a mesh (an OBJ's textures, a glTF's buffers and images), refusing
    a named pipe, a device or a folder (image_files.NotARegularFile) before trimesh opens it and waits."""
    import trimesh

    class Checked(trimesh.resolvers.FilePathResolver):
        def get(self, name: str) -> bytes:
            for candidate in (name.strip(), name.strip().lstrip("/"), os.path.split(name)[-1]):  # as trimesh tries
                check_regular_file(os.path.join(self.parent, candidate))
            return super().get(name)

    return Checked


def _all_libraries_resolver(path: Path, libraries: bytes):
    """A trimesh resolver that answers every request for an MTL file with ``libraries`` (all the OBJ's material
    libraries, joined), and any other (a texture) from the OBJ's folder."""

    class AllLibraries(_checked_resolver_class()):
        def get(self, name: str) -> bytes:
            if name.strip().lower().endswith(".mtl"):
                return libraries
            return super().get(name)

    return AllLibraries(str(path))


def _mtllib_statements(text: bytes) -> list[str]:
    """The values of an OBJ's ``mtllib`` statements. Found with bytes.find, which skips a hundred megabytes of
    vertices in milliseconds, where a multi-line regular expression tries every line start."""
    values = []
    at = text.find(b"mtllib")
    while at >= 0:
        line_start = text.rfind(b"\n", 0, at) + 1
        line_end = text.find(b"\n", at)
        line_end = len(text) if line_end < 0 else line_end
        match = re.fullmatch(rb"[ \t]*mtllib[ \t]+(.+?)[ \t\r]*", text[line_start:line_end])
        if match:
            values.append(match.group(1).decode("utf-8", "replace"))
        at = text.find(b"mtllib", line_end)
    return values


class ObjMaterials:
    def __init__(self, path: Path, notes: Notes):
        self.path, self.notes = path, notes
        self.definitions: dict[str, tuple[dict[str, tuple[str, str]], Path]] = {}  # name -> (keys, MTL folder)
        self._mapped: dict[str, Mapped] = {}
        self._library_files: list[Path] = []
        text = read_file_bytes(path)
        # None for a small file, or one outside the compiled reader's subset: trimesh reads those.
        self._compiled_reading = read_obj(text) if len(text) >= TEXT_COMPILED_MIN_BYTES else None
        libraries = self._compiled_reading.libraries if self._compiled_reading else _mtllib_statements(text)
        for value in libraries:
            self._read_library(value)

    def _read_library(self, value: str) -> None:
        names = [value] if os.path.isfile(self.path.parent / value) else value.split()
        for name in names:
            library = self.path.parent / name.replace("\\", "/")
            if not os.path.isfile(library):
                self.notes.add_file(f"material library '{name}' {_not_there(library)} ({library}): "
                                    "its materials render with the node's material or the default grey")
                continue
            self._library_files.append(library)
            for material, keys in parse_mtl(read_file_bytes(library).decode("utf-8", "replace")).items():
                _check_mtl_numbers(library, material, keys)
                self.definitions.setdefault(material, (keys, library.parent))

    def load_trimesh(self):
        import trimesh

        if self._compiled_reading is not None:
            return _text_scene(self._compiled_reading.pieces, self.path)
        # trimesh reads only the first library an OBJ names; handed all of them as one, it names every material
        # the faces use, as the compiled reader does.
        resolver = _all_libraries_resolver(self.path, b"\n".join(read_file_bytes(library)
                                                                  for library in self._library_files))
        return trimesh.load(str(self.path), process=False, force="scene", resolver=resolver)

    def material_for(self, geometry) -> Mapped | None:
        name = getattr(getattr(geometry.visual, "material", None), "name", None)
        if name not in self.definitions:
            return None
        if name not in self._mapped:
            keys, folder = self.definitions[name]
            order = list(self.definitions).index(name)
            self._mapped[name] = Mapped(name, order, name, self._map(name, keys, folder))
        return self._mapped[name]

    def _map(self, name: str, keys: dict[str, tuple[str, str]], folder: Path) -> Material:
        def note(text: str) -> None:
            self.notes.add(name, name, text)

        def number(key: str, default: float | None = None) -> float | None:
            values = _floats(keys[key][1]) if key in keys else []
            return values[0] if values else default

        def colour(key: str, default) -> tuple[float, float, float]:
            values = _floats(keys[key][1]) if key in keys else []
            return _clamp_rgb(values) if values else default

        for key, (written, _) in keys.items():
            if key not in MTL_HANDLED and not _mtl_without_effect(key, keys):
                note(f"{written} ignored")
        kd = colour("kd", (0.8, 0.8, 0.8))
        ks = colour("ks", (0.0, 0.0, 0.0))
        ke = _rgb(np.maximum(_floats(keys["ke"][1]) or [0.0], 0.0)) if "ke" in keys else (0.0, 0.0, 0.0)
        ni = number("ni")
        ior = ni if ni is not None and 1.0 < ni <= 4.0 else 1.5
        opacity = number("d")
        if opacity is None and number("tr") is not None:
            opacity = 1.0 - number("tr")
        opacity = 1.0 if opacity is None else _unit(opacity)
        pr, pm = number("pr"), number("pm")
        roughness = _unit(pr) if pr is not None else roughness_from_phong(number("ns", 0.0))
        albedo_texture = self._texture(keys, "map_kd", folder, note, "auto")
        roughness_texture = self._texture(keys, "map_pr", folder, note, "raw")  # data: values as stored

        if max(ke) > 0.0:
            # A lamp's diffuser reflects as well as glows (as in Blender, where Ke adds to the surface).
            reflects = any(key in keys for key in ("kd", "ks", "map_kd"))
            rest = {key: value for key, value in keys.items() if key != "ke"}
            return Emissive(radiance=ke, surface=self._map(name, rest, folder) if reflects else None)
        if opacity < 1.0:
            if opacity > 0.0:
                note(f"dissolve {_fmt(opacity)} (partly transparent) rendered as clear glass")
            if albedo_texture is not None:
                note("map_Kd ignored on glass")
            tf = colour("tf", (1.0, 1.0, 1.0))
            return Dielectric(ior=max(ior, 1.0001), roughness=_unit(pr) if pr is not None else 0.0, tint=tf)
        if "tf" in keys and colour("tf", (1.0, 1.0, 1.0)) != (1.0, 1.0, 1.0):
            note("Tf ignored on an opaque material")
        kd_black = max(kd) < 0.01 and albedo_texture is None
        if (pm is not None and pm >= 0.5) or (pm is None and kd_black and max(ks) > 0.01):
            if pm is not None and pm < 1.0:
                note(f"metallic Pm {_fmt(pm)} rendered as a full metal")
            if albedo_texture is not None:
                note("map_Kd ignored on a metal (metals take one colour)")
            return conductor_from_f0(kd if pm is not None else ks, roughness, roughness_texture)
        if pm is not None and pm > 0.0:
            note(f"metallic Pm {_fmt(pm)} rendered as plastic")
        if max(ks) > 0.01 or pr is not None:
            return Plastic(albedo=kd, albedo_texture=albedo_texture, ior=ior, roughness=roughness,
                           roughness_texture=roughness_texture)
        if roughness_texture is not None:
            note("map_Pr ignored on a diffuse material")
        return Diffuse(albedo=kd, albedo_texture=albedo_texture)

    def _texture(self, keys, key: str, folder: Path, note, color_space: str) -> ImageTexture | None:
        if key not in keys:
            return None
        written, value = keys[key]
        file, tiles, ignored = parse_texture_statement(value)
        for option in ignored:
            note(f"{written} option {option} ignored")
        if not file:
            return None
        path = Path(file.replace("\\", "/"))
        path = path if path.is_absolute() else folder / path
        if not os.path.isfile(path):
            note(f"{written} texture file '{file}' {_not_there(path)} ({path}): it renders as a "
                 "magenta checkerboard")
        return ImageTexture(file=str(path), color_space=color_space, tiles=tiles)


# ---------------------------------------------------------------------------------------------------------
# glTF 2.0 / GLB
# ---------------------------------------------------------------------------------------------------------
GLTF_HANDLED_EXTENSIONS = {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume",
                           "KHR_materials_emissive_strength"}
GLTF_REPEAT = 10497
GLB_JSON, GLB_BIN = 0x4E4F534A, 0x004E4942
MIME_SUFFIX = {"image/png": ".png", "image/jpeg": ".jpg", "image/webp": ".webp"}
TAG = "lenslab-material-{}"  # the name trimesh sees, so each geometry names its material by index
TAG_PATTERN = re.compile(r"^lenslab-material-(\d+)$")


# Extensions whose lobe is off at these values (their defaults): written by some exporters for every material.
GLTF_NEUTRAL = {
    "KHR_materials_clearcoat": {"clearcoatFactor": 0.0},
    "KHR_materials_sheen": {"sheenColorFactor": [0.0, 0.0, 0.0]},
    "KHR_materials_iridescence": {"iridescenceFactor": 0.0},
    "KHR_materials_anisotropy": {"anisotropyStrength": 0.0},
    "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0.0},
    "KHR_materials_dispersion": {"dispersion": 0.0},
    "KHR_materials_specular": {"specularFactor": 1.0, "specularColorFactor": [1.0, 1.0, 1.0]},
}


def _gltf_without_effect(extension: str, values) -> bool:
    """True when the extension's lobe is off: its strength is its factor times its texture."""
    neutral = GLTF_NEUTRAL.get(extension)
    if neutral is None or not isinstance(values, dict):
        return False
    try:
        at_default = all(np.allclose(values.get(key, default), default) for key, default in neutral.items())
    except (TypeError, ValueError):  # a factor that is no number: not known to be off, so reported as ignored
        return False
    if extension == "KHR_materials_specular":  # neutral factors of 1: a texture still changes things
        return at_default and not any(key.endswith("Texture") for key in values)
    return at_default


# What the material mapping reads of a glTF, and the JSON type each must have (glTF 2.0's schema): a file with
# a number where a list belongs, a null factor or an object of images is refused in one line naming the field,
# before anything is read from it. "info": a textureInfo; ("numbers", n): a list of n numbers.
_TEXTURE_INFO = {"index": "index", "texCoord": "index", "extensions": dict, "scale": "number", "strength": "number"}
_GLTF_MATERIAL = {
    "name": str, "alphaMode": str, "doubleSided": bool, "emissiveFactor": ("numbers", 3), "extensions": dict,
    "normalTexture": _TEXTURE_INFO, "occlusionTexture": _TEXTURE_INFO, "emissiveTexture": _TEXTURE_INFO,
    "pbrMetallicRoughness": {"baseColorFactor": ("numbers", 4), "metallicFactor": "number",
                             "roughnessFactor": "number", "baseColorTexture": _TEXTURE_INFO,
                             "metallicRoughnessTexture": _TEXTURE_INFO},
}
_GLTF_EXTENSIONS = {
    "KHR_materials_transmission": {"transmissionFactor": "number", "transmissionTexture": _TEXTURE_INFO},
    "KHR_materials_ior": {"ior": "number"},
    "KHR_materials_emissive_strength": {"emissiveStrength": "number"},
    "KHR_materials_volume": {"attenuationDistance": "number", "attenuationColor": ("numbers", 3),
                             "thicknessFactor": "number"},
}
_GLTF_LISTS = {  # top-level arrays: what each entry holds, and which other array each index points into
    "materials": (_GLTF_MATERIAL, {}),
    "textures": ({"source": "index", "sampler": "index", "extensions": dict}, {"source": "images",
                                                                                "sampler": "samplers"}),
    "samplers": ({"wrapS": "index", "wrapT": "index"}, {}),
    "images": ({"uri": str, "mimeType": str, "bufferView": "index"}, {"bufferView": "bufferViews"}),
    "bufferViews": ({"buffer": "index", "byteOffset": "index", "byteLength": "index"}, {"buffer": "buffers"}),
    "buffers": ({"uri": str}, {}),
}
_GLTF_REQUIRED = {"bufferViews": ("buffer", "byteLength")}
_JSON_TYPE_NAMES = {str: "a string", bool: "true or false", dict: "an object", "number": "a number",
                    "index": "a whole number of 0 or more"}


def _gltf_value_problem(value, kind) -> str | None:
    """Why ``value`` is not of ``kind`` (see _GLTF_MATERIAL), or None."""
    if isinstance(kind, dict):
        if not isinstance(value, dict):
            return f"expected an object, not {_json_shown(value)}"
        return None
    if isinstance(kind, tuple):
        count = kind[1]
        if not isinstance(value, list) or len(value) != count:
            return f"expected a list of {count} numbers, not {_json_shown(value)}"
        for item in value:
            problem = _gltf_value_problem(item, "number")
            if problem:
                return problem
        return None
    if kind in ("number", "index"):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f"expected {_JSON_TYPE_NAMES[kind]}, not {_json_shown(value)}"
        if kind == "index" and (not isinstance(value, int) or value < 0):
            return f"expected {_JSON_TYPE_NAMES[kind]}, not {_json_shown(value)}"
        return number_problem(value)
    if not isinstance(value, kind) or (kind is not bool and isinstance(value, bool)):
        return f"expected {_JSON_TYPE_NAMES[kind]}, not {_json_shown(value)}"
    return None


def _json_shown(value) -> str:
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _gltf_fields_problem(table: dict, fields: dict, where: str) -> str | None:
    for key, kind in fields.items():
        if key not in table:
            continue
        problem = _gltf_value_problem(table[key], kind)
        if problem is None and isinstance(kind, dict):
            problem = _gltf_fields_problem(table[key], kind, f"{where}.{key}")
            if problem:
                return problem
        if problem:
            return f"{where}.{key}: {problem}"
    return None


def _gltf_problem(header) -> str | None:
    """The first field of a glTF's JSON that the material mapping reads and that has the wrong type, a number
    that is not finite or beyond limits.LARGEST_NUMBER, or an index past the array it points into, as
    "materials[0].pbrMetallicRoughness.baseColorFactor: expected a list of 4 numbers, not 0.5"; None if none."""
    if not isinstance(header, dict):
        return f"expected a glTF object at the top, not {_json_shown(header)}"
    for name in _GLTF_LISTS:
        if not isinstance(header.get(name, []), list):
            return f"{name}: expected a list, not {_json_shown(header[name])}"
    for name, (fields, points_into) in _GLTF_LISTS.items():
        for i, entry in enumerate(header.get(name, [])):
            where = f"{name}[{i}]"
            if not isinstance(entry, dict):
                return f"{where}: expected an object, not {_json_shown(entry)}"
            problem = _gltf_fields_problem(entry, fields, where)
            if problem:
                return problem
            missing = [key for key in _GLTF_REQUIRED.get(name, ()) if key not in entry]
            if missing:
                return f"{where}: no {missing[0]} (glTF requires one)"
            for key, target in points_into.items():
                count = len(header.get(target, []))
                if key in entry and entry[key] >= count:
                    return f"{where}.{key}: {entry[key]} points past the file's {count} {target}"
            extensions = entry.get("extensions")
            for extension, values in (extensions.items() if isinstance(extensions, dict) else ()):
                if extension in _GLTF_EXTENSIONS or name == "textures":
                    if not isinstance(values, dict):
                        return f"{where}.extensions.{extension}: expected an object, not {_json_shown(values)}"
                    problem = _gltf_fields_problem(values, _GLTF_EXTENSIONS.get(extension, {"source": "index"}),
                                                   f"{where}.extensions.{extension}")
                    if problem:
                        return problem
    return None


def split_glb(data: bytes) -> tuple[dict, bytes | None]:
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2:
        raise MeshLoadError("not a glTF 2.0 binary")
    header, binary, offset = None, None, 12
    while offset + 8 <= min(length, len(data)):
        chunk_length, chunk_type = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8: offset + 8 + chunk_length]
        if chunk_type == GLB_JSON and header is None:
            header = json.loads(chunk.decode("utf-8"))
        elif chunk_type == GLB_BIN and binary is None:
            binary = bytes(chunk)
        offset += 8 + chunk_length
    if header is None:
        raise MeshLoadError("GLB without a JSON chunk")
    return header, binary


def _base64(payload: str, index: int, what: str = "image") -> bytes:
    """The bytes of a data URI's base64 payload; OSError (an unreadable image or buffer) where it is not base64."""
    try:
        return base64.b64decode(payload)
    except ValueError as exc:
        raise OSError(f"{what} {index}: its data URI is not base64 ({exc})") from None


def join_glb(header: dict, binary: bytes | None) -> bytes:
    text = json.dumps(header).encode("utf-8")
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), GLB_JSON) + text
    if binary is not None:
        binary += b"\0" * (-len(binary) % 4)
        chunks += struct.pack("<II", len(binary), GLB_BIN) + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


class GltfMaterials:
    def __init__(self, path: Path, notes: Notes):
        self.path, self.notes = path, notes
        data = read_file_bytes(path)
        try:
            if data[:4] == b"glTF":
                self.header, self.binary = split_glb(data)
            else:
                self.header, self.binary = json.loads(data.decode("utf-8")), None
        except (ValueError, struct.error, UnicodeDecodeError, RecursionError) as exc:
            raise MeshLoadError(f"{path}: cannot read glTF ({exc})") from None
        problem = _gltf_problem(self.header)
        if problem is not None:
            raise MeshLoadError(f"{path}: {problem}")
        self.materials = self.header.get("materials", [])
        self._mapped: dict[int, Mapped] = {}
        self._textures: dict[tuple, Texture | None] = {}
        self._pixels: dict[int, np.ndarray] = {}

    def load_trimesh(self):
        import trimesh

        header = copy.copy(self.header)
        header["materials"] = [dict(m, name=TAG.format(i)) for i, m in enumerate(self.materials)]
        if self.binary is not None or self.path.suffix.lower() == ".glb":
            data, file_type = join_glb(header, self.binary), "glb"
        else:
            data, file_type = json.dumps(header).encode("utf-8"), "gltf"
        checked = _checked_resolver_class()
        try:
            resolver = checked(str(self.path), allow_anywhere=True)
        except TypeError:  # trimesh before allow_anywhere
            resolver = checked(str(self.path))
        return trimesh.load(io.BytesIO(data), file_type=file_type, resolver=resolver, process=False, force="scene")

    def material_for(self, geometry) -> Mapped | None:
        match = TAG_PATTERN.match(str(getattr(getattr(geometry.visual, "material", None), "name", "")))
        if match is None or int(match.group(1)) >= len(self.materials):
            return None
        index = int(match.group(1))
        if index not in self._mapped:
            name = self.materials[index].get("name") or f"material {index}"
            self._mapped[index] = Mapped(index, index, name, self._map(index, name))
        return self._mapped[index]

    # -- one material ------------------------------------------------------------------------------------
    def _map(self, index: int, name: str, material: dict | None = None) -> Material:
        material = self.materials[index] if material is None else material

        def note(text: str) -> None:
            self.notes.add(index, name, text)

        pbr = material.get("pbrMetallicRoughness", {})
        extensions = material.get("extensions", {}) or {}
        for extension, values in extensions.items():
            if extension not in GLTF_HANDLED_EXTENSIONS and not _gltf_without_effect(extension, values):
                note(f"{extension} ignored")
        base = [float(x) for x in pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))]
        base_rgb = _clamp_rgb(base[:3])
        metallic = _unit(float(pbr.get("metallicFactor", 1.0)))
        roughness = _unit(float(pbr.get("roughnessFactor", 1.0)))
        transmission = _unit(float(extensions.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0)))
        ior = float(extensions.get("KHR_materials_ior", {}).get("ior", 1.5))
        strength = float(extensions.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0))
        emission = np.maximum(np.asarray(material.get("emissiveFactor", (0.0, 0.0, 0.0)), float) * strength, 0.0)

        alpha_mode = material.get("alphaMode", "OPAQUE")
        if alpha_mode != "OPAQUE":
            note(f"alpha mode {alpha_mode} ignored (rendered opaque)")
        if "normalTexture" in material:
            note("normal map ignored")
        if "occlusionTexture" in material:
            note("occlusion map ignored")

        # metallicRoughness texture: G is roughness (a texture of its own), B metalness (decides the material)
        roughness_texture, metal_varies = None, False
        if "metallicRoughnessTexture" in pbr:
            channels = self._data_texture(pbr["metallicRoughnessTexture"], "metallicRoughness", note)
            if isinstance(channels, Texture):  # missing file: the placeholder shows it
                roughness_texture = channels
            elif channels is not None:
                rgb = _rgb3(channels)
                g, b = rgb[..., 1] * roughness, rgb[..., 2] * metallic
                if np.ptp(g) > 1.0 / 255.0:
                    pixels = np.repeat(g[..., None], 3, axis=2).astype(np.float32)
                    roughness_texture = InlineImageTexture(pixels=pixels, color_space="raw", name=self._image_label(
                        pbr["metallicRoughnessTexture"], "roughness"))
                roughness = _unit(float(g.mean()))
                metal_varies = bool(np.ptp(b) > 1.0 / 255.0)
                metallic = _unit(float(b.mean()))

        base_info = pbr.get("baseColorTexture")
        if max(emission) > 0.0:
            if "emissiveTexture" in material:
                mean = self._mean_colour(material["emissiveTexture"], "emissive", note)
                if mean is not None:
                    emission = emission * mean
                    note("emissive texture averaged to one colour (emitters take one radiance)")
            rest = dict(material, emissiveFactor=(0.0, 0.0, 0.0))
            return Emissive(radiance=_rgb(np.minimum(emission, 1e6)), two_sided=bool(material.get("doubleSided", False)),
                            surface=self._map(index, name, rest))
        if metallic >= 0.5:
            f0 = np.asarray(base_rgb)
            if base_info is not None:
                mean = self._mean_colour(base_info, "base colour", note)
                if mean is not None:
                    f0 = f0 * mean
                    note("base colour texture averaged to one colour (metals take one colour)")
            if metal_varies:
                note(f"metalness texture varies: rendered all metal (mean metallic {metallic:.2f})")
            elif metallic < 1.0:
                note(f"metallic {metallic:.2f} rendered as a full metal")
            if transmission > 0.0:
                note("transmission ignored on a metal")
            return conductor_from_f0(f0, roughness, roughness_texture)
        if metal_varies:
            note(f"metalness texture ignored (mean metallic {metallic:.2f} -> plastic)")
        elif metallic > 0.0:
            note(f"metallic {metallic:.2f} rendered as plastic")
        if transmission > 0.0:
            return self._glass(material, extensions, base_rgb, base_info, ior, roughness, roughness_texture,
                               transmission, note)
        albedo_texture = self._colour_texture(base_info, base_rgb, "base colour", note) if base_info else None
        return Plastic(albedo=base_rgb, albedo_texture=albedo_texture, ior=min(max(ior, 1.0), 4.0),
                       roughness=roughness, roughness_texture=roughness_texture)

    def _glass(self, material, extensions, base_rgb, base_info, ior, roughness, roughness_texture,
               transmission, note) -> Dielectric:
        if transmission < 1.0:
            note(f"transmission {transmission:.2f} rendered as fully transmissive glass")
        if "transmissionTexture" in extensions.get("KHR_materials_transmission", {}):
            note("transmission texture ignored")
        if base_info is not None:
            note("base colour texture ignored on glass (tint from baseColorFactor)")
        if roughness_texture is not None:
            note(f"roughness texture ignored on glass (mean roughness {roughness:.2f})")
        glass = Dielectric(ior=min(max(ior, 1.0001), 4.0), roughness=roughness, tint=base_rgb)
        volume = extensions.get("KHR_materials_volume", {})
        distance = float(volume.get("attenuationDistance", math.inf))
        colour = _clamp_rgb(volume.get("attenuationColor", (1.0, 1.0, 1.0)), 1e-6, 1.0)
        if math.isfinite(distance) and distance > 0.0 and colour != (1.0, 1.0, 1.0):
            glass.absorption_color = colour
            glass.absorption_distance_m = min(max(distance, 1e-6), 1e6)
        return glass

    # -- textures ----------------------------------------------------------------------------------------
    def _texture_image(self, info: dict, role: str, note) -> int | None:
        """The image index a textureInfo reads, with what we cannot honour of it noted."""
        try:
            texture = self.header["textures"][info["index"]]
        except (KeyError, IndexError, TypeError):
            note(f"{role} texture: no texture {info.get('index')!r} in the file")
            return None
        if info.get("texCoord", 0) != 0:
            note(f"{role} texture uses uv set {info['texCoord']}: read with the first")
        if "KHR_texture_transform" in (info.get("extensions") or {}):
            note(f"{role} texture transform (KHR_texture_transform) ignored")
        if "sampler" in texture:
            sampler = self.header.get("samplers", [{}])[texture["sampler"]]
            if sampler.get("wrapS", GLTF_REPEAT) != GLTF_REPEAT or sampler.get("wrapT", GLTF_REPEAT) != GLTF_REPEAT:
                note(f"{role} texture wrap mode ignored (textures repeat)")
        source = texture.get("source")
        if source is None:
            source = next((e["source"] for e in (texture.get("extensions") or {}).values()
                           if isinstance(e, dict) and "source" in e), None)
        if source is None or source >= len(self.header.get("images", [])):
            note(f"{role} texture has no image")
            return None
        return source

    def _image_label(self, info: dict, role: str) -> str:
        return f"{self.path.name}: {role} of texture {info.get('index')}"

    def _external_path(self, image_index: int) -> Path | None:
        uri = self.header["images"][image_index].get("uri")
        if uri is None or uri.startswith("data:"):
            return None
        path = Path(urllib.parse.unquote(uri))
        return path if path.is_absolute() else self.path.parent / path

    def _image_pixels(self, image_index: int) -> np.ndarray:
        """The image as stored (0..1), read through OpenImageIO. Raises OSError."""
        if image_index not in self._pixels:
            image = self.header["images"][image_index]
            external = self._external_path(image_index)
            if external is not None:
                self._pixels[image_index] = read_image(external)
            else:
                suffix = MIME_SUFFIX.get(image.get("mimeType", ""), ".png")
                if "uri" in image:
                    head, _, payload = image["uri"].partition(",")
                    suffix = MIME_SUFFIX.get(head[5:].split(";")[0], suffix)
                    data = (_base64(payload, image_index) if head.endswith(";base64")
                            else urllib.parse.unquote_to_bytes(payload))
                elif "bufferView" in image:
                    data = self._buffer_view(image["bufferView"])
                else:
                    raise OSError(f"image {image_index} has neither a uri nor a bufferView")
                self._pixels[image_index] = read_image_bytes(data, suffix)
        return self._pixels[image_index]

    def _buffer_view(self, index: int) -> bytes:
        view = self.header["bufferViews"][index]
        buffer = self.header["buffers"][view["buffer"]]
        uri = buffer.get("uri")
        if uri is None:
            data = self.binary or b""
        elif uri.startswith("data:"):
            data = _base64(uri.partition(",")[2], view["buffer"], "buffer")
        else:
            data = read_file_bytes(self.path.parent / urllib.parse.unquote(uri))
        start = view.get("byteOffset", 0)
        return data[start: start + view["byteLength"]]

    def _missing(self, image_index: int, role: str, note, fallback: str = "it renders as a magenta checkerboard"
                 ) -> Path | None:
        """The external file of an image when it does not exist (noted, with what happens instead), else None."""
        path = self._external_path(image_index)
        if path is None or os.path.isfile(path):
            return None
        uri = self.header["images"][image_index]["uri"]
        note(f"{role} texture file '{uri}' {_not_there(path)} ({path}): {fallback}")
        return path

    def _colour_texture(self, info: dict, factor, role: str, note) -> Texture | None:
        """An sRGB colour texture times ``factor``: the file on disk when it needs no change, else linear pixels."""
        image_index = self._texture_image(info, role, note)
        if image_index is None:
            return None
        missing = self._missing(image_index, role, note)
        if missing is not None:
            return ImageTexture(file=str(missing), color_space="srgb")
        key = ("colour", image_index, tuple(factor))
        if key not in self._textures:
            external = self._external_path(image_index)
            if external is not None and tuple(factor) == (1.0, 1.0, 1.0):
                self._textures[key] = ImageTexture(file=str(external), color_space="srgb")
            else:
                try:
                    pixels = srgb_to_linear(_rgb3(self._image_pixels(image_index))) * np.asarray(factor)
                    self._textures[key] = InlineImageTexture(pixels=pixels.astype(np.float32),
                                                             name=self._image_label(info, role))
                except OSError as exc:
                    note(f"{role} texture unreadable ({exc}): it renders as a magenta checkerboard")
                    self._textures[key] = PLACEHOLDER
        return self._textures[key]

    def _data_texture(self, info: dict, role: str, note) -> np.ndarray | Texture | None:
        """The channels of a data texture as stored; for a missing file an ImageTexture on it (the placeholder)."""
        image_index = self._texture_image(info, role, note)
        if image_index is None:
            return None
        missing = self._missing(image_index, role, note)
        if missing is not None:
            return ImageTexture(file=str(missing), color_space="raw")
        try:
            return self._image_pixels(image_index)
        except OSError as exc:
            note(f"{role} texture unreadable ({exc}): ignored")
            return None

    def _mean_colour(self, info: dict, role: str, note) -> np.ndarray | None:
        image_index = self._texture_image(info, role, note)
        if image_index is None or self._missing(image_index, role, note, "ignored") is not None:
            return None
        try:
            return srgb_to_linear(_rgb3(self._image_pixels(image_index))).reshape(-1, 3).mean(axis=0)
        except OSError as exc:
            note(f"{role} texture unreadable ({exc}): ignored")
            return None
