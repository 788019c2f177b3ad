"""Undo commands: every edit the studio makes to a scene is one of these, pushed on the document's QUndoStack.

Commands address what they change by target and field (see ``lenslab.scene.editable``), never by holding on to
objects, so that any order of undo and redo finds the right thing. Values are deep-copied in and out. Each
announces what it changed on the scene's own events (``doc.model``), whichever way it runs.

Consecutive edits of the same fields from a spin box's arrows or a slider's keys merge into one step
(``mergeWith``) when they arrive within :data:`MERGE_SECONDS` of each other, so one Ctrl+Z undoes one gesture. The
edits of one mouse drag carry the drag's *gesture* (a token the control gives them from the press to the release):
they merge however long the hand pauses on the way, and never with another drag's. A step's text (the History
panel's row) names the value it sets, and a merged step takes the text of the last edit it took in: a drag from f/4
to f/22 reads "Aperture f/22", the value that row restores.
"""

from __future__ import annotations

import copy
import time
from typing import Any

from PySide6.QtGui import QUndoCommand

from lenslab.optics import LensPreset, format_distance, format_f_number, format_focal_length
from lenslab.scene.editing import camera_changes_keeping_focus
from lenslab.scene.events import SceneChange
from lenslab.scene.lights import Light
from lenslab.scene.scene import Node

MERGE_SECONDS = 1.5
_SET_VALUES_ID = 1001

_FIELD_LABELS = {
    "f_number": "Aperture", "focal_length_mm": "Focal length", "focus_distance_m": "Focus distance",
    "sensor_mm": "Sensor", "aperture_blades": "Aperture blades", "blade_rotation_deg": "Blade rotation",
    "translate": "Move", "position": "Move", "rotate_deg": "Rotate", "scale": "Scale", "name": "Rename",
}
#: Labels that name what they act on: "Move tall box to ...", "Move camera to ...".
_NAMING_FIELDS = {"translate", "position", "rotate_deg", "scale", "name"}


#: How a value reads in a History row, for the fields photographers know by their own notation.
_VALUE_FORMATS = {"f_number": format_f_number, "focal_length_mm": format_focal_length,
                  "focus_distance_m": format_distance}
_VALUE_TEXT_LIMIT = 48


def _value_text(field: str, value: Any) -> str:
    """A value as a History row shows it: short, rounded, never a dataclass's repr."""
    if field in _VALUE_FORMATS and isinstance(value, (int, float)):
        return _VALUE_FORMATS[field](value)
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (tuple, list)) and all(isinstance(v, (int, float)) for v in value):
        return "(" + ", ".join(f"{v:.4g}" for v in value) + ")"
    if isinstance(value, str):
        text = value or "none"
    elif value is None:
        text = "none"
    else:
        text = getattr(value, "type_name", "") or type(value).__name__
    return text if len(text) <= _VALUE_TEXT_LIMIT else "…" + text[-(_VALUE_TEXT_LIMIT - 1):]


def _target_name(doc, target: tuple) -> str:
    if target[0] in ("node", "light"):
        return doc.model.resolve(target).name
    if target[0] == "material":
        return str(target[1])
    return {"render": "render settings"}.get(target[0], target[0])


def _label(doc, target: tuple, changes: dict) -> str:
    """The History text of an edit: what it sets and to what ("Move tall box to (0.2, 0.3, -0.1)")."""
    fields = list(changes)
    if len(fields) != 1:
        return "Edit " + _target_name(doc, target)
    field = fields[0]
    if not field:  # the whole thing: a material of another type, a camera put back as it was
        kind = getattr(changes[field], "type_name", "")
        return f"Set {_target_name(doc, target)}" + (f" to {kind}" if kind else "")
    leaf = field[-1]
    value = _value_text(leaf, changes[field])
    if leaf in _NAMING_FIELDS:
        return f"{_FIELD_LABELS[leaf]} {_target_name(doc, target)} to {value}"
    if leaf in _FIELD_LABELS:
        return f"{_FIELD_LABELS[leaf]} {value}"
    return f"Set {leaf.replace('_', ' ')} of {_target_name(doc, target)} to {value}"


class SetValuesCommand(QUndoCommand):
    """Set one or more fields of one target; ``gesture``: the mouse drag the edit is part of, if any."""

    def __init__(self, doc, target: tuple, changes: dict[tuple, Any], text: str | None = None, merge: bool = False,
                 gesture: object | None = None):
        super().__init__(text or _label(doc, target, changes))
        self.doc = doc
        self.target = tuple(target)
        self.new = {tuple(k): copy.deepcopy(v) for k, v in changes.items()}
        self.old = {k: copy.deepcopy(doc.model.get_value(self.target, k)) for k in self.new}
        self.merge = merge
        self.gesture = gesture
        self.stamp = time.monotonic()

    def redo(self) -> None:
        self._apply(self.new)

    def undo(self) -> None:
        self._apply(self.old)

    def _apply(self, values: dict) -> None:
        for field, value in values.items():
            self.doc.model.apply_value(self.target, field, value, notify=False)
        for field in values:
            self.doc.model.notify_target(self.target, field)

    def id(self) -> int:
        return _SET_VALUES_ID

    def continued_by(self, target: tuple, fields, merge: bool, gesture: object | None, stamp: float) -> bool:
        """Whether an edit of ``fields`` of ``target`` made at ``stamp`` belongs to this step."""
        if not (self.merge and merge) or tuple(target) != self.target or set(map(tuple, fields)) != set(self.new):
            return False
        if self.gesture is not None or gesture is not None:
            return gesture == self.gesture  # one drag, however long it takes; another drag is another step
        return stamp - self.stamp <= MERGE_SECONDS

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, SetValuesCommand) or \
                not self.continued_by(other.target, other.new, other.merge, other.gesture, other.stamp):
            return False
        self.new = other.new
        self.stamp = other.stamp
        self.setText(other.text())  # the value this step now sets, and its History row restores
        if self.new == self.old:
            self.setObsolete(True)
        return True


def value_before_step(doc, target: tuple, field: tuple, fields, merge: bool, gesture: object | None = None) -> Any:
    """The value ``field`` of ``target`` had before the History's newest step, when an edit of ``fields`` made now
    would merge into that step; its value now otherwise. An edit that works out one value from another (a focal
    length that moves the focus out) starts from there, so that what the step passed through on the way leaves no
    trace at its end."""
    now = doc.model.get_value(target, field)
    stack = doc.undo_stack
    index = stack.index()
    if index == 0 or index == stack.cleanIndex():  # QUndoStack never merges into the state a file was saved at
        return now
    step = stack.command(index - 1)
    merging = isinstance(step, SetValuesCommand) and step.id() == _SET_VALUES_ID and \
        step.continued_by(target, fields, merge, gesture, time.monotonic())
    return copy.deepcopy(step.old.get(tuple(field), now)) if merging else now


def push_values(doc, target: tuple, changes: dict, text: str | None = None, merge: bool = False,
                gesture: object | None = None) -> None:
    """Set ``changes`` as one step, for an edit that may be part of a mouse drag (``gesture``): all the fields,
    when any of them changes. A control that sets two fields (a focal length and the focus it moves out) sets both
    every time, so its edits always name the same fields, and those of one gesture merge."""
    if any(doc.model.get_value(target, tuple(k)) != v for k, v in changes.items()):
        doc.push(SetValuesCommand(doc, target, changes, text, merge, gesture))


class LensCommand(QUndoCommand):
    """Mount a lens preset (or none): it sets the focal length, clamps the aperture, sets the iris and moves the
    focus out to the lens's minimum if it was nearer. A real lens names itself as the camera's ``real_lens`` and
    sets the thin lens's stand-ins for glass aside (``LensPreset.mount``); none, or a thin-lens preset, takes a
    real lens off."""

    def __init__(self, doc, lens: LensPreset | None):
        super().__init__(f"Lens {lens.name}" if lens else "No lens limits")
        self.doc = doc
        self.old_lens, self.new_lens = doc.lens, lens
        cam = doc.scene.camera
        changes = {}
        if lens is not None:
            changes = camera_changes_keeping_focus(cam, lens, **lens.mount(cam.focal_length_mm, cam.f_number))
        elif cam.real_lens:  # Free: no limits, and the thin lens again
            changes = camera_changes_keeping_focus(cam, None, real_lens="")
        self.old = {k: getattr(cam, k) for k in changes}
        self.new = changes

    def _apply(self, lens, values) -> None:
        for key, value in _mounting_order(self.doc.scene.camera, values):
            self.doc.model.apply_value(("camera",), (key,), value, notify=False)
        self.doc.set_lens_state(lens)
        self.doc.model.notify(SceneChange("camera", ("camera",), ("focal_length_mm",)))

    def redo(self) -> None:
        self._apply(self.new_lens, self.new)

    def undo(self) -> None:
        self._apply(self.old_lens, self.old)


def _mounting_order(camera, values: dict) -> list[tuple[str, Any]]:
    """``values`` in an order that never leaves the camera one ``validate`` refuses between two of them: a real
    lens comes off first (a thin lens takes any f-number, squeeze or aperture image), and the new one goes on last,
    once the f-number is within it and the thin lens's stand-ins are set aside. Changing one real lens for another
    passes through the thin lens."""
    values = dict(values)
    new_lens = values.pop("real_lens", camera.real_lens)
    if new_lens == camera.real_lens:
        return list(values.items())
    off = [("real_lens", "")] if camera.real_lens else []
    on = [("real_lens", new_lens)] if new_lens else []
    return off + list(values.items()) + on


class AddNodeCommand(QUndoCommand):
    def __init__(self, doc, node: Node, parent_path: tuple = (), index: int | None = None, text: str | None = None):
        super().__init__(text or f"Add {node.name}")
        self.doc = doc
        self.node = copy.deepcopy(node)
        self.parent_path = tuple(parent_path)
        self.index = len(doc.model.children_of(self.parent_path)) if index is None else index
        self.old_selection = list(doc.selection)

    @property
    def path(self) -> tuple:
        return self.parent_path + (self.index,)

    def redo(self) -> None:
        self.doc.model.children_of(self.parent_path).insert(self.index, copy.deepcopy(self.node))
        self.doc.model.notify(SceneChange("structure", ("node", self.path)))
        self.doc.set_selection([("node", self.path)])

    def undo(self) -> None:
        del self.doc.model.children_of(self.parent_path)[self.index]
        self.doc.set_selection([t for t in self.old_selection if self.doc.model.exists(t)])
        self.doc.model.notify(SceneChange("structure", ("node", self.parent_path)))


class RemoveNodesCommand(QUndoCommand):
    def __init__(self, doc, paths: list[tuple]):
        paths = _outermost(sorted({tuple(p) for p in paths}))
        names = [doc.model.node(p).name for p in paths]
        super().__init__("Delete " + (names[0] if len(names) == 1 else f"{len(names)} nodes"))
        self.doc = doc
        self.removed = [(p, copy.deepcopy(doc.model.node(p))) for p in paths]
        self.old_selection = list(doc.selection)

    def redo(self) -> None:
        for path, _node in sorted(self.removed, reverse=True):  # deepest and last first: paths stay valid
            del self.doc.model.children_of(path[:-1])[path[-1]]
        self.doc.set_selection([])
        self.doc.model.notify(SceneChange("structure"))

    def undo(self) -> None:
        for path, node in sorted(self.removed):
            self.doc.model.children_of(path[:-1]).insert(path[-1], copy.deepcopy(node))
        self.doc.set_selection(self.old_selection)
        self.doc.model.notify(SceneChange("structure"))


class AddLightCommand(QUndoCommand):
    """Add a point light or a sun (lights that are not shapes: the scene's list of lights)."""

    def __init__(self, doc, light: Light):
        super().__init__(f"Add {light.name}")
        self.doc = doc
        self.light = copy.deepcopy(light)
        self.index = len(doc.scene.lights)
        self.old_selection = list(doc.selection)

    def redo(self) -> None:
        self.doc.scene.lights.insert(self.index, copy.deepcopy(self.light))
        self.doc.model.notify(SceneChange("structure", ("light", self.index)))
        self.doc.set_selection([("light", self.index)])

    def undo(self) -> None:
        del self.doc.scene.lights[self.index]
        self.doc.set_selection([t for t in self.old_selection if self.doc.model.exists(t)])
        self.doc.model.notify(SceneChange("structure"))


class RemoveLightsCommand(QUndoCommand):
    def __init__(self, doc, indices: list[int]):
        indices = sorted(set(indices))
        names = [doc.scene.lights[i].name for i in indices]
        super().__init__("Delete " + (names[0] if len(names) == 1 else f"{len(names)} lights"))
        self.doc = doc
        self.removed = [(i, copy.deepcopy(doc.scene.lights[i])) for i in indices]
        self.old_selection = list(doc.selection)

    def redo(self) -> None:
        for index, _light in reversed(self.removed):  # last first: the other indices stay valid
            del self.doc.scene.lights[index]
        self.doc.set_selection([t for t in self.doc.selection if t[0] != "light"])
        self.doc.model.notify(SceneChange("structure"))

    def undo(self) -> None:
        for index, light in self.removed:
            self.doc.scene.lights.insert(index, copy.deepcopy(light))
        self.doc.set_selection(self.old_selection)
        self.doc.model.notify(SceneChange("structure"))


def _outermost(paths: list[tuple]) -> list[tuple]:
    """Drop paths inside another path of the list (deleting a group deletes its children)."""
    out: list[tuple] = []
    for p in paths:
        if not any(p[: len(q)] == q for q in out):
            out.append(p)
    return out


class MoveNodeCommand(QUndoCommand):
    """Re-parent or re-order a node (outliner drag and drop), optionally with a new local transform that keeps
    it where it was in the world."""

    def __init__(self, doc, src: tuple, dst_parent: tuple, dst_index: int, transform=None):
        node = doc.model.node(src)
        super().__init__(f"Move {node.name}")
        self.doc = doc
        self.src = tuple(src)
        self.dst_parent = tuple(dst_parent)
        self.dst_index = dst_index
        self.old_transform = copy.deepcopy(node.transform)
        self.new_transform = copy.deepcopy(transform) if transform is not None else self.old_transform
        # Where the node ends up, once it has left its old place (which may shift the destination's index).
        parent = self.dst_parent
        index = dst_index
        src_parent, src_index = self.src[:-1], self.src[-1]
        if parent[: len(src_parent) + 1][:-1] == src_parent and len(parent) > len(src_parent) and \
                parent[len(src_parent)] > src_index:
            parent = parent[: len(src_parent)] + (parent[len(src_parent)] - 1,) + parent[len(src_parent) + 1:]
        if parent == src_parent and index > src_index:
            index -= 1
        self.final = parent + (index,)

    def redo(self) -> None:
        node = self.doc.model.children_of(self.src[:-1]).pop(self.src[-1])
        node.transform = copy.deepcopy(self.new_transform)
        self.doc.model.children_of(self.final[:-1]).insert(self.final[-1], node)
        self.doc.model.notify(SceneChange("structure", ("node", self.final)))
        self.doc.set_selection([("node", self.final)])

    def undo(self) -> None:
        node = self.doc.model.children_of(self.final[:-1]).pop(self.final[-1])
        node.transform = copy.deepcopy(self.old_transform)
        self.doc.model.children_of(self.src[:-1]).insert(self.src[-1], node)
        self.doc.model.notify(SceneChange("structure", ("node", self.src)))
        self.doc.set_selection([("node", self.src)])


class AddMaterialCommand(QUndoCommand):
    def __init__(self, doc, name: str, material, assign_to: list[tuple] = ()):
        super().__init__(f"Add material {name}")
        self.doc = doc
        self.name = name
        self.material = copy.deepcopy(material)
        self.assign = [(tuple(p), doc.model.node(p).material) for p in assign_to]

    def redo(self) -> None:
        self.doc.scene.materials[self.name] = copy.deepcopy(self.material)
        for path, _old in self.assign:
            self.doc.model.node(path).material = self.name
        self.doc.model.notify(SceneChange("structure", ("material", self.name)))

    def undo(self) -> None:
        for path, old in self.assign:
            self.doc.model.node(path).material = old
        del self.doc.scene.materials[self.name]
        self.doc.set_selection([t for t in self.doc.selection if self.doc.model.exists(t)])
        self.doc.model.notify(SceneChange("structure"))


class RemoveMaterialCommand(QUndoCommand):
    """Delete a material; nodes that used it fall back to the default grey (and get it back on undo)."""

    def __init__(self, doc, name: str):
        super().__init__(f"Delete material {name}")
        self.doc = doc
        self.name = name
        self.material = copy.deepcopy(doc.scene.materials[name])
        self.position = list(doc.scene.materials).index(name)
        self.users = doc.model.material_users(name)

    def redo(self) -> None:
        del self.doc.scene.materials[self.name]
        for path in self.users:
            self.doc.model.node(path).material = ""
        self.doc.set_selection([t for t in self.doc.selection if self.doc.model.exists(t)])
        self.doc.model.notify(SceneChange("structure"))

    def undo(self) -> None:
        items = list(self.doc.scene.materials.items())
        items.insert(self.position, (self.name, copy.deepcopy(self.material)))
        self.doc.scene.materials.clear()
        self.doc.scene.materials.update(items)
        for path in self.users:
            self.doc.model.node(path).material = self.name
        self.doc.model.notify(SceneChange("structure", ("material", self.name)))


class RenameMaterialCommand(QUndoCommand):
    """Rename a material, keeping its place in the library and every node that refers to it."""

    def __init__(self, doc, old: str, new: str):
        super().__init__(f"Rename material {old} to {new}")
        self.doc = doc
        self.old, self.new = old, new
        self.users = doc.model.material_users(old)

    def _rename(self, a: str, b: str) -> None:
        items = [(b if k == a else k, v) for k, v in self.doc.scene.materials.items()]
        self.doc.scene.materials.clear()
        self.doc.scene.materials.update(items)
        for path in self.users:
            self.doc.model.node(path).material = b
        self.doc.selection = [("material", b) if t == ("material", a) else t for t in self.doc.selection]
        self.doc.model.notify(SceneChange("structure", ("material", b)))
        self.doc.selection_changed.emit()

    def redo(self) -> None:
        self._rename(self.old, self.new)

    def undo(self) -> None:
        self._rename(self.new, self.old)
