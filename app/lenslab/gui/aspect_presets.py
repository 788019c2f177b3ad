"""The export frame's aspect ratio: the Camera > Aspect Ratio menu and the viewport toolbar's combo box.

Choosing a preset (:data:`lenslab.optics.aspect.ASPECT_PRESETS`) sets the camera's resolution to that shape,
keeping its long edge in pixels, as one undo step; the preset the resolution has is shown checked, and "Custom"
(with the shape's name) when it has none: the combo lists that entry only then, so it never offers "Custom (3:2)"
beside 3:2. A shape is a preset's when the preset gives it back, or when it is that preset's to the nearest pixel
as the frame's label names it (1919 × 1280 is 3:2 there too). Both follow the camera, whoever changes it."""

from __future__ import annotations

from PySide6.QtCore import QObject, Qt
from PySide6.QtGui import QAction, QActionGroup
from PySide6.QtWidgets import QComboBox, QMenu

from lenslab.gui.document import listen
from lenslab.optics.aspect import ASPECT_PRESETS, AspectPreset, aspect_name, matching_preset, resolution_for_aspect

TIP = "Set the export resolution to {name}, keeping the long edge ({long} px): {w} × {h}. {use}."


class AspectPresets(QObject):
    def __init__(self, doc, parent: QObject | None = None):
        super().__init__(parent)
        self.doc = doc
        self.group = QActionGroup(self)
        self.group.setExclusive(True)
        self.actions: dict[str, QAction] = {}
        for preset in ASPECT_PRESETS:
            action = QAction(preset.name, self)
            action.setCheckable(True)
            action.triggered.connect(lambda _c=False, p=preset: self.choose(p))
            self.group.addAction(action)
            self.actions[preset.name] = action
        self.custom_action = QAction("Custom", self)
        self.custom_action.setCheckable(True)
        self.custom_action.setEnabled(False)  # it says what the shape is; a shape of one's own is typed in Properties
        self.group.addAction(self.custom_action)
        self.combo = QComboBox()
        self.combo.setObjectName("aspectCombo")
        for preset in ASPECT_PRESETS:
            self.combo.addItem(preset.name, preset.name)
        self.combo.activated.connect(self._combo_chosen)
        listen(doc.model.events.changed, self, self._scene_changed)
        self.sync()

    def fill_menu(self, menu: QMenu) -> None:
        menu.setToolTipsVisible(True)
        for preset in ASPECT_PRESETS:
            menu.addAction(self.actions[preset.name])
        menu.addSeparator()
        menu.addAction(self.custom_action)

    def choose(self, preset: AspectPreset | str) -> None:
        """Give the camera ``preset``'s shape (one undo step; nothing when it has it already)."""
        if isinstance(preset, str):
            preset = next(p for p in ASPECT_PRESETS if p.name == preset)
        current = tuple(self.doc.scene.camera.resolution)
        new = resolution_for_aspect(current, preset)
        if new != current:
            self.doc.set_camera(f"Aspect ratio {preset.name} ({new[0]} × {new[1]})", resolution=new)
        self.sync()

    def _combo_chosen(self, index: int) -> None:
        name = self.combo.itemData(index)
        if name is None:
            self.sync()  # "Custom" names the shape: choosing it changes nothing
        else:
            self.choose(name)

    def _scene_changed(self, change) -> None:
        if change.kind == "scene" or (change.kind == "camera" and change.field[:1] in ((), ("resolution",))):
            self.sync()

    def sync(self) -> None:
        """Show the camera's shape: its preset checked, or Custom with its name."""
        w, h = self.doc.scene.camera.resolution
        name = aspect_name(w, h)
        preset = next((p for p in ASPECT_PRESETS if p.name == name), None) or matching_preset((w, h))
        custom = f"Custom ({name})"
        self.custom_action.setText(custom)
        self.custom_action.setVisible(preset is None)
        (self.actions[preset.name] if preset else self.custom_action).setChecked(True)
        for p in ASPECT_PRESETS:
            nw, nh = resolution_for_aspect((w, h), p)
            tip = TIP.format(name=p.name, long=max(w, h), w=nw, h=nh, use=p.use)
            self.actions[p.name].setToolTip(tip)
            self.actions[p.name].setStatusTip(tip)
            self.combo.setItemData(self.combo.findText(p.name), tip, Qt.ToolTipRole)
        custom_index = len(ASPECT_PRESETS)
        if preset is None and self.combo.count() == custom_index:
            self.combo.addItem(custom, None)
        elif preset is not None and self.combo.count() > custom_index:
            self.combo.removeItem(custom_index)
        if preset is None:
            self.combo.setItemText(custom_index, custom)
        self.combo.setCurrentIndex(ASPECT_PRESETS.index(preset) if preset else custom_index)
        self.combo.setToolTip(f"Aspect ratio of the export: {w} × {h} ({aspect_name(w, h)}). A preset keeps the "
                              "long edge.")
