"""The outliner: a Qt item model over the scene (camera, environment, the node tree, materials, the lights, render
settings) and the tree view that shows it. Selecting here selects in the viewport and the property editor and
back; nodes can be renamed in place (F2 or double click) and dragged onto another node to parent them, keeping
where they are in the world, as in Blender's outliner.

Lights lists every light there is: point lights, spots and suns, and the objects that glow (area lights: a shape
with an emissive material, which live in the node tree), each of those an entry that stands for its object
(selecting or renaming it selects or renames the object; both its rows show it selected). A scene with no light at
all has no Lights group."""

from __future__ import annotations

import json

from PySide6.QtCore import QAbstractItemModel, QItemSelection, QItemSelectionModel, QMimeData, QModelIndex, Qt, Signal
from PySide6.QtGui import QColor, QFont
from PySide6.QtWidgets import QAbstractItemView, QMenu, QTreeView

from lenslab.gui import theme
from lenslab.gui.commands import MoveNodeCommand, RenameMaterialCommand
from lenslab.gui.document import listen
from lenslab.gui.properties import display_rgb
from lenslab.scene.editing import can_move, reparented_transform
from lenslab.scene.shapes import Box, Cylinder, MeshFile, Rectangle, Sphere

NODE_MIME = "application/x-lenslab-node-paths"

OBJECTS = ("objects",)
MATERIALS = ("materials",)
LIGHTS = ("lights",)  # point lights, spots and suns; and ("emitter", path): an object that glows, listed here too
EMITTER = "emitter"
LIGHT_KIND_NAMES = {"point": "point light", "spot": "spot light", "sun": "sun"}
GROUPS = {OBJECTS: "Objects", MATERIALS: "Materials", LIGHTS: "Lights"}
TARGET_KINDS = ("camera", "environment", "render", "material", "node", "light")  # rows that select something


class _Item:
    __slots__ = ("key", "parent", "children", "row")

    def __init__(self, key: tuple, parent: "_Item | None"):
        self.key = key
        self.parent = parent
        self.children: list[_Item] = []
        self.row = 0

    def add(self, key: tuple) -> "_Item":
        child = _Item(key, self)
        child.row = len(self.children)
        self.children.append(child)
        return child


class SceneTreeModel(QAbstractItemModel):
    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.doc = doc
        self._root = _Item(("root",), None)
        self._by_key: dict[tuple, _Item] = {}
        self._build()
        listen(doc.model.events.changed, self, self._on_change)

    # -- structure -------------------------------------------------------------------------------------------
    def _build(self) -> None:
        root = _Item(("root",), None)
        by_key: dict[tuple, _Item] = {}

        def add(parent: _Item, key: tuple) -> _Item:
            item = parent.add(key)
            by_key[key] = item
            return item

        add(root, ("camera",))
        add(root, ("environment",))
        objects = add(root, OBJECTS)

        def add_nodes(parent_item: _Item, nodes, prefix: tuple) -> None:
            for i, node in enumerate(nodes):
                item = add(parent_item, ("node", prefix + (i,)))
                add_nodes(item, node.children, prefix + (i,))

        add_nodes(objects, self.doc.scene.nodes, ())
        materials = add(root, MATERIALS)
        for name in self.doc.scene.materials:
            add(materials, ("material", name))
        emitters = self.emitter_paths()
        if emitters or self.doc.scene.lights:
            lights = add(root, LIGHTS)
            for i in range(len(self.doc.scene.lights)):
                add(lights, ("light", i))
            for path in emitters:
                add(lights, (EMITTER, path))
        self._emitters = emitters
        add(root, ("render",))
        self._root, self._by_key = root, by_key

    def emitter_paths(self) -> list[tuple]:
        """The objects that glow: a shape whose material emits (the area lights), in the tree's order."""
        materials = self.doc.scene.materials
        return [path for path, node in self.doc.model.walk_nodes()
                if node.shape is not None and getattr(materials.get(node.material), "emits", False)]

    def rebuild(self) -> None:
        self.beginResetModel()
        self._build()
        self.endResetModel()

    def _on_change(self, change) -> None:
        if change.kind in ("structure", "scene") or \
                (change.kind in ("node", "material") and self.emitter_paths() != self._emitters):
            self.rebuild()  # a node given a glowing material (or a material made to glow) joins the lights
        elif change.kind in ("node", "light"):
            for key in (change.target, (EMITTER,) + tuple(change.target[1:])):
                item = self._by_key.get(key)
                if item is not None:
                    index = self.createIndex(item.row, 0, item)
                    self.dataChanged.emit(index, index)
        elif change.kind == "material":
            # Swatches of the material and light icons of the nodes that use it.
            self.dataChanged.emit(self.index(0, 0), self.index(self.rowCount() - 1, 0))
            self._emit_all_changed(self._root)

    def _emit_all_changed(self, item: _Item) -> None:
        if item.children:
            first = self.createIndex(0, 0, item.children[0])
            last = self.createIndex(len(item.children) - 1, 0, item.children[-1])
            self.dataChanged.emit(first, last)
            for child in item.children:
                self._emit_all_changed(child)

    # -- Qt model interface --------------------------------------------------------------------------------
    def index(self, row: int, column: int, parent: QModelIndex = QModelIndex()) -> QModelIndex:
        item = parent.internalPointer() if parent.isValid() else self._root
        if column != 0 or not 0 <= row < len(item.children):
            return QModelIndex()
        return self.createIndex(row, 0, item.children[row])

    def parent(self, index: QModelIndex = QModelIndex()) -> QModelIndex:  # noqa: A003 (Qt's name)
        if not index.isValid():
            return QModelIndex()
        item = index.internalPointer()
        parent = item.parent
        if parent is None or parent is self._root:
            return QModelIndex()
        return self.createIndex(parent.row, 0, parent)

    def rowCount(self, parent: QModelIndex = QModelIndex()) -> int:
        if parent.isValid() and parent.column() != 0:
            return 0
        item = parent.internalPointer() if parent.isValid() else self._root
        return len(item.children)

    def columnCount(self, parent: QModelIndex = QModelIndex()) -> int:
        return 1

    def key(self, index: QModelIndex) -> tuple | None:
        return index.internalPointer().key if index.isValid() else None

    def index_of(self, key: tuple) -> QModelIndex:
        item = self._by_key.get(tuple(key))
        return self.createIndex(item.row, 0, item) if item is not None else QModelIndex()

    def data(self, index: QModelIndex, role: int = Qt.DisplayRole):
        if not index.isValid():
            return None
        key = index.internalPointer().key
        kind = key[0]
        if kind == EMITTER:
            return self._emitter_data(key, role)
        try:
            obj = self.doc.model.resolve(key) if kind in TARGET_KINDS else None
        except (KeyError, IndexError):
            return None
        group = key in GROUPS
        if role in (Qt.DisplayRole, Qt.EditRole):
            if kind in ("node", "light"):
                return obj.name
            if kind == "material":
                return key[1]
            if group:
                return GROUPS[key]
            return {"camera": "Camera", "environment": "Environment", "render": "Render settings"}[kind]
        if role == Qt.DecorationRole:
            if kind == "node":
                return theme.icon(self._node_icon(obj))
            if kind == "material":
                return theme.swatch(display_rgb(obj))
            if group:
                return theme.icon("folder")
            return theme.icon({"camera": "camera", "environment": "environment", "render": "render",
                               "light": "light"}[kind])
        if role == Qt.ToolTipRole:
            return self._tooltip(kind, key, obj)
        if role == Qt.ForegroundRole and group:
            return QColor(theme.DIM_TEXT)
        if role == Qt.FontRole and group:
            font = QFont()
            font.setBold(True)
            return font
        return None

    def _emitter_data(self, key: tuple, role: int):
        """A glowing object's entry under Lights: its name, the light icon, and what it is."""
        try:
            node = self.doc.model.node(key[1])
        except (KeyError, IndexError):
            return None
        if role in (Qt.DisplayRole, Qt.EditRole):
            return node.name
        if role == Qt.DecorationRole:
            return theme.icon("light")
        if role == Qt.ToolTipRole:
            shape = getattr(node.shape, "type_name", "shape")
            return (f"<b>{node.name}</b><br>area light: a {shape} with the emissive material {node.material}"
                    "<br>the object itself, listed under Objects")
        return None

    def _node_icon(self, node) -> str:
        material = self.doc.scene.materials.get(node.material)
        if material is not None and getattr(material, "emits", False):
            return "light"
        shape = node.shape
        if shape is None:
            return "group"
        return {Sphere: "sphere", Box: "box", Cylinder: "cylinder", Rectangle: "rectangle",
                MeshFile: "mesh"}.get(type(shape), "mesh")

    def _tooltip(self, kind, key, obj) -> str | None:
        if kind == "node":
            shape = getattr(obj.shape, "type_name", "group") if obj.shape is not None else "group"
            parts = [f"<b>{obj.name}</b>", shape]
            if isinstance(obj.shape, MeshFile):
                parts.append(obj.shape.file)
            parts.append(f"material: {obj.material or 'default grey'}")
            return "<br>".join(parts)
        if kind == "light":
            return f"<b>{obj.name}</b><br>{LIGHT_KIND_NAMES.get(obj.type_name, obj.type_name)}"
        if key == LIGHTS:
            return ("Every light: the objects that glow (area lights: objects with an emissive material, also "
                    "under Objects) and the point lights, spots and suns.")
        if kind == "material":
            users = len(self.doc.model.material_users(key[1]))
            return f"<b>{key[1]}</b><br>{obj.type_name} · used by {users} node{'s' * (users != 1)}"
        if kind == "camera":
            from lenslab.optics import format_camera_settings

            return (f"{format_camera_settings(obj.focal_length_mm, obj.f_number, obj.focus_distance_m)}"
                    f" · {obj.resolution[0]}×{obj.resolution[1]}")
        return None

    def flags(self, index: QModelIndex):
        if not index.isValid():
            return Qt.ItemIsDropEnabled
        key = index.internalPointer().key
        flags = Qt.ItemIsEnabled | Qt.ItemIsSelectable
        if key[0] == "node":
            flags |= Qt.ItemIsEditable | Qt.ItemIsDragEnabled | Qt.ItemIsDropEnabled
        elif key[0] in ("material", "light", EMITTER):
            flags |= Qt.ItemIsEditable
        elif key == OBJECTS:
            flags |= Qt.ItemIsDropEnabled
        return flags

    def setData(self, index: QModelIndex, value, role: int = Qt.EditRole) -> bool:
        if role != Qt.EditRole or not index.isValid():
            return False
        key = index.internalPointer().key
        text = str(value).strip()
        if not text:
            return False
        key = target_of(key)
        if key[0] in ("node", "light"):
            if text != self.doc.model.resolve(key).name:
                self.doc.set_value(key, ("name",), text, text=f"Rename to {text}")
            return True
        if key[0] == "material" and text != key[1]:
            if text in self.doc.scene.materials:
                return False
            self.doc.push(RenameMaterialCommand(self.doc, key[1], text))
            return True
        return False

    # -- drag and drop -----------------------------------------------------------------------------------------
    def supportedDropActions(self):
        return Qt.MoveAction

    def supportedDragActions(self):
        return Qt.MoveAction

    def mimeTypes(self) -> list[str]:
        return [NODE_MIME]

    def mimeData(self, indexes) -> QMimeData:
        paths = [list(self.key(i)[1]) for i in indexes if self.key(i) and self.key(i)[0] == "node"]
        data = QMimeData()
        data.setData(NODE_MIME, json.dumps(paths).encode())
        return data

    def canDropMimeData(self, data, action, row, column, parent) -> bool:
        if not data.hasFormat(NODE_MIME):
            return False
        key = self.key(parent)
        return key is None or key == OBJECTS or key[0] == "node"

    def dropMimeData(self, data, action, row, column, parent) -> bool:
        if not self.canDropMimeData(data, action, row, column, parent):
            return False
        paths = [tuple(p) for p in json.loads(bytes(data.data(NODE_MIME)).decode())]
        if len(paths) != 1:
            return False
        key = self.key(parent)
        dst_parent = key[1] if key is not None and key[0] == "node" else ()
        count = len(self.doc.model.children_of(dst_parent))
        index = count if row < 0 else min(row, count)
        move_node(self.doc, paths[0], dst_parent, index)
        return False  # we moved it ourselves; Qt must not remove the source row


def target_of(key: tuple) -> tuple:
    """What a row stands for: a glowing object's entry under Lights is the object."""
    return ("node",) + tuple(key[1:]) if key and key[0] == EMITTER else key


def move_node(doc, src: tuple, dst_parent: tuple, index: int) -> bool:
    """Re-parent ``src`` under ``dst_parent`` at ``index``, keeping its place in the world when possible."""
    if not can_move(src, dst_parent, index):
        return False
    transform = reparented_transform(doc.model, src, dst_parent)
    doc.push(MoveNodeCommand(doc, tuple(src), tuple(dst_parent), index, transform))
    return True


class SceneTreeView(QTreeView):
    """The outliner's view: keeps its selection and the document's in step."""

    context_menu_requested = Signal(object)  # QPoint global

    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.setObjectName("outliner")
        self.tree_model = SceneTreeModel(doc, self)
        self.setModel(self.tree_model)
        self.setHeaderHidden(True)
        self.setSelectionMode(QAbstractItemView.ExtendedSelection)
        self.setEditTriggers(QAbstractItemView.EditKeyPressed | QAbstractItemView.DoubleClicked)
        self.setDragDropMode(QAbstractItemView.InternalMove)
        self.setDragEnabled(True)
        self.setAcceptDrops(True)
        self.setDropIndicatorShown(True)
        self.setDefaultDropAction(Qt.MoveAction)
        self.setUniformRowHeights(True)
        self.setIndentation(14)
        self.setContextMenuPolicy(Qt.CustomContextMenu)
        self.customContextMenuRequested.connect(lambda pos: self.context_menu_requested.emit(self.viewport().mapToGlobal(pos)))
        self._syncing = False
        self._expanded: set[tuple] = {OBJECTS, MATERIALS, LIGHTS}
        self.expanded.connect(lambda i: self._expanded.add(self.tree_model.key(i)))
        self.collapsed.connect(lambda i: self._expanded.discard(self.tree_model.key(i)))
        self.tree_model.modelAboutToBeReset.connect(self._remember)
        self.tree_model.modelReset.connect(self._restore)
        self.selectionModel().selectionChanged.connect(self._selection_to_doc)
        doc.selection_changed.connect(self._selection_from_doc)
        self._restore()

    def _remember(self) -> None:
        pass  # expansion is tracked live through expanded/collapsed

    def _restore(self) -> None:
        self._syncing = True
        try:
            for key in list(self._expanded):
                index = self.tree_model.index_of(key)
                if index.isValid():
                    self.setExpanded(index, True)
            # Nodes are shown expanded down to the first level so that a fresh scene shows its objects.
            self.setExpanded(self.tree_model.index_of(OBJECTS), True)
            self.setExpanded(self.tree_model.index_of(MATERIALS), MATERIALS in self._expanded)
        finally:
            self._syncing = False
        self._selection_from_doc()

    def _selection_to_doc(self, _selected=None, deselected=None) -> None:
        if self._syncing:
            return
        # The row just clicked let go of (Ctrl-click) lets go of what it stands for, though its twin row (a glowing
        # object's other row) is still selected.
        current = self.selectionModel().currentIndex()
        dropped = {target_of(self.tree_model.key(current))} if deselected is not None and current.isValid() and \
            deselected.contains(current) else set()
        keys = [target_of(self.tree_model.key(i)) for i in self.selectionModel().selectedRows()]
        keys = [k for k in keys if k and k[0] in TARGET_KINDS and k not in dropped]
        self._syncing = True
        try:
            self.doc.set_selection(keys)
            self._match_twins(dropped)
        finally:
            self._syncing = False

    def _match_twins(self, dropped: set) -> None:
        """A glowing object has two rows, under Objects and under Lights: both show whether it is selected. Only
        the twins are touched (no clearing, no new current row), so a Shift-click's anchor stays where it was."""
        model, selection = self.tree_model, self.selectionModel()
        add, remove = QItemSelection(), QItemSelection()
        for path in model.emitter_paths():
            node = ("node", path)
            for key in (node, (EMITTER, path)):
                index = model.index_of(key)
                if not index.isValid():
                    continue
                if node in self.doc.selection and not selection.isSelected(index):
                    add.select(index, index)
                elif node in dropped and selection.isSelected(index):
                    remove.select(index, index)
        if not add.isEmpty():
            selection.select(add, QItemSelectionModel.Select | QItemSelectionModel.Rows)
        if not remove.isEmpty():
            selection.select(remove, QItemSelectionModel.Deselect | QItemSelectionModel.Rows)

    def _selection_from_doc(self) -> None:
        if self._syncing:
            return
        self._syncing = True
        try:
            selection = QItemSelection()
            first = None
            for key in self.doc.selection:
                index = self.tree_model.index_of(key)
                if index.isValid():
                    selection.select(index, index)
                    first = first or index
                    parent = index.parent()
                    while parent.isValid():
                        self.setExpanded(parent, True)
                        parent = parent.parent()
                if key[0] == "node":  # its entry under Lights too, if it glows
                    entry = self.tree_model.index_of((EMITTER,) + tuple(key[1:]))
                    if entry.isValid():
                        selection.select(entry, entry)
            self.selectionModel().select(selection, QItemSelectionModel.ClearAndSelect | QItemSelectionModel.Rows)
            if first is not None:
                self.selectionModel().setCurrentIndex(first, QItemSelectionModel.NoUpdate)
                self.scrollTo(first)
        finally:
            self._syncing = False

    def dropEvent(self, event) -> None:
        super().dropEvent(event)
        event.setDropAction(Qt.IgnoreAction)  # the model applied an undoable move; no row removal by Qt


def node_context_menu(parent, actions: dict) -> QMenu:
    menu = QMenu(parent)
    for name in ("add_group", "add_sphere", "add_box", "add_rectangle", "add_light", "add_point_light", "add_spot_light",
                 "add_sun",
                 "import_mesh", None,
                 "new_material", None, "focus_on_selection", "rename", "duplicate", "delete"):
        if name is None:
            menu.addSeparator()
        elif name in actions:
            menu.addAction(actions[name])
    return menu
