"""The property editor: a form for whatever is selected, built from the scene's dataclass fields.

Nothing here lists a material's or a shape's parameters by hand. Each dataclass field becomes an editor chosen by
its type annotation (float, int, bool, str with ``choices``, fixed-length tuples, colours, nested dataclasses,
and the polymorphic shape / material / environment slots, which get a type selector) and limited by its
``metadata["range"]``; ``metadata["doc"]`` becomes the tooltip. A material type added to ``MATERIAL_TYPES`` later
appears here with its own fields without a change to this file. Every edit is an undo command.
"""

from __future__ import annotations

import dataclasses
import math
import typing
from pathlib import Path
from typing import Any, Callable

from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from lenslab.gui import theme
from lenslab.gui.commands import AddMaterialCommand, RenameMaterialCommand
from lenslab.gui.document import listen
from lenslab.gui.panel_form import PanelForm
from lenslab.gui.panel_scroll import PanelScroll
from lenslab.gui.wheel_guard import guard_wheels
from lenslab.gui.widgets import ColorEdit, IntEdit, NumberEdit, Section, VectorEdit, hint
from lenslab.scene.editing import file_reference, screen_drag_rate
from lenslab.scene.fields import control_bounds, range_holding
from lenslab.scene.lights import LIGHT_TYPES, Light
from lenslab.scene.materials import MATERIAL_TYPES, Diffuse, Material
from lenslab.scene.textures import TEXTURE_TYPES, Texture
from lenslab.scene.io.meshes import MESH_SUFFIXES
from lenslab.scene.scene import ENVIRONMENT_TYPES, Environment, Node
from lenslab.scene.shapes import SHAPE_TYPES, Box, Cylinder, Disk, Rectangle, Relief, Shape, Sphere

#: Polymorphic slots: the base class picks the registry of concrete types to choose from.
TAGGED_TYPES: dict[type, dict[str, type]] = {Shape: SHAPE_TYPES, Material: MATERIAL_TYPES,
                                             Environment: ENVIRONMENT_TYPES, Light: LIGHT_TYPES,
                                             Texture: TEXTURE_TYPES}
#: What each kind of light is, under its name in the property editor.
LIGHT_SUBTITLES = {"point": "Point light: intensity in candela (or lumens), the same in every direction",
                   "spot": "Spot light: intensity in candela (or lumens) along its axis, fading to nothing at the "
                           "cutoff angle",
                   "sun": "Sun: parallel light from a direction, irradiance in lux"}

#: Fields whose RGB triple is a colour (the scene model's RGB alias is a plain tuple, so the name tells).
COLOUR_FIELDS = {"albedo", "radiance", "color", "colour", "reflectance", "transmittance", "specular", "tint",
                 "absorption", "base_color", "emission"}

#: Fields shown elsewhere or not editable as a value.
SKIP_FIELDS = {"children", "source_path"}

_UNITS = {"_mm": " (mm)", "_m": " (m)", "_deg": " (°)"}

#: Places (a node's translate, a light's position) that scrub at the speed of the picture: the object follows the
#: mouse on screen (``lenslab.scene.editing.screen_drag_rate``); shown to a tenth of a millimetre.
PLACE_FIELDS = {"node": ("transform", "translate"), "light": ("position",)}
PLACE_DECIMALS = 4


#: Field names that read badly when merely capitalised.
_NAMES = {"spp": "Samples per pixel", "max_depth": "Max path length", "rr_depth": "Russian roulette from",
          "filter_stddev": "Filter std. dev. (px)", "filter_weights": "Filter weights", "clamp": "Clamp radiance"}


def pretty(name: str) -> str:
    if name in _NAMES:
        return _NAMES[name]
    for suffix, unit in _UNITS.items():
        if name.endswith(suffix):
            return name[: -len(suffix)].replace("_", " ").capitalize() + unit
    return name.replace("_", " ").capitalize()


def tagged_base(annotation: Any) -> type | None:
    """The polymorphic base class of a field annotation (``Shape | None`` -> Shape), if it is one."""
    args = [a for a in typing.get_args(annotation) if a is not type(None)] or [annotation]
    for a in args:
        if isinstance(a, type) and a in TAGGED_TYPES:
            return a
    return None


def type_name_of(obj: Any) -> str:
    return getattr(obj, "type_name", "") or type(obj).__name__


def convert_type(old: Any, new_cls: type) -> Any:
    """A default instance of ``new_cls`` that keeps the values of same-named fields of ``old`` (and the first
    colour, so that a red diffuse becomes a red emitter)."""
    kwargs = {}
    if old is not None and dataclasses.is_dataclass(old):
        old_fields = {f.name: getattr(old, f.name) for f in dataclasses.fields(old)}
        new_fields = {f.name: f for f in dataclasses.fields(new_cls) if f.init}
        hints = typing.get_type_hints(new_cls)
        for name in new_fields:
            if name in old_fields and type(old_fields[name]) is type(getattr(new_cls(), name)):
                choices = new_fields[name].metadata.get("choices")
                if choices is None or old_fields[name] in choices:  # a map's unit "scale" is no constant sky's
                    kwargs[name] = old_fields[name]
        old_colour = next((v for k, v in old_fields.items() if k in COLOUR_FIELDS), None)
        new_colour = next((k for k in new_fields if k in COLOUR_FIELDS and k not in kwargs), None)
        if old_colour is not None and new_colour is not None and typing.get_origin(hints[new_colour]) is tuple:
            kwargs[new_colour] = tuple(old_colour)
        kwargs.update(_same_extent(old, new_cls))
    return new_cls(**kwargs)


def _same_extent(old: Any, new_cls: type) -> dict[str, Any]:
    """Size fields that keep a shape's extent when its type changes (a 0.3 m box becomes a 0.3 m sphere)."""
    half = {Sphere: lambda o: o.radius, Disk: lambda o: o.radius, Cylinder: lambda o: max(o.radius, o.height / 2),
            Box: lambda o: max(o.size) / 2,
            Rectangle: lambda o: max(o.size) / 2, Relief: lambda o: max(o.size) / 2}.get(type(old))
    if half is None:
        return {}
    r = float(half(old))
    if isinstance(old, (Rectangle, Relief)) and new_cls in (Rectangle, Relief):
        return {"size": tuple(old.size)}  # a floor becomes a relief of the same extent, and back
    return {Sphere: {"radius": r}, Disk: {"radius": r}, Cylinder: {"radius": r, "height": 2 * r},
            Box: {"size": (2 * r,) * 3}, Rectangle: {"size": (2 * r, 2 * r)}, Relief: {"size": (2 * r, 2 * r)}}.get(new_cls, {})


class FieldEditor:
    """One editor widget bound to a field path; ``refresh`` reads the value back from the document."""

    def __init__(self, widget: QWidget, setter: Callable[[Any], None]):
        self.widget = widget
        self.setter = setter

    def refresh(self, value: Any) -> None:
        self.setter(value)


class PropertyEditor(QWidget):
    """Shows and edits the first selected target of the document."""

    def __init__(self, doc, parent: QWidget | None = None):
        super().__init__(parent)
        self.doc = doc
        self.target: tuple | None = None
        self._signature = None
        self._editors: dict[tuple, FieldEditor] = {}
        # The height of the picture on screen, in pixels (the main window asks its viewport); a place scrubs by
        # what one such pixel spans at the object's depth. None: the camera's image at 100 %.
        self.picture_height: Callable[[], float] | None = None
        self.title = QLabel()
        self.title.setObjectName("bigReadout")
        self.title.setStyleSheet("font-size: 14px;")
        self.subtitle = hint("")
        self.scroll = PanelScroll()  # up and down only, as wide as the fields need
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 6, 8, 4)
        layout.addWidget(self.title)
        layout.addWidget(self.subtitle)
        layout.addWidget(self.scroll, 1)
        doc.selection_changed.connect(self.rebuild)
        listen(doc.model.events.changed, self, self._on_change)
        self.rebuild()

    # -- building --------------------------------------------------------------------------------------------
    def _current_target(self) -> tuple | None:
        return self.doc.selection[0] if self.doc.selection else None

    def _structure_signature(self, target) -> tuple:
        if target is None or not self.doc.model.exists(target):
            return (None,)
        obj = self.doc.model.resolve(target)
        extra = tuple(self.doc.scene.materials) if target[0] == "node" else ()
        return (target, _type_tree(obj), extra)

    def rebuild(self) -> None:
        target = self._current_target()
        self.target = target
        self._editors = {}
        self._signature = self._structure_signature(target)
        container = QWidget()
        layout = QVBoxLayout(container)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(2)
        if target is None or not self.doc.model.exists(target):
            self.title.setText("Nothing selected")
            self.subtitle.setText("Select something in the scene tree or click it in the viewport (Q: select tool).")
            layout.addStretch(1)
            self._set_container(container)
            return
        obj = self.doc.model.resolve(target)
        kind = target[0]
        if kind == "node":
            self.title.setText(obj.name)
            shape = type_name_of(obj.shape) if obj.shape is not None else "group"
            self.subtitle.setText(f"Node · {shape}" + (f" · {len(obj.children)} children" if obj.children else ""))
            self._build_node(layout, obj)
        elif kind == "material":
            self.title.setText(target[1])
            users = len(self.doc.model.material_users(target[1]))
            self.subtitle.setText(f"Material · {type_name_of(obj)} · used by {users} node{'s' * (users != 1)}")
            self._build_material(layout, obj)
        elif kind == "light":
            self.title.setText(obj.name)
            self.subtitle.setText(LIGHT_SUBTITLES.get(obj.type_name, ""))
            section = Section("Light")
            form = self._form()
            section.add(form)
            self._add_type_selector(form, target, (), obj, Light)
            self._add_fields(form, target, (), obj)
            layout.addWidget(section)
        else:
            self.title.setText({"camera": "Camera", "environment": "Environment", "render": "Render settings"}[kind])
            self.subtitle.setText({"camera": "Placement and film back; the photographic controls are in the Camera panel.",
                                   "environment": "Light arriving from far away, where rays leave the scene.",
                                   "render": "How the image is sampled, in the viewport and in exports. Samples per "
                                             "pixel is the export default; the viewport refines up to the toolbar's "
                                             "limit."}[kind])
            section = Section("Parameters")
            form = self._form()
            section.add(form)
            if kind == "environment":
                self._add_type_selector(form, target, (), obj, Environment)
            self._add_fields(form, target, (), obj)
            layout.addWidget(section)
        layout.addStretch(1)
        self._set_container(container)

    def _set_container(self, container: QWidget) -> None:
        # The old form may hold the very widget whose signal led here: delete it later, not now.
        old = self.scroll.takeWidget()
        if old is not None:
            old.hide()
            old.deleteLater()
        self.scroll.setWidget(container)
        guard_wheels(container)

    @staticmethod
    def _form() -> QFormLayout:
        return PanelForm()  # a narrow panel puts labels above their fields

    def _build_node(self, layout, node: Node) -> None:
        target = self.target
        section = Section("Object")
        form = self._form()
        name = QLineEdit(node.name)
        name.editingFinished.connect(lambda: self._commit(target, ("name",), name.text().strip() or node.name, False))
        self._editors[("name",)] = FieldEditor(name, lambda v: name.setText(v) if not name.hasFocus() else None)
        form.addRow("Name", name)
        # Material: a choice among the scene's materials, plus one click to give this node its own.
        row = QWidget()
        row_layout = QHBoxLayout(row)
        row_layout.setContentsMargins(0, 0, 0, 0)
        combo = QComboBox()
        combo.addItem("(default grey)", "")
        for mat_name, material in self.doc.scene.materials.items():
            combo.addItem(theme.swatch(_display_rgb(material)), mat_name, mat_name)

        def set_combo(value: str) -> None:
            combo.blockSignals(True)
            combo.setCurrentIndex(max(0, combo.findData(value)))
            combo.blockSignals(False)

        set_combo(node.material)
        combo.currentIndexChanged.connect(lambda _i: self._commit(target, ("material",), combo.currentData(), False))
        new_button = QToolButton()
        new_button.setIcon(theme.icon("add"))
        new_button.setToolTip("New material for this node")
        new_button.clicked.connect(self._new_material_for_node)
        row_layout.addWidget(combo, 1)
        row_layout.addWidget(new_button)
        self._editors[("material",)] = FieldEditor(row, set_combo)
        form.addRow("Material", row)
        section.add(form)
        layout.addWidget(section)

        transform = Section("Transform")
        tform = self._form()
        self._add_fields(tform, target, ("transform",), node.transform)
        transform.add(tform)
        transform.add(hint("Rotation in degrees about X, then Y, then Z. Drag a letter to scrub."))
        layout.addWidget(transform)

        shape = Section("Shape")
        sform = self._form()
        self._add_type_selector(sform, target, ("shape",), node.shape, Shape, allow_none=True)
        if node.shape is not None:
            self._add_fields(sform, target, ("shape",), node.shape)
        shape.add(sform)
        layout.addWidget(shape)

    def _build_material(self, layout, material) -> None:
        target = self.target
        section = Section("Material")
        form = self._form()
        name = QLineEdit(target[1])

        def rename() -> None:
            new = name.text().strip()
            old = self.target[1] if self.target else None
            if not new or old is None or new == old:
                name.setText(old or "")
                return
            if new in self.doc.scene.materials:
                name.setText(old)
                self.subtitle.setText(f"A material called '{new}' already exists.")
                return
            self.doc.push(RenameMaterialCommand(self.doc, old, new))

        name.editingFinished.connect(rename)
        form.addRow("Name", name)
        self._add_type_selector(form, target, (), material, Material)
        self._add_fields(form, target, (), material)
        section.add(form)
        layout.addWidget(section)
        doc = material.__doc__ or ""
        if doc and not doc.startswith(type(material).__name__ + "("):
            layout.addWidget(hint(" ".join(doc.replace("``", "").split())))

    # -- fields ------------------------------------------------------------------------------------------------
    def _add_type_selector(self, form, target, path, obj, base: type, allow_none: bool = False,
                           none_label: str = "none (group)") -> None:
        registry = TAGGED_TYPES[base]
        combo = QComboBox()
        if allow_none:
            combo.addItem(none_label, None)
        for type_name in registry:
            combo.addItem(type_name.capitalize(), type_name)

        def set_combo(value) -> None:
            combo.blockSignals(True)
            combo.setCurrentIndex(max(0, combo.findData(type_name_of(value) if value is not None else None)))
            combo.blockSignals(False)

        def changed(_index: int) -> None:
            chosen = combo.currentData()
            current = self.doc.model.get_value(target, path)
            if chosen is None:
                new = None
            else:
                new = convert_type(current, registry[chosen])
            self._commit(target, path, new, False, text=f"Change {pretty(path[-1]) if path else 'type'} to "
                                                          f"{chosen or 'none'}")

        set_combo(obj)
        combo.currentIndexChanged.connect(changed)
        self._editors[tuple(path) + ("__type__",)] = FieldEditor(combo, lambda v: None)
        form.addRow("Type", combo)

    def _add_fields(self, form: QFormLayout, target: tuple, prefix: tuple, obj: Any) -> None:
        hints = typing.get_type_hints(type(obj))
        for f in dataclasses.fields(obj):
            if not f.init or f.name in SKIP_FIELDS or (prefix == () and target[0] == "node"):
                continue
            path = tuple(prefix) + (f.name,)
            annotation = hints.get(f.name)
            value = getattr(obj, f.name)
            meta = dict(f.metadata)
            base = tagged_base(annotation)
            if base is not None:
                # A material or texture held by this one (a light's surface, a blend's two, a bump map's
                # texture): its own type choice and fields, indented under the field's name.
                self._add_held(form, target, path, annotation, value, base, meta)
                continue
            if dataclasses.is_dataclass(value) and base is None:
                sub = self._form()
                self._add_fields(sub, target, path, value)
                box = QWidget()
                box.setLayout(sub)
                form.addRow(QLabel(pretty(f.name)))
                form.addRow(box)
                continue
            editor = self._make_editor(target, path, annotation, value, meta)
            if editor is None:
                continue
            label = QLabel(pretty(f.name))
            if meta.get("doc"):
                label.setToolTip(meta["doc"])
                editor.widget.setToolTip(meta["doc"])
            form.addRow(label, editor.widget)
            self._editors[path] = editor

    def _add_held(self, form, target, path, annotation, value, base: type, meta: dict) -> None:
        sub = self._form()
        sub.setContentsMargins(12, 0, 0, 0)
        optional = type(None) in typing.get_args(annotation)
        self._add_type_selector(sub, target, path, value, base, allow_none=optional, none_label="none")
        if value is not None:
            self._add_fields(sub, target, path, value)
        label = QLabel(pretty(path[-1]))
        if meta.get("doc"):
            label.setToolTip(meta["doc"])
        box = QWidget()
        box.setLayout(sub)
        form.addRow(label)
        form.addRow(box)

    def _make_editor(self, target, path, annotation, value, meta) -> FieldEditor | None:
        # What the control offers (a field's "controls", else its "range"), widened to show a scene's value beyond
        # it as it is: a control limits what it offers, never what a scene holds.
        lo, hi = control_bounds(meta, (-1e6, 1e6))
        if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
            lo, hi = range_holding(lo, hi, value)
        origin = typing.get_origin(annotation)
        args = typing.get_args(annotation)
        commit = lambda v, merge=True: self._commit(target, path, v, merge)  # noqa: E731
        if annotation is bool:
            box = QCheckBox()
            box.setChecked(bool(value))
            box.toggled.connect(lambda on: commit(bool(on), False))
            return FieldEditor(box, lambda v: _quiet(box, box.setChecked, bool(v)))
        if annotation is float:
            spin = NumberEdit(lo, hi, step=_step_for(lo, hi))
            spin.set_quietly(value)
            spin.edited.connect(lambda v, merge: commit(float(v), merge))
            return FieldEditor(spin, spin.set_quietly)
        if annotation is int:
            spin = IntEdit(lo if lo > -1e6 else -(2**31), hi if hi < 1e6 else 2**31 - 1)
            spin.set_quietly(value)
            spin.edited.connect(lambda v, merge: commit(int(v), merge))
            return FieldEditor(spin, spin.set_quietly)
        if annotation is str:
            if "choices" in meta:
                combo = QComboBox()
                combo.addItems(list(meta["choices"]))
                combo.setCurrentText(value)
                combo.currentTextChanged.connect(lambda text: commit(text, False))
                return FieldEditor(combo, lambda v: _quiet(combo, combo.setCurrentText, v))
            if path[-1] == "file" and len(path) >= 2 and path[-2] == "shape":
                return self._file_editor(target, path, value)
            line = QLineEdit(value)
            line.editingFinished.connect(lambda: commit(line.text(), False) if line.text() != self.doc.model.get_value(target, path) else None)
            return FieldEditor(line, lambda v: line.setText(v) if not line.hasFocus() else None)
        if origin is tuple and args and all(a in (int, float) for a in args):
            n = len(args)
            integer = args[0] is int
            if n == 3 and not integer and path[-1] in COLOUR_FIELDS:
                colour = ColorEdit(max(lo, 0.0), hi)
                colour.set_value(value)
                colour.edited.connect(lambda v, merge: commit(tuple(float(c) for c in v), merge))
                return FieldEditor(colour, colour.set_value)
            labels = ("X", "Y", "Z") if n == 3 else (("W", "H") if n == 2 else tuple(str(i) for i in range(n)))
            colours = None if n != 3 else ("#e06c6c", "#7fc56b", "#6b9be0")
            step = 1.0 if path[-1] == "rotate_deg" else _step_for(lo, hi)
            place = PLACE_FIELDS.get(target[0]) == tuple(path)
            vec = VectorEdit(labels, lo, hi, integer=integer, step=None if integer else step, colours=colours,
                             decimals=PLACE_DECIMALS if place else None)
            if place:
                vec.set_scrub_rate(lambda: self.drag_rate(target))
            vec.set_value(value)
            nonzero = meta.get("nonzero", False)

            def vec_commit(v, merge, vec=vec):
                v = tuple(int(c) if integer else float(c) for c in v)
                if nonzero and any(c == 0 for c in v):
                    vec.set_value(self.doc.model.get_value(target, path))  # a zero scale would flatten the object
                    return
                commit(v, merge)

            vec.edited.connect(vec_commit)
            return FieldEditor(vec, vec.set_value)
        if tagged_base(annotation) is not None:
            return None  # handled by _add_type_selector + the nested fields
        label = QLabel(repr(value))
        return FieldEditor(label, lambda v: label.setText(repr(v)))

    def _file_editor(self, target, path, value) -> FieldEditor:
        row = QWidget()
        layout = QHBoxLayout(row)
        layout.setContentsMargins(0, 0, 0, 0)
        line = QLineEdit(value)
        browse = QToolButton()
        browse.setText("…")
        browse.setToolTip("Choose a mesh file")

        def choose() -> None:
            start = str(self.doc.scene.base_dir())
            pattern = "Meshes (" + " ".join("*" + s for s in MESH_SUFFIXES) + ")"
            name, _ = QFileDialog.getOpenFileName(self, "Mesh file", start, pattern)
            if name:
                self._commit(target, path, file_reference(Path(name), self.doc.path), False)

        line.editingFinished.connect(
            lambda: self._commit(target, path, line.text(), False) if line.text() != self.doc.model.get_value(target, path) else None)
        browse.clicked.connect(choose)
        layout.addWidget(line, 1)
        layout.addWidget(browse)
        return FieldEditor(row, lambda v: line.setText(v) if not line.hasFocus() else None)

    def drag_rate(self, target) -> float | None:
        """Metres (in the parent's units) per pixel of scrubbing the place of ``target``: see PLACE_FIELDS."""
        if target is None or not self.doc.model.exists(target):
            return None
        height = self.picture_height() if self.picture_height is not None else 0.0
        if not height or height <= 0:
            height = self.doc.scene.camera.resolution[1]
        return screen_drag_rate(self.doc.model, target, height)

    # -- editing and refreshing ----------------------------------------------------------------------------------
    def _commit(self, target, path, value, merge, text=None) -> None:
        if target is None or not self.doc.model.exists(target):
            return
        if path and self.doc.model.get_value(target, path) == value:
            return
        self.doc.set_value(target, path, value, text=text, merge=merge)

    def _new_material_for_node(self) -> None:
        if self.target is None or self.target[0] != "node":
            return
        node = self.doc.model.resolve(self.target)
        base = self.doc.scene.materials.get(node.material)
        material = convert_type(base, type(base)) if base is not None else Diffuse()
        name = self.doc.model.unique_material_name(f"{node.name} material")
        self.doc.push(AddMaterialCommand(self.doc, name, material, assign_to=[self.target[1]]))

    def _on_change(self, change) -> None:
        target = self._current_target()
        if target != self.target or self._structure_signature(target) != self._signature:
            self.rebuild()
            return
        if target is None or not self.doc.model.exists(target):
            return
        if change.kind in ("scene", "structure") or change.target == target:
            for path, editor in self._editors.items():
                if path and path[-1] == "__type__":
                    continue
                try:
                    editor.refresh(self.doc.model.get_value(target, path))
                except (AttributeError, KeyError):
                    self.rebuild()
                    return
            if target[0] in ("node", "light"):
                self.title.setText(self.doc.model.resolve(target).name)


def _type_tree(obj: Any) -> tuple:
    """The types of a dataclass and of everything it holds: the form's structure, rebuilt when it changes."""
    if not dataclasses.is_dataclass(obj):
        return (type(obj),)
    return (type(obj),) + tuple(_type_tree(getattr(obj, f.name)) for f in dataclasses.fields(obj))


def _quiet(widget, setter, value) -> None:
    widget.blockSignals(True)
    try:
        setter(value)
    finally:
        widget.blockSignals(False)


def _step_for(lo: float, hi: float) -> float:
    if hi <= 1.0:
        return 0.01
    if hi <= 400:
        return 0.05
    return 0.1


def _display_rgb(material) -> tuple:
    for f in dataclasses.fields(material):
        if f.name in COLOUR_FIELDS:
            rgb = getattr(material, f.name)
            peak = max(max(rgb), 1e-9)
            return tuple(c / peak for c in rgb) if peak > 1 else rgb
    return (0.5, 0.5, 0.5)


def display_rgb(material) -> tuple:
    return _display_rgb(material)


__all__ = ["PropertyEditor", "convert_type", "pretty", "display_rgb", "COLOUR_FIELDS", "TAGGED_TYPES", "math"]
