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
    assert banner_text(state(paused=True, snapshot_alone=True)) is None  # A/B's A is shown: nothing live in sight


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
    banner = WorkBanner(viewport, controller, viewport)  # goes with the viewport
    banner.refresh()
    assert banner.text == "Opening the scene…" and viewport.idle_text == "Opening the scene…"
    controller.working.emit(WorkNote(1, "building the kd-tree", 2, 5))
    controller.work_note = WorkNote(1, "building the kd-tree", 2, 5)
    banner.refresh()
    assert "building the kd-tree (step 2 of 5)" in banner.text and banner.fraction == 0.2
    controller.picture_is_current = True
    banner.refresh()
    assert banner.text is None and not banner.dim


def test_the_banners_seconds_count_from_the_newest_edit_not_from_when_the_picture_was_last_current(
        qtbot, monkeypatch):
    from lenslab.gui import work_banner
    from lenslab.gui.viewport import Viewport

    clock = [100.0]
    monkeypatch.setattr(work_banner.time, "perf_counter", lambda: clock[0])
    viewport = Viewport()
    qtbot.addWidget(viewport)
    controller = FakeController()
    banner = WorkBanner(viewport, controller, viewport)  # goes with the viewport
    controller.generation = 2  # an edit the picture does not show
    banner.refresh()
    clock[0] += 5.0
    assert banner.state().stale_seconds == pytest.approx(5.0)
    controller.generation = 3  # another edit before the first one's picture came
    banner.refresh()
    clock[0] += 1.0
    assert banner.state().stale_seconds == pytest.approx(1.0)
    banner.refresh()
    assert banner.text.endswith("· 1 s")


def test_a_note_left_from_before_another_scene_was_opened_is_not_shown_as_the_new_ones(qtbot):
    from lenslab.gui.viewport import Viewport

    viewport = Viewport()
    qtbot.addWidget(viewport)
    controller = FakeController()
    banner = WorkBanner(viewport, controller, viewport)  # goes with the viewport
    controller.work_note = WorkNote(2, "preparing the kernel", 5, 5)  # the last edit's, finished
    controller.generation = controller.scene_generation = 3  # File > Open: the new scene's notes are not in yet
    banner.refresh()
    assert banner.text == "Opening the scene…"


def test_an_edit_that_sends_the_same_scene_again_is_not_opening_another_one(window, qtbot):
    controller = window.controller
    wait_for_frame(qtbot, window)
    opened = controller.scene_generation
    controller.set_quality("auto")  # the picture's size changes: the scene goes to the worker again
    assert controller.generation > opened and controller.scene_generation == opened
    window.doc.set_camera(f_number=8.0)
    state = window.render_status.work_banner.state()
    assert not state.new_scene  # no "Opening the scene", no dimming: it is this scene's picture
    window.doc.replace(dataclasses.replace(window.doc.scene), None)  # File > New / Open: another scene
    assert controller.scene_generation == controller.generation
    assert window.render_status.work_banner.state().new_scene


def test_the_frames_label_describes_the_picture_shown_not_the_newest_resolution(window, qtbot):
    wait_for_frame(qtbot, window)
    framing = window.viewing.framing
    before = framing.label()
    window.render_status.set_paused(True)
    qtbot.waitUntil(lambda: window.controller.paused)
    w, h = window.doc.scene.camera.resolution
    window.doc.set_camera(resolution=(w * 2, h))
    assert framing.label() == before, "the label changed while the picture still has the old frame"
    window.render_status.set_paused(False)
    wait_for_frame(qtbot, window, generation=window.controller.generation)
    qtbot.waitUntil(lambda: framing.label().endswith(f"{w * 2} × {h}"), timeout=10000)


# -- the render loop and its denoiser, without Qt ------------------------------------------------------------
LOOP_SIZE = (320, 240)  # large enough for a quarter-resolution preview


class FullPassDenoising:
    """Holds back the denoising of full-resolution pictures (on any Denoiser: the shared one the previews use, or
    one of the loop's own) until ``let_go`` is set or ``seconds`` pass; a preview's goes through. ``entered``:
    one is being held; ``timed_out``: a True for each that waited the whole time."""

    def __init__(self, monkeypatch, seconds: float):
        import threading

        from lenslab.render import denoise as oidn

        self.entered, self.let_go, self.timed_out = threading.Event(), threading.Event(), []
        self.seconds = seconds
        real = oidn.Denoiser.denoise

        def denoise(denoiser, color, *args, **kwargs):
            if color.shape[:2] == LOOP_SIZE[::-1] and not self.let_go.is_set():
                self.entered.set()
                self.timed_out.append(not self.let_go.wait(self.seconds))
            return real(denoiser, color, *args, **kwargs)

        monkeypatch.setattr(oidn.Denoiser, "denoise", denoise)


class QuietEvents:
    def __getattr__(self, name):
        return lambda *args: None


def denoising_loop(scene):
    """A RenderLoop on a renderer of its own, rendering ``scene`` at LOOP_SIZE with the denoiser on."""
    from lenslab.gui.render_loop import DenoiseEdit, RenderLoop, SceneEdit, TargetSpp
    from lenslab.render.tracer import Renderer

    loop = RenderLoop(Renderer(), QuietEvents())
    loop.handle([DenoiseEdit(True), TargetSpp(None), SceneEdit(scene, LOOP_SIZE, 1)])
    return loop


def first_frame_of(loop, generation: int):
    frame = None
    while frame is None or frame.generation != generation:
        loop.step()
        frame = loop.take_frame() or frame
    return frame


def stopped_down(scene):
    from lenslab.gui.render_loop import CameraEdit

    camera = dataclasses.replace(scene.camera, f_number=scene.camera.f_number * 2)
    return CameraEdit(camera, LOOP_SIZE, 2, False)


@pytest.mark.smoke
def test_an_edit_made_while_a_picture_is_denoised_is_rendered_at_once(gl_available, small_scene, monkeypatch):
    """The full-resolution pictures are denoised off the render thread: an edit that comes while one is being
    denoised gets its own denoised preview without waiting for that picture, which it has made stale and which
    is never shown."""
    held = FullPassDenoising(monkeypatch, seconds=20)
    loop = denoising_loop(small_scene)
    try:
        while not held.entered.is_set():  # the preview, the first full pass, and its denoising begun
            loop.step()
        loop.handle([stopped_down(small_scene)])
        first = first_frame_of(loop, 2)
        assert not held.let_go.is_set() and not any(held.timed_out), \
            "the edit waited for the stale picture's denoising"
        assert first.preview and first.denoised
        held.let_go.set()
        shown = []
        while not shown or shown[-1].preview:
            loop.step()
            frame = loop.take_frame()
            if frame is not None:
                shown.append(frame)
        assert all(f.generation == 2 and f.denoised for f in shown), "a picture of the edit before was shown"
        assert shown[-1].samples_per_pixel >= 1 and not any(held.timed_out)
    finally:
        held.let_go.set()
        loop.release()


@pytest.mark.smoke
def test_a_preview_held_back_for_the_picture_on_screen_is_shown_when_the_hold_ends(gl_available, small_scene,
                                                                                   monkeypatch):
    """An edit's preview that comes sooner than the hold (the picture on screen is kept for a moment after an
    edit, so that a drag does not flash worse pictures) is shown when the hold ends, not dropped for the long
    wait until the full pass is denoised."""
    from lenslab.gui import render_loop

    monkeypatch.setattr(render_loop, "HOLD_SECONDS", 0.5)  # longer than this preview takes
    loop = denoising_loop(small_scene)
    held = None
    try:
        frame = None
        while frame is None or frame.preview:  # a full-resolution denoised picture on screen
            loop.step()
            frame = loop.take_frame() or frame
        held = FullPassDenoising(monkeypatch, seconds=5)  # the edit's full pass: up to 5 s
        loop.handle([stopped_down(small_scene)])
        first = first_frame_of(loop, 2)
        assert first.preview and first.denoised, "the preview was dropped for the full pass's picture"
        assert not any(held.timed_out), "the edit showed nothing until its full pass was denoised"
    finally:
        if held is not None:
            held.let_go.set()
        loop.release()


@pytest.mark.smoke
def test_peaking_and_clipping_marks_are_not_drawn_over_a_picture_not_worth_judging(qtbot):
    """The marks last worked out (the previous picture's edges) wait for the layer's next run; over an edit's
    preview they would mark where the old picture was sharp."""
    from types import SimpleNamespace

    from PySide6.QtCore import QRectF
    from PySide6.QtGui import QColor, QImage, QPainter

    from lenslab.gui.layer_support import MaskLayer

    layer = MaskLayer(SimpleNamespace(), interval_ms=200)
    layer._overlay = QImage(4, 4, QImage.Format_RGBA8888)
    layer._overlay.fill(QColor(255, 255, 0))

    def painted(worth_judging: bool) -> QColor:
        canvas = QImage(4, 4, QImage.Format_RGBA8888)
        canvas.fill(QColor(0, 0, 0))
        p = QPainter(canvas)
        layer.paint(p, SimpleNamespace(worth_judging=worth_judging), QRectF(0, 0, 4, 4))
        p.end()
        return canvas.pixelColor(1, 1)

    assert painted(True) == QColor(255, 255, 0)
    assert painted(False) == QColor(0, 0, 0)
