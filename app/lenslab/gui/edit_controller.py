"""The studio's edits of the scene's contents from the Edit menu, the toolbar and the outliner's context menu:
add an object, a light or a material, duplicate, delete and rename the selection; each one step of the undo
history."""

from __future__ import annotations

from PySide6.QtCore import QObject
from PySide6.QtWidgets import QMainWindow

from lenslab.gui.commands import (AddLightCommand, AddMaterialCommand, AddNodeCommand, RemoveLightsCommand,
                                  RemoveMaterialCommand, RemoveNodesCommand)
from lenslab.gui.document import Document
from lenslab.scene import editing


class EditController(QObject):
    """Edits of the window's document, as undo commands. Renaming starts the edit in the window's outliner
    (``scene_tree``, in its "scene" dock)."""

    def __init__(self, window: QMainWindow, doc: Document):
        super().__init__(window)
        self.window = window
        self.doc = doc

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
        scene_tree = self.window.scene_tree
        index = scene_tree.tree_model.index_of(self.doc.selection[0])
        if index.isValid():
            self.window.docks["scene"].show()
            scene_tree.setFocus()
            scene_tree.edit(index)


__all__ = ["EditController"]
