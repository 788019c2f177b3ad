"""The render loop's messages: typed, coalesced so that only the latest edit of each kind is applied.

No thread, no GL context and no Qt: a ``RenderLoop`` is driven directly through ``handle``, as the worker's thread
drives it, by a subclass whose appliers record what reaches them, with an events object that records what the
loop reports. The worker's own side, its methods that put these messages on its queue, is checked on its own."""

from __future__ import annotations

import subprocess
import sys

import pytest

from lenslab.gui.render_loop import (
    CameraEdit,
    ExportRequest,
    ExportStart,
    Pause,
    Phase,
    PickRequest,
    PickResult,
    RenderLoop,
    SceneEdit,
    SettingsEdit,
    Stop,
    TargetSpp,
)
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.scene import RenderSettings, Scene

pytestmark = pytest.mark.smoke  # in the quick tier (docs/testing.md)


class RecordedEvents:
    """A LoopEvents that keeps every report as (name, *arguments)."""

    def __init__(self):
        self.calls = []

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        return lambda *args: self.calls.append((name, *args))


class RecordingLoop(RenderLoop):
    """The loop with no device: the edits, picks, exports and republished pictures that reach it are recorded."""

    def __init__(self):
        super().__init__(renderer=None, events=RecordedEvents())
        self.applied = []
        self.republished = []
        self.exports = []
        self.refuse_exports = False

    def apply_scene(self, edit):
        self.applied.append(edit)

    def apply_camera(self, edit):
        self.applied.append(edit)

    def apply_settings(self, edit):
        self.applied.append(edit)

    def pick(self, request):
        self.applied.append(request)

    def republish(self, with_linear):
        self.republished.append(with_linear)

    def start_export(self, start):
        self.exports.append(start)
        return not self.refuse_exports


class NoDevice:
    """A renderer that cannot be used: whatever the loop asks of it fails."""

    def __getattr__(self, name):
        raise RuntimeError("no device in this test")


@pytest.fixture
def loop():
    return RecordingLoop()


def test_only_the_latest_camera_is_applied_and_a_move_is_not_forgotten(loop):
    moved, refocused = ThinLensCamera(position=(0, 1, 4)), ThinLensCamera(focus_distance_m=2.0)
    loop.handle([CameraEdit(moved, (64, 48), 1, view_changed=True),
                 CameraEdit(refocused, (64, 48), 2, view_changed=False)])
    assert loop.applied == [CameraEdit(refocused, (64, 48), 2, view_changed=True)]


def test_a_new_scene_supersedes_the_edits_queued_before_it(loop):
    scene = Scene()
    loop.handle([CameraEdit(ThinLensCamera(), (64, 48), 1, view_changed=True),
                 SettingsEdit(RenderSettings(spp=8), 2),
                 SceneEdit(scene, (32, 24), 3),
                 SettingsEdit(RenderSettings(spp=16), 4)])
    assert loop.applied == [SceneEdit(scene, (32, 24), 3), SettingsEdit(RenderSettings(spp=16), 4)]


def test_picks_follow_the_edits_they_were_asked_after_and_stop_ends_the_handling(loop):
    camera = ThinLensCamera()
    loop.handle([PickRequest(0.25, 0.75, 7), CameraEdit(camera, (64, 48), 5, True)])
    assert loop.applied == [CameraEdit(camera, (64, 48), 5, True), PickRequest(0.25, 0.75, 7)]
    assert not loop.stopped
    loop.applied.clear()
    loop.handle([Stop(), CameraEdit(camera, (64, 48), 6, True)])
    assert loop.applied == [] and loop.stopped


def test_pause_and_target_change_the_loop_state(loop):
    assert loop.phase is Phase.IDLE and not loop.paused and loop.target_spp == 1024
    loop.handle([TargetSpp(16), Pause(True)])
    assert loop.target_spp == 16 and loop.paused
    assert loop.phase is Phase.IDLE and not loop.busy  # no scene yet: nothing to render


def test_pausing_or_starting_an_export_republishes_the_picture_with_its_linear_image(loop):
    # The last picture stays up while paused or exporting: it must come with the radiance behind it, or the
    # pixel readout answers from an older one.
    loop.handle([Pause(True)])
    assert loop.republished == [True]
    loop.handle([Pause(True), Pause(False)])  # already paused: nothing new to show
    assert loop.republished == [True]

    request = ExportRequest(scene=Scene(), path="shot.exr", target_spp=4, seconds=None)
    loop.handle([ExportStart(1, request)])
    assert loop.republished == [True, True]
    loop.refuse_exports = True  # the second one fails
    loop.handle([ExportStart(2, request)])
    assert loop.exports == [ExportStart(1, request), ExportStart(2, request)] and loop.republished == [True, True]


def test_a_scene_that_cannot_render_is_reported_and_leaves_the_loop_idle_in_error():
    events = RecordedEvents()
    loop = RenderLoop(NoDevice(), events)
    loop.handle([SceneEdit(Scene(), (64, 48), 3), TargetSpp(16), PickRequest(0.5, 0.5, 9)])
    assert loop.phase is Phase.ERROR and loop.generation == 3 and not loop.busy
    assert events.calls == [("scene_failed", 3, "no device in this test"), ("pick_ready", PickResult(9, 3, False))]
    loop.step()  # nothing to render: reports nothing
    assert len(events.calls) == 2 and loop.take_frame() is None


def test_the_workers_methods_queue_the_messages_its_loop_handles(qapp):
    from lenslab.gui.worker import RenderWorker

    worker = RenderWorker()
    scene, camera, request = Scene(), ThinLensCamera(), ExportRequest(scene=Scene(), path="shot.exr")
    worker.set_camera(camera, 64.0, 48, generation=1)
    worker.set_settings(RenderSettings(spp=8), generation=2)
    worker.set_scene(scene, 32, 24, generation=3)
    worker.request_pick(0.25, 0.75, request_id=7)
    worker.set_target_spp(16)
    worker.set_paused(1)
    worker.start_export(4, request)
    worker.stop()
    assert worker.take_messages(block=False) == [
        CameraEdit(camera, (64, 48), 1, view_changed=True), SettingsEdit(RenderSettings(spp=8), 2),
        SceneEdit(scene, (32, 24), 3), PickRequest(0.25, 0.75, 7), TargetSpp(16), Pause(True),
        ExportStart(4, request), Stop()]
    assert worker.take_messages(block=False) == [] and worker.take_frame() is None


def test_the_render_loop_imports_no_qt():
    code = ("import lenslab.gui.render_loop, sys; "
            "print([m for m in sys.modules if m.startswith(('PySide6', 'shiboken6'))])")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"


@pytest.mark.smoke
def test_the_preview_is_enlarged_bilinearly_between_pixel_centres():
    import numpy as np

    from lenslab.gui.render_loop import upscale_smooth

    rng = np.random.default_rng(3)
    small = rng.random((5, 7, 3), dtype=np.float32)
    big = upscale_smooth(small, 28, 20)  # four times each way
    assert big.shape == (20, 28, 3) and big.dtype == np.float32
    # Each enlarged pixel's centre maps to (x + 0.5) / 4 - 0.5 in the small one: blended from its four neighbours.
    for y, x in [(0, 0), (3, 5), (10, 13), (19, 27), (7, 2)]:
        sy, sx = min(max((y + 0.5) / 4 - 0.5, 0), 4), min(max((x + 0.5) / 4 - 0.5, 0), 6)
        y0, x0 = int(sy), int(sx)
        y1, x1 = min(y0 + 1, 4), min(x0 + 1, 6)
        fy, fx = sy - y0, sx - x0
        expected = ((1 - fy) * ((1 - fx) * small[y0, x0] + fx * small[y0, x1])
                    + fy * ((1 - fx) * small[y1, x0] + fx * small[y1, x1]))
        np.testing.assert_allclose(big[y, x], expected, rtol=1e-5, atol=1e-6)
    quantised = (small * 255).astype(np.uint8)
    eight = upscale_smooth(quantised, 28, 20)  # 8-bit in, 8-bit out, rounded to the nearest
    exact = upscale_smooth(quantised.astype(np.float32), 28, 20)
    assert eight.dtype == np.uint8 and np.abs(eight - exact).max() <= 0.5 + 1e-4
