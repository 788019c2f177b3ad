"""The property editor shows and edits the materials a material holds (a light's surface, a blend's two) and
the textures it holds, each edit one undo step."""

from __future__ import annotations

import copy

from tests.gui.helpers import wait_for_frame


def test_a_lights_surface_is_chosen_and_edited_in_the_property_editor(qtbot, window):
    doc = window.doc
    wait_for_frame(qtbot, window)
    before = copy.deepcopy(doc.scene)
    doc.set_selection([("material", "light")])
    editors = window.properties._editors
    surface_type = editors[("surface", "__type__")].widget
    assert surface_type.currentData() is None  # a light reflects nothing by default
    surface_type.setCurrentIndex(surface_type.findData("diffuse"))
    assert doc.scene.materials["light"].surface.type_name == "diffuse"
    # The form now holds the surface's own fields.
    albedo = window.properties._editors[("surface", "albedo")]
    albedo.widget.set_value((0.25, 0.5, 0.75))
    albedo.widget.edited.emit((0.25, 0.5, 0.75), False)
    assert doc.scene.materials["light"].surface.albedo == (0.25, 0.5, 0.75)
    assert doc.undo_stack.undoText().startswith("Set") or doc.undo_stack.count() >= 2
    # A texture slot of the surface offers the texture types and none.
    texture_type = window.properties._editors[("surface", "albedo_texture", "__type__")].widget
    assert texture_type.currentData() is None and texture_type.findData("checker") >= 0
    texture_type.setCurrentIndex(texture_type.findData("checker"))
    assert doc.scene.materials["light"].surface.albedo_texture.type_name == "checker"
    while doc.undo_stack.canUndo():
        doc.undo_stack.undo()
    assert doc.scene == before


def test_a_blend_shows_both_of_its_materials(qtbot, window):
    doc = window.doc
    doc.set_selection([("material", "white")])
    type_combo = window.properties._editors[("__type__",)].widget
    type_combo.setCurrentIndex(type_combo.findData("blend"))
    blend = doc.scene.materials["white"]
    assert blend.type_name == "blend"
    editors = window.properties._editors
    assert ("first", "__type__") in editors and ("second", "__type__") in editors
    second = editors[("second", "__type__")].widget
    second.setCurrentIndex(second.findData("dielectric"))
    assert doc.scene.materials["white"].second.type_name == "dielectric"
    assert ("second", "distribution") in window.properties._editors
    wait_for_frame(qtbot, window, generation=window.controller.generation)
