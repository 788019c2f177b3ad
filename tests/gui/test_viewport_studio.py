"""The viewport as a photographer uses it: a picture the widget's size with the sensor's gate, never blank after
an edit, a camera moved with the mouse (one undo step a gesture), a render region, and the denoised preview."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from PySide6.QtCore import QEvent, Qt

from tests.gui.helpers import send_mouse as _mouse
from tests.gui.helpers import wait_for_frame


def drag(widget, start, end, button=Qt.MiddleButton, modifiers=Qt.NoModifier, steps=5):
    _mouse(widget, QEvent.MouseButtonPress, start, button, button, modifiers)
    for i in range(1, steps + 1):
        t = i / steps
        pos = (start[0] + (end[0] - start[0]) * t, start[1] + (end[1] - start[1]) * t)
        _mouse(widget, QEvent.MouseMove, pos, Qt.NoButton, button, modifiers)
    _mouse(widget, QEvent.MouseButtonRelease, end, button, Qt.NoButton, modifiers)


def test_the_viewport_renders_at_its_own_size_with_the_gate(make_window, small_scene, settings, qtbot):
    settings.setValue("viewport/quality", "quarter")
    window = make_window(small_scene)
    viewport = window.viewport

    def sized():
        frame = window.controller.last_frame
        assert frame is not None and not frame.preview
        assert (frame.width, frame.height) == (round(viewport.width() / 4), round(viewport.height() / 4))

    qtbot.waitUntil(sized, timeout=20000)
    frame = window.controller.last_frame
    x, y, w, h = frame.gate
    export_w, export_h = small_scene.camera.resolution
    assert w / h == pytest.approx(export_w / export_h, rel=1e-6)
    assert x >= 0 and y >= 0 and x + w <= frame.width + 1e-6 and y + h <= frame.height + 1e-6
    assert viewport.gate_rect is not None and viewport.gate_rect.width() == pytest.approx(w)
    # The picture fills the viewport: no extra margin around a picture that is the widget's size.
    assert viewport.image_rect().width() == pytest.approx(viewport.width(), abs=2)


def test_an_edit_keeps_the_last_picture_until_the_new_one_is_as_good(make_window, small_scene, qtbot):
    from lenslab.gui.worker import HOLD_SECONDS, HOLD_SPP

    small_scene.camera = dataclasses.replace(small_scene.camera, resolution=(320, 240))  # with a preview pass
    window = make_window(small_scene)
    wait_for_frame(qtbot, window, min_spp=8)
    frames = []
    window.controller.frame_ready.connect(frames.append)
    window.doc.set_camera(f_number=8.0)
    generation = window.controller.generation
    wait_for_frame(qtbot, window, min_spp=1, generation=generation)
    first = next(f for f in frames if f.generation >= generation)
    # The first picture of the edit is shown because it is as good as a few samples, or because the old one
    # had been up long enough; a quarter-resolution preview never replaces the clean picture at once.
    assert (not first.preview and first.samples_per_pixel >= HOLD_SPP) or first.elapsed_seconds >= HOLD_SECONDS * 0.9
    # Every picture is whole: no pixel without a value (alpha is opaque everywhere).
    assert all((f.display[..., 3] == 255).all() for f in frames)


def test_orbit_drag_moves_the_camera_in_one_undo_step(make_window, small_scene, qtbot):
    window = make_window(small_scene)
    wait_for_frame(qtbot, window)
    before = dataclasses.replace(window.doc.scene.camera)  # a copy: edits change the scene's camera in place
    steps = window.doc.undo_stack.count()
    viewport = window.viewport
    centre = (viewport.width() / 2, viewport.height() / 2)
    drag(viewport, centre, (centre[0] + 60, centre[1] + 20))
    after = dataclasses.replace(window.doc.scene.camera)
    assert after.position != before.position
    assert window.doc.undo_stack.count() == steps + 1
    assert window.doc.undo_stack.text(steps) == "Orbit camera"
    # A second gesture is a step of its own (Maya's Alt + right button dollies).
    drag(viewport, centre, (centre[0], centre[1] - 40), button=Qt.RightButton, modifiers=Qt.AltModifier)
    assert window.doc.undo_stack.count() == steps + 2
    assert window.doc.undo_stack.text(steps + 1) == "Dolly camera"
    window.doc.undo_stack.undo()
    assert window.doc.scene.camera.position == after.position
    window.doc.undo_stack.undo()
    assert window.doc.scene.camera.position == before.position


def test_pan_drag_with_shift_middle_moves_camera_and_target(make_window, small_scene, qtbot):
    window = make_window(small_scene)
    wait_for_frame(qtbot, window)
    before = dataclasses.replace(window.doc.scene.camera)
    viewport = window.viewport
    centre = (viewport.width() / 2, viewport.height() / 2)
    drag(viewport, centre, (centre[0] + 30, centre[1]), modifiers=Qt.ShiftModifier)
    after = window.doc.scene.camera
    shift = np.subtract(after.position, before.position)
    np.testing.assert_allclose(np.subtract(after.look_at, before.look_at), shift, atol=1e-9)
    assert np.linalg.norm(shift) > 0


def test_frame_selection_points_the_camera_at_it_and_focuses(make_window, small_scene, qtbot):
    window = make_window(small_scene)
    wait_for_frame(qtbot, window)
    paths = window.doc.model.node_paths()
    window.doc.set_selection([("node", paths[-1])])
    window.actions["frame_selection"].trigger()
    camera = window.doc.scene.camera
    assert window.doc.undo_stack.text(window.doc.undo_stack.index() - 1) == "Frame selection"
    distance = np.linalg.norm(np.subtract(camera.look_at, camera.position))
    assert camera.focus_setting_for(distance) == pytest.approx(camera.focus_distance_m, abs=1e-3)


def test_the_region_tool_refines_only_its_rectangle(make_window, small_scene, qtbot):
    window = make_window(small_scene)
    wait_for_frame(qtbot, window, min_spp=2)
    window.set_tool("region")
    viewport = window.viewport
    rect = viewport.image_rect()
    start = (rect.left() + rect.width() * 0.25, rect.top() + rect.height() * 0.25)
    end = (rect.left() + rect.width() * 0.75, rect.top() + rect.height() * 0.75)
    drag(viewport, start, end, button=Qt.LeftButton)
    region = window.controller.region
    assert region is not None
    x, y, w, h = region
    assert (x, y) == pytest.approx((16, 12), abs=1) and (w, h) == pytest.approx((32, 24), abs=1)

    def refined():
        frame = window.controller.last_frame
        assert frame.region == region and frame.samples_per_pixel >= 4

    qtbot.waitUntil(refined, timeout=20000)
    assert viewport.region_rect is not None
    window.actions["clear_region"].trigger()
    qtbot.waitUntil(lambda: window.controller.last_frame.region is None and
                    window.controller.last_frame.samples_per_pixel >= 1, timeout=20000)


def test_the_denoised_preview_is_on_by_default_and_one_toggle(make_window, small_scene, settings, qtbot):
    pytest.importorskip("pyoidn")
    settings.remove("viewport/denoise")  # a new user's settings
    window = make_window(small_scene)
    assert window.actions["denoise"].isChecked()
    qtbot.waitUntil(lambda: window.controller.last_frame is not None and window.controller.last_frame.denoised
                    and window.controller.last_frame.image is not None, timeout=30000)
    assert "denoised" in window.viewport.status_text
    # Another display exposure shows the same denoised image anew (no second denoise needed): brighter.
    before = window.controller.last_frame
    window.set_display_exposure(1.0)
    qtbot.waitUntil(lambda: window.controller.last_frame.view.exposure_stops == 1.0, timeout=20000)
    after = window.controller.last_frame
    assert after.denoised
    assert after.display[..., :3].astype(float).mean() > before.display[..., :3].astype(float).mean() + 5
    window.actions["denoise"].trigger()
    assert settings.value("viewport/denoise") in (False, "false")
    qtbot.waitUntil(lambda: not window.controller.last_frame.denoised, timeout=20000)


def test_undoing_a_scrub_twice_renders_again_at_once(make_window, small_scene, qtbot):
    """A user's report: after scrubbing a translate and pressing Ctrl+Z twice the viewport stayed on
    "preview" at 0 samples/s for 15 to 25 s. Undo is an edit like any other: a full pass follows promptly."""
    small_scene.camera = dataclasses.replace(small_scene.camera, resolution=(320, 240))  # with a preview pass
    window = make_window(small_scene)
    wait_for_frame(qtbot, window, min_spp=2)
    path = window.doc.model.node_paths()[-1]
    x, y, z = window.doc.model.get_value(("node", path), ("transform", "translate"))
    for i in range(1, 6):  # a scrub: many merged edits
        window.doc.set_value(("node", path), ("transform", "translate"), (x + 0.01 * i, y, z), merge=True)
    window.doc.set_value(("node", path), ("transform", "translate"), (x, y + 0.05, z))
    window.doc.undo_stack.undo()
    window.doc.undo_stack.undo()
    assert window.doc.model.get_value(("node", path), ("transform", "translate")) == (x, y, z)
    frame = wait_for_frame(qtbot, window, min_spp=2, generation=window.controller.generation, timeout=10000)
    assert frame.samples_per_second > 0


def test_the_selection_outline_follows_a_lens_drag(make_window, small_scene, qtbot):
    """A user's report: the selection outline lagged a lens change by seconds. The depth and selection buffer
    is now remade during a drag too (every GBUFFER_INTERVAL), not only once the edits stop."""
    from PySide6.QtCore import QTimer

    small_scene.camera = dataclasses.replace(small_scene.camera, resolution=(320, 240))  # with a preview pass
    window = make_window(small_scene)
    wait_for_frame(qtbot, window)
    start_generation = window.controller.generation
    seen = []  # (generation of the buffer, the newest edit's generation when it arrived)
    window.controller.gbuffer_ready.connect(lambda g: seen.append((g.generation, window.controller.generation)))
    ticks = iter(range(60))
    timer = QTimer()
    timer.setInterval(15)

    def tick():
        i = next(ticks, None)
        if i is None:
            timer.stop()
            return
        window.doc.set_camera(focal_length_mm=30.0 + i * 0.5, merge=True)

    timer.timeout.connect(tick)
    timer.start()
    qtbot.waitUntil(lambda: not timer.isActive(), timeout=20000)
    last_generation = window.controller.generation
    during = [g for g, newest in seen if start_generation < g and newest < last_generation]
    assert during, f"no selection buffer during the drag: {seen}"
