"""The studio's files: new, open (a file, an example, a recent scene, with what its reader warned about), save and
save as, the question about unsaved changes, meshes imported (on a background thread) and files dropped on the
window; and the folders each kind of file was last in and the recent scenes, remembered between runs (QSettings)."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QObject, QSettings, Qt, QTimer, Signal
from PySide6.QtWidgets import QFileDialog, QMainWindow, QMenu, QMessageBox

from lenslab.gui.commands import AddNodeCommand
from lenslab.gui.defaults import studio_scene
from lenslab.gui.document import Document, is_shipped
from lenslab.messages import one_line
from lenslab.scene import editing
from lenslab.scene.io.loader import (SCENE_FORMATS, SCENE_SUFFIXES, open_scene, resolve_scene_path, scene_title,
                                     shipped_scene_names)
from lenslab.scene.io.meshes import MESH_SUFFIXES, MeshLoadError, load_mesh
from lenslab.scene.io.native import SCENE_SUFFIX, save_scene
from lenslab.scene.scene import SceneError

MAX_RECENT = 10


def file_filter(name: str, suffixes) -> str:
    return f"{name} ({' '.join('*' + suffix for suffix in suffixes)})"


def open_dialog_filters() -> str:
    """The Open dialog's filters, made from what the readers accept: every kind at once (the default), each scene
    format, meshes (imported into the open scene, as a dropped mesh is), and any file."""
    kinds = (*SCENE_FORMATS, ("Meshes", MESH_SUFFIXES))
    supported = [suffix for _name, suffixes in kinds for suffix in suffixes]
    return ";;".join([file_filter("All supported", supported), *(file_filter(*kind) for kind in kinds),
                      "All files (*)"])


class FileController(QObject):
    """The window's document to and from files. The window (the dialogs' parent, its status bar the messages')
    is asked for nothing else; ``write_scene`` writes a scene file (save_scene's arguments)."""

    mesh_imported = Signal(str)  # path, once its node is in the scene
    mesh_import_failed = Signal(str, str)  # path, reason
    scene_opened_with_warnings = Signal(str, list)  # path, what its reader approximated or left out (maybe none)
    _mesh_loaded = Signal(object, object, str)  # from the loading thread

    def __init__(self, window: QMainWindow, doc: Document, settings: QSettings,
                 write_scene: Callable[..., None] = save_scene):
        super().__init__(window)
        self.window = window
        self.doc = doc
        self.settings = settings
        self.write_scene = write_scene
        self.unsaved_box: QMessageBox | None = None
        self.closing = False  # the window is closing: a failure is not worth a message box
        self._pending_imports = 0
        self._mesh_library_warming = False
        self._mesh_loaded.connect(self._on_mesh_loaded, Qt.QueuedConnection)

    def _status(self, text: str, ms: int = 0) -> None:
        self.window.statusBar().showMessage(text, ms)

    # -- the document ------------------------------------------------------------------------------------------
    def maybe_save(self) -> bool:
        """True when it is fine to drop the current document (saved, discarded, or unchanged)."""
        if not self.doc.modified:
            return True
        box = QMessageBox(QMessageBox.Warning, "Unsaved changes",
                          f"Save the changes to “{self.doc.display_name}” before closing it?",
                          QMessageBox.Save | QMessageBox.Discard | QMessageBox.Cancel, self.window)
        box.setInformativeText("Your changes will be lost if you don't save them.")
        box.setDefaultButton(QMessageBox.Save)
        box.setObjectName("unsavedChangesBox")
        self.unsaved_box = box
        try:
            answer = box.exec()
        finally:
            self.unsaved_box = None
        if answer == QMessageBox.Save:
            return self.save()
        return answer == QMessageBox.Discard

    def new_scene(self) -> None:
        if self.maybe_save():
            self.doc.replace(studio_scene(), None)

    def open_dialog(self) -> None:
        start = str(self.last_folder("scenes") or (self.doc.path.parent if self.doc.path else Path.home()))
        name, _ = QFileDialog.getOpenFileName(self.window, "Open", start, open_dialog_filters())
        if not name:
            return
        if Path(name).suffix.lower() in MESH_SUFFIXES:  # added to the open scene: no question about it
            self.remember_folder("meshes", name)
            self.window.import_mesh(Path(name))
        else:
            self.open_path(name)  # asks about unsaved changes now that a scene is chosen

    def open_path(self, text: str | os.PathLike, ask: bool = True) -> bool:
        if ask and not self.maybe_save():
            return False
        warnings: list[str] = []  # the reader runs on this thread: it reports to this list as it reads
        try:
            path = resolve_scene_path(text)
            scene = open_scene(text, warn=warnings.append)
        except (SceneError, OSError) as exc:
            QMessageBox.critical(self.window, "Cannot open scene", one_line(exc))
            return False
        self.doc.replace(scene, path)
        self.scene_opened_with_warnings.emit(str(path), warnings)
        if not is_shipped(path):
            self.add_recent(path)
            self.remember_folder("scenes", path)
        self._status(f"Opened {path}", 4000)
        return True

    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        return self.write(self.doc.path)

    def save_as(self) -> bool:
        folder = self.last_folder("scenes") or Path.home()
        start = str(self.doc.path or (folder / f"{self.doc.display_name}{SCENE_SUFFIX}"))
        name, _ = QFileDialog.getSaveFileName(self.window, "Save scene", start, f"LensLab scenes (*{SCENE_SUFFIX})")
        if not name:
            return False
        path = Path(name)
        if path.suffix.lower() != SCENE_SUFFIX:
            path = path.with_suffix(SCENE_SUFFIX)
        return self.write(path)

    def write(self, path: Path) -> bool:
        path = Path(path)
        # Relative file names (meshes, textures, the environment map) are rewritten for the new folder in the
        # copy that is written; the open scene takes them on only once the file is there, so a failed save
        # leaves it exactly as it was.
        file_paths = editing.rebased_file_paths(self.doc.model, path.resolve().parent)
        try:
            self.write_scene(editing.with_file_paths(self.doc.scene, file_paths), path)
        except OSError as exc:
            reason = exc.strerror or str(exc)  # the writer's own messages name the file already
            QMessageBox.critical(self.window, "Cannot save scene",
                                 reason if str(path) in reason else f"{path}: {reason}")
            return False
        self.doc.saved_as(path, file_paths)
        self.add_recent(path)
        self.remember_folder("scenes", path)
        self._status(f"Saved {path}", 4000)
        return True

    # -- folders and recent scenes ---------------------------------------------------------------------------
    def last_folder(self, kind: str) -> Path | None:
        """The folder the last file of ``kind`` ("scenes": opened or saved; "meshes": imported; "images":
        exported) was in, remembered between runs, if it is still there."""
        value = self.settings.value(f"folders/{kind}")
        folder = Path(str(value)) if value else None
        return folder if folder is not None and folder.is_dir() else None

    def remember_folder(self, kind: str, file: str | os.PathLike) -> None:
        self.settings.setValue(f"folders/{kind}", str(Path(file).expanduser().resolve().parent))

    def recent_files(self) -> list[str]:
        value = self.settings.value("recent_files", [])
        if isinstance(value, str):
            value = [value]
        return [str(v) for v in (value or [])]

    def add_recent(self, path: Path) -> None:
        text = str(Path(path).resolve())
        recent = [p for p in self.recent_files() if p != text]
        self.settings.setValue("recent_files", [text] + recent[: MAX_RECENT - 1])

    def fill_examples_menu(self, menu: QMenu) -> None:
        for name in shipped_scene_names():
            menu.addAction(scene_title(name), lambda n=name: self.open_path(n))

    def fill_recent_menu(self, menu: QMenu) -> None:
        menu.clear()
        recent = self.recent_files()
        for i, path in enumerate(recent):
            action = menu.addAction(f"&{(i + 1) % 10}  {Path(path).parent.name}/{Path(path).name}",
                                    lambda p=path: self.open_path(p))
            action.setToolTip(path)
            action.setEnabled(Path(path).exists())
        if recent:
            menu.addSeparator()
            menu.addAction("Clear List", lambda: self.settings.setValue("recent_files", []))
        else:
            menu.addAction("No recent scenes").setEnabled(False)

    # -- importing meshes ------------------------------------------------------------------------------------
    def import_dialog(self) -> None:
        self.warm_up_mesh_library()
        start = str(self.last_folder("meshes") or self.doc.scene.base_dir())
        pattern = file_filter("Meshes", MESH_SUFFIXES) + ";;All files (*)"
        names, _ = QFileDialog.getOpenFileNames(self.window, "Import mesh", start, pattern)
        if names:
            self.remember_folder("meshes", names[0])
        for name in names:
            self.window.import_mesh(Path(name))  # through the window's own entry point for an import

    def import_mesh(self, path: Path) -> None:
        """Add a mesh file as a node. The file is read on a background thread (a large mesh, or the first use of
        the mesh library, takes seconds); the node appears, as one undo step, when it has been read."""
        path = Path(path).resolve()
        self._pending_imports += 1
        self._status(f"Reading {path.name}…")
        self.window.setCursor(Qt.BusyCursor)

        def load() -> None:
            try:
                mesh = load_mesh(path, True)
            except MeshLoadError as exc:
                self._mesh_loaded.emit(path, None, str(exc))
            except Exception as exc:  # a broken file can make trimesh raise anything
                self._mesh_loaded.emit(path, None, f"{path}: cannot read mesh ({exc})")
            else:
                self._mesh_loaded.emit(path, mesh, "")

        threading.Thread(target=load, name=f"load {path.name}", daemon=True).start()

    def _on_mesh_loaded(self, path: Path, mesh, error: str) -> None:
        self._pending_imports -= 1
        if self._pending_imports == 0:
            self.window.unsetCursor()
        if mesh is None:
            self.window.statusBar().clearMessage()
            self.mesh_import_failed.emit(str(path), error)
            if not self.closing:
                QMessageBox.critical(self.window, "Cannot import mesh", error)
            return
        node, scale = editing.mesh_node(self.doc.model, path, mesh.vertices, self.doc.path)
        parent = editing.insertion_parent(self.doc.model, self.doc.selected_node_paths())
        self.doc.push(AddNodeCommand(self.doc, node, parent, text=f"Import {path.name}"))
        note = f", scaled ×{scale:g} to fit the view" if scale != 1.0 else ""
        self._status(f"Imported {path.name}: {mesh.triangle_count:,} triangles{note}", 6000)
        self.mesh_imported.emit(str(path))

    def warm_up_mesh_library(self) -> None:
        """Start importing the mesh library (trimesh, scipy: seconds the first time) while the user picks a file."""
        if not self._mesh_library_warming:
            self._mesh_library_warming = True
            threading.Thread(target=lambda: __import__("trimesh"), name="import trimesh", daemon=True).start()

    # -- drag and drop ---------------------------------------------------------------------------------------
    @staticmethod
    def dropped_paths(event) -> list[Path]:
        if not event.mimeData().hasUrls():
            return []
        return [Path(u.toLocalFile()) for u in event.mimeData().urls() if u.isLocalFile()]

    def drag_enter(self, event) -> None:
        paths = self.dropped_paths(event)
        if any(p.suffix.lower() in MESH_SUFFIXES for p in paths):
            self.warm_up_mesh_library()
        if any(p.suffix.lower() in (*MESH_SUFFIXES, *SCENE_SUFFIXES) or p.is_dir() for p in paths):
            event.acceptProposedAction()

    def drop(self, event) -> None:
        paths = self.dropped_paths(event)
        meshes = [p for p in paths if p.suffix.lower() in MESH_SUFFIXES]
        scenes = [p for p in paths if p.suffix.lower() in SCENE_SUFFIXES or p.is_dir()]
        event.acceptProposedAction()
        if meshes:
            for p in meshes:
                self.window.import_mesh(p)
        elif scenes:
            QTimer.singleShot(0, lambda: self.open_path(scenes[0]))


__all__ = ["FileController", "MAX_RECENT", "open_dialog_filters"]
