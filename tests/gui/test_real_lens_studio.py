"""Real lenses in the studio (docs/lenses.md): mounted from the lens buttons in one undo step and taken off again by
Free or a thin-lens preset, the thin lens's stand-ins for glass stepping aside meanwhile, a side view of the glass
that follows the f-number and the focus, and a scene that names a real lens opening with it mounted.

The camera panel is built on its own document here (no render window: nothing here needs a picture)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

DOUBLE_GAUSS = "50 mm f/2 double-Gauss"
FISHEYE = "10 mm f/4 fisheye"


@pytest.fixture
def studio(qtbot, small_scene):
    from lenslab.gui.app import create_application
    from lenslab.gui.camera_panel import CameraPanel
    from lenslab.gui.document import Document

    create_application()
    doc = Document(small_scene)
    panel = CameraPanel(doc)
    qtbot.addWidget(panel)
    panel.resize(340, 1600)
    panel.show()
    yield panel
    doc.undo_stack.setClean()
    doc.silence()


def lens_named(panel, name):
    return next(lens for lens in panel.lenses if lens.name == name)


def button_of(panel, lens):
    return panel.lens_buttons[1 + panel.lenses.index(lens)]


def thin_only_controls(panel):
    return [panel.squeeze, panel.barrel, panel.aperture_image_button]


@pytest.mark.smoke
def test_mounting_the_double_gauss_from_its_button_is_one_undo_step_and_undo_takes_it_off(studio):
    panel, doc = studio, studio.doc
    lens = lens_named(panel, DOUBLE_GAUSS)
    button = button_of(panel, lens)
    assert "traced through its glass: 11 surfaces, 6 elements" in button.toolTip().lower()
    before, rows = dataclasses.replace(doc.scene.camera), doc.undo_stack.count()
    button.click()
    cam = doc.scene.camera
    assert cam.real_lens == DOUBLE_GAUSS and doc.lens == lens and button.isChecked()
    assert cam.focal_length_mm == pytest.approx(cam.lens_system().efl) and cam.focal_length_mm != 50.0
    assert cam.f_number >= 2.0 * (1 - 1e-9)
    cam.validate(doc.lens)  # a camera the renderer can draw
    assert doc.undo_stack.count() == rows + 1
    doc.undo_stack.undo()
    assert doc.scene.camera == before and doc.lens is None and panel.lens_buttons[0].isChecked()
    doc.undo_stack.redo()
    assert doc.scene.camera.real_lens == DOUBLE_GAUSS


@pytest.mark.smoke
def test_free_or_a_thin_lens_preset_takes_a_real_lens_off_and_the_thin_lens_controls_come_back(studio):
    panel, doc = studio, studio.doc
    for control in thin_only_controls(panel):
        assert control.isEnabled()
    for leave_by in (None, lens_named(panel, "85 mm f/1.4")):
        button_of(panel, lens_named(panel, DOUBLE_GAUSS)).click()
        for control in thin_only_controls(panel):
            assert not control.isEnabled()
            assert "traced through its glass" in control.toolTip()
        (panel.lens_buttons[0] if leave_by is None else button_of(panel, leave_by)).click()
        cam = doc.scene.camera
        assert cam.real_lens == "" and doc.lens == leave_by
        cam.validate(doc.lens)
        for control in thin_only_controls(panel):
            assert control.isEnabled()
            assert "traced through its glass" not in control.toolTip()


def test_changing_one_real_lens_for_another_never_leaves_a_camera_the_renderer_refuses(studio, monkeypatch):
    panel, doc = studio, studio.doc
    model = doc.model
    apply_value = model.apply_value

    def apply_and_check(target, field, value, notify=True):  # every value on its own must leave a valid camera
        apply_value(target, field, value, notify)
        model.scene.camera.validate()

    panel.choose_lens(lens_named(panel, DOUBLE_GAUSS))
    panel.set_f_number(2.0)
    monkeypatch.setattr(model, "apply_value", apply_and_check)
    panel.choose_lens(lens_named(panel, FISHEYE))  # f/2 is wider than the fisheye opens
    assert doc.scene.camera.real_lens == FISHEYE and doc.scene.camera.f_number == pytest.approx(4.0)
    doc.undo_stack.undo()  # back to the double-Gauss at f/2
    assert doc.scene.camera.real_lens == DOUBLE_GAUSS and doc.scene.camera.f_number == pytest.approx(2.0)
    panel.choose_lens(None)
    doc.undo_stack.undo()
    assert doc.scene.camera.real_lens == DOUBLE_GAUSS


@pytest.mark.smoke
def test_the_side_view_shows_a_real_lens_and_its_stop_closes_as_the_f_number_grows(studio):
    panel = studio
    diagram = panel.lens_diagram
    assert diagram.isHidden() and panel.lens_diagram_info.isHidden()
    panel.choose_lens(lens_named(panel, DOUBLE_GAUSS))
    assert not diagram.isHidden()
    panel.set_f_number(2.0)
    wide = diagram.stop_opening_mm()
    assert "EFL 50.4 mm" in panel.lens_diagram_info.text() and "diagonal" in panel.lens_diagram_info.text()
    panel.set_f_number(8.0)
    narrow = diagram.stop_opening_mm()
    # The stop opens fully at the glass's own f/2.03 and scales as 1 / N from there: at f/8 about a quarter.
    system = panel.doc.scene.camera.lens_system()
    assert wide == pytest.approx(2.0 * system.aperture_radius[system.stop])
    assert narrow == pytest.approx(wide * system.widest_f_number / 8.0)
    assert not diagram.grab().isNull()
    panel.choose_lens(None)
    assert diagram.isHidden() and panel.lens_diagram_info.isHidden()


def test_the_side_view_traces_its_rays_at_the_current_focus(studio):
    panel = studio
    panel.choose_lens(lens_named(panel, DOUBLE_GAUSS))
    panel.set_f_number(2.8)

    def on_axis_rays():
        return [ray for ray in panel.lens_diagram.ray_paths() if ray.on_axis]

    sensor_z = studio.doc.scene.camera.lens_system().efl
    assert panel.set_focus(5.0)
    far = on_axis_rays()
    assert panel.set_focus(0.5)
    near = on_axis_rays()
    for rays in (far, near):
        assert len(rays) == 5 and all(ray.reached_sensor for ray in rays)
        # The point in focus is imaged: the on-axis fan meets on the sensor (within its aberrations).
        ends = np.array([ray.points[-1] for ray in rays])
        assert np.allclose(ends[:, 0], sensor_z) and np.abs(ends[:, 1]).max() < 0.05
    # Focused near, the lens has moved forward: every ray crosses each surface elsewhere, and comes in steeper.
    assert not any(np.allclose(a.points, b.points) for a, b in zip(far, near) if len(a.points) == len(b.points))
    assert incoming_slope(near[0]) > 2.0 * incoming_slope(far[0])


def incoming_slope(ray) -> float:
    """How steeply a drawn ray comes in from the scene: dy/dz of its first segment."""
    dz, dy = ray.points[1] - ray.points[0]
    return abs(dy / dz)


def test_a_scene_whose_camera_names_a_real_lens_opens_with_that_lens_mounted(studio, small_scene, tmp_path):
    from lenslab.gui.document import Document
    from lenslab.scene.io.loader import open_scene
    from lenslab.scene.io.native import save_scene

    panel, doc = studio, studio.doc
    lens = lens_named(panel, FISHEYE)
    scene = dataclasses.replace(small_scene, camera=dataclasses.replace(
        small_scene.camera, **lens.mount(small_scene.camera.focal_length_mm, 4.0), focus_distance_m=1.0))
    path = tmp_path / "fisheye.json"
    save_scene(scene, path)
    doc.replace(open_scene(str(path)), path)  # File > Open
    assert doc.lens == lens
    assert button_of(panel, lens).isChecked() and not panel.lens_buttons[0].isChecked()
    assert not panel.lens_diagram.isHidden() and not panel.squeeze.isEnabled()
    assert Document(open_scene(str(path))).lens == lens  # the window's first scene
    panel.choose_lens(None)
    assert doc.scene.camera.real_lens == ""


def test_the_dispersion_switch_shows_for_dispersive_glass_and_sets_the_camera(studio):
    """The lens section offers an achromatic preview for glass that disperses: unticking it sets the camera's
    dispersion off in one undo step; a thin lens hides the switch."""
    panel = studio
    doc = panel.doc
    panel.choose_lens(lens_named(panel, DOUBLE_GAUSS))
    assert panel.dispersion.isVisibleTo(panel) and panel.dispersion.isChecked()
    rows = doc.undo_stack.count()
    panel.dispersion.setChecked(False)
    assert doc.scene.camera.dispersion is False and doc.undo_stack.count() == rows + 1
    doc.undo_stack.undo()
    assert doc.scene.camera.dispersion is True and panel.dispersion.isChecked()
    panel.choose_lens(None)
    assert not panel.dispersion.isVisibleTo(panel)
