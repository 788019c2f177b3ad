"""The viewport's aids for judging a picture, wired into the main window: the sensor's gate with the composition
guides, the safe frame and the passepartout; the aspect-ratio presets; focus peaking; the histogram dock and the
clipping warnings; the loupe. Their menu entries and shortcuts, and the choices remembered in the window's
settings (``overlays/...``).

The main window makes one :class:`ViewingAids` once its docks, menus and toolbar exist, and it fits itself in:
its layers onto the viewport, the Histogram dock above the camera panel, its entries into the View menu (with
the zoom entries) and the Camera menu (Aspect Ratio), the aspect combo into the viewport's toolbar. Each aid
lives in a module of its own: ``framing_overlay``, ``aspect_presets``, ``peaking_layer``, ``clipping_layer``,
``histogram_panel``, ``loupe_layer``.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QObject, Qt
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import QDockWidget, QMenu, QToolBar

from lenslab.gui.aspect_presets import AspectPresets
from lenslab.gui.clipping_layer import ClippingLayer
from lenslab.gui.document import listen
from lenslab.gui.framing_overlay import DEFAULT_PASSEPARTOUT, PASSEPARTOUTS, FramingLayer
from lenslab.gui.histogram_panel import HistogramPanel
from lenslab.gui.layer_support import PictureWatch, gate_in_image
from lenslab.gui.loupe_layer import LOUPE_ZOOMS, LoupeLayer
from lenslab.gui.peaking_layer import DEFAULT_PEAKING_COLOUR, PEAKING_COLOURS, FocusPeakingLayer
from lenslab.optics.composition import GUIDE_NAMES, GUIDES
from lenslab.optics.peaking import PEAKING_SENSITIVITY

#: The shortcuts (free in the studio: Q, F, H are the tools, P pauses): G cycles the guides (Lightroom's O
#: cycles its crop overlays), K peaking, J clipping warnings (Lightroom's J), L the loupe.
SHORTCUTS = {"cycle_guides": "G", "peaking": "K", "clipping": "J", "loupe": "L"}


def _bool(value, default: bool) -> bool:
    if value is None:
        return default
    if isinstance(value, str):
        return value.lower() in ("1", "true", "yes", "on")
    return bool(value)


class ViewingAids(QObject):
    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.doc = window.doc
        self.viewport = window.viewport
        self.settings = window.settings
        self.watch = PictureWatch(self)
        self.framing = FramingLayer()
        self.peaking = FocusPeakingLayer(self.viewport, self.sharp_limits, self)
        self.clipping = ClippingLayer(self.viewport, self)
        self.loupe = LoupeLayer(self.viewport, self)
        # Under the gate's passepartout: peaking and clipping (dimmed outside the frame with the picture); the loupe
        # on top of everything.
        self.viewport.layers.extend([self.watch, self.peaking, self.clipping, self.framing, self.loupe])
        self.aspect = AspectPresets(self.doc, self)
        self.actions: dict[str, QAction] = {}
        self._create_actions()
        self.histogram_panel = HistogramPanel(self.viewport, self.actions["clipping"])
        for receiver in (self.peaking, self.clipping, self.histogram_panel):
            self.watch.changed.connect(receiver.changed)
        listen(self.doc.model.events.changed, self, self._scene_changed)
        self.framing.set_camera(self.doc.scene.camera)
        self._restore()
        self._install_dock()
        self._install_menus()
        self._install_toolbar()

    # -- fitting into the window -------------------------------------------------------------------------------
    def _install_dock(self) -> None:
        w = self.window
        self.dock = QDockWidget("Histogram", w)
        self.dock.setObjectName("histogramDock")  # restoreState finds it by this name
        self.dock.setWidget(self.histogram_panel)
        self.dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable |
                              QDockWidget.DockWidgetClosable)
        w.addDockWidget(Qt.RightDockWidgetArea, self.dock)
        if hasattr(w, "docks"):
            w.docks["histogram"] = self.dock
        self.default_layout()
        if "reset_layout" in getattr(w, "actions", {}):
            w.actions["reset_layout"].triggered.connect(self.default_layout)  # after the window's own reset

    def default_layout(self) -> None:
        """The histogram above the camera panel (and the panels tabbed with it), as in Lightroom."""
        w = self.window
        docks = getattr(w, "docks", {})
        self.dock.setFloating(False)
        self.dock.show()
        camera = docks.get("camera")
        if camera is None:
            return
        tabbed = [d for d in w.tabifiedDockWidgets(camera) if d is not self.dock]
        w.splitDockWidget(self.dock, camera, Qt.Vertical)  # takes the camera panel out of its tabs
        for other in tabbed:
            w.tabifyDockWidget(camera, other)
        camera.raise_()
        w.resizeDocks([self.dock, camera], [170, 700], Qt.Vertical)

    def _install_menus(self) -> None:
        view = self._menu("View")
        # With the zoom entries (and the comparison), before the panels.
        first_separator = next((x for x in view.actions() if x.isSeparator()), None)
        self.fill_view_menu(view, first_separator)
        toggle = self.dock.toggleViewAction()  # with the other panels' toggles, before Reset Panel Layout
        reset = getattr(self.window, "actions", {}).get("reset_layout")
        view.insertAction(reset if reset in view.actions() else None, toggle)
        camera = self._menu("Camera")
        camera.addSeparator()
        self.fill_camera_menu(camera)

    def _menu(self, title: str) -> QMenu:
        bar = self.window.menuBar()
        for action in bar.actions():
            if action.menu() is not None and action.text().replace("&", "") == title:
                return action.menu()
        return bar.addMenu(f"&{title}")

    def _install_toolbar(self) -> None:
        """The aspect combo on the viewport's toolbar, before the resolution combo (or at its end)."""
        bar = self.window.findChild(QToolBar, "viewportBar")
        if bar is None:
            return
        quality = getattr(self.window, "quality_combo", None)
        before = next((a for a in bar.actions() if quality is not None and bar.widgetForAction(a) is quality), None)
        if before is not None:
            bar.insertWidget(before, self.aspect.combo)
        else:
            bar.addWidget(self.aspect.combo)

    # -- what is sharp -----------------------------------------------------------------------------------------
    def sharp_limits(self) -> tuple[float, float, float] | None:
        """Near and far limits of acceptable sharpness from the lens (the depth buffer's reference), for the
        export's circle of confusion and the aperture's real area, as the camera panel's readout has them; and
        that circle of confusion in pixels of the viewport's picture (its frame spans the imaged area)."""
        cam = self.doc.scene.camera
        if cam.pinhole:
            return 0.0, math.inf, 0.0
        panel = getattr(self.window, "camera_panel", None)
        light = panel.light_fraction() if panel is not None else 1.0
        try:
            dof = cam.depth_of_field(*cam.resolution, light, reference="lens")
        except ValueError:  # nearer than the lens focuses: nothing is sharp to show
            return None
        coc_px = cam.coc_mm() * gate_in_image(self.viewport).width() / cam.imaged_area_mm()[0]
        return dof.near_m, dof.far_m, coc_px

    # -- actions and menus -------------------------------------------------------------------------------------
    def _action(self, key: str, text: str, slot, checkable: bool = False, shortcut: str | None = None,
                tip: str | None = None) -> QAction:
        action = QAction(text, self.window)
        action.setCheckable(checkable)
        if shortcut:
            action.setShortcut(QKeySequence(shortcut))
        if tip:
            action.setStatusTip(tip)
            action.setToolTip(f"{tip} ({shortcut})" if shortcut else tip)
        action.triggered.connect(slot)
        self.window.addAction(action)  # its shortcut works with the menu bar hidden too
        self.actions[key] = action
        return action

    def _choices(self, key: str, items, slot) -> QActionGroup:
        group = QActionGroup(self)
        group.setExclusive(True)
        for value, text in items:
            action = self._action(f"{key}:{value}", text, lambda _c=False, v=value: slot(v), checkable=True)
            group.addAction(action)
        return group

    def _create_actions(self) -> None:
        self.guide_group = self._choices("guides", [(g, GUIDE_NAMES[g]) for g in GUIDES], self.set_guides)
        self._action("cycle_guides", "Next Guide", self.cycle_guides, shortcut=SHORTCUTS["cycle_guides"],
                     tip="Show the next composition guide: none, thirds, golden section, centre")
        self._action("safe_frame", "Safe Frame", self.set_safe_frame, checkable=True,
                     tip="Action safe (93 %) and title safe (90 %) areas, as SMPTE ST 2046-1 and EBU R 95")
        self.passepartout_group = self._choices(
            "passepartout", [(o, f"{name} ({round(o * 100)} %)" if o else name) for name, o in PASSEPARTOUTS],
            self.set_passepartout)
        self._action("peaking", "Focus Peaking", self.set_peaking, checkable=True, shortcut=SHORTCUTS["peaking"],
                     tip="Mark the edges that lie within the depth of field")
        self.peaking_colour_group = self._choices(
            "peaking_colour", [(c, c.capitalize()) for c in PEAKING_COLOURS], self.set_peaking_colour)
        self.peaking_sensitivity_group = self._choices(
            "peaking_sensitivity", [(s, s.capitalize()) for s in PEAKING_SENSITIVITY], self.set_peaking_sensitivity)
        self._action("clipping", "Clipping Warnings", self.set_clipping, checkable=True,
                     shortcut=SHORTCUTS["clipping"],
                     tip="Clipped highlights in red, crushed shadows in blue, as displayed")
        self._action("loupe", "Loupe", self.set_loupe, checkable=True, shortcut=SHORTCUTS["loupe"],
                     tip="A magnifier of the picture's pixels that follows the cursor")
        self.loupe_group = self._choices("loupe_zoom", [(z, f"{z}:1") for z in LOUPE_ZOOMS], self.set_loupe_zoom)

    def fill_view_menu(self, menu: QMenu, before: QAction | None = None) -> None:
        """The View menu's entries, put before ``before`` (or at the end)."""

        def add(item) -> None:
            if item is None:
                item = QAction(menu)
                item.setSeparator(True)
            menu.insertAction(before, item.menuAction() if isinstance(item, QMenu) else item)

        def submenu(title: str, key: str, values) -> QMenu:
            sub = QMenu(title, menu)
            for value in values:
                sub.addAction(self.actions[f"{key}:{value}"])
            add(sub)
            return sub

        add(None)
        guides = submenu("&Guides", "guides", GUIDES)
        guides.addSeparator()
        guides.addAction(self.actions["cycle_guides"])
        add(self.actions["safe_frame"])
        submenu("Passepartout", "passepartout", [o for _n, o in PASSEPARTOUTS])
        add(None)
        add(self.actions["peaking"])
        submenu("Peaking Colour", "peaking_colour", PEAKING_COLOURS)
        submenu("Peaking Sensitivity", "peaking_sensitivity", PEAKING_SENSITIVITY)
        add(self.actions["clipping"])
        add(self.actions["loupe"])
        submenu("Loupe Magnification", "loupe_zoom", LOUPE_ZOOMS)

    def fill_camera_menu(self, menu: QMenu) -> None:
        self.aspect.fill_menu(menu.addMenu("&Aspect Ratio"))

    # -- the choices ---------------------------------------------------------------------------------------------
    def _remember(self, key: str, value) -> None:
        self.settings.setValue(f"overlays/{key}", value)

    def set_guides(self, kind: str) -> None:
        self.framing.set_guides(kind)
        self.actions[f"guides:{kind}"].setChecked(True)
        self._remember("guides", kind)
        self.viewport.update()

    def cycle_guides(self) -> None:
        self.set_guides(GUIDES[(GUIDES.index(self.framing.guides) + 1) % len(GUIDES)])

    def set_safe_frame(self, on: bool) -> None:
        self.framing.safe_frame = bool(on)
        self.actions["safe_frame"].setChecked(bool(on))
        self._remember("safe_frame", bool(on))
        self.viewport.update()

    def set_passepartout(self, opacity: float) -> None:
        self.framing.passepartout = float(opacity)
        action = self.actions.get(f"passepartout:{opacity}")
        if action is not None:
            action.setChecked(True)
        self._remember("passepartout", float(opacity))
        self.viewport.update()

    def set_peaking(self, on: bool) -> None:
        self.actions["peaking"].setChecked(bool(on))
        self.peaking.set_visible(on)
        self._remember("peaking", bool(on))

    def set_peaking_colour(self, name: str) -> None:
        self.peaking.set_colour(name)
        self.actions[f"peaking_colour:{name}"].setChecked(True)
        self._remember("peaking_colour", name)

    def set_peaking_sensitivity(self, name: str) -> None:
        self.peaking.set_sensitivity(name)
        self.actions[f"peaking_sensitivity:{name}"].setChecked(True)
        self._remember("peaking_sensitivity", name)

    def set_clipping(self, on: bool) -> None:
        self.actions["clipping"].setChecked(bool(on))
        self.clipping.set_visible(on)
        self._remember("clipping", bool(on))

    def set_loupe(self, on: bool) -> None:
        self.actions["loupe"].setChecked(bool(on))
        self.loupe.set_visible(on)
        self._remember("loupe", bool(on))

    def set_loupe_zoom(self, zoom: int) -> None:
        self.loupe.set_zoom(int(zoom))
        self.actions[f"loupe_zoom:{int(zoom)}"].setChecked(True)
        self._remember("loupe_zoom", int(zoom))

    def _restore(self) -> None:
        """The choices of the last session; anything unknown (edited by hand, another version) is the default."""
        s = self.settings
        guides = str(s.value("overlays/guides", "none"))
        self.set_guides(guides if guides in GUIDES else "none")
        self.set_safe_frame(_bool(s.value("overlays/safe_frame"), False))
        try:
            opacity = float(s.value("overlays/passepartout", DEFAULT_PASSEPARTOUT))
        except (TypeError, ValueError):
            opacity = DEFAULT_PASSEPARTOUT
        offered = [o for _n, o in PASSEPARTOUTS]
        self.set_passepartout(min(offered, key=lambda o: abs(o - opacity)))
        colour = str(s.value("overlays/peaking_colour", DEFAULT_PEAKING_COLOUR))
        self.set_peaking_colour(colour if colour in PEAKING_COLOURS else DEFAULT_PEAKING_COLOUR)
        sensitivity = str(s.value("overlays/peaking_sensitivity", "medium"))
        self.set_peaking_sensitivity(sensitivity if sensitivity in PEAKING_SENSITIVITY else "medium")
        try:
            zoom = int(s.value("overlays/loupe_zoom", 2))
        except (TypeError, ValueError):
            zoom = 2
        self.set_loupe_zoom(zoom if zoom in LOUPE_ZOOMS else 2)
        self.set_peaking(_bool(s.value("overlays/peaking"), False))
        self.set_clipping(_bool(s.value("overlays/clipping"), False))
        self.set_loupe(_bool(s.value("overlays/loupe"), False))

    # -- the camera ------------------------------------------------------------------------------------------------
    def _scene_changed(self, change) -> None:
        if change.kind in ("camera", "scene"):  # the frame's label follows the picture (window.update_camera_tag)
            self.peaking.changed()
            self.viewport.update()
