"""The render worker's queue: typed messages, coalesced so that only the latest edit of each kind is applied.

No thread and no GL context: the worker's drain step is driven directly, with its appliers recording what
reaches them."""

from __future__ import annotations

import pytest

from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.scene import RenderSettings, Scene


@pytest.fixture
def worker(qapp):
    from lenslab.gui.worker import RenderWorker

    w = RenderWorker()
    w.applied = []
    w._apply_scene = lambda edit: w.applied.append(edit)
    w._apply_camera = lambda edit: w.applied.append(edit)
    w._apply_settings = lambda edit: w.applied.append(edit)
    w._pick = lambda request: w.applied.append(request)
    return w


def test_only_the_latest_camera_is_applied_and_a_move_is_not_forgotten(worker):
    from lenslab.gui.worker import CameraEdit

    moved, refocused = ThinLensCamera(position=(0, 1, 4)), ThinLensCamera(focus_distance_m=2.0)
    worker.set_camera(moved, 64, 48, generation=1, view_changed=True)
    worker.set_camera(refocused, 64, 48, generation=2, view_changed=False)
    worker._drain(block=False)
    assert worker.applied == [CameraEdit(refocused, (64, 48), 2, view_changed=True)]


def test_a_new_scene_supersedes_the_edits_queued_before_it(worker):
    from lenslab.gui.worker import SceneEdit, SettingsEdit

    scene = Scene()
    worker.set_camera(ThinLensCamera(), 64, 48, generation=1)
    worker.set_settings(RenderSettings(spp=8), generation=2)
    worker.set_scene(scene, 32, 24, generation=3)
    worker.set_settings(RenderSettings(spp=16), generation=4)
    worker._drain(block=False)
    assert worker.applied == [SceneEdit(scene, (32, 24), 3), SettingsEdit(RenderSettings(spp=16), 4)]


def test_picks_follow_the_edits_they_were_asked_after_and_stop_ends_the_drain(worker):
    from lenslab.gui.worker import CameraEdit, PickRequest

    camera = ThinLensCamera()
    worker.request_pick(0.25, 0.75, request_id=7)
    worker.set_camera(camera, 64, 48, generation=5)
    worker._drain(block=False)
    assert worker.applied == [CameraEdit(camera, (64, 48), 5, True), PickRequest(0.25, 0.75, 7)]
    worker.applied.clear()
    worker.stop()
    worker.set_camera(camera, 64, 48, generation=6)
    worker._drain(block=False)
    assert worker.applied == [] and worker._stop.is_set()


def test_pause_and_target_change_the_worker_state(worker):
    worker.set_target_spp(16)
    worker.set_paused(True)
    worker._drain(block=False)
    assert worker._target_spp == 16 and worker._paused


def test_pausing_or_starting_an_export_republishes_the_picture_with_its_linear_image(worker):
    # The last picture stays up while paused or exporting: it must come with the radiance behind it, or the
    # pixel readout answers from an older one.
    from lenslab.gui.worker import ExportRequest

    republished = []
    worker._republish = lambda with_linear: republished.append(with_linear)
    worker.set_paused(True)
    worker._drain(block=False)
    assert republished == [True]
    worker.set_paused(True)  # already paused: nothing new to show
    worker.set_paused(False)
    worker._drain(block=False)
    assert republished == [True]

    started = []
    worker._start_export = lambda start: started.append(start) or len(started) == 1  # the second one fails
    request = ExportRequest(scene=Scene(), path="shot.exr", target_spp=4, seconds=None, exposure_stops=0.0,
                            tone_map="filmic")
    worker.start_export(1, request)
    worker._drain(block=False)
    assert republished == [True, True]
    worker.start_export(2, request)
    worker._drain(block=False)
    assert len(started) == 2 and republished == [True, True]
