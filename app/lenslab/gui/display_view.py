"""The viewport's view transform as the studio chooses it: OpenColorIO's display, view and look (from the config in
``$OCIO``, else OCIO's built-in ACES config), the display exposure in stops and the contrast about middle grey,
over the open scene's working space. One :class:`~lenslab.colour_management.view.ViewTransform` carries all of it to
the viewport, the render worker, the snapshots and the export dialog; changing it never restarts the render.

:class:`DisplayView` holds the choice and says when it changes; :class:`ViewMenus` are its menus (Display, View,
Look), which the viewport's toolbar and the window's View menu both show. The choice is remembered between runs
(``viewport/display``, ``viewport/view``, ``viewport/look``, ``viewport/exposure``, ``viewport/contrast``); what an
earlier version stored as ``viewport/tone_map`` is read through the old names' aliases (``filmic``: the display's
default view, ``clamp``: its Un-tone-mapped view; ``reinhard``, which no view matches, and anything else unknown:
the default view). A display, view or look the config no longer has falls back to the config's default, with a line
for the log saying so (``DisplayView.notes``): never an error at start.
"""

from __future__ import annotations

import dataclasses
import math
import re

from PySide6.QtCore import QObject, QSettings, Qt, Signal
from PySide6.QtGui import QAction, QActionGroup
from PySide6.QtWidgets import QHBoxLayout, QLabel, QMenu, QToolButton, QWidget, QWidgetAction

from lenslab.colour_management.config import (BUILTIN_CONFIG, DEFAULT_SOURCE, ColourConfigError, config_name,
                                              load_config)
from lenslab.colour_management.view import CONTRAST_RANGE, VIEW_ALIASES, ViewTransform
from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE
from lenslab.gui.widgets import ResetSlider, SignedNumberEdit

DISPLAY_EXPOSURE_STOPS = 6.0  # the display exposure slider and field reach this many stops either way
#: The contrast control's reach (a factor about middle grey; OCIO takes 0.1 to 10, the useful part is near 1).
CONTRAST_LIMITS = (max(CONTRAST_RANGE[0], 0.25), min(CONTRAST_RANGE[1], 4.0))
NO_LOOK = ""


def _number(settings: QSettings, key: str, default: float, low: float, high: float) -> float:
    try:
        value = float(settings.value(key, default))
    except (TypeError, ValueError):
        return default
    return min(high, max(low, value)) if math.isfinite(value) else default


def short_display_name(display: str) -> str:
    """A display's name without the " - Display" the ACES configs add to every one: "sRGB", "Display P3"."""
    return display.removesuffix(" - Display").strip() or display


def short_view_name(view: str) -> str:
    """A view's name as a toolbar has room for it. The ACES configs name a view "family - kind peak (gamut)"
    ("ACES 2.0 - SDR 100 nits (Rec.709)"): that is "ACES 2.0 SDR", the peak and gamut left to the tooltip (the
    display says the gamut). Other names are kept as they are ("Un-tone-mapped", a studio's "Film (Kodak 2383)")."""
    if " - " not in view:
        return view
    short = re.sub(r"\s*\([^()]*\)\s*$", "", view)
    short = re.sub(r"\s*\d+\s*nits\b", "", short)
    return " ".join(short.replace(" - ", " ").split()) or view


def saved_view(settings: QSettings, working_space: str = DEFAULT_WORKING_SPACE,
               config: str = DEFAULT_SOURCE) -> tuple[ViewTransform, list[str]]:
    """The viewport's view transform from the last session, resolved in the config (its display and view named),
    and the lines to log about what could not be kept. An earlier version's ``viewport/tone_map`` is read through
    the old names' aliases; a value edited by hand or a name the config lacks falls back to the default."""
    notes: list[str] = []
    exposure = _number(settings, "viewport/exposure", 0.0, -DISPLAY_EXPOSURE_STOPS, DISPLAY_EXPOSURE_STOPS)
    contrast = _number(settings, "viewport/contrast", 1.0, *CONTRAST_LIMITS)
    try:
        ocio = load_config(config)
    except ColourConfigError as exc:
        notes.append(f"{exc}: the viewport uses OpenColorIO's built-in config ({config_name(BUILTIN_CONFIG)})")
        config = BUILTIN_CONFIG
        ocio = load_config(config)
    display = str(settings.value("viewport/display", "") or "")
    view = settings.value("viewport/view")
    if view is None:  # an earlier version's tone curve: its alias, and the default view for any other
        view = VIEW_ALIASES.get(str(settings.value("viewport/tone_map", "") or ""), "")
    view = VIEW_ALIASES.get(str(view), str(view))
    look = str(settings.value("viewport/look", "") or "")
    name = config_name(config)
    displays = list(ocio.getDisplays())
    if display and display not in displays:
        notes.append(f"the display '{display}' chosen last time is not in the OCIO config {name}: the viewport "
                     f"shows '{ocio.getDefaultDisplay()}'")
        display = ""
    display = display or ocio.getDefaultDisplay()
    views = list(ocio.getViews(display))
    if view and view not in views:
        notes.append(f"the view '{view}' chosen last time is not one of display '{display}''s in the OCIO config "
                     f"{name}: the viewport shows '{ocio.getDefaultView(display)}'")
        view = ""
    view = view or ocio.getDefaultView(display)
    if look and ocio.getLook(look) is None:
        notes.append(f"the look '{look}' chosen last time is not in the OCIO config {name}: no look")
        look = ""
    transform = ViewTransform(display=display, view=view, looks=look, exposure_stops=exposure, contrast=contrast,
                              working_space=working_space, config=config)
    try:
        return transform.resolved(), notes
    except ColourConfigError as exc:  # the config has no colour space for the working space: the built-in one has
        if config == BUILTIN_CONFIG:
            raise
        notes.append(f"{exc}: the viewport uses OpenColorIO's built-in config ({config_name(BUILTIN_CONFIG)})")
        built_in = ViewTransform(exposure_stops=exposure, contrast=contrast, working_space=working_space,
                                 config=BUILTIN_CONFIG)
        return built_in.resolved(), notes


class DisplayView(QObject):
    """The viewport's view transform, ``view`` (always resolved: its display and view named as the config names
    them), and its edits. ``changed`` carries each new one; ``notes`` are the lines the last restore or working
    space change had to say about names the config lacks (the window logs them)."""

    changed = Signal(object)  # ViewTransform

    def __init__(self, settings: QSettings, working_space: str = DEFAULT_WORKING_SPACE,
                 parent: QObject | None = None):
        super().__init__(parent)
        self.view, self.notes = saved_view(settings, working_space)

    # -- what the config offers ------------------------------------------------------------------------------------
    @property
    def config(self):
        return load_config(self.view.config)

    def displays(self) -> list[str]:
        return list(self.config.getDisplays())

    def views(self, display: str | None = None) -> list[str]:
        return list(self.config.getViews(display or self.view.display))

    def looks(self) -> list[str]:
        return [look.getName() for look in self.config.getLooks()]

    def describe(self) -> str:
        """``"sRGB - Display / ACES 2.0 - SDR 100 nits (Rec.709)"``, with a look after a ``+``."""
        return self.view.describe()

    def short_view_text(self) -> str:
        """The view as the toolbar's button names it: ``"ACES 2.0 SDR"``, ``"Un-tone-mapped + <look>"``."""
        text = short_view_name(self.view.view)
        return text + (f" + {self.view.looks}" if self.view.looks else "")

    def short_text(self) -> str:
        """What the toolbar's button says: ``"sRGB / ACES 2.0 SDR"`` (:func:`short_view_name`), with ``+`` and
        the look's name when there is one."""
        text = f"{short_display_name(self.view.display)} / {short_view_name(self.view.view)}"
        return text + (f" + {self.view.looks}" if self.view.looks else "")

    # -- edits -----------------------------------------------------------------------------------------------------
    def _set(self, **changes) -> bool:
        new = dataclasses.replace(self.view, _resolved=False, **changes).resolved()
        if new == self.view:
            return False
        self.view = new
        self.changed.emit(new)
        return True

    def set_display(self, display: str) -> bool:
        """Show on ``display``: the view keeps its name where the display has a view of that name, else the
        display's default view."""
        view = self.view.view if self.view.view in self.views(display) else ""
        return self._set(display=display, view=view)

    def set_view(self, view: str) -> bool:
        return self._set(view=view)

    def set_look(self, look: str) -> bool:
        return self._set(looks=look or NO_LOOK)

    def set_exposure(self, stops: float) -> bool:
        stops = min(DISPLAY_EXPOSURE_STOPS, max(-DISPLAY_EXPOSURE_STOPS, round(float(stops), 1)))
        return self._set(exposure_stops=stops)

    def set_contrast(self, contrast: float) -> bool:
        contrast = min(CONTRAST_LIMITS[1], max(CONTRAST_LIMITS[0], round(float(contrast), 2)))
        return self._set(contrast=contrast)

    def set_working_space(self, working_space: str) -> bool:
        """The open scene's working space (its pixels are in it); a config without it keeps the last one, and
        ``notes`` says why."""
        self.notes = []
        try:
            return self._set(working_space=working_space)
        except ColourConfigError as exc:
            self.notes = [str(exc)]
            return False

    def save(self, settings: QSettings) -> None:
        v = self.view
        settings.setValue("viewport/display", v.display)
        settings.setValue("viewport/view", v.view)
        settings.setValue("viewport/look", v.looks)
        settings.setValue("viewport/exposure", v.exposure_stops)
        settings.setValue("viewport/contrast", v.contrast)
        settings.remove("viewport/tone_map")  # read once, as the view it stood for


class ContrastControl(QWidget):
    """Contrast about middle grey: a label, a slider (a factor on a logarithmic scale), a field and a reset to 1."""

    def __init__(self, state: DisplayView, parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("contrastControl")
        self.state = state
        layout = QHBoxLayout(self)
        layout.setContentsMargins(28, 4, 8, 4)  # the label in line with the entries' text
        layout.setSpacing(4)
        label = QLabel("Contrast")
        self.slider = ResetSlider(Qt.Horizontal, default=0)
        lo, hi = CONTRAST_LIMITS
        self.slider.setRange(round(100 * math.log2(lo)), round(100 * math.log2(hi)))  # hundredths of a stop
        self.slider.setFixedWidth(110)
        self.slider.setToolTip("Contrast about middle grey (1 = as the view makes it); double-click: back to 1")
        self.field = SignedNumberEdit(lo, hi, 2, 0.05)
        self.field.setObjectName("displayContrast")
        self.field.textFromValue = lambda value: f"{value:.2f}"  # a factor, not a signed amount
        self.field.setFixedWidth(58)
        self.field.setToolTip("Contrast: a factor about middle grey (0.18), 1 as the view makes it")
        self.reset = QToolButton()
        self.reset.setText("\u21ba")  # ↺
        self.reset.setToolTip("Contrast back to 1")
        for widget in (label, self.slider, self.field, self.reset):
            layout.addWidget(widget)
        self.show_value()
        self.slider.valueChanged.connect(lambda v: state.set_contrast(2.0 ** (v / 100)))
        self.field.valueChanged.connect(state.set_contrast)
        self.reset.clicked.connect(lambda: state.set_contrast(1.0))
        state.changed.connect(self.show_value)

    def show_value(self, *_args) -> None:
        contrast = self.state.view.contrast
        for widget, value in ((self.slider, round(100 * math.log2(contrast))), (self.field, contrast)):
            widget.blockSignals(True)
            widget.setValue(value)
            widget.blockSignals(False)
        self.reset.setEnabled(contrast != 1.0)


class ContrastAction(QWidgetAction):
    """The contrast control as a menu entry: each menu that shows it gets a control of its own (a QWidgetAction's
    single default widget shows in one menu only), all of them following the one setting."""

    def __init__(self, state: DisplayView, parent: QObject):
        super().__init__(parent)
        self.state = state

    def createWidget(self, parent: QWidget) -> QWidget:
        return ContrastControl(self.state, parent)


class ViewMenus(QObject):
    """The Display, View and Look menus of the config (checkable, one choice each) and the contrast entry, shown in
    the toolbar's view button and the window's View menu alike. The View menu is filled again when the display
    changes: each display has its own views."""

    def __init__(self, state: DisplayView, parent: QObject):
        super().__init__(parent)
        self.state = state
        self.display_menu = QMenu("Di&splay")
        self.display_menu.setObjectName("displayMenu")
        self.view_menu = QMenu("View &Transform")
        self.view_menu.setObjectName("viewMenu")
        self.look_menu = QMenu("Loo&k")
        self.look_menu.setObjectName("lookMenu")
        self.contrast_action = ContrastAction(state, self)
        self.reset_action = QAction("Reset Exposure and Contrast", self)
        self.reset_action.setStatusTip("The display exposure back to 0 EV and the contrast to 1")
        self.reset_action.triggered.connect(self.reset_adjustment)
        self.display_actions: dict[str, QAction] = {}
        self.view_actions: dict[str, QAction] = {}
        self.look_actions: dict[str, QAction] = {}
        self._groups: dict[str, QActionGroup] = {}
        self.fill()
        state.changed.connect(self._changed)

    def reset_adjustment(self) -> None:
        self.state._set(exposure_stops=0.0, contrast=1.0)

    def fill(self) -> None:
        """Every menu from the config, its choices checked."""
        state = self.state
        self.display_actions = self._fill(self.display_menu, state.displays(), state.view.display,
                                          state.set_display)
        self._fill_views()
        looks = [(NO_LOOK, "None")] + [(name, name) for name in state.looks()]
        self.look_actions = self._fill(self.look_menu, looks, state.view.looks, state.set_look)

    def _fill_views(self) -> None:
        state = self.state
        default = state.config.getDefaultView(state.view.display)
        items = [(name, f"{name} (default)" if name == default else name) for name in state.views()]
        self.view_actions = self._fill(self.view_menu, items, state.view.view, state.set_view)

    def _fill(self, menu: QMenu, items, current: str, choose) -> dict[str, QAction]:
        menu.clear()
        old = self._groups.pop(menu.objectName(), None)
        if old is not None:
            old.deleteLater()
        group = self._groups[menu.objectName()] = QActionGroup(self)
        group.setExclusive(True)
        actions = {}
        for item in items:
            value, text = item if isinstance(item, tuple) else (item, item)
            action = QAction(text.replace("&", "&&"), menu)
            action.setCheckable(True)
            action.setChecked(value == current)
            action.triggered.connect(lambda _checked=False, v=value: choose(v))
            group.addAction(action)
            menu.addAction(action)
            actions[value] = action
        return actions

    def _changed(self, view: ViewTransform) -> None:
        if list(self.view_actions) != self.state.views():
            self._fill_views()  # another display: its views
        for actions, current in ((self.display_actions, view.display), (self.view_actions, view.view),
                                 (self.look_actions, view.looks)):
            for value, action in actions.items():
                action.setChecked(value == current)

    def fill_window_menu(self, menu: QMenu) -> None:
        """The window's View menu: Display, View Transform and Look, the contrast and the reset."""
        menu.addMenu(self.display_menu)
        menu.addMenu(self.view_menu)
        menu.addMenu(self.look_menu)
        menu.addAction(self.contrast_action)
        menu.addAction(self.reset_action)

    def fill_button_menu(self, menu: QMenu) -> None:
        """The toolbar button's menu: the views of the display at once (the choice made most), then the display,
        the look, the contrast and the reset."""
        menu.clear()
        title = menu.addSection("View")
        title.setObjectName("viewSection")
        for action in self.view_actions.values():
            menu.addAction(action)
        menu.addSeparator()
        menu.addMenu(self.display_menu)
        menu.addMenu(self.look_menu)
        menu.addSeparator()
        menu.addAction(self.contrast_action)
        menu.addAction(self.reset_action)


__all__ = ["DisplayView", "ViewMenus", "ContrastControl", "ContrastAction", "saved_view", "short_display_name",
           "short_view_name",
           "DISPLAY_EXPOSURE_STOPS", "CONTRAST_LIMITS"]
