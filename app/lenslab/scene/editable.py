"""The scene open for editing: the data, the events that announce each edit, and addressing by target.

:class:`EditableScene` is the model the studio's widgets observe, napari style: whoever edits it (an undo
command, a script) sets values through :meth:`EditableScene.apply_value` or says what it changed with
:meth:`EditableScene.notify`, and every observer connected to ``events.changed`` hears a
:class:`~lenslab.scene.events.SceneChange`. Nothing here imports Qt; the studio's ``Document`` adds what is
Qt's (the undo stack, the selection, the file) around one of these.

Things inside the scene are addressed by *targets*, small tuples that stay valid across undo and redo:
``("camera",)``, ``("environment",)``, ``("render",)``, ``("material", name)``, ``("light", index)`` and
``("node", path)`` where ``path`` is the tuple of child indices from the scene's root list (``(0, 2)`` = third
child of the first node). A *field* is an attribute path inside a target: ``("transform", "translate")``,
``("shape", "radius")``; the empty field ``()`` means the target object itself (replacing a material by one of
another type).
"""

from __future__ import annotations

import copy
from typing import Any, Iterator

from lenslab.scene.events import SceneChange, SceneEvents
from lenslab.scene.scene import Node, Scene

CAMERA = ("camera",)

# A target's kind is the kind of change that editing it announces.
_CHANGE_KIND_OF_TARGET = {"camera": "camera", "environment": "environment", "render": "render",
                          "material": "material", "node": "node", "light": "light"}


class EditableScene:
    """One scene being edited and the events that say what changed in it."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.events = SceneEvents()

    def replace(self, scene: Scene) -> None:
        """Edit another scene from now on (File > Open, New); observers stay connected."""
        self.scene = scene
        self.notify(SceneChange("scene"))

    # -- announcing ------------------------------------------------------------------------------------------
    def notify(self, change: SceneChange) -> None:
        self.events.changed.emit(change)

    def notify_target(self, target: tuple, field: tuple = ()) -> None:
        self.notify(SceneChange(_CHANGE_KIND_OF_TARGET[target[0]], tuple(target), tuple(field)))

    # -- nodes by path -----------------------------------------------------------------------------------------
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

    # -- names ---------------------------------------------------------------------------------------------
    def unique_node_name(self, base: str) -> str:
        return unique_name(base, {node.name for _, node in self.walk_nodes()})

    def unique_material_name(self, base: str) -> str:
        return unique_name(base, set(self.scene.materials))

    def unique_light_name(self, base: str) -> str:
        return unique_name(base, {light.name for light in self.scene.lights})

    # -- targets ---------------------------------------------------------------------------------------------
    def resolve(self, target: tuple) -> Any:
        kind = target[0]
        if kind in ("camera", "environment", "render"):
            return getattr(self.scene, kind)
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
        """Set a value (a copy of it) and announce it; undo commands call this from redo and undo."""
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


def unique_name(base: str, taken: set[str]) -> str:
    """``base``, or ``base.001``, ``base.002`` ... (Blender's way) if that is taken; a trailing number of
    ``base`` is replaced, not extended."""
    if base not in taken:
        return base
    stem = base.rstrip("0123456789").rstrip(".") or base
    i = 1
    while f"{stem}.{i:03d}" in taken:
        i += 1
    return f"{stem}.{i:03d}"
