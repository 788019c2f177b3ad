"""A clean picture after every edit, and a viewport that says what it is doing.

With the denoiser on, an edit shows a denoised preview (marked as one) and then denoised full-resolution
pictures; raw samples never. Peaking, clipping and the histogram wait for a picture worth judging. The camera
tag describes the picture on screen, not the document's newest camera, and while the picture is not the latest
edit's the work banner says what is under way."""

from __future__ import annotations

import dataclasses

import pytest

from PySide6.QtCore import QObject, Signal

from lenslab.gui.render_loop import Frame, WorkNote
from lenslab.gui.work_banner import BANNER_DELAY_SECONDS, BannerState, WorkBanner, banner_text
from tests.gui.helpers import wait_for_frame


def preview_window(make_window, small_scene, settings, denoise: bool):
    """A window whose picture is large enough for a preview pass and whose first pass takes several dispatches."""
    settings.setValue("viewport/denoise", denoise)
    small_scene.camera = dataclasses.replace(small_scene.camera, resolution=(320, 256))
    return make_window(small_scene)


def test_with_the_denoiser_an_edit_shows_a_denoised_preview_then_denoised_pictures_never_raw_noise(
        make_window, small_scene, settings, qtbot):
    window = preview_window(make_window, small_scene, settings, denoise=True)
    wait_for_frame(qtbot, window, min_spp=2)
    frames: list[Frame] = []
    judged: list[tuple[Frame, bool]] = []
    window.controller.frame_ready.connect(frames.append)
    window.controller.frame_ready.connect(lambda f: judged.append((f, window.viewport.worth_judging)))
    window.doc.set_camera(f_number=window.doc.scene.camera.f_number * 2)
    edit = window.controller.generation
    wait_for_frame(qtbot, window, min_spp=2, generation=edit)
    shown = [f for f in frames if f.generation == edit]
    # Until the edit has a picture as clean as the last one, the last one stays (or the preview comes first).
    raw = [(f.samples_per_pixel, f.preview) for f in shown if not f.denoised]
    assert raw == [], f"raw pictures shown with the denoiser on: {raw}"
    assert shown[-1].samples_per_pixel >= 2 and not shown[-1].preview
    # A preview is not judged (peaking would follow the noise of a quarter-resolution pass) and says what it
    # is; the full resolution's denoised pictures are judged.
    assert not any(ok for f, ok in judged if f.generation == edit and f.preview)
    assert all(ok for f, ok in judged if f.generation == edit and not f.preview)
    assert all("preview" in samples_tag(f) for f in shown if f.preview)


def samples_tag(frame: Frame) -> str:
    from lenslab.gui.controller import samples_text

    return samples_text(frame)


def test_without_the_denoiser_peaking_waits_for_enough_samples(make_window, small_scene, settings, qtbot):
    window = preview_window(make_window, small_scene, settings, denoise=False)
    seen: list[tuple[int, bool, bool]] = []
    window.controller.frame_ready.connect(
        lambda f: seen.append((f.samples_per_pixel, f.preview, window.viewport.worth_judging)))
    wait_for_frame(qtbot, window, min_spp=2)
    assert seen and not any(ok for spp, preview, ok in seen if preview or spp < 2)


def test_the_camera_tag_describes_the_picture_shown_not_the_newest_edit(make_window, small_scene, qtbot):
    window = make_window(small_scene)
    wait_for_frame(qtbot, window)
    before = window.viewport.hud_text
    assert "f/" in before
    window.render_status.set_paused(True)
    qtbot.waitUntil(lambda: window.controller.paused)
    window.doc.set_camera(f_number=16.0)
    assert window.viewport.hud_text == before, "the tag changed while the picture still shows the old f-number"
    window.render_status.set_paused(False)
    wait_for_frame(qtbot, window, generation=window.controller.generation)
    qtbot.waitUntil(lambda: "f/16" in window.viewport.hud_text, timeout=10000)


def test_the_work_banner_says_a_paused_picture_is_behind_and_goes_once_the_picture_is_current(
        make_window, small_scene, qtbot):
    window = make_window(small_scene)
    wait_for_frame(qtbot, window)
    banner = window.render_status.work_banner
    assert banner.text is None
    window.render_status.set_paused(True)
    window.doc.set_camera(f_number=11.0)
    qtbot.waitUntil(lambda: banner.text is not None and banner.text.startswith("Paused"), timeout=5000)
    window.render_status.set_paused(False)
    wait_for_frame(qtbot, window, generation=window.controller.generation)
    qtbot.waitUntil(lambda: banner.text is None, timeout=5000)


@pytest.mark.smoke
def test_the_render_loop_notes_each_step_of_a_scene_load_in_order(gl_available, small_scene):
    from lenslab.gui.render_loop import RenderLoop, SceneEdit
    from lenslab.render.tracer import SCENE_STAGES, Renderer

    notes: list[WorkNote] = []

    class Events:
        def working(self, note):
            notes.append(note)

        def __getattr__(self, name):
            return lambda *args: None

    loop = RenderLoop(Renderer(), Events())  # a renderer of its own: the loop releases it
    try:
        loop.handle([SceneEdit(small_scene, (64, 48), 7)])
        stages = [n.stage for n in notes if n.steps]
        assert stages == list(SCENE_STAGES)
        assert [n.step for n in notes if n.steps] == list(range(1, len(SCENE_STAGES) + 1))
        assert all(n.generation == 7 for n in notes)
    finally:
        loop.release()


# -- the banner's line --------------------------------------------------------------------------------------
def state(**overrides) -> BannerState:
    values = dict(current=False, stale_seconds=1.5, has_picture=True, preview=False, new_scene=False, paused=False,
                  note=None)
    values.update(overrides)
    return BannerState(**values)


def test_banner_text_names_the_stage_and_how_far_along_it_is():
    assert banner_text(state(current=True)) is None
    assert banner_text(state(stale_seconds=BANNER_DELAY_SECONDS / 2)) is None  # a drag's pictures follow at once
    assert banner_text(state(has_picture=False, stale_seconds=0.0, new_scene=True)) == "Opening the scene…"
    loading = banner_text(state(new_scene=True, note=WorkNote(3, "building the kd-tree", 2, 5)))
    assert loading == "Opening the scene: building the kd-tree (step 2 of 5) · 2 s"
    assert banner_text(state(note=WorkNote(3, "first pass", fraction=0.4))) == \
        "Updating the picture: first pass 40% · 2 s"
    assert banner_text(state(current=True, preview=True, stale_seconds=0.0)) == \
        "Preview at ¼ resolution: full resolution under way"
    assert banner_text(state(paused=True)).startswith("Paused")


class FakeController(QObject):
    frame_ready = Signal(object)
    working = Signal(object)

    def __init__(self):
        super().__init__()
        self.last_frame = None
        self.generation = 1
        self.scene_generation = 1
        self.work_note = None
        self.paused = False
        self.picture_is_current = False


def test_the_banner_follows_the_controller_and_dims_another_scenes_picture(qtbot):
    from lenslab.gui.viewport import Viewport

    viewport = Viewport()
    qtbot.addWidget(viewport)
    controller = FakeController()
    banner = WorkBanner(viewport, controller)
    banner.refresh()
    assert banner.text == "Opening the scene…" and viewport.idle_text == "Opening the scene…"
    controller.working.emit(WorkNote(1, "building the kd-tree", 2, 5))
    controller.work_note = WorkNote(1, "building the kd-tree", 2, 5)
    banner.refresh()
    assert "building the kd-tree (step 2 of 5)" in banner.text and banner.fraction == 0.2
    controller.picture_is_current = True
    banner.refresh()
    assert banner.text is None and not banner.dim
