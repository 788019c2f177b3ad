"""What a photographer found wrong in the studio, each fixed and held here: History rows that
name the value they restore, a translate scrub that follows the mouse on screen, every light under Lights, example
scenes with proper names, file dialogs that remember their folder, and a display exposure that can be typed and
reset."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent

from lenslab.optics import format_distance, format_f_number

from .helpers import wait_for_frame


@pytest.fixture
def doc(qtbot, small_scene):
    from lenslab.gui.app import create_application
    from lenslab.gui.document import Document

    create_application()
    document = Document(small_scene)
    yield document
    document.silence()  # its undo stack says nothing more as Qt deletes it


def last_row(doc) -> str:
    """The newest row of the History panel (a QUndoView shows each command's text)."""
    stack = doc.undo_stack
    return stack.text(stack.count() - 1)


def node_path(doc, name: str) -> tuple:
    return next(path for path, node in doc.model.walk_nodes() if node.name == name)


def axis_label(vector, axis: int):
    """The letter (X, Y, Z) in front of one of a vector field's numbers."""
    from lenslab.gui.widgets import ScrubLabel

    return vector.findChildren(ScrubLabel)[axis]


def scrub(label, dx: int, modifiers=Qt.NoModifier) -> None:
    """Drag a field's letter ``dx`` pixels sideways, in steps of a few pixels, as a hand does."""
    start = label.mapToGlobal(QPoint(4, 4))

    def send(kind, x, button, buttons):
        at = QPointF(start.x() + x, start.y())
        event = QMouseEvent(kind, label.mapFromGlobal(at), at, button, buttons, modifiers)
        {QEvent.MouseButtonPress: label.mousePressEvent, QEvent.MouseMove: label.mouseMoveEvent,
         QEvent.MouseButtonRelease: label.mouseReleaseEvent}[kind](event)

    send(QEvent.MouseButtonPress, 0, Qt.LeftButton, Qt.LeftButton)
    step = 5 if dx >= 0 else -5
    for x in list(range(step, dx, step)) + [dx]:
        send(QEvent.MouseMove, x, Qt.NoButton, Qt.LeftButton)
    send(QEvent.MouseButtonRelease, dx, Qt.LeftButton, Qt.NoButton)


# -- 1. History rows name the value they restore ---------------------------------------------------------------------
def test_a_dragged_slider_or_field_names_the_value_its_history_row_restores(doc):
    from lenslab.gui.camera_panel import CameraPanel
    from lenslab.gui.properties import PropertyEditor

    panel = CameraPanel(doc)
    stack = doc.undo_stack
    # The aperture slider from f/4 to f/22, one notch at a time: one step, named after where it ended.
    panel.set_f_number(4.0)
    slider = panel.stop_slider.slider
    scale = panel.stop_slider.scale
    start, end = slider.value(), next(i for i, stop in enumerate(scale) if format_f_number(stop) == "f/22")
    count = stack.count()
    for index in range(start + 1, end + 1):
        slider.setValue(index)
    assert stack.count() == count + 1
    assert format_f_number(doc.scene.camera.f_number) == "f/22"
    assert last_row(doc) == "Aperture f/22"
    stack.undo()
    assert format_f_number(doc.scene.camera.f_number) == "f/4"
    stack.redo()  # the row restores what it says
    assert format_f_number(doc.scene.camera.f_number) == "f/22"

    # The focal length slider, the focus slider and field, the iris's numbers and the sensor: each merged drag
    # reads its last value.
    for position in (500, 520, 560):
        panel.focal_slider.setValue(position)
    assert last_row(doc) == f"Focal length {doc.scene.camera.focal_length_mm:g} mm"
    for position in (300, 340, 420):
        panel.focus_slider.setValue(position)
    assert last_row(doc) == f"Focus {format_distance(doc.scene.camera.focus_distance_m)}"
    for metres in (2.0, 2.25, 2.5):
        panel.focus.setValue(metres)
    assert last_row(doc) == "Focus 2.50 m"
    for value in (0.2, 0.4, 0.65):
        panel.curvature.setValue(value)
    assert last_row(doc) == "Blade curvature 0.65"
    for value in (5, 6, 7):
        panel.blades.setValue(value)
    assert last_row(doc) == "Aperture blades 7"
    for degrees in (10.0, 20.0, 35.0):
        panel.rotation.setValue(degrees)
    assert last_row(doc) == "Blade rotation 35°"
    for width in (30.0, 28.0, 23.5):
        panel.sensor_w.setValue(width)
    assert last_row(doc) == f"Sensor size 23.5 × {doc.scene.camera.sensor_mm[1]:g} mm"

    # A scrub in the Properties panel: "Move tall box to" where it ended, not where it was after one pixel.
    editor = PropertyEditor(doc)
    editor.picture_height = lambda: 600.0
    doc.set_selection([("node", node_path(doc, "tall box"))])
    translate = editor._editors[("transform", "translate")].widget
    scrub(axis_label(translate, 0), 80)
    x, y, z = doc.model.node(node_path(doc, "tall box")).transform.translate
    assert last_row(doc) == f"Move tall box to ({x:.4g}, {y:.4g}, {z:.4g})"
    assert x != pytest.approx(-0.18)


# -- 2. The translate scrub follows the mouse ------------------------------------------------------------------------
def screen_x(camera, point, picture_height: float) -> float:
    """Where a world point is drawn, in screen pixels from the picture's centre, with the picture
    ``picture_height`` pixels tall: the pinhole projection, written out here."""
    frame = camera.frame()
    offset = np.asarray(point, float) - frame.position
    depth = float(offset @ frame.forward)
    return float(offset @ frame.right) / (depth * frame.tan_half_fov[1]) * picture_height / 2


@pytest.mark.parametrize("modifiers, drag, on_screen", [(Qt.NoModifier, 100, 100), (Qt.ShiftModifier, 100, 10),
                                                        (Qt.ControlModifier, 10, 100)])
def test_the_translate_scrub_moves_an_object_as_far_on_screen_as_the_mouse(doc, modifiers, drag, on_screen):
    from lenslab.gui.properties import PropertyEditor

    height = 640.0
    editor = PropertyEditor(doc)
    editor.picture_height = lambda: height
    path = node_path(doc, "tall box")
    doc.set_selection([("node", path)])
    before = doc.model.node(path).transform.translate
    scrub(axis_label(editor._editors[("transform", "translate")].widget, 0), drag, modifiers)
    after = doc.model.node(path).transform.translate
    moved = screen_x(doc.scene.camera, after, height) - screen_x(doc.scene.camera, before, height)
    assert moved == pytest.approx(on_screen, rel=0.02)
    assert after[1:] == before[1:]
    # In metres: a couple of millimetres a pixel in the Cornell box, not the 2.5 cm that sent the box out of it.
    assert abs(after[0] - before[0]) / (drag * {Qt.NoModifier: 1, Qt.ShiftModifier: 0.1,
                                                Qt.ControlModifier: 10}[modifiers]) < 0.003


def test_the_scrub_rate_scales_with_distance_zoom_and_a_scaled_group(small_scene):
    from lenslab.scene.editable import EditableScene
    from lenslab.scene.editing import screen_drag_rate

    model = EditableScene(small_scene)
    box = ("node", next(p for p, n in model.walk_nodes() if n.name == "tall box"))
    near = screen_drag_rate(model, box, 600)
    assert screen_drag_rate(model, box, 300) == pytest.approx(2 * near)  # the picture drawn half as tall
    # The camera twice as far from the box: twice the metres per pixel.
    cam = model.scene.camera
    box_z = -0.15
    far_z = box_z + 2 * (cam.position[2] - box_z)
    model.scene.camera = dataclasses.replace(cam, position=(cam.position[0], cam.position[1], far_z),
                                             look_at=(cam.look_at[0], cam.look_at[1], far_z - 1.0))
    assert screen_drag_rate(model, box, 600) == pytest.approx(2 * near, rel=0.01)
    model.scene.camera = cam
    # Inside a group scaled twice, a ball's own translate moves twice as far: half the number per pixel. Both
    # balls sit 2 m ahead of the lens.
    from lenslab.scene.scene import Node
    from lenslab.scene.shapes import Sphere
    from lenslab.scene.transform import Transform

    model.scene.nodes += [Node("ball", Transform(translate=(0.0, 0.5, -0.1)), Sphere(radius=0.05)),
                          Node("group", Transform(scale=(2.0, 2.0, 2.0)), None,
                               children=[Node("small ball", Transform(translate=(0.0, 0.25, -0.05)),
                                              Sphere(radius=0.025))])]
    ball, small_ball = ("node", (len(model.scene.nodes) - 2,)), ("node", (len(model.scene.nodes) - 1, 0))
    two_metres = cam.frame().view_size_at(2.0)[1] / 600
    assert screen_drag_rate(model, ball, 600) == pytest.approx(two_metres)
    assert screen_drag_rate(model, small_ball, 600) == pytest.approx(two_metres / 2)
    # Behind the camera the plane of focus stands in; a sun has no place to drag.
    model.node(box[1]).transform = dataclasses.replace(model.node(box[1]).transform, translate=(0.0, 0.5, 5.0))
    focus = cam.frame().view_size_at(cam.frame().focus_distance)[1] / 600
    assert screen_drag_rate(model, box, 600) == pytest.approx(focus)
    from lenslab.scene.lights import PointLight, SunLight

    model.scene.lights += [SunLight(name="sun"), PointLight(name="bulb", position=(0.0, 0.5, -2.1))]
    assert screen_drag_rate(model, ("light", 0), 600) is None
    assert screen_drag_rate(model, ("light", 1), 600) == pytest.approx(cam.frame().view_size_at(4.0)[1] / 600)


# -- 3. Every light under Lights -------------------------------------------------------------------------------------
def test_the_ceiling_light_is_under_lights_and_selects_the_object(doc, qtbot):
    from lenslab.gui import scene_tree
    from lenslab.gui.scene_tree import LIGHTS, SceneTreeView
    from lenslab.scene.materials import Diffuse

    view = SceneTreeView(doc)
    qtbot.addWidget(view)
    model = view.tree_model
    group = model.index_of(LIGHTS)
    assert group.isValid() and model.rowCount(group) == 1
    entry = model.index(0, 0, group)
    ceiling = node_path(doc, "ceiling light")
    EMITTER = scene_tree.EMITTER
    assert model.key(entry) == (EMITTER, ceiling) and model.data(entry) == "ceiling light"
    assert "emissive" in model.data(entry, Qt.ToolTipRole)
    # Clicking it selects the object itself (the viewport outlines it, the properties show it), and both its rows
    # show that; a Ctrl-click on either lets go of it.
    view.resize(300, 500)
    view.show()

    def click(key, modifiers=Qt.NoModifier):
        qtbot.mouseClick(view.viewport(), Qt.LeftButton, modifiers, view.visualRect(model.index_of(key)).center())

    def rows():
        return {model.key(i) for i in view.selectionModel().selectedRows()}

    click((EMITTER, ceiling))
    assert doc.selection == [("node", ceiling)] and rows() == {("node", ceiling), (EMITTER, ceiling)}
    tall = ("node", node_path(doc, "tall box"))
    click(tall, Qt.ControlModifier)
    assert doc.selection == [("node", ceiling), tall]
    click(("node", ceiling), Qt.ControlModifier)
    assert doc.selection == [tall] and rows() == {tall}
    # Selected from elsewhere, both its rows show it.
    doc.set_selection([("node", ceiling)])
    assert rows() == {("node", ceiling), (EMITTER, ceiling)}
    # Renamed there, it is the object that is renamed.
    assert model.setData(model.index(0, 0, model.index_of(LIGHTS)), "softbox")
    assert doc.model.node(ceiling).name == "softbox"
    # A light that stops glowing leaves the group; with no light at all there is no group.
    doc.set_value(("material", "light"), (), Diffuse())
    assert not model.index_of(LIGHTS).isValid()
    doc.undo_stack.undo()
    assert model.rowCount(model.index_of(LIGHTS)) == 1
    # A box given the light's material joins it.
    doc.set_value(("node", node_path(doc, "short box")), ("material",), "light")
    names = [model.data(model.index(r, 0, model.index_of(LIGHTS))) for r in range(2)]
    assert names == ["short box", "softbox"]


# -- 4. Example names ------------------------------------------------------------------------------------------------
def test_shipped_scene_names_read_as_titles():
    from lenslab.scene.io.loader import scene_title

    assert scene_title("dof_chart") == "DOF Chart"
    assert scene_title("cornell_box") == "Cornell Box"
    assert scene_title("product_shot") == "Product Shot"
    assert scene_title("marbles_on_sand") == "Marbles on Sand"
    assert scene_title("on_the_table") == "On the Table"
    assert scene_title("my-HDRI_studio") == "My HDRI Studio"
    assert scene_title("McLaren_in_fog") == "McLaren in Fog"


def test_file_open_example_lists_the_scenes_by_their_titles(window):
    examples = [a.text() for a in window.shipped_menu.actions()]
    assert {"DOF Chart", "Cornell Box", "Product Shot", "Marbles on Sand"} <= set(examples)
    window.shipped_menu.actions()[examples.index("DOF Chart")].trigger()
    assert window.windowTitle().startswith("DOF Chart (example)")


# -- 5. File dialogs remember their folders --------------------------------------------------------------------------
def test_file_dialogs_start_in_the_folder_used_last_even_after_a_restart(qtbot, make_window, small_scene, tmp_path,
                                                                       monkeypatch):
    from PySide6.QtWidgets import QDialog, QFileDialog

    from lenslab.gui import main_window
    from lenslab.gui.document import copy_scene
    from lenslab.gui.worker import ExportRequest
    from lenslab.scene.io.native import save_scene

    window = make_window(small_scene)

    scenes, saved, meshes, images = (tmp_path / name for name in ("scenes", "saved", "meshes", "images"))
    for folder in (scenes, saved, meshes, images):
        folder.mkdir()
    save_scene(small_scene, scenes / "table.json")
    asked = {}

    def open_file(_parent, _caption, start, _filter=""):
        asked["open"] = start
        return str(scenes / "table.json"), ""

    def save_file(_parent, _caption, start, _filter=""):
        asked["save"] = start
        return str(saved / "copy.json"), ""

    def open_files(_parent, _caption, start, _filter=""):
        asked["import"] = start
        return [str(meshes / "teapot.obj")], ""

    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(open_file))
    monkeypatch.setattr(QFileDialog, "getSaveFileName", staticmethod(save_file))
    monkeypatch.setattr(QFileDialog, "getOpenFileNames", staticmethod(open_files))
    monkeypatch.setattr(main_window.MainWindow, "import_mesh", lambda self, path: None)

    class Dialog:  # the export dialog: records where it starts, and renders a small picture into images/
        Accepted = QDialog.Accepted
        started_at = []

        def __init__(self, doc, view, rate, last_path, parent):
            Dialog.started_at.append(last_path)
            self.doc = doc

        def exec(self):
            return QDialog.Accepted

        def request(self):
            scene = copy_scene(self.doc.scene)
            scene.camera = dataclasses.replace(scene.camera, resolution=(16, 12))
            return ExportRequest(scene=scene, path=images / "shot.png", target_spp=1, seconds=None)

    monkeypatch.setattr(window.export_flow, "make_dialog", Dialog)  # the export flow's dialog

    window.open_dialog()
    window.save_as()
    window.import_dialog()
    window.export_dialog()
    qtbot.waitUntil(lambda: window.export_id is None and (images / "shot.png").is_file(), timeout=20000)
    window.close()

    # The next run starts every dialog where the last one left off.
    again = make_window(small_scene)
    again.save_as()
    assert asked["save"] == str(saved / "Untitled.json")
    again.open_dialog()
    assert asked["open"] == str(saved)  # scenes opened and saved share a folder: the last was the save
    again.import_dialog()
    assert asked["import"] == str(meshes)
    Dialog.started_at.clear()
    monkeypatch.setattr(again.export_flow, "make_dialog", Dialog)
    monkeypatch.setattr(Dialog, "exec", lambda self: QDialog.Rejected)
    again.export_dialog()
    assert Dialog.started_at[0].parent == images


# -- 6. The display exposure: typed, stepped, reset ------------------------------------------------------------------
def test_the_display_exposure_can_be_typed_stepped_and_reset(qtbot, window):
    from PySide6.QtTest import QTest

    wait_for_frame(qtbot, window)
    spin, slider, reset = window.exposure_spin, window.exposure_slider, window.exposure_reset
    spin.setFocus()
    spin.lineEdit().selectAll()
    QTest.keyClicks(spin, "1.5")
    QTest.keyClick(spin, Qt.Key_Return)
    assert window.viewport.exposure == 1.5 and slider.value() == 15 and spin.text() == "+1.5 EV"
    qtbot.waitUntil(lambda: window.controller.last_frame.view.exposure_stops == 1.5, timeout=10000)
    QTest.keyClick(spin, Qt.Key_Up)
    assert window.viewport.exposure == pytest.approx(1.6) and slider.value() == 16
    slider.setValue(-23)
    assert spin.value() == pytest.approx(-2.3) and window.viewport.exposure == pytest.approx(-2.3)
    assert reset.isEnabled()
    reset.click()
    assert window.viewport.exposure == 0 and slider.value() == 0 and spin.text() == "0.0 EV"
    assert not reset.isEnabled()
    slider.setValue(30)
    qtbot.mouseDClick(slider, Qt.LeftButton, pos=slider.rect().center())
    assert window.viewport.exposure == 0 and spin.value() == 0
    # The scrub rate reads the export frame's height as the viewport draws it.
    gate = window.viewport.gate_rect
    expected = (gate.height() if gate is not None else window.viewport.image_size()[1]) * window.viewport.scale()
    assert window.properties.picture_height() == pytest.approx(expected) and expected > 0
