"""The render worker: a thread with its own GL context that keeps the viewport's image converging.

The GUI thread never touches the GPU. It sends the worker immutable copies of what changed (a whole scene, a
camera, render settings) through a queue (the methods below, each a typed message of gui/render_loop.py). The
thread makes the renderer, then takes what came in, hands it to a ``RenderLoop`` and lets the loop render one
bounded dispatch, over and over; what the loop does, and why, is render_loop.py's to tell. It waits on the queue
only when the loop has nothing to render.

Results go back through Qt signals (queued across threads): the loop reports to ``LoopEvents``, and the worker's
emits the signal of the same name. Frames are coalesced: the loop keeps only the newest and signals once until
the GUI has taken it (``take_frame``), so a busy GUI never builds up a backlog.
"""

from __future__ import annotations

import queue
import threading
import traceback

from PySide6.QtCore import QThread, Signal

# The messages, results and constants live with the loop (Qt-free); the studio imports them from here.
from lenslab.gui.render_loop import (  # noqa: F401
    DENOISE_MIN_INTERVAL,
    EXPORT_PROGRESS_INTERVAL,
    FRAME_INTERVAL,
    GBUFFER_INTERVAL,
    HOLD_SECONDS,
    HOLD_SPP,
    LINEAR_INTERVAL,
    PREVIEW_DIVISOR,
    PREVIEW_MIN_PIXELS,
    VIEWPORT_DISPATCH_SECONDS,
    CameraEdit,
    DenoiseEdit,
    DisplayEdit,
    ExportCancel,
    ExportProgress,
    ExportRequest,
    ExportStart,
    Frame,
    GBuffer,
    MeterReading,
    MeterSpot,
    Pause,
    PickRequest,
    PickResult,
    RegionEdit,
    RenderLoop,
    SceneEdit,
    SettingsEdit,
    Stop,
    TargetSpp,
    WorkNote,
    opaque,
    preview_size,
    upscale_smooth,
)

MESSAGE_WAIT_SECONDS = 0.2  # an idle worker looks at its stop flag this often


class RenderWorker(QThread):
    device_ready = Signal(dict)  # renderer.describe()
    device_failed = Signal(str)  # no GL context: nothing will render
    crashed = Signal(str)  # an unexpected error stopped the worker
    frame_ready = Signal()  # take it with take_frame()
    gbuffer_ready = Signal(object)  # GBuffer
    pick_ready = Signal(object)  # PickResult
    restarted = Signal(int)  # generation: accumulation restarted for this edit
    working = Signal(object)  # WorkNote: what is under way before the edit's picture is shown
    render_warnings = Signal(list)  # lines the scene's packing warned about, each once per scene
    scene_failed = Signal(int, str)  # generation, one-line reason: the scene cannot be rendered
    export_progress = Signal(object)  # ExportProgress
    export_finished = Signal(int, str)  # request id, path written
    export_failed = Signal(int, str)
    export_cancelled = Signal(int)

    def __init__(self, device_index: int | None = None, dispatch_seconds: float = VIEWPORT_DISPATCH_SECONDS,
                 parent=None):
        super().__init__(parent)
        self.setObjectName("LensLab render worker")
        self.device_index = device_index
        self.dispatch_seconds = dispatch_seconds
        self._queue: queue.Queue = queue.Queue()
        self._stop = threading.Event()
        self._loop: RenderLoop | None = None  # made in run(), on the worker thread; kept for take_frame

    # -- the GUI thread's side ---------------------------------------------------------------------------------
    def set_scene(self, scene, width: int, height: int, generation: int, margin: float | None = None) -> None:
        self._queue.put(SceneEdit(scene, (int(width), int(height)), generation, margin))

    def set_camera(self, camera, width: int, height: int, generation: int, view_changed: bool = True,
                   margin: float | None = None) -> None:
        self._queue.put(CameraEdit(camera, (int(width), int(height)), generation, view_changed, margin))

    def set_region(self, region: tuple[int, int, int, int] | None, generation: int) -> None:
        """Refine only this rectangle of the viewport's picture (pixels), or the whole picture again (None)."""
        self._queue.put(RegionEdit(None if region is None else tuple(int(v) for v in region), generation))

    def set_denoise(self, on: bool) -> None:
        self._queue.put(DenoiseEdit(bool(on)))

    def set_settings(self, settings, generation: int) -> None:
        self._queue.put(SettingsEdit(settings, generation))

    def set_paused(self, paused: bool) -> None:
        self._queue.put(Pause(bool(paused)))

    def set_display(self, view) -> None:
        """The viewport's view transform (a resolved lenslab.colour_management.view.ViewTransform), for the
        pictures the worker makes from now on."""
        self._queue.put(DisplayEdit(view))

    def set_meter_spot(self, x: float, y: float) -> None:
        """Where the spot meter reads: fractions of the frame's width and height from its top left."""
        self._queue.put(MeterSpot((float(x), float(y))))

    def set_target_spp(self, spp: int | None) -> None:
        self._queue.put(TargetSpp(spp))

    def request_pick(self, u: float, v: float, request_id: int) -> None:
        """Ask for the surface at (u, v) in [0, 1] image coordinates (0, 0 top left); answered by pick_ready."""
        self._queue.put(PickRequest(float(u), float(v), request_id))

    def start_export(self, request_id: int, request: ExportRequest) -> None:
        self._queue.put(ExportStart(request_id, request))

    def cancel_export(self, request_id: int) -> None:
        self._queue.put(ExportCancel(request_id))

    def stop(self) -> None:
        """Ask the worker to finish; it does within one dispatch. Follow with wait()."""
        self._stop.set()
        self._queue.put(Stop())

    def take_frame(self) -> Frame | None:
        loop = self._loop
        return None if loop is None else loop.take_frame()

    # -- the worker thread ----------------------------------------------------------------------------------
    def take_messages(self, block: bool) -> list:
        """The messages sent since the last call, oldest first; with ``block``, waits up to
        MESSAGE_WAIT_SECONDS for the first (an empty list if none came)."""
        messages = []
        try:
            messages.append(self._queue.get(timeout=MESSAGE_WAIT_SECONDS) if block else self._queue.get_nowait())
            while True:
                messages.append(self._queue.get_nowait())
        except queue.Empty:
            pass
        return messages

    def run(self) -> None:
        from lenslab.render.tracer import Renderer

        try:
            renderer = Renderer(self.device_index)
        except Exception as exc:  # GLUnavailable, or a driver's own exception
            self.device_failed.emit(str(exc) or type(exc).__name__)
            return
        loop = RenderLoop(renderer, _SignalEvents(self), self.dispatch_seconds,
                          more_messages=lambda: not self._queue.empty())
        self._loop = loop
        try:
            loop.start()
            while not self._stop.is_set():
                loop.handle(self.take_messages(block=not loop.busy))
                if loop.stopped:
                    self._stop.set()
                if self._stop.is_set():
                    break
                loop.step()
        except Exception:
            self.crashed.emit(traceback.format_exc(limit=6))
        finally:
            loop.release()


class _SignalEvents:
    """The loop's LoopEvents: each one is the worker's signal of the same name, queued to the GUI thread."""

    def __init__(self, worker: RenderWorker):
        self._worker = worker

    def device_ready(self, info: dict) -> None:
        self._worker.device_ready.emit(info)

    def frame_ready(self) -> None:
        self._worker.frame_ready.emit()

    def gbuffer_ready(self, gbuffer: GBuffer) -> None:
        self._worker.gbuffer_ready.emit(gbuffer)

    def pick_ready(self, result: PickResult) -> None:
        self._worker.pick_ready.emit(result)

    def restarted(self, generation: int) -> None:
        self._worker.restarted.emit(generation)

    def working(self, note: WorkNote) -> None:
        self._worker.working.emit(note)

    def render_warnings(self, lines: list) -> None:
        self._worker.render_warnings.emit(list(lines))

    def scene_failed(self, generation: int, reason: str) -> None:
        self._worker.scene_failed.emit(generation, reason)

    def export_progress(self, progress: ExportProgress) -> None:
        self._worker.export_progress.emit(progress)

    def export_finished(self, request_id: int, path: str) -> None:
        self._worker.export_finished.emit(request_id, path)

    def export_failed(self, request_id: int, reason: str) -> None:
        self._worker.export_failed.emit(request_id, reason)

    def export_cancelled(self, request_id: int) -> None:
        self._worker.export_cancelled.emit(request_id)
