"""Read Mitsuba 3 XML scenes into LensLab's scene model (docs/mitsuba-import.md).

Two passes, as in Mitsuba's own parser (``src/core/parser.cpp``):

1. **Expand** the XML: parse each file with expat (so that every element knows its file and line), apply
   ``<default>`` and ``$param`` substitution (``defines`` win over ``<default>``, as ``mitsuba -D`` does),
   splice ``<include>`` files in (relative to the including file), and register every ``id``.
2. **Convert** the expanded tree: integrator, sensor/film/sampler, shapes with their BSDFs and area lights,
   the constant emitter. Each plugin is a small function; BSDFs go through ``mitsuba_bsdfs.BSDF_MAPPINGS``,
   one entry per Mitsuba plugin name, made from the material kinds' own ``from_mitsuba``; textures, the
   cylinder and each shape's uvs through ``mitsuba_textures`` (``texture_of``, ``material_on_shape``).

Whatever LensLab cannot render yet gives one warning naming the element and its line, and the rest of the
scene still loads. A file that is not well-formed XML, or that Mitsuba itself would reject (an undefined
``$param``, a ``<ref>`` to an unknown id, a missing mesh or included file), raises one :class:`SceneError`
naming the file and line.

Conventions converted here (checked in ``tests/test_mitsuba_import.py``):

* Mitsuba's camera looks down its local +Z with +X to the image's *left* and +Y up (``perspective_projection``
  in ``include/mitsuba/render/sensor.h``); ours looks down -Z with +X right. Both are right-handed frames, one
  the other turned half a turn about Y, so position, view direction and up carry over unchanged.
* ``fov`` with any ``fov_axis``, or a 35 mm-equivalent ``focal_length`` (a diagonal field of view on a
  36 x 24 mm frame), becomes Mitsuba's horizontal field of view (``parse_fov``), then our focal length on a
  36 mm wide sensor. ``aperture_radius`` r becomes ``f_number = f / 2r`` so that our lens radius is r.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import logging
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable
from xml.parsers import expat

import numpy as np

from lenslab.image_files import not_a_file, not_found, read_file_bytes
from lenslab.optics.stops import F_NUMBER_RANGE, MAX_F_NUMBER
from lenslab.optics.thinlens import (FOCAL_LENGTH_RANGE_MM, FOCUS_DISTANCE_RANGE_M, f_number_for_lens_radius,
                                     field_of_view_x, focal_length_for_fov)
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.fields import declared_range
from lenslab.scene.materials import Diffuse, Emissive, Material
from lenslab.scene.lights import Light, PointLight, SpotLight, SunLight
from lenslab.scene.scene import ConstantEnvironment, EnvironmentMap, Node, RenderSettings, Scene, SceneError
from lenslab.scene.scene import environment_orientation
from lenslab.scene.shapes import Box, Cylinder, Disk, MeshFile, Rectangle, Sphere
from lenslab.scene.textures import Texture
from lenslab.scene.transform import transform_points

from . import mitsuba_textures as mt
from . import mitsuba_values as mv
from .mitsuba_bsdfs import BSDF_MAPPINGS, Mapped

__all__ = ["load_mitsuba_scene", "load_mitsuba_string", "BSDF_MAPPINGS", "WarnCallback"]

log = logging.getLogger("lenslab.import")

WarnCallback = Callable[[str], None]
RGB = tuple[float, float, float]

SENSOR_WIDTH_MM = 36.0  # imported cameras get a full-frame-wide sensor; the focal length carries the fov
MAX_INCLUDE_DEPTH = 15
#: A scene assembled from many files includes hundreds; includes of includes multiply past any real scene.
MAX_INCLUDES = 10_000
#: Deeper than any real scene (a shape in a shape group in an instance in the scene is four); the passes below
#: recurse once per level, so an absurd depth is refused while parsing rather than exhausting Python's stack.
MAX_ELEMENT_DEPTH = 100
#: Each instance of a shapegroup is a copy of its nodes (about 8 microseconds each): a forest of 250,000 trees
#: fits, while thirty instances of thirty instances, five deep (24 M copies in a 3 KB file), is refused as read.
MAX_INSTANCED_NODES = 250_000
DISK_SEGMENTS = 128

# Element names of Mitsuba's format (interpret_tag in parser.cpp).
OBJECT_TAGS = {"scene", "integrator", "sensor", "film", "rfilter", "sampler", "shape", "bsdf", "emitter",
               "texture", "medium", "phase", "volume", "field"}
VALUE_TAGS = {"float", "integer", "boolean", "string", "point", "vector", "rgb", "spectrum", "transform"}
TRANSFORM_OPS = {"translate", "rotate", "scale", "lookat", "matrix"}

# Properties that change nothing in a LensLab image: read and dropped without a word.
SILENT = {
    "film": {"pixel_format", "component_format", "file_format", "banner", "compensate", "sample_border"},
    "sensor": {"near_clip", "far_clip", "shutter_open", "shutter_close", "srf"},
    "integrator": {"emitter_samples", "bsdf_samples"},
    "sampler": {"jitter", "scramble_seed", "seed_offset"},
    "shape": {"flip_tex_coords", "flip_normals", "mesh_attributes"},
    "rfilter": {"radius"},
    "emitter": {"mis_compensation", "sampling_weight"},
}


# ---------------------------------------------------------------------------------------------------------
# Pass 1: the XML tree, with lines, substitutions, includes and ids
# ---------------------------------------------------------------------------------------------------------
@dataclass(eq=False)
class XNode:
    tag: str
    attrs: dict[str, str]
    line: int
    file: str  # as shown in messages
    folder: Path  # where relative paths in this element's file start
    version: tuple[int, ...] = (3, 0, 0)
    children: list["XNode"] = field(default_factory=list)

    @property
    def type(self) -> str:
        return self.attrs.get("type", "")

    def label(self) -> str:
        text = f"<{self.tag}"
        if self.type:
            text += f' type="{self.type}"'
        if "id" in self.attrs:
            text += f' id="{self.attrs["id"]}"'
        elif "name" in self.attrs:
            text += f' name="{self.attrs["name"]}"'
        return text + ">"

    def where(self) -> str:
        return f"{self.file}:{self.line}"

    def error(self, message: str) -> SceneError:
        return SceneError(f"{self.file}: line {self.line}: {self.label()}: {message}")


def _parse_xml(data: bytes, display: str, folder: Path) -> XNode:
    parser = expat.ParserCreate()
    parser.buffer_text = True
    stack: list[XNode] = []
    roots: list[XNode] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        if len(stack) >= MAX_ELEMENT_DEPTH:
            raise SceneError(f"{display}: line {parser.CurrentLineNumber}: elements nested more than "
                             f"{MAX_ELEMENT_DEPTH} deep (no scene needs that many)")
        node = XNode(tag, dict(attrs), parser.CurrentLineNumber, display, folder)
        (stack[-1].children if stack else roots).append(node)
        stack.append(node)

    def end(_tag: str) -> None:
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(data, True)
    except LookupError as exc:  # the XML declaration names an encoding Python does not know
        raise SceneError(f"{display}: line 1: {exc}") from None
    except ValueError as exc:  # one expat does not read ("multi-byte encodings are not supported": UTF-32)
        if isinstance(exc, SceneError):
            raise
        raise SceneError(f"{display}: line 1: cannot read the file's encoding ({exc})") from None
    except expat.ExpatError as exc:
        raise SceneError(
            f"{display}: line {exc.lineno} column {exc.offset + 1}: not well-formed XML ({expat.ErrorString(exc.code)})"
        ) from None
    root = roots[0]
    version_text = root.attrs.get("version")
    if version_text is None:
        raise SceneError(f"{display}: line {root.line}: <{root.tag}> has no version attribute (not a Mitsuba scene?)")
    try:
        version = tuple(int(p) for p in version_text.strip().split("."))
    except ValueError:
        raise SceneError(f"{display}: line {root.line}: invalid version number '{version_text}'") from None

    def stamp(node: XNode) -> None:
        node.version = version
        for child in node.children:
            stamp(child)

    stamp(root)
    return root


def _camel_to_underscore(name: str) -> str:
    return re.sub(r"(?<=[a-z])([A-Z]+)", lambda m: "_" + m.group(1).lower(), name)


# Bounds on $param substitution, so that a small file cannot expand into an enormous one. A <default> may use
# the parameters before it, so a file of a kilobyte can double a value 28 times (p2 = "$p1$p1",
# p3 = "$p2$p2" ...: 134 M characters). Real scenes substitute numbers and file names; an attribute of a
# megabyte, or 16 M characters substituted in all, is a file built to exhaust memory.
MAX_EXPANDED_VALUE_CHARS = 1 << 20
MAX_SUBSTITUTED_CHARS = 1 << 24


class _Expander:
    """Substitution, defaults, includes and ids, in document order, as Mitsuba's parser does."""

    def __init__(self, defines: dict[str, str]):
        self.params: dict[str, str] = dict(defines)
        self.substituted_chars = 0  # characters inserted by substitution so far, in the whole document
        self.used: set[str] = set()
        self.ids: dict[str, XNode] = {}
        self.files: list[Path] = []
        self.includes = 0  # <include>s read so far, at every depth

    def substitute(self, node: XNode) -> None:
        keys = sorted(self.params, key=len, reverse=True)
        for attr, value in node.attrs.items():
            if "$" not in value:
                continue
            for key in keys:
                token = "$" + key
                pos = value.find(token)
                while pos >= 0:
                    if pos > 0 and value[pos - 1] == "\\":
                        pos = value.find(token, pos + len(token))
                        continue
                    self._check_room(node, attr, key, len(value) - len(token))
                    value = value[:pos] + self.params[key] + value[pos + len(token):]
                    self.used.add(key)
                    pos = value.find(token, pos + len(self.params[key]))
            match = re.search(r"(?<!\\)\$(\w*)", value)
            if match:
                raise SceneError(f"{node.file}: line {node.line}: <{node.tag}>: undefined parameter ${match.group(1)}")
            node.attrs[attr] = value.replace("\\$", "$")

    def _check_room(self, node: XNode, attr: str, key: str, rest: int) -> None:
        """Refuse, before building it, a substitution of ``$key`` into a value of ``rest`` other characters
        that would pass the bounds above: one line naming the file, the line, the parameter and the bound."""
        inserted = len(self.params[key])
        self.substituted_chars += inserted
        if rest + inserted > MAX_EXPANDED_VALUE_CHARS:
            problem = f'makes "{attr}" longer than {MAX_EXPANDED_VALUE_CHARS:,} characters'
        elif self.substituted_chars > MAX_SUBSTITUTED_CHARS:
            problem = f"brings the substituted text past {MAX_SUBSTITUTED_CHARS:,} characters in all"
        else:
            return
        raise SceneError(f"{node.file}: line {node.line}: <{node.tag}>: ${key} {problem} "
                         "(a parameter that doubles itself?)")

    def expand(self, node: XNode, depth: int) -> list[XNode]:
        """The node as it stands after expansion: [] for a <default>, an included file's elements for an
        <include>, otherwise the node itself with its children expanded."""
        self.substitute(node)
        if node.tag == "default":
            name, value = node.attrs.get("name"), node.attrs.get("value")
            if not name or value is None:
                raise node.error("needs a name and a value")
            self.params.setdefault(name, value)
            return []
        if node.tag == "include":
            return self.include(node, depth)
        if node.tag in OBJECT_TAGS or (node.tag == "spectrum" and "type" in node.attrs):
            ident = node.attrs.get("id")
            if ident:
                if ident in self.ids:
                    raise node.error(f'duplicate id "{ident}" (first at {self.ids[ident].where()})')
                self.ids[ident] = node
        children = []
        for child in node.children:
            children.extend(self.expand(child, depth))
        node.children = children
        return [node]

    def include(self, node: XNode, depth: int) -> list[XNode]:
        filename = node.attrs.get("filename")
        if not filename:
            raise node.error("needs a filename")
        path = Path(filename) if Path(filename).is_absolute() else node.folder / filename
        if not os.path.isfile(path):
            raise node.error(not_found("included file", path))
        if depth + 1 >= MAX_INCLUDE_DEPTH:
            raise node.error(f"includes nested deeper than {MAX_INCLUDE_DEPTH} (an include cycle?)")
        self.includes += 1
        if self.includes > MAX_INCLUDES:  # ten includes of ten includes, twelve deep, is 10^12 files to read
            raise node.error(f"more than {MAX_INCLUDES:,} includes in all (includes of includes multiply)")
        root = self.parse_file(path)
        expanded = self.expand(root, depth + 1)
        if root.tag == "scene":
            return expanded[0].children if expanded else []
        return expanded

    def parse_file(self, path: Path) -> XNode:
        try:
            data = read_file_bytes(path)  # a named pipe or a device is refused, not waited on
        except OSError as exc:
            raise SceneError(f"{path}: cannot read ({exc.strerror})") from None
        self.files.append(path)
        return _parse_xml(data, str(path), path.resolve().parent)


# ---------------------------------------------------------------------------------------------------------
# Pass 2: properties of one element
# ---------------------------------------------------------------------------------------------------------
class Props:
    """The named properties and nested objects of one plugin element, each read at most once.

    Reading marks a property used; :meth:`finish` warns once for each one nobody read (what LensLab does not
    support), except those in :data:`SILENT`. Nested objects without a name are kept in order in ``objects``.
    """

    def __init__(self, importer: "MitsubaImporter", node: XNode):
        self.importer = importer
        self.node = node
        self.values: dict[str, XNode] = {}
        self.objects: list[XNode] = []
        self.used: set[str] = set()
        upgrade = node.version < (2, 0, 0)
        for child in node.children:
            tag = child.tag
            if tag == "ref":
                target = importer.resolve_ref(child)
                name = child.attrs.get("name")
                if name:
                    self.values[self._name(name, upgrade)] = target
                else:
                    self.objects.append(target)
            elif tag in VALUE_TAGS and not (tag == "spectrum" and "type" in child.attrs):
                name = child.attrs.get("name")
                if not name:
                    raise child.error("a property needs a name")
                self.values[self._name(name, upgrade)] = child
            elif tag in OBJECT_TAGS or tag == "spectrum":
                name = child.attrs.get("name")
                if name:
                    self.values[self._name(name, upgrade)] = child
                else:
                    self.objects.append(child)
            elif tag in TRANSFORM_OPS:
                importer.warn(child, "a transform operation outside <transform>: ignored")
            else:
                importer.warn(child, "unknown element: ignored")

    def _name(self, name: str, upgrade: bool) -> str:
        if upgrade:  # Mitsuba 0.x scenes: camelCase names, as Mitsuba's own upgrade pass renames them
            name = _camel_to_underscore(name)
            if self.node.tag == "bsdf" and self.node.type == "diffuse" and name == "diffuse_reflectance":
                name = "reflectance"
        return name

    def has(self, name: str) -> bool:
        return name in self.values

    def take(self, name: str) -> XNode | None:
        node = self.values.get(name)
        if node is not None:
            self.used.add(name)
        return node

    def _attr(self, node: XNode, key: str = "value") -> str:
        if key not in node.attrs:
            raise node.error(f'missing attribute "{key}"')
        return node.attrs[key]

    def _expect(self, node: XNode, tags: tuple[str, ...]) -> None:
        if node.tag not in tags:
            raise node.error(f"expected <{'> or <'.join(tags)}>")

    def float(self, name: str, default: float | None = None) -> float | None:
        node = self.take(name)
        if node is None:
            return default
        self._expect(node, ("float", "integer"))
        text = self._attr(node)
        try:
            return mv.parse_number(text)
        except mv.NumberTooLarge as exc:
            raise node.error(str(exc)) from None
        except ValueError:
            raise node.error(f'could not parse "{text}" as a finite floating point value') from None

    def int(self, name: str, default: int | None = None) -> int | None:
        node = self.take(name)
        if node is None:
            return default
        self._expect(node, ("integer",))
        text = self._attr(node)
        try:
            return int(text.strip())
        except ValueError:  # also a number of more digits than Python will convert
            raise node.error(f'could not parse integer value "{text}"') from None

    def bool(self, name: str, default: bool) -> bool:
        node = self.take(name)
        if node is None:
            return default
        self._expect(node, ("boolean",))
        text = self._attr(node).strip().lower()
        if text not in ("true", "false"):
            raise node.error(f'could not parse boolean value "{text}" -- must be "true" or "false"')
        return text == "true"

    def string(self, name: str, default: str | None = None) -> str | None:
        node = self.take(name)
        if node is None:
            return default
        self._expect(node, ("string",))
        return self._attr(node)

    def vector(self, name: str, default=None) -> np.ndarray | None:
        node = self.take(name)
        if node is None:
            return None if default is None else np.asarray(default, dtype=float)
        self._expect(node, ("point", "vector"))
        return _xyz(node, 0.0)

    def transform(self, name: str = "to_world") -> np.ndarray:
        node = self.take(name)
        if node is None:
            return np.eye(4)
        self._expect(node, ("transform",))
        return _transform_matrix(node, self.importer)

    def color(self, name: str, default: float | RGB, emission: bool = False) -> RGB:
        """A colour property; ``emission`` reads spectra as Mitsuba reads an emitter's (absolute)."""
        node = self.take(name)
        if node is None:
            return (float(default),) * 3 if isinstance(default, (int, float)) else tuple(default)  # type: ignore[return-value]
        return self.importer.color_of(node, emission)

    def finish(self, silent: set[str] = frozenset()) -> None:
        silent = set(silent) | SILENT.get(self.node.tag, set())
        for name, node in self.values.items():
            if name not in self.used and name not in silent:
                self.importer.warn(node, f'{self.node.label()} property "{name}" is not supported: ignored')


def _xyz(node: XNode, default: float) -> np.ndarray:
    try:
        if "value" in node.attrs:
            values = mv.split_numbers(node.attrs["value"])
            if len(values) == 1:
                values = values * 3
            if len(values) != 3:
                raise node.error('"value" must have exactly 1 or 3 elements')
            return np.array(values, dtype=float)
        return np.array([mv.parse_number(node.attrs.get(k, str(default))) for k in "xyz"])
    except SceneError:
        raise
    except mv.NumberTooLarge as exc:  # it reads, but as nothing a scene can hold: said as it is
        raise node.error(str(exc)) from None
    except ValueError:
        raise node.error("could not parse a number") from None


def _transform_matrix(node: XNode, importer: "MitsubaImporter") -> np.ndarray:
    """A <transform>: every operation multiplied on the left, in document order (first listed, first applied)."""
    m = np.eye(4)
    for op in node.children:
        try:
            if op.tag == "translate":
                step = mv.translate_matrix(_xyz(op, 0.0))
            elif op.tag == "scale":
                step = mv.scale_matrix(_xyz(op, 1.0))
            elif op.tag == "rotate":
                if "angle" not in op.attrs:
                    raise op.error('missing attribute "angle"')
                axis = _xyz(op, 0.0)
                step = mv.rotate_matrix(axis, mv.parse_number(op.attrs["angle"]))
                if abs(np.linalg.norm(axis) - 1.0) > 1e-6:
                    importer.warn(op, "the rotation axis is not of unit length: Mitsuba 3 does not normalise it, "
                                  "so this rotation also scales (kept, to match Mitsuba)")
            elif op.tag == "lookat":
                if "origin" not in op.attrs or "target" not in op.attrs:
                    raise op.error('needs "origin" and "target"')
                origin = _three(op, "origin")
                target = _three(op, "target")
                up = _three(op, "up") if op.attrs.get("up", "").strip() else None
                step = mv.lookat_matrix(origin, target, up)
            elif op.tag == "matrix":
                step = mv.matrix_from_values(mv.split_numbers(op.attrs.get("value", "")))
            else:
                importer.warn(op, "unexpected element inside <transform>: ignored")
                continue
        except SceneError:
            raise
        except ValueError as exc:
            raise op.error(str(exc)) from None
        m = step @ m
    return m


def _three(node: XNode, key: str) -> np.ndarray:
    try:
        values = mv.split_numbers(node.attrs[key])
    except mv.NumberTooLarge as exc:
        raise node.error(f'"{key}": {exc}') from None
    except ValueError:
        raise node.error(f'could not parse "{key}"') from None
    if len(values) != 3:
        raise node.error(f'"{key}" needs 3 values, got {len(values)}')
    return np.array(values)


def _check_camera_frame(to_world: np.ndarray, node: XNode) -> None:
    """Refuse a sensor's to_world that gives the camera no frame: a view direction (+Z) or an up (+Y) mapped
    to nothing or onto each other, as an all-zero matrix does. Mitsuba cannot invert such a matrix either; read
    on, the camera would look along NaN and every pixel would be lost without a word."""
    linear = to_world[:3, :3]
    forward, up = linear @ (0.0, 0.0, 1.0), linear @ (0.0, 1.0, 0.0)
    lengths = np.linalg.norm(forward), np.linalg.norm(up)
    if not (lengths[0] > 0 and lengths[1] > 0) or np.linalg.norm(np.cross(forward / lengths[0],
                                                                         up / lengths[1])) < 1e-9:
        raise node.error("to_world gives the camera no direction to look in or no up (its matrix maps +Z or +Y to "
                         "zero, or both onto one line): a sensor needs an invertible placement")


def _copy_tree(node: Node) -> Node:
    """A copy of ``node`` and its children that an edit of one copy leaves the others as they were: each copy
    has its own transform and shape (plain values inside), made ten times faster than copy.deepcopy."""
    return dataclasses.replace(node, transform=dataclasses.replace(node.transform), shape=copy.copy(node.shape),
                               children=[_copy_tree(child) for child in node.children])


def _node_count(node: Node) -> int:
    return 1 + sum(_node_count(child) for child in node.children)


@contextlib.contextmanager
def _named_errors(node: XNode):
    """A value that makes no sense where it lands (a zero that divides, a number outside a function's domain)
    found deep inside one top-level element: reported at that element, as every other error is, with its
    file and line. Errors that already name their element pass through."""
    try:
        yield
    except SceneError:
        raise
    except (ValueError, ArithmeticError) as exc:
        raise node.error(str(exc) or type(exc).__name__) from None


MITSUBA_DEFAULT_MATERIAL = "mitsuba_default"  # a shape without a BSDF: Mitsuba's diffuse, reflectance 0.5


# ---------------------------------------------------------------------------------------------------------
# Pass 2: the scene
# ---------------------------------------------------------------------------------------------------------
@dataclass
class _Camera:
    node: XNode | None
    to_world: np.ndarray
    fov_x_deg: float
    aperture_radius: float | None  # None: a pinhole (perspective)
    focus_distance: float


class MitsubaImporter:
    """Reads one parsed and expanded scene file into LensLab's scene: the state (materials, nodes, lights,
    the camera) that the element readers here, in the BSDF mappings (mitsuba_bsdfs, the material kinds'
    ``from_mitsuba``, mitsuba_props) and in mitsuba_textures share."""

    def __init__(self, root: XNode, ids: dict[str, XNode], root_folder: Path, warn: WarnCallback):
        self.root = root
        self.ids = ids
        self.root_folder = root_folder
        self._warn = warn
        self.materials: dict[str, Material] = {}
        self._material_of: dict[int, str] = {}
        self.nodes: list[Node] = []
        self._names: set[str] = set()
        self._groups: dict[int, list[Node]] = {}
        self._groups_being_read: set[int] = set()  # a group met again while its own shapes are read instances itself
        self.instanced_nodes = 0  # nodes copied for instances so far
        self.environment = ConstantEnvironment()
        self._environment_node: XNode | None = None
        self.lights: list[Light] = []
        self._top_level_area_lights: list[XNode] = []  # checked against _attached_emitters at the end
        self._attached_emitters: set[int] = set()  # ids of the emitter elements shapes took
        self.render = RenderSettings(spp=4, max_depth=1024, rr_depth=5, seed=0, sampler="independent")
        self.resolution = (768, 576)
        self.camera: _Camera | None = None
        self._unsupported_sensor = False
        self.search_dirs: list[Path] = []
        self._textures: dict[tuple[int, bool], Texture | None] = {}  # texture_of's, by element and use
        self._uv_variants: dict[str, tuple[Material, dict]] = {}  # material_on_shape's, by material name
        self._moved_textures: dict = {}  # mt.on_shape's copies of textures, shared between materials

    # -- reporting ----------------------------------------------------------------------------------------
    def warn(self, node: XNode, message: str) -> None:
        self._warn(f"{node.where()}: {node.label()}: {message}")

    def resolve_ref(self, ref: XNode) -> XNode:
        ident = ref.attrs.get("id")
        if not ident:
            raise ref.error('a <ref> needs an "id"')
        if ident not in self.ids:
            raise ref.error(f'unresolved reference to "{ident}": no object has id="{ident}"')
        return self.ids[ident]

    def resolve_file(self, node: XNode, filename: str) -> Path:
        """A file named in ``node``: relative to its own file's folder, then the scene's, then <path> folders."""
        path = Path(filename)
        if path.is_absolute():
            return path
        for folder in [node.folder, self.root_folder, *self.search_dirs]:
            if os.path.exists(folder / path):
                return folder / path
        return node.folder / path

    def unique_name(self, base: str) -> str:
        name, n = base, 1
        while name in self._names:
            n += 1
            name = f"{base}_{n}"
        self._names.add(name)
        return name

    def unique_material(self, base: str) -> str:
        name, n = base, 1
        while name in self.materials:
            n += 1
            name = f"{base}_{n}"
        return name

    # -- values -------------------------------------------------------------------------------------------
    def color_of(self, node: XNode, emission: bool = False) -> RGB:
        """An RGB from <rgb>, <spectrum>, <float> or a texture (textures are averaged, with a warning)."""
        try:
            if node.tag == "rgb":
                values = mv.split_numbers(node.attrs.get("value", ""))
                if len(values) == 1:
                    values = values * 3
                if len(values) != 3:
                    raise node.error(f"<rgb> needs one or three values (got {len(values)})")
                return tuple(values)  # type: ignore[return-value]
            if node.tag == "float":
                v = mv.parse_number(node.attrs.get("value", ""))
                return (v, v, v)
            if node.tag == "spectrum" and "type" not in node.attrs:
                if "filename" in node.attrs:
                    self.warn(node, "spectra from files are not supported: white used")
                    return (1.0, 1.0, 1.0)
                return mv.spectrum_to_rgb(mv.parse_spectrum(node.attrs.get("value", "")), emission)
        except SceneError:
            raise
        except ValueError as exc:
            raise node.error(str(exc)) from None
        if node.tag in ("texture", "spectrum"):
            return self.texture_color(node, emission)
        raise node.error("expected a colour (<rgb>, <spectrum>, <float> or a texture)")

    def texture_color(self, node: XNode, emission: bool = False) -> RGB:
        """A texture's colour where LensLab takes one colour: a constant texture's, or (with a warning) the
        mean of one that varies."""
        kind = node.type
        if kind in ("srgb", "d65", "uniform"):
            p = Props(self, node)
            value = p.take("color") or p.take("value")
            rgb = self.color_of(value, emission) if value is not None else (1.0, 1.0, 1.0)
            if kind == "d65" and p.has("scale"):
                s = p.float("scale", 1.0)
                rgb = tuple(c * s for c in rgb)
            p.finish()
            return rgb  # type: ignore[return-value]
        texture = self.texture_of(node)
        if texture is None:
            self.warn(node, f'texture "{kind}" is not supported: grey 0.5 used')
            return (0.5, 0.5, 0.5)
        rgb = mt.mean_colour(self, node, texture) or (0.5, 0.5, 0.5)  # an unreadable file: warned already
        self.warn(node, f"LensLab cannot vary this property over the surface: the {kind}'s mean colour "
                  f"{_fmt(rgb)} used")
        return rgb

    def texture_of(self, node: XNode, scalar: bool = False) -> Texture | None:
        """The LensLab texture for a Mitsuba ``<texture>`` element (nested in a property, or the target of a
        ``<ref>``), or None for one LensLab cannot look up (``color_of`` then gives its mean, with a warning).
        ``scalar``: for a property Mitsuba reads with ``eval_1`` (a weight, an opacity), where a checkerboard
        swaps its colours (mitsuba_textures.as_scalar). Converted once per element: every material that refers
        to it shares the one texture. Its uvs are a mesh file's; ``material_on_shape`` fits other shapes."""
        if node.tag != "texture":
            return None
        key = (id(node), scalar)
        if key not in self._textures:
            if scalar:
                texture = self.texture_of(node)
                self._textures[key] = mt.as_scalar(texture) if texture is not None else None
            else:
                with _named_errors(node):
                    self._textures[key] = mt.texture_from_element(self, node)
        return self._textures[key]

    def material_on_shape(self, node: XNode, p: "Props", material: str, matrix: np.ndarray) -> str:
        """The material to give a shape of Mitsuba type ``node.type`` placed at ``matrix``: ``material`` itself,
        or, when it holds textures and the shape's uvs are not a mesh file's, a copy whose textures take the
        shape's own uvs (mitsuba_textures.shape_uv). The first shape to use a material gets it fitted in place;
        a shape with other uvs, a copy named after its type."""
        original, variants = self._uv_variants.get(material, (self.materials[material], {}))
        if not mt.textures_of(original):
            return material
        flip_tex = p.bool("flip_tex_coords", mt.FLIP_TEX_COORDS_DEFAULT.get(node.type, False))
        uv = mt.shape_uv(node.type, matrix, flip_tex, p.bool("flip_normals", False))
        if isinstance(uv, str):
            self.warn(node, uv)
            uv = mt.UNMAPPED
        if uv not in variants:
            fitted, exact = (original, True) if uv.is_identity else mt.on_shape(original, uv, self._moved_textures)
            if not exact:
                self.warn(node, "Mitsuba's texture seam on this sphere is where to_world turns it, and LensLab's "
                          "sphere keeps its seam on the world's -X: a texture that does not repeat around the "
                          "sphere lands differently there")
            name = material if not variants else self.unique_material(f"{material}.{node.type}")
            self.materials[name] = fitted
            variants[uv] = name
            self._uv_variants[material] = (original, variants)
        return variants[uv]

    # -- BSDFs --------------------------------------------------------------------------------------------
    def map_bsdf(self, node: XNode) -> Mapped:
        if node.tag != "bsdf":
            raise node.error("expected a <bsdf>")
        mapping = BSDF_MAPPINGS.get(node.type)
        if mapping is None:
            return Mapped(Diffuse((0.5, 0.5, 0.5)), f'BSDF "{node.type}" is not supported: grey diffuse 0.5 used')
        p = Props(self, node)
        mapped = mapping(p, self)
        p.finish()
        return mapped

    def material_for(self, bsdf: XNode | None, owner: str) -> str:
        """The material name for a BSDF element (converted once, however many shapes use it)."""
        if bsdf is None:
            if MITSUBA_DEFAULT_MATERIAL not in self.materials:
                self.materials[MITSUBA_DEFAULT_MATERIAL] = Diffuse((0.5, 0.5, 0.5))
            return MITSUBA_DEFAULT_MATERIAL
        key = id(bsdf)
        if key not in self._material_of:
            mapped = self.map_bsdf(bsdf)
            if mapped.note:
                self.warn(bsdf, mapped.note)
            name = self.unique_material(bsdf.attrs.get("id") or f"{owner}.bsdf")
            self.materials[name] = mapped.material
            self._material_of[key] = name
        return self._material_of[key]

    # -- the scene ----------------------------------------------------------------------------------------
    def run(self) -> None:
        root = self.root
        if root.tag != "scene":
            raise root.error("the root element must be <scene>")
        sensors = []
        for child in root.children:
            with _named_errors(child):
                self._top_level(child, sensors)
        for light in self._top_level_area_lights:
            if id(light) not in self._attached_emitters:
                self.warn(light, "an area emitter that no <shape> refers to lights nothing: ignored")
        if sensors:
            with _named_errors(sensors[0]):
                self.sensor(sensors[0])
            for extra in sensors[1:]:
                self.warn(extra, "only the first sensor is used: ignored")

    def _top_level(self, child: XNode, sensors: list[XNode]) -> None:
        tag = child.tag
        if tag == "integrator":
            self.integrator(child)
        elif tag == "sensor":
            sensors.append(child)
        elif tag == "shape":
            self.nodes.extend(self.shape(child))
        elif tag == "emitter":
            self.emitter(child)
        elif tag in ("bsdf", "texture", "spectrum"):
            pass  # converted where a shape refers to them
        elif tag == "path":
            folder = self.resolve_file(child, child.attrs.get("value", ""))
            if not os.path.isdir(folder):
                raise child.error(f"folder not found: {folder}")
            self.search_dirs.insert(0, folder)
        elif tag in ("medium", "phase", "volume", "field"):
            self.warn(child, "participating media are not supported: ignored")
        elif tag == "ref":
            self.resolve_ref(child)
            self.warn(child, "a top-level <ref> adds nothing: ignored")
        elif tag == "sampler":
            if "id" not in child.attrs:  # with an id it is used where a sensor refers to it
                self.warn(child, "a sampler belongs inside the <sensor> (Mitsuba 3 ignores it here too): ignored")
        elif tag in OBJECT_TAGS or tag in VALUE_TAGS:
            self.warn(child, "not expected in <scene>: ignored")
        else:
            self.warn(child, "unknown element: ignored")

    def integrator(self, node: XNode) -> None:
        p = Props(self, node)
        kind = node.type
        if kind in ("path", "volpath", "volpathmis", "prb", "prbvolpath"):
            max_depth = p.int("max_depth", -1)
            rr_depth = p.int("rr_depth", 5)
            if p.bool("hide_emitters", False):
                self.warn(node, "hide_emitters is not supported: emitters stay visible")
        elif kind == "direct":
            max_depth, rr_depth = 2, 1024
        else:
            inner = [n for n in p.objects if n.tag == "integrator"]
            if inner:  # aov, moment, ...: wrappers around the integrator that makes the image
                self.warn(node, f'integrator "{kind}" is not supported: its nested integrator is used')
                self.integrator(inner[0])
            else:
                self.warn(node, f'integrator "{kind}" is not supported: a path tracer is used')
            return
        p.finish()
        if max_depth is not None and max_depth < 0:
            max_depth = 1024  # Mitsuba's -1: unbounded; Russian roulette ends paths long before this
        if max_depth == 0:
            self.warn(node, "max_depth 0 (an empty image) is not supported: 1 used")
            max_depth = 1
        self.render.max_depth = int(min(max_depth, 1024))
        self.render.rr_depth = int(min(max(rr_depth, 1), 1024))

    def emitter(self, node: XNode) -> None:
        p = Props(self, node)
        kind = node.type
        if kind == "constant":
            rgb = p.color("radiance", 1.0, emission=True)
            scale = p.float("scale", 1.0)
            p.finish()
            old = self.environment
            if isinstance(old, EnvironmentMap):
                self.warn(node, "LensLab has one environment: this constant light is dropped beside the envmap "
                          f"at {self._environment_node.where()}")
                return
            self.environment = ConstantEnvironment(tuple(float(a + b * scale) for a, b in zip(old.radiance, rgb)))  # type: ignore[arg-type]
            self._environment_node = node
        elif kind == "envmap":
            self.envmap(node, p)
        elif kind == "point":
            intensity = p.color("intensity", 1.0, emission=True)
            to_world = p.transform("to_world")
            position = p.vector("position")
            p.finish()
            if position is None:
                position = to_world[:3, 3]
            name = self.unique_name(node.attrs.get("id") or "point")
            self.lights.append(PointLight(name=name, position=tuple(float(v) for v in position),
                                          intensity=_clip_rgb(intensity)))
        elif kind == "directional":
            irradiance = p.color("irradiance", 1.0, emission=True)
            to_world = p.transform("to_world")
            direction = p.vector("direction")
            p.finish()
            # Mitsuba's direction is the way the light travels (default: its local +Z); ours points at the sun.
            travel = np.asarray(direction if direction is not None else to_world[:3, :3] @ (0.0, 0.0, 1.0), float)
            if np.linalg.norm(travel) == 0:
                raise node.error("the direction must not be zero")
            name = self.unique_name(node.attrs.get("id") or "directional")
            self.lights.append(SunLight(name=name, direction=tuple(float(-v) for v in travel / np.linalg.norm(travel)),
                                        irradiance=_clip_rgb(irradiance), angular_diameter_deg=0.0))
        elif kind == "area":
            # Declared here and referenced from a shape (<ref id=...> inside it), as Mitsuba's own Cornell
            # box does: whether any shape took it is known once the whole scene is read (run()).
            self._top_level_area_lights.append(node)
        elif kind == "spot":
            self.spot(node, p)
        else:
            p.finish(silent=set(p.values))
            self.warn(node, f'emitter "{kind}" is not supported yet: ignored (the scene lacks this light)')

    def envmap(self, node: XNode, p: "Props") -> None:
        """Mitsuba's envmap: u = atan2(x, -z) / 2pi in its local frame, so its left edge (u = 0) looks down -Z
        where ours has the centre column: the same picture turned half a turn about +Y. Its ``to_world`` R
        then turns that frame into the world, so our map's frame turns by R Ry(180), whatever R is: that
        rotation becomes ``zenith`` and ``rotation_deg`` (scene.environment_orientation). A turn by theta about
        +Y alone gives ``rotation_deg`` 180 - theta and the zenith straight up.

        Mitsuba applies to_world's inverse to a direction without normalising it, so a to_world that scales
        or shears distorts its lookups; LensLab keeps the nearest rotation and says so."""
        filename = p.string("filename")
        scale = p.float("scale", 1.0)
        to_world = p.transform("to_world")
        p.finish()
        if not filename:
            raise node.error('needs a "filename"')
        path = self.resolve_file(node, filename)
        if not os.path.isfile(path):
            raise node.error(not_found("environment map", path))
        rotation = self._nearest_rotation(node, to_world[:3, :3], "the map")
        half_turn = np.diag([-1.0, 1.0, -1.0])  # Ry(180), exactly
        zenith, rotation_deg = environment_orientation(rotation @ half_turn)
        zenith = tuple(0.0 if abs(v) < 1e-12 else v for v in zenith)  # a turn about +Y keeps (0, 1, 0) exact
        if self._environment_node is not None:
            self.warn(node, "LensLab has one environment: this envmap replaces the "
                      f"{self._environment_node.label()} at {self._environment_node.where()}")
        self.environment = EnvironmentMap(file=self.scene_relative_path(path), strength=float(max(scale, 0.0)),
                                          rotation_deg=float(rotation_deg), rows="pole_to_pole", zenith=zenith)
        self._environment_node = node

    def _nearest_rotation(self, node: XNode, linear: np.ndarray, what: str) -> np.ndarray:
        """The rotation nearest a to_world's 3x3 part (from its SVD), with a warning where that part also
        scales, shears or mirrors (which LensLab's lights and maps do not)."""
        u, sizes, vt = np.linalg.svd(linear)
        mirrored = np.linalg.det(u @ vt) < 0
        if mirrored:
            u = u @ np.diag([1.0, 1.0, -1.0])
        if not np.allclose(sizes, 1.0, atol=1e-6):
            self.warn(node, f"to_world scales or shears {what}: Mitsuba looks directions up through it without "
                      "normalising them (a distorted picture); LensLab uses its rotation alone")
        if mirrored:
            self.warn(node, f"to_world mirrors {what}: LensLab uses the nearest rotation, unmirrored")
        return u @ vt

    def spot(self, node: XNode, p: "Props") -> None:
        """Mitsuba's spot (src/emitters/spot.cpp): at to_world's origin, shining along its +Z, its texture's u
        along +X and v along +Y with v = 0 the image's top row, so the image's top points along -Y: our
        SpotLight's ``up``. A to_world that scales evenly changes nothing (Mitsuba normalises directions)."""
        intensity_node = p.take("intensity")
        if intensity_node is not None and intensity_node.tag == "texture" and \
                intensity_node.type not in ("srgb", "d65", "uniform"):
            raise intensity_node.error("a spot's intensity cannot vary over space (Mitsuba refuses it too)")
        intensity = self.color_of(intensity_node, emission=True) if intensity_node is not None else (1.0,) * 3
        cutoff = p.float("cutoff_angle", 20.0)
        beam = p.float("beam_width", cutoff * 3.0 / 4.0)
        texture_node = p.take("texture")
        to_world = p.transform("to_world")
        p.finish()
        if not 0.0 < cutoff <= 180.0 or beam < 0.0:
            raise node.error(f"cutoff_angle must be in (0, 180] and beam_width at least 0 "
                             f"(got {cutoff:g} and {beam:g})")
        texture = self._spot_texture(texture_node) if texture_node is not None else None
        linear = to_world[:3, :3]
        sizes = np.linalg.svd(linear, compute_uv=False)
        if sizes.max() - sizes.min() > 1e-6 * sizes.max():
            self.warn(node, "to_world scales unevenly or shears the spot: Mitsuba's cone is then elliptical, "
                      "LensLab's stays round about to_world's +Z")
        if texture is not None and np.linalg.det(linear) < 0:
            self.warn(node, "to_world mirrors the spot: its texture is projected unmirrored")
        axis, top = linear @ (0.0, 0.0, 1.0), -(linear @ (0.0, 1.0, 0.0))
        name = self.unique_name(node.attrs.get("id") or "spot")
        self.lights.append(SpotLight(
            name=name, position=tuple(float(v) + 0.0 for v in to_world[:3, 3]),  # + 0.0: no -0.0 in files
            direction=tuple(float(v) + 0.0 for v in axis / np.linalg.norm(axis)), intensity=_clip_rgb(intensity),
            cutoff_angle_deg=float(cutoff), beam_width_deg=float(beam), texture=texture,
            up=tuple(float(v) + 0.0 for v in top / np.linalg.norm(top))))

    def _spot_texture(self, node: XNode):
        """A spot's projected texture (Mitsuba refuses one that does not vary over space). Textures expect the
        uvs of a mesh file (mitsuba_textures: v = 1 - Mitsuba's v), which is how SpotLight projects them."""
        if node.tag != "texture" or node.type in ("srgb", "d65", "uniform"):
            raise node.error("a spot's texture must vary over space, such as a bitmap (Mitsuba refuses others)")
        texture = self.texture_of(node)
        if texture is None:
            self.warn(node, "this texture cannot be projected by LensLab: the spot shines untextured")
        return texture

    # -- shapes -------------------------------------------------------------------------------------------
    def shape(self, node: XNode) -> list[Node]:
        kind = node.type
        p = Props(self, node)
        name = self.unique_name(node.attrs.get("id") or kind or "shape")
        if kind == "shapegroup":
            return []  # instanced where an <shape type="instance"> refers to it
        if kind == "instance":
            return self.instance(node, p, name)
        to_world = p.transform("to_world")
        local = np.eye(4)
        flip = p.bool("flip_normals", False)
        shape = None
        if kind == "sphere":
            center = p.vector("center", (0, 0, 0))
            radius = p.float("radius", 1.0)
            if not radius > 0:  # Mitsuba's sphere is scaled by it: a negative one is no sphere it means
                raise node.error(f"a sphere's radius must be positive, not {radius:g}")
            local = mv.translate_matrix(center)
            shape = Sphere(radius=radius)
        elif kind == "rectangle":
            shape = Rectangle(size=(2.0, 2.0))
            if flip:  # the same square seen from behind: turn it half a turn about its x axis
                local = mv.rotate_matrix((1, 0, 0), 180.0)
                flip = False
        elif kind == "cube":
            shape = Box(size=(2.0, 2.0, 2.0))
        elif kind == "disk":
            shape = Disk(radius=1.0, segments=DISK_SEGMENTS)  # a polygon of the disk's area
            if flip:
                local = mv.rotate_matrix((1, 0, 0), 180.0)
                flip = False
        elif kind == "cylinder":  # a tube of the cylinder's area; the node's matrix carries Mitsuba's placement
            p0, p1 = p.vector("p0", (0, 0, 0)), p.vector("p1", (0, 0, 1))
            radius = p.float("radius", 1.0)
            if not radius > 0:
                raise node.error(f"a cylinder's radius must be positive, not {radius:g}")
            with _named_errors(node):
                whole = mt.cylinder_matrix(p0, p1, radius, to_world)
            shape, to_world = mt.cylinder_shape(whole, flip)
            flip = False  # the tube's normals turn themselves
        elif kind in ("obj", "ply", "stl", "serialized"):
            filename = p.string("filename")
            if not filename:
                raise node.error('needs a "filename"')
            path = self.resolve_file(node, filename)
            if not os.path.isfile(path):
                raise node.error(not_found("mesh file", path))
            smooth = not p.bool("face_normals", False)
            shape_index = p.int("shape_index", 0) if kind == "serialized" else 0  # which of the file's meshes
            if not 0 <= shape_index < 2**31:
                raise node.error(f"shape_index must be in [0, {2**31 - 1}] (got {shape_index})")
            shape = MeshFile(file=self.scene_relative_path(path), smooth=smooth, shape_index=shape_index)
        else:
            p.finish(silent=set(p.values))
            self.warn(node, f'shape "{kind}" is not supported: skipped')
            return []

        emitters = [n for n in p.objects if n.tag == "emitter"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "emitter"]
        bsdfs = [n for n in p.objects if n.tag == "bsdf"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "bsdf"]
        for key in ("interior", "exterior"):
            if p.take(key) is not None:
                self.warn(node, f"the {key} medium is ignored (participating media are not supported)")
        for other in p.objects:
            if other.tag not in ("emitter", "bsdf"):
                self.warn(other, f"not supported inside {node.label()}: ignored")
        p.finish()

        if len(bsdfs) > 1:
            self.warn(bsdfs[1], "a shape takes one BSDF: the first is used")
        material = None
        if emitters:
            material = self.area_light(emitters[0], node, name, flip, bsdfs[0] if bsdfs else None)
            for extra in emitters[1:]:
                self.warn(extra, "a shape takes one emitter: the first is used")
        if material is None:
            bsdf = bsdfs[0] if bsdfs else None
            if bsdf is not None and bsdf.type == "null":
                self.warn(bsdf, "an invisible (null BSDF) shape without a light: skipped")
                return []
            material = self.material_for(bsdf, name)

        matrix = to_world @ local
        if isinstance(shape, Sphere):
            matrix = self._similarity(node, matrix)
        material = self.material_on_shape(node, p, material, matrix)
        return self.place(node, name, matrix, shape, material)

    def area_light(self, emitter: XNode, shape_node: XNode, name: str, flip: bool, bsdf: XNode | None) -> str | None:
        """An area light: Emissive, whose surface is the shape's BSDF. Mitsuba gives an emitting shape without
        a BSDF a black diffuse one (``Shape::Shape``), which is our surface-less light."""
        self._attached_emitters.add(id(emitter))
        if emitter.type != "area":
            self.warn(emitter, f'emitter "{emitter.type}" cannot be attached to a shape: ignored')
            return None
        p = Props(self, emitter)
        radiance = p.color("radiance", 1.0, emission=True)
        p.finish()
        if flip:
            self.warn(shape_node, "flip_normals on an emitting "
                      f"{shape_node.type} is not supported: it emits from its outside")
        surface = None
        if bsdf is not None and bsdf.type == "null":
            self.warn(bsdf, "a light with a null BSDF: in LensLab its surface is black and blocks what lies behind it")
        elif bsdf is not None:
            mapped = self.map_bsdf(bsdf)
            if mapped.note:
                self.warn(bsdf, mapped.note)
            surface = mapped.material
        material = self.unique_material(f"{name}.emitter")
        clipped = tuple(float(min(max(c, 0.0), 1e6)) for c in radiance)
        self.materials[material] = Emissive(radiance=clipped, two_sided=False, surface=surface)  # type: ignore[arg-type]
        return material

    def instance(self, node: XNode, p: Props, name: str) -> list[Node]:
        to_world = p.transform("to_world")
        groups = [n for n in p.objects if n.tag == "shape" and n.type == "shapegroup"]
        p.finish()
        if not groups:
            self.warn(node, "an instance needs a <ref> to a shapegroup: skipped")
            return []
        group = groups[0]
        key = id(group)
        if key in self._groups_being_read:
            raise node.error(f"{group.label()} instances itself (at {group.where()})")
        if key not in self._groups:
            self._groups_being_read.add(key)
            gp = Props(self, group)
            members = []
            for child in gp.objects:
                if child.tag == "shape":
                    members.extend(self.shape(child))
                else:
                    self.warn(child, "a shapegroup holds only shapes: ignored")
            gp.finish()
            self._groups_being_read.discard(key)
            self._groups[key] = members
        # Instances of instances multiply: count what this copy adds before making it.
        self.instanced_nodes += sum(_node_count(member) for member in self._groups[key])
        if self.instanced_nodes > MAX_INSTANCED_NODES:
            raise node.error(f"instances of shapegroups make more than {MAX_INSTANCED_NODES:,} nodes (instances "
                             "nested in instances multiply)")
        children = [_copy_tree(member) for member in self._groups[key]]
        try:
            transforms = mv.decompose_affine(to_world)
        except SceneError:
            raise
        except ValueError as exc:
            self.warn(node, f"{exc}: skipped")
            return []
        outer = Node(name=name, transform=transforms[0], children=children)
        if len(transforms) == 2:
            outer.children = [Node(name=f"{name}.shear", transform=transforms[1], children=children)]
        return [outer]

    def place(self, node: XNode, name: str, matrix: np.ndarray, shape, material: str) -> list[Node]:
        """A node (or, for a sheared matrix, a node holding a node) that puts ``shape`` at ``matrix``."""
        try:
            transforms = mv.decompose_affine(matrix)
        except SceneError:
            raise
        except ValueError as exc:
            self.warn(node, f"{exc}: shape skipped")
            return []
        if len(transforms) == 1:
            return [Node(name=name, transform=transforms[0], shape=shape, material=material)]
        inner = Node(name=f"{name}.shear", transform=transforms[1], shape=shape, material=material)
        return [Node(name=name, transform=transforms[0], children=[inner])]

    def _similarity(self, node: XNode, matrix: np.ndarray) -> np.ndarray:
        scale = np.linalg.norm(matrix[:3, :3], axis=0)
        gram = matrix[:3, :3].T @ matrix[:3, :3]
        if np.ptp(scale) <= 1e-9 * scale.max() and np.allclose(gram, np.diag(np.diag(gram)), atol=1e-9 * scale.max() ** 2):
            return matrix
        self.warn(node, "a sphere takes no non-uniform scale or shear (Mitsuba forbids it too): "
                  "the nearest uniform scale used")
        return mv.nearest_similarity(matrix)

    def scene_relative_path(self, path: Path) -> str:
        """``path`` relative to the scene file's folder, the way the imported scene names its files."""
        try:
            return os.path.relpath(path.resolve(), self.root_folder.resolve())
        except ValueError:  # another drive on Windows
            return str(path.resolve())

    # -- sensor, film, sampler ----------------------------------------------------------------------------
    def sensor(self, node: XNode) -> None:
        p = Props(self, node)
        kind = node.type
        films = [n for n in p.objects if n.tag == "film"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "film"]
        samplers = [n for n in p.objects if n.tag == "sampler"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "sampler"]
        if films:
            self.film(films[0])
        else:
            self._gaussian_filter(0.5)  # Mitsuba's default film
        if samplers:
            self.sampler(samplers[0])
        if kind not in ("perspective", "thinlens"):
            p.finish(silent=set(p.values))
            self.warn(node, f'sensor "{kind}" is not supported: a 45-degree camera looking down +Z at the whole '
                      "scene is used")
            self._unsupported_sensor = True
            return
        to_world = p.transform("to_world")
        _check_camera_frame(to_world, node)
        width, height = self.resolution
        aspect = width / height
        try:
            fov_x = _parse_fov(p, aspect)
        except SceneError:
            raise
        except ValueError as exc:
            raise node.error(str(exc)) from None
        focus = p.float("focus_distance", 1e4)  # Mitsuba: the far clip plane
        radius = None
        if kind == "thinlens":
            radius = p.float("aperture_radius")
            if radius is None:
                raise node.error('needs an "aperture_radius" (Mitsuba has no default either)')
            if radius < 0:  # no lens has one: f/N with N < 0
                raise node.error(f"aperture_radius {radius:g} is negative: a lens's radius is 0 (a pinhole) or more")
        for key in ("principal_point_offset_x", "principal_point_offset_y"):
            if p.float(key, 0.0) != 0.0:
                self.warn(node, f"{key} (an off-centre image) is not supported: centred")
        p.finish()
        self.camera = _Camera(node, to_world, fov_x, radius, focus)

    def _gaussian_filter(self, stddev: float) -> None:
        """Mitsuba's gaussian rfilter: samples splatted over the pixels within 4 stddev, each pixel divided by
        the weights its samples drew, as Mitsuba's film does (RenderSettings.filter_weights = "sampled")."""
        self.render.pixel_filter, self.render.filter_stddev = "gaussian", stddev
        self.render.filter_weights = "sampled"

    def film(self, node: XNode) -> None:
        p = Props(self, node)
        if node.type not in ("hdrfilm", "specfilm"):
            self.warn(node, f'film "{node.type}" is not supported: read as an hdrfilm')
        width, height = p.int("width", 768), p.int("height", 576)
        if not (1 <= width <= 16384 and 1 <= height <= 16384):
            raise node.error(f"film size {width} x {height} is out of range [1, 16384]")
        self.resolution = (width, height)
        for key in ("crop_offset_x", "crop_offset_y", "crop_width", "crop_height"):
            if p.take(key) is not None:
                self.warn(node, f"{key}: cropped films are not supported: the whole frame is rendered")
        filters = [n for n in p.objects if n.tag == "rfilter"] + [p.take(k) for k in list(p.values) if p.values[k].tag == "rfilter"]
        p.finish()
        if not filters:  # Mitsuba's default: a gaussian of standard deviation 0.5 pixels
            self._gaussian_filter(0.5)
            return
        rfilter = filters[0]
        rp = Props(self, rfilter)
        if rfilter.type == "gaussian":
            stddev = rp.float("stddev", 0.5)
            rp.finish(silent={"radius"})
            low, high = declared_range(RenderSettings, "filter_stddev")  # what the film can draw, as written
            if stddev <= 0:
                raise rfilter.error(f"stddev {stddev:g} must be positive (a gaussian's width)")
            if not low <= stddev <= high:
                nearest = min(max(stddev, low), high)
                self.warn(rfilter, f"stddev {stddev:g} pixels is beyond what LensLab's film draws ({low:g}-{high:g}): "
                          f"{nearest:g} used")
                stddev = nearest
            self._gaussian_filter(float(stddev))
            return
        rp.finish(silent=set(rp.values))
        self.render.pixel_filter = "box"
        if rfilter.type != "box":
            self.warn(rfilter, f'reconstruction filter "{rfilter.type}" is not supported: a box filter is used')

    def sampler(self, node: XNode) -> None:
        p = Props(self, node)
        spp = p.int("sample_count", 4)
        seed = p.int("seed", 0)
        p.finish()
        if not 1 <= spp <= 1 << 24:
            raise node.error(f"sample_count {spp} is out of range [1, {1 << 24}]")
        self.render.spp = spp
        self.render.seed = int(seed) % (2**31)
        # independent stays independent; every stratified or low-discrepancy sampler maps onto our Sobol: the
        # same image, with the noise of a different pattern.
        self.render.sampler = "independent" if node.type == "independent" else "sobol"
        if node.type != "independent":
            self.warn(node, f'sampler "{node.type}" is rendered with LensLab\'s Owen-scrambled Sobol sampler: '
                      "the same image, stratified in its own way")

    # -- the camera, last: without a sensor it needs the scene's extent --------------------------------------------
    def make_camera(self) -> ThinLensCamera:
        width, height = self.resolution
        cam = self.camera
        if cam is None:
            cam = self._default_camera()
        m = cam.to_world
        linear = m[:3, :3]
        position = m[:3, 3]
        forward = linear @ (0.0, 0.0, 1.0)
        up = linear @ (0.0, 1.0, 0.0)
        left = linear @ (1.0, 0.0, 0.0)
        norms = np.linalg.norm([left, up, forward], axis=1)
        where = cam.node if cam.node is not None else self.root
        if np.any(np.abs(norms - 1) > 1e-6) or abs(np.dot(forward, up)) > 1e-6 * norms[1] * norms[2]:
            self.warn(where, "the camera's to_world scales or shears (Mitsuba forbids it): its rotation is used")
        if np.linalg.det(linear) < 0:
            self.warn(where, "the camera's to_world mirrors the image: not supported, the image is unmirrored")
        forward = forward / np.linalg.norm(forward)
        up = up - np.dot(up, forward) * forward
        up = up / np.linalg.norm(up)

        # Every value is kept as written where LensLab can render it: the camera's ranges are what a value may be
        # (thinlens.FOCAL_LENGTH_RANGE_MM, stops.F_NUMBER_RANGE: float32's limits), not what the studio's controls
        # offer (f/0.5 to f/128, 1 to 2000 mm). Mitsuba's own sensor_thinlens is f/0.13.
        fov_x = math.radians(cam.fov_x_deg)
        focal_mm = focal_length_for_fov(fov_x, SENSOR_WIDTH_MM)
        low, high = FOCAL_LENGTH_RANGE_MM
        if not low <= focal_mm <= high:
            nearest = min(max(focal_mm, low), high)
            self.warn(where, f"a field of view of {cam.fov_x_deg:.8g} degrees needs a {focal_mm:.4g} mm lens, beyond "
                      f"what float32 carries on the GPU ({low:g}-{high:g} mm): {nearest:g} mm "
                      f"({math.degrees(field_of_view_x(nearest, SENSOR_WIDTH_MM)):.8g} degrees) used")
            focal_mm = nearest
        focus = cam.focus_distance
        pinhole = cam.aperture_radius is None or cam.aperture_radius == 0.0  # a lens of radius 0 is a pinhole
        f_number = MAX_F_NUMBER  # a pinhole ignores it; the narrowest the controls offer, should it be turned off
        if not pinhole:
            r = cam.aperture_radius
            f_number = f_number_for_lens_radius(focal_mm, r)
            low, high = F_NUMBER_RANGE
            if f_number > high:  # a lens float32 cannot tell from a pinhole: render it as one, exactly
                self.warn(where, f"aperture_radius {r:g} gives f/{f_number:.4g}, narrower than float32 resolves "
                          f"beside the focal length (f/{high:g}): rendered as a pinhole")
                pinhole, f_number = True, MAX_F_NUMBER
            elif f_number < low:
                self.warn(where, f"aperture_radius {r:g} gives f/{f_number:.4g}, wider than float32 carries "
                          f"(f/{low:g}): f/{low:g} used")
                f_number = low
        low, high = FOCUS_DISTANCE_RANGE_M
        if not low <= focus <= high and not pinhole:
            self.warn(where, f"focus_distance {focus:g} is outside {low:g}-{high:g}: clamped")
        focus = min(max(focus, low), high)
        return ThinLensCamera(
            position=tuple(float(v) for v in position),
            look_at=tuple(float(v) for v in position + forward),
            up=tuple(float(v) for v in up),
            focal_length_mm=float(focal_mm),
            f_number=float(f_number),
            focus_distance_m=float(focus),
            sensor_mm=(SENSOR_WIDTH_MM, SENSOR_WIDTH_MM * height / width),
            resolution=(width, height),
            pinhole=pinhole,
            # Mitsuba's thin lens exactly: focus measured from the lens, the sensor one focal length behind it
            # at every focus, the field of view across the image's width.
            focus_from="lens",
            focus_breathing=False,
            sensor_fit="horizontal",
        )

    def _bounds_corners(self) -> np.ndarray:
        from lenslab.scene.io.meshes import MeshLoadError, load_mesh

        points = []
        for root in self.nodes:
            for node, matrix in root.walk():
                shape = node.shape
                if shape is None:
                    continue
                if isinstance(shape, Sphere):
                    r = shape.radius
                    local = np.array([[x, y, z] for x in (-r, r) for y in (-r, r) for z in (-r, r)])
                elif isinstance(shape, (Rectangle, Box, Disk, Cylinder)):
                    local = shape.mesh().vertices
                else:
                    path = Path(shape.file)
                    path = path if path.is_absolute() else self.root_folder / path
                    try:
                        v = load_mesh(path, shape.smooth, shape.shape_index).vertices
                    except MeshLoadError as exc:
                        raise SceneError(f"{exc}") from None
                    lo, hi = v.min(axis=0), v.max(axis=0)
                    local = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
                points.append(transform_points(matrix, local))
        return np.concatenate(points) if points else np.zeros((0, 3))

    def _default_camera(self) -> _Camera:
        """A camera for a scene without a (supported) sensor, placed as Mitsuba 2 placed its default one:
        45 degrees, looking down +Z at the whole scene. (Mitsuba 3.9 itself renders nothing without one.)"""
        if not self._unsupported_sensor:
            self.warn(self.root, "no sensor: a 45-degree camera looking down +Z at the whole scene is used")
        corners = self._bounds_corners()
        if len(corners) == 0:
            return _Camera(None, np.eye(4), 45.0, None, 1e4)
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        center, extents = (lo + hi) / 2, hi - lo
        distance = extents.max() / (2 * math.tan(math.radians(45 / 2)))
        origin = (center[0], center[1], lo[2] - distance)
        return _Camera(None, mv.translate_matrix(origin), 45.0, None, distance + extents[2] / 2)


def _parse_fov(p: Props, aspect: float) -> float:
    """Mitsuba's ``parse_fov``: the horizontal field of view in degrees."""
    if p.has("fov") and p.has("focal_length"):
        raise ValueError("give either a focal length ('focal_length') or a field of view ('fov'), not both")
    if p.has("fov"):
        fov = p.float("fov")
        axis = (p.string("fov_axis", "x") or "x").lower()
        if axis == "smaller":
            axis = "y" if aspect > 1 else "x"
        elif axis == "larger":
            axis = "x" if aspect > 1 else "y"
    else:
        text = p.string("focal_length", "50mm").strip()
        if text.endswith("mm"):
            text = text[:-2]
        try:
            value = mv.parse_number(text)
        except ValueError:
            raise ValueError(f"could not parse the focal length '{text}' (expected <x>mm)") from None
        if value <= 0:
            raise ValueError(f"the focal length must be positive, not '{text}mm'")
        fov = 2 * math.degrees(math.atan(math.hypot(36.0, 24.0) / (2 * value)))
        axis = "diagonal"
    half = math.radians(fov) / 2
    if axis == "x":
        result = fov
    elif axis == "y":
        result = math.degrees(2 * math.atan(math.tan(half) * aspect))
    elif axis == "diagonal":
        width = 2 * math.tan(half) / math.sqrt(1 + 1 / (aspect * aspect))
        result = math.degrees(2 * math.atan(width / 2))
    else:
        raise ValueError("fov_axis must be one of 'x', 'y', 'diagonal', 'smaller' or 'larger'")
    if not 0 < result < 180:
        raise ValueError(f"the horizontal field of view ({result:g} degrees) must lie between 0 and 180")
    return result


def _fmt(rgb) -> str:
    return "(" + ", ".join(f"{c:.3g}" for c in rgb) + ")"


def _clip_rgb(rgb) -> RGB:
    return tuple(float(min(max(c, 0.0), 1e9)) for c in rgb)  # type: ignore[return-value]


# ---------------------------------------------------------------------------------------------------------
# Entry points
# ---------------------------------------------------------------------------------------------------------
def _default_warn(message: str) -> None:
    log.warning("%s", message)


def _load(root_loader, display: str, folder: Path, source_path: Path | None,
          defines: dict[str, str] | None, warn: WarnCallback | None) -> Scene:
    warn = warn or _default_warn
    expander = _Expander({k: str(v) for k, v in (defines or {}).items()})
    root = root_loader(expander)
    expanded = expander.expand(root, 0)[0]
    for name in sorted(set(defines or {}) - expander.used):
        warn(f"{display}: -D {name}={defines[name]} is not used by the scene")
    importer = MitsubaImporter(expanded, expander.ids, folder, warn)
    importer.run()
    camera = importer.make_camera()
    return Scene(
        camera=camera,
        environment=importer.environment,
        render=importer.render,
        materials=importer.materials,
        nodes=importer.nodes,
        lights=importer.lights,
        source_path=source_path,
    )


def load_mitsuba_scene(path: str | os.PathLike, defines: dict[str, str] | None = None,
                       warn: WarnCallback | None = None) -> Scene:
    """Read a Mitsuba 3 XML scene.

    ``defines``: ``$name`` values, as ``mitsuba -D name=value`` (they win over ``<default>``).
    ``warn``: called with one line per thing LensLab approximates or leaves out (``file:line: <element>:
    what was done``); by default they go to the ``lenslab.import`` logger as warnings.
    Raises :class:`SceneError` (file and line in its message) for a file Mitsuba would reject too.
    """
    path = Path(path)
    if not os.path.isfile(path):
        raise SceneError(f"{path}: {not_a_file(path) or 'no such scene file'}")
    folder = path.resolve().parent
    return _load(lambda ex: ex.parse_file(path), str(path), folder, path.resolve(), defines, warn)


def load_mitsuba_string(text: str, base_dir: str | os.PathLike | None = None, defines: dict[str, str] | None = None,
                        warn: WarnCallback | None = None, name: str = "<string>") -> Scene:
    """Read a Mitsuba scene held in a string; relative files resolve against ``base_dir`` (default: cwd).
    The scene's ``source_path`` is a (not existing) file in ``base_dir`` so that mesh paths resolve."""
    folder = Path(base_dir or Path.cwd()).resolve()
    source = folder / "scene.xml"
    return _load(lambda ex: _parse_xml(text.encode("utf-8"), name, folder), name, folder, source, defines, warn)
