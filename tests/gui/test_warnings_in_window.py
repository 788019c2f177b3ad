"""Warnings in the window: what opening a scene warned about (an unknown Mitsuba plugin read as grey diffuse) shows
in a bar above the picture, with the lines behind Details, and stays in the Log panel with its time and file; the
Open dialog offers every format the readers accept, each from the readers' own lists."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
from PySide6.QtGui import QDragEnterEvent, QDropEvent
from PySide6.QtWidgets import QApplication, QFileDialog, QMessageBox

pytestmark = pytest.mark.gl

UNKNOWN_PLUGIN = 'BSDF "frobnicate" is not supported'


def mitsuba_scene(folder: Path, bsdf: str = '<bsdf type="frobnicate"/>', name: str = "odd.xml") -> Path:
    """A small Mitsuba 3 scene: a sphere under a constant sky, its BSDF ``bsdf``."""
    path = folder / name
    path.write_text(
        '<?xml version="1.0"?>\n<scene version="3.0.0">\n'
        '<sensor type="perspective"><transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" '
        'up="0, 1, 0"/></transform><film type="hdrfilm"><integer name="width" value="64"/>'
        '<integer name="height" value="48"/><rfilter type="box"/></film></sensor>\n'
        '<emitter type="constant"><rgb name="radiance" value="1"/></emitter>\n'
        f'<shape type="sphere">{bsdf}</shape>\n</scene>\n')
    return path


def choose_in_open_dialog(monkeypatch, path: Path) -> dict:
    asked = {}

    def open_file(_parent, _caption, start, filters="", *_args):
        asked["filters"] = filters
        return str(path), ""

    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(open_file))
    return asked


def test_a_mitsuba_scene_with_an_unknown_plugin_shows_its_warning_in_the_bar_and_the_log(qtbot, window, tmp_path,
                                                                                        monkeypatch):
    path = mitsuba_scene(tmp_path)
    choose_in_open_dialog(monkeypatch, path)
    bar = window.warning_bar
    assert not bar.isVisible()

    window.open_dialog()

    assert window.doc.path == path  # opened, grey diffuse in place of what it cannot read
    assert bar.isVisible()
    assert bar.summary.text() == "1 warning while opening odd.xml"
    assert not bar.details.isVisible()
    bar.details_button.click()  # the lines, one click away
    assert bar.details.isVisible()
    assert len(bar.lines()) == 1 and UNKNOWN_PLUGIN in bar.lines()[0] and f"{path}:" in bar.lines()[0]

    log = window.log_panel.lines()
    assert len(log) == 1 and UNKNOWN_PLUGIN in log[0] and str(path) in log[0]
    assert re.match(r"\d\d:\d\d:\d\d  ", log[0])  # with its time

    log_dock = window.docks["log"]
    assert log_dock.isHidden()  # hidden until asked for: the bar's Log button, or View > Log
    view = next(a.menu() for a in window.menuBar().actions() if a.text().replace("&", "") == "View")
    assert log_dock.toggleViewAction() in view.actions()
    bar.log_button.click()
    assert log_dock.isVisible()
    # Each line is read from its start: long lines wrap, nothing is scrolled out of sight sideways.
    for text_view in (window.log_panel.view, bar.details):
        qtbot.waitUntil(lambda v=text_view: v.viewport().width() > 0)
        text_view.resize(320, text_view.height())  # narrower than the line
        QApplication.processEvents()
        assert text_view.horizontalScrollBar().maximum() == 0
    bar.close_button.click()
    assert not bar.isVisible()
    assert window.log_panel.lines() == log  # the log keeps what the bar said


def test_a_scene_without_warnings_takes_the_last_ones_bar_away_and_the_log_keeps_them(qtbot, window, tmp_path):
    odd = mitsuba_scene(tmp_path)
    plain = mitsuba_scene(tmp_path, '<bsdf type="diffuse"/>', "plain.xml")
    assert window.files.open_path(odd, ask=False)
    assert window.warning_bar.isVisible()
    assert window.files.open_path(plain, ask=False)
    assert not window.warning_bar.isVisible()
    assert len(window.log_panel.lines()) == 1


def test_a_dropped_mitsuba_scene_opens_and_warns_too(qtbot, window, tmp_path):
    path = mitsuba_scene(tmp_path)
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(path))])
    enter = QDragEnterEvent(QPoint(100, 100), Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier)
    window.dragEnterEvent(enter)
    assert enter.isAccepted()
    window.dropEvent(QDropEvent(QPointF(100, 100), Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier))
    qtbot.waitUntil(lambda: window.doc.path == path, timeout=5000)
    assert window.warning_bar.isVisible() and UNKNOWN_PLUGIN in window.log_panel.lines()[0]


def test_the_open_dialog_offers_every_format_the_readers_accept(qtbot, window, tmp_path, monkeypatch):
    from lenslab.scene.io.meshes import MESH_SUFFIXES

    asked = choose_in_open_dialog(monkeypatch, tmp_path / "nothing.json")
    monkeypatch.setattr(window.files, "open_path", lambda *_a, **_k: True)
    window.open_dialog()
    filters = asked["filters"].split(";;")
    meshes = " ".join("*" + suffix for suffix in MESH_SUFFIXES)
    assert filters == ["All supported (*.json *.xml " + meshes + ")", "LensLab scenes (*.json)",
                       "Mitsuba 3 scenes (*.xml)", f"Meshes ({meshes})", "All files (*)"]


def test_a_mesh_chosen_in_the_open_dialog_is_imported_into_the_open_scene(qtbot, window, tmp_path, monkeypatch):
    mesh = tmp_path / "tri.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    choose_in_open_dialog(monkeypatch, mesh)
    imported, errors = [], []
    monkeypatch.setattr(type(window), "import_mesh", lambda self, path: imported.append(path))
    monkeypatch.setattr(QMessageBox, "critical", staticmethod(lambda _p, _t, text, *_a: errors.append(text)))
    opened_before = window.doc.path
    window.open_dialog()
    assert errors == []  # not read as a scene
    assert imported == [mesh] and window.doc.path == opened_before


def test_a_mitsuba_scene_named_on_the_command_line_shows_its_warnings_too(qtbot, monkeypatch, tmp_path):
    from PySide6.QtCore import QSettings, QTimer
    from PySide6.QtWidgets import QApplication

    from lenslab import cli
    from lenslab.gui import main_window

    monkeypatch.setattr(main_window, "studio_settings", lambda: QSettings(str(tmp_path / "s.ini"), QSettings.IniFormat))
    path = mitsuba_scene(tmp_path)
    seen = {}

    def look_and_close():
        window = next((w for w in QApplication.topLevelWidgets()
                       if isinstance(w, main_window.MainWindow) and w.isVisible()), None)
        if window is None or "bar" in seen:  # not shown yet, or already seen
            return
        seen["bar"] = window.warning_bar.isVisible() and window.warning_bar.lines()
        seen["log"] = window.log_panel.lines()
        window.close()

    monkeypatch.setattr(QApplication, "exec", lambda self: (QTimer.singleShot(0, look_and_close), 0)[1])
    assert cli.run([str(path)]) == 0
    qtbot.waitUntil(lambda: "bar" in seen, timeout=10000)
    assert seen["bar"] and UNKNOWN_PLUGIN in seen["bar"][0]
    assert len(seen["log"]) == 1 and UNKNOWN_PLUGIN in seen["log"][0]


def test_a_missing_texture_found_while_rendering_reaches_the_bar_and_the_log_once(make_window, small_scene, qtbot,
                                                                                  tmp_path):
    """The render worker packs the scene: what it finds there (a texture file that is not there) is shown beside
    the load's warnings, once, however many edits restart the render."""
    import dataclasses

    from lenslab.scene.textures import ImageTexture

    name, material = next(iter(small_scene.materials.items()))
    small_scene.materials[name] = dataclasses.replace(material, albedo_texture=ImageTexture(file=str(tmp_path / "gone.png")))
    window = make_window(small_scene)
    qtbot.waitUntil(lambda: window.warning_bar.isVisible(), timeout=20000)
    assert any("gone.png: texture file not found" in line for line in window.warning_bar.lines())
    logged = [line for line in window.log_panel.lines() if "gone.png" in line]
    assert len(logged) == 1
    window.doc.set_camera(f_number=8.0)  # a restart: the same warning is not said again
    qtbot.waitUntil(lambda: window.controller.last_frame is not None
                    and window.controller.last_frame.generation == window.controller.generation, timeout=20000)
    assert len([line for line in window.log_panel.lines() if "gone.png" in line]) == 1
