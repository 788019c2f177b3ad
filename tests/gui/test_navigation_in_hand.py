"""Moving the camera with the mouse as in Blender and Maya, through the real viewport (docs/studio.md, "Moving the
camera"): a drag moves the camera as far whether the mouse reported it in one event or in a hundred, orbits turn
about the selection when there is one, a modifier held during the drag makes it fine, the Ctrl+wheel dollies in
fixed steps, and each gesture is one step in the History."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication

from .helpers import send_mouse

VIEW = (640, 480)

GESTURES = {  # what starts each gesture: button and modifiers at the press
    "orbit": (Qt.MiddleButton, Qt.NoModifier),
    "pan": (Qt.MiddleButton, Qt.ShiftModifier),
    "dolly": (Qt.MiddleButton, Qt.ControlModifier),
    "maya orbit": (Qt.LeftButton, Qt.AltModifier),
}


@pytest.fixture
def studio(qtbot, small_scene):
    """The studio's camera moves without its renderer: the document, the real Viewport widget and the navigator
    the window wires to it, the picture on screen framed as the window frames it."""
    from lenslab.gui.app import create_application
    from lenslab.gui.document import Document
    from lenslab.gui.navigation import CameraNavigator
    from lenslab.gui.viewport import Viewport

    create_application()
    doc = Document(small_scene)
    viewport = Viewport()
    qtbot.addWidget(viewport)
    viewport.resize(*VIEW)
    viewport.show()
    navigator = CameraNavigator(doc, viewport, lambda: doc.scene.camera.view_frame(*VIEW, 0.04))
    yield SimpleNamespace(doc=doc, viewport=viewport, navigator=navigator)
    doc.silence()


def drag(viewport, travel, events: int, gesture: str = "orbit", during=None) -> None:
    """Press, move ``travel`` = (dx, dy) pixels from the viewport's centre in ``events`` mouse moves, release.
    ``during`` gives the modifiers held at each move (by its index); by default those of the press."""
    button, modifiers = GESTURES[gesture]
    x0, y0 = viewport.width() / 2, viewport.height() / 2
    send_mouse(viewport, QEvent.MouseButtonPress, (x0, y0), button, button, modifiers)
    for i in range(1, events + 1):
        t = i / events
        held = modifiers if during is None else during(i, events)
        send_mouse(viewport, QEvent.MouseMove, (x0 + travel[0] * t, y0 + travel[1] * t), Qt.NoButton, button, held)
    send_mouse(viewport, QEvent.MouseButtonRelease, (x0 + travel[0], y0 + travel[1]), button, Qt.NoButton, modifiers)


def placed(camera) -> np.ndarray:
    return np.concatenate([camera.position, camera.look_at])


def camera_after(studio, travel, events, gesture="orbit", during=None):
    """The camera a drag leaves, which is then undone: each drag starts from the same camera."""
    stack = studio.doc.undo_stack
    index = stack.index()
    drag(studio.viewport, travel, events, gesture, during)
    after = dataclasses.replace(studio.doc.scene.camera)
    assert stack.index() == index + 1 and stack.count() == index + 1, "one drag, one step in the History"
    stack.undo()
    return after


@pytest.mark.parametrize("gesture", ["orbit", "pan", "dolly", "maya orbit"])
def test_a_drag_moves_the_camera_as_far_whatever_the_mouse_event_rate(studio, gesture):
    before = dataclasses.replace(studio.doc.scene.camera)
    cameras = [camera_after(studio, (100, -40), events, gesture) for events in (1, 10, 100)]
    assert placed(studio.doc.scene.camera) == pytest.approx(placed(before))  # each undone
    moved = np.linalg.norm(placed(cameras[0]) - placed(before))
    assert moved > 0.05
    for camera in cameras[1:]:
        np.testing.assert_allclose(placed(camera), placed(cameras[0]), rtol=0, atol=1e-9)


def depth_and_place(camera, point) -> np.ndarray:
    """Where a point lies in the camera's own frame (right, up, back): the same numbers, the same place in the
    picture at the same distance."""
    frame = camera.frame()
    return (np.asarray(point, float) - frame.position) @ frame.to_world


def test_an_orbit_turns_about_the_selection_and_otherwise_about_the_plane_of_focus(studio):
    from lenslab.scene import navigation

    doc = studio.doc
    start = dataclasses.replace(doc.scene.camera)
    focus_pivot = navigation.pivot(start)
    # Nothing selected: the point of the view axis in focus stays where it is, in the middle of the frame.
    orbited = camera_after(studio, (120, 30), 12)
    np.testing.assert_allclose(depth_and_place(orbited, focus_pivot), depth_and_place(start, focus_pivot),
                               atol=1e-9)
    # The tall box selected: its centre keeps its place in the picture and its distance, off the axis as it is.
    path = next(p for p, node in doc.model.walk_nodes() if node.name == "tall box")
    doc.set_selection([("node", path)])
    flat = doc.scene.flatten()
    boxes = flat.prim_bounds()[np.isin(flat.prim_node, doc.model.subtree_indices(path))]
    centre = (boxes[:, 0].min(axis=0) + boxes[:, 1].max(axis=0)) / 2
    orbited = camera_after(studio, (120, 30), 12)
    assert np.linalg.norm(placed(orbited) - placed(start)) > 0.05
    np.testing.assert_allclose(depth_and_place(orbited, centre), depth_and_place(start, centre), atol=1e-9)
    assert np.linalg.norm(depth_and_place(start, centre)[:2]) > 0.05  # it was off the axis, and it stays there


@pytest.mark.parametrize("gesture, fine", [("orbit", Qt.ShiftModifier), ("dolly", Qt.ShiftModifier),
                                           ("maya orbit", Qt.ShiftModifier),
                                           # Shift chose Blender's pan; Ctrl makes it fine.
                                           ("pan", Qt.ControlModifier)])
def test_a_modifier_held_during_the_drag_makes_that_part_of_it_fine(studio, gesture, fine):
    _button, chosen_by = GESTURES[gesture]

    def second_half_fine(i, events):
        return chosen_by | fine if i > events // 2 else chosen_by

    # 60 pixels at full speed then 60 at a tenth are 66 pixels: in 2 events or in 120.
    slow = [camera_after(studio, (120, 60), events, gesture, second_half_fine) for events in (2, 120)]
    plain = camera_after(studio, (66, 33), 1, gesture)
    for camera in slow:
        np.testing.assert_allclose(placed(camera), placed(plain), rtol=0, atol=1e-9)


def test_ctrl_wheel_dollies_a_fixed_step_a_notch_and_the_notches_make_one_step(studio):
    doc, viewport = studio.doc, studio.viewport
    stack = doc.undo_stack
    index = stack.index()
    start = dataclasses.replace(doc.scene.camera)
    positions = [np.asarray(start.position)]
    centre = QPointF(viewport.width() / 2, viewport.height() / 2)
    for _notch in range(3):
        event = QWheelEvent(centre, viewport.mapToGlobal(centre), QPoint(0, 0), QPoint(0, 120), Qt.NoButton,
                            Qt.ControlModifier, Qt.NoScrollPhase, False)
        QApplication.sendEvent(viewport, event)
        positions.append(np.asarray(doc.scene.camera.position))
    # Each notch walks the same way by the same share of the distance to the pivot; with nothing selected the
    # pivot is the plane of focus, which the focus ring (untouched) carries along: the same distance each time.
    steps = np.diff(positions, axis=0)
    forward = -start.basis()[2]
    assert (steps @ forward > 0).all()
    np.testing.assert_allclose(steps, [steps[0]] * 3, rtol=0, atol=1e-9)
    assert stack.index() == index + 1 and stack.text(index) == "Dolly camera"
    stack.undo()
    assert placed(doc.scene.camera) == pytest.approx(placed(start))
