"""The open scene as the studio holds it: the scene being edited, where it lives on disk, its undo history, the
selection and the lens in use.

The scene and its events belong to a Qt-free :class:`~lenslab.scene.editable.EditableScene` (``doc.model``):
every undo command (``lenslab.gui.commands``) edits through it and it announces each change as a
:class:`~lenslab.scene.events.SceneChange` on ``doc.model.events.changed``. The outliner, the property editor,
the camera panel and the render worker's feeder connect there directly (with :func:`listen`), napari style;
nothing re-emits those changes as Qt signals. What stays here is Qt's: the QUndoStack, the file's name and
modified state, and the selection and the lens, which are the studio's state rather than the scene's. Targets
and fields address things inside the scene as ``lenslab.scene.editable`` describes.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any, Callable

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack

from lenslab.optics import LensPreset
from lenslab.optics.lenses import find_lens
from lenslab.resources import scenes_dir
from lenslab.scene.editable import CAMERA, EditableScene
from lenslab.scene.events import EventEmitter
from lenslab.scene.scene import Scene


def is_shipped(path: Path | None) -> bool:
    """True for the scenes that come with LensLab: they open as templates, never overwritten by Save."""
    if path is None:
        return False
    try:
        Path(path).resolve().relative_to(scenes_dir().resolve())
        return True
    except ValueError:
        return False


def mounted_lens(scene: Scene) -> LensPreset | None:
    """The lens a scene opens with: the real lens its camera is traced through, as the lens list names it (a lens
    file's own entry where the camera names a file). A thin-lens preset leaves no trace in a scene, so any other
    camera opens with no lens limits (Free); so does one whose real lens cannot be found (the render says why)."""
    name = scene.camera.real_lens
    if not name:
        return None
    try:
        lens = find_lens(name)
    except ValueError:  # PresetError too: no such lens, or a broken lens file
        return None
    return lens if lens.is_real else None


def listen(emitter: EventEmitter, receiver: QObject, callback: Callable[[Any], None]) -> None:
    """Connect ``callback``, a method of the Qt object ``receiver``, to a scene event for as long as
    ``receiver`` lives. A Qt signal drops its connections to a destroyed receiver by itself; a plain emitter
    must be told, or it would call into a deleted widget."""
    emitter.connect(callback)
    receiver.destroyed.connect(lambda *_: emitter.disconnect(callback))


class Document(QObject):
    selection_changed = Signal()
    file_changed = Signal()  # the path, the title or the modified state changed
    lens_changed = Signal()

    def __init__(self, scene: Scene, path: Path | None = None, parent: QObject | None = None):
        super().__init__(parent)
        self.model = EditableScene(scene)
        self.undo_stack = QUndoStack(self)
        self.undo_stack.cleanChanged.connect(lambda _clean: self.file_changed.emit())
        self.path: Path | None = None
        self.display_name = "Untitled"
        self.selection: list[tuple] = []
        self.lens: LensPreset | None = mounted_lens(scene)
        self._set_path(path)

    @property
    def scene(self) -> Scene:
        return self.model.scene

    # -- file ------------------------------------------------------------------------------------------------
    def _set_path(self, path: Path | None) -> None:
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
        self._set_path(path)
        self.selection = []
        self.lens = mounted_lens(scene)
        self.undo_stack.clear()
        self.undo_stack.setClean()
        self.model.replace(scene)  # everything else is in place before anyone hears of it
        self.lens_changed.emit()
        self.selection_changed.emit()
        self.file_changed.emit()

    def saved_as(self, path: Path, file_paths: dict | None = None) -> None:
        """The scene has been written to ``path``; ``file_paths`` are the files (meshes, textures, the
        environment map) the written copy names differently (``lenslab.scene.editing.rebased_file_paths``),
        which the open scene now takes on: the same files, named from the new folder. That is announced but is
        no undo step: nothing a user sees changed."""
        self.path = Path(path)
        self.scene.source_path = self.path.resolve()
        for (target, field), name in (file_paths or {}).items():
            self.model.apply_value(target, field, name)
        self.display_name = self.path.parent.name if self.path.name == "scene.json" else self.path.stem
        self.undo_stack.setClean()
        self.file_changed.emit()

    @property
    def modified(self) -> bool:
        return not self.undo_stack.isClean()

    def silence(self) -> None:
        """Tell nobody anything any more: the document outlives its window's widgets by a little while Qt
        tears the window down."""
        self.blockSignals(True)
        self.undo_stack.blockSignals(True)
        self.model.events.changed.disconnect()

    # -- selection -------------------------------------------------------------------------------------------
    def set_selection(self, targets: list[tuple]) -> None:
        targets = [t for t in dict.fromkeys(tuple(t) for t in targets) if self.model.exists(t)]
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
        self.set_values(target, {tuple(field): value}, text, merge)

    def set_values(self, target: tuple, changes: dict[tuple, Any], text: str | None = None, merge: bool = False) -> None:
        from lenslab.gui.commands import SetValuesCommand  # commands know the document: import when used

        changes = {tuple(k): v for k, v in changes.items() if self.model.get_value(target, tuple(k)) != v}
        if not changes:
            return
        self.undo_stack.push(SetValuesCommand(self, target, changes, text, merge))

    def set_camera(self, text: str | None = None, merge: bool = False, **changes: Any) -> None:
        self.set_values(CAMERA, {(k,): v for k, v in changes.items()}, text, merge)

    def push(self, command) -> None:
        self.undo_stack.push(command)


def copy_scene(scene: Scene) -> Scene:
    """An independent copy for another thread (the renderer never sees an object the GUI may still edit)."""
    return copy.deepcopy(scene)
