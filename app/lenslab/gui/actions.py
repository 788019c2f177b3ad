"""The main window's actions and menus, declared as data (as napari's app-model does): ``ACTIONS`` says what each
action is (text, shortcuts, icon, what it does, when it is enabled), ``MENU_BAR`` where it appears. The window
builds its QActions and its menu bar from the two tables; the studio's panels add their own actions (and menu
entries) with ``make_action`` afterwards."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from operator import attrgetter
from typing import Union

from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import QMenu, QMenuBar, QWidget

from lenslab.gui import theme

Shortcut = Union[str, QKeySequence, QKeySequence.StandardKey]
# What an action does: a method of the window, by its dotted name ("save", "viewport.fit"), looked up when the
# action is made and connected as it is (a checkable action's slot receives the new state); or a function of
# the window, called with it when the action is triggered.
Handler = Union[str, Callable[[QWidget], object]]


@dataclass(frozen=True)
class ActionSpec:
    id: str  # the key in the window's ``actions``
    text: str
    handler: Handler | None = None
    shortcut: Shortcut | tuple[Shortcut, ...] | None = None  # several: the first is the one menus show
    icon: str | None = None
    checkable: bool = False
    tip: str | None = None  # the status tip, and the tooltip with the shortcut appended
    enabled_when: Callable[[QWidget], bool] | None = None  # of the window's state, asked after each change
    checked_when: Callable[[QWidget], bool] | None = None  # the checked state the action starts in
    group: str | None = None  # checkable actions of one group are exclusive (a QActionGroup)
    create: Callable[[QWidget], QAction] | None = None  # a QAction made elsewhere (the undo stack's) in place of one


@dataclass(frozen=True)
class Submenu:
    title: str
    items: tuple = ()  # as a menu's items: action ids, SEPARATOR, Submenu, Section
    key: str | None = None  # the window keeps the menu by this key
    fill: str | None = None  # the window's filler of this name fills it once it is made
    fill_on_show: str | None = None  # ... or afresh each time it is about to show


@dataclass(frozen=True)
class Section:
    """Entries the window adds in this place (its panels' toggles, its lenses): its filler of this name."""
    fill: str


SEPARATOR = "-"


def selection_has_nodes(window) -> bool:
    return bool(window.doc.selected_node_paths())


def selection_has_nodes_or_materials(window) -> bool:
    return any(t[0] in ("node", "material") for t in window.doc.selection)


def _undo_action(window) -> QAction:
    return window.doc.undo_stack.createUndoAction(window, "&Undo")


def _redo_action(window) -> QAction:
    return window.doc.undo_stack.createRedoAction(window, "&Redo")


def _tool(name: str, key: str, tip: str) -> ActionSpec:
    return ActionSpec("tool_" + name, name.capitalize(), lambda w: w.set_tool(name), key, name, True, tip,
                      checked_when=(lambda _w: True) if name == "select" else None, group="tools")


ACTIONS: tuple[ActionSpec, ...] = (
    ActionSpec("new", "&New", "files.new_scene", QKeySequence.New),
    ActionSpec("open", "&Open…", "files.open_dialog", QKeySequence.Open),
    ActionSpec("save", "&Save", "files.save", QKeySequence.Save),
    ActionSpec("save_as", "Save &As…", "files.save_as", QKeySequence("Ctrl+Shift+S")),
    ActionSpec("import_mesh", "&Import Mesh…", "files.import_dialog", "Ctrl+I",
               tip="Add a mesh file (OBJ, PLY, glTF, STL)"),
    ActionSpec("export", "&Export Image…", "export_flow.open_dialog", "Ctrl+E", tip="Render to an EXR or PNG file"),
    ActionSpec("quit", "&Quit", "close", QKeySequence.Quit),
    ActionSpec("undo", "&Undo", shortcut=(QKeySequence.Undo,), create=_undo_action),
    ActionSpec("redo", "&Redo", shortcut=(QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")), create=_redo_action),
    ActionSpec("add_group", "Group", lambda w: w.add_primitive("group"), icon="group"),
    ActionSpec("add_sphere", "Sphere", lambda w: w.add_primitive("sphere"), icon="sphere"),
    ActionSpec("add_box", "Box", lambda w: w.add_primitive("box"), icon="box"),
    ActionSpec("add_cylinder", "Cylinder", lambda w: w.add_primitive("cylinder"), icon="cylinder"),
    ActionSpec("add_rectangle", "Rectangle", lambda w: w.add_primitive("rectangle"), icon="rectangle"),
    ActionSpec("add_light", "Area Light", lambda w: w.add_primitive("light"), icon="light"),
    ActionSpec("add_point_light", "Point Light", lambda w: w.add_light("point"), icon="light"),
    ActionSpec("add_spot_light", "Spot Light", lambda w: w.add_light("spot"), icon="light"),
    ActionSpec("add_sun", "Sun", lambda w: w.add_light("sun"), icon="light"),
    ActionSpec("new_material", "New Material", "new_material", icon="material"),
    ActionSpec("duplicate", "Du&plicate", "duplicate_selection", "Ctrl+D", enabled_when=selection_has_nodes),
    ActionSpec("rename", "Re&name", "rename_selection", "F2", enabled_when=selection_has_nodes_or_materials),
    ActionSpec("delete", "&Delete", "delete_selection", QKeySequence.Delete, icon="delete",
               enabled_when=selection_has_nodes_or_materials),
    ActionSpec("fit", "&Fit in Window", "viewport.fit", "Ctrl+0", icon="fit", tip="Fit the image in the window"),
    ActionSpec("actual", "&Actual Pixels", lambda w: w.viewport.set_zoom(1.0), "Ctrl+1", tip="100%"),
    ActionSpec("zoom_in", "Zoom &In", lambda w: w.viewport.zoom_step(1), (QKeySequence.ZoomIn, "Ctrl+=")),
    ActionSpec("zoom_out", "Zoom &Out", lambda w: w.viewport.zoom_step(-1), QKeySequence.ZoomOut),
    ActionSpec("reset_layout", "Reset Panel Layout", "reset_layout"),
    ActionSpec("denoise", "&Denoise Preview", "set_denoise", "D", "denoise", True,
               "Show the viewport through Intel Open Image Denoise (never applied to an export unless the export asks)",
               checked_when=lambda w: w.controller.denoise),
    ActionSpec("frame_selection", "&Frame Selection", "frame_selection", ".",
               tip="Point the camera at the selection, fill the frame with it and focus on it"),
    ActionSpec("frame_all", "F&rame All", lambda w: w.frame_selection(everything=True), "Home",
               tip="Point the camera at the whole scene"),
    ActionSpec("clear_region", "C&lear Render Region", lambda w: w.controller.set_region(None), "Alt+R",
               tip="Refine the whole picture again"),
    _tool("select", "Q", "Select: click an object"),
    _tool("focus", "F", "Focus: click to focus there"),
    _tool("pan", "H", "Pan: drag the image"),
    _tool("region", "R", "Render region: drag a rectangle to refine only that part of the picture"),
    # The camera panel names the stop: the window renames these two after its stop scale.
    ActionSpec("open_up", "Open Up ⅓ Stop", lambda w: w.camera_panel.step_aperture(-1), "["),
    ActionSpec("stop_down", "Stop Down ⅓ Stop", lambda w: w.camera_panel.step_aperture(+1), "]"),
    ActionSpec("focus_on_selection", "Focus on Selection", "focus_on_selection", "Shift+F",
               enabled_when=selection_has_nodes),
    ActionSpec("pause", "&Pause Rendering", "set_paused", "P", "pause", True, "Pause or resume the viewport render"),
    ActionSpec("restart", "&Restart Rendering", "controller.restart", "Ctrl+R", "restart",
               tip="Start accumulating afresh"),
    ActionSpec("shortcuts", "Keyboard Shortcuts", "show_shortcuts", QKeySequence.HelpContents),
    ActionSpec("about", "About LensLab", "show_about"),
)

#: Each key does one thing: no two actions share a shortcut, no shortcut is a menu's Alt+letter, and no two entries
#: of a menu share their letter (tests/gui/test_layout_holds.py walks them all).
MENU_BAR: tuple[Submenu, ...] = (
    Submenu("&File", ("new", "open", Submenu("Open Example", key="examples", fill="examples"),
                      Submenu("Open &Recent", key="recent", fill_on_show="recent"), SEPARATOR,
                      "save", "save_as", SEPARATOR, "import_mesh", "export", SEPARATOR, "quit")),
    Submenu("&Edit", ("undo", "redo", SEPARATOR,
                      Submenu("&Add", ("add_group", "add_sphere", "add_box", "add_cylinder", "add_rectangle",
                                       "add_light", "add_point_light", "add_spot_light", "add_sun", SEPARATOR,
                                       "import_mesh")),
                      "new_material", SEPARATOR, "duplicate", "rename", "delete")),
    Submenu("&View", ("fit", "actual", "zoom_in", "zoom_out", SEPARATOR, "denoise", SEPARATOR,
                      Section("view_transform"), SEPARATOR, Section("panels"), "reset_layout")),
    Submenu("&Camera", ("tool_select", "tool_focus", "tool_pan", SEPARATOR, "frame_selection", "frame_all",
                        SEPARATOR, "open_up", "stop_down", "focus_on_selection",
                        Submenu("&Lens", fill="lenses"))),
    # Alt+R is Clear Render Region's (as Alt+letter clears what the letter draws): the menu answers to Alt+N.
    Submenu("Re&nder", ("pause", "restart", SEPARATOR, "tool_region", "clear_region", SEPARATOR, "export")),
    Submenu("&Help", ("shortcuts", "about")),
)


def make_action(window: QWidget, text: str, slot=None, shortcut=None, icon: str | None = None,
                checkable: bool = False, tip: str | None = None, action: QAction | None = None) -> QAction:
    """A QAction added to the window, so its shortcut works wherever the focus is; the tip, shortcut
    appended, is its status tip and tooltip. The studio's panels make their actions with it too."""
    if action is None:
        action = QAction(text, window)
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
    window.addAction(action)
    return action


def _slot(window, handler: Handler | None):
    if handler is None or not isinstance(handler, str):
        return None if handler is None else (lambda *_args: handler(window))
    return attrgetter(handler)(window)


def create_actions(window, specs: tuple[ActionSpec, ...] = ACTIONS) -> dict[str, QAction]:
    """The window's actions, by id, made from the table (in its order)."""
    actions: dict[str, QAction] = {}
    groups: dict[str, QActionGroup] = {}
    for spec in specs:
        made = spec.create(window) if spec.create is not None else None
        action = make_action(window, spec.text, _slot(window, spec.handler), spec.shortcut, spec.icon,
                             spec.checkable, spec.tip, made)
        if spec.group is not None:
            if spec.group not in groups:
                groups[spec.group] = QActionGroup(window)
            groups[spec.group].addAction(action)
        actions[spec.id] = action
    for spec in specs:
        if spec.checked_when is not None:
            actions[spec.id].setChecked(bool(spec.checked_when(window)))
    return actions


def update_enabled(window, actions: dict[str, QAction], specs: tuple[ActionSpec, ...] = ACTIONS) -> None:
    """Enable each action whose table entry has a predicate by what that predicate says of the window now."""
    for spec in specs:
        if spec.enabled_when is not None:
            actions[spec.id].setEnabled(bool(spec.enabled_when(window)))


def build_menus(bar: QMenuBar, actions: dict[str, QAction], fillers: dict[str, Callable[[QMenu], None]],
                layout: tuple[Submenu, ...] = MENU_BAR) -> dict[str, QMenu]:
    """The menu bar, from the layout; returns the submenus that have a key, by it."""
    kept: dict[str, QMenu] = {}

    def fill(menu, items) -> None:
        for item in items:
            if item == SEPARATOR:
                menu.addSeparator()
            elif isinstance(item, Section):
                fillers[item.fill](menu)
            elif isinstance(item, Submenu):
                add(menu, item)
            else:
                menu.addAction(actions[item])

    def add(parent, spec: Submenu) -> None:
        menu = parent.addMenu(spec.title)
        fill(menu, spec.items)
        if spec.fill is not None:
            fillers[spec.fill](menu)
        if spec.fill_on_show is not None:
            menu.aboutToShow.connect(lambda: fillers[spec.fill_on_show](menu))
        if spec.key is not None:
            kept[spec.key] = menu

    for spec in layout:
        add(bar, spec)
    return kept


__all__ = ["ACTIONS", "MENU_BAR", "ActionSpec", "Section", "Submenu", "SEPARATOR", "build_menus", "create_actions",
           "make_action", "update_enabled", "selection_has_nodes", "selection_has_nodes_or_materials"]
