"""The viewport's judging aids, driven with pytest-qt: the sensor's gate with the guides,
the safe frame and the passepartout; the aspect-ratio presets; focus peaking; the histogram and the clipping
warnings; the loupe.

The layers are tried first on a viewport of their own holding a synthetic picture and depth buffer, where every
pixel's answer is known; then in the studio on a real render (llvmpipe), through its menus, its undo stack and its
settings.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, QRectF, Qt
from PySide6.QtGui import QAction

from lenslab.gui.clipping_layer import ClippingLayer
from lenslab.gui.framing_overlay import FramingLayer
from lenslab.gui.histogram_panel import HistogramPanel
from lenslab.gui.layer_support import gate_in_widget, qimage_to_array
from lenslab.gui.loupe_layer import LoupeLayer
from lenslab.gui.peaking_layer import PEAKING_COLOURS, FocusPeakingLayer
from lenslab.optics.histogram import clipping_masks
from lenslab.optics.peaking import within_depth_of_field
from lenslab.scene.camera import ThinLensCamera

from .helpers import hover, wait_for_frame, wait_for_gbuffer


# -- a viewport of its own -------------------------------------------------------------------------------------------
@pytest.fixture
def viewport(qtbot):
    from lenslab.gui.app import create_application
    from lenslab.gui.viewport import Viewport

    create_application()
    v = Viewport()
    v.resize(800, 600)
    v.show()
    qtbot.addWidget(v)
    qtbot.waitExposed(v)
    return v


@pytest.fixture
def keep():
    """Objects to hold on to until the test's teardown: pytest-qt processes events after the test body, and a
    widget Python owns, collected then, would be destroyed in the middle of its own paint."""
    held = []
    yield held.append
    held.clear()


def show_picture(viewport, picture: np.ndarray, depth: np.ndarray | None = None, linear=None):
    """Put a picture (RGBA8) and, if given, a depth buffer in the viewport, as the render worker would."""
    viewport.set_frame(picture, viewport.view, linear)
    if depth is not None:
        viewport.set_gbuffer(SimpleNamespace(depth=depth, node_index=np.full(depth.shape, -1, np.int32),
                                             generation=0))


def grab(viewport) -> np.ndarray:
    """What the viewport shows, (H, W, 4) uint8."""
    return qimage_to_array(viewport.grab().toImage())


def widget_pixel(viewport, x: float, y: float) -> tuple[int, int]:
    point = viewport.image_to_widget(x, y)
    return round(point.x()), round(point.y())


def charts(width=160, height=100):
    """Two cards with hard-edged checks: the left at 2 m, the right at 6 m; background at infinity."""
    picture = np.full((height, width, 4), 40, np.uint8)
    picture[..., 3] = 255
    depth = np.full((height, width), np.inf, np.float32)
    yy, xx = np.mgrid[0:height, 0:width]
    checks = (xx // 8 + yy // 8) % 2 == 0
    for x0, d in ((16, 2.0), (96, 6.0)):
        card = (xx >= x0) & (xx < x0 + 48) & (yy >= 24) & (yy < 72)
        picture[card & checks, :3] = 230
        picture[card & ~checks, :3] = 90
        depth[card] = d
    return picture, depth


# -- the gate and the guides ------------------------------------------------------------------------------------------
def test_guides_lie_at_thirds_of_the_gate_and_the_passepartout_dims_outside_it(viewport):
    picture = np.full((100, 160, 4), 180, np.uint8)
    picture[..., 3] = 255
    show_picture(viewport, picture)
    layer = FramingLayer()
    layer.set_camera(ThinLensCamera(resolution=(1200, 600)))
    viewport.layers.append(layer)
    viewport.gate_rect = QRectF(20, 10, 120, 60)  # image pixels, as the viewport's picture carries a margin
    layer.set_guides("thirds")
    layer.passepartout = 0.65
    rect = viewport.image_rect()
    gate = gate_in_widget(viewport, rect)
    s = viewport.scale()
    assert gate == QRectF(rect.left() + 20 * s, rect.top() + 10 * s, 120 * s, 60 * s)
    lines = layer.guide_lines(gate)
    assert [line.x1() for line in lines[:2]] == pytest.approx([gate.left() + 40 * s, gate.left() + 80 * s])
    assert [line.y1() for line in lines[2:]] == pytest.approx([gate.top() + 20 * s, gate.top() + 40 * s])
    shot = grab(viewport)
    # On a guide: light; between guides: the picture as it is; outside the gate: dimmed by the passepartout.
    gx, gy = round(lines[0].x1()), round(gate.center().y() + 7 * s)
    assert shot[gy, gx, 0] > 190 and shot[gy, gx + 1, 0] < 170  # a light line with a dark rim
    cx, cy = widget_pixel(viewport, 80, 40)
    assert shot[cy, cx, 0] == 180
    ox, oy = widget_pixel(viewport, 80, 4)
    assert shot[oy, ox, 0] == pytest.approx(180 * 0.35, abs=3)
    assert layer.label() == "2:1  1200 × 600"
    # Golden section: lines at 0.382 and 0.618 of the gate.
    layer.set_guides("golden")
    lines = layer.guide_lines(gate)
    assert lines[0].x1() == pytest.approx(gate.left() + 0.381966 * gate.width(), abs=1e-3)
    assert lines[3].y1() == pytest.approx(gate.top() + 0.618034 * gate.height(), abs=1e-3)
    # The safe frame: action safe 93 %, title safe 90 %, centred in the gate.
    layer.safe_frame = True
    action, title = layer.safe_rects(gate)
    assert action.width() == pytest.approx(0.93 * gate.width()) and action.center() == gate.center()
    assert title.height() == pytest.approx(0.90 * gate.height())
    # Without a gate from the viewport, the frame is the whole picture.
    viewport.gate_rect = None
    assert gate_in_widget(viewport, viewport.image_rect()) == viewport.image_rect()


# -- focus peaking --------------------------------------------------------------------------------------------------
def test_peaking_marks_the_in_focus_card_and_not_the_other(viewport):
    picture, depth = charts()
    show_picture(viewport, picture, depth)
    limits = [(1.6, 2.5)]
    layer = FocusPeakingLayer(viewport, lambda: limits[0])
    viewport.layers.append(layer)
    layer.set_visible(True)
    mask = layer.mask
    assert mask[depth == 2.0].sum() > 200 and not mask[depth == 6.0].any()
    yellow = PEAKING_COLOURS[layer.colour]
    shot = grab(viewport)
    marked = (np.abs(shot[..., :3].astype(int) - (yellow.red(), yellow.green(), yellow.blue())).sum(axis=2) < 30)
    near_x, near_y = widget_pixel(viewport, 16, 24)
    far_x, far_y = widget_pixel(viewport, 96, 24)
    card_w, card_h = round(48 * viewport.scale()), round(48 * viewport.scale())
    assert marked[near_y:near_y + card_h, near_x:near_x + card_w].sum() > 200
    assert not marked[far_y:far_y + card_h, far_x:far_x + card_w].any()
    # Focus on the far card: once worked out again, the marks move there.
    limits[0] = (5.0, 7.5)
    layer.refresh()
    assert layer.mask[depth == 6.0].sum() > 200 and not layer.mask[depth == 2.0].any()
    # Nothing sharp to show (nearer than the lens focuses): no marks at all.
    limits[0] = None
    layer.refresh()
    assert layer.mask is None
    layer.set_visible(False)
    assert not grab(viewport)[..., :3].tolist() == shot[..., :3].tolist()  # the marks are gone


# -- the histogram and the clipping warnings ---------------------------------------------------------------------
def test_histogram_panel_counts_the_frame_and_lights_its_clipping_indicators(viewport, qtbot, keep):
    picture = np.full((100, 200, 4), 128, np.uint8)
    picture[..., 3] = 255
    picture[:, :20, :3] = 0  # 10 % crushed
    picture[:, 150:, 0] = 255  # 25 % with red clipped
    show_picture(viewport, picture)
    action = QAction("Clipping Warnings")
    action.setCheckable(True)
    panel = HistogramPanel(viewport, action)
    keep((action, panel))
    qtbot.addWidget(panel)
    panel.show()
    panel.refresh()
    h = panel.histogram
    assert h.pixels == 20000 and h.counts[0, 255] == 5000 and h.counts[1, 128] == 18000
    assert h.crushed_all == pytest.approx(0.10) and h.clipped_any == pytest.approx(0.25)
    assert panel.shadows_label.text() == "◀ 10 %" and panel.highlights_label.text() == "25 % ▶"
    assert "#ff463c" in panel.highlights_label.styleSheet()  # lit
    # Inside the frame only: a gate over the middle leaves both ends out.
    viewport.gate_rect = QRectF(40, 0, 100, 100)
    panel.refresh()
    assert panel.histogram.pixels == 10000 and panel.histogram.clipped_any == 0
    assert panel.highlights_label.text() == "0 % ▶" and "#ff463c" not in panel.highlights_label.styleSheet()
    # A click on a clipping triangle turns the warnings on.
    view = panel.view
    qtbot.mouseClick(view, Qt.LeftButton, pos=view.highlight_indicator().center().toPoint())
    assert action.isChecked()


def test_clipping_layer_paints_clipped_red_and_crushed_blue(viewport):
    picture = np.full((60, 90, 4), 128, np.uint8)
    picture[..., 3] = 255
    picture[:, :30, :3] = 0
    picture[:, 60:, :3] = 255
    show_picture(viewport, picture)
    layer = ClippingLayer(viewport)
    viewport.layers.append(layer)
    layer.set_visible(True)
    assert layer.highlights[:, 60:].all() and not layer.highlights[:, :60].any()
    assert layer.shadows[:, :30].all() and not layer.shadows[:, 30:].any()
    shot = grab(viewport)
    for x, expected in ((15, "blue"), (45, "grey"), (75, "red")):
        r, g, b = (int(c) for c in shot[widget_pixel(viewport, x + 0.5, 30.5)[::-1]][:3])
        colour = "red" if r > 200 and g < 80 else "blue" if b > 200 and r < 80 else "grey" if r == g == b else "?"
        assert colour == expected, (x, r, g, b)
    # Only inside the export frame, where the histogram counts.
    viewport.gate_rect = QRectF(20, 0, 50, 60)
    layer.refresh()
    assert layer.highlights[:, 60:70].all() and not layer.highlights[:, 70:].any()
    assert layer.shadows[:, 20:30].all() and not layer.shadows[:, :20].any()


# -- the loupe ------------------------------------------------------------------------------------------------------
def test_loupe_shows_the_pixel_under_the_cursor_and_hides_when_it_leaves(viewport, qtbot):
    picture = np.full((100, 160, 4), 60, np.uint8)
    picture[..., 3] = 255
    picture[40, 70, :3] = (250, 30, 200)  # one magenta pixel
    linear = np.full((100, 160, 3), 0.05, np.float32)
    linear[40, 70] = (2.5, 0.0125, 0.75)
    depth = np.full((100, 160), 3.25, np.float32)
    show_picture(viewport, picture, depth, linear)
    loupe = LoupeLayer(viewport)
    viewport.layers.append(loupe)
    loupe.set_visible(True)
    loupe.set_zoom(4)
    hover(viewport, QPoint(*widget_pixel(viewport, 70.5, 40.5)))
    qtbot.waitUntil(lambda: loupe.pixel == (70, 40))
    assert loupe.source_rect().center() == QPoint(70, 40) and loupe.span() % 2 == 1
    caption = loupe.caption()
    assert "x 70  y 40" in caption and "R 2.5000  G 0.0125  B 0.7500" in caption and "3.25 m" in caption
    grab(viewport)
    box = loupe.last_box
    assert box is not None and box.width() == loupe.span() * 4
    anchor = viewport.image_to_widget(70.5, 40.5)
    assert not box.contains(anchor)  # beside the cursor, not over what it points at
    shot = grab(viewport)
    # The middle cell of the loupe is the pixel under the cursor, 4 x 4 screen pixels (framed); its neighbours
    # are the grey around it.
    middle_x, middle_y = round(box.left()) + (loupe.span() // 2) * 4, round(box.top()) + (loupe.span() // 2) * 4
    assert shot[middle_y + 1, middle_x + 1, :3].tolist() == [250, 30, 200]
    assert shot[middle_y + 1, middle_x + 2, :3].tolist() == [250, 30, 200]
    assert abs(int(shot[middle_y + 1, middle_x + 9, 0]) - 60) <= 30  # the next cell but one: grey (maybe grid)
    # 1:1 shows more pixels across; 4:1 draws a grid.
    loupe.set_zoom(1)
    assert loupe.span() > 150
    # The cursor leaves: the loupe goes.
    leave = QEvent(QEvent.Leave)
    viewport.leaveEvent(leave)
    assert loupe.pixel is None and loupe.source_rect() is None
    after = grab(viewport)
    assert loupe.last_box is None
    assert after[middle_y + 1, middle_x + 1, :3].tolist() != [250, 30, 200]


# -- in the studio --------------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_aspect_preset_sets_the_resolution_in_one_undo_step(qtbot, make_window, small_scene):
    window = make_window(small_scene)
    aspect, stack = window.viewing.aspect, window.doc.undo_stack
    assert window.doc.scene.camera.resolution == (64, 48)
    assert aspect.custom_action.isChecked() and aspect.custom_action.text() == "Custom (4:3)"
    assert aspect.combo.currentText() == "Custom (4:3)"
    assert "keeping the long edge (64 px): 64 × 43" in aspect.actions["3:2"].toolTip()
    before = stack.count()
    aspect.actions["3:2"].trigger()
    assert window.doc.scene.camera.resolution == (64, 43) and stack.count() == before + 1
    assert aspect.actions["3:2"].isChecked() and aspect.combo.currentText() == "3:2"
    assert window.viewing.framing.label() == "3:2  64 × 43"
    stack.undo()
    assert window.doc.scene.camera.resolution == (64, 48) and aspect.custom_action.isChecked()
    stack.redo()
    assert window.doc.scene.camera.resolution == (64, 43)
    # The toolbar's combo does the same; choosing the shape the camera has is no step at all.
    aspect.combo.activated.emit(aspect.combo.findText("4:5"))
    assert window.doc.scene.camera.resolution == (51, 64) and stack.count() == before + 2
    aspect.choose("4:5")
    assert stack.count() == before + 2
    assert stack.undoText().startswith("Aspect ratio 4:5")
    # The Camera menu has them.
    camera_menu = next(a.menu() for a in window.menuBar().actions() if a.text().replace("&", "") == "Camera")
    aspect_menu = next(a.menu() for a in camera_menu.actions() if a.menu() and "Aspect" in a.text())
    assert [a.text() for a in aspect_menu.actions() if not a.isSeparator()][:4] == ["3:2", "4:5", "1:1", "16:9"]


@pytest.mark.gl
def test_view_menu_choices_are_remembered(qtbot, make_window, small_scene, settings):
    window = make_window(small_scene)
    aids = window.viewing
    view_menu = next(a.menu() for a in window.menuBar().actions() if a.text().replace("&", "") == "View")
    names = [a.text().replace("&", "") for a in view_menu.actions()]
    for entry in ("Guides", "Safe Frame", "Passepartout", "Focus Peaking", "Clipping Warnings", "Loupe", "Histogram"):
        assert entry in names
    assert {aids.actions[k].shortcut().toString() for k in ("peaking", "clipping", "loupe", "cycle_guides")} == \
        {"K", "J", "L", "G"}
    # Each of them is free: no other action of the window has it.
    taken = [a.shortcut().toString() for a in window.findChildren(QAction) if not a.shortcut().isEmpty()]
    for key in ("K", "J", "L", "G"):
        assert taken.count(key) == 1, key
    aids.actions["guides:golden"].trigger()
    aids.actions["safe_frame"].trigger()
    aids.actions["passepartout:0.9"].trigger()
    aids.actions["loupe"].trigger()
    aids.actions["loupe_zoom:4"].trigger()
    aids.actions["peaking_colour:cyan"].trigger()
    assert aids.framing.guides == "golden" and aids.framing.safe_frame and aids.framing.passepartout == 0.9
    aids.cycle_guides()
    assert aids.framing.guides == "centre" and aids.actions["guides:centre"].isChecked()
    window.close()
    again = make_window(small_scene).viewing
    assert again.framing.guides == "centre" and again.framing.safe_frame and again.framing.passepartout == 0.9
    assert again.loupe.visible and again.loupe.zoom == 4 and again.actions["loupe_zoom:4"].isChecked()
    assert again.peaking.colour == "cyan" and not again.peaking.visible
    assert settings.value("overlays/guides") == "centre"


@pytest.mark.gl
def test_peaking_on_a_render_marks_only_what_lies_within_the_depth_of_field(qtbot, make_window, small_scene):
    window = make_window(small_scene)
    aids = window.viewing
    wait_for_frame(qtbot, window, min_spp=8)
    g = wait_for_gbuffer(qtbot, window)
    aids.actions["peaking"].trigger()
    # Peaking marks a picture worth judging with its g-buffer (render_loop.Frame.worth_judging): on a loaded machine
    # a new pass may be under way when the action fires, and the marks come with its next picture.
    assert aids.peaking.visible
    qtbot.waitUntil(lambda: aids.peaking.mask is not None, timeout=10000)
    g = window.viewport.gbuffer
    near, far, _coc_px = aids.sharp_limits()
    zone = within_depth_of_field(g.depth, near, far)
    mask = aids.peaking.mask
    assert mask.any(), "the boxes in focus have edges"
    assert not (mask & ~zone).any()
    # Focus on the lens's nearest: nothing in the box is sharp any more, and the marks go once worked out again.
    camera = window.doc.scene.camera
    window.doc.set_camera(focus_distance_m=camera.closest_focus_m * 1.01, f_number=1.4)
    near, far, _coc_px = aids.sharp_limits()
    assert far < float(np.min(g.depth))
    qtbot.waitUntil(lambda: aids.peaking.mask is not None and not aids.peaking.mask.any(), timeout=5000)


@pytest.mark.gl
def test_overexposing_lights_the_highlight_warning_and_the_dock_agrees(qtbot, make_window, small_scene):
    window = make_window(small_scene)
    aids, panel = window.viewing, window.viewing.histogram_panel
    assert window.docks["histogram"].isVisible() and panel.isVisible()
    wait_for_frame(qtbot, window, min_spp=4)
    window.display.set_view("Un-tone-mapped")  # the view that clips (an ACES view rolls highlights off)
    window.set_display_exposure(4.0)  # display only: the linear picture is made again at once
    qtbot.waitUntil(lambda: panel.histogram is not None and panel.histogram.clipped_any > 0.3, timeout=5000)
    aids.actions["clipping"].trigger()
    expected, _ = clipping_masks(qimage_to_array(window.viewport.qimage))
    assert np.array_equal(aids.clipping.highlights, expected)
    assert aids.clipping.highlights.mean() == pytest.approx(panel.histogram.clipped_any)
    assert panel.highlights_label.text().endswith("% ▶") and panel.highlights_label.text() != "0 % ▶"
    window.set_display_exposure(0.0)
    qtbot.waitUntil(lambda: panel.histogram.clipped_any < 0.3 and aids.clipping.highlights.mean() < 0.3,
                    timeout=5000)
    # The histogram dock is part of the default layout and comes back with it.
    window.docks["histogram"].close()
    window.reset_layout()
    assert window.docks["histogram"].isVisible()
