"""LensLab's native scene format: JSON, versioned, documented in docs/scene-format.md.

Reading is strict: an unknown key, a value of the wrong type, a value out of range or a mesh file that does not
exist is a :class:`SceneError` whose one-line message names the file and the key path
(``scene.json: camera.f_number: 0.2 is out of range [0.5, 128]``). Saving writes every value, defaults
included, so a saved file says exactly what was rendered; ``load(save(scene)) == scene``.

The reader and writer are generic over the scene's dataclasses: each field's type annotation says what JSON
value it takes and its ``metadata`` carries the range, choices and whether it is required.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import types
import typing
from pathlib import Path
from typing import Any

from lenslab.atomic import atomic_path
from lenslab.image_files import not_found, read_file_bytes
from lenslab.limits import LARGEST_NUMBER
from lenslab.scene.fields import text_problem
from lenslab.scene.materials import MATERIAL_TYPES, Material
from lenslab.scene.light_units import check_environment_map
from lenslab.scene.scene import ENVIRONMENT_TYPES, Environment, EnvironmentMap, Node, Scene, SceneError
from lenslab.scene.shapes import SHAPE_TYPES, MeshFile, Shape
from lenslab.scene.textures import TEXTURE_TYPES, Texture
from lenslab.scene.lights import LIGHT_TYPES, Light

FORMAT_KEY = "lenslab_scene"
FORMAT_VERSION = 4
#: 2, 3 and 4 differ only by what each added (docs/scene-format.md, "Versions"): an older file reads unchanged.
READABLE_VERSIONS = (1, 2, 3, FORMAT_VERSION)
#: Version 1 files measured the focus distance from the lens, kept the sensor one focal length behind it and
#: spanned the image across the sensor's width; version 2's defaults are the photographer's (docs/scene-format.md,
#: "Versions"). A version 1 file is read with its old meaning, so it renders exactly as it always did.
_VERSION_1_CAMERA = {"focus_from": "lens", "focus_breathing": False, "sensor_fit": "horizontal"}
SCENE_SUFFIX = ".json"
#: How deep nodes may nest. Assemblies from CAD and DCC tools nest a few dozen levels at most; the reader,
#: the flattener and the studio's tree walk nodes recursively, so a deeper tree is refused when it is read.
MAX_NODE_DEPTH = 100

# Polymorphic fields: the JSON object's "type" key picks the dataclass.
_TAGGED = {Shape: SHAPE_TYPES, Material: MATERIAL_TYPES, Environment: ENVIRONMENT_TYPES, Texture: TEXTURE_TYPES, Light: LIGHT_TYPES}


class _Invalid(Exception):
    """Raised inside the reader with a key path; turned into a SceneError naming the file."""

    def __init__(self, path: str, message: str):
        super().__init__(f"{path}: {message}" if path else message)


def _join(path: str, key: str | int) -> str:
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


def _type_hints(cls) -> dict[str, Any]:
    return typing.get_type_hints(cls)


def _describe(value: Any) -> str:
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        return f"a {len(str(abs(value)))}-digit number"
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


# ---------------------------------------------------------------------------------------------------------
# Reading
# ---------------------------------------------------------------------------------------------------------
def _read_number(value: Any, kind: type, path: str, meta: dict) -> float | int:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _Invalid(path, f"expected a number, got {_describe(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        raise _Invalid(path, f"{value} is not a finite number")
    if abs(value) > LARGEST_NUMBER:  # exact for integers of any length: no conversion to float can overflow
        raise _Invalid(path, f"{_describe(value)} is too large (the most any value may be is {LARGEST_NUMBER:g})")
    if kind is int and not float(value).is_integer():
        raise _Invalid(path, f"expected a whole number, got {_describe(value)}")
    if "range" in meta:
        lo, hi = meta["range"]
        if not lo <= value <= hi:
            raise _Invalid(path, f"{_describe(value)} is out of range [{lo:g}, {hi:g}]")
    if meta.get("nonzero") and value == 0:
        raise _Invalid(path, "must not be zero")
    if "zero_or_at_least" in meta and 0 < abs(value) < meta["zero_or_at_least"]:  # a sun too small to be a disk
        raise _Invalid(path, f"{_describe(value)} is too small: give 0 or at least {meta['zero_or_at_least']:g}")
    return int(value) if kind is int else float(value)


def _read_value(value: Any, annotation: Any, path: str, meta: dict) -> Any:
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        (annotation,) = [a for a in args if a is not type(None)]
        return _read_value(value, annotation, path, meta)
    if annotation in (int, float):
        return _read_number(value, annotation, path, meta)
    if annotation is bool:
        if not isinstance(value, bool):
            raise _Invalid(path, f"expected true or false, got {_describe(value)}")
        return value
    if annotation is str:
        if not isinstance(value, str):
            raise _Invalid(path, f"expected a string, got {_describe(value)}")
        problem = text_problem(meta, value)
        if problem:
            raise _Invalid(path, problem)
        return value
    if origin is tuple:
        if not isinstance(value, list) or len(value) != len(args):
            raise _Invalid(path, f"expected a list of {len(args)} numbers, got {_describe(value)}")
        result = tuple(_read_value(v, a, _join(path, i), meta) for i, (v, a) in enumerate(zip(value, args)))
        if meta.get("nonzero_vector") and not any(result):
            raise _Invalid(path, "must not be the zero vector")
        return result
    if origin is list:
        if not isinstance(value, list):
            raise _Invalid(path, f"expected a list, got {_describe(value)}")
        return [_read_value(v, args[0], _join(path, i), meta) for i, v in enumerate(value)]
    if origin is dict:
        if not isinstance(value, dict):
            raise _Invalid(path, f"expected an object, got {_describe(value)}")
        return {k: _read_value(v, args[1], _join(path, k), meta) for k, v in value.items()}
    if isinstance(annotation, type) and annotation in _TAGGED:
        return _read_tagged(value, _TAGGED[annotation], path)
    if dataclasses.is_dataclass(annotation):
        return _read_dataclass(value, annotation, path)
    if annotation is typing.Any or annotation is object:
        return value
    raise TypeError(f"no reader for {annotation!r}")  # a programming error, not a user's


def _read_tagged(value: Any, registry: dict[str, type], path: str) -> Any:
    if not isinstance(value, dict):
        raise _Invalid(path, f"expected an object, got {_describe(value)}")
    kind = value.get("type")
    if not isinstance(kind, str) or kind not in registry:
        raise _Invalid(_join(path, "type"), f"unknown type {_describe(kind)}; expected one of {', '.join(registry)}")
    return _read_dataclass({k: v for k, v in value.items() if k != "type"}, registry[kind], path)


def _read_dataclass(value: Any, cls: type, path: str) -> Any:
    if not isinstance(value, dict):
        raise _Invalid(path, f"expected an object, got {_describe(value)}")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init and f.name != "source_path"}
    hints = _type_hints(cls)
    for key in value:
        if key not in fields:
            raise _Invalid(_join(path, key), f"unknown key (expected one of {', '.join(fields)})")
    kwargs = {}
    for name, f in fields.items():
        if name in value:
            kwargs[name] = _read_value(value[name], hints[name], _join(path, name), dict(f.metadata))
        elif f.metadata.get("required"):
            raise _Invalid(_join(path, name), "missing required key")
    return cls(**kwargs)


def _check_references(scene: Scene) -> None:
    """Cross-field checks the types alone cannot express."""
    from lenslab.optics.real_lenses import names_a_file

    real_lens = scene.camera.real_lens
    if real_lens and names_a_file(real_lens) and not Path(real_lens).expanduser().is_absolute():
        # A lens file is named relative to the scene, as meshes and textures are.
        scene.camera.real_lens = str(scene.base_dir() / real_lens)
    try:
        scene.camera.validate()
    except ValueError as exc:
        raise _Invalid("camera", str(exc)) from None
    if isinstance(scene.environment, EnvironmentMap):
        try:  # the range holds a negative EV; a negative scale or mean luminance is named while the scene opens
            check_environment_map(scene.environment)
        except ValueError as exc:
            raise _Invalid("environment.strength", str(exc)) from None
    if scene.camera.aperture_image:
        try:  # read now, so that a missing or black image is named while the scene opens
            scene.camera.aperture(scene.base_dir())
        except ValueError as exc:
            raise _Invalid("camera.aperture_image", str(exc)) from None

    def visit(nodes: list[Node], path: str) -> None:
        for i, node in enumerate(nodes):
            node_path = _join(path, i)
            if node.material and node.material not in scene.materials:
                raise _Invalid(_join(node_path, "material"), f"unknown material '{node.material}'")
            if isinstance(node.shape, MeshFile):
                mesh_path = Path(node.shape.file)
                if not mesh_path.is_absolute():
                    mesh_path = scene.base_dir() / mesh_path
                if not os.path.isfile(mesh_path):
                    raise _Invalid(_join(_join(node_path, "shape"), "file"), not_found("mesh file", mesh_path))
            visit(node.children, _join(node_path, "children"))

    visit(scene.nodes, "nodes")


def _check_node_depth(nodes: Any) -> None:
    """Refuse a node tree deeper than MAX_NODE_DEPTH before anything recurses into it."""
    level, depth = nodes if isinstance(nodes, list) else [], 0
    while level:
        depth += 1
        if depth > MAX_NODE_DEPTH:
            raise _Invalid("nodes", f"nested more than {MAX_NODE_DEPTH} deep (the format's limit)")
        level = [child for node in level if isinstance(node, dict) and isinstance(node.get("children"), list)
                 for child in node["children"]]


def scene_from_dict(data: Any, source_path: Path | None = None) -> Scene:
    """Build a Scene from parsed JSON; raises _Invalid with the key path."""
    if not isinstance(data, dict):
        raise _Invalid("", "the file does not hold a JSON object")
    version = data.get(FORMAT_KEY)
    if version is None:
        raise _Invalid(FORMAT_KEY, "missing: this is not a LensLab scene")
    if version not in READABLE_VERSIONS or isinstance(version, bool):
        raise _Invalid(FORMAT_KEY, f"version {_describe(version)} is not supported (this LensLab reads "
                                   f"{', '.join(map(str, READABLE_VERSIONS[:-1]))} and {FORMAT_VERSION})")
    data = {k: v for k, v in data.items() if k != FORMAT_KEY}
    _check_node_depth(data.get("nodes"))
    if version == 1:
        camera = data.get("camera", {})
        if isinstance(camera, dict):
            for key in camera.keys() & _VERSION_1_CAMERA.keys():
                raise _Invalid(_join("camera", key), f"unknown key in a version 1 scene (write "
                                                     f'"{FORMAT_KEY}": {FORMAT_VERSION} to use it)')
            data["camera"] = {**_VERSION_1_CAMERA, **camera}
    scene = _read_dataclass(data, Scene, "")
    scene.source_path = source_path
    _check_references(scene)
    return scene


def load_scene(path: str | os.PathLike) -> Scene:
    path = Path(path)
    try:
        text = read_file_bytes(path).decode("utf-8")  # a named pipe or a device is refused, not waited on
    except FileNotFoundError:
        raise SceneError(f"{path}: no such scene file") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: cannot read ({exc})") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SceneError(f"{path}: line {exc.lineno} column {exc.colno}: not valid JSON ({exc.msg})") from None
    except RecursionError:
        raise SceneError(f"{path}: lists or objects nested too deeply to read") from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise SceneError(f"{path}: a number too long to read ({str(exc).split(';')[0]})") from None
    except MemoryError:
        raise SceneError(f"{path}: too large to read") from None
    try:
        return scene_from_dict(data, path.resolve())
    except _Invalid as exc:
        raise SceneError(f"{path}: {exc}") from None


# ---------------------------------------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------------------------------------
def _write_value(value: Any) -> Any:
    if dataclasses.is_dataclass(value):
        out = {"type": value.type_name} if getattr(value, "type_name", "") else {}
        for f in dataclasses.fields(value):
            if f.name != "source_path":
                out[f.name] = _write_value(getattr(value, f.name))
        return out
    if isinstance(value, (tuple, list)):
        return [_write_value(v) for v in value]
    if isinstance(value, dict):
        return {k: _write_value(v) for k, v in value.items()}
    return value


def scene_to_dict(scene: Scene) -> dict:
    return {FORMAT_KEY: FORMAT_VERSION, **_write_value(scene)}


def _format_json(value: Any, indent: str = "") -> str:
    """Indented JSON with short lists of numbers kept on one line, so that a scene file reads like a table."""
    inner = indent + "  "
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = [f"{inner}{json.dumps(k)}: {_format_json(v, inner)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + f"\n{indent}}}"
    if isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
        return "[\n" + ",\n".join(inner + _format_json(v, inner) for v in value) + f"\n{indent}]"
    return json.dumps(value)


def save_scene(scene: Scene, path: str | os.PathLike) -> None:
    """Write atomically: a crash mid-save leaves the previous file intact."""
    path = Path(path)
    text = _format_json(scene_to_dict(scene)) + "\n"
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
