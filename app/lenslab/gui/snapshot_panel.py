"""Snapshots in the studio: the Snapshots dock, the actions and menu entries, and the readout over a snapshot.

:class:`StudioSnapshots` installs the feature on a main window (``window.snapshots``): Render > Take Snapshot
(Ctrl+T) keeps the picture in the viewport as the A side of a comparison; View > Compare chooses how it meets the
live picture (Off, Split Wipe, Side by Side; Ctrl+\\ steps through them); \\ toggles A alone in place of the live
picture. The dock lists the snapshots with thumbnails and labels: select one to make it A, rename it (F2 or a
double-click), delete it (Del), or restore its camera (and lens) as one undo step.

The store (``lenslab.gui.snapshots``) holds the data; the viewport's comparison (``lenslab.gui.compare``) draws it.
"""

from __future__ import annotations

import time

import numpy as np
from PySide6.QtCore import QEvent, QObject, QSize, Qt
from PySide6.QtGui import QAction, QActionGroup, QIcon, QPixmap
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QDockWidget,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMenu,
    QPushButton,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from lenslab.gui.compare import Comparison
from lenslab.gui.snapshots import COMPARE_LABELS, COMPARE_MODES, MAX_SNAPSHOTS, Snapshot, SnapshotStore, camera_label
from lenslab.gui.viewport import rgba_to_qimage
from lenslab.color import luminance

THUMBNAIL = QSize(96, 64)
ID_ROLE = Qt.UserRole + 1
TAKE_SHORTCUT = "Ctrl+T"
TOGGLE_SHORTCUT = "\\"
CYCLE_SHORTCUT = "Ctrl+\\"


def readout_text(x: int, y: int, snapshot: Snapshot) -> str:
    """The readout over a snapshot: its pixel, the radiance kept with it and its luminance (no depth or object: the
    picking buffers are the live picture's)."""
    parts = [f"<b>A</b>  x {x}  y {y}"]
    if snapshot.linear is None:
        r, g, b = (int(c) for c in snapshot.display[y, x, :3])
        parts.append(f"display RGB {r} {g} {b} (no radiance kept)")
    else:
        rgb = snapshot.linear[y, x]
        r, g, b = (float(c) for c in rgb)
        lum = float(luminance(rgb))
        parts.append(f"<span style='color:#e06c6c'>R</span> {r:.4f}  <span style='color:#7fc56b'>G</span> {g:.4f}  "
                     f"<span style='color:#6b9be0'>B</span> {b:.4f}")
        parts.append(f"L {lum:.4f} ({np.log2(lum / 0.18):+.1f} EV from mid grey)" if lum > 0 else "L 0")
    parts.append(snapshot.label)
    return "   ·   ".join(parts)


class SnapshotList(QListWidget):
    """The snapshots, newest first. Del and F2 act on the list while it has the keyboard (not on the scene's
    selection, which the window's Delete and Rename act on elsewhere)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setObjectName("snapshotList")
        self.setIconSize(THUMBNAIL)
        self.setSelectionMode(QAbstractItemView.SingleSelection)
        self.setEditTriggers(QAbstractItemView.DoubleClicked | QAbstractItemView.EditKeyPressed)
        self.setWordWrap(True)
        self.setSpacing(2)
        self.setUniformItemSizes(False)
        self.delete_requested = None  # callable(id)

    def event(self, event) -> bool:
        if event.type() == QEvent.ShortcutOverride and event.key() in (Qt.Key_Delete, Qt.Key_Backspace, Qt.Key_F2) \
                and self.state() != QAbstractItemView.EditingState:
            event.accept()
            return True
        return super().event(event)

    def keyPressEvent(self, event) -> None:
        item = self.currentItem()
        if event.key() in (Qt.Key_Delete, Qt.Key_Backspace) and item is not None and self.delete_requested:
            self.delete_requested(item.data(ID_ROLE))
            return
        super().keyPressEvent(event)


class SnapshotPanel(QWidget):
    """The Snapshots dock's contents."""

    def __init__(self, store: SnapshotStore, actions: dict[str, QAction], parent=None):
        super().__init__(parent)
        self.store = store
        self._thumbnails: dict[int, QIcon] = {}
        self.list = SnapshotList()
        self.list.delete_requested = store.remove
        self.empty_hint = QLabel(f"No snapshots yet. {TAKE_SHORTCUT} (Render > Take Snapshot) keeps the picture "
                                 "as it is, to compare with what you change next.")
        self.empty_hint.setObjectName("hint")
        self.empty_hint.setWordWrap(True)

        def button(action: QAction) -> QToolButton:
            b = QToolButton()
            b.setDefaultAction(action)  # its text is the action's icon text
            b.setToolButtonStyle(Qt.ToolButtonTextBesideIcon)
            return b

        self.take_button = button(actions["take_snapshot"])
        self.restore_button = QPushButton("Restore Camera")
        self.restore_button.setToolTip("Set the camera (and lens) to the selected snapshot's: one undo step")
        self.rename_button = QPushButton("Rename")
        self.delete_button = QPushButton("Delete")
        self.compare_combo = QComboBox()
        self.compare_combo.setObjectName("compareMode")
        for mode in COMPARE_MODES:
            self.compare_combo.addItem(COMPARE_LABELS[mode], mode)
        self.compare_combo.setToolTip(f"How the selected snapshot (A) meets the live picture (B) ({CYCLE_SHORTCUT})")
        self.toggle_button = button(actions["toggle_ab"])

        row = QHBoxLayout()
        row.setContentsMargins(0, 0, 0, 0)
        for w in (self.take_button, self.restore_button, self.rename_button, self.delete_button):
            row.addWidget(w)
        row.addStretch(1)
        compare_row = QHBoxLayout()
        compare_row.setContentsMargins(0, 0, 0, 0)
        compare_row.addWidget(QLabel("Compare"))
        compare_row.addWidget(self.compare_combo, 1)
        compare_row.addWidget(self.toggle_button)
        self.usage = QLabel()
        self.usage.setObjectName("hint")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.addLayout(compare_row)
        layout.addWidget(self.empty_hint)
        layout.addWidget(self.list, 1)
        layout.addLayout(row)
        layout.addWidget(self.usage)

        self.rename_button.clicked.connect(self.rename_selected)
        self.delete_button.clicked.connect(self.delete_selected)
        self.compare_combo.currentIndexChanged.connect(lambda _i: store.set_mode(self.compare_combo.currentData()))
        self.list.currentItemChanged.connect(self._current_changed)
        self.list.itemChanged.connect(self._item_edited)
        store.events.connect(self._store_changed)
        self.refresh()

    def selected_id(self) -> int | None:
        item = self.list.currentItem()
        return None if item is None else item.data(ID_ROLE)

    def rename_selected(self) -> None:
        item = self.list.currentItem()
        if item is not None:
            self.list.setFocus()
            self.list.editItem(item)

    def delete_selected(self) -> None:
        if self.selected_id() is not None:
            self.store.remove(self.selected_id())

    def _thumbnail(self, snapshot: Snapshot) -> QIcon:
        icon = self._thumbnails.get(snapshot.id)
        if icon is None:
            image = rgba_to_qimage(snapshot.display).scaled(THUMBNAIL, Qt.KeepAspectRatio, Qt.SmoothTransformation)
            icon = self._thumbnails[snapshot.id] = QIcon(QPixmap.fromImage(image))
        return icon

    def refresh(self) -> None:
        store = self.store
        self.list.blockSignals(True)
        self.list.clear()
        for snapshot in reversed(store.snapshots):
            item = QListWidgetItem(self._thumbnail(snapshot), snapshot.label)
            item.setData(ID_ROLE, snapshot.id)
            item.setFlags(item.flags() | Qt.ItemIsEditable)
            w, h = snapshot.size
            taken = time.strftime("%H:%M:%S", time.localtime(snapshot.taken))
            item.setToolTip(f"<b>{snapshot.label}</b><br>{camera_label(snapshot.camera, snapshot.samples_per_pixel)}"
                            f"<br>taken {taken} · {w} × {h} px")
            self.list.addItem(item)
            if snapshot.id == store.a_id:
                self.list.setCurrentItem(item)
        self.list.blockSignals(False)
        for snapshot_id in set(self._thumbnails) - {s.id for s in store.snapshots}:
            del self._thumbnails[snapshot_id]
        has = bool(store.snapshots)
        self.empty_hint.setVisible(not has)
        self.list.setVisible(has)
        for w in (self.restore_button, self.rename_button, self.delete_button):
            w.setEnabled(store.a is not None)
        self.compare_combo.blockSignals(True)
        self.compare_combo.setCurrentIndex(self.compare_combo.findData(store.mode))
        self.compare_combo.blockSignals(False)
        self.usage.setText(f"{len(store.snapshots)} of {MAX_SNAPSHOTS} kept · {store.nbytes / 2**20:.0f} MB; "
                           "the oldest go first" if has else "")

    def _store_changed(self, what: str) -> None:
        if what in ("snapshots", "a", "mode"):
            self.refresh()

    def _current_changed(self, current: QListWidgetItem | None, _previous) -> None:
        if current is not None:
            self.store.select(current.data(ID_ROLE))

    def _item_edited(self, item: QListWidgetItem) -> None:
        self.store.rename(item.data(ID_ROLE), item.text())


class StudioSnapshots(QObject):
    """The snapshot feature of a main window: its store, the viewport's comparison, the dock, actions and menus."""

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.store = SnapshotStore()
        self.comparison = Comparison(self.store, window.viewport, lambda: window.doc.scene.camera)
        self._create_actions()
        self.panel = SnapshotPanel(self.store, window.actions)
        self.panel.restore_button.clicked.connect(lambda: self.restore_camera(self.panel.selected_id()))
        self.dock = QDockWidget("Snapshots", window)
        self.dock.setObjectName("snapshotsDock")
        self.dock.setWidget(self.panel)
        self.dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable |
                              QDockWidget.DockWidgetClosable)
        window.addDockWidget(Qt.RightDockWidgetArea, self.dock)
        window.docks["snapshots"] = self.dock
        self.default_layout()
        self._create_menus()
        window.actions["reset_layout"].triggered.connect(self.default_layout)  # after the window's own reset
        # Connected after the window's own slots, so the readout over a snapshot replaces the live one.
        window.viewport.pixel_hovered.connect(self._show_readout)
        window.controller.frame_ready.connect(self._show_readout)
        self.store.events.connect(self._store_changed)
        self._store_changed("snapshots")

    # -- construction ------------------------------------------------------------------------------------------
    def _create_actions(self) -> None:
        w, store = self.window, self.store
        a = w.make_action
        act = w.actions
        act["take_snapshot"] = a("Take &Snapshot", self.take, TAKE_SHORTCUT, "camera",
                                 tip="Keep the picture as it is, to compare with the live one (A/B)")
        act["restore_snapshot_camera"] = a("Restore Snapshot &Camera", lambda: self.restore_camera(),
                                           tip="Set the camera and lens to snapshot A's (one undo step)")
        group = QActionGroup(w)
        for mode in COMPARE_MODES:
            action = a(COMPARE_LABELS[mode], lambda _c=False, m=mode: store.set_mode(m), checkable=True,
                       tip=f"Compare snapshot A with the live picture: {COMPARE_LABELS[mode].lower()}")
            group.addAction(action)
            act["compare_" + mode] = action
        act["compare_off"].setChecked(True)
        act["take_snapshot"].setIconText("Take")
        act["cycle_compare"] = a("Next Compare Mode", store.cycle_mode, CYCLE_SHORTCUT)
        act["toggle_ab"] = a("Toggle &A/B", lambda on: store.toggle_a(on), TOGGLE_SHORTCUT, checkable=True,
                             tip="Show snapshot A alone in place of the live picture, or the live picture again")

    def _create_menus(self) -> None:
        w, act = self.window, self.window.actions
        view = _menu(w, "View")
        compare = QMenu("&Compare", view)
        for name in ("compare_off", "compare_wipe", "compare_side"):
            compare.addAction(act[name])
        compare.addSeparator()
        compare.addAction(act["cycle_compare"])
        compare.addAction(act["toggle_ab"])
        first_separator = next((x for x in view.actions() if x.isSeparator()), None)
        if first_separator is not None:  # with the zoom entries, before the panels
            view.insertMenu(first_separator, compare)
        else:
            view.addMenu(compare)
        toggle = self.dock.toggleViewAction()
        if act.get("reset_layout") in view.actions():
            view.insertAction(act["reset_layout"], toggle)
        else:
            view.addAction(toggle)
        render = _menu(w, "Render")
        render.addSeparator()
        render.addAction(act["take_snapshot"])
        render.addAction(act["restore_snapshot_camera"])

    def default_layout(self) -> None:
        """Tabbed with the History panel behind the camera panel."""
        w = self.window
        self.dock.setFloating(False)
        self.dock.show()
        w.tabifyDockWidget(w.docks["history"], self.dock)
        w.docks["camera"].raise_()

    # -- taking and restoring ------------------------------------------------------------------------------------
    def take(self) -> Snapshot | None:
        """Keep the viewport's picture (the render's newest frame, the radiance behind it, the camera and lens) as
        snapshot A."""
        w = self.window
        frame = w.controller.last_frame
        if frame is None:
            w.statusBar().showMessage("Nothing to keep yet: the renderer has not shown a picture", 4000)
            return None
        linear = frame.image if frame.image is not None else w.viewport.linear
        snapshot = self.store.take(frame.display, frame.view, linear, w.doc.scene.camera, w.doc.lens,
                                   frame.samples_per_pixel,
                                   exposure_scale=frame.exposure.scale if frame.exposure is not None else 1.0)
        hint = ""
        if self.store.mode == "off":
            hint = " Change the camera, then compare: View > Compare, or \\ for A alone."
        w.statusBar().showMessage(f"Snapshot A: {snapshot.label}.{hint}", 6000)
        return snapshot

    def restore_camera(self, snapshot_id: int | None = None) -> bool:
        """Set the scene's camera and lens to a snapshot's (A by default), as one undo step. False: nothing to do."""
        w = self.window
        doc = w.doc
        snapshot = self.store.get(snapshot_id if snapshot_id is not None else self.store.a_id)
        if snapshot is None:
            return False
        if snapshot.camera == doc.scene.camera and snapshot.lens == doc.lens:
            w.statusBar().showMessage("The camera is already the snapshot's", 4000)
            return False
        from lenslab.gui.commands import LensCommand  # commands know the document: imported when used

        stack = doc.undo_stack
        stack.beginMacro(f"Restore camera: {camera_label(snapshot.camera)}")
        if snapshot.lens != doc.lens:
            doc.push(LensCommand(doc, snapshot.lens))  # the lens's limits, then the camera exactly as it was
        doc.set_values(("camera",), {(): snapshot.camera})
        stack.endMacro()
        return True

    # -- state -----------------------------------------------------------------------------------------------------
    def _store_changed(self, _what: str) -> None:
        act, store = self.window.actions, self.store
        has_a = store.a is not None
        for name in ("compare_off", "compare_wipe", "compare_side", "cycle_compare", "toggle_ab",
                     "restore_snapshot_camera"):
            act[name].setEnabled(has_a)
        act["compare_" + store.mode].setChecked(True)
        act["toggle_ab"].setChecked(store.show_a)
        self._show_readout()

    def _show_readout(self, *_args) -> None:
        xy = self.comparison.hover_a
        a = self.store.a
        if xy is not None and a is not None:
            self.window.readout.setText(readout_text(*xy, a))


def _menu(window, title: str):
    """The window's menu of that title (ignoring the & of its shortcut), made if there is none."""
    for action in window.menuBar().actions():
        if action.menu() is not None and action.text().replace("&", "") == title:
            return action.menu()
    return window.menuBar().addMenu(f"&{title}")


__all__ = ["StudioSnapshots", "SnapshotPanel", "readout_text"]
