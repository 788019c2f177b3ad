"""The link between the open document and the render worker, on the GUI thread.

It listens to the scene's own events (``doc.model.events``) and sends the worker the cheapest message that
brings it up to date (a camera, the render settings, or a copy of the whole scene), numbering each edit (its
*generation*) so that the GUI can tell which frames already show it. It also decides the viewport's render size
(the widget's size times the chosen resolution scale, independent of the export's resolution; or the export's
own pixels), routes pick answers to whoever asked, and runs exports.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Callable

from PySide6.QtCore import QObject, Signal

from lenslab.gui.document import copy_scene, listen
from lenslab.gui.worker import VIEWPORT_DISPATCH_SECONDS, ExportRequest, Frame, RenderWorker

#: Viewport resolution: a fraction of the viewport widget's pixels; "auto" (all of them on a GPU, at most
#: AUTO_LONG_EDGE on the long side on a CPU device such as llvmpipe); or "export", the export's own pixels.
QUALITIES = {"auto": None, "full": 1.0, "half": 0.5, "quarter": 0.25, "export": None}
AUTO_LONG_EDGE = 800
#: Around the sensor's gate the viewport shows this much more of the scene (a fraction of the frame, each side).
VIEW_MARGIN = 0.04
SAMPLE_LIMITS = (16, 64, 256, 1024, 4096, None)


def viewport_size(resolution: tuple[int, int], quality: str, widget_size: tuple[int, int] | None = None,
                  cpu_device: bool = True) -> tuple[int, int]:
    """The viewport's picture in pixels: the widget's size scaled by the quality (the export's resolution with
    "export", or while the widget's size is not known yet)."""
    if quality == "export" or widget_size is None:
        w, h = resolution
        fraction = 1.0 if quality == "export" else min(1.0, AUTO_LONG_EDGE / max(w, h))
    else:
        w, h = widget_size
        fraction = QUALITIES.get(quality)
        if fraction is None:
            fraction = min(1.0, AUTO_LONG_EDGE / max(w, h)) if cpu_device else 1.0
    return max(1, round(w * fraction)), max(1, round(h * fraction))


class RenderController(QObject):
    frame_ready = Signal(object)  # Frame
    gbuffer_ready = Signal(object)
    restarted = Signal(int)
    working = Signal(object)  # WorkNote of the latest edit, while its picture is not shown yet
    render_warnings = Signal(list)  # what rendering the scene warned about (a missing texture...), once each
    device_ready = Signal(dict)
    render_error = Signal(str)  # "" when an edit made the scene renderable again
    export_progress = Signal(object)
    export_finished = Signal(int, str)
    export_failed = Signal(int, str)
    export_cancelled = Signal(int)

    def __init__(self, doc, device_index: int | None = None, dispatch_seconds: float = VIEWPORT_DISPATCH_SECONDS,
                 quality: str = "auto", target_spp: int | None = 1024, parent: QObject | None = None):
        super().__init__(parent)
        self.doc = doc
        self.quality = quality if quality in QUALITIES else "auto"
        self.target_spp = target_spp
        self.paused = False
        self.generation = 0
        self.scene_generation = 0  # the generation that sent another scene (File > Open, New): not an edit of this one
        self.work_note = None  # the latest WorkNote
        self.device: dict | None = None
        self.device_error: str | None = None
        self.error = ""
        self.last_frame: Frame | None = None
        self.last_gbuffer = None
        self._ids = itertools.count(1)
        self._pick_callbacks: dict[int, Callable] = {}
        self._widget_size: tuple[int, int] | None = None
        self._size = self._view_size()
        self.region: tuple[int, int, int, int] | None = None
        self.denoise = False
        self._error_generation = -1
        self._shut_down = False
        self.worker = RenderWorker(device_index, dispatch_seconds)
        w = self.worker
        w.device_ready.connect(self._device_ready)
        w.device_failed.connect(self._device_failed)
        w.crashed.connect(self._crashed)
        w.frame_ready.connect(self._take_frame)
        w.gbuffer_ready.connect(self._gbuffer)
        w.pick_ready.connect(self._pick_answered)
        w.restarted.connect(self._restarted)
        w.working.connect(self._working)
        w.render_warnings.connect(self.render_warnings)
        w.scene_failed.connect(self._scene_failed)
        w.export_progress.connect(self.export_progress)
        w.export_finished.connect(self.export_finished)
        w.export_failed.connect(self.export_failed)
        w.export_cancelled.connect(self.export_cancelled)
        w.set_target_spp(target_spp)
        listen(doc.model.events.changed, self, self._on_change)
        w.start()
        self.send_scene(another_scene=True)

    # -- keeping the worker up to date ----------------------------------------------------------------------
    def _next_generation(self) -> int:
        self.generation += 1
        return self.generation

    @property
    def size(self) -> tuple[int, int]:
        return self._size

    @property
    def margin(self) -> float | None:
        """How the viewport frames the camera: None, as the export; else the margin around the sensor's gate."""
        return None if self.quality == "export" or self._widget_size is None else VIEW_MARGIN

    def _view_size(self) -> tuple[int, int]:
        cpu = self.device is None or "llvmpipe" in str(self.device.get("renderer", "")).lower()
        return viewport_size(self.doc.scene.camera.resolution, self.quality, self._widget_size, cpu)

    def send_scene(self, another_scene: bool = False) -> None:
        """Send the worker a copy of the whole scene: ``another_scene`` when it is not the one on screen (File >
        Open, New), so that the picture shown until its own comes is known to be another scene's."""
        size = self._view_size()
        if size != self._size:
            self.region = None  # the worker drops a region whose picture changed size, as here
        self._size = size
        generation = self._next_generation()
        if another_scene:
            self.scene_generation = generation
        self.worker.set_scene(copy_scene(self.doc.scene), *self._size, generation, self.margin)

    def set_widget_size(self, width: int, height: int) -> None:
        """The viewport widget's size in device pixels: the picture follows it (except at "export" quality)."""
        size = (max(1, int(width)), max(1, int(height)))
        if size == self._widget_size:
            return
        self._widget_size = size
        if self._view_size() != self._size or self.quality != "export":
            self._send_camera(moved=True)

    def _send_camera(self, moved: bool) -> None:
        size = self._view_size()
        moved = moved or size != self._size
        if size != self._size:
            self.region = None
        self._size = size
        self.worker.set_camera(dataclasses.replace(self.doc.scene.camera), *size, self._next_generation(), moved,
                               self.margin)

    def set_region(self, region: tuple[int, int, int, int] | None) -> None:
        """Refine only this rectangle of the viewport's picture (x, y, width, height in its pixels), or all."""
        self.region = None if region is None else tuple(int(v) for v in region)
        self.worker.set_region(self.region, self._next_generation())

    def set_denoise(self, on: bool) -> None:
        """The viewport's pictures through the denoiser (display only: the render goes on as it was)."""
        self.denoise = bool(on)
        self.worker.set_denoise(self.denoise)

    def _on_change(self, change) -> None:
        if change.kind == "camera":
            self._send_camera(change.geometry or change.field[:1] == ("resolution",))
        elif change.kind == "render":
            if change.field == ("spp",):
                return  # the export default; the viewport has its own sample limit
            self.worker.set_settings(dataclasses.replace(self.doc.scene.render), self._next_generation())
        else:
            self.send_scene(another_scene=change.kind == "scene")

    def set_quality(self, quality: str) -> None:
        if quality in QUALITIES and quality != self.quality:
            self.quality = quality
            self.send_scene()

    def set_target_spp(self, spp: int | None) -> None:
        self.target_spp = spp
        self.worker.set_target_spp(spp)

    def set_paused(self, paused: bool) -> None:
        self.paused = paused
        self.worker.set_paused(paused)

    def set_display(self, view) -> None:
        """The viewport's view transform (a ViewTransform): the worker makes its pictures through it (display only,
        no restart). Checked here, so that a name the OCIO config lacks is refused on the GUI's side (a
        ColourConfigError) rather than stopping the render thread."""
        self.worker.set_display(view.resolved())

    def set_meter_spot(self, x: float, y: float) -> None:
        """Where the spot meter reads (fractions of the frame, top left); the picture is read again there."""
        self.worker.set_meter_spot(x, y)

    def restart(self) -> None:
        self.send_scene()

    # -- answers from the worker ---------------------------------------------------------------------------
    def _device_ready(self, info: dict) -> None:
        self.device = info
        if self._view_size() != self._size:  # "auto" renders more pixels on a GPU than on the CPU
            self._send_camera(moved=True)
        self.device_ready.emit(info)

    def _device_failed(self, message: str) -> None:
        self.device_error = message
        self.error = f"No OpenGL 4.3 device: {message}"
        self.render_error.emit(self.error)

    def _crashed(self, trace: str) -> None:
        last = trace.strip().splitlines()[-1] if trace.strip() else "unknown error"
        self.error = f"The renderer stopped: {last}"
        self.render_error.emit(self.error)

    def _take_frame(self) -> None:
        frame = self.worker.take_frame()
        if frame is None:
            return
        self.last_frame = frame
        self.frame_ready.emit(frame)

    def _gbuffer(self, gbuffer) -> None:
        self.last_gbuffer = gbuffer
        self.gbuffer_ready.emit(gbuffer)

    def _restarted(self, generation: int) -> None:
        if self.error and generation > self._error_generation:
            self.error = ""
            self.render_error.emit("")
        self.restarted.emit(generation)

    def _working(self, note) -> None:
        self.work_note = note
        self.working.emit(note)

    @property
    def picture_is_current(self) -> bool:
        """The picture on screen shows the latest edit (at full resolution), or the edit cannot render."""
        frame = self.last_frame
        if self.error and self._error_generation >= self.generation:
            return True
        return frame is not None and frame.generation >= self.generation and not frame.preview

    def _scene_failed(self, generation: int, message: str) -> None:
        self._error_generation = generation
        self.error = f"Cannot render: {message}"
        self.render_error.emit(self.error)

    # -- picking -----------------------------------------------------------------------------------------------
    def pick(self, u: float, v: float, callback: Callable) -> int:
        request_id = next(self._ids)
        self._pick_callbacks[request_id] = callback
        self.worker.request_pick(u, v, request_id)
        return request_id

    def _pick_answered(self, result) -> None:
        callback = self._pick_callbacks.pop(result.request_id, None)
        if callback is not None:
            callback(result)

    # -- export ------------------------------------------------------------------------------------------------
    def start_export(self, request: ExportRequest) -> int:
        request_id = next(self._ids)
        self.worker.start_export(request_id, request)
        return request_id

    def cancel_export(self, request_id: int) -> None:
        self.worker.cancel_export(request_id)

    # -- shutting down -----------------------------------------------------------------------------------------
    def shutdown(self, timeout_ms: int = 15000) -> bool:
        """Stop the worker (within a dispatch) and wait for it to release its GL context."""
        if not self._shut_down:
            self._shut_down = True
            self.doc.model.events.changed.disconnect(self._on_change)
        if not self.worker.isRunning():
            return True
        self.worker.stop()
        return self.worker.wait(timeout_ms)


def samples_text(frame: Frame) -> str:
    if frame.preview:
        return "preview ¼ res"
    target = f" / {frame.target_spp}" if frame.target_spp else ""
    return f"{frame.samples_per_pixel}{target} spp"


def rate_text(samples_per_second: float) -> str:
    if samples_per_second >= 1e6:
        return f"{samples_per_second / 1e6:.2f} M samples/s"
    return f"{samples_per_second / 1e3:.0f} k samples/s"


def elapsed_text(seconds: float) -> str:
    seconds = int(math.floor(seconds))
    if seconds >= 3600:
        return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"
    return f"{seconds // 60}:{seconds % 60:02d}"
