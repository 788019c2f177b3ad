"""A seeded generator of malformed scenes, and the check that LensLab meets each with one clear line.

Every case starts from a scene that ships with LensLab (native JSON, or one of the Mitsuba XML validation
scenes) and breaks one thing the way real files break: a key deleted, a value of the wrong type, a number out
of range or not finite, a string a terminal would obey, a nest too deep, a truncation, flipped bytes, a mesh
whose faces point past its vertices, a texture cut short, an entity trick in the XML; a batch file's value of
the wrong kind (a TOML date), a Mitsuba ``.serialized`` mesh cut short, a glTF field of the wrong type, a named
pipe (FIFO) where a file is read or written. The contract (:func:`judge`): the command ends with exit 0 and a
whole, finite image, or with a non-zero exit and exactly one line ``lenslab: error: ...`` that names a file the
case wrote and holds no control characters; never a traceback, never a hang.

A hang is found from the work a case does, not from the clock (the watcher, ``_WATCHER``): a case that spends more than
``CASE_CPU_SECONDS`` of CPU (a loop without end) or none at all for ``STALLED_CHECKS`` checks in a row (a read that
waits for ever) is stopped. A machine busy with other work slows a case, but never makes it do more work.

``tests/test_malformed_inputs.py`` runs a few hundred cases in-process; for a larger run, in a subprocess per
case as a user meets them::

    python tests/malformed_inputs.py --cases 3000 --seed 11 [--subprocess]
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import os
import random
import re
import shutil
import signal
import stat
import struct
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
import zlib
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
NATIVE_SCENES = ("cornell_box", "dof_chart", "product_shot", "cornell_caustic")  # marbles: a million triangles
MITSUBA_SCENES = (REPO / "app/lenslab/validate/scenes", REPO / "tests/data/mitsuba")
RENDER_ARGS = ["--spp", "1", "--width", "8", "--height", "8"]
#: The work one case may do, in CPU seconds of its process (all threads): a case renders 8 x 8 pixels at one
#: sample in well under one; a reader that loops without end reaches this and is stopped.
CASE_CPU_SECONDS = 300
#: A case whose process does no work at all (no CPU) at this many checks in a row is blocked: a read that waits
#: for ever, as on a named pipe. A check every CHECK_SECONDS; a case at work spends CPU between any two.
STALLED_CHECKS = 60
CHECK_SECONDS = 1.0
#: --subprocess only, a backstop for what the checks cannot see: generous, and not what finds a hang.
BACKSTOP_SECONDS = 1800
MAX_ERROR_LINE = 1000
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f\x9b]")


@dataclass
class Case:
    """One malformed input: the files to write in an empty folder, which one to open, what was broken."""

    what: str
    files: dict[str, bytes]
    scene: str  # the scene file opened, or the batch file
    extra_args: list[str] = field(default_factory=list)
    fifos: list[str] = field(default_factory=list)  # named pipes made in the folder ("out.png": the output)
    command: str = "render"  # or "batch": `lenslab batch FILE --dry-run`


@dataclass
class Outcome:
    case: Case
    status: int | None  # None: an exception escaped (a traceback), or the case hung
    stderr: str
    seconds: float
    problem: str = ""  # empty when the contract held


# ---------------------------------------------------------------------------------------------------------
# Values a careless exporter or an attacker might write
# ---------------------------------------------------------------------------------------------------------
_HUGE_INT_TEXT = "9" * 400
_WEIRD_STRINGS = ["", " ", "\x1b[2J\x1b[31mred", "a" * 300, "é☃\u202e", "../" * 20 + "etc/passwd", "/", ".",
                  "x" * 100_000, "nan", "1e999", "-1", "\x00", "line\nbreak", "CON", "%s%n{0}$p1"]


def _weird_json_value(rng: random.Random):
    choice = rng.randrange(14)
    if choice == 0:
        return None
    if choice == 1:
        return rng.choice([[], {}, [[]], {"type": []}, [1, 2], [1, 2, 3, 4]])
    if choice == 2:
        return rng.choice([True, False])
    if choice == 3:
        return rng.choice([0, -1, -0.0, 1e-320, 5e-324, -1e308, 1e308, 3.4e38, 2**64, 2**31, -2**31 - 1])
    if choice == 4:
        return rng.choice(_WEIRD_STRINGS)
    if choice == 5:
        return float(rng.choice(["nan", "inf", "-inf"]))
    if choice == 6:
        return [float("nan"), 1.0, 2.0]
    if choice == 7:
        return [1e308, 1e308, 1e308]
    if choice == 8:
        return rng.uniform(-1e6, 1e6)
    if choice == 9:
        return rng.randint(-5, 100_000)
    if choice == 10:
        return {"type": rng.choice(["", "sphere", "map", "diffuse", "mesh", "constant", 7])}
    if choice == 11:
        return [[[[[]]]]]
    if choice == 12:
        return "$HUGE_INT$"  # replaced in the text by a 400-digit integer
    return [0, 0, 0]


def _paths(value, prefix=()):
    """Every (path, value) in a parsed JSON document."""
    yield prefix, value
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _paths(item, prefix + (key,))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            yield from _paths(item, prefix + (index,))


def _parent(doc, path):
    for key in path[:-1]:
        doc = doc[key]
    return doc


# ---------------------------------------------------------------------------------------------------------
# Corrupting bytes
# ---------------------------------------------------------------------------------------------------------
def _truncate(data: bytes, rng: random.Random) -> bytes:
    return data[:rng.randrange(len(data))] if data else data


def _flip_bytes(data: bytes, rng: random.Random) -> bytes:
    if not data:
        return data
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        out[rng.randrange(len(out))] = rng.randrange(256)
    return bytes(out)


def _insert_bytes(data: bytes, rng: random.Random) -> bytes:
    at = rng.randrange(len(data) + 1)
    junk = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
    return data[:at] + junk + data[at:]


def _corrupt_bytes(data: bytes, rng: random.Random) -> tuple[str, bytes]:
    kind = rng.choice(("truncated", "bytes flipped", "bytes inserted"))
    corrupt = {"truncated": _truncate, "bytes flipped": _flip_bytes, "bytes inserted": _insert_bytes}[kind]
    return kind, corrupt(data, rng)


# ---------------------------------------------------------------------------------------------------------
# Native scenes
# ---------------------------------------------------------------------------------------------------------
def _shipped_files(name: str) -> dict[str, bytes]:
    folder = REPO / "scenes" / name
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file() and p.suffix != ".py"}


def _native_text(doc) -> bytes:
    text = json.dumps(doc, indent=1, allow_nan=True)
    return text.replace('"$HUGE_INT$"', _HUGE_INT_TEXT).encode()


def _mutate_native_value(doc, rng: random.Random) -> str:
    path, _ = rng.choice([p for p in _paths(doc) if p[0] and p[0][0] != "lenslab_scene"])
    parent = _parent(doc, path)
    action = rng.randrange(4)
    where = ".".join(map(str, path))
    if action == 0 and isinstance(parent, dict):
        del parent[path[-1]]
        return f"{where} deleted"
    if action == 1 and isinstance(parent, dict):
        parent[rng.choice(_WEIRD_STRINGS[:6])] = _weird_json_value(rng)
        return f"an unknown key beside {where}"
    value = _weird_json_value(rng)
    parent[path[-1]] = value
    return f"{where} = {json.dumps(value, allow_nan=True)[:60]}"


def _deep_nodes(doc, depth: int) -> bytes:
    """The scene with one chain of nodes ``depth`` deep, written as text (json.dumps itself recurses)."""
    leaf = '{"name": "leaf", "shape": {"type": "sphere", "radius": 0.1}, "material": "", "children": []}'
    chain = '{"name": "level", "children": [' * depth + leaf + "]}" * depth
    doc["nodes"] = "$NODES$"
    return _native_text(doc).replace(b'"$NODES$"', b"[" + chain.encode() + b"]")


def _extreme_number(doc, rng: random.Random) -> str:
    """A number where a number belongs, but at or past the edge of sense: zero, tiny, huge, negative."""
    numbers = [(path, value) for path, value in _paths(doc) if path and path[0] != "lenslab_scene"
               and isinstance(value, (int, float)) and not isinstance(value, bool)]
    path, value = rng.choice(numbers)
    new = rng.choice([0, -0.0, 1e-30, 1e-9, -1, -1e9, 1e9, 1e29, 1e31, 65536, 2**31, 0.5, value * 1e6,
                      value * -1, 16384, 16385])
    _parent(doc, path)[path[-1]] = new
    return f"{'.'.join(map(str, path))} = {new}"


_LONG_NAME = "n" * 300


def _broken_file_reference(doc, files: dict[str, bytes], rng: random.Random) -> str:
    """A file the scene names, broken: a name too long for the file system, a folder, a corrupt image."""
    kind = rng.randrange(6)
    if kind == 0:
        doc.setdefault("nodes", []).append({"name": "long", "shape": {"type": "mesh", "file": _LONG_NAME + ".obj"}})
        return "a mesh file name of 300 characters"
    if kind == 1:
        doc["environment"] = {"type": "map", "file": _LONG_NAME + ".exr"}
        return "an environment map name of 300 characters"
    if kind == 2:
        files["folder.obj/placeholder"] = b""
        doc.setdefault("nodes", []).append({"name": "dir", "shape": {"type": "mesh", "file": "folder.obj"}})
        return "a mesh file that is a folder"
    material = next(iter(doc.get("materials") or {}), None)
    image = (REPO / "scenes/product_shot/studio.exr").read_bytes()
    how, image = _corrupt_bytes(image, rng) if kind < 5 else ("whole", image)
    files["texture.exr"] = image
    if kind == 3 and material and doc["materials"][material].get("type") in ("diffuse", "plastic"):
        doc["materials"][material]["albedo_texture"] = {"type": "image", "file": "texture.exr"}
        return f"a texture {how}"
    doc["camera"]["aperture_image"] = "texture.exr" if kind != 5 else _LONG_NAME + ".png"
    return f"an aperture image {how}" if kind != 5 else "an aperture image name of 300 characters"


def native_case(rng: random.Random) -> Case:
    name = rng.choice(NATIVE_SCENES)
    files = _shipped_files(name)
    doc = json.loads(files["scene.json"])
    kind = rng.randrange(15)
    if kind == 12:
        what = _extreme_number(doc, rng)
        files["scene.json"] = _native_text(doc)
        return Case(f"{name}: {what}", files, "scene.json")
    if kind == 13:
        what = _broken_file_reference(doc, files, rng)
        files["scene.json"] = _native_text(doc)
        return Case(f"{name}: {what}", files, "scene.json")
    if kind == 14:
        return Case(f"{name}: a folder without a scene", {"notes.txt": b"hello"}, ".")
    if kind <= 5:
        what = " and ".join(_mutate_native_value(doc, rng) for _ in range(rng.randint(1, 2)))
        files["scene.json"] = _native_text(doc)
    elif kind == 6:
        what, files["scene.json"] = _corrupt_bytes(files["scene.json"], rng)
    elif kind == 7:
        depth = rng.choice((300, 5_000, 100_000))
        files["scene.json"] = b"[" * depth + b"]" * depth
        what = f"{depth} nested ["
    elif kind == 8:
        depth = rng.choice((250, 1_200, 3_000))
        files["scene.json"] = _deep_nodes(doc, depth)
        what = f"a node tree {depth} deep"
    elif kind == 9:
        what = _broken_mesh(doc, files, rng)
        files["scene.json"] = _native_text(doc)
    elif kind == 10:
        what = _broken_texture(doc, files, rng)
        files["scene.json"] = _native_text(doc)
    else:
        text = files["scene.json"].decode()
        numbers = list(re.finditer(r"-?\d+\.?\d*", text))
        if not numbers:
            return native_case(rng)
        number = rng.choice(numbers)
        replacement = rng.choice(["NaN", "Infinity", "-Infinity", _HUGE_INT_TEXT, "1e400", "-0", "9" * 5000,
                                  "1e-320", "3.4e38"])
        files["scene.json"] = (text[:number.start()] + replacement + text[number.end():]).encode()
        what = f"a number in the text replaced by {replacement[:20]}"
    return Case(f"{name}: {what}", files, "scene.json")


# Meshes: a small PLY or OBJ, broken in one of the ways exporters break them.
_PLY_HEADER = ("ply\nformat ascii 1.0\nelement vertex {v}\nproperty float x\nproperty float y\nproperty float z\n"
               "element face {f}\nproperty list uchar int vertex_indices\nend_header\n")


_TRIANGLE_PLY = _PLY_HEADER.format(v=3, f=1) + "0 0 0\n1 0 0\n0 1 0\n"
#: Meshes broken the ways exporters break them: (what, file name, contents).
_BROKEN_MESHES = [
    ("a PLY face past the vertex count", "m.ply", (_TRIANGLE_PLY + "3 0 1 99\n").encode()),
    ("a PLY with a negative face index", "m.ply", (_TRIANGLE_PLY + "3 0 -5 2\n").encode()),
    ("a PLY whose header claims more than it holds", "m.ply",
     (_PLY_HEADER.format(v=300, f=100) + "0 0 0\n1 0 0\n").encode()),
    ("a PLY with NaN vertices", "m.ply",
     (_PLY_HEADER.format(v=3, f=1) + "nan 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n").encode()),
    ("an OBJ face past the vertex count", "m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n"),
    ("an OBJ face with index 0", "m.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
    ("an OBJ with huge coordinates", "m.obj", b"v 3.4e38 0 0\nv -3.4e38 0 0\nv 0 1e300 0\nf 1 2 3\n"),
    ("an OBJ with an MTL whose Ke is NaN", "m.obj", b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glow\nf 1 2 3\n"),
    ("an empty OBJ", "m.obj", b"# nothing\n"),
    ("an OBJ with NaN normals and texture coordinates", "m.obj",
     b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 1\nvn 0 0 1\nvn 0 0 1\nvt inf 0\nvt 1 0\nvt 0 1\nf 1/1/1 2/2/2 3/3/3\n"),
]


def _broken_mesh(doc, files: dict[str, bytes], rng: random.Random) -> str:
    what, name, data = rng.choice(_BROKEN_MESHES)
    files[name] = data
    files["m.mtl"] = b"newmtl glow\nKd 0.5 0.5 0.5\nKe nan inf 1\nKs 1e999 0 0\nNs -5\n"
    doc.setdefault("nodes", []).append({"name": "broken mesh", "shape": {"type": "mesh", "file": name},
                                        "material": "", "children": []})
    return what


def _broken_texture(doc, files: dict[str, bytes], rng: random.Random) -> str:
    image = files.get("studio.exr") or (REPO / "scenes/product_shot/studio.exr").read_bytes()
    how, image = _corrupt_bytes(image, rng)
    files["studio.exr"] = image
    doc["environment"] = {"type": "map", "file": "studio.exr", "strength": 1.0}
    return f"an environment map {how}"


# ---------------------------------------------------------------------------------------------------------
# Mitsuba XML scenes
# ---------------------------------------------------------------------------------------------------------
def _mitsuba_sources() -> list[Path]:
    return sorted(p for folder in MITSUBA_SCENES for p in folder.glob("*.xml"))


_XML_VALUES = ["", "nan", "inf", "-inf", "-1", "0", "1e-320", "1e400", _HUGE_INT_TEXT, "abc", "1,2", "1 2 3 4 5",
               "$missing", "true", "\x1b[2J", "a" * 300, "0 0 0", "-0"]


def _mutate_xml_tree(root: ET.Element, rng: random.Random) -> str:
    elements = list(root.iter())
    element = rng.choice(elements)
    action = rng.randrange(7)
    if action <= 2 and element.attrib:
        key = rng.choice(sorted(element.attrib))
        if action == 0:
            del element.attrib[key]
            return f"<{element.tag}> without its {key}"
        element.attrib[key] = rng.choice(_XML_VALUES)
        return f"<{element.tag} {key}='{element.attrib[key][:20]}'>"
    if action == 3 and element is not root:
        parent = next(p for p in root.iter() if element in list(p))
        parent.remove(element)
        return f"<{element.tag}> removed"
    if action == 4:
        element.tag = rng.choice(["bogus", "shape", "float", "ref", "include", "default", "transform"])
        return f"an element renamed <{element.tag}>"
    if action == 5 and element is not root:
        parent = next(p for p in root.iter() if element in list(p))
        parent.append(copy.deepcopy(element))
        return f"<{element.tag}> duplicated"
    element.append(ET.Element(rng.choice(["float", "rgb", "integer", "point", "matrix", "string", "boolean"]),
                              {"name": rng.choice(["radius", "fov", "to_world", "reflectance", "value", "x"]),
                               "value": rng.choice(_XML_VALUES)}))
    return f"a property added to <{element.tag}>"


_XML_TRICKS = {
    "billion laughs": ('<?xml version="1.0"?>\n<!DOCTYPE s [<!ENTITY a "aaaaaaaaaa">'
                       '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">'
                       '<!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;"><!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;">'
                       '<!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;"><!ENTITY g "&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;">]>\n'
                       '<scene version="3.0.0"><string name="x" value="&g;"/></scene>\n'),
    "an external entity": ('<?xml version="1.0"?>\n<!DOCTYPE s [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n'
                           '<scene version="3.0.0"><string name="x" value="&x;"/></scene>\n'),
    "a bogus encoding": '<?xml version="1.0" encoding="bogus"?>\n<scene version="3.0.0"/>\n',
    "defaults that double": ('<scene version="3.0.0">' + '<default name="p0" value="ab"/>' +
                             "".join(f'<default name="p{i}" value="$p{i - 1}$p{i - 1}"/>' for i in range(1, 29)) +
                             '<integer name="x" value="$p28"/></scene>\n'),
    "an include of itself": '<scene version="3.0.0"><include filename="scene.xml"/></scene>\n',
    "shapes nested 1000 deep": ('<scene version="3.0.0">' + '<shape type="sphere">' * 1000 +
                                '</shape>' * 1000 + '</scene>\n'),
    "a property with no value": ('<scene version="3.0.0"><sensor type="perspective"><float name="fov"/>'
                                 '</sensor></scene>\n'),
    "ext_ior of 0": ('<scene version="3.0.0"><shape type="sphere"><bsdf type="dielectric">'
                     '<float name="ext_ior" value="0"/></bsdf></shape></scene>\n'),
    "alpha_u of -1": ('<scene version="3.0.0"><shape type="sphere"><bsdf type="roughconductor">'
                      '<float name="alpha_u" value="-1"/><float name="alpha_v" value="0.1"/></bsdf></shape>'
                      '</scene>\n'),
    "a huge translate": ('<scene version="3.0.0"><shape type="sphere"><transform name="to_world">'
                         '<translate x="3.4e38"/></transform></shape></scene>\n'),
    "a NaN matrix": ('<scene version="3.0.0"><shape type="cube"><transform name="to_world">'
                     '<matrix value="1 0 0 0 0 nan 0 0 0 0 1 0 0 0 0 1"/></transform></shape></scene>\n'),
    "a version 0 scene": '<scene version="0.0.1"><shape type="sphere"/></scene>\n',
    "not a scene": '<?xml version="1.0"?>\n<html><body/></html>\n',
}


def mitsuba_case(rng: random.Random) -> Case:
    if rng.random() < 0.15:
        trick = rng.choice(sorted(_XML_TRICKS))
        return Case(f"Mitsuba: {trick}", {"scene.xml": _XML_TRICKS[trick].encode()}, "scene.xml")
    source = rng.choice(_mitsuba_sources())
    files = {p.name: p.read_bytes() for p in source.parent.iterdir()
             if p.is_file() and p.suffix in (".exr", ".ply", ".obj", ".png")}
    data = source.read_bytes()
    if rng.random() < 0.25:
        how, data = _corrupt_bytes(data, rng)
        what = how
    else:
        root = ET.fromstring(data)
        what = " and ".join(_mutate_xml_tree(root, rng) for _ in range(rng.randint(1, 2)))
        data = ET.tostring(root)
    files["scene.xml"] = data
    return Case(f"{source.name}: {what}", files, "scene.xml")


# ---------------------------------------------------------------------------------------------------------
# Command-line values
# ---------------------------------------------------------------------------------------------------------
_CLI_VALUES = ["0", "-1", "nan", "inf", "1e400", _HUGE_INT_TEXT, "", "abc", "\x1b[2J", "1/0", "f/0", "0x10"]
_CLI_OPTIONS = ["--spp", "--width", "--f-number", "--f-stop", "--focal-length", "--focus-distance", "--seed",
                "--max-depth", "--time-limit", "--exposure", "--iso", "--shutter", "--circle-of-confusion", "--coc",
                "--aperture-blades", "--blades", "--anamorphic-squeeze", "--anamorphic", "--lens"]


def cli_case(rng: random.Random) -> Case:
    if rng.random() < 0.3:
        source = rng.choice(_mitsuba_sources())
        value = rng.choice(_XML_VALUES + ["$x", "$$", "\\$"])
        files = {p.name: p.read_bytes() for p in source.parent.iterdir() if p.suffix in (".exr", ".ply", ".obj")}
        return Case(f"{source.name}: -D {value[:20]!r}", {**files, "scene.xml": source.read_bytes()}, "scene.xml",
                    ["-D", f"{rng.choice(['spp', 'res', 'x', ''])}={value}"])
    files = _shipped_files("cornell_box")
    option, value = rng.choice(_CLI_OPTIONS), rng.choice(_CLI_VALUES)
    return Case(f"cornell_box: {option} {value[:20]!r}", files, "scene.json", [option, value])


# ---------------------------------------------------------------------------------------------------------
# Batch files: one shot, one value of the wrong kind (TOML's dates and times too) or an output pattern that
# makes no file name; read with --dry-run (the checks all happen before anything renders)
# ---------------------------------------------------------------------------------------------------------
_TOML_VALUES = ["1979-05-27", "07:32:00", "1979-05-27T07:32:00Z", "1979-05-27 07:32:00.5", "[1979-05-27, 2]",
                "{from = 1979-05-27, to = 2, steps = 2}", "{from = 1, to = 07:32:00, steps = 2}",
                "{from = 1, to = 2, steps = 1979-05-27}", "nan", "inf", "-inf", "1e400", _HUGE_INT_TEXT, '"abc"',
                "true", "[]", "{}", '"f/0"', '"1/0"', "0", "-1", "[nan, 1]", '"\\u001b[2J"', '"\\u202e"',
                "{x = 1979-05-27}", "[[1, 2]]", "0x10", "1_000"]
_BATCH_KEYS = ["spp", "f_number", "width", "shutter", "name", "scene", "split", "defines", "iso", "focus_distance",
               "exposure", "seed", "lens", "tone_map", "time_limit", "aperture_image", "focal_length", "nonsense"]
_OUTPUT_PATTERNS = ["{index:c}.png", "x{index:c}.png", "{name}/{index}.png", "{index:>300}.png", "{index[0]}.png",
                    "\\u202e{index}.png", "{spp:c}.png", "{scene}/../{index}.png", "{index:c}{index:c}.exr",
                    "{f_number:c}.png", "{index:d}/{index:c}.png", "{lens}.png", "{missing}.png", "{}.png"]


def batch_case(rng: random.Random) -> Case:
    lines = ['[[shots]]', 'scene = "cornell_box"', 'output = "out/{index}.png"']
    if rng.random() < 0.35:
        pattern = rng.choice(_OUTPUT_PATTERNS)
        lines[2] = f'output = "{pattern}"'
        lines += ['spp = [1, 2, 47, 3]', f'name = "{rng.choice(["..", ".", "a/b", "ok"])}"',
                  f'lens = "{rng.choice(["..", "85 mm f/1.4", "/"])}"']
        what = f"output = {pattern!r}"
    else:
        key, value = rng.choice(_BATCH_KEYS), rng.choice(_TOML_VALUES)
        lines.append(f"{key} = {value}")
        what = f"{key} = {value[:30]}"
    if rng.random() < 0.2:  # the same value in [defaults]
        lines = ["[defaults]", lines[-1], *lines[:-1]]
        what += " in [defaults]"
    return Case(f"batch: {what}", {"shots.toml": ("\n".join(lines) + "\n").encode()}, "shots.toml", command="batch")


# ---------------------------------------------------------------------------------------------------------
# Mitsuba .serialized meshes: two to a file, cut short, their zlib streams ended early, bytes flipped
# ---------------------------------------------------------------------------------------------------------
def _serialized_mesh(vertices, faces, body_cut: int | None = None, claim: tuple[int, int] | None = None) -> bytes:
    """One mesh as Mitsuba writes it (version 4, float32, no normals): its header, then a zlib stream. ``body_cut``
    ends the (complete, well-formed) stream early; ``claim`` puts other counts in it."""
    counts = claim or (len(vertices), len(faces))
    body = struct.pack("<I", 0x1000) + b"mesh\0" + struct.pack("<QQ", *counts)
    body += b"".join(bytes(struct.pack("<fff", *v)) for v in vertices)
    body += b"".join(bytes(struct.pack("<III", *f)) for f in faces)
    return struct.pack("<HH", 0x041C, 4) + zlib.compress(body[:body_cut] if body_cut is not None else body)


_TETRA = ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
_SQUARE = ([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2), (0, 2, 3)])


def _serialized_file(first: bytes, second: bytes) -> bytes:
    return first + second + struct.pack("<QQI", 0, len(first), 2)


_SERIALIZED_SCENE = ('<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="40"/>'
                     '<transform name="to_world"><lookat origin="0 0 5" target="0 0 0" up="0 1 0"/></transform>'
                     '</sensor><emitter type="constant"/>'
                     '<shape type="serialized"><string name="filename" value="m.serialized"/>'
                     '<integer name="shape_index" value="0"/></shape>'
                     '<shape type="serialized"><string name="filename" value="m.serialized"/>'
                     '<integer name="shape_index" value="1"/></shape></scene>\n')


def serialized_case(rng: random.Random) -> Case:
    kind = rng.randrange(5)
    whole = _serialized_file(_serialized_mesh(*_TETRA), _serialized_mesh(*_SQUARE))
    if kind == 0:  # a complete zlib stream that holds less than its counts: the next mesh's bytes follow it
        cut = rng.randrange(4, 120)
        data, what = _serialized_file(_serialized_mesh(*_TETRA, body_cut=cut), _serialized_mesh(*_SQUARE)), \
            f"mesh 0's stream ended after {cut} bytes"
    elif kind == 1:
        data = whole[:rng.randrange(len(whole))]
        what = f"the file cut at byte {len(data)}"
    elif kind == 2:
        claim = (rng.choice([4, 5, 1000, 2**31]), rng.choice([4, 5, 1000, 2**40]))
        data, what = _serialized_file(_serialized_mesh(*_TETRA, claim=claim), _serialized_mesh(*_SQUARE)), \
            f"mesh 0 claims {claim[0]} vertices and {claim[1]} triangles"
    else:
        how, data = _corrupt_bytes(whole, rng)
        what = f"the file {how}"
    return Case(f"serialized: {what}", {"scene.xml": _SERIALIZED_SCENE.encode(), "m.serialized": data}, "scene.xml")


# ---------------------------------------------------------------------------------------------------------
# glTF: a textured quad whose material, texture, image, sampler or buffer fields hold the wrong type
# ---------------------------------------------------------------------------------------------------------
def _gltf_quad() -> dict:
    import base64

    positions = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    uvs = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
    indices = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    blob = positions + uvs + indices
    return {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0],
                       "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                        {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "materials": [{"name": "Paint", "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.2, 0.2, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.5,
            "baseColorTexture": {"index": 0}}, "emissiveFactor": [0.0, 0.0, 0.0],
            "extensions": {"KHR_materials_ior": {"ior": 1.5},
                           "KHR_materials_emissive_strength": {"emissiveStrength": 1.0}}}],
        "textures": [{"source": 0, "sampler": 0}], "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": "label.png"}],
    }


_GLTF_PARTS = ("materials", "textures", "images", "samplers", "bufferViews", "buffers")


def gltf_case(rng: random.Random) -> Case:
    header = _gltf_quad()
    if rng.random() < 0.2:
        part = rng.choice(_GLTF_PARTS)
        header[part] = _weird_json_value(rng)
        what = f"{part} = {json.dumps(header[part], allow_nan=True)[:40]}"
    else:
        path, _ = rng.choice([p for p in _paths({k: header[k] for k in _GLTF_PARTS}) if p[0]])
        parent = _parent(header, path)
        parent[path[-1]] = _weird_json_value(rng)
        what = f"{'.'.join(map(str, path))} = {json.dumps(parent[path[-1]], allow_nan=True)[:40]}"
    files = _shipped_files("cornell_box")
    doc = json.loads(files["scene.json"])
    doc["nodes"].append({"name": "quad", "shape": {"type": "mesh", "file": "quad.gltf"}, "children": []})
    files["scene.json"] = _native_text(doc)
    files["quad.gltf"] = _native_text(header)
    files["label.png"] = (REPO / "app/lenslab/validate/scenes/label.png").read_bytes()
    return Case(f"glTF: {what}", files, "scene.json")


# ---------------------------------------------------------------------------------------------------------
# Named pipes (FIFOs) where a file is read or written: refused at once, never waited on
# ---------------------------------------------------------------------------------------------------------
def fifo_case(rng: random.Random) -> Case:
    files = _shipped_files("cornell_box")
    doc = json.loads(files["scene.json"])
    material = next(iter(doc["materials"]))
    kind = rng.randrange(12)
    if kind == 0:
        doc["materials"][material]["albedo_texture"] = {"type": "image", "file": "pipe.png"}
        what = "an image texture"
    elif kind == 1:
        doc["camera"]["aperture_image"] = "pipe.png"
        what = "an aperture image"
    elif kind == 2:
        doc["environment"] = {"type": "map", "file": "pipe.png", "strength": 1.0}
        what = "an environment map"
    elif kind in (3, 4, 5):
        name = ["pipe.obj", "pipe.ply", "pipe.gltf"][kind - 3]
        doc["nodes"].append({"name": "pipe", "shape": {"type": "mesh", "file": name}, "children": []})
        return Case(f"FIFO: a mesh file {name}", {**files, "scene.json": _native_text(doc)}, "scene.json",
                    fifos=[name])
    elif kind == 6:  # a glTF whose buffer, then whose image, is a named pipe
        header = _gltf_quad()
        if rng.random() < 0.5:
            header["buffers"][0]["uri"] = "pipe.png"
            what = "a glTF buffer"
        else:
            what = "a glTF image"
        header["images"][0]["uri"] = "pipe.png"
        files["quad.gltf"] = _native_text(header)
        doc["nodes"].append({"name": "quad", "shape": {"type": "mesh", "file": "quad.gltf"}, "children": []})
    elif kind == 7:  # an OBJ whose material library, or its map_Kd, is a named pipe
        library = rng.choice(["pipe.mtl", "m.mtl"])
        files["m.obj"] = (f"mtllib {library}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\n"
                          "f 1/1 2/2 3/3\n").encode()
        files["m.mtl"] = b"newmtl a\nKd 1 1 1\nmap_Kd pipe.png\n"
        doc["nodes"].append({"name": "obj", "shape": {"type": "mesh", "file": "m.obj"}, "children": []})
        files["scene.json"] = _native_text(doc)
        return Case(f"FIFO: an OBJ's {'library' if library == 'pipe.mtl' else 'map_Kd'}", files, "scene.json",
                    fifos=["pipe.mtl", "pipe.png"])
    elif kind == 8:
        return Case("FIFO: the scene file", {}, "scene.json", fifos=["scene.json"])
    elif kind == 9:
        return Case("FIFO: the output (-o)", files, "scene.json", fifos=["out.png"])
    elif kind == 10:
        xml = _SERIALIZED_SCENE.replace('value="m.serialized"', 'value="pipe.serialized"', 1)
        return Case("FIFO: a Mitsuba .serialized mesh", {"scene.xml": xml.encode(),
                                                         "m.serialized": _serialized_file(_serialized_mesh(*_TETRA),
                                                                                          _serialized_mesh(*_SQUARE))},
                    "scene.xml", fifos=["pipe.serialized"])
    else:
        return Case("FIFO: the batch file", {}, "shots.toml", fifos=["shots.toml"], command="batch")
    files["scene.json"] = _native_text(doc)
    return Case(f"FIFO: {what}", files, "scene.json", fifos=["pipe.png"])


def generate(count: int, seed: int) -> list[Case]:
    rng = random.Random(seed)
    makers = [native_case] * 5 + [mitsuba_case] * 4 + [cli_case, batch_case, serialized_case, gltf_case, fifo_case]
    return [rng.choice(makers)(rng) for _ in range(count)]


# ---------------------------------------------------------------------------------------------------------
# Running a case and judging what came out
# ---------------------------------------------------------------------------------------------------------
@contextlib.contextmanager
def fifo_read_as_empty(path: Path):
    """A named pipe made at ``path`` for a test of a reader that must refuse it: should the reader open it anyway,
    a writer (a thread, waiting for it) opens the other end and closes it at once, so that the reader's first
    open and read end with an empty file rather than wait for ever. The test then fails on what it was told,
    instead of hanging. Yields ``path``."""
    import threading

    os.mkfifo(path)

    def answer() -> None:
        os.close(os.open(path, os.O_WRONLY))  # returns once a reader has the pipe open

    writer = threading.Thread(target=answer, name="fifo-answer", daemon=True)
    writer.start()
    try:
        yield path
    finally:
        reader = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # lets a writer still waiting go
        writer.join()
        os.close(reader)


def write_case(case: Case, folder: Path) -> Path:
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    for name, data in case.files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)
    for name in case.fifos:
        os.mkfifo(folder / name)
    return folder / case.scene


def _arguments(case: Case, scene: Path, output: Path) -> list[str]:
    if case.command == "batch":
        return ["batch", str(scene), "--dry-run"]
    args = [str(scene), "--headless", "-o", str(output), *RENDER_ARGS]
    if case.extra_args:  # the case's own value of an option wins over the default one
        option = case.extra_args[0]
        if option in args:
            index = args.index(option)
            del args[index:index + 2]
        args += case.extra_args
    return args


class _Hung(BaseException):
    pass


_case_running = False  # SIGALRM from the watcher stops a case only while one runs


def _raise_hung(signum, frame):
    if _case_running:
        raise _Hung()


# The watcher: a small process beside this one, for the whole run, that judges each case by the work it does.
# A thread cannot: a library blocked in C with the GIL held (OpenImageIO opening a named pipe) stops every
# thread of the process. The watcher reads this process's CPU time from /proc; when a case spends more than
# CASE_CPU_SECONDS, or none at STALLED_CHECKS checks in a row, it sends SIGALRM (a blocking call returns, and
# _raise_hung stops the case) and opens the case's named pipes at the other end, so that a read or a write
# waiting on one ends. Told "start<TAB>fifo<TAB>..." and "end" on its stdin; answers "end" with the verdict,
# if any, then "ok".
_WATCHER = r"""
import os, select, signal, sys
parent, check, stalled, budget = int(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
tick = os.sysconf("SC_CLK_TCK")
def cpu():
    try:
        with open(f"/proc/{parent}/stat") as stat:
            fields = stat.read().rpartition(")")[2].split()
        return (int(fields[11]) + int(fields[12])) / tick
    except (OSError, ValueError, IndexError):
        return None
def release(paths):
    for path in paths:
        for flags in (os.O_WRONLY, os.O_RDONLY):
            try:
                os.close(os.open(path, flags | os.O_NONBLOCK))
            except OSError:
                pass
active, fifos, first, last, still, verdict, pending = False, [], 0.0, None, 0, "", b""
while True:
    if select.select([0], [], [], check)[0]:
        data = os.read(0, 65536)
        if not data:
            break
        pending += data
        while b"\n" in pending:
            line, pending = pending.split(b"\n", 1)
            words = line.decode().split("\t")
            if words[0] == "start":
                active, fifos, still, verdict = True, words[1:], 0, ""
                first = last = cpu()
            elif words[0] == "end":
                active = False
                os.write(1, (verdict + "\n" if verdict else "").encode() + b"ok\n")
        continue
    now = cpu() if active else None
    if now is None or first is None:
        continue
    still = still + 1 if now == last else 0
    last = now
    if now - first > budget:
        verdict = verdict or f"spent over {budget:g} s of CPU without ending (a loop without end?)"
    elif still >= stalled:
        verdict = verdict or f"did no work at {stalled} checks in a row (blocked on a read or a write?)"
    if verdict:
        os.kill(parent, signal.SIGALRM)
        release(fifos)
"""
_watcher_process: subprocess.Popen | None = None
_previous_handler = None  # SIGALRM's handler before the watcher started, put back by close_watcher


def _watcher() -> subprocess.Popen:
    """The watcher of this process, started on first use (with this process's SIGALRM handler)."""
    global _watcher_process, _previous_handler
    if _watcher_process is None or _watcher_process.poll() is not None:
        previous = signal.signal(signal.SIGALRM, _raise_hung)  # stays until close_watcher: idle between cases
        if _watcher_process is None:
            _previous_handler = previous
        _watcher_process = subprocess.Popen(
            [sys.executable, "-c", _WATCHER, str(os.getpid()), str(CHECK_SECONDS), str(STALLED_CHECKS),
             str(CASE_CPU_SECONDS)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    return _watcher_process


def close_watcher() -> None:
    """End the watcher (it also ends by itself when this process does) and put SIGALRM's handler back."""
    global _watcher_process
    if _watcher_process is not None:
        _watcher_process.stdin.close()
        _watcher_process.wait()  # it has answered every "end": no SIGALRM of its is on the way
        _watcher_process.stdout.close()
        _watcher_process = None
        signal.signal(signal.SIGALRM, _previous_handler or signal.SIG_DFL)


@contextlib.contextmanager
def _watched(fifos: list[Path]):
    """Run the block as one case under the watcher; yields a list that holds its verdict afterwards, if any."""
    global _case_running
    watcher = _watcher()
    verdict: list[str] = []
    watcher.stdin.write(("\t".join(["start", *map(str, fifos)]) + "\n").encode())
    watcher.stdin.flush()
    _case_running = True
    try:
        yield verdict
    finally:
        watcher.stdin.write(b"end\n")
        watcher.stdin.flush()
        while True:  # until the watcher has stopped watching: no SIGALRM comes after its "ok"
            try:
                line = watcher.stdout.readline().decode().strip()
            except _Hung:  # the watcher's last word crossed the case's end
                continue
            if line == "ok" or not line and watcher.poll() is not None:
                break
            verdict.append(line)
        _case_running = False


@contextlib.contextmanager
def _c_level_stderr(into: io.StringIO):
    """What libraries print from C or C++ onto file descriptor 2 (OpenImageIO, Mesa), added to ``into``:
    a user sees it as they see Python's own lines."""
    import tempfile

    from lenslab.image_files import c_stderr_into

    with tempfile.TemporaryFile() as capture:
        try:
            with c_stderr_into(capture):
                yield
        finally:
            capture.seek(0)
            into.write(capture.read().decode("utf-8", "replace"))


def run_in_process(case: Case, folder: Path) -> Outcome:
    """Run ``lenslab.cli.main`` on the case in this process, its stderr captured; an exception that escapes
    is a traceback the user would have seen."""
    from lenslab.cli import main

    scene = write_case(case, folder)
    output = folder / "out.png"
    stderr = io.StringIO()
    start = time.perf_counter()
    verdict: list[str] = []
    try:
        with _watched([folder / name for name in case.fifos]) as verdict, contextlib.redirect_stderr(stderr), \
                contextlib.redirect_stdout(io.StringIO()), _c_level_stderr(stderr):
            status = main(_arguments(case, scene, output))
    except _Hung:
        return Outcome(case, None, stderr.getvalue(), time.perf_counter() - start,
                       f"hung: {'; '.join(verdict) or 'stopped by the watcher'}")
    except BaseException as exc:  # noqa: BLE001 - anything escaping main is a traceback for the user
        import traceback

        return Outcome(case, None, stderr.getvalue() + "".join(traceback.format_exception(exc)[-6:]),
                       time.perf_counter() - start,
                       f"traceback: {type(exc).__name__}: {str(exc)[:200]}")
    if verdict:  # it ended as the watcher stopped it
        return Outcome(case, None, stderr.getvalue(), time.perf_counter() - start, f"hung: {'; '.join(verdict)}")
    return judge(Outcome(case, status, stderr.getvalue(), time.perf_counter() - start), output)


def _cpu_seconds(pid: int) -> float | None:
    """CPU time (user + system) of process ``pid`` so far, from /proc; None where it cannot be read."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def run_in_subprocess(case: Case, folder: Path) -> Outcome:
    """The case as a user runs it, in a process of its own: stopped when it spends more than CASE_CPU_SECONDS of
    CPU or none at STALLED_CHECKS checks in a row (read from /proc), or, as a backstop, after BACKSTOP_SECONDS."""
    import tempfile

    scene = write_case(case, folder)
    output = folder / "out.png"
    start = time.perf_counter()
    with tempfile.TemporaryFile() as err:
        process = subprocess.Popen([sys.executable, "-m", "lenslab", *_arguments(case, scene, output)],
                                   stdout=subprocess.DEVNULL, stderr=err,
                                   env={**os.environ, "PYTHONPATH": str(REPO / "app")})
        verdict, last, still = "", None, 0
        while True:
            try:
                process.wait(CHECK_SECONDS)
                break
            except subprocess.TimeoutExpired:
                pass
            cpu = _cpu_seconds(process.pid)
            still = still + 1 if cpu is not None and cpu == last else 0
            last = cpu
            if cpu is not None and cpu > CASE_CPU_SECONDS:
                verdict = f"spent over {CASE_CPU_SECONDS} s of CPU without ending (a loop without end?)"
            elif still >= STALLED_CHECKS:
                verdict = f"did no work at {STALLED_CHECKS} checks in a row (blocked on a read?)"
            elif time.perf_counter() - start > BACKSTOP_SECONDS:
                verdict = f"still running after {BACKSTOP_SECONDS} s"
            if verdict:
                process.kill()
                process.wait()
                break
        err.seek(0)
        stderr = err.read().decode("utf-8", "replace")
    if verdict:
        return Outcome(case, None, stderr, time.perf_counter() - start, f"hung: {verdict}")
    return judge(Outcome(case, process.returncode, stderr, time.perf_counter() - start), output)


def judge(outcome: Outcome, output: Path) -> Outcome:
    """Fill in ``outcome.problem``: what about the run broke the contract, if anything."""
    lines = outcome.stderr.splitlines()
    case = outcome.case
    error_prefix = "lenslab batch: error: " if case.command == "batch" else "lenslab: error: "
    output_fifo = "out.png" in case.fifos
    if "Traceback (most recent call last)" in outcome.stderr:
        outcome.problem = "a traceback on stderr"
    elif any(_CONTROL.search(line) for line in lines):
        outcome.problem = "a control character on stderr"
    elif any(len(line) > MAX_ERROR_LINE for line in lines):  # the whole line, prefix included
        outcome.problem = f"a line over {MAX_ERROR_LINE} characters"
    elif output_fifo and not _is_fifo(output):
        outcome.problem = "the named pipe given as -o was replaced"
    elif outcome.status == 0 and case.command == "batch":
        outcome.problem = ""  # a dry run: every check passed, nothing to look at
    elif outcome.status == 0:
        outcome.problem = ("exit 0 with a named pipe as -o" if output_fifo else
                           _judge_image(output, expect_size=not outcome.case.extra_args))
    else:
        errors = [line for line in lines if line.startswith(error_prefix)]
        others = [line for line in lines if not line.startswith((error_prefix, "lenslab: warning: "))]
        if len(errors) != 1 or others:
            outcome.problem = f"{len(errors)} error lines and {len(others)} other lines"
        elif "internal error" in errors[0]:
            outcome.problem = "an internal error (a case a reader missed)"
        elif not _names_a_file(errors[0], outcome.case, output.parent):
            outcome.problem = "the error names no file"
        elif errors[0].count(f"{output.parent / outcome.case.scene}: ") > 1:
            outcome.problem = "the scene file is named twice"
        elif output.exists() and not output_fifo:
            outcome.problem = "an image was written although the render failed"
    return outcome


def _is_fifo(path: Path) -> bool:
    try:
        return stat.S_ISFIFO(os.lstat(path).st_mode)
    except OSError:
        return False


def _names_a_file(line: str, case: Case, folder: Path) -> bool:
    """The line names the scene, a file of the case (perhaps one too long to show whole), or for a value
    given on the command line, its option."""
    if case.extra_args and (case.extra_args[0] in line or "argument" in line):
        return True
    return any(name in line for name in case.files) or str(folder) in line


def _judge_image(output: Path, expect_size: bool) -> str:
    import numpy as np

    from lenslab.render.film import read_image

    if not output.is_file():
        return "exit 0 without an image"
    pixels, _ = read_image(output)
    if expect_size and pixels.shape[:2] != (8, 8):
        return f"an image of {pixels.shape[1]} x {pixels.shape[0]}, not 8 x 8"
    if not np.all(np.isfinite(pixels)):
        return "an image with non-finite pixels"
    return ""


def main(argv: list[str] | None = None) -> int:
    import argparse
    import tempfile

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=300)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--subprocess", action="store_true", help="one process per case, as a user runs it")
    parser.add_argument("--show", action="store_true", help="print every case, not only the failures")
    parser.add_argument("--only", type=int, help="run just this case of the sequence, and print all of its stderr")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(REPO / "app"))
    run = run_in_subprocess if args.subprocess else run_in_process
    failures, slowest = 0, []
    with tempfile.TemporaryDirectory() as tmp:
        for index, case in enumerate(generate(args.cases, args.seed)):
            if args.only is not None and index != args.only:
                continue
            outcome = run(case, Path(tmp) / "case")
            slowest.append((outcome.seconds, case.what))
            if args.only is not None:
                print(outcome.stderr)
            if outcome.problem or args.show:
                failures += bool(outcome.problem)
                last = outcome.stderr.strip().splitlines()[-1:] or [""]
                print(f"[{index}] {case.what[:120]!r}: {outcome.problem or 'ok'} (exit {outcome.status}, "
                      f"{outcome.seconds:.1f} s)\n      {last[0][:300]!r}", flush=True)
    close_watcher()
    slowest.sort(reverse=True)
    print(f"{args.cases} cases, {failures} broke the contract; slowest: "
          + "; ".join(f"{s:.1f} s {w[:60]!r}" for s, w in slowest[:3]))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
