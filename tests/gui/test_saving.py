"""Saving in the studio: relative file names (meshes, textures, the environment map) follow the scene into a new folder, and a save that fails leaves the
open scene exactly as it was (mesh paths, file, modified state, history)."""

from __future__ import annotations

import copy
import errno
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QLineEdit, QMessageBox

from lenslab.render.film import write_image
from lenslab.scene.events import SceneChange
from lenslab.scene.io.native import load_scene, save_scene
from lenslab.scene.scene import EnvironmentMap, Node
from lenslab.scene.shapes import MeshFile
from lenslab.scene.transform import Transform

from .helpers import wait_for_frame

pytestmark = pytest.mark.gl

TETRAHEDRON = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.fixture
def studio(make_window, small_scene, tmp_path):
    """The studio on a scene saved in shots/a, with a mesh beside it named by a relative path, the mesh
    selected, and one unsaved edit."""
    folder = tmp_path / "shots" / "a"
    (folder / "meshes").mkdir(parents=True)
    (folder / "meshes" / "tetra.obj").write_text(TETRAHEDRON)
    write_image(folder / "sky.exr", np.full((4, 8, 3), 0.5, np.float32))
    small_scene.environment = EnvironmentMap(file="sky.exr")
    small_scene.nodes.append(Node("tetra", Transform(translate=(0.2, 0.1, 0.2), scale=(0.1, 0.1, 0.1)),
                                  MeshFile(file="meshes/tetra.obj")))
    small_scene.source_path = (folder / "scene.json").resolve()
    save_scene(small_scene, folder / "scene.json")
    window = make_window(small_scene, folder / "scene.json")
    window.doc.set_selection([("node", (len(small_scene.nodes) - 1,))])
    window.camera_panel.set_f_number(4.0)
    assert window.doc.modified
    return window


def mesh_path(window) -> tuple:
    return next(p for p, n in window.doc.model.walk_nodes() if n.name == "tetra")


def file_field(window) -> QLineEdit:
    return window.properties._editors[("shape", "file")].widget.findChild(QLineEdit)


def refuse_to_show(monkeypatch) -> list[str]:
    """Collect the error boxes instead of showing them (a modal box would wait for a click)."""
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "critical", staticmethod(lambda _parent, _title, text, *_a: shown.append(text)))
    return shown


def assert_untouched(window, scene_before, path_before, source_before, steps_before, heard):
    doc = window.doc
    assert doc.scene == scene_before
    assert doc.model.node(mesh_path(window)).shape.file == "meshes/tetra.obj"
    assert file_field(window).text() == "meshes/tetra.obj"
    assert doc.scene.source_path == source_before and doc.path == path_before
    assert doc.modified and window.isWindowModified()
    assert doc.undo_stack.count() == steps_before and doc.undo_stack.undoText() == "Aperture f/4"
    assert heard == []  # nothing changed, so nothing was announced


@pytest.mark.parametrize("how", ["folder cannot be written", "writer fails"])
def test_a_failed_save_leaves_the_open_scene_exactly_as_it_was(studio, tmp_path, monkeypatch, how):
    doc = studio.doc
    shown = refuse_to_show(monkeypatch)
    before = (copy.deepcopy(doc.scene), doc.path, doc.scene.source_path, doc.undo_stack.count())
    heard = []
    doc.model.events.changed.connect(heard.append)
    if how == "folder cannot be written":
        not_a_folder = tmp_path / "shots" / "b"
        not_a_folder.write_text("a file where the folder should be")
        target = not_a_folder / "scene.json"
    else:
        (tmp_path / "shots" / "b").mkdir()
        target = tmp_path / "shots" / "b" / "scene.json"

        def full_disk(scene, path):
            raise OSError(errno.ENOSPC, "No space left on device")

        monkeypatch.setattr(studio.files, "write_scene", full_disk)  # the file controller's scene writer
    assert not studio.files.write(target)
    assert len(shown) == 1 and shown[0].count(str(target)) == 1  # the file named once, with the reason
    assert not target.exists()
    assert_untouched(studio, *before, heard)
    # Nothing lost: the history still undoes the edit, and saving where the scene lives still works.
    monkeypatch.undo()
    assert studio.save()
    assert not doc.modified and load_scene(doc.path).camera.f_number == 4.0


def test_saving_into_another_folder_renames_mesh_paths_and_the_studio_hears_of_it(qtbot, studio, tmp_path):
    doc = studio.doc
    mesh = mesh_path(studio)
    original = (tmp_path / "shots" / "a" / "meshes" / "tetra.obj").resolve()
    heard = []
    doc.model.events.changed.connect(heard.append)
    (tmp_path / "shots" / "b").mkdir()
    target = tmp_path / "shots" / "b" / "scene.json"
    assert studio.files.write(target)
    renamed = str(Path("..") / "a" / "meshes" / "tetra.obj")
    # The file names the same mesh from its own folder; so does the open scene, which said so.
    saved = load_scene(target)
    assert saved.nodes[mesh[0]].shape.file == renamed and (target.parent / renamed).resolve() == original
    assert doc.model.node(mesh).shape.file == renamed
    assert doc.scene.source_path == target.resolve() and doc.path == target
    assert SceneChange("node", ("node", mesh), ("shape", "file")) in heard
    # Every file the scene names follows it, not only meshes: here the environment map.
    assert saved.environment.file == str(Path("..") / "a" / "sky.exr") == doc.scene.environment.file
    assert file_field(studio).text() == renamed  # the property editor shows the new name
    assert not doc.modified and doc.undo_stack.undoText() == "Aperture f/4"
    # The renderer still finds the mesh.
    wait_for_frame(qtbot, studio, generation=studio.controller.generation, timeout=60000)
    assert studio.viewport.message == ""
