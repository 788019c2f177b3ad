"""The studio's side of a real camera's controls: stop scales, focus limits, the new optics and exposure."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenslab.color import srgb_to_linear

from .helpers import wait_for_frame

pytestmark = pytest.mark.gl


def stops_moved(before: float, after: float) -> float:
    return 2 * math.log2(after / before)


@pytest.mark.smoke
@pytest.mark.parametrize("scale, fraction", [("third", 1 / 3), ("half", 1 / 2), ("full", 1.0)])
def test_one_key_press_is_one_step_of_the_chosen_scale(window, settings, scale, fraction):
    panel = window.camera_panel
    panel.stop_scale_combo.setCurrentIndex(-1)  # so that choosing the default is a change too
    panel.stop_scale_combo.setCurrentIndex(panel.stop_scale_combo.findData(scale))
    assert settings.value("camera/stop_scale") == scale
    window.actions["stop_down"].trigger()  # from f/1.8, a value between marks: onto the next mark
    for _ in range(3):
        before = window.doc.scene.camera.f_number
        window.actions["stop_down"].trigger()
        assert stops_moved(before, window.doc.scene.camera.f_number) == pytest.approx(fraction)
    # The slider's labels and the combo show marks; the camera holds exact values.
    assert panel.aperture_combo.currentText() in {f"f/{m:g}" for m in (2.8, 3.3, 4, 5.6, 8, 11, 4.5, 5, 3.2)}
    window.actions["open_up"].trigger()
    assert window.doc.scene.camera.f_number == pytest.approx(before)


@pytest.mark.smoke
def test_focus_nearer_than_the_lens_is_refused_and_a_longer_lens_moves_it_out(window, qtbot):
    panel = window.camera_panel
    messages = []
    panel.status_message.connect(messages.append)
    lens = next(lens for lens in panel.lenses if lens.name == "85 mm f/1.4")
    panel.choose_lens(lens)
    assert panel.focus_limits()[0] == pytest.approx(0.8)
    before = window.doc.scene.camera.focus_distance_m
    assert not panel.set_focus(0.5)
    assert window.doc.scene.camera.focus_distance_m == before
    assert messages[-1] == ("Cannot focus there: focus 0.5 m from the sensor is nearer than the 85 mm f/1.4 lens's "
                            "minimum focus of 0.8 m from the sensor")  # the command line's check, in the panel's word
    assert panel.set_focus(0.9)
    # Free, 50 mm at 0.25 m: a 200 mm lens cannot focus there (four focal lengths), so zooming moves it out.
    panel.choose_lens(None)
    panel.set_focal_length(50.0, False)
    assert panel.set_focus(0.25)
    panel.set_focal_length(200.0, False)
    cam = window.doc.scene.camera
    assert cam.focal_length_mm == 200.0 and cam.focus_distance_m == pytest.approx(0.8)
    assert "Focus moved out" in messages[-1]
    window.doc.undo_stack.undo()  # one undo step puts both back
    assert (window.doc.scene.camera.focal_length_mm, window.doc.scene.camera.focus_distance_m) == (50.0, 0.25)


@pytest.mark.smoke
def test_the_new_controls_edit_the_camera_and_undo(window, tmp_path):
    panel = window.camera_panel
    cam = window.doc.scene.camera
    edits = [(panel.curvature, "blade_curvature", 0.6), (panel.squeeze, "anamorphic_squeeze", 1.8),
             (panel.barrel, "barrel_clipping", 0.4), (panel.coc, "circle_of_confusion_mm", 0.02)]
    for widget, field, value in edits:
        widget.setValue(value)
        assert getattr(window.doc.scene.camera, field) == pytest.approx(value), field
    panel.coc.setValue(0.0)  # "auto"
    assert window.doc.scene.camera.circle_of_confusion_mm is None
    panel.sensor_fit.setCurrentIndex(panel.sensor_fit.findData("fill"))
    assert window.doc.scene.camera.sensor_fit == "fill"
    panel.breathing.setChecked(False)
    assert window.doc.scene.camera.focus_breathing is False
    plane = window.doc.scene.camera.plane_of_focus_m
    panel.focus_from.setCurrentIndex(panel.focus_from.findData("lens"))
    assert window.doc.scene.camera.focus_from == "lens"
    assert window.doc.scene.camera.plane_of_focus_m == pytest.approx(plane)  # the plane of focus stays
    for _ in range(9):
        window.doc.undo_stack.undo()
    assert window.doc.scene.camera == cam


@pytest.mark.smoke
def test_a_missing_aperture_image_keeps_the_stop_and_says_why(window, tmp_path):
    import OpenImageIO as oiio

    panel = window.camera_panel
    messages = []
    panel.status_message.connect(messages.append)
    panel.set_aperture_image(str(tmp_path / "nosuch.png"))
    assert window.doc.scene.camera.aperture_image == "" and "aperture image not found" in messages[-1]
    star = tmp_path / "mask.exr"
    out = oiio.ImageOutput.create(str(star))
    out.open(str(star), oiio.ImageSpec(8, 8, 1, oiio.FLOAT))
    mask = np.zeros((8, 8), np.float32)
    mask[2:6, 2:6] = 1.0
    out.write_image(mask)
    out.close()
    panel.set_aperture_image(str(star))
    assert window.doc.scene.camera.aperture_image == str(star)
    assert panel.light_fraction() == pytest.approx(4 * 0.25 / math.pi)
    assert "passing 32%" in panel.aperture_info.text()


def test_physical_exposure_darkens_the_picture_a_stop_per_stop(window, qtbot):
    window.set_display_exposure(0.0)
    window.display.set_view("clamp")  # the old name: the Un-tone-mapped view, linear up to the display's white

    def picture(f_number: float, mode: str) -> np.ndarray:
        # The Cornell box's lamp is lit in nits (its walls about 50 cd/m²): 1/60 s at ISO 100 exposes it about
        # right at f/2.8, and a stop less at f/4.
        window.doc.set_camera("test", False, f_number=f_number, exposure_mode=mode, iso=100.0, shutter_s=1 / 60)
        # The generation this edit started, not the first restart signalled: on a cold start the window's first
        # scene may still be on its way to the worker, and its restart, with the old camera, comes first.
        edit = window.controller.generation
        return wait_for_frame(qtbot, window, min_spp=16, generation=edit).display[..., :3]

    def ratio(a: np.ndarray, b: np.ndarray) -> float:
        """Mean linear radiance of a over b, where neither is clipped (the lamp is)."""
        unclipped = (a.max(axis=2) < 250) & (b.max(axis=2) < 250)
        return float(srgb_to_linear(a[unclipped] / 255.0).mean() / srgb_to_linear(b[unclipped] / 255.0).mean())

    physical = ratio(picture(2 ** 1.5, "physical"), picture(4.0, "physical"))
    assert "f/4 · focus" in window.viewport.hud_text and window.viewport.hud_text.endswith("1/60 s · ISO 100")
    window.set_display_exposure(-6.0)  # compensated: the scene's nits as they are, 6 stops down to be seen
    compensated = ratio(picture(2 ** 1.5, "compensated"), picture(4.0, "compensated"))
    assert physical == pytest.approx(2.0, rel=0.12)
    assert compensated == pytest.approx(1.0, rel=0.08)


@pytest.mark.parametrize("scale, fraction", [("third", 1 / 3), ("half", 1 / 2), ("full", 1.0)])
def test_the_shutter_steps_on_the_chosen_scale_and_names_the_menu(window, scale, fraction):
    panel = window.camera_panel
    panel.stop_scale_combo.setCurrentIndex(panel.stop_scale_combo.findData(scale))
    amount = {"third": "⅓", "half": "½", "full": "1"}[scale]
    assert window.actions["stop_down"].text() == f"Stop Down {amount} Stop"
    window.doc.set_camera("test", False, exposure_mode="physical", shutter_s=1 / 125)
    assert panel.shutter_longer.isEnabled()
    panel.step_shutter(+1)
    longer = window.doc.scene.camera.shutter_s
    # Dial marks are rounded (1/60 for 1/62.5): one step is the scale's fraction to within the rounding.
    assert math.log2(longer * 125) == pytest.approx(fraction, abs=0.08)
    panel.step_shutter(-1)
    assert window.doc.scene.camera.shutter_s == pytest.approx(1 / 125)
    panel.step_shutter(-1000)  # the dial's end holds
    assert window.doc.scene.camera.shutter_s == pytest.approx(1 / 8000)
    assert not panel.shutter_shorter.isEnabled()


def test_the_shutter_buttons_sleep_while_exposure_is_compensated(window):
    window.doc.set_camera("test", False, exposure_mode="compensated")
    assert not window.camera_panel.shutter_longer.isEnabled()
    assert not window.camera_panel.shutter.isEnabled()


def test_auto_circle_of_confusion_shows_its_value_and_steps_from_it(window):
    panel = window.camera_panel
    window.doc.set_camera("test", False, circle_of_confusion_mm=None)
    film_w, film_h = window.doc.scene.camera.imaged_area_mm(*window.doc.scene.camera.resolution)
    auto = math.hypot(film_w, film_h) / 1500
    assert panel.coc.specialValueText() == f"auto · {auto:.4f} mm"
    panel.coc.stepBy(1)  # the first step up from auto starts at the auto value, not at zero
    assert window.doc.scene.camera.circle_of_confusion_mm == pytest.approx(round(auto, 4))


def test_folded_sections_are_remembered(make_window, small_scene, settings):
    window = make_window(small_scene)
    bokeh = window.camera_panel.sections["bokeh"]
    assert bokeh.header.isChecked() and bokeh.body.isVisibleTo(window)
    bokeh.header.setChecked(False)
    assert not bokeh.body.isVisibleTo(window)
    again = make_window(small_scene)
    assert not again.camera_panel.sections["bokeh"].header.isChecked()
    assert not again.camera_panel.sections["bokeh"].body.isVisibleTo(again)
    assert again.camera_panel.sections["exposure"].header.isChecked()


def test_a_scene_at_f_0_13_opens_as_written_and_the_panel_shows_it(make_window, small_scene, tmp_path, qtbot):
    # The controls offer f/0.5 to f/128 and 1 to 2000 mm; a scene holds what it holds (Mitsuba's sensor_thinlens is
    # f/0.13): shown as it is, and neither opening, showing nor leaving the fields changes it.
    import dataclasses

    from lenslab.scene.io.loader import open_scene
    from lenslab.scene.io.native import save_scene

    small_scene.camera = dataclasses.replace(small_scene.camera, f_number=0.13, focal_length_mm=0.5,
                                             focus_from="lens", focus_breathing=False)
    path = tmp_path / "wide_open.json"
    save_scene(small_scene, path)
    window = make_window(open_scene(str(path)), path)
    panel = window.camera_panel
    assert panel.aperture_combo.currentText() == "f/0.13"
    assert panel.focal.value() == 0.5 and panel.focal.text().startswith("0.5")
    assert not panel.open_up.isEnabled() and panel.stop_down.isEnabled()  # wider than every stop on the scale
    wait_for_frame(qtbot, window)
    panel.aperture_combo.lineEdit().editingFinished.emit()  # leaving the fields as shown edits nothing
    panel.focal.editingFinished.emit()
    cam = window.doc.scene.camera
    assert (cam.f_number, cam.focal_length_mm) == (0.13, 0.5)
    assert window.doc.undo_stack.count() == 0 and window.doc.undo_stack.isClean()
    window.actions["stop_down"].trigger()  # a step is a control: onto the scale, at its widest stop
    assert window.doc.scene.camera.f_number == pytest.approx(2 ** -0.5)
    window.doc.undo_stack.undo()
    assert window.doc.scene.camera.f_number == 0.13 and panel.aperture_combo.currentText() == "f/0.13"
