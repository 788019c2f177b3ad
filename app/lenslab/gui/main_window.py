"""The studio's main window: the viewport in the centre, the outliner and property editor on the left, the camera
panel on the right, the render status at the bottom; menus for files, editing, the view, the camera and the
render. The layout, the display settings and the recent files are remembered between runs (QSettings).

The window assembles the studio; its actions and menus are declared in :mod:`.actions`, its files handled by
:mod:`.file_controller` and its exports by :mod:`.export_flow`."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

from PySide6.QtCore import QPointF, QRectF, QSettings, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QMenu,
    QMessageBox,
    QProgressBar,
    QProgressDialog,
    QScrollArea,
    QSizePolicy,
    QToolBar,
    QToolButton,
    QUndoView,
    QVBoxLayout,
    QWidget,
)

from lenslab import __version__
from lenslab.gui import theme
from lenslab.gui.actions import build_menus, create_actions, make_action, selection_has_nodes, update_enabled
from lenslab.gui.camera_panel import CameraPanel
from lenslab.gui.commands import (AddLightCommand, AddMaterialCommand, AddNodeCommand, RemoveLightsCommand,
                                  RemoveMaterialCommand, RemoveNodesCommand)
from lenslab.gui.controller import SAMPLE_LIMITS, RenderController, elapsed_text, rate_text, samples_text
from lenslab.gui.defaults import studio_scene
from lenslab.gui.document import Document, is_shipped, listen
from lenslab.gui.export_dialog import ExportDialog
from lenslab.gui.export_flow import ExportFlow
from lenslab.gui.file_controller import FileController
from lenslab.gui.navigation import CameraNavigator
from lenslab.gui.properties import PropertyEditor
from lenslab.gui.scene_tree import SceneTreeView, node_context_menu
from lenslab.gui.snapshot_panel import StudioSnapshots
from lenslab.gui.viewing_aids import ViewingAids
from lenslab.gui.viewport import Viewport
from lenslab.gui.widgets import ResetSlider, SignedNumberEdit
from lenslab.gui.worker import VIEWPORT_DISPATCH_SECONDS
from lenslab.color import luminance
from lenslab.optics import format_camera_settings, format_distance
from lenslab.optics.exposure import format_shutter
from lenslab.render.film import TONE_MAPS
from lenslab.scene import editing
from lenslab.scene.io.loader import scene_title
from lenslab.scene.io.native import save_scene

DISPLAY_EXPOSURE_STOPS = 6.0  # the display exposure slider reaches this many stops either way

APP_NAME = "LensLab"


def studio_settings() -> QSettings:
    return QSettings(QSettings.IniFormat, QSettings.UserScope, "LensLab", "studio")


class MainWindow(QMainWindow):
    closed = Signal()
    mesh_imported = Signal(str)  # path, once its node is in the scene
    mesh_import_failed = Signal(str, str)  # path, reason

    def __init__(self, scene=None, path: Path | None = None, *, device_index: int | None = None,
                 settings: QSettings | None = None, dispatch_seconds: float = VIEWPORT_DISPATCH_SECONDS,
                 restore_layout: bool = True):
        super().__init__()
        from PySide6.QtWidgets import QApplication

        from lenslab.gui.qtcompat import guard_singletons

        guard_singletons(QApplication.instance())
        self.setObjectName("LensLabMainWindow")
        self.settings = settings if settings is not None else studio_settings()
        self.doc = Document(scene if scene is not None else studio_scene(), path, self)
        quality = str(self.settings.value("viewport/quality", "auto"))
        limit = self.settings.value("viewport/sample_limit", 1024)
        limit = None if limit in (None, "", "none", "None") else int(limit)
        self.controller = RenderController(self.doc, device_index, dispatch_seconds, quality, limit, self)
        # The file writer and the export dialog are looked up here when they are used, so that a test can stand
        # in for them (lenslab.gui.main_window.save_scene, .ExportDialog).
        self.files = FileController(self, self.doc, self.settings, lambda scene, path: save_scene(scene, path))
        self.files.mesh_imported.connect(self.mesh_imported)
        self.files.mesh_import_failed.connect(self.mesh_import_failed)
        self.export_flow = ExportFlow(self, self.controller, self.files, lambda *args: ExportDialog(*args))
        self._structure_generation = 0
        self._hover: tuple[int, int] | None = None

        self.viewport = Viewport()
        self.viewport.set_display(*self._saved_look())
        self.controller.set_display(self.viewport.exposure, self.viewport.tone_map)
        self.controller.set_denoise(self.settings.value("viewport/denoise", True) not in (False, "false", "0", 0))
        self.navigator = CameraNavigator(self.doc, self.viewport, self._view_frame, self)
        # The picture follows the viewport's size, once the size has settled (a window being dragged larger
        # would otherwise restart the render at every step).
        self._resize_timer = QTimer(self)
        self._resize_timer.setSingleShot(True)
        self._resize_timer.setInterval(120)
        self._resize_timer.timeout.connect(self._send_viewport_size)
        self._viewport_size: tuple[int, int] | None = None
        self.actions: dict[str, QAction] = create_actions(self)
        self.setCentralWidget(self._central())
        self._create_docks()
        menus = build_menus(self.menuBar(), self.actions, {
            "examples": self.files.fill_examples_menu, "recent": self.files.fill_recent_menu,
            "panels": self._add_panel_toggles, "lenses": self._fill_lens_menu})
        self.shipped_menu, self.recent_menu = menus["examples"], menus["recent"]
        self._create_status_bar()
        self._connect()
        self.snapshots = StudioSnapshots(self)  # its dock exists before the saved layout is restored
        # The sensor's gate and guides, aspect presets, focus peaking, the histogram and clipping warnings, the loupe.
        self.viewing = ViewingAids(self)
        self.setAcceptDrops(True)
        self.setWindowIcon(app_icon())
        self.resize(1480, 920)
        if restore_layout:
            self._restore_layout()
        self._update_title()
        self._update_hud()
        self._update_actions()

    # -- construction ------------------------------------------------------------------------------------------
    def make_action(self, text: str, slot=None, shortcut=None, icon: str | None = None, checkable: bool = False,
                    tip: str | None = None) -> QAction:
        """A QAction added to the window, so its shortcut works wherever the focus is; the tip, shortcut
        appended, is its status tip and tooltip. The studio's panels make their actions with it too."""
        return make_action(self, text, slot, shortcut, icon, checkable, tip)

    def _saved_look(self) -> tuple[float, str]:
        """The viewport's exposure and tone map from the last session; a value edited by hand or written by
        another version falls back to the default rather than stopping the studio."""
        try:
            exposure = float(self.settings.value("viewport/exposure", 0.0))
        except (TypeError, ValueError):
            exposure = 0.0
        if not math.isfinite(exposure):
            exposure = 0.0
        exposure = min(DISPLAY_EXPOSURE_STOPS, max(-DISPLAY_EXPOSURE_STOPS, exposure))
        tone_map = str(self.settings.value("viewport/tone_map", "filmic"))
        return exposure, tone_map if tone_map in TONE_MAPS else "filmic"

    def _central(self) -> QWidget:
        bar = QToolBar()
        bar.setObjectName("viewportBar")
        bar.setMovable(False)
        for name in ("tool_select", "tool_focus", "tool_pan", "tool_region"):
            bar.addAction(self.actions[name])
        bar.addSeparator()
        bar.addAction(self.actions["fit"])
        self.zoom_label = QLabel("Fit")
        self.zoom_label.setObjectName("readout")
        self.zoom_label.setMinimumWidth(44)
        bar.addWidget(self.zoom_label)
        bar.addSeparator()
        exposure_label = QLabel(" EV ")
        exposure_label.setToolTip("Display exposure")
        bar.addWidget(exposure_label)
        # The slider, a field to type a value into (1.5 is +1.5 EV; the arrows step a tenth) and a reset to 0,
        # all three the same setting (display only).
        self.exposure_slider = ResetSlider(Qt.Horizontal, default=0)
        self.exposure_slider.setRange(round(-10 * DISPLAY_EXPOSURE_STOPS), round(10 * DISPLAY_EXPOSURE_STOPS))
        self.exposure_slider.setFixedWidth(110)
        self.exposure_slider.setValue(round(self.viewport.exposure * 10))
        self.exposure_slider.setToolTip("Display exposure in stops (display only: the render is not restarted); "
                                        "double-click: back to 0")
        self.exposure_spin = SignedNumberEdit(-DISPLAY_EXPOSURE_STOPS, DISPLAY_EXPOSURE_STOPS, 1, 0.1, " EV")
        self.exposure_spin.setObjectName("displayExposure")
        self.exposure_spin.setFixedWidth(70)
        self.exposure_spin.setToolTip("Display exposure in stops: type a value (1.5 is +1.5 EV); the arrow keys "
                                      "and the wheel step a tenth")
        self.exposure_reset = QToolButton()
        self.exposure_reset.setObjectName("exposureReset")
        self.exposure_reset.setText("\u21ba")  # ↺
        self.exposure_reset.setStyleSheet("QToolButton { border: 1px solid #45464b; padding: 0px 5px; }"
                                          "QToolButton:disabled { color: #5c5e62; border-color: #38393c; }")
        self.exposure_reset.setToolTip("Display exposure back to 0 EV (or double-click the slider)")
        bar.addWidget(self.exposure_slider)
        bar.addWidget(self.exposure_spin)
        bar.addWidget(self.exposure_reset)
        self.tone_combo = QComboBox()
        self.tone_combo.setObjectName("toneMap")
        for name in TONE_MAPS:
            self.tone_combo.addItem(name.capitalize(), name)
        self.tone_combo.setCurrentIndex(max(0, self.tone_combo.findData(self.viewport.tone_map)))
        self.tone_combo.setToolTip("Tone map: how radiance above 1 is brought into the displayable range "
                                   "(filmic by default)")
        bar.addWidget(self.tone_combo)
        spacer = QWidget()
        spacer.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        bar.addWidget(spacer)
        self.quality_combo = QComboBox()
        for name, label in (("auto", "Auto res"), ("full", "Full res"), ("half", "½ res"), ("quarter", "¼ res"),
                            ("export", "Export res")):
            self.quality_combo.addItem(label, name)
        self.quality_combo.setCurrentIndex(max(0, self.quality_combo.findData(self.controller.quality)))
        self.quality_combo.setToolTip("The viewport's resolution: a fraction of its own size in pixels (Auto: all "
                                      "of them on a GPU, at most 800 on the long side on the CPU), or the "
                                      "export's own pixels")
        bar.addWidget(self.quality_combo)
        bar.addAction(self.actions["denoise"])
        self.limit_combo = QComboBox()
        for spp in SAMPLE_LIMITS:
            self.limit_combo.addItem(f"{spp} spp" if spp else "∞ spp", spp)
        self.limit_combo.setCurrentIndex(max(0, self.limit_combo.findData(self.controller.target_spp)))
        self.limit_combo.setToolTip("The viewport stops refining at this many samples per pixel")
        bar.addWidget(self.limit_combo)
        bar.addAction(self.actions["pause"])
        bar.addAction(self.actions["restart"])
        self._update_exposure_label()

        self.readout = QLabel(" ")
        self.readout.setObjectName("readout")
        self.readout.setContentsMargins(8, 2, 8, 2)
        self.readout.setTextFormat(Qt.RichText)
        central = QWidget()
        layout = QVBoxLayout(central)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(bar)
        layout.addWidget(self.viewport, 1)
        layout.addWidget(self.readout)
        return central

    def _create_docks(self) -> None:
        self.setDockOptions(QMainWindow.AnimatedDocks | QMainWindow.AllowTabbedDocks)
        self.scene_tree = SceneTreeView(self.doc)
        self.properties = PropertyEditor(self.doc)
        self.properties.picture_height = self._frame_height_on_screen  # a scrubbed object follows the mouse
        self.camera_panel = CameraPanel(self.doc, self.actions["tool_focus"], settings=self.settings)
        self.camera_panel.stop_scale_changed.connect(self._name_stop_actions)
        self._name_stop_actions(self.camera_panel.scale_name)
        self.camera_panel.focus_selection_button.clicked.connect(self.focus_on_selection)
        camera_scroll = QScrollArea()
        camera_scroll.setWidgetResizable(True)
        camera_scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
        camera_scroll.setWidget(self.camera_panel)
        camera_scroll.setMinimumWidth(330)
        self.history = QUndoView(self.doc.undo_stack)
        self.history.setEmptyLabel("Opened")
        self.docks: dict[str, QDockWidget] = {}
        for key, title, widget, area in (("scene", "Scene", self.scene_tree, Qt.LeftDockWidgetArea),
                                         ("properties", "Properties", self.properties, Qt.LeftDockWidgetArea),
                                         ("camera", "Camera", camera_scroll, Qt.RightDockWidgetArea),
                                         ("history", "History", self.history, Qt.RightDockWidgetArea)):
            dock = QDockWidget(title, self)
            dock.setObjectName(f"{key}Dock")
            dock.setWidget(widget)
            dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable |
                             QDockWidget.DockWidgetClosable)
            self.addDockWidget(area, dock)
            self.docks[key] = dock
        self._default_dock_layout()

    def _default_dock_layout(self) -> None:
        for dock in self.docks.values():
            dock.setFloating(False)
            dock.show()
        self.splitDockWidget(self.docks["scene"], self.docks["properties"], Qt.Vertical)
        self.tabifyDockWidget(self.docks["camera"], self.docks["history"])
        self.docks["camera"].raise_()
        self.resizeDocks([self.docks["scene"], self.docks["camera"]], [360, 350], Qt.Horizontal)
        self.resizeDocks([self.docks["scene"], self.docks["properties"]], [300, 520], Qt.Vertical)

    def _add_panel_toggles(self, menu: QMenu) -> None:
        for dock in self.docks.values():
            menu.addAction(dock.toggleViewAction())

    def _fill_lens_menu(self, menu: QMenu) -> None:
        self.lens_actions = []
        free = self.make_action("Free (no lens limits)", lambda: self.camera_panel.choose_lens(None), "Alt+0")
        menu.addAction(free)
        menu.addSeparator()
        for i, lens in enumerate(self.camera_panel.lenses):
            action = self.make_action(lens.name, lambda _c=False, lens=lens: self.camera_panel.choose_lens(lens),
                                      f"Alt+{i + 1}" if i < 9 else None)
            menu.addAction(action)
            self.lens_actions.append(action)

    def _create_status_bar(self) -> None:
        status = self.statusBar()
        self.spp_label = QLabel("—")
        self.spp_label.setObjectName("sppLabel")
        self.progress_bar = QProgressBar()
        self.progress_bar.setFixedWidth(120)
        self.progress_bar.setTextVisible(False)
        self.progress_bar.setRange(0, 1000)
        self.rate_label = QLabel("")
        self.elapsed_label = QLabel("")
        self.device_label = QLabel("starting renderer…")
        self.device_label.setObjectName("deviceLabel")
        for widget in (self.spp_label, self.progress_bar, self.rate_label, self.elapsed_label, self.device_label):
            status.addPermanentWidget(widget)

    def _connect(self) -> None:
        doc, c = self.doc, self.controller
        doc.file_changed.connect(self._update_title)
        doc.selection_changed.connect(self._selection_changed)
        listen(doc.model.events.changed, self, self._scene_changed)
        doc.undo_stack.indexChanged.connect(lambda _i: self._update_actions())
        c.frame_ready.connect(self._frame)
        c.gbuffer_ready.connect(self._gbuffer)
        c.device_ready.connect(self._device)
        c.render_error.connect(self._render_error)
        v = self.viewport
        v.pixel_hovered.connect(self._hovered)
        v.node_clicked.connect(self._node_clicked)
        v.focus_clicked.connect(self._focus_clicked)
        v.focus_preview.connect(self._focus_preview)
        v.zoom_changed.connect(lambda s: self.zoom_label.setText("Fit" if v.zoom is None else f"{s * 100:.0f}%"))
        v.resized.connect(self._viewport_resized)
        v.region_drawn.connect(self._region_drawn)
        self.exposure_slider.valueChanged.connect(lambda tenths: self.set_display_exposure(tenths / 10))
        self.exposure_spin.valueChanged.connect(self.set_display_exposure)
        self.exposure_reset.clicked.connect(lambda: self.set_display_exposure(0.0))
        self.tone_combo.currentIndexChanged.connect(self._tone_changed)
        self.quality_combo.currentIndexChanged.connect(self._quality_changed)
        self.limit_combo.currentIndexChanged.connect(self._limit_changed)
        self.camera_panel.status_message.connect(lambda text: self.statusBar().showMessage(text, 5000))
        self.scene_tree.context_menu_requested.connect(
            lambda pos: node_context_menu(self, self.actions).exec(pos))
        self.scene_tree.doubleClicked.connect(lambda _i: None)

    # -- layout memory -----------------------------------------------------------------------------------------
    def _restore_layout(self) -> None:
        geometry = self.settings.value("window/geometry")
        state = self.settings.value("window/state")
        if geometry is not None:
            self.restoreGeometry(geometry)
        if state is not None:
            self.restoreState(state)

    def _save_layout(self) -> None:
        s = self.settings
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        s.setValue("viewport/exposure", self.viewport.exposure)
        s.setValue("viewport/tone_map", self.viewport.tone_map)
        s.setValue("viewport/quality", self.controller.quality)
        s.setValue("viewport/sample_limit", self.controller.target_spp or "none")
        s.sync()

    def reset_layout(self) -> None:
        self._default_dock_layout()

    # -- title, actions, HUD -----------------------------------------------------------------------------------
    def _update_title(self) -> None:
        example = self.doc.path is None and self.doc.scene.source_path and is_shipped(self.doc.scene.source_path)
        name = scene_title(self.doc.display_name) if example else self.doc.display_name
        suffix = " (example)" if example else ""
        self.setWindowTitle(f"{name}{suffix}[*] — {APP_NAME}")
        self.setWindowModified(self.doc.modified)
        if self.doc.path is not None:
            self.setWindowFilePath(str(self.doc.path))

    def _update_actions(self) -> None:
        update_enabled(self, self.actions)  # the actions' own predicates (actions.ACTIONS)
        self.camera_panel.focus_selection_button.setEnabled(selection_has_nodes(self))

    def _name_stop_actions(self, scale: str) -> None:
        """[ and ] step the camera panel's stop scale: their menu entries say by how much."""
        amount = {"full": "1", "half": "½", "third": "⅓"}.get(scale, "⅓")
        self.actions["open_up"].setText(f"Open Up {amount} Stop")
        self.actions["stop_down"].setText(f"Stop Down {amount} Stop")

    def _update_hud(self) -> None:
        cam = self.doc.scene.camera
        self.viewport.hud_text = format_camera_settings(cam.focal_length_mm, cam.f_number, cam.focus_distance_m)
        if cam.exposure_mode == "physical":
            self.viewport.hud_text += f" \u00b7 {format_shutter(cam.shutter_s)} \u00b7 ISO {cam.iso:g}"
        self.viewport.update()

    # -- document events ---------------------------------------------------------------------------------------
    def _scene_changed(self, change) -> None:
        if change.kind in ("structure", "scene"):
            self._structure_generation = self.controller.generation
            self._selection_changed()
        if change.kind == "scene":
            self.viewport.fit()
            self.camera_panel.refresh()
        if change.kind == "camera":
            self._update_hud()
            if change.field[:1] in (("focus_distance_m",), ("f_number",), ("sensor_mm",)) or change.field == ():
                self._show_focus_overlay(self.doc.scene.camera.plane_of_focus_m)
        if change.kind == "scene":
            self._update_hud()
        self._update_actions()

    def _selection_changed(self) -> None:
        indices: list[int] = []
        for path in self.doc.selected_node_paths():
            indices.extend(self.doc.model.subtree_indices(path))
        self.viewport.set_selection(indices)
        self._update_actions()

    # -- render events -------------------------------------------------------------------------------------------
    def _frame(self, frame) -> None:
        export_pixels = self.controller.quality == "export"
        self.viewport.fit_margin = 24 if export_pixels else 0
        self.viewport.gate_rect = QRectF(*frame.gate) if frame.gate is not None and not export_pixels else None
        self.viewport.region_rect = QRectF(*frame.region) if frame.region is not None else None
        self.viewport.set_frame(frame.display, frame.display_settings, frame.image)
        if self.viewport.zoom is None:
            self.zoom_label.setText("Fit")
        self.spp_label.setText(samples_text(frame))
        if frame.target_spp:
            self.progress_bar.setValue(round(1000 * min(1.0, frame.samples_per_pixel / frame.target_spp)))
        self.progress_bar.setVisible(bool(frame.target_spp))
        self.rate_label.setText(rate_text(frame.samples_per_second) if frame.samples_per_second else "")
        self.elapsed_label.setText(elapsed_text(frame.elapsed_seconds))
        self._update_corner_state(frame)
        if self._hover is not None:
            self._hovered(self._hover)

    def _gbuffer(self, gbuffer) -> None:
        self.viewport.set_gbuffer(gbuffer)
        if self.viewport.overlay_visible():
            self._show_focus_overlay(self.doc.scene.camera.plane_of_focus_m)

    def _device(self, info: dict) -> None:
        self.device_label.setText(info.get("renderer", "GPU"))
        self.device_label.setToolTip("\n".join(f"{k}: {v}" for k, v in info.items()))

    def _render_error(self, message: str) -> None:
        self.viewport.message = message
        self.viewport.update()
        if message:
            self.statusBar().showMessage(message, 8000)
        if self.controller.device_error:
            self.device_label.setText("no GPU")

    # -- viewport interaction --------------------------------------------------------------------------------------
    def set_tool(self, tool: str) -> None:
        self.actions["tool_" + tool].setChecked(True)
        self.viewport.set_tool(tool)
        hints = {"select": "Select: click an object in the picture; Shift adds to the selection.",
                 "focus": "Focus: click a point to focus there; hold the button to preview the plane of focus.",
                 "pan": "Pan: drag the picture; the wheel zooms.",
                 "region": "Render region: drag a rectangle to refine only it; Alt+R renders everything again."}
        self.statusBar().showMessage(hints[tool], 4000)

    def _hovered(self, xy) -> None:
        self._hover = xy
        image = self.viewport.linear
        if xy is None or image is None:
            self.readout.setText(" ")
            return
        x, y = xy
        h, w = image.shape[:2]
        if not (0 <= x < w and 0 <= y < h):
            self.readout.setText(" ")
            return
        r, g, b = (float(c) for c in image[y, x])
        lum = luminance((r, g, b))
        parts = [f"x {x}  y {y}",
                 f"<span style='color:#e06c6c'>R</span> {r:.4f}  <span style='color:#7fc56b'>G</span> {g:.4f}  "
                 f"<span style='color:#6b9be0'>B</span> {b:.4f}",
                 f"L {lum:.4f} ({math.log2(lum / 0.18):+.1f} EV from mid grey)" if lum > 0 else "L 0"]
        depth = self.viewport.depth_at(x, y)
        if math.isfinite(depth):
            parts.append(f"depth {format_distance(depth)}")
        index = self.viewport.node_at(x, y)
        paths = self.doc.model.node_paths()
        if 0 <= index < len(paths):
            parts.append(self.doc.model.node(paths[index]).name)
        self.readout.setText("   ·   ".join(parts))

    def _node_clicked(self, index: int, add: bool) -> None:
        g = self.viewport.gbuffer
        paths = self.doc.model.node_paths()
        if g is not None and g.generation < self._structure_generation:
            return  # the picture's node numbers predate an edit of the tree
        target = [("node", paths[index])] if 0 <= index < len(paths) else []
        if add:
            current = list(self.doc.selection)
            for t in target:
                if t in current:
                    current.remove(t)
                else:
                    current.append(t)
            self.doc.set_selection(current)
        else:
            self.doc.set_selection(target)

    def _focus_clicked(self, u: float, v: float) -> None:
        self.controller.pick(u, v, self._focus_answered)

    def _focus_answered(self, result) -> None:
        self.viewport.focus_pending = False
        if not result.hit:
            self.viewport.hide_focus_overlay()
            self.statusBar().showMessage("Nothing there to focus on: that is the background.", 4000)
            return
        paths = self.doc.model.node_paths()
        name = self.doc.model.node(paths[result.node_index]).name if 0 <= result.node_index < len(paths) else "surface"
        camera = self.doc.scene.camera
        # The pick's depth is from the lens; the camera's focus reading may be from the sensor.
        if camera.focus_from == "sensor" and result.depth <= camera.focal_length_mm / 1000:
            self.statusBar().showMessage(f"{name} is nearer than any lens focuses", 4000)
            return
        setting = round(camera.focus_setting_for(float(result.depth)), 4)
        if self.camera_panel.set_focus(setting, text=f"Focus on {name} ({format_distance(setting)})"):
            self.statusBar().showMessage(f"Focused on {name} at {format_distance(setting)}", 4000)

    def _focus_preview(self, depth: float) -> None:
        self._show_focus_overlay(depth, hold=True)

    def _show_focus_overlay(self, depth: float, hold: bool = False) -> None:
        """The zone of sharpness on the picture, were the plane of focus ``depth`` ahead of the lens (the depth
        buffer's distances)."""
        cam = self.doc.scene.camera
        if cam.focus_from == "sensor" and depth <= cam.focal_length_mm / 1000 * 1.0001:
            return
        try:
            trial = dataclasses.replace(cam, focus_distance_m=cam.focus_setting_for(max(depth, 1e-3)))
            dof = trial.depth_of_field(*cam.resolution, self.camera_panel.light_fraction(), reference="lens")
        except ValueError:  # nearer than the lens can focus: no zone to show
            return
        self.viewport.show_focus_overlay(depth, dof.near_m, dof.far_m, hold)

    def _frame_height_on_screen(self) -> float:
        """The export frame's height as the viewport draws it, in screen pixels (0 before the first picture):
        what the camera's frame spans at an object's depth is spread over this many pixels."""
        gate = self.viewport.gate_rect
        height = gate.height() if gate is not None else self.viewport.image_size()[1]
        return height * self.viewport.scale()

    def set_display_exposure(self, stops: float) -> None:
        """The viewport's display exposure, from the slider, the field or the reset: each shows it after."""
        stops = min(DISPLAY_EXPOSURE_STOPS, max(-DISPLAY_EXPOSURE_STOPS, round(float(stops), 1)))
        if stops != self.viewport.exposure:
            self.viewport.set_display(exposure=stops)
            self.controller.set_display(self.viewport.exposure, self.viewport.tone_map)
        self._update_exposure_label()

    def _update_exposure_label(self) -> None:
        """The slider and the field show the viewport's exposure (without telling anyone again)."""
        for widget, value in ((self.exposure_slider, round(self.viewport.exposure * 10)),
                              (self.exposure_spin, self.viewport.exposure)):
            widget.blockSignals(True)
            widget.setValue(value)
            widget.blockSignals(False)
        self.exposure_reset.setEnabled(self.viewport.exposure != 0)

    def _tone_changed(self, _index: int) -> None:
        self.viewport.set_display(operator=self.tone_combo.currentData())
        self.controller.set_display(self.viewport.exposure, self.viewport.tone_map)

    def _quality_changed(self, _index: int) -> None:
        self.controller.set_quality(self.quality_combo.currentData())

    def _limit_changed(self, _index: int) -> None:
        self.controller.set_target_spp(self.limit_combo.currentData())

    # -- the viewport's picture: size, render region, denoiser, camera moves ----------------------------------------
    def _viewport_resized(self, width: int, height: int) -> None:
        self._viewport_size = (width, height)
        self._resize_timer.start()

    def _send_viewport_size(self) -> None:
        if self._viewport_size is not None:
            self.controller.set_widget_size(*self._viewport_size)

    def _region_drawn(self, region) -> None:
        self.controller.set_region(region)
        self.statusBar().showMessage("Refining the render region; Alt+R renders the whole picture again.", 5000)

    def set_denoise(self, on: bool) -> None:
        self.controller.set_denoise(bool(on))
        self.actions["denoise"].setChecked(bool(on))
        self.settings.setValue("viewport/denoise", bool(on))

    def _view_frame(self):
        """The CameraFrame of the picture on screen."""
        camera = self.doc.scene.camera
        w, h = self.controller.size
        margin = self.controller.margin
        return camera.frame(w, h) if margin is None else camera.view_frame(w, h, margin)

    def frame_selection(self, everything: bool = False) -> None:
        paths = [] if everything else self.doc.selected_node_paths()
        if not self.navigator.frame_selection(paths):
            self.statusBar().showMessage("Nothing to frame", 4000)

    def set_paused(self, paused: bool) -> None:
        self.controller.set_paused(bool(paused))
        self.actions["pause"].setIcon(theme.icon("play" if paused else "pause"))
        self.actions["pause"].setText("Resume Rendering" if paused else "Pause Rendering")
        self._update_corner_state(self.controller.last_frame)

    def _update_corner_state(self, frame) -> None:
        """The viewport's corner tag: the status bar's sample count (one text for both, so they never disagree),
        and whether the render is paused or done and the picture denoised."""
        if frame is None:
            return
        state = [samples_text(frame)]
        if self.controller.paused:
            state.append("paused")
        elif frame.converged:
            state.append("done")
        if frame.denoised:
            state.append("denoised")
        self.viewport.status_text = " · ".join(state)
        self.viewport.update()

    # -- adding, importing, deleting --------------------------------------------------------------------------------
    def add_primitive(self, kind: str) -> None:
        new = editing.new_primitive(self.doc.model, kind)
        parent = editing.insertion_parent(self.doc.model, self.doc.selected_node_paths())
        if new.material is None:
            self.doc.push(AddNodeCommand(self.doc, new.node, parent))
            return
        stack = self.doc.undo_stack
        stack.beginMacro(f"Add {new.node.name}")
        self.doc.push(AddMaterialCommand(self.doc, *new.material))
        self.doc.push(AddNodeCommand(self.doc, new.node, parent))
        stack.endMacro()

    def add_light(self, kind: str) -> None:
        self.doc.push(AddLightCommand(self.doc, editing.new_light(self.doc.model, kind)))

    def new_material(self) -> None:
        name, material = editing.new_material(self.doc.model)
        self.doc.push(AddMaterialCommand(self.doc, name, material, assign_to=self.doc.selected_node_paths()))
        self.doc.set_selection([("material", name)])

    def delete_selection(self) -> None:
        nodes = self.doc.selected_node_paths()
        materials = [t[1] for t in self.doc.selection if t[0] == "material"]
        lights = [t[1] for t in self.doc.selection if t[0] == "light" and self.doc.model.exists(t)]
        if not nodes and not materials and not lights:
            return
        stack = self.doc.undo_stack
        stack.beginMacro("Delete")
        if lights:
            self.doc.push(RemoveLightsCommand(self.doc, lights))
        if nodes:
            self.doc.push(RemoveNodesCommand(self.doc, nodes))
        for name in materials:
            if name in self.doc.scene.materials:
                self.doc.push(RemoveMaterialCommand(self.doc, name))
        stack.endMacro()

    def duplicate_selection(self) -> None:
        paths = self.doc.selected_node_paths()
        if not paths:
            return
        stack = self.doc.undo_stack
        stack.beginMacro("Duplicate")
        new_targets = []
        for path in sorted(paths, reverse=True):  # last first: the paths still to copy stay valid
            node = editing.duplicate(self.doc.model, path)
            command = AddNodeCommand(self.doc, node, path[:-1], path[-1] + 1, text=f"Duplicate {node.name}")
            self.doc.push(command)
            new_targets.append(("node", command.path))
        stack.endMacro()
        self.doc.set_selection(new_targets)

    def rename_selection(self) -> None:
        if not self.doc.selection:
            return
        index = self.scene_tree.tree_model.index_of(self.doc.selection[0])
        if index.isValid():
            self.docks["scene"].show()
            self.scene_tree.setFocus()
            self.scene_tree.edit(index)

    def focus_on_selection(self) -> None:
        paths = self.doc.selected_node_paths()
        if not paths:
            return
        g = self.viewport.gbuffer
        fresh = g is not None and g.generation >= self._structure_generation  # its node numbers are today's
        distance = editing.focus_distance_for(self.doc.model, paths, g if fresh else None)
        if distance is None:
            self.statusBar().showMessage("The selection is behind the camera, or nearer than the lens focuses", 4000)
            return
        name = self.doc.model.node(paths[0]).name
        self.camera_panel.set_focus(distance, text=f"Focus on {name}")

    # -- files and export: the file controller and the export flow do them -----------------------------------------
    def maybe_save(self) -> bool:
        return self.files.maybe_save()

    def new_scene(self) -> None:
        self.files.new_scene()

    def open_dialog(self) -> None:
        self.files.open_dialog()

    def open_path(self, text: str | os.PathLike, ask: bool = True) -> bool:
        return self.files.open_path(text, ask)

    def save(self) -> bool:
        return self.files.save()

    def save_as(self) -> bool:
        return self.files.save_as()

    def _write(self, path: Path) -> bool:
        return self.files.write(path)

    def last_folder(self, kind: str) -> Path | None:
        return self.files.last_folder(kind)

    def remember_folder(self, kind: str, file: str | os.PathLike) -> None:
        self.files.remember_folder(kind, file)

    def recent_files(self) -> list[str]:
        return self.files.recent_files()

    def import_dialog(self) -> None:
        self.files.import_dialog()

    def import_mesh(self, path: Path) -> None:
        self.files.import_mesh(path)

    @property
    def _unsaved_box(self) -> QMessageBox | None:
        return self.files.unsaved_box

    def dragEnterEvent(self, event) -> None:
        self.files.drag_enter(event)

    def dropEvent(self, event) -> None:
        self.files.drop(event)

    def export_dialog(self) -> None:
        self.export_flow.open_dialog()

    def start_export(self, request) -> int:
        return self.export_flow.start(request)

    def cancel_export(self) -> None:
        self.export_flow.cancel()

    @property
    def export_id(self) -> int | None:
        return self.export_flow.export_id

    @property
    def export_progress_dialog(self) -> QProgressDialog | None:
        return self.export_flow.progress_dialog

    @property
    def last_export_path(self) -> Path | None:
        return self.export_flow.last_path

    # -- help ----------------------------------------------------------------------------------------------------------
    def show_shortcuts(self) -> None:
        rows = []
        for action in self.findChildren(QAction):
            if action.shortcut().isEmpty() or not action.text():
                continue
            rows.append((action.text().replace("&", ""), action.shortcut().toString(QKeySequence.NativeText)))
        rows = sorted(set(rows))
        table = "".join(f"<tr><td>{name}</td><td style='padding-left:16px'><b>{key}</b></td></tr>" for name, key in rows)
        QMessageBox.information(self, "Keyboard shortcuts",
                                f"<table>{table}</table><p>Space + drag pans; the wheel zooms; drag a field's label to "
                                "scrub its value.</p>")

    def show_about(self) -> None:
        device = self.controller.device or {}
        QMessageBox.about(self, "About LensLab",
                          f"<h3>LensLab {__version__}</h3><p>A photographic studio on a physically based path tracer "
                          "with a thin-lens camera.</p>"
                          f"<p>Renderer: {device.get('renderer', 'not started')}<br>OpenGL {device.get('version', '')}</p>")

    # -- closing -------------------------------------------------------------------------------------------------------
    def closeEvent(self, event) -> None:
        if not self.maybe_save():
            event.ignore()
            return
        self.files.closing = self.export_flow.closing = True  # a failure now is not worth a message box
        self._save_layout()
        if self.export_id is not None:
            self.cancel_export()
        stopped = self.controller.shutdown()
        if not stopped:  # a very long kd-tree build: do not hang the desktop; the process exit will end it
            self.statusBar().showMessage("The renderer is still busy; closing anyway")
        self.doc.silence()
        event.accept()
        self.closed.emit()


def app_icon():
    from PySide6.QtGui import QIcon

    here = Path(__file__).resolve().parent / "resources"
    icon = QIcon()
    for name in ("lenslab.svg", "lenslab-256.png"):
        if (here / name).exists():
            icon.addFile(str(here / name))
    return icon


__all__ = ["MainWindow", "studio_settings", "QPointF", "QHBoxLayout"]
