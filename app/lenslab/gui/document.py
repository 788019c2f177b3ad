"""The open scene: the data, where it lives on disk, its undo history, the selection and the lens in use.

Every edit goes through :class:`Document` as an undo command (``lenslab.gui.commands``), and every command says
what it changed with a :class:`~lenslab.scene.events.SceneChange` on ``document.events``; the outliner, the
property editor, the camera panel and the render worker's feeder listen there (napari style: the scene
classes themselves know nothing of Qt). ``changed`` re-emits the same change as a Qt signal for widgets that
prefer one.

Things inside the scene are addressed by *targets*, small tuples that stay valid across undo and redo:
``("camera",)``, ``("environment",)``, ``("render",)``, ``("material", name)`` and ``("node", path)`` where
``path`` is the tuple of child indices from the scene's root list (``(0, 2)`` = third child of the first node).
A *field* is an attribute path inside a target: ``("transform", "translate")``, ``("shape", "radius")``; the
empty field ``()`` means the target object itself (replacing a material by one of another type).
"""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path
from typing import Any, Iterator

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack

from lenslab.optics import LensPreset
from lenslab.resources import scenes_dir
from lenslab.scene.events import SceneChange, SceneEvents
from lenslab.scene.scene import Node, Scene

CAMERA = ("camera",)
ENVIRONMENT = ("environment",)
RENDER = ("render",)

_KIND_OF_TARGET = {"camera": "camera", "environment": "environment", "render": "render", "material": "material",
                   "node": "node", "light": "light"}


def node_target(path) -> tuple:
    return ("node", tuple(path))


def material_target(name: str) -> tuple:
    return ("material", name)


def describe_target(target: tuple) -> str:
    if target[0] in ("node", "light"):
        return target[0]
    if target[0] == "material":
        return f"material '{target[1]}'"
    return target[0]


def is_shipped(path: Path | None) -> bool:
    """True for the scenes that come with LensLab: they open as templates, never overwritten by Save."""
    if path is None:
        return False
    try:
        Path(path).resolve().relative_to(scenes_dir().resolve())
        return True
    except ValueError:
        return False


class Document(QObject):
    changed = Signal(object)  # SceneChange, after the scene has changed
    selection_changed = Signal()
    file_changed = Signal()  # the path, the title or the modified state changed
    lens_changed = Signal()

    def __init__(self, scene: Scene, path: Path | None = None, parent: QObject | None = None):
        super().__init__(parent)
        self.events = SceneEvents()
        self.events.changed.connect(self.changed.emit)
        self.undo_stack = QUndoStack(self)
        self.undo_stack.cleanChanged.connect(lambda _clean: self.file_changed.emit())
        self.scene = scene
        self.path: Path | None = None
        self.display_name = "Untitled"
        self.selection: list[tuple] = []
        self.lens: LensPreset | None = None
        self._set_path(path, scene)

    # -- file ------------------------------------------------------------------------------------------------
    def _set_path(self, path: Path | None, scene: Scene) -> None:
        if path is not None and is_shipped(path):
            # A shipped scene is a template: edits go to a new file chosen at the first save.
            self.path = None
            self.display_name = Path(path).parent.name if Path(path).name == "scene.json" else Path(path).stem
        elif path is not None:
            self.path = Path(path)
            self.display_name = self.path.parent.name if self.path.name == "scene.json" else self.path.stem
        else:
            self.path = None
            self.display_name = "Untitled"

    def replace(self, scene: Scene, path: Path | None) -> None:
        """Show another scene (File > Open, New): history and selection start afresh."""
        self.scene = scene
        self._set_path(path, scene)
        self.undo_stack.clear()
        self.undo_stack.setClean()
        self.selection = []
        self.lens = None
        self.lens_changed.emit()
        self.selection_changed.emit()
        self.notify(SceneChange("scene"))
        self.file_changed.emit()

    def saved_as(self, path: Path) -> None:
        self.path = Path(path)
        self.scene.source_path = self.path.resolve()
        self.display_name = self.path.parent.name if self.path.name == "scene.json" else self.path.stem
        self.undo_stack.setClean()
        self.file_changed.emit()

    @property
    def modified(self) -> bool:
        return not self.undo_stack.isClean()

    # -- change notification ---------------------------------------------------------------------------------
    def notify(self, change: SceneChange) -> None:
        self.events.changed.emit(change)

    def notify_target(self, target: tuple, field: tuple = ()) -> None:
        self.notify(SceneChange(_KIND_OF_TARGET[target[0]], target, tuple(field)))

    # -- addressing ------------------------------------------------------------------------------------------
    def node(self, path) -> Node:
        nodes = self.scene.nodes
        node = None
        for index in path:
            node = nodes[index]
            nodes = node.children
        if node is None:
            raise KeyError("empty node path")
        return node

    def children_of(self, parent_path) -> list[Node]:
        return self.node(parent_path).children if parent_path else self.scene.nodes

    def resolve(self, target: tuple) -> Any:
        kind = target[0]
        if kind == "camera":
            return self.scene.camera
        if kind == "environment":
            return self.scene.environment
        if kind == "render":
            return self.scene.render
        if kind == "material":
            return self.scene.materials[target[1]]
        if kind == "node":
            return self.node(target[1])
        if kind == "light":
            return self.scene.lights[target[1]]
        raise KeyError(f"unknown target {target!r}")

    def exists(self, target: tuple) -> bool:
        try:
            self.resolve(target)
            return True
        except (KeyError, IndexError):
            return False

    def get_value(self, target: tuple, field: tuple) -> Any:
        obj = self.resolve(target)
        for name in field:
            obj = getattr(obj, name)
        return obj

    def apply_value(self, target: tuple, field: tuple, value: Any, notify: bool = True) -> None:
        """Set a value without recording it (commands call this from redo and undo)."""
        value = copy.deepcopy(value)
        if not field:
            kind = target[0]
            if kind == "material":
                self.scene.materials[target[1]] = value
            elif kind in ("camera", "environment", "render"):
                setattr(self.scene, kind, value)
            elif kind == "node":
                parent, index = target[1][:-1], target[1][-1]
                self.children_of(parent)[index] = value
            elif kind == "light":
                self.scene.lights[target[1]] = value
        else:
            obj = self.resolve(target)
            for name in field[:-1]:
                obj = getattr(obj, name)
            setattr(obj, field[-1], value)
        if notify:
            self.notify_target(target, field)

    # -- nodes -----------------------------------------------------------------------------------------------
    def node_paths(self) -> list[tuple[int, ...]]:
        """Every node's path, depth first: the order of ``Scene.walk`` and of the renderer's node indices."""
        out: list[tuple[int, ...]] = []

        def visit(nodes: list[Node], prefix: tuple[int, ...]) -> None:
            for i, node in enumerate(nodes):
                out.append(prefix + (i,))
                visit(node.children, prefix + (i,))

        visit(self.scene.nodes, ())
        return out

    def walk_nodes(self) -> Iterator[tuple[tuple[int, ...], Node]]:
        for path in self.node_paths():
            yield path, self.node(path)

    def subtree_indices(self, path) -> list[int]:
        """Depth-first indices of a node and all its descendants (what the viewport outlines for it)."""
        path = tuple(path)
        return [i for i, p in enumerate(self.node_paths()) if p[: len(path)] == path]

    def material_users(self, name: str) -> list[tuple[int, ...]]:
        return [path for path, node in self.walk_nodes() if node.material == name]

    def unique_node_name(self, base: str) -> str:
        names = {node.name for _, node in self.walk_nodes()}
        return _unique(base, names)

    def unique_material_name(self, base: str) -> str:
        return _unique(base, set(self.scene.materials))

    def unique_light_name(self, base: str) -> str:
        return _unique(base, {light.name for light in self.scene.lights})

    # -- selection -------------------------------------------------------------------------------------------
    def set_selection(self, targets: list[tuple]) -> None:
        targets = [t for t in dict.fromkeys(tuple(t) for t in targets) if self.exists(t)]
        if targets != self.selection:
            self.selection = targets
            self.selection_changed.emit()

    def selected_node_paths(self) -> list[tuple[int, ...]]:
        return [t[1] for t in self.selection if t[0] == "node"]

    # -- lens -------------------------------------------------------------------------------------------------
    def set_lens_state(self, lens: LensPreset | None) -> None:
        if lens != self.lens:
            self.lens = lens
            self.lens_changed.emit()

    # -- editing (every method pushes an undo command) -------------------------------------------------------
    def set_value(self, target: tuple, field: tuple, value: Any, text: str | None = None, merge: bool = False) -> None:
        from lenslab.gui.commands import SetValuesCommand

        self.set_values(target, {tuple(field): value}, text, merge)

    def set_values(self, target: tuple, changes: dict[tuple, Any], text: str | None = None, merge: bool = False) -> None:
        from lenslab.gui.commands import SetValuesCommand

        changes = {tuple(k): v for k, v in changes.items() if self.get_value(target, tuple(k)) != v}
        if not changes:
            return
        self.undo_stack.push(SetValuesCommand(self, target, changes, text, merge))

    def set_camera(self, text: str | None = None, merge: bool = False, **changes: Any) -> None:
        self.set_values(CAMERA, {(k,): v for k, v in changes.items()}, text, merge)

    def push(self, command) -> None:
        self.undo_stack.push(command)


def _unique(base: str, taken: set[str]) -> str:
    if base not in taken:
        return base
    stem = base.rstrip("0123456789").rstrip(".") or base
    i = 1
    while f"{stem}.{i:03d}" in taken:
        i += 1
    return f"{stem}.{i:03d}"


def copy_scene(scene: Scene) -> Scene:
    """An independent copy for another thread (the renderer never sees an object the GUI may still edit)."""
    out = copy.deepcopy(scene)
    out.source_path = scene.source_path
    return out


def camera_copy(scene: Scene):
    return dataclasses.replace(scene.camera)
