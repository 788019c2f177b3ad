"""The studio, driven as a user would (pytest-qt, offscreen, rendering on llvmpipe in its worker thread).

What is checked: choosing f/2.8 sets the f-number and restarts accumulation; a lens preset sets the focal
length and clamps the aperture; clicking an object focuses at its depth within 1 %; undo restores each edit;
export writes a valid file and cancelling writes none; closing with unsaved changes prompts; the window closes
cleanly while rendering.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path

import pytest
from PySide6.QtCore import QPoint, Qt, QTimer
from PySide6.QtWidgets import QApplication, QMessageBox, QPushButton

from .helpers import cpu_depth, wait_for_frame, wait_for_gbuffer

pytestmark = pytest.mark.gl


def lens_named(window, name):
    return next(lens for lens in window.camera_panel.lenses if lens.name == name)


def lens_button(window, lens):
    panel = window.camera_panel
    return panel.lens_buttons[1 + panel.lenses.index(lens)]


def click_image(qtbot, window, x: float, y: float):
    """Click the viewport at image position (x, y) in pixels."""
    point = window.viewport.image_to_widget(x, y)
    qtbot.mouseClick(window.viewport, Qt.LeftButton, pos=QPoint(round(point.x()), round(point.y())))


def drop_files(window, paths):
    from PySide6.QtCore import QMimeData, QPoint, QPointF, QUrl
    from PySide6.QtGui import QDragEnterEvent, QDropEvent

    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(p)) for p in paths])
    enter = QDragEnterEvent(QPoint(100, 100), Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier)
    window.dragEnterEvent(enter)
    assert enter.isAccepted()
    window.dropEvent(QDropEvent(QPointF(100, 100), Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier))


# -- aperture --------------------------------------------------------------------------------------------------
def test_choosing_f28_sets_the_f_number_and_restarts_accumulation(qtbot, window):
    frames = []
    window.controller.frame_ready.connect(lambda f: frames.append((f.generation, f.samples_per_pixel, f.preview)))
    # Enough samples that the new generation's first frame, a quarter of a second in, cannot have as many
    # unless accumulation failed to restart.
    before = wait_for_frame(qtbot, window, min_spp=300)
    assert window.doc.scene.camera.f_number == 1.8
    combo = window.camera_panel.aperture_combo
    with qtbot.waitSignal(window.controller.restarted, timeout=5000) as restart:
        combo.setCurrentIndex(combo.findText("f/2.8"))
    assert window.doc.scene.camera.f_number == 2 ** 1.5  # the mark f/2.8 is the exact stop
    generation = restart.args[0]
    assert generation > before.generation
    # The first picture of the new generation starts again from a few samples.
    qtbot.waitUntil(lambda: any(g == generation for g, _s, _p in frames), timeout=10000)
    first = next((s, p) for g, s, p in frames if g == generation)
    assert first[1] or first[0] < before.samples_per_pixel
    assert combo.currentText() == "f/2.8" and window.viewport.hud_text.find("f/2.8") >= 0
    # The free field takes values off the scale.
    combo.lineEdit().setText("f/3")
    combo.lineEdit().editingFinished.emit()
    assert window.doc.scene.camera.f_number == 3.0
    # Stepping goes along the third-stop scale from there: to the exact f/3.2.
    window.camera_panel.step_aperture(+1)
    assert window.doc.scene.camera.f_number == pytest.approx(2 ** (10 / 6))


# -- the look on screen ----------------------------------------------------------------------------------------
def test_the_worker_makes_each_picture_through_the_viewports_view(qtbot, window):
    import numpy as np

    from lenslab.render.film import display_pixels, to_8bit

    window.controller.set_target_spp(6)
    # Frames of the render that began before the new target may come first: wait for the finished one.
    qtbot.waitUntil(lambda: window.controller.last_frame is not None and window.controller.last_frame.converged,
                    timeout=20000)
    first = window.controller.last_frame
    assert first.samples_per_pixel >= 6 and first.view == window.viewport.view
    # A finished render makes no more frames by itself: a new view must still reach the screen, from the GPU.
    window.exposure_slider.setValue(20)
    window.display.set_view("Un-tone-mapped")
    qtbot.waitUntil(lambda: window.controller.last_frame.view == window.display.view, timeout=5000)
    frame = window.controller.last_frame
    assert (frame.view.view, frame.view.exposure_stops) == ("Un-tone-mapped", 2.0)
    assert frame.samples_per_pixel == first.samples_per_pixel and frame.image is not None  # no new samples
    # OCIO's CPU processor and its GLSL on the GPU agree within a level; the camera's exposure (the Cornell box is
    # exposed physically) goes into the transform's exposure.
    camera_stops = math.log2(frame.exposure.scale)
    made = dataclasses.replace(frame.view, exposure_stops=frame.view.exposure_stops + camera_stops)
    assert window.viewport.picture_view() == made
    expected = to_8bit(display_pixels(frame.image, made))
    difference = np.abs(frame.display[..., :3].astype(int) - expected.astype(int))
    assert difference.max() <= 1 and (frame.display[..., 3] == 255).all()
    assert not np.array_equal(frame.display[..., :3], first.display[..., :3])
    shown = window.viewport.display_image()
    h, w = expected.shape[:2]
    for x, y in ((0, 0), (w // 2, h // 2), (w - 1, h - 1)):
        colour = shown.pixelColor(x, y)
        assert (colour.red(), colour.green(), colour.blue()) == tuple(int(c) for c in frame.display[y, x, :3])


def test_a_look_saved_by_hand_or_by_another_version_falls_back_to_the_default(qtbot, make_window, settings,
                                                                              small_scene):
    from lenslab.colour_management.view import ViewTransform

    settings.setValue("viewport/exposure", "bright")
    settings.setValue("viewport/tone_map", "aces")  # not one of ours
    window = make_window(small_scene)
    default = ViewTransform().resolved()
    assert window.viewport.view.view == default.view and window.viewport.exposure == 0.0
    assert wait_for_frame(qtbot, window).view == window.viewport.view  # the worker renders on
    settings.setValue("viewport/exposure", 40.0)  # beyond the slider's six stops
    assert make_window(small_scene).viewport.exposure == 6.0
    with pytest.raises(ValueError, match="view 'aces' is not one of display"):
        window.controller.set_display(ViewTransform(view="aces"))


# -- lens presets ----------------------------------------------------------------------------------------------
def test_a_lens_preset_sets_the_focal_length_and_clamps_the_aperture(qtbot, window):
    cam = window.doc.scene.camera
    assert (cam.focal_length_mm, cam.f_number) == (50.0, 1.8)
    lens = lens_named(window, "135 mm f/2")
    qtbot.mouseClick(lens_button(window, lens), Qt.LeftButton)
    cam = window.doc.scene.camera
    assert cam.focal_length_mm == 135.0
    assert cam.f_number == 2.0  # f/1.8 is wider than the lens opens (f/2 is exact)
    assert cam.aperture_blades == lens.aperture_blades
    assert window.doc.lens == lens
    # The aperture scale now stops at the lens's widest: asking for f/1.4 gives f/2.
    assert window.camera_panel.aperture_combo.itemText(0) == "f/2"
    window.camera_panel.set_f_number(1.4)
    assert window.doc.scene.camera.f_number == 2.0
    # A prime's focal length cannot be changed; a zoom limits it to its range.
    window.camera_panel.set_focal_length(35.0, False)
    assert window.doc.scene.camera.focal_length_mm == 135.0
    zoom = lens_named(window, "24-70 mm f/2.8")
    window.lens_actions[window.camera_panel.lenses.index(zoom)].trigger()  # the menu entry (Alt+N)
    cam = window.doc.scene.camera
    assert cam.focal_length_mm == 70.0 and cam.f_number == 2 ** 1.5
    window.camera_panel.set_focal_length(200.0, False)
    assert window.doc.scene.camera.focal_length_mm == 70.0
    # Free: no limits again, and one undo puts the previous lens back.
    qtbot.mouseClick(window.camera_panel.lens_buttons[0], Qt.LeftButton)
    assert window.doc.lens is None
    window.camera_panel.set_f_number(1.4)
    assert window.doc.scene.camera.f_number == 1.4  # a number set as it is (typed text reads marks as exact)
    window.doc.undo_stack.undo()
    window.doc.undo_stack.undo()
    assert window.doc.lens == zoom


# -- click to focus -----------------------------------------------------------------------------------------------
def test_clicking_an_object_focuses_at_its_depth(qtbot, window):
    wait_for_frame(qtbot, window)
    wait_for_gbuffer(qtbot, window)
    window.set_tool("focus")
    clicks = []
    window.viewport.focus_clicked.connect(lambda u, v: clicks.append((u, v)))
    scene = copy.deepcopy(window.doc.scene)
    names = [n.name for _p, n in window.doc.model.walk_nodes()]
    changes = []
    window.doc.model.events.changed.connect(changes.append)  # the scene's own events, no Qt signal
    # The overlay fades after a second or so, and a slow machine can spend that long below; so the test records
    # each time the viewport is asked to show it rather than racing the fade.
    overlays = []
    show_overlay = window.viewport.show_focus_overlay
    window.viewport.show_focus_overlay = lambda focus, *a, **k: (overlays.append(focus), show_overlay(focus, *a, **k))
    for x, y, name in ((24.5, 28.5, "tall box"), (40.5, 40.5, "short box"), (36.5, 12.5, "back wall")):
        before = window.doc.scene.camera.plane_of_focus_m
        seen = len(changes)
        overlays.clear()
        click_image(qtbot, window, x, y)
        qtbot.waitUntil(lambda: any(c.field == ("focus_distance_m",) for c in changes[seen:]), timeout=10000)
        u, v = clicks[-1]
        truth, node_index = cpu_depth(scene, u, v)
        # The reading is from the sensor; the plane it puts in focus is at the clicked depth from the lens.
        focus = window.doc.scene.camera.plane_of_focus_m
        assert math.isfinite(truth) and names[node_index] == name
        assert abs(focus - truth) <= 0.01 * truth, (name, focus, truth)
        assert abs(focus - before) > 0.01 * truth
        assert name in window.doc.undo_stack.undoText()
        assert overlays and abs(overlays[-1] - focus) <= 1e-9 * focus  # the new plane of focus is shown on the image
        assert window.doc.undo_stack.undoText().startswith("Focus on")
    # The focus tool on the background changes nothing.
    window.viewport.set_zoom(0.25)
    focus = window.doc.scene.camera.focus_distance_m
    w = window.viewport
    qtbot.mouseClick(w, Qt.LeftButton, pos=QPoint(w.width() // 2, w.height() // 2))
    assert window.doc.scene.camera.focus_distance_m == focus


def test_clicking_selects_and_the_viewport_outlines_the_selection(qtbot, window):
    wait_for_frame(qtbot, window)
    g = wait_for_gbuffer(qtbot, window)
    click_image(qtbot, window, 24.5, 28.5)
    paths = window.doc.model.node_paths()
    index = int(g.node_index[28, 24])
    assert window.doc.selection == [("node", paths[index])]
    assert window.doc.model.node(paths[index]).name == "tall box"
    assert window.viewport._outline is not None
    # The outliner follows, and its selection drives the property editor.
    rows = window.scene_tree.selectionModel().selectedRows()
    assert [window.scene_tree.tree_model.key(i) for i in rows] == [("node", paths[index])]
    assert window.properties.title.text() == "tall box"


# -- editing and undo ---------------------------------------------------------------------------------------------
def test_undo_restores_each_edit(qtbot, window, tmp_path):
    doc = window.doc
    snapshots = [copy.deepcopy(doc.scene)]
    lenses = [doc.lens]

    def edited():
        snapshots.append(copy.deepcopy(doc.scene))
        lenses.append(doc.lens)

    panel = window.camera_panel
    combo = panel.aperture_combo
    combo.setCurrentIndex(combo.findText("f/4"))
    edited()
    panel.choose_lens(lens_named(window, "85 mm f/1.4"))
    edited()
    # Two slider moves in quick succession are one step.
    panel.focus_slider.setValue(panel.focus_slider.value() + 40)
    panel.focus_slider.setValue(panel.focus_slider.value() + 40)
    edited()
    steps = doc.undo_stack.count()
    # Move a node through the property editor's transform fields.
    tall = next(p for p, n in doc.model.walk_nodes() if n.name == "tall box")
    doc.set_selection([("node", tall)])
    translate = window.properties._editors[("transform", "translate")].widget
    translate.spins[0].setValue(0.05)
    edited()
    # Give it another material through the property editor.
    material = window.properties._editors[("material",)].widget.findChild(type(combo))
    material.setCurrentIndex(material.findData("red"))
    edited()
    assert doc.model.node(tall).material == "red"
    # Add, then delete.
    window.add_primitive("sphere")
    edited()
    window.doc.set_selection([("node", (0,))])
    window.delete_selection()
    edited()
    # Import a mesh file.
    obj = tmp_path / "tetra.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    with qtbot.waitSignal(window.mesh_imported, timeout=30000):
        drop_files(window, [obj])  # as if dragged from a file manager; read on a background thread
    assert doc.model.node((len(doc.scene.nodes) - 1,)).shape.file == str(obj.resolve())
    edited()
    # Change a material's type (diffuse to emissive keeps its colour).
    doc.set_selection([("material", "green")])
    type_combo = window.properties._editors[("__type__",)].widget
    type_combo.setCurrentIndex(type_combo.findData("emissive"))
    edited()
    assert doc.scene.materials["green"].type_name == "emissive"

    assert doc.undo_stack.count() == steps + 6 and steps == 3
    assert window.isWindowModified()
    for i in range(len(snapshots) - 1, 0, -1):
        assert doc.scene == snapshots[i]
        doc.undo_stack.undo()
        assert doc.scene == snapshots[i - 1], f"undo of step {i} ({doc.undo_stack.redoText()})"
        assert doc.lens == lenses[i - 1]
    assert not window.isWindowModified()
    while doc.undo_stack.canRedo():
        doc.undo_stack.redo()
    assert doc.scene == snapshots[-1]
    # Ctrl+Z is wired to the same stack.
    assert window.actions["undo"].shortcut().toString() == "Ctrl+Z"
    assert "Ctrl+Shift+Z" in [s.toString() for s in window.actions["redo"].shortcuts()]


def test_reparenting_in_the_outliner_keeps_the_world_position(window):
    from lenslab.gui.scene_tree import move_node
    from lenslab.scene.editing import world_matrix

    doc = window.doc
    short = next(p for p, n in doc.model.walk_nodes() if n.name == "short box")
    before = world_matrix(doc.model, short)
    walls = next(p for p, n in doc.model.walk_nodes() if n.name == "walls")
    window.add_primitive("group")  # a new group at the plane of focus
    group = doc.selected_node_paths()[0]
    group_name = doc.model.node(group).name
    doc.set_value(("node", group), ("transform", "rotate_deg"), (0.0, 30.0, 0.0))
    short = next(p for p, n in doc.model.walk_nodes() if n.name == "short box")
    assert move_node(doc, short, group, 0)
    moved = next(p for p, n in doc.model.walk_nodes() if n.name == "short box")
    assert doc.model.node(moved[:-1]).name == group_name  # the group moved up one place as the box left
    assert abs(world_matrix(doc.model, moved) - before).max() < 1e-6
    assert not move_node(doc, walls, walls + (0,), 0)  # never into itself
    doc.undo_stack.undo()
    assert doc.model.node(short).name == "short box"


# -- export ---------------------------------------------------------------------------------------------------------
def export_request(window, path, **kwargs):
    from lenslab.gui.document import copy_scene
    from lenslab.gui.worker import ExportRequest
    import dataclasses

    scene = copy_scene(window.doc.scene)
    scene.camera = dataclasses.replace(scene.camera, resolution=(32, 24))
    return ExportRequest(scene=scene, path=Path(path), **kwargs)


def test_export_writes_a_valid_file_and_cancelling_writes_none(qtbot, window, tmp_path):
    from lenslab.render.film import read_image

    out = tmp_path / "shot.exr"
    with qtbot.waitSignal(window.controller.export_finished, timeout=30000) as done:
        window.start_export(export_request(window, out, target_spp=4))
        assert window.export_progress_dialog is not None
    assert done.args[1] == str(out)
    pixels, metadata = read_image(out)
    assert pixels.shape == (24, 32, 3)
    assert metadata["lenslab:SamplesPerPixel"] == 4
    assert metadata["FNumber"] == pytest.approx(1.8)
    assert pixels.max() > 0
    assert window.export_progress_dialog is None

    png = tmp_path / "shot.png"
    with qtbot.waitSignal(window.controller.export_finished, timeout=30000):
        window.start_export(export_request(window, png, seconds=0.3, view=window.viewport.view))
    assert read_image(png)[0].shape == (24, 32, 3)

    cancelled = tmp_path / "cancelled.png"
    with qtbot.waitSignal(window.controller.export_progress, timeout=30000):
        window.start_export(export_request(window, cancelled, target_spp=1_000_000))
    with qtbot.waitSignal(window.controller.export_cancelled, timeout=10000):
        window.export_progress_dialog.findChild(QPushButton).click()  # the progress dialog's Cancel button
    assert not cancelled.exists()
    left = sorted(p.name for p in tmp_path.iterdir() if p.name != "studio.ini")
    assert left == ["shot.exr", "shot.png"]  # and no half-written temporary file


def test_export_dialog_builds_the_request(window, tmp_path):
    from lenslab.gui.export_dialog import ExportDialog

    from lenslab.colour_management.view import ViewTransform

    dialog = ExportDialog(window.doc, ViewTransform(view="clamp", exposure_stops=0.5), samples_per_second=1e5)
    assert dialog.view_combo.currentText() == "Un-tone-mapped" and dialog.exposure_spin.value() == 0.5
    dialog.path_edit.setText(str(tmp_path / "a.png"))
    dialog.format_combo.setCurrentIndex(0)  # EXR
    assert dialog.path_edit.text().endswith("a.exr")
    dialog.width_spin.setValue(128)
    assert dialog.height_spin.value() == 96  # aspect kept
    dialog.by_time.setChecked(True)
    dialog.seconds_spin.setValue(2.5)
    request = dialog.request()
    assert request.scene.camera.resolution == (128, 96)
    assert (request.target_spp, request.seconds) == (None, 2.5)
    assert window.doc.scene.camera.resolution == (64, 48)  # the document is untouched
    dialog.path_edit.setText(str(tmp_path / "missing" / "a.png"))
    assert "does not exist" in dialog.validate()
    dialog.accept()  # refused, with the reason under the settings
    assert "does not exist" in dialog.estimate.text()
    dialog.path_edit.setText(str(tmp_path / "a.png"))  # fixed: the complaint goes
    assert dialog.validate() is None and "does not exist" not in dialog.estimate.text()


# -- closing -----------------------------------------------------------------------------------------------------------
def answer_next_prompt(window, button):
    seen = []

    def answer():
        box = window.files.unsaved_box or QApplication.activeModalWidget()
        if box is None:
            QTimer.singleShot(20, answer)
            return
        seen.append(box.text())
        box.button(button).click()

    QTimer.singleShot(0, answer)
    return seen


def test_closing_with_unsaved_changes_prompts(qtbot, make_window, small_scene, tmp_path):
    from lenslab.scene.io.native import load_scene

    window = make_window(small_scene)
    window.camera_panel.set_f_number(4.0)
    assert window.isWindowModified() and "*" not in window.windowTitle().replace("[*]", "")
    seen = answer_next_prompt(window, QMessageBox.Cancel)
    assert not window.close()
    assert seen and "Save the changes" in seen[0]
    assert window.isVisible() and window.controller.worker.isRunning()

    seen = answer_next_prompt(window, QMessageBox.Discard)
    assert window.close()
    assert seen and window.controller.worker.isFinished()

    # Save writes the scene before closing.
    path = tmp_path / "scene.json"
    window = make_window(copy.deepcopy(small_scene), None)
    window.doc.saved_as(path)
    window.camera_panel.set_f_number(5.6)
    answer_next_prompt(window, QMessageBox.Save)
    assert window.close()
    assert load_scene(path).camera.f_number == 5.6

    # No changes: no question.
    window = make_window(copy.deepcopy(small_scene))
    assert window.close()


def test_the_window_closes_cleanly_while_rendering(qtbot, make_window, small_scene, tmp_path):
    import dataclasses

    small_scene.camera = dataclasses.replace(small_scene.camera, resolution=(160, 120))
    window = make_window(small_scene)
    wait_for_frame(qtbot, window, min_spp=1)
    assert window.controller.worker.isRunning() and not window.controller.last_frame.converged
    # An export in flight too: closing asks, and stopping it leaves no file.
    out = tmp_path / "never.exr"
    window.start_export(export_request(window, out, target_spp=1_000_000))
    qtbot.waitSignal(window.controller.export_progress, timeout=20000).wait()
    answered = []
    window.export_flow.cancel = lambda cancel=window.export_flow.cancel: (answered.append(True), cancel())
    answer_next_prompt(window, QMessageBox.Discard)  # Stop Export and Close
    assert window.close()
    # The answer cancelled the export, and the render thread has stopped (close waits for it; not timed, so that
    # the test holds on a loaded machine).
    assert answered and window.controller.worker.isFinished()
    assert not out.exists()
    assert window.settings.value("window/state") is not None  # the layout is remembered


def test_an_unrenderable_edit_shows_why_and_undo_recovers(qtbot, window):
    wait_for_frame(qtbot, window)
    doc = window.doc
    window.add_primitive("sphere")
    sphere = doc.selected_node_paths()[0]
    with qtbot.waitSignal(window.controller.render_error, timeout=10000,
                          check_params_cb=lambda message: bool(message)):
        doc.set_value(("node", sphere), ("transform", "scale"), (1.0, 2.0, 1.0))
    assert "needs a uniform scale, not (1, 2, 1)" in window.viewport.message
    with qtbot.waitSignal(window.controller.render_error, timeout=10000,
                          check_params_cb=lambda message: message == ""):
        doc.undo_stack.undo()
    assert window.viewport.message == ""
    wait_for_frame(qtbot, window, generation=window.controller.generation)


# -- point lights and suns -------------------------------------------------------------------------------------
def test_point_lights_and_suns_are_in_the_outliner_editable_and_undoable(qtbot, make_window, small_scene):
    from lenslab.gui.scene_tree import LIGHTS
    from lenslab.scene.lights import SunLight

    small_scene.lights = [SunLight(name="late sun", direction=(1.0, 1.0, 0.5))]
    window = make_window(small_scene)
    doc, model = window.doc, window.scene_tree.tree_model
    group = model.index_of(LIGHTS)
    assert model.data(group) == "Lights" and model.rowCount(group) == 2  # and the ceiling light, an object
    assert model.data(model.index(0, 0, group)) == "late sun"
    wait_for_frame(qtbot, window)

    # Selecting it in the outliner shows its fields; an edit there re-renders.
    window.scene_tree.setCurrentIndex(model.index(0, 0, group))
    assert doc.selection == [("light", 0)] and window.properties.title.text() == "late sun"
    generation = window.controller.generation
    irradiance = window.properties._editors[("irradiance",)].widget
    irradiance.spins[0].setValue(7.5)
    assert doc.scene.lights[0].irradiance[0] == 7.5 and window.controller.generation > generation
    # Renamed in place, deleted, then both undone.
    assert model.setData(model.index(0, 0, group), "noon sun")
    assert doc.scene.lights[0].name == "noon sun"
    window.delete_selection()
    assert doc.scene.lights == [] and model.rowCount(model.index_of(LIGHTS)) == 1
    for _ in range(3):
        doc.undo_stack.undo()
    assert doc.scene.lights == [SunLight(name="late sun", direction=(1.0, 1.0, 0.5))]

    # Edit > Add > Point Light puts one above the point of focus and selects it.
    window.actions["add_point_light"].trigger()
    assert [type(light).__name__ for light in doc.scene.lights] == ["SunLight", "PointLight"]
    assert doc.selection == [("light", 1)] and window.properties.title.text() == "point light"
    doc.undo_stack.undo()
    assert len(doc.scene.lights) == 1


def test_a_lights_unit_is_a_menu_in_the_property_editor(qtbot, window):
    """The Cornell box's ceiling light is in lumens: its unit is offered beside its colour, and a change re-renders
    and undoes (docs/colour.md, "Light units")."""
    doc = window.doc
    wait_for_frame(qtbot, window)
    doc.set_selection([("material", "light")])
    unit = window.properties._editors[("unit",)].widget
    assert [unit.itemText(i) for i in range(unit.count())] == ["nits", "lumens"] and unit.currentText() == "lumens"
    generation = window.controller.generation
    unit.setCurrentText("nits")
    assert doc.scene.materials["light"].unit == "nits" and window.controller.generation > generation
    doc.undo_stack.undo()
    assert doc.scene.materials["light"].unit == "lumens"
    wait_for_frame(qtbot, window, generation=window.controller.generation)


# -- a million triangles -----------------------------------------------------------------------------------------
def test_the_million_triangle_scene_opens_in_the_studio_and_renders(qtbot, make_window):
    import dataclasses

    from lenslab.scene.io.loader import open_scene

    scene = open_scene("marbles_on_sand")
    scene.camera = dataclasses.replace(scene.camera, resolution=(64, 48))
    window = make_window(scene)
    assert window.doc.scene.nodes[0].shape.type_name == "relief"
    frame = wait_for_frame(qtbot, window, min_spp=1, timeout=180000)
    assert frame.samples_per_pixel >= 1
