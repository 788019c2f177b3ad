"""Snapshots and A/B comparison: keep a render at f/1.4 and compare it with the live one at f/4,
with a split wipe or side by side.

The store's rules (the cap, the labels, the picture made again through another view) are checked without a window;
the rest drives the studio offscreen. Pixel checks compare a grab of the viewport with the two pictures at 400 %, where the viewport
draws pixels as they are (no smoothing), so that each screen pixel is one picture pixel exactly.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt

from lenslab.colour_management.view import ViewTransform
from lenslab.gui.snapshots import SnapshotStore, camera_label, compare_tags
from lenslab.render.film import display_pixels, to_8bit
from lenslab.scene.camera import ThinLensCamera

from .helpers import hover, press_drag_release, wait_for_frame, wait_for_gbuffer

ZOOM = 4.0
ACES = ViewTransform().resolved()  # the built-in config's default view (the old "filmic")


def picture(h=6, w=8, value=0.5):
    rng = np.random.default_rng(int(value * 1000))
    linear = rng.uniform(0, 2 * value, (h, w, 3)).astype(np.float32)
    rgba = np.empty((h, w, 4), np.uint8)
    rgba[..., :3] = to_8bit(display_pixels(linear, ACES))
    rgba[..., 3] = 255
    return rgba, linear


# -- the store, without a window --------------------------------------------------------------------------------
def test_the_cap_evicts_the_oldest_and_the_newest_is_a():
    store = SnapshotStore(max_count=3)
    seen = []
    store.events.connect(seen.append)
    camera = ThinLensCamera()
    taken = []
    for i in range(5):
        rgba, linear = picture(value=0.1 * (i + 1))
        taken.append(store.take(rgba, ACES, linear, dataclasses.replace(camera, f_number=2.0 + i), None, 16))
    assert [s.id for s in store.snapshots] == [taken[2].id, taken[3].id, taken[4].id]
    assert store.a is taken[4] and "snapshots" in seen and "a" in seen
    # The camera is a copy: editing the scene's later does not change what the snapshot remembers.
    assert store.a.camera.f_number == 6.0 and store.a.camera is not camera
    # Deleting A makes the newest remaining one A.
    store.remove(taken[4].id)
    assert store.a is taken[3]
    store.remove(taken[2].id)
    assert store.a is taken[3] and len(store.snapshots) == 1
    # A byte budget: each 6 x 8 snapshot holds 8 * 6 * (4 + 12) bytes; two fit in 2.5 of them.
    each = 8 * 6 * 16
    small = SnapshotStore(max_count=12, max_bytes=int(2.5 * each))
    rgba, linear = picture()
    for _ in range(4):
        small.take(rgba, ACES, linear, camera)
    assert len(small.snapshots) == 2 and small.nbytes == 2 * each
    assert [s.id for s in small.snapshots] == [3, 4]


def test_labels_name_what_a_photographer_reads():
    camera = ThinLensCamera(focal_length_mm=50.0, f_number=1.4, focus_distance_m=2.1)
    assert camera_label(camera, 256) == "50 mm f/1.4, focus 2.10 m, 256 spp"
    store = SnapshotStore()
    rgba, linear = picture()
    snapshot = store.take(rgba, ACES, linear, camera, None, 256)
    assert snapshot.label == "50 mm f/1.4, focus 2.10 m, 256 spp"
    live = dataclasses.replace(camera, f_number=4.0)
    assert compare_tags(snapshot, live) == ("A: f/1.4", "B: live f/4")
    refocused = dataclasses.replace(live, focus_distance_m=3.0)
    assert compare_tags(snapshot, refocused) == ("A: f/1.4 focus 2.10 m", "B: live f/4 focus 3.00 m")
    assert compare_tags(snapshot, camera) == ("A: f/1.4", "B: live f/1.4")  # nothing differs: the aperture
    store.rename(snapshot.id, "  wide open ")
    assert snapshot.label == "wide open" and compare_tags(snapshot, live)[0] == "A: wide open"
    store.rename(snapshot.id, "")
    assert snapshot.label == snapshot.auto_label


def test_a_snapshot_is_made_again_through_a_new_view():
    rgba, linear = picture(value=0.7)
    store = SnapshotStore()
    snapshot = store.take(rgba, ACES, linear, ThinLensCamera())
    assert snapshot.picture(ACES) is snapshot.display  # its own view: the picture as it was shown
    other = ViewTransform(view="Un-tone-mapped", exposure_stops=1.5).resolved()
    brighter = snapshot.picture(other)
    assert np.array_equal(brighter[..., :3], to_8bit(display_pixels(linear, other)))
    assert (brighter[..., 3] == 255).all() and not np.array_equal(brighter, rgba)
    # A snapshot keeps its camera's exposure: its radiance is scaled by it, through any view.
    dim = store.take(rgba, ACES, linear, ThinLensCamera(), exposure_scale=0.25)
    assert np.array_equal(dim.picture(other)[..., :3],
                          to_8bit(display_pixels(linear, ViewTransform(view="Un-tone-mapped", exposure_stops=-0.5))))
    # Without radiance (a picture of another size than the radiance at hand) it stays as it was shown.
    flat = store.take(rgba, ACES, linear[:3], ThinLensCamera())
    assert flat.linear is None and flat.picture(other) is flat.display


def test_compare_modes_and_the_quick_toggle():
    store = SnapshotStore()
    assert store.view == "off"
    store.set_mode("wipe")
    assert store.view == "off"  # nothing to compare with yet
    store.take(picture()[0], ACES, None, ThinLensCamera())
    assert store.view == "wipe"
    store.toggle_a()
    assert store.view == "a" and store.show_a
    store.toggle_a()
    assert store.view == "wipe"
    store.toggle_a()
    store.set_mode("side")  # choosing a mode ends the toggle
    assert store.view == "side" and not store.show_a
    store.cycle_mode()
    assert store.mode == "off"
    store.set_divider(1.7)
    assert store.divider == 1.0
    with pytest.raises(ValueError, match="unknown compare mode 'blink'"):
        store.set_mode("blink")


# -- in the studio ------------------------------------------------------------------------------------------------

def rendered_at(qtbot, window, min_spp: int = 4, **camera):
    """Set the camera and wait for a picture of it with at least ``min_spp`` samples. The edit's generation is
    the controller's own number for it, taken as it is sent: waiting for the next ``restarted`` signal instead
    could catch one still queued from an earlier edit, and then accept that edit's picture (a snapshot test saw
    the old resolution that way, now and then)."""
    window.doc.set_camera(**camera)
    return wait_for_frame(qtbot, window, min_spp=min_spp, generation=window.controller.generation)


def snapshot_then_stop_down(qtbot, window):
    """Snapshot A at f/1.4, then the live picture at f/4; pixel peeping at 400 %."""
    window.controller.set_target_spp(16)
    rendered_at(qtbot, window, min_spp=16, f_number=1.4)
    shown = window.viewport.qimage.copy()
    snapshot = window.snapshots.take()
    assert snapshot is not None and snapshot.camera.f_number == 1.4 and snapshot.samples_per_pixel >= 16
    w, h = snapshot.size
    assert all(shown.pixelColor(x, y).red() == snapshot.display[y, x, 0] for x, y in ((0, 0), (w // 2, h // 2)))
    rendered_at(qtbot, window, min_spp=4, f_number=4.0)
    window.viewport.set_zoom(ZOOM)
    return snapshot


def grab(qtbot, window):
    """The viewport on screen, with the live picture it drew (no event is handled in between): the pictures and
    the comparison's own marks alone, without the plane-of-focus overlay or the other overlay layers."""
    v = window.viewport
    v.hide_focus_overlay()
    qtbot.waitUntil(lambda: not v.overlay_visible(), timeout=5000)
    layers, v.layers = v.layers, []
    try:
        return v.grab().toImage(), v.qimage.copy()
    finally:
        v.layers = layers


def rgb(image, x: int, y: int) -> np.ndarray:
    c = image.pixelColor(x, y)
    return np.array([c.red(), c.green(), c.blue()])


def at(point: QPoint) -> tuple[int, int]:
    return point.x(), point.y()


def on_screen(rect, x: int, y: int) -> QPoint:
    """The screen pixel at the centre of picture pixel (x, y) drawn at ZOOM in ``rect``."""
    return QPoint(int(rect.left() + (x + 0.5) * ZOOM), int(rect.top() + (y + 0.5) * ZOOM))


@pytest.mark.gl
def test_split_wipe_shows_the_snapshot_left_of_the_divider_and_live_right(qtbot, window):
    snapshot = snapshot_then_stop_down(qtbot, window)
    store, comparison = window.snapshots.store, window.snapshots.comparison
    window.actions["compare_wipe"].trigger()  # View > Compare > Split Wipe
    assert store.view == "wipe" and window.snapshots.panel.compare_combo.currentData() == "wipe"
    store.set_divider(0.375)
    screen, live = grab(qtbot, window)
    a = comparison.a_image()
    rect = window.viewport.image_rect()
    assert comparison.a_rect() == rect  # the same rectangle, the same scale
    w, h = snapshot.size
    divider = 0.375 * w
    differ = 0
    for y in range(0, h - 8, 3):  # the tags are in the bottom corners
        for x in range(w):
            if abs(x + 0.5 - divider) < 3:
                continue  # the divider's line and handle
            p = on_screen(rect, x, y)
            seen = rgb(screen, p.x(), p.y())
            expected, other = (rgb(a, x, y), rgb(live, x, y)) if x < divider else (rgb(live, x, y), rgb(a, x, y))
            assert np.abs(seen - expected).max() <= 1, (x, y, seen, expected)
            differ += np.abs(expected - other).max() > 8
    assert differ >= 10  # f/1.4 and f/4 tell the sides apart: the test would see a mix-up
    assert compare_tags(snapshot, window.doc.scene.camera) == ("A: f/1.4", "B: live f/4")


@pytest.mark.gl
def test_dragging_the_divider_moves_it(qtbot, window):
    snapshot_then_stop_down(qtbot, window)
    store, comparison, v = window.snapshots.store, window.snapshots.comparison, window.viewport
    store.set_mode("wipe")
    rect = v.image_rect()
    x = comparison.divider_x()
    assert x == pytest.approx(rect.center().x())
    y = round(rect.center().y())
    hover(v, QPoint(round(x) + 3, y))
    assert v.cursor().shape() == Qt.SplitHCursor  # within a few pixels, the cursor says it can be dragged
    selection = list(window.doc.selection)
    target = rect.left() + 0.2 * rect.width()
    press_drag_release(v, QPoint(round(x) + 3, y), QPoint(round(target), y + 20))
    assert store.divider == pytest.approx((round(target) - rect.left()) / rect.width(), abs=1e-9)
    assert store.divider == pytest.approx(0.2, abs=0.01)
    assert window.doc.selection == selection  # the drag was the divider's, not the select tool's click
    # Away from the divider the cursor is the tool's again, and a press there is the tool's.
    hover(v, QPoint(round(rect.left() + 0.7 * rect.width()), y))
    assert v.cursor().shape() == Qt.ArrowCursor
    press_drag_release(v, QPoint(round(rect.left() + 0.7 * rect.width()), y),
                       QPoint(round(rect.left() + 0.9 * rect.width()), y))
    assert store.divider == pytest.approx(0.2, abs=0.01)


@pytest.mark.gl
def test_side_by_side_maps_the_mouse_to_each_half(qtbot, window):
    snapshot = snapshot_then_stop_down(qtbot, window)
    g = wait_for_gbuffer(qtbot, window)
    store, comparison, v = window.snapshots.store, window.snapshots.comparison, window.viewport
    store.set_mode("side")
    rect = v.image_rect()
    half = v.width() / 2
    assert rect.left() >= half and rect.center().x() == pytest.approx(half + half / 2)  # B: the right half
    a_rect = comparison.a_rect()
    assert a_rect == rect.translated(-half, 0)  # A: its twin in the left half
    # The live half maps to the live picture's pixels; the snapshot's half to none of them, but to A's.
    x, y = 24, 28  # the tall box
    right, left = on_screen(rect, x, y), on_screen(a_rect, x, y)
    assert tuple(int(c) for c in v.widget_to_image(QPointF(right))) == (x, y)
    assert v.widget_to_image(QPointF(left)) is None
    assert comparison.a_pixel_at(QPointF(left)) == (x, y) and comparison.a_pixel_at(QPointF(right)) is None
    # What is drawn there is what they map to.
    screen, live = grab(qtbot, window)
    a = comparison.a_image()
    for px, py in ((2, 2), (x, y), (40, 30), (60, 5)):
        assert np.abs(rgb(screen, *at(on_screen(rect, px, py))) - rgb(live, px, py)).max() <= 1
        assert np.abs(rgb(screen, *at(on_screen(a_rect, px, py))) - rgb(a, px, py)).max() <= 1
    # The readout reads the half under the cursor: A's radiance on the left, the live picture's on the right.
    hover(v, left)
    text = window.readout.text()
    assert text.startswith("<b>A</b>  x 24  y 28") and f"{snapshot.linear[y, x, 0]:.4f}" in text
    hover(v, right)
    # The live half's readout needs the live picture's radiance, which may come with the next frame.
    qtbot.waitUntil(lambda: window.readout.text().startswith("x 24  y 28"), timeout=10000)
    text = window.readout.text()
    assert "tall box" in text
    # Clicking selects in the live half; in the snapshot's half a click does nothing.
    qtbot.mouseClick(v, Qt.LeftButton, pos=left)
    assert window.doc.selection == []
    qtbot.mouseClick(v, Qt.LeftButton, pos=right)
    paths = window.doc.model.node_paths()
    assert window.doc.selection == [("node", paths[int(g.node_index[y, x])])]
    qtbot.mouseClick(v, Qt.LeftButton, pos=left)
    assert window.doc.selection == [("node", paths[int(g.node_index[y, x])])]
    # Off again: the picture takes the whole widget back.
    store.set_mode("off")
    assert v.image_rect().center().x() == pytest.approx(v.width() / 2)
    assert tuple(int(c) for c in v.widget_to_image(v.image_to_widget(x + 0.5, y + 0.5))) == (x, y)


@pytest.mark.gl
def test_a_snapshot_of_another_size_is_scaled_into_the_same_rect(qtbot, window):
    snapshot = snapshot_then_stop_down(qtbot, window)
    comparison, v = window.snapshots.comparison, window.viewport
    rendered_at(qtbot, window, min_spp=1, resolution=(128, 96))
    assert v.image_size() == (128, 96) and snapshot.size == (64, 48)
    window.snapshots.store.set_mode("wipe")
    window.snapshots.store.set_divider(1.0)  # all A
    v.set_zoom(2.0)  # 2 screen pixels a live pixel: 4 a snapshot pixel
    rect = v.image_rect()
    assert comparison.a_rect() == rect
    screen, _live = grab(qtbot, window)
    a = comparison.a_image()
    for x, y in ((3, 3), (30, 20), (58, 4)):  # clear of the tags and the divider at the right edge
        assert np.abs(rgb(screen, *at(on_screen(rect, x, y))) - rgb(a, x, y)).max() <= 1
    # A picture of another shape is fitted inside, centred.
    rendered_at(qtbot, window, min_spp=1, resolution=(96, 96))
    rect = v.image_rect()
    fitted = comparison.a_rect()
    assert fitted.width() == pytest.approx(rect.width()) and fitted.height() == pytest.approx(rect.width() * 0.75)
    assert fitted.center() == rect.center()


@pytest.mark.gl
def test_restore_camera_is_one_undo_step(qtbot, window):
    snapshot_then_stop_down(qtbot, window)
    doc = window.doc
    a_camera = window.snapshots.store.a.camera
    # More changes since: focus, focal length, and a lens mounted.
    doc.set_camera(focus_distance_m=3.0)
    lens = next(lens for lens in window.camera_panel.lenses if lens.name == "135 mm f/2")
    window.camera_panel.choose_lens(lens)
    before, lens_before, steps = doc.scene.camera, doc.lens, doc.undo_stack.count()
    assert before != a_camera and lens_before == lens
    window.snapshots.panel.restore_button.click()
    assert doc.scene.camera == a_camera and doc.lens is None
    assert doc.undo_stack.count() == steps + 1 and doc.undo_stack.undoText().startswith("Restore camera: 50 mm f/1.4")
    # The camera tag follows once the restored camera's picture is on screen.
    qtbot.waitUntil(lambda: "f/1.4" in window.viewport.hud_text, timeout=20000)
    doc.undo_stack.undo()
    assert doc.scene.camera == before and doc.lens == lens
    doc.undo_stack.redo()
    assert doc.scene.camera == a_camera and doc.lens is None
    # Nothing to restore: no empty step.
    assert not window.snapshots.restore_camera() and doc.undo_stack.count() == steps + 1


@pytest.mark.gl
def test_the_dock_lists_renames_deletes_and_caps(qtbot, window):
    panel, store = window.snapshots.panel, window.snapshots.store
    store.max_count = 3
    assert panel.empty_hint.isVisibleTo(panel) and not window.actions["compare_wipe"].isEnabled()
    stops = (1.4, 2.0, 2.8, 4.0)
    taken = []
    for n in stops:
        rendered_at(qtbot, window, min_spp=1, f_number=n)
        window.actions["take_snapshot"].trigger()  # Render > Take Snapshot
        taken.append(store.a)
    assert window.actions["take_snapshot"].shortcut().toString() == "Ctrl+T"
    # The oldest went; the newest is first in the list, and it is A.
    assert [s.camera.f_number for s in store.snapshots] == [2.0, 2.8, 4.0]
    assert panel.list.count() == 3 and not panel.list.item(0).icon().isNull()
    assert panel.list.item(0).text().startswith("50 mm f/4, focus") and panel.selected_id() == taken[-1].id
    assert window.actions["compare_wipe"].isEnabled()
    # Selecting a row makes it A.
    panel.list.setCurrentRow(2)
    assert store.a is taken[1]
    # Renaming in place; the tags use the name.
    item = panel.list.item(2)
    item.setText("wide")
    assert store.a.name == "wide" and panel.list.item(2).text() == "wide"
    store.set_mode("wipe")
    assert window.snapshots.comparison.view() == "wipe"
    # Deleting A: the newest remaining becomes A.
    panel.delete_button.click()
    assert [s.camera.f_number for s in store.snapshots] == [2.8, 4.0] and store.a is taken[-1]
    assert panel.list.count() == 2
    # The quick toggle: A alone in place of the live picture, and back.
    window.actions["toggle_ab"].trigger()
    assert store.view == "a" and window.actions["toggle_ab"].isChecked()
    window.actions["toggle_ab"].trigger()
    assert store.view == "wipe"
    window.actions["cycle_compare"].trigger()
    assert store.view == "side" and window.actions["compare_side"].isChecked()
    assert panel.compare_combo.currentData() == "side"


@pytest.mark.gl
def test_a_snapshot_follows_the_viewports_look(qtbot, window):
    snapshot = snapshot_then_stop_down(qtbot, window)
    comparison = window.snapshots.comparison
    window.snapshots.store.set_mode("wipe")
    window.exposure_slider.setValue(15)
    window.display.set_view("Un-tone-mapped")
    a = comparison.a_image()
    view = window.viewport.view  # with the snapshot's own camera exposure
    made = dataclasses.replace(view, exposure_stops=view.exposure_stops + math.log2(snapshot.exposure_scale))
    expected = to_8bit(display_pixels(snapshot.linear, made))
    w, h = snapshot.size
    for x, y in ((0, 0), (w // 2, h // 2), (w - 1, h - 1)):
        assert tuple(rgb(a, x, y)) == tuple(int(c) for c in expected[y, x])
