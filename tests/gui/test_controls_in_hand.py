"""Controls that only do what they are asked (docs/studio.md, "The camera panel"): the wheel scrolls a panel over
its sliders and lists without changing them, and edits only a focused control; a focal-length drag through a long
lens leaves the focus where it was; a slider drag is one step in the History however long the hand takes."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication, QHBoxLayout, QScrollArea, QStyle, QStyleOptionSlider, QWidget

from lenslab.optics import format_distance


@pytest.fixture
def studio(qtbot, small_scene):
    """The camera panel in its scroll area beside the viewport, as the window lays them out, short enough that the
    panel scrolls."""
    from lenslab.gui.app import create_application
    from lenslab.gui.camera_panel import CameraPanel
    from lenslab.gui.document import Document
    from lenslab.gui.navigation import CameraNavigator
    from lenslab.gui.viewport import Viewport

    create_application()
    doc = Document(small_scene)
    top = QWidget()
    qtbot.addWidget(top)
    layout = QHBoxLayout(top)
    viewport = Viewport()
    navigator = CameraNavigator(doc, viewport, lambda: doc.scene.camera.view_frame(320, 240, 0.04))
    panel = CameraPanel(doc)
    scroll = QScrollArea()
    scroll.setWidgetResizable(True)
    scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
    scroll.setWidget(panel)
    scroll.setMinimumWidth(330)
    layout.addWidget(viewport, 1)
    layout.addWidget(scroll)
    top.resize(900, 360)
    top.show()
    qtbot.waitExposed(top)
    top.activateWindow()
    qtbot.waitUntil(top.isActiveWindow)
    yield SimpleNamespace(doc=doc, top=top, viewport=viewport, navigator=navigator, panel=panel, scroll=scroll)
    doc.silence()


def wheel_over(top, widget, notches: int = -1, modifiers=Qt.NoModifier) -> None:
    """Turn the wheel with the mouse over ``widget``'s centre, as the window system delivers it (to the widget
    under the mouse, then its parents if it does not take it)."""
    at = widget.mapTo(top, widget.rect().center())
    QTest.wheelEvent(top.windowHandle(), QPointF(at), QPoint(0, 120 * notches), QPoint(0, 0), modifiers)
    QApplication.processEvents()


def test_the_wheel_scrolls_the_panel_over_its_sliders_and_lists_and_changes_nothing(studio):
    doc, panel, scroll = studio.doc, studio.panel, studio.scroll
    bar = scroll.verticalScrollBar()
    assert bar.maximum() > 0, "the panel must be taller than its dock for this test"
    for control in (panel.focus_slider, panel.focal_slider, panel.stop_slider.slider, panel.focus_from,
                    panel.focus):
        assert not control.hasFocus()
        scroll.ensureWidgetVisible(control, 0, 60)
        QApplication.processEvents()
        camera, rows, scrolled = dataclasses.replace(doc.scene.camera), doc.undo_stack.count(), bar.value()
        assert scrolled < bar.maximum()
        wheel_over(studio.top, control, notches=-1)
        assert doc.scene.camera == camera, f"the wheel over {control.objectName() or control} changed the camera"
        assert doc.undo_stack.count() == rows
        assert bar.value() > scrolled, "the panel scrolls instead"


def test_the_wheel_edits_a_focused_control_and_the_viewport_keeps_its_wheel(studio):
    doc, panel = studio.doc, studio.panel
    studio.scroll.ensureWidgetVisible(panel.focus_slider, 0, 60)
    for control in (panel.focus_slider, panel.focus):
        control.setFocus(Qt.MouseFocusReason)
        assert control.hasFocus()
        before = doc.scene.camera.focus_distance_m
        wheel_over(studio.top, control, notches=1)
        assert doc.scene.camera.focus_distance_m > before
        focus = format_distance(doc.scene.camera.focus_distance_m)
        assert doc.undo_stack.text(doc.undo_stack.index() - 1) == f"Focus {focus}"
    # The viewport zooms the picture with the wheel and dollies the camera with Ctrl + wheel, focused or not.
    viewport = studio.viewport
    viewport.zoom = 1.0
    wheel_over(studio.top, viewport, notches=1)
    assert viewport.zoom > 1.0
    position = doc.scene.camera.position
    wheel_over(studio.top, viewport, notches=1, modifiers=Qt.ControlModifier)
    assert doc.scene.camera.position != position
    assert doc.undo_stack.text(doc.undo_stack.index() - 1) == "Dolly camera"


def slider_x(slider, value: int) -> int:
    """Where the middle of the slider's handle lies (widget pixels) when it shows ``value``."""
    option = QStyleOptionSlider()
    slider.initStyleOption(option)
    style = slider.style()
    groove = style.subControlRect(QStyle.CC_Slider, option, QStyle.SC_SliderGroove, slider)
    handle = style.subControlRect(QStyle.CC_Slider, option, QStyle.SC_SliderHandle, slider)
    span = groove.width() - handle.width()
    return groove.x() + QStyle.sliderPositionFromValue(slider.minimum(), slider.maximum(), value, span) \
        + handle.width() // 2


def drag_slider(slider, values, on_the_way=None) -> None:
    """Grab the slider's handle with the mouse and drag it through ``values`` (slider positions), one mouse event
    each; ``on_the_way(value)`` is called after each."""
    y = slider.height() // 2

    def send(kind, x, button, buttons):
        at = QPointF(x, y)
        QApplication.sendEvent(slider, QMouseEvent(kind, at, slider.mapToGlobal(at), button, buttons,
                                                   Qt.NoModifier))

    send(QEvent.MouseButtonPress, slider_x(slider, slider.value()), Qt.LeftButton, Qt.LeftButton)
    assert slider.isSliderDown()
    for value in values:
        send(QEvent.MouseMove, slider_x(slider, value), Qt.NoButton, Qt.LeftButton)
        if on_the_way is not None:
            on_the_way(slider.value())
    send(QEvent.MouseButtonRelease, slider_x(slider, values[-1]), Qt.LeftButton, Qt.NoButton)


def test_a_focal_length_drag_through_a_long_lens_leaves_the_focus_as_it_was(studio):
    from lenslab.gui.widgets import log_to_slider

    doc, panel = studio.doc, studio.panel
    panel.set_focal_length(50.0, False)
    assert panel.set_focus(3.09)
    studio.scroll.ensureWidgetVisible(panel.focal_slider)
    slider = panel.focal_slider
    rows = doc.undo_stack.count()
    seen, said = [], []
    panel.status_message.connect(said.append)
    out = list(range(slider.value(), slider.maximum() + 1, 25)) + [slider.maximum()]
    back = list(range(slider.maximum(), log_to_slider(31.0, 8.0, 800.0) - 1, -25)) + [log_to_slider(31.0, 8.0, 800.0)]
    drag_slider(slider, out + back,
                lambda _v: seen.append((doc.scene.camera.focal_length_mm, doc.scene.camera.focus_distance_m)))
    # At 800 mm the lens focuses no nearer than 3.20 m, and the picture is focused there; back at 31 mm the
    # focus is the photographer's 3.09 m again, to the last digit.
    assert max(seen) == (800.0, pytest.approx(3.2))
    camera = doc.scene.camera
    assert camera.focal_length_mm == pytest.approx(31.0, abs=0.2)
    assert camera.focus_distance_m == 3.09
    # The status bar said the focus moved out, and then that it is back: its last word is not the long lens's.
    assert any("focuses no nearer" in line for line in said)
    assert said[-1] == "Focus back at 3.09 m, where it was set"
    # One step, which undoes to where the drag began.
    assert doc.undo_stack.count() == rows + 1
    assert doc.undo_stack.text(rows).startswith("Focal length ")
    doc.undo_stack.undo()
    assert (doc.scene.camera.focal_length_mm, doc.scene.camera.focus_distance_m) == (50.0, 3.09)


def test_a_focal_length_typed_or_stepped_past_what_the_focus_allows_moves_it_out_and_back(studio):
    doc, panel = studio.doc, studio.panel
    panel.set_focal_length(50.0, False)
    assert panel.set_focus(3.09)
    rows = doc.undo_stack.count()
    # The arrow keys on the field, one after another: one step, and the focus back where it was.
    for mm in (200.0, 800.0, 400.0, 31.0):
        panel.focal.setValue(mm)
    assert doc.scene.camera.focus_distance_m == 3.09 and doc.undo_stack.count() == rows + 1
    # A focal length chosen on its own that cannot focus so near moves the focus out, in the same step.
    panel.set_focal_length(800.0, False)
    assert doc.scene.camera.focus_distance_m == pytest.approx(3.2)
    doc.undo_stack.undo()
    assert (doc.scene.camera.focal_length_mm, doc.scene.camera.focus_distance_m) == (31.0, 3.09)


@pytest.mark.parametrize("name", ["focal_slider", "focus_slider", "aperture"])
def test_a_long_slider_drag_is_one_step_in_the_history(studio, monkeypatch, name):
    from lenslab.gui import commands

    # The hand pauses longer than the merge window between every two moves.
    monkeypatch.setattr(commands, "MERGE_SECONDS", -1.0)
    doc, panel = studio.doc, studio.panel
    slider = panel.stop_slider.slider if name == "aperture" else getattr(panel, name)
    studio.scroll.ensureWidgetVisible(slider)
    start = slider.value()
    rows = doc.undo_stack.count()
    # A dozen moves of the handle, each to another position (a stop of the aperture, a pixel or so of the others).
    span = max(12, (slider.maximum() - slider.minimum()) // 80)
    ahead = min(slider.maximum(), start + span)
    drag_slider(slider, [start + (ahead - start) * i // 12 for i in range(1, 13)])
    dragged = slider.value()
    assert dragged > start
    assert doc.undo_stack.count() == rows + 1
    # A second drag is a step of its own, however soon it follows.
    monkeypatch.setattr(commands, "MERGE_SECONDS", 1e9)
    drag_slider(slider, [ahead - (ahead - start) * i // 12 for i in range(1, 13)])
    assert slider.value() < dragged
    assert doc.undo_stack.count() == rows + 2
    doc.undo_stack.undo()
    assert slider.value() == dragged
