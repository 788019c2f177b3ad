"""The studio's main window: the viewport in the centre, the outliner and property editor on the left, the camera
panel on the right, the render status at the bottom; menus for files, editing, the view, the camera and the
render. The layout, the display settings (the view transform: :mod:`.display_view`) and the recent files are
remembered between runs (QSettings).

The window assembles the studio; its actions and menus are declared in :mod:`.actions`, its files handled by
:mod:`.file_controller`, its exports by :mod:`.export_flow` and its edits by :mod:`.edit_controller`; the viewport's
toolbar is :mod:`.viewport_toolbar`, what the pointer does over the picture :mod:`.viewport_tools`, and the render's
progress in the viewport and the status bar :mod:`.render_status`."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSettings, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (QDockWidget, QLabel, QMainWindow, QMenu, QMessageBox, QProgressDialog, QSizePolicy,
                               QUndoView, QVBoxLayout, QWidget)

from lenslab import __version__
from lenslab.gui.actions import build_menus, create_actions, make_action, selection_has_nodes, update_enabled
from lenslab.gui.camera_panel import CameraPanel
from lenslab.gui.controller import RenderController
from lenslab.gui.corner_tags import camera_tag
from lenslab.gui.defaults import studio_scene
from lenslab.gui.display_view import DisplayView, ViewMenus
from lenslab.gui.document import Document, is_shipped, listen
from lenslab.gui.edit_controller import EditController
from lenslab.gui.export_flow import ExportFlow
from lenslab.gui.file_controller import FileController
from lenslab.gui.log_panel import LogPanel, install_log_dock, show_dock
from lenslab.gui.navigation import CameraNavigator
from lenslab.gui.panel_scroll import PanelScroll
from lenslab.gui.properties import PropertyEditor
from lenslab.gui.render_status import RenderStatus
from lenslab.gui.scene_tree import SceneTreeView, node_context_menu
from lenslab.gui.snapshot_panel import StudioSnapshots
from lenslab.gui.viewing_aids import ViewingAids
from lenslab.gui.viewport import Viewport
from lenslab.gui.viewport_toolbar import ViewportToolbar, under_toolbar
from lenslab.gui.viewport_tools import ViewportTools
from lenslab.gui.warning_bar import WarningBar
from lenslab.gui.wheel_guard import guard_wheels
from lenslab.gui.worker import VIEWPORT_DISPATCH_SECONDS
from lenslab.scene.io.loader import scene_title

APP_NAME = "LensLab"
#: The window's size when it has none remembered, and the default widths of the left and right panels (the property
#: editor's rows and the camera panel whole, the toolbar above the picture in one row).
DEFAULT_SIZE = (1480, 920)
DEFAULT_DOCK_WIDTHS = (250, 330)


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
        self.files = FileController(self, self.doc, self.settings)
        self.files.mesh_imported.connect(self.mesh_imported)
        self.files.mesh_import_failed.connect(self.mesh_import_failed)
        self.export_flow = ExportFlow(self, self.controller, self.files)
        self.edits = EditController(self, self.doc)  # add, duplicate, delete, rename

        self.viewport = Viewport()
        # The view transform (OCIO's display, view, look, the display exposure and contrast) of the last session,
        # over the scene's working space; what it could not keep is said in the Log once the Log exists.
        self.display = DisplayView(self.settings, self.doc.scene.render.working_space, self)
        self.view_menus = ViewMenus(self.display, self)
        self.viewport.set_view(self.display.view)
        self.controller.set_display(self.display.view)
        self.display.changed.connect(self._view_changed)
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
        self._install_warnings()
        menus = build_menus(self.menuBar(), self.actions, {
            "examples": self.files.fill_examples_menu, "recent": self.files.fill_recent_menu,
            "panels": self._add_panel_toggles, "lenses": self._fill_lens_menu,
            "view_transform": self.view_menus.fill_window_menu})
        self.shipped_menu, self.recent_menu = menus["examples"], menus["recent"]
        self.render_status = RenderStatus(self, self.viewport, self.controller)  # the status bar's labels
        self._install_view_label()
        self._connect()
        self.snapshots = StudioSnapshots(self)  # its dock exists before the saved layout is restored
        self.docks["snapshots"].setWidget(PanelScroll(self.snapshots.panel))
        # The sensor's gate and guides, aspect presets, focus peaking, the histogram and clipping warnings, the loupe.
        self.viewing = ViewingAids(self)
        self.setAcceptDrops(True)
        self.setWindowIcon(app_icon())
        self.resize(*DEFAULT_SIZE)
        if restore_layout:
            self._restore_layout()
        self._update_title()
        self.update_camera_tag()
        self._update_actions()
        guard_wheels(self)  # every value control the window holds; the property editor guards its own rebuilds

    # -- construction ------------------------------------------------------------------------------------------
    def make_action(self, text: str, slot=None, shortcut=None, icon: str | None = None, checkable: bool = False,
                    tip: str | None = None) -> QAction:
        """A QAction added to the window, so its shortcut works wherever the focus is; the tip, shortcut
        appended, is its status tip and tooltip. The studio's panels make their actions with it too."""
        return make_action(self, text, slot, shortcut, icon, checkable, tip)

    def _central(self) -> QWidget:
        """The viewport between its toolbar (the tools and the display settings) and the readout under the cursor.
        The viewport and the readout are ``viewport.parentWidget()``, in a column; the toolbar is above it."""
        self.toolbar = ViewportToolbar(self.actions, self.viewport, self.controller, self.display, self.view_menus,
                                       self)
        # Its widgets, by the names the studio's panels and the tests know them by.
        t = self.toolbar
        self.exposure_slider, self.exposure_spin = t.exposure_slider, t.exposure_spin
        self.exposure_reset, self.view_button, self.quality_combo = t.exposure_reset, t.view_button, t.quality_combo
        self.tools = ViewportTools(self)  # hover readout, click to select, click to focus, render region
        self.readout = self.tools.readout
        central = QWidget()
        layout = QVBoxLayout(central)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.viewport, 1)
        layout.addWidget(self.readout)
        return under_toolbar(t.bar, central)

    def _create_docks(self) -> None:
        self.setDockOptions(QMainWindow.AnimatedDocks | QMainWindow.AllowTabbedDocks)
        self.scene_tree = SceneTreeView(self.doc)
        self.properties = PropertyEditor(self.doc)
        self.properties.picture_height = self.tools.frame_height_on_screen  # a scrubbed object follows the mouse
        self.camera_panel = CameraPanel(self.doc, self.actions["tool_focus"], settings=self.settings)
        self.camera_panel.stop_scale_changed.connect(self._name_stop_actions)
        self._name_stop_actions(self.camera_panel.scale_name)
        self.camera_panel.focus_selection_button.clicked.connect(self.focus_on_selection)
        camera_scroll = PanelScroll(self.camera_panel)
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

    def _install_warnings(self) -> None:
        """What opening a scene warned about: a bar above the picture, and the Log panel (View > Log) that keeps it."""
        self.warning_bar = WarningBar()
        layout = self.viewport.parentWidget().layout()
        layout.insertWidget(layout.indexOf(self.viewport), self.warning_bar)
        self.log_panel = LogPanel()
        self.docks["log"] = install_log_dock(self, self.log_panel)
        self.actions["reset_layout"].triggered.connect(self.docks["log"].hide)  # after the window's own reset
        self.warning_bar.log_requested.connect(lambda: show_dock(self.docks["log"]))
        self.files.scene_opened_with_warnings.connect(self.report_warnings)
        self.controller.render_warnings.connect(self.report_render_warnings)
        self._log_display_notes()

    def _default_dock_layout(self) -> None:
        for dock in self.docks.values():
            dock.setFloating(False)
            dock.show()
        self.splitDockWidget(self.docks["scene"], self.docks["properties"], Qt.Vertical)
        self.tabifyDockWidget(self.docks["camera"], self.docks["history"])
        self.docks["camera"].raise_()
        self._dock_sizes_due = True
        if self.isVisible():
            self._size_docks()

    def _size_docks(self) -> None:
        """The panels' default widths and heights. A window given them before it is shown shares its width out
        anew when it is, so a new window takes them in its first show (``showEvent``)."""
        self._dock_sizes_due = False
        self.resizeDocks([self.docks["scene"], self.docks["camera"]], list(DEFAULT_DOCK_WIDTHS), Qt.Horizontal)
        self.resizeDocks([self.docks["scene"], self.docks["properties"]], [300, 520], Qt.Vertical)

    def showEvent(self, event) -> None:
        super().showEvent(event)
        if self._dock_sizes_due:
            self._size_docks()

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

    def _connect(self) -> None:
        doc, c = self.doc, self.controller
        doc.file_changed.connect(self._update_title)
        doc.selection_changed.connect(self._selection_changed)
        listen(doc.model.events.changed, self, self._scene_changed)
        doc.undo_stack.indexChanged.connect(lambda _i: self._update_actions())
        status, tools = self.render_status, self.tools
        # A frame: the picture and the status first, then the zoom and the readout that read it.
        for slot in (status.show_frame, self.toolbar.frame_shown, tools.refresh_readout, self.camera_panel.show_frame):
            c.frame_ready.connect(slot)
        c.gbuffer_ready.connect(status.show_gbuffer)
        c.gbuffer_ready.connect(tools.refresh_focus_overlay)
        c.device_ready.connect(status.show_device)
        c.render_error.connect(status.show_error)
        v = self.viewport
        v.pixel_hovered.connect(tools.show_readout)
        v.node_clicked.connect(tools.node_clicked)
        v.focus_clicked.connect(tools.focus_clicked)
        v.focus_preview.connect(tools.focus_preview)
        v.resized.connect(self._viewport_resized)
        v.region_drawn.connect(tools.region_drawn)
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
        if state is not None and self.restoreState(state):
            self._dock_sizes_due = False  # the panels as they were left

    def _save_layout(self) -> None:
        s = self.settings
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        self.display.save(s)
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

    def update_camera_tag(self) -> None:
        """The camera tag and the frame's label describe the picture shown, not the document's latest camera:
        until the new picture comes the work banner says one is on its way."""
        frame = self.controller.last_frame
        cam = frame.camera if frame is not None and frame.camera is not None else self.doc.scene.camera
        exposure = frame.exposure if frame is not None and frame.camera is cam else None
        self.viewport.hud_text = camera_tag(cam, exposure)  # as a snapshot's is written (the A/B comparison)
        self.viewing.framing.set_camera(cam)
        self.viewport.update()

    # -- document events ---------------------------------------------------------------------------------------
    def _scene_changed(self, change) -> None:
        if change.kind in ("structure", "scene"):
            self.tools.structure_generation = self.controller.generation
            self._selection_changed()
        if change.kind == "scene":
            self.viewport.fit()
            self.camera_panel.refresh()
        if change.kind == "camera":
            self.update_camera_tag()
            if change.field[:1] in (("focus_distance_m",), ("f_number",), ("sensor_mm",)) or change.field == ():
                self.tools.show_focus_overlay(self.doc.scene.camera.plane_of_focus_m)
        if change.kind == "scene":
            self.update_camera_tag()
        if change.kind == "scene" or (change.kind == "render" and change.field[:1] == ("working_space",)):
            if self.display.set_working_space(self.doc.scene.render.working_space) or self.display.notes:
                self._log_display_notes()
        self._update_actions()

    def _selection_changed(self) -> None:
        indices: list[int] = []
        for path in self.doc.selected_node_paths():
            indices.extend(self.doc.model.subtree_indices(path))
        self.viewport.set_selection(indices)
        self._update_actions()

    # -- the viewport's tools and display: the toolbar and the tools do them ------------------------------------
    def set_tool(self, tool: str) -> None:
        self.tools.set_tool(tool)

    def focus_on_selection(self) -> None:
        self.tools.focus_on_selection()

    def set_display_exposure(self, stops: float) -> None:
        self.toolbar.set_display_exposure(stops)

    def _view_changed(self, view) -> None:
        """A new view transform: the viewport shows it at once (from the radiance it has), the worker makes its
        pictures through it, and the status bar names it for a moment."""
        self.viewport.set_view(view)
        self.controller.set_display(view)
        self.statusBar().showMessage(f"View: {self.display.describe()}, exposure {view.exposure_stops:+.1f} EV, "
                                     f"contrast {view.contrast:.2f}", 4000)

    def _install_view_label(self) -> None:
        """The status bar names the display and view ("sRGB / ACES 2.0 SDR"; the toolbar's button the view alone),
        first of its permanent labels; it gives way before the window does."""
        self.view_label = QLabel()
        self.view_label.setObjectName("viewLabel")
        self.view_label.setSizePolicy(QSizePolicy.Preferred, QSizePolicy.Preferred)
        self.view_label.setMinimumWidth(1)  # not its text's: a narrow window cuts it rather than growing
        self.statusBar().insertPermanentWidget(0, self.view_label)
        self._show_view_label()
        self.display.changed.connect(self._show_view_label)

    def _show_view_label(self, *_args) -> None:
        text = self.display.short_text()
        self.view_label.setText(text)
        self.view_label.setToolTip(f"The view transform: {self.display.describe()} (View > Display, View Transform, "
                                   "Look)")

    def _log_display_notes(self) -> None:
        """What restoring the view transform, or the scene's working space, could not keep: in the Log."""
        notes, self.display.notes = self.display.notes, []
        if notes:
            self.log_panel.add("OpenColorIO", notes)

    # -- the viewport's picture: size, render region, denoiser, camera moves ----------------------------------------
    def _viewport_resized(self, width: int, height: int) -> None:
        self._viewport_size = (width, height)
        self._resize_timer.start()

    def _send_viewport_size(self) -> None:
        if self._viewport_size is not None:
            self.controller.set_widget_size(*self._viewport_size)

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
        self.render_status.set_paused(paused)

    # -- edits: the edit controller does them ------------------------------------------------------------------------
    def add_primitive(self, kind: str) -> None:
        self.edits.add_primitive(kind)

    def add_light(self, kind: str) -> None:
        self.edits.add_light(kind)

    def new_material(self) -> None:
        self.edits.new_material()

    def delete_selection(self) -> None:
        self.edits.delete_selection()

    def duplicate_selection(self) -> None:
        self.edits.duplicate_selection()

    def rename_selection(self) -> None:
        self.edits.rename_selection()

    # -- files and export: the file controller and the export flow do them -----------------------------------------
    def open_dialog(self) -> None:
        self.files.open_dialog()

    def save(self) -> bool:
        return self.files.save()

    def save_as(self) -> bool:
        return self.files.save_as()

    def import_dialog(self) -> None:
        self.files.import_dialog()

    def import_mesh(self, path: Path) -> None:
        self.files.import_mesh(path)

    def dragEnterEvent(self, event) -> None:
        self.files.drag_enter(event)

    def dropEvent(self, event) -> None:
        self.files.drop(event)

    def export_dialog(self) -> None:
        self.export_flow.open_dialog()

    def start_export(self, request) -> int:
        return self.export_flow.start(request)

    @property
    def export_id(self) -> int | None:
        return self.export_flow.export_id

    @property
    def export_progress_dialog(self) -> QProgressDialog | None:
        return self.export_flow.progress_dialog

    def report_warnings(self, source: str, lines: list[str]) -> None:
        """Show what opening ``source`` warned about; with nothing to say, the bar about the last scene goes."""
        self.warning_bar.show_warnings(source, lines)
        self.log_panel.add(source, lines)

    def report_render_warnings(self, lines: list[str]) -> None:
        """What rendering the scene found (a texture that is not there...): added to the bar and the Log."""
        source = str(self.doc.path or self.doc.scene.source_path or self.doc.display_name)
        # The reader may have said it already (a Mitsuba scene's missing texture): a line about a file the
        # scene's warnings named is not said twice.
        said = "\n".join(self.warning_bar.lines())
        lines = [line for line in lines if line.split(": ", 1)[0] not in said]
        self.warning_bar.add_warnings(source, lines)
        if lines:
            self.log_panel.add(source, lines)

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
        # An export running asks first: waiting for it closes later, when unsaved changes are asked about.
        if not self.export_flow.may_close() or not self.files.maybe_save():
            event.ignore()
            return
        self.files.closing = self.export_flow.closing = True  # a failure now is not worth a message box
        self._save_layout()
        if self.export_flow.running:
            self.export_flow.cancel()
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


__all__ = ["MainWindow", "studio_settings", "app_icon"]
