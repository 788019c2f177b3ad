"""The studio's view transform and light meter (docs/studio.md, "Display, view and look" and "The light meter").

The Display, View Transform and Look menus list what the OpenColorIO config has, and choosing another view changes
the picture (made again on the GPU, the render going on); the histogram and the clipping warnings read the picture
the chosen view makes (an Un-tone-mapped view clips the Cornell box's lamp, an ACES view rolls it off); a view
stored by an earlier version (``viewport/tone_map``: filmic, clamp, reinhard) or one the config no longer has opens
without an error; the meter's Apply sets the shutter it suggests as one undo step; the auto exposure puts the
meter's reading at middle grey (a uniform sky comes out as middle grey on an un-tone-mapped display).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenslab.colour_management.config import load_config
from lenslab.gui.camera_panel import dial_mark
from lenslab.optics.exposure import (MIDDLE_GREY, format_shutter, metered_ev100, nearest_third_stop_shutter,
                                     shutter_for)

from .helpers import wait_for_frame

pytestmark = pytest.mark.gl

UNTONED = "Un-tone-mapped"


def frame_with(qtbot, window, condition, timeout=20000):
    """The newest frame once ``condition(frame)`` holds for it."""
    qtbot.waitUntil(lambda: window.controller.last_frame is not None and condition(window.controller.last_frame),
                    timeout=timeout)
    return window.controller.last_frame


@pytest.mark.smoke
def test_the_menus_list_the_configs_displays_views_and_looks_and_a_view_changes_the_picture(qtbot, window):
    config = load_config()
    menus, display = window.view_menus, window.display
    default = config.getDefaultDisplay()
    assert list(menus.display_actions) == list(config.getDisplays())
    assert list(menus.view_actions) == list(config.getViews(default))
    assert list(menus.look_actions) == [""] + [look.getName() for look in config.getLooks()]
    assert menus.look_actions[""].text() == "None" and menus.look_actions[""].isChecked()
    assert menus.display_actions[default].isChecked()
    # The window's View menu holds the three menus; the toolbar's button names the display and view.
    view_menu = next(a.menu() for a in window.menuBar().actions() if a.text().replace("&", "") == "View")
    titles = [a.text().replace("&", "") for a in view_menu.actions()]
    assert {"Display", "View Transform", "Look"} <= set(titles)
    assert window.view_button.text() == "ACES 2.0 SDR" and window.view_label.text() == "sRGB / ACES 2.0 SDR"
    assert display.describe() in window.view_button.toolTip() and display.describe() in window.view_label.toolTip()
    window.toolbar.view_menu.aboutToShow.emit()
    assert set(menus.view_actions.values()) <= set(window.toolbar.view_menu.actions())

    window.controller.set_target_spp(4)
    first = frame_with(qtbot, window, lambda f: f.converged and f.view == display.view)
    menus.view_actions[UNTONED].trigger()  # as a click on the menu entry
    assert display.view.view == UNTONED and window.viewport.view == display.view
    assert menus.view_actions[UNTONED].isChecked() and window.view_button.text() == UNTONED
    after = frame_with(qtbot, window, lambda f: f.view.view == UNTONED)
    assert after.samples_per_pixel == first.samples_per_pixel  # the render was not restarted
    assert not np.array_equal(after.display[..., :3], first.display[..., :3])
    # Another display lists its own views and keeps the view's name where it has one.
    p3 = "Display P3 - Display"
    menus.display_actions[p3].trigger()
    assert display.view.display == p3 and display.view.view == UNTONED
    assert list(menus.view_actions) == list(config.getViews(p3)) and menus.view_actions[UNTONED].isChecked()
    display.set_view(config.getDefaultView(p3))
    display.set_display(default)  # sRGB has no P3 view: its default
    assert display.view.view == config.getDefaultView(default)
    # A look, then none again; the contrast and the reset.
    look = config.getLooks()[0].getName()
    menus.look_actions[look].trigger()
    assert display.view.looks == look and look in window.view_button.text() + window.view_button.toolTip()
    menus.look_actions[""].trigger()
    assert display.view.looks == ""
    display.set_contrast(1.5)
    window.set_display_exposure(1.0)
    assert (window.viewport.view.contrast, window.viewport.exposure) == (1.5, 1.0)
    menus.reset_action.trigger()
    assert (display.view.contrast, display.view.exposure_stops) == (1.0, 0.0)


def test_the_histogram_shows_the_clipping_of_the_chosen_view(qtbot, window):
    """The lamp through the Un-tone-mapped view reaches display code value 255 (its channels clip); through the
    ACES view it rolls off below it, at the same exposure."""
    aids, panel = window.viewing, window.viewing.histogram_panel
    aids.actions["clipping"].trigger()
    window.controller.set_target_spp(16)
    window.set_display_exposure(1.0)
    frame_with(qtbot, window, lambda f: f.converged and f.view == window.display.view)

    def judged(view_name):
        window.display.set_view(view_name)
        frame = frame_with(qtbot, window, lambda f: f.view == window.display.view and f.converged)
        qtbot.waitUntil(lambda: window.viewport.qimage is not None and panel.histogram is not None
                        and not panel._stale, timeout=5000)
        panel.refresh()
        aids.clipping.refresh()
        picture = frame.display[..., :3]
        return panel.histogram, aids.clipping.highlights, picture

    aces, aces_marks, aces_picture = judged(window.display.config.getDefaultView(window.display.view.display))
    flat, flat_marks, flat_picture = judged(UNTONED)
    # The histogram counts the code values of the picture the GPU made through the view.
    assert flat.clipped_any == pytest.approx((flat_picture.max(axis=2) == 255).mean())
    assert aces.clipped_any == pytest.approx((aces_picture.max(axis=2) == 255).mean())
    assert flat.clipped_any > 0 and flat_marks.any()
    assert aces.clipped_any < flat.clipped_any and aces_marks.sum() < flat_marks.sum()
    assert panel.highlights_label.text() != "0 % ▶"


@pytest.mark.parametrize("stored, shown", [("filmic", ""), ("clamp", UNTONED), ("reinhard", ""), ("aces", "")])
def test_an_earlier_versions_tone_map_opens_as_its_view(qtbot, make_window, settings, small_scene, stored, shown):
    settings.remove("viewport/view")
    settings.setValue("viewport/tone_map", stored)
    window = make_window(small_scene)
    config = load_config()
    expected = shown or config.getDefaultView(config.getDefaultDisplay())
    assert window.display.view.view == expected and window.viewport.view.view == expected
    assert wait_for_frame(qtbot, window).view.view == expected
    assert window.log_panel.lines() == []  # silently: an old name is not a problem
    window.close()
    assert settings.value("viewport/view") == expected and settings.value("viewport/tone_map") is None


def test_a_display_or_view_the_config_lacks_falls_back_with_a_line_in_the_log(qtbot, make_window, settings,
                                                                               small_scene):
    settings.setValue("viewport/display", "Cinema Projector - Display")
    settings.setValue("viewport/view", "Film (Kodak 2383)")
    settings.setValue("viewport/look", "Bleach Bypass")
    window = make_window(small_scene)
    config = load_config()
    assert window.display.view.display == config.getDefaultDisplay()
    assert window.display.view.view == config.getDefaultView(config.getDefaultDisplay())
    assert window.display.view.looks == ""
    logged = "\n".join(window.log_panel.lines())
    assert "Cinema Projector - Display" in logged and "Bleach Bypass" in logged
    wait_for_frame(qtbot, window)


def test_the_working_space_of_the_scene_goes_into_the_view(qtbot, window):
    assert window.display.view.working_space == window.doc.scene.render.working_space == "lin_rec709"
    window.doc.set_values(("render",), {("working_space",): "acescg"})
    assert window.display.view.working_space == "acescg" and window.viewport.view.working_space == "acescg"
    frame_with(qtbot, window, lambda f: f.view.working_space == "acescg")


def test_the_meters_apply_sets_the_shutter_it_suggests_as_one_undo_step(qtbot, window):
    panel = window.camera_panel
    section = panel.exposure_section
    window.doc.set_camera("test", False, exposure_mode="physical", shutter_s=1 / 8000, iso=200.0)
    frame = frame_with(qtbot, window, lambda f: f.meter is not None and f.meter.luminance > 0
                       and f.generation >= window.controller.generation)
    reading = section.reading
    assert reading is frame.meter and panel.meter_apply.isEnabled()
    cam = window.doc.scene.camera
    ev = metered_ev100(reading.luminance)  # the round stop: all of its light
    third = nearest_third_stop_shutter(shutter_for(ev, cam.f_number, cam.iso))
    expected = dial_mark(third)  # the dial's mark for it: 1/125 for 2^-7 s
    assert abs(math.log2(expected / third)) < 0.06
    assert math.log2(third) * 3 == pytest.approx(round(math.log2(third) * 3))  # a third stop
    text = panel.meter_label.text()
    assert f"EV {ev:.1f}" in text and "ISO 200" in text and f"→ {format_shutter(expected)}" in text
    before = window.doc.undo_stack.count()
    panel.meter_apply.click()
    assert window.doc.scene.camera.shutter_s == pytest.approx(expected)
    assert panel.shutter.currentText() == format_shutter(expected)  # a mark of the dial
    assert window.doc.undo_stack.count() == before + 1 and "(meter)" in window.doc.undo_stack.undoText()
    window.doc.undo_stack.undo()
    assert window.doc.scene.camera.shutter_s == pytest.approx(1 / 8000)
    # A compensated camera turns physical at the metered exposure (one step, undone as one).
    window.doc.set_camera("test", False, exposure_mode="compensated")
    panel.meter_apply.click()
    assert window.doc.scene.camera.exposure_mode == "physical"
    window.doc.undo_stack.undo()
    assert window.doc.scene.camera.exposure_mode == "compensated"


def test_spot_metering_follows_the_point_last_clicked_to_focus(qtbot, window):
    window.doc.set_camera("test", False, metering="spot")
    assert window.camera_panel.metering.currentData() == "spot"
    frame_with(qtbot, window, lambda f: f.meter is not None and f.meter.mode == "spot")
    window.tools.focus_clicked(0.25, 0.75)  # what a click of the focus tool calls
    spot = window.tools.meter_spot
    assert spot == pytest.approx((0.25, 0.75), abs=0.05)  # the frame fills the picture at the export's pixels
    frame = frame_with(qtbot, window, lambda f: f.meter is not None and f.meter.spot == spot)
    assert "(spot at 25%, 75% of the frame)" in window.camera_panel.meter_label.toolTip()
    assert frame.meter.luminance >= 0


def test_auto_exposure_scales_the_picture_by_middle_grey_over_the_reading(qtbot, window):
    panel = window.camera_panel
    panel.exposure_mode.setCurrentIndex(panel.exposure_mode.findData("auto"))
    assert window.doc.scene.camera.exposure_mode == "auto"
    edit = window.controller.generation
    frame = frame_with(qtbot, window, lambda f: f.generation >= edit and f.exposure is not None
                       and f.exposure.metered_cd_m2 and f.meter is not None
                       and f.exposure.metered_cd_m2 == f.meter.luminance)
    assert frame.exposure.scale == pytest.approx(MIDDLE_GREY / frame.meter.luminance, rel=1e-9)
    # The panel shows the shutter the meter chose, read-only; ISO stays the photographer's.
    qtbot.waitUntil(lambda: panel.shutter.currentText() == format_shutter(
        window.controller.last_frame.exposure.shutter_s), timeout=5000)
    assert not panel.shutter.isEnabled() and panel.iso.isEnabled()
    assert panel.exposure_info.text().startswith("Auto: the meter chose")
    assert " A 1/" in window.viewport.hud_text or " A " in window.viewport.hud_text


def test_auto_exposure_makes_a_uniform_sky_middle_grey(qtbot, make_window):
    """A camera looking into a uniform sky of 3,200 cd/m² (a sunlit grey card's luminance): the auto exposure puts
    it at scene-linear 0.18, which the Un-tone-mapped sRGB view shows as code value 118 (sRGB's encoding of 0.18)."""
    from lenslab.scene.camera import ThinLensCamera
    from lenslab.scene.scene import ConstantEnvironment, Scene

    scene = Scene(camera=ThinLensCamera(resolution=(64, 48), exposure_mode="auto", iso=100.0),
                  environment=ConstantEnvironment(radiance=(3200.0, 3200.0, 3200.0)))
    window = make_window(scene)
    window.display.set_view(UNTONED)
    frame = frame_with(qtbot, window, lambda f: f.view.view == UNTONED and f.exposure is not None
                       and f.exposure.metered_cd_m2 and f.samples_per_pixel >= 1 and not f.preview)
    assert frame.meter.luminance == pytest.approx(3200.0, rel=1e-3)
    assert frame.exposure.scale * 3200.0 == pytest.approx(MIDDLE_GREY, rel=1e-3)
    assert np.abs(frame.display[..., :3].astype(int) - 118).max() <= 1
    # The settings it chose make the meter's EV100 (log2(L S / K), 14.6 here: sunny 16's).
    assert frame.exposure.ev100 == pytest.approx(math.log2(3200 * 100 / 12.5), abs=0.01)


def test_the_panels_suggestion_counts_the_light_the_aperture_passes():
    """The studio's meter and the auto exposure agree on an aperture passing half the light: a stop longer."""
    from lenslab.gui.camera_panel.exposure import metered_shutter

    full_ev, full = metered_shutter(400.0, 4.0, 100)
    half_ev, half = metered_shutter(400.0, 4.0, 100, light_fraction=0.5)
    assert half_ev == pytest.approx(full_ev - 1.0)
    assert math.log2(half / full) == pytest.approx(1.0, abs=1 / 6)  # on the dial's marks
