"""The studio's layout holds from its smallest window to 4K: every control of every panel can be reached (seen, or
scrolled to up and down) and is not cut; the viewport's toolbar shows each control or keeps it behind its overflow
button; the histogram stays a histogram's height; the viewport's tags never cover one another. With them, what
the window says: one binding per key, an aspect ratio list that names a preset as itself, and an A/B tag that
reads the settings of the picture shown.

What "reachable" and "cut" mean is written out in ``layout_checks.py``. The windows render the export's tiny
pixels (conftest), so a 4K window costs no more to render than a small one; each test takes one window through
the sizes (a window is the slow part) and says at which size what went wrong.
"""

from __future__ import annotations

import re
from collections import defaultdict
from contextlib import contextmanager

import pytest
from PySide6.QtCore import QRect, QRectF, Qt, QTimer
from PySide6.QtGui import QAction, QPainter, QShortcut
from PySide6.QtWidgets import QAbstractButton, QApplication, QMenu

from .helpers import wait_for_frame, wait_for_gbuffer
from .layout_checks import dock_problems, toolbar_problems

SIZES = {"minimum": None, "default": (1480, 920), "fresh 1500 x 950": (1500, 950), "4K": (3840, 2160)}
#: What a node, the camera and a material show in the Properties panel: each form is checked.
TARGETS = (("node", (1,)), ("camera",), ("material", "white"))


def settle(qtbot, window) -> None:
    """Let the window lay itself out (docks, scroll areas, the toolbar) after a change."""
    for _ in range(3):
        QApplication.processEvents()
        qtbot.wait(20)


def size_to(qtbot, window, size) -> None:
    """The window at ``size``, or at the least size it allows (None)."""
    settle(qtbot, window)
    if size is None:
        window.resize(window.minimumSize())
        settle(qtbot, window)
        window.resize(window.minimumSize())  # what the panels need may have changed with the smaller size
    else:
        window.resize(*size)
    settle(qtbot, window)
    if size is not None:
        assert (window.width(), window.height()) == size


def shown_docks(window):
    """The docks a user sees or can bring forward with a tab: all but those closed (the Log, until asked for)."""
    return [dock for dock in window.docks.values() if not dock.isHidden()]


# -- the panels ---------------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_every_control_of_every_panel_is_reachable_and_whole(qtbot, window):
    problems = []
    for size, extent in SIZES.items():
        for target in TARGETS:
            window.doc.set_selection([target])
            size_to(qtbot, window, extent)
            for dock in shown_docks(window):
                dock.raise_()
                settle(qtbot, window)
                problems += [f"{size} ({window.width()} x {window.height()}), {target[0]} selected: {line}"
                             for line in dock_problems(dock)]
        window.docks["camera"].raise_()
    shown = problems[:40] + ([f"... and {len(problems) - 40} more"] if len(problems) > 40 else [])
    assert not problems, "\n".join(shown)


# -- the viewport's toolbar ---------------------------------------------------------------------------------------
def press_extension(qtbot, bar) -> list[str]:
    """Press the toolbar's extension button. A toolbar outside a main window opens a menu instead, which would wait
    for a click: it is read (its entries are returned) and closed."""
    seen: list[str] = []

    def close_menu() -> None:
        menu = QApplication.activePopupWidget()
        if isinstance(menu, QMenu):
            seen.extend(a.text() for a in menu.actions())
            menu.close()

    QTimer.singleShot(300, close_menu)
    bar.findChild(QAbstractButton, "qt_toolbar_ext_button").click()
    qtbot.wait(400)
    return seen


def hidden_controls(bar) -> list[str]:
    return [bar.widgetForAction(a).objectName() or a.text() or type(bar.widgetForAction(a)).__name__
            for a in bar.actions() if bar.widgetForAction(a) is not None and not a.isSeparator()
            and not bar.widgetForAction(a).isVisible()]


def overflow_problems(qtbot, bar) -> list[str]:
    """What the toolbar hides and its overflow button does not show; the bar closed again after."""
    problems = toolbar_problems(bar)
    hidden = hidden_controls(bar)
    if problems or not hidden:
        return problems
    menu = press_extension(qtbot, bar)
    still_hidden = hidden_controls(bar)
    if still_hidden:
        problems.append(f"{hidden} were hidden; the overflow button showed {still_hidden} no better"
                        + (f" (it opened a menu of {menu})" if menu else ""))
    for control in bar.findChildren(QAbstractButton):
        if control.isVisible() and control.objectName() != "qt_toolbar_ext_button" \
                and not bar.rect().contains(control.geometry()):
            problems.append(f"{control.text()} is cut by the opened toolbar")
    press_extension(qtbot, bar)  # and it closes again
    if hidden_controls(bar) != hidden:
        problems.append(f"pressed again, the toolbar hides {hidden_controls(bar)}, not {hidden}")
    return problems


@pytest.mark.gl
def test_the_toolbar_shows_each_control_or_keeps_it_behind_its_overflow(qtbot, window):
    bar = window.toolbar.bar
    problems = []
    for size in ("minimum", "default", "wide left panel", "4K"):
        size_to(qtbot, window, SIZES.get(size, SIZES["default"]))
        if size == "wide left panel":
            window.resizeDocks([window.docks["scene"]], [560], Qt.Horizontal)
            settle(qtbot, window)
        if size == "4K" and hidden_controls(bar):
            problems.append(f"at 4K the toolbar hides {hidden_controls(bar)}")
        problems += [f"{size} ({bar.width()} px of toolbar): {line}" for line in overflow_problems(qtbot, bar)]
    assert not problems, "\n".join(problems)


# -- the histogram ------------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_the_histogram_keeps_a_histograms_height(qtbot, window):
    histogram, camera = window.docks["histogram"], window.docks["camera"]
    plot = window.viewing.histogram_panel.view
    for size in ("default", "4K"):
        size_to(qtbot, window, SIZES[size])
        assert 90 <= plot.height() <= 160, f"at the {size} size the histogram is {plot.height()} px tall"
        assert histogram.height() <= 220, \
            f"at the {size} size the Histogram panel takes {histogram.height()} px of {window.height()}"
        assert camera.height() > 2 * histogram.height(), f"at the {size} size the camera panel has less room"


# -- the viewport's tags ------------------------------------------------------------------------------------------
@contextmanager
def tags_drawn(monkeypatch):
    """The boxes and texts the viewport paints while the block runs: every tag is a rounded box with its text."""
    boxes: list[QRectF] = []
    texts: list[str] = []
    draw_box, draw_text = QPainter.drawRoundedRect, QPainter.drawText

    def box(painter, rect, *args, **kwargs):
        if isinstance(rect, (QRectF, QRect)):
            boxes.append(QRectF(rect))
        return draw_box(painter, rect, *args, **kwargs)

    def text(painter, *args, **kwargs):
        if args and isinstance(args[-1], str):
            texts.append(args[-1])
        return draw_text(painter, *args, **kwargs)

    with monkeypatch.context() as patch:
        patch.setattr(QPainter, "drawRoundedRect", box)
        patch.setattr(QPainter, "drawText", text)
        yield boxes, texts


def overlaps(boxes: list[QRectF]) -> list[tuple[QRectF, QRectF]]:
    boxes = [b for b in boxes if b.width() > 0 and b.height() > 0]
    return [(a, b) for i, a in enumerate(boxes) for b in boxes[i + 1:] if a.intersects(b)]


@pytest.mark.gl
def test_the_viewports_tags_never_cover_one_another(qtbot, window, monkeypatch):
    """Every tag at once: the camera's in the physical exposure mode (its longest), the render paused, the plane of
    focus's distance, "focusing…", the frame's size and the sensor's outline (a 4:3 frame on a 3:2 sensor); and the
    work banner over them, an edit made while paused."""
    window.doc.set_camera(exposure_mode="physical")
    wait_for_frame(qtbot, window, generation=window.controller.generation)
    qtbot.waitUntil(lambda: "ISO" in window.viewport.hud_text, timeout=10000)
    window.set_paused(True)
    v = window.viewport
    wait_for_gbuffer(qtbot, window)
    v.show_focus_overlay(1.6, 1.2, 2.2, hold=True)
    v.set_tool("focus")
    v.focus_pending = True
    window.doc.set_camera(f_number=window.doc.scene.camera.f_number * 2)
    banner = window.render_status.work_banner
    qtbot.waitUntil(lambda: (banner.text or "").startswith("Paused"), timeout=5000)
    for size in ("minimum", "default", "4K"):
        size_to(qtbot, window, SIZES[size])
        with tags_drawn(monkeypatch) as (boxes, texts):
            v.grab()
        # Where there is room every tag is drawn whole; at the smallest size some give way to the camera's.
        assert len(boxes) >= (3 if size == "minimum" else 6), f"tags missing at the {size} size: {texts}"
        covered = overlaps(boxes)
        assert not covered, (f"at the {size} size (viewport {v.width()} x {v.height()}) tags cover one another: "
                             + "; ".join(f"{a.getRect()} and {b.getRect()}" for a, b in covered)
                             + f"; texts {texts}")
        assert v.hud_text in texts, f"at the {size} size the camera's tag is not whole: {texts}"
    v.focus_pending = False


# -- keys ---------------------------------------------------------------------------------------------------------
def mnemonic(text: str) -> str | None:
    found = re.search(r"&([^&])", text.replace("&&", ""))
    return found.group(1).upper() if found else None


@pytest.mark.gl
def test_each_key_does_one_thing(qtbot, window):
    """Every shortcut of the window's actions and shortcuts, and every Alt+letter of its menu bar, belongs to one
    action; within each menu, each letter to one entry."""
    bound = defaultdict(list)
    for action in window.findChildren(QAction):
        if action.shortcutContext() in (Qt.WindowShortcut, Qt.ApplicationShortcut):
            for key in action.shortcuts():
                bound[key.toString()].append(action.text() or action.objectName())
    for shortcut in window.findChildren(QShortcut):
        if shortcut.context() in (Qt.WindowShortcut, Qt.ApplicationShortcut):
            for key in shortcut.keys():
                bound[key.toString()].append(f"shortcut {shortcut.objectName()}")
    letters = defaultdict(list)
    for entry in window.menuBar().actions():
        letter = mnemonic(entry.text())
        if letter:
            bound[f"Alt+{letter}"].append(f"the {entry.text()} menu")
        if entry.menu() is not None:
            entry.menu().aboutToShow.emit()  # the menus filled as they open

    def walk(menu: QMenu, path: str) -> None:
        seen = defaultdict(list)
        for entry in menu.actions():
            letter = mnemonic(entry.text())
            if letter and entry.isVisible():
                seen[letter].append(entry.text())
            if entry.menu() is not None:
                walk(entry.menu(), f"{path} > {entry.text()}")
        letters.update({f"{path}: {k}": v for k, v in seen.items() if len(v) > 1})

    for entry in window.menuBar().actions():
        if entry.menu() is not None:
            walk(entry.menu(), entry.text())
    twice = {key: names for key, names in bound.items() if len(names) > 1}
    assert not twice, f"keys bound twice: {twice}"
    assert not letters, f"menu letters used twice: {dict(letters)}"
    assert window.actions["clear_region"].shortcut().toString() == "Alt+R"  # as documented


# -- the aspect ratio list ----------------------------------------------------------------------------------------
def combo_texts(combo) -> list[str]:
    return [combo.itemText(i) for i in range(combo.count())]


@pytest.mark.gl
def test_the_aspect_list_names_a_preset_as_itself(qtbot, window):
    from lenslab.gui.framing_overlay import FramingLayer

    aspect = window.viewing.aspect
    wait_for_frame(qtbot, window)
    window.set_paused(True)  # the shapes are all this is about: no need to render 1920 x 1280 on the CPU
    on_screen = window.viewing.framing.label()
    for resolution, shown in (((1920, 1280), "3:2"), ((1919, 1280), "3:2"), ((1080, 1350), "4:5"),
                              ((101, 100), "1:1")):
        window.doc.set_camera(resolution=resolution)
        assert aspect.combo.currentText() == shown, f"{resolution} shows {aspect.combo.currentText()}"
        assert aspect.actions[shown].isChecked() and not aspect.custom_action.isVisible()
        assert combo_texts(aspect.combo) == ["3:2", "4:5", "1:1", "16:9"], \
            f"at {resolution} the list offers {combo_texts(aspect.combo)}"
        label = FramingLayer()
        label.set_camera(window.doc.scene.camera)
        assert label.label().startswith(shown + "  ")  # the frame's label, once a picture of it shows, agrees
        assert window.viewing.framing.label() == on_screen  # until then it is the paused picture's
    window.doc.set_camera(resolution=(640, 480))
    assert aspect.combo.currentText() == "Custom (4:3)" and aspect.custom_action.isChecked()
    assert combo_texts(aspect.combo) == ["3:2", "4:5", "1:1", "16:9", "Custom (4:3)"]
    aspect.choose("3:2")
    assert window.doc.scene.camera.resolution == (640, 427) and combo_texts(aspect.combo)[-1] == "16:9"


# -- A and B ------------------------------------------------------------------------------------------------------
@pytest.mark.gl
def test_the_ab_tags_read_the_picture_shown(qtbot, window, monkeypatch):
    """A snapshot at f/1.4 and the live picture at f/8: with A shown alone, every tag reads A's settings."""
    window.doc.set_camera(f_number=1.4)
    wait_for_frame(qtbot, window, min_spp=2, generation=window.controller.generation)
    snapshot = window.snapshots.take()
    assert snapshot is not None and snapshot.camera.f_number == 1.4
    window.doc.set_camera(f_number=8.0)
    wait_for_frame(qtbot, window, min_spp=2, generation=window.controller.generation)
    qtbot.waitUntil(lambda: "f/8" in window.viewport.hud_text, timeout=10000)
    store = window.snapshots.store
    store.toggle_a(True)
    with tags_drawn(monkeypatch) as (_boxes, texts):
        window.viewport.grab()
    assert any("f/1.4" in t and "50 mm" in t for t in texts), f"no tag gives A's settings: {texts}"
    assert not any("f/8" in t for t in texts), f"a tag reads the live f/8 over snapshot A: {texts}"
    # The live picture falls behind an edit (paused) while A is shown: no banner over A speaks of it.
    store.toggle_a(False)
    window.set_paused(True)
    window.doc.set_camera(f_number=11.0)
    banner = window.render_status.work_banner
    qtbot.waitUntil(lambda: (banner.text or "").startswith("Paused"), timeout=5000)
    store.toggle_a(True)
    banner.refresh()
    assert banner.text is None, f"the banner speaks of the live picture over snapshot A: {banner.text}"
    store.toggle_a(False)
    banner.refresh()
    assert (banner.text or "").startswith("Paused")  # the live picture is back in sight, behind the edit
    window.set_paused(False)
    wait_for_frame(qtbot, window, generation=window.controller.generation)
    store.set_mode("wipe")
    with tags_drawn(monkeypatch) as (_boxes, texts):
        window.viewport.grab()
    assert "A: f/1.4" in texts and "B: live f/11" in texts
    assert any(t.startswith("B: ") and "f/11" in t and "50 mm" in t for t in texts), \
        f"in the wipe the camera's tag, over A's side, does not say it is B's: {texts}"
