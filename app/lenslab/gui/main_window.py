"""The studio's main window: the viewport in the centre, the outliner and property editor on the left, the camera
panel on the right, the render status at the bottom; menus for files, editing, the view, the camera and the
render. The layout, the display settings and the recent files are remembered between runs (QSettings)."""

from __future__ import annotations

import dataclasses
import math
import os
import threading
from pathlib import Path

from PySide6.QtCore import QPointF, QRectF, QSettings, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QMainWindow,
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
from lenslab.gui.camera_panel import CameraPanel
from lenslab.gui.commands import (AddLightCommand, AddMaterialCommand, AddNodeCommand, RemoveLightsCommand,
                                  RemoveMaterialCommand, RemoveNodesCommand)
from lenslab.gui.controller import SAMPLE_LIMITS, RenderController, elapsed_text, rate_text, samples_text
from lenslab.gui.defaults import studio_scene
from lenslab.gui.document import Document, is_shipped, listen
from lenslab.gui.navigation import CameraNavigator
from lenslab.gui.export_dialog import ExportDialog, default_export_path
from lenslab.gui.properties import PropertyEditor
from lenslab.gui.scene_tree import SceneTreeView, node_context_menu
from lenslab.gui.snapshot_panel import StudioSnapshots
from lenslab.gui.viewing_aids import ViewingAids
from lenslab.gui.viewport import Viewport
from lenslab.gui.widgets import ResetSlider, SignedNumberEdit
from lenslab.gui.worker import VIEWPORT_DISPATCH_SECONDS
from lenslab.color import luminance
from lenslab.messages import one_line
from lenslab.optics import format_camera_settings, format_distance
from lenslab.optics.exposure import format_shutter
from lenslab.render.film import TONE_MAPS
from lenslab.scene import editing
from lenslab.scene.io.loader import open_scene, resolve_scene_path, scene_title, shipped_scene_names
from lenslab.scene.io.meshes import MESH_SUFFIXES, MeshLoadError, load_mesh
from lenslab.scene.io.native import SCENE_SUFFIX, save_scene
from lenslab.scene.scene import SceneError

DISPLAY_EXPOSURE_STOPS = 6.0  # the display exposure slider reaches this many stops either way

MAX_RECENT = 10
APP_NAME = "LensLab"


def studio_settings() -> QSettings:
    return QSettings(QSettings.IniFormat, QSettings.UserScope, "LensLab", "studio")


class MainWindow(QMainWindow):
    closed = Signal()
    mesh_imported = Signal(str)  # path, once its node is in the scene
    mesh_import_failed = Signal(str, str)  # path, reason
    _mesh_loaded = Signal(object, object, str)  # from the loading thread

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
        self.export_id: int | None = None
        self.export_progress_dialog: QProgressDialog | None = None
        self.last_export_path: Path | None = None
        self._unsaved_box: QMessageBox | None = None
        self._structure_generation = 0
        self._closing = False
        self._hover: tuple[int, int] | None = None
        self._pending_imports = 0
        self._mesh_loaded.connect(self._on_mesh_loaded, Qt.QueuedConnection)

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
        self._create_actions()
        self.setCentralWidget(self._central())
        self._create_docks()
        self._create_menus()
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
        action = QAction(text, self)
        if shortcut is not None:
            if isinstance(shortcut, (list, tuple)):
                action.setShortcuts([QKeySequence(s) for s in shortcut])
            else:
                action.setShortcut(QKeySequence(shortcut))
        if icon:
            action.setIcon(theme.icon(icon))
        action.setCheckable(checkable)
        if tip:
            action.setStatusTip(tip)
            action.setToolTip(f"{tip} ({action.shortcut().toString()})" if action.shortcut() else tip)
        if slot is not None:
            action.triggered.connect(slot)
        self.addAction(action)
        return action

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

    def _create_actions(self) -> None:
        a = self.make_action
        self.actions: dict[str, QAction] = {}
        act = self.actions
        act["new"] = a("&New", self.new_scene, QKeySequence.New)
        act["open"] = a("&Open…", self.open_dialog, QKeySequence.Open)
        act["save"] = a("&Save", self.save, QKeySequence.Save)
        act["save_as"] = a("Save &As…", self.save_as, QKeySequence("Ctrl+Shift+S"))
        act["import_mesh"] = a("&Import Mesh…", self.import_dialog, "Ctrl+I", tip="Add a mesh file (OBJ, PLY, glTF, STL)")
        act["export"] = a("&Export Image…", self.export_dialog, "Ctrl+E", tip="Render to an EXR or PNG file")
        act["quit"] = a("&Quit", self.close, QKeySequence.Quit)
        undo = self.doc.undo_stack.createUndoAction(self, "&Undo")
        undo.setShortcuts([QKeySequence.Undo])
        redo = self.doc.undo_stack.createRedoAction(self, "&Redo")
        redo.setShortcuts([QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")])
        self.addAction(undo)
        self.addAction(redo)
        act["undo"], act["redo"] = undo, redo
        act["add_group"] = a("Group", lambda: self.add_primitive("group"), icon="group")
        act["add_sphere"] = a("Sphere", lambda: self.add_primitive("sphere"), icon="sphere")
        act["add_box"] = a("Box", lambda: self.add_primitive("box"), icon="box")
        act["add_cylinder"] = a("Cylinder", lambda: self.add_primitive("cylinder"), icon="cylinder")
        act["add_rectangle"] = a("Rectangle", lambda: self.add_primitive("rectangle"), icon="rectangle")
        act["add_light"] = a("Area Light", lambda: self.add_primitive("light"), icon="light")
        act["add_point_light"] = a("Point Light", lambda: self.add_light("point"), icon="light")
        act["add_spot_light"] = a("Spot Light", lambda: self.add_light("spot"), icon="light")
        act["add_sun"] = a("Sun", lambda: self.add_light("sun"), icon="light")
        act["new_material"] = a("New Material", self.new_material, icon="material")
        act["duplicate"] = a("&Duplicate", self.duplicate_selection, "Ctrl+D")
        act["rename"] = a("Re&name", self.rename_selection, "F2")
        act["delete"] = a("&Delete", self.delete_selection, QKeySequence.Delete, icon="delete")
        act["fit"] = a("&Fit in Window", self.viewport.fit, "Ctrl+0", icon="fit", tip="Fit the image in the window")
        act["actual"] = a("&Actual Pixels", lambda: self.viewport.set_zoom(1.0), "Ctrl+1", tip="100%")
        act["zoom_in"] = a("Zoom &In", lambda: self.viewport.zoom_step(1), [QKeySequence.ZoomIn, "Ctrl+="])
        act["zoom_out"] = a("Zoom &Out", lambda: self.viewport.zoom_step(-1), QKeySequence.ZoomOut)
        act["reset_layout"] = a("Reset Panel Layout", self.reset_layout)
        act["denoise"] = a("&Denoise Preview", self.set_denoise, "D", "denoise", True,
                           "Show the viewport through Intel Open Image Denoise (never applied to an export "
                           "unless the export asks)")
        act["denoise"].setChecked(self.controller.denoise)
        act["frame_selection"] = a("&Frame Selection", self.frame_selection, ".",
                                   tip="Point the camera at the selection, fill the frame with it and focus on it")
        act["frame_all"] = a("Frame &All", lambda: self.frame_selection(everything=True), "Home",
                             tip="Point the camera at the whole scene")
        act["clear_region"] = a("&Clear Render Region", lambda: self.controller.set_region(None), "Alt+R",
                                tip="Refine the whole picture again")
        tools = QActionGroup(self)
        for name, key, icon_name, tip in (("select", "Q", "select", "Select: click an object"),
                                          ("focus", "F", "focus", "Focus: click to focus there"),
                                          ("pan", "H", "pan", "Pan: drag the image"),
                                          ("region", "R", "region", "Render region: drag a rectangle to refine "
                                                                     "only that part of the picture")):
            action = a(name.capitalize(), lambda _c=False, n=name: self.set_tool(n), key, icon_name, True, tip)
            tools.addAction(action)
            act["tool_" + name] = action
        act["tool_select"].setChecked(True)
        act["open_up"] = a("Open Up ⅓ Stop", lambda: self.camera_panel.step_aperture(-1), "[")
        act["stop_down"] = a("Stop Down ⅓ Stop", lambda: self.camera_panel.step_aperture(+1), "]")
        act["focus_on_selection"] = a("Focus on Selection", self.focus_on_selection, "Shift+F")
        act["pause"] = a("&Pause Rendering", self.set_paused, "P", "pause", True, "Pause or resume the viewport render")
        act["restart"] = a("&Restart Rendering", self.controller.restart, "Ctrl+R", "restart", tip="Start accumulating afresh")
        act["shortcuts"] = a("Keyboard Shortcuts", self.show_shortcuts, QKeySequence.HelpContents)
        act["about"] = a("About LensLab", self.show_about)

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

    def _create_menus(self) -> None:
        act = self.actions
        bar = self.menuBar()
        file_menu = bar.addMenu("&File")
        file_menu.addAction(act["new"])
        file_menu.addAction(act["open"])
        self.shipped_menu = file_menu.addMenu("Open Example")
        for name in shipped_scene_names():
            self.shipped_menu.addAction(scene_title(name), lambda n=name: self.open_path(n))
        self.recent_menu = file_menu.addMenu("Open &Recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent_menu)
        file_menu.addSeparator()
        file_menu.addAction(act["save"])
        file_menu.addAction(act["save_as"])
        file_menu.addSeparator()
        file_menu.addAction(act["import_mesh"])
        file_menu.addAction(act["export"])
        file_menu.addSeparator()
        file_menu.addAction(act["quit"])

        edit = bar.addMenu("&Edit")
        edit.addAction(act["undo"])
        edit.addAction(act["redo"])
        edit.addSeparator()
        add = edit.addMenu("&Add")
        for name in ("add_group", "add_sphere", "add_box", "add_cylinder", "add_rectangle", "add_light",
                     "add_point_light", "add_spot_light", "add_sun"):
            add.addAction(act[name])
        add.addSeparator()
        add.addAction(act["import_mesh"])
        edit.addAction(act["new_material"])
        edit.addSeparator()
        edit.addAction(act["duplicate"])
        edit.addAction(act["rename"])
        edit.addAction(act["delete"])

        view = bar.addMenu("&View")
        for name in ("fit", "actual", "zoom_in", "zoom_out"):
            view.addAction(act[name])
        view.addSeparator()
        view.addAction(act["denoise"])
        view.addSeparator()
        for dock in self.docks.values():
            view.addAction(dock.toggleViewAction())
        view.addAction(act["reset_layout"])

        camera = bar.addMenu("&Camera")
        for name in ("tool_select", "tool_focus", "tool_pan"):
            camera.addAction(act[name])
        camera.addSeparator()
        camera.addAction(act["frame_selection"])
        camera.addAction(act["frame_all"])
        camera.addSeparator()
        camera.addAction(act["open_up"])
        camera.addAction(act["stop_down"])
        camera.addAction(act["focus_on_selection"])
        lens_menu = camera.addMenu("&Lens")
        self.lens_actions = []
        free = self.make_action("Free (no lens limits)", lambda: self.camera_panel.choose_lens(None), "Alt+0")
        lens_menu.addAction(free)
        lens_menu.addSeparator()
        for i, lens in enumerate(self.camera_panel.lenses):
            action = self.make_action(lens.name, lambda _c=False, lens=lens: self.camera_panel.choose_lens(lens),
                                      f"Alt+{i + 1}" if i < 9 else None)
            lens_menu.addAction(action)
            self.lens_actions.append(action)

        render = bar.addMenu("&Render")
        render.addAction(act["pause"])
        render.addAction(act["restart"])
        render.addSeparator()
        render.addAction(act["tool_region"])
        render.addAction(act["clear_region"])
        render.addSeparator()
        render.addAction(act["export"])

        help_menu = bar.addMenu("&Help")
        help_menu.addAction(act["shortcuts"])
        help_menu.addAction(act["about"])

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
        c.export_progress.connect(self._export_progress)
        c.export_finished.connect(self._export_finished)
        c.export_failed.connect(self._export_failed)
        c.export_cancelled.connect(self._export_cancelled)
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
        has_nodes = bool(self.doc.selected_node_paths())
        has_any = any(t[0] in ("node", "material") for t in self.doc.selection)
        self.actions["delete"].setEnabled(has_any)
        self.actions["duplicate"].setEnabled(has_nodes)
        self.actions["rename"].setEnabled(has_any)
        self.actions["focus_on_selection"].setEnabled(has_nodes)
        self.camera_panel.focus_selection_button.setEnabled(has_nodes)

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

    # -- files ---------------------------------------------------------------------------------------------------
    def maybe_save(self) -> bool:
        """True when it is fine to drop the current document (saved, discarded, or unchanged)."""
        if not self.doc.modified:
            return True
        box = QMessageBox(QMessageBox.Warning, "Unsaved changes",
                          f"Save the changes to “{self.doc.display_name}” before closing it?",
                          QMessageBox.Save | QMessageBox.Discard | QMessageBox.Cancel, self)
        box.setInformativeText("Your changes will be lost if you don't save them.")
        box.setDefaultButton(QMessageBox.Save)
        box.setObjectName("unsavedChangesBox")
        self._unsaved_box = box
        try:
            answer = box.exec()
        finally:
            self._unsaved_box = None
        if answer == QMessageBox.Save:
            return self.save()
        return answer == QMessageBox.Discard

    def new_scene(self) -> None:
        if self.maybe_save():
            self.doc.replace(studio_scene(), None)

    def open_dialog(self) -> None:
        if not self.maybe_save():
            return
        start = str(self.last_folder("scenes") or (self.doc.path.parent if self.doc.path else Path.home()))
        name, _ = QFileDialog.getOpenFileName(self, "Open scene", start, f"LensLab scenes (*{SCENE_SUFFIX});;All files (*)")
        if name:
            self.open_path(name, ask=False)

    def open_path(self, text: str | os.PathLike, ask: bool = True) -> bool:
        if ask and not self.maybe_save():
            return False
        try:
            path = resolve_scene_path(text)
            scene = open_scene(text)
        except (SceneError, OSError) as exc:
            QMessageBox.critical(self, "Cannot open scene", one_line(exc))
            return False
        self.doc.replace(scene, path)
        if not is_shipped(path):
            self._add_recent(path)
            self.remember_folder("scenes", path)
        self.statusBar().showMessage(f"Opened {path}", 4000)
        return True

    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        return self._write(self.doc.path)

    def save_as(self) -> bool:
        folder = self.last_folder("scenes") or Path.home()
        start = str(self.doc.path or (folder / f"{self.doc.display_name}{SCENE_SUFFIX}"))
        name, _ = QFileDialog.getSaveFileName(self, "Save scene", start, f"LensLab scenes (*{SCENE_SUFFIX})")
        if not name:
            return False
        path = Path(name)
        if path.suffix.lower() != SCENE_SUFFIX:
            path = path.with_suffix(SCENE_SUFFIX)
        return self._write(path)

    def _write(self, path: Path) -> bool:
        path = Path(path)
        # Relative file names (meshes, textures, the environment map) are rewritten for the new folder in the
        # copy that is written; the open scene takes them on only once the file is there, so a failed save
        # leaves it exactly as it was.
        file_paths = editing.rebased_file_paths(self.doc.model, path.resolve().parent)
        try:
            save_scene(editing.with_file_paths(self.doc.scene, file_paths), path)
        except OSError as exc:
            reason = exc.strerror or str(exc)  # the writer's own messages name the file already
            QMessageBox.critical(self, "Cannot save scene", reason if str(path) in reason else f"{path}: {reason}")
            return False
        self.doc.saved_as(path, file_paths)
        self._add_recent(path)
        self.remember_folder("scenes", path)
        self.statusBar().showMessage(f"Saved {path}", 4000)
        return True

    def last_folder(self, kind: str) -> Path | None:
        """The folder the last file of ``kind`` ("scenes": opened or saved; "meshes": imported; "images":
        exported) was in, remembered between runs, if it is still there."""
        value = self.settings.value(f"folders/{kind}")
        folder = Path(str(value)) if value else None
        return folder if folder is not None and folder.is_dir() else None

    def remember_folder(self, kind: str, file: str | os.PathLike) -> None:
        self.settings.setValue(f"folders/{kind}", str(Path(file).expanduser().resolve().parent))

    def recent_files(self) -> list[str]:
        value = self.settings.value("recent_files", [])
        if isinstance(value, str):
            value = [value]
        return [str(v) for v in (value or [])]

    def _add_recent(self, path: Path) -> None:
        text = str(Path(path).resolve())
        recent = [p for p in self.recent_files() if p != text]
        self.settings.setValue("recent_files", [text] + recent[: MAX_RECENT - 1])

    def _fill_recent_menu(self) -> None:
        menu = self.recent_menu
        menu.clear()
        recent = self.recent_files()
        for i, path in enumerate(recent):
            action = menu.addAction(f"&{(i + 1) % 10}  {Path(path).parent.name}/{Path(path).name}",
                                    lambda p=path: self.open_path(p))
            action.setToolTip(path)
            action.setEnabled(Path(path).exists())
        if recent:
            menu.addSeparator()
            menu.addAction("Clear List", lambda: self.settings.setValue("recent_files", []))
        else:
            menu.addAction("No recent scenes").setEnabled(False)

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

    def import_dialog(self) -> None:
        self._warm_up_mesh_library()
        start = str(self.last_folder("meshes") or self.doc.scene.base_dir())
        pattern = "Meshes (" + " ".join("*" + s for s in MESH_SUFFIXES) + ");;All files (*)"
        names, _ = QFileDialog.getOpenFileNames(self, "Import mesh", start, pattern)
        if names:
            self.remember_folder("meshes", names[0])
        for name in names:
            self.import_mesh(Path(name))

    def import_mesh(self, path: Path) -> None:
        """Add a mesh file as a node. The file is read on a background thread (a large mesh, or the first use of
        the mesh library, takes seconds); the node appears, as one undo step, when it has been read."""
        path = Path(path).resolve()
        self._pending_imports += 1
        self.statusBar().showMessage(f"Reading {path.name}…")
        self.setCursor(Qt.BusyCursor)

        def load() -> None:
            try:
                mesh = load_mesh(path, True)
            except MeshLoadError as exc:
                self._mesh_loaded.emit(path, None, str(exc))
            except Exception as exc:  # a broken file can make trimesh raise anything
                self._mesh_loaded.emit(path, None, f"{path}: cannot read mesh ({exc})")
            else:
                self._mesh_loaded.emit(path, mesh, "")

        threading.Thread(target=load, name=f"load {path.name}", daemon=True).start()

    def _on_mesh_loaded(self, path: Path, mesh, error: str) -> None:
        self._pending_imports -= 1
        if self._pending_imports == 0:
            self.unsetCursor()
        if mesh is None:
            self.statusBar().clearMessage()
            self.mesh_import_failed.emit(str(path), error)
            if not self._closing:
                QMessageBox.critical(self, "Cannot import mesh", error)
            return
        node, scale = editing.mesh_node(self.doc.model, path, mesh.vertices, self.doc.path)
        parent = editing.insertion_parent(self.doc.model, self.doc.selected_node_paths())
        self.doc.push(AddNodeCommand(self.doc, node, parent, text=f"Import {path.name}"))
        note = f", scaled ×{scale:g} to fit the view" if scale != 1.0 else ""
        self.statusBar().showMessage(f"Imported {path.name}: {mesh.triangle_count:,} triangles{note}", 6000)
        self.mesh_imported.emit(str(path))

    def _warm_up_mesh_library(self) -> None:
        """Start importing the mesh library (trimesh, scipy: seconds the first time) while the user picks a file."""
        if not getattr(self, "_mesh_library_warming", False):
            self._mesh_library_warming = True
            threading.Thread(target=lambda: __import__("trimesh"), name="import trimesh", daemon=True).start()

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

    # -- export -----------------------------------------------------------------------------------------------------
    def export_dialog(self) -> None:
        if self.export_id is not None:
            return
        frame = self.controller.last_frame
        folder = self.last_folder("images")
        last = self.last_export_path or (folder / default_export_path(self.doc).name if folder else None)
        dialog = ExportDialog(self.doc, self.viewport.exposure, self.viewport.tone_map,
                              frame.samples_per_second if frame else None, last, self)
        if dialog.exec() == ExportDialog.Accepted:
            self.start_export(dialog.request())

    def start_export(self, request) -> int:
        self.last_export_path = Path(request.path)
        self.remember_folder("images", request.path)
        self.export_id = self.controller.start_export(request)
        w, h = request.scene.camera.resolution
        dialog = QProgressDialog(f"Rendering {w}×{h} to {Path(request.path).name}…", "Cancel", 0, 1000, self)
        dialog.setObjectName("exportProgress")
        dialog.setWindowTitle("Export")
        dialog.setWindowModality(Qt.WindowModal)
        dialog.setMinimumDuration(0)
        dialog.setAutoClose(False)
        dialog.setAutoReset(False)
        dialog.setValue(0)
        dialog.canceled.connect(self.cancel_export)
        self.export_progress_dialog = dialog
        dialog.show()
        return self.export_id

    def cancel_export(self) -> None:
        if self.export_id is not None:
            self.controller.cancel_export(self.export_id)

    def _export_progress(self, update) -> None:
        dialog = self.export_progress_dialog
        if dialog is None or update.request_id != self.export_id:
            return
        progress = update.progress
        dialog.setValue(round(progress.fraction * 1000))
        goal = f" / {progress.target_spp}" if progress.target_spp else ""
        limit = f" of {elapsed_text(progress.time_limit)}" if progress.time_limit else ""
        remaining = ""
        if 0.02 < progress.fraction < 1:
            remaining = f" · about {elapsed_text(progress.elapsed_seconds * (1 - progress.fraction) / progress.fraction)} left"
        dialog.setLabelText(f"{progress.samples_per_pixel}{goal} spp · {elapsed_text(progress.elapsed_seconds)}{limit}"
                            f"{remaining} · {rate_text(progress.samples_per_second)}")

    def _close_export_dialog(self) -> None:
        dialog = self.export_progress_dialog
        self.export_progress_dialog = None
        self.export_id = None
        if dialog is not None:
            dialog.canceled.disconnect(self.cancel_export)
            dialog.close()
            dialog.deleteLater()

    def _export_finished(self, request_id: int, path: str) -> None:
        if request_id != self.export_id:
            return
        self._close_export_dialog()
        self.statusBar().showMessage(f"Exported {path}", 8000)

    def _export_failed(self, request_id: int, message: str) -> None:
        if request_id != self.export_id:
            return
        self._close_export_dialog()
        if not self._closing:
            QMessageBox.critical(self, "Export failed", message)

    def _export_cancelled(self, request_id: int) -> None:
        if request_id != self.export_id:
            return
        self._close_export_dialog()
        self.statusBar().showMessage("Export cancelled: nothing was written", 5000)

    # -- drag and drop ---------------------------------------------------------------------------------------------
    @staticmethod
    def _dropped_paths(event) -> list[Path]:
        if not event.mimeData().hasUrls():
            return []
        return [Path(u.toLocalFile()) for u in event.mimeData().urls() if u.isLocalFile()]

    def dragEnterEvent(self, event) -> None:
        paths = self._dropped_paths(event)
        if any(p.suffix.lower() in MESH_SUFFIXES for p in paths):
            self._warm_up_mesh_library()
        if any(p.suffix.lower() in MESH_SUFFIXES or p.suffix.lower() == SCENE_SUFFIX or p.is_dir() for p in paths):
            event.acceptProposedAction()

    def dropEvent(self, event) -> None:
        paths = self._dropped_paths(event)
        meshes = [p for p in paths if p.suffix.lower() in MESH_SUFFIXES]
        scenes = [p for p in paths if p.suffix.lower() == SCENE_SUFFIX or p.is_dir()]
        event.acceptProposedAction()
        if meshes:
            for p in meshes:
                self.import_mesh(p)
        elif scenes:
            QTimer.singleShot(0, lambda: self.open_path(scenes[0]))

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
        self._closing = True
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
