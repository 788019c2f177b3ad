"""What the studio's editing operations do, decided without a GUI.

Each function looks at an :class:`~lenslab.scene.editable.EditableScene` and returns what an edit should be:
the node to add and where it goes, the focus distance that makes a selection sharp, the transform that keeps a
re-parented node where it is, the file names a save must rewrite. None of them changes the scene: the studio
wraps what they return in undo commands (``lenslab.gui.commands``); a script may apply it directly. Camera
geometry comes from the camera's frame (``ThinLensCamera.frame()``), its one home. No Qt here
(tests/test_editing.py checks).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np

from lenslab.optics.thinlens import FOCUS_DISTANCE_RANGE_M
from lenslab.scene.camera import CameraFrame
from lenslab.scene.editable import EditableScene
from lenslab.scene.lights import Light, PointLight, SpotLight, SunLight
from lenslab.scene.materials import Diffuse, Emissive, Material
from lenslab.scene.scene import EnvironmentMap, Node, Scene
from lenslab.scene.shapes import Box, Cylinder, MeshFile, Rectangle, Sphere
from lenslab.scene.textures import ImageTexture
from lenslab.scene.transform import Transform

#: What Edit > Add makes; "light" is an area light (an emissive rectangle), "group" a node without a shape.
PRIMITIVES = ("group", "sphere", "box", "cylinder", "rectangle", "light")
#: The lights that are not shapes.
LIGHTS = ("point", "spot", "sun")


@dataclass(frozen=True)
class NewObject:
    """A node to add, and the material made for it (added first) if it needs one of its own."""

    node: Node
    material: tuple[str, Material] | None = None


# -- where new things go ---------------------------------------------------------------------------------------
def object_size(frame: CameraFrame) -> float:
    """The side of a new object, metres: 12 % of what the image spans at the plane of focus (at least 5 cm),
    so that it is in view and neither a speck nor a wall whatever the lens."""
    return max(0.05, view_width_at_focus(frame) * 0.12)


def view_width_at_focus(frame: CameraFrame) -> float:
    return frame.view_size_at(frame.focus_distance)[0]


def new_primitive(model: EditableScene, kind: str) -> NewObject:
    """A primitive at the point of focus (where the photographer is looking, and sharp); an area light faces
    down from above it with a bright emissive material of its own."""
    frame = model.scene.camera.frame()
    size = round(object_size(frame), 3)
    at = _rounded(frame.focus_point(), 4)
    if kind == "group":
        return NewObject(Node(model.unique_node_name("group"), Transform(), None))
    if kind == "sphere":
        return NewObject(Node(model.unique_node_name("sphere"), Transform(translate=at), Sphere(radius=size / 2)))
    if kind == "box":
        return NewObject(Node(model.unique_node_name("box"), Transform(translate=at), Box(size=(size, size, size))))
    if kind == "cylinder":  # standing: its axis (local +Z) turned to +Y, up in a LensLab scene
        return NewObject(Node(model.unique_node_name("cylinder"), Transform(translate=at, rotate_deg=(-90.0, 0.0, 0.0)),
                              Cylinder(radius=size / 2, height=size)))
    if kind == "rectangle":
        return NewObject(Node(model.unique_node_name("rectangle"), Transform(translate=at),
                              Rectangle(size=(size, size))))
    if kind == "light":
        above = _rounded(frame.focus_point() + frame.up * size * 3, 4)
        material = model.unique_material_name("light")
        node = Node(model.unique_node_name("area light"), Transform(translate=above, rotate_deg=(90.0, 0.0, 0.0)),
                    Rectangle(size=(size * 2, size * 2)), material)
        return NewObject(node, (material, Emissive(radiance=(10.0, 10.0, 10.0))))
    raise ValueError(f"unknown primitive {kind!r} (expected one of {', '.join(PRIMITIVES)})")


def new_light(model: EditableScene, kind: str) -> Light:
    """A point light above the point of focus, bright enough for an object of the new-object size there, a spot
    there aimed at it, or a sun from behind the camera's right shoulder."""
    frame = model.scene.camera.frame()
    if kind == "sun":
        direction = _rounded(0.5 * frame.right + frame.up + 0.7 * frame.back, 4)
        return SunLight(name=model.unique_light_name("sun"), direction=direction)
    if kind == "point":
        size = object_size(frame)
        at = _rounded(frame.focus_point() + frame.up * size * 4, 4)
        return PointLight(name=model.unique_light_name("point light"), position=at, intensity=(size * 40.0,) * 3)
    if kind == "spot":
        size = object_size(frame)
        at = _rounded(frame.focus_point() + frame.up * size * 4, 4)
        return SpotLight(name=model.unique_light_name("spot"), position=at, direction=_rounded(-frame.up, 4),
                         up=_rounded(frame.back, 4), intensity=(size * 40.0,) * 3)
    raise ValueError(f"unknown light {kind!r} (expected one of {', '.join(LIGHTS)})")


def new_material(model: EditableScene) -> tuple[str, Material]:
    return model.unique_material_name("material"), Diffuse()


def insertion_parent(model: EditableScene, selected: list[tuple]) -> tuple:
    """Where new objects go: into the selected group when exactly one group is selected, else the root."""
    if len(selected) == 1 and model.node(selected[0]).shape is None:
        return tuple(selected[0])
    return ()


def duplicate(model: EditableScene, path: tuple) -> Node:
    """A copy of the node at ``path`` (and its children) under a name of its own."""
    node = copy.deepcopy(model.node(path))
    node.name = model.unique_node_name(node.name)
    return node


# -- importing a mesh -------------------------------------------------------------------------------------------
def mesh_node(model: EditableScene, path: Path, vertices: np.ndarray,
              scene_file: Path | None = None) -> tuple[Node, float]:
    """A node for the mesh file ``path`` whose vertices are ``vertices`` (N, 3), and the scale it was given.

    It stands on its lowest point at the point of focus, scaled to 40 % of the view's width there when its own
    size is far off (a model in millimetres would otherwise fill the sky; one in kilometres be a speck), the
    scale rounded to three figures. The file is named relative to ``scene_file``'s folder when there is one."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    extent = float(np.max(hi - lo)) or 1.0
    frame = model.scene.camera.frame()
    wanted = view_width_at_focus(frame) * 0.4
    scale = 1.0 if wanted / 10 <= extent <= wanted * 1.5 else wanted / extent
    scale = float(f"{scale:.3g}")
    centre = (lo + hi) / 2
    at = frame.focus_point() - scale * centre
    at[1] += scale * (centre[1] - lo[1])  # standing on its lowest point at the focus point's height
    node = Node(model.unique_node_name(Path(path).stem),
                Transform(translate=_rounded(at, 5), scale=(scale, scale, scale)),
                MeshFile(file=file_reference(path, scene_file), smooth=True))
    return node, scale


def file_reference(path: Path, scene_file: Path | None) -> str:
    """How a scene names a file: relative to the scene file's folder when it has one, else absolute."""
    return relative_file_name(path, Path(scene_file).resolve().parent) if scene_file else str(Path(path).resolve())


def relative_file_name(path: Path, folder: Path) -> str:
    """``path`` named from ``folder`` (``../textures/wood.png``), or absolute where no relative name exists."""
    path = Path(path).resolve()
    try:
        return os.path.relpath(path, Path(folder).resolve())
    except ValueError:  # another drive (Windows)
        return str(path)


# -- focusing ---------------------------------------------------------------------------------------------------
def focus_distance_for(model: EditableScene, paths: Iterable[tuple], gbuffer=None) -> float | None:
    """The focus distance (in the camera's reference: from the sensor or the lens) that makes the nodes at
    ``paths`` sharp, rounded to 0.1 mm.

    With a depth buffer (``gbuffer``: per-pixel ``node_index`` and ``depth`` arrays, nodes numbered in
    ``model.node_paths()`` order, made since the node tree last changed), the median depth of the pixels the
    nodes and their children cover: the part of them the camera sees. Where they cover none (out of view, or
    no buffer), the depth of the first one's origin. None when that is behind the camera, or nearer than any
    lens focuses."""
    paths = [tuple(p) for p in paths]
    if not paths:
        return None
    distance = None
    if gbuffer is not None:
        indices = np.asarray([i for p in paths for i in model.subtree_indices(p)], np.int32)
        mask = np.isin(gbuffer.node_index, indices) & np.isfinite(gbuffer.depth)
        if mask.any():
            distance = float(np.median(gbuffer.depth[mask]))
    if distance is None:
        distance = model.scene.camera.frame().depth_of(world_matrix(model, paths[0])[:3, 3])
    camera = model.scene.camera
    if distance <= FOCUS_DISTANCE_RANGE_M[0] or (camera.focus_from == "sensor" and distance <= camera.focal_length_mm
                                                   / 1000):
        return None
    setting = camera.focus_setting_for(distance)
    return round(setting, 4) if setting >= camera.closest_focus_m else None


# -- scrubbing ----------------------------------------------------------------------------------------------------
def screen_drag_rate(model: EditableScene, target: tuple, picture_height_px: float) -> float | None:
    """How far one pixel of a drag moves the place of ``target`` (a node's translate, in its parent's units; a
    point or spot light's position) so that it moves on screen about as far as the mouse: the height the picture
    shows at the thing's depth over the height, in screen pixels, of the picture on screen. A cup on a table and a
    house across the street both follow the hand, at any focal length and zoom. At or behind the lens, the plane
    of focus's depth stands in. None for what has no place to move (a sun, a group's fields of another kind)."""
    frame = model.scene.camera.frame()
    if target[0] == "node":
        path = tuple(target[1])
        parent = world_matrix(model, path[:-1])
        point = (parent @ np.append(np.asarray(model.node(path).transform.translate, float), 1.0))[:3]
        parent_scale = abs(float(np.linalg.det(parent[:3, :3]))) ** (1.0 / 3.0)  # a scaled group's units
    elif target[0] == "light" and hasattr(model.resolve(target), "position"):
        point, parent_scale = np.asarray(model.resolve(target).position, float), 1.0
    else:
        return None
    depth = frame.depth_of(point)
    if not depth > 1e-3:
        depth = frame.focus_distance
    height = max(float(picture_height_px), 1.0)
    return frame.view_size_at(depth)[1] / height / max(parent_scale, 1e-9)


# -- transforms ---------------------------------------------------------------------------------------------------
def world_matrix(model: EditableScene, path: tuple) -> np.ndarray:
    """The 4x4 matrix from the node's own space to the world's; the identity for the root (the empty path)."""
    m = np.eye(4)
    for i in range(1, len(path) + 1):
        m = m @ model.node(path[:i]).transform.matrix()
    return m


def decompose(matrix: np.ndarray) -> Transform | None:
    """Translate, Euler XYZ rotation and scale of a 4x4 matrix; None when it holds a shear we cannot express."""
    t = matrix[:3, 3]
    a = matrix[:3, :3]
    scale = np.linalg.norm(a, axis=0)
    if np.any(scale < 1e-12):
        return None
    if np.linalg.det(a) < 0:
        scale[0] = -scale[0]
    r = a / scale
    ry = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    if abs(r[2, 0]) < 0.999999:
        rx = math.atan2(r[2, 1], r[2, 2])
        rz = math.atan2(r[1, 0], r[0, 0])
    else:  # gimbal lock: put it all in x
        rx = math.atan2(-r[1, 2], r[1, 1])
        rz = 0.0
    clean = lambda v: 0.0 if abs(v) < 1e-9 else float(round(v, 9))  # noqa: E731
    out = Transform(translate=tuple(clean(v) for v in t),
                    rotate_deg=tuple(clean(math.degrees(v)) for v in (rx, ry, rz)),
                    scale=tuple(clean(v) for v in scale))
    if not np.allclose(out.matrix(), matrix, atol=1e-6):
        return None
    return out


def can_move(src: tuple, dst_parent: tuple, index: int) -> bool:
    """False for a move into the node's own subtree, or to the place where it already is."""
    src, dst_parent = tuple(src), tuple(dst_parent)
    if dst_parent[: len(src)] == src:
        return False
    return not (dst_parent == src[:-1] and index in (src[-1], src[-1] + 1))


def reparented_transform(model: EditableScene, src: tuple, dst_parent: tuple) -> Transform | None:
    """The local transform that keeps the node at ``src`` where it is in the world once it is a child of
    ``dst_parent``. None when it keeps its own: it stays under the same parent, or the new parent's transform
    would need a shear that a :class:`Transform` cannot express."""
    src, dst_parent = tuple(src), tuple(dst_parent)
    if dst_parent == src[:-1]:
        return None
    return decompose(np.linalg.inv(world_matrix(model, dst_parent)) @ world_matrix(model, src))


# -- saving -----------------------------------------------------------------------------------------------------
#: Where a file name sits in the scene: (target, field), as undo commands address values.
FileField = tuple[tuple, tuple]


def file_fields(model: EditableScene) -> Iterator[FileField]:
    """Every file the scene names: mesh files, image textures of materials, the environment map."""
    for path, node in model.walk_nodes():
        if isinstance(node.shape, MeshFile):
            yield ("node", path), ("shape", "file")
    for name, material in model.scene.materials.items():
        for field in dataclasses.fields(material):
            if isinstance(getattr(material, field.name), ImageTexture):
                yield ("material", name), (field.name, "file")
    if isinstance(model.scene.environment, EnvironmentMap):
        yield ("environment",), ("file",)
    if model.scene.camera.aperture_image:
        yield ("camera",), ("aperture_image",)


def rebased_file_paths(model: EditableScene, new_folder: Path) -> dict[FileField, str]:
    """The file names that change when the scene is saved into ``new_folder``: each relative name
    re-expressed from there so that it still names the same file. Absolute names stay as they are."""
    old_folder = model.scene.base_dir().resolve()
    new_folder = Path(new_folder).resolve()
    if old_folder == new_folder:
        return {}
    out: dict[FileField, str] = {}
    for target, field in file_fields(model):
        name = model.get_value(target, field)
        if name and not Path(name).is_absolute():
            out[target, field] = relative_file_name(old_folder / name, new_folder)
    return out


def with_file_paths(scene: Scene, file_paths: dict[FileField, str]) -> Scene:
    """A copy of ``scene`` that names the given files at the given places; ``scene`` is untouched (a save
    writes the copy, so that a failed save leaves the open scene as it was)."""
    out = copy.deepcopy(scene)
    copy_model = EditableScene(out)
    for (target, field), name in file_paths.items():
        copy_model.apply_value(target, field, name, notify=False)
    return out


def _rounded(v, digits: int) -> tuple[float, ...]:
    """A point as plain floats, rounded so that the property editor shows what was meant (0.3, not
    0.30000000000000004)."""
    return tuple(float(round(c, digits)) for c in v)


# -- the camera ---------------------------------------------------------------------------------------------------
def camera_changes_keeping_focus(camera, lens=None, **changes) -> dict:
    """``changes`` to the camera, plus the focus moved out to the closest the new camera can focus if it was
    nearer (a longer focal length or a lens with a farther minimum cannot focus as close): the camera stays one
    the renderer can draw, and the user sees why in the focus field."""
    changed = dataclasses.replace(camera, **changes)
    closest = changed.closest_focus_with(lens)
    if changed.focus_distance_m < closest:
        changes = {**changes, "focus_distance_m": math.ceil(closest * 1e4) / 1e4}
    return changes
