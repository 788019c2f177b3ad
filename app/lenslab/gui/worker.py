"""The render worker: a thread with its own GL context that keeps the viewport's image converging.

The GUI thread never touches the GPU. It sends the worker immutable copies of what changed (a whole scene, a
camera, render settings) through a queue; the worker applies only the latest of each, restarts accumulation and
goes on rendering in bounded dispatches (``RenderSession.step``), publishing the image several times a second.
Edits are therefore seen within one dispatch (about a tenth of a second) however long a render has run.

After each restart the worker first renders one pass at a quarter of the resolution (a preview that appears
within a fraction of a second), then the full resolution, whose first pass fills in over the preview tile by
tile. Once per change of view it casts one ray per pixel through the same kd-tree to find the node and the depth
under every pixel: the viewport outlines the selection with the first and shows the plane of focus with the
second. Click-to-focus picks and exports (a second ``RenderSession`` on the same context) run here too.

Results go back through Qt signals (queued across threads). Frames are coalesced: the worker keeps only the
newest and signals once until the GUI has taken it, so a busy GUI never builds up a backlog.
"""

from __future__ import annotations

import math
import queue
import threading
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PySide6.QtCore import QThread, Signal

PREVIEW_DIVISOR = 4  # the preview pass renders at 1/4 of the width and height
PREVIEW_MIN_PIXELS = 256 * 256  # images smaller than this skip the preview pass
FRAME_INTERVAL = 0.25  # seconds between published frames while a pass is in progress
EXPORT_PROGRESS_INTERVAL = 0.1


@dataclass(frozen=True)
class Frame:
    image: np.ndarray  # (H, W, 3) float32 linear radiance; pixels still without samples show the preview
    width: int
    height: int
    samples_per_pixel: int
    target_spp: int | None
    samples_per_second: float
    elapsed_seconds: float  # wall time since the last restart
    generation: int
    preview: bool  # only the quarter-resolution preview so far
    converged: bool  # reached the target sample count


@dataclass(frozen=True)
class GBuffer:
    """What is under each pixel of the viewport image (through the lens centre)."""

    node_index: np.ndarray  # (H, W) int32 depth-first node index, -1 for the background
    depth: np.ndarray  # (H, W) float32 distance along the view axis in metres, inf for the background
    generation: int


@dataclass(frozen=True)
class PickResult:
    request_id: int
    generation: int
    hit: bool
    depth: float = math.nan  # along the view axis: the focus distance that makes the point sharp
    point: tuple = ()
    node_index: int = -1


@dataclass(frozen=True)
class ExportRequest:
    scene: object  # a Scene copy whose camera resolution is the export size
    path: Path
    target_spp: int | None = None  # stop at this many samples per pixel ...
    seconds: float | None = None  # ... or after this long (whichever comes first when both are given)
    exposure_stops: float = 0.0
    tone_map: str = "clamp"


@dataclass(frozen=True)
class ExportProgress:
    request_id: int
    samples_per_pixel: int
    target_spp: int | None
    elapsed_seconds: float
    seconds: float | None
    fraction: float
    samples_per_second: float


def preview_size(width: int, height: int) -> tuple[int, int]:
    return max(1, math.ceil(width / PREVIEW_DIVISOR)), max(1, math.ceil(height / PREVIEW_DIVISOR))


def upscale_nearest(image: np.ndarray, width: int, height: int) -> np.ndarray:
    h, w = image.shape[:2]
    rows = np.minimum((np.arange(height) * h) // height, h - 1)
    cols = np.minimum((np.arange(width) * w) // width, w - 1)
    return image[rows][:, cols]


class RenderWorker(QThread):
    device_ready = Signal(dict)  # renderer.describe()
    device_failed = Signal(str)  # no GL context: nothing will render
    crashed = Signal(str)  # an unexpected error stopped the worker
    frame_ready = Signal()  # take it with take_frame()
    gbuffer_ready = Signal(object)  # GBuffer
    pick_ready = Signal(object)  # PickResult
    restarted = Signal(int)  # generation: accumulation restarted for this edit
    scene_failed = Signal(int, str)  # generation, one-line reason: the scene cannot be rendered
    export_progress = Signal(object)  # ExportProgress
    export_finished = Signal(int, str)  # request id, path written
    export_failed = Signal(int, str)
    export_cancelled = Signal(int)

    def __init__(self, device_index: int | None = None, dispatch_seconds: float = 0.1, parent=None):
        super().__init__(parent)
        self.setObjectName("LensLab render worker")
        self.device_index = device_index
        self.dispatch_seconds = dispatch_seconds
        self._queue: queue.Queue = queue.Queue()
        self._stop = threading.Event()
        self._frame_lock = threading.Lock()
        self._frame: Frame | None = None
        self._frame_signalled = False
        # Worker-thread state (touched only in run()).
        self._renderer = None
        self._session = None
        self._size = (0, 0)
        self._generation = 0
        self._phase = "idle"  # idle | preview | full | done | error
        self._paused = False
        self._target_spp: int | None = 1024
        self._scene_ok = False
        self._camera_ok = True
        self._preview_image = None
        self._gbuffer_due = False
        self._gbuffer_size: tuple[int, int] | None = None
        self._restart_time = 0.0
        self._last_publish = 0.0
        self._published_spp = -1
        self._export = None

    # -- the GUI thread's side ---------------------------------------------------------------------------------
    def set_scene(self, scene, width: int, height: int, generation: int) -> None:
        self._queue.put(("scene", scene, (int(width), int(height)), generation))

    def set_camera(self, camera, width: int, height: int, generation: int, view_changed: bool = True) -> None:
        self._queue.put(("camera", camera, (int(width), int(height)), generation, view_changed))

    def set_settings(self, settings, generation: int) -> None:
        self._queue.put(("settings", settings, generation))

    def set_paused(self, paused: bool) -> None:
        self._queue.put(("pause", bool(paused)))

    def set_target_spp(self, spp: int | None) -> None:
        self._queue.put(("target", spp))

    def request_pick(self, u: float, v: float, request_id: int) -> None:
        """Ask for the surface at (u, v) in [0, 1] image coordinates (0, 0 top left); answered by pick_ready."""
        self._queue.put(("pick", float(u), float(v), request_id))

    def start_export(self, request_id: int, request: ExportRequest) -> None:
        self._queue.put(("export", request_id, request))

    def cancel_export(self, request_id: int) -> None:
        self._queue.put(("cancel_export", request_id))

    def stop(self) -> None:
        """Ask the worker to finish; it does within one dispatch. Follow with wait()."""
        self._stop.set()
        self._queue.put(("stop",))

    def take_frame(self) -> Frame | None:
        with self._frame_lock:
            frame, self._frame = self._frame, None
            self._frame_signalled = False
        return frame

    # -- the worker thread ----------------------------------------------------------------------------------
    def run(self) -> None:
        from lenslab.render.tracer import Renderer

        try:
            self._renderer = Renderer(self.device_index)
        except Exception as exc:  # GLUnavailable, or a driver's own exception
            self.device_failed.emit(str(exc) or type(exc).__name__)
            return
        try:
            self.device_ready.emit(self._renderer.describe())
            while not self._stop.is_set():
                self._drain(block=not self._busy())
                if self._stop.is_set():
                    break
                if self._export is not None:
                    self._export_step()
                elif self._busy():
                    self._viewport_step()
        except Exception:
            self.crashed.emit(traceback.format_exc(limit=6))
        finally:
            self._release()

    def _busy(self) -> bool:
        if self._export is not None:
            return True
        return (not self._paused and self._session is not None and self._scene_ok and self._camera_ok
                and self._phase in ("preview", "full"))

    def _release(self) -> None:
        if self._export is not None:
            self._export["session"].release()
            self._export = None
        if self._session is not None:
            self._session.release()
            self._session = None
        if self._renderer is not None:
            self._renderer.release()
            self._renderer = None

    def _drain(self, block: bool) -> None:
        messages = []
        try:
            messages.append(self._queue.get(timeout=0.2) if block else self._queue.get_nowait())
            while True:
                messages.append(self._queue.get_nowait())
        except queue.Empty:
            pass
        scene_msg = camera_msg = settings_msg = None
        for msg in messages:
            kind = msg[0]
            if kind == "stop":
                self._stop.set()
                return
            if kind == "scene":
                scene_msg, camera_msg, settings_msg = msg, None, None
            elif kind == "camera":
                # Keep "the view moved" if any of the coalesced camera edits moved it.
                moved = msg[4] or (camera_msg is not None and camera_msg[4])
                camera_msg = msg[:4] + (moved,)
            elif kind == "settings":
                settings_msg = msg
            elif kind == "pause":
                self._paused = msg[1]
                if not self._paused and self._phase == "done":
                    self._phase = "full"  # the target may have been raised meanwhile
            elif kind == "target":
                self._target_spp = msg[1]
                if self._phase == "done":
                    self._phase = "full"
        if scene_msg is not None:
            self._apply_scene(*scene_msg[1:])
        if camera_msg is not None:
            self._apply_camera(*camera_msg[1:])
        if settings_msg is not None:
            self._apply_settings(*settings_msg[1:])
        for msg in messages:
            if msg[0] == "pick":
                self._pick(*msg[1:])
            elif msg[0] == "export":
                self._start_export(*msg[1:])
            elif msg[0] == "cancel_export":
                self._cancel_export(msg[1])

    # -- applying edits ------------------------------------------------------------------------------------
    def _apply_scene(self, scene, size, generation) -> None:
        from lenslab.render.tracer import RenderSession

        try:
            if self._session is None:
                self._session = RenderSession(self._renderer, scene, width=size[0], height=size[1],
                                              dispatch_seconds=self.dispatch_seconds)
            else:
                self._session.set_scene(scene, width=size[0], height=size[1])
        except Exception as exc:  # SceneError, SceneTooLarge, a camera ValueError, a mesh that fails to load
            self._scene_ok = False
            self._phase = "error"
            self._generation = generation
            self.scene_failed.emit(generation, _one_line(exc))
            return
        self._scene_ok = self._camera_ok = True
        self._size = size
        self._restart(generation, view_changed=True)

    def _apply_camera(self, camera, size, generation, view_changed) -> None:
        if self._session is None:
            return
        try:
            self._session.set_camera(camera)
        except Exception as exc:
            self._camera_ok = False
            self._phase = "error"
            self._generation = generation
            self.scene_failed.emit(generation, _one_line(exc))
            return
        self._camera_ok = True
        if not self._scene_ok:
            self._generation = generation
            return
        self._size = size
        self._restart(generation, view_changed=view_changed or size != self._gbuffer_size)

    def _apply_settings(self, settings, generation) -> None:
        if self._session is None:
            return
        self._session.set_settings(settings)
        if self._scene_ok and self._camera_ok:
            self._restart(generation, view_changed=False)

    def _resize(self, width: int, height: int) -> None:
        # RenderSession keeps the scene on the GPU; a new size only needs a new accumulation buffer, which
        # reset() allocates when width * height changed.
        session = self._session
        session.width, session.height = int(width), int(height)
        session.reset()

    def _restart(self, generation: int, view_changed: bool) -> None:
        self._generation = generation
        self._preview_image = None
        self._published_spp = -1
        self._restart_time = time.perf_counter()
        w, h = self._size
        if w * h >= PREVIEW_MIN_PIXELS:
            self._resize(*preview_size(w, h))
            self._phase = "preview"
        else:
            self._resize(w, h)
            self._phase = "full"
        if view_changed:
            self._gbuffer_due = True
        self.restarted.emit(generation)

    # -- rendering the viewport ------------------------------------------------------------------------------
    def _viewport_step(self) -> None:
        session = self._session
        if self._phase == "preview":
            session.step(self.dispatch_seconds / 2, target_spp=1)
            if session.samples_per_pixel >= 1:
                self._preview_image = session.image()
                w, h = self._size
                self._publish(upscale_nearest(self._preview_image, w, h), preview=True)
                self._resize(w, h)
                self._phase = "full"
            return
        if self._gbuffer_due and self._queue.empty():
            self._gbuffer_due = False
            self._compute_gbuffer()
            return
        target = self._target_spp
        progress = session.step(self.dispatch_seconds, target)
        done = target is not None and progress.samples_per_pixel >= target
        now = time.perf_counter()
        if done or progress.samples_per_pixel != self._published_spp or now - self._last_publish >= FRAME_INTERVAL:
            self._publish_session(done)
        if done:
            self._phase = "done"

    def _publish_session(self, converged: bool) -> None:
        from lenslab.render.film import resolve

        accumulation = self._session.accumulation()
        image = resolve(accumulation)
        if self._preview_image is not None:
            empty = accumulation[..., 3] <= 0
            if empty.any():
                w, h = self._size
                image[empty] = upscale_nearest(self._preview_image, w, h)[empty]
        self._publish(image, preview=False, converged=converged)

    def _publish(self, image: np.ndarray, preview: bool, converged: bool = False) -> None:
        session = self._session
        progress = session.progress(self._target_spp)
        spp = 0 if preview else session.samples_per_pixel
        frame = Frame(image=image, width=image.shape[1], height=image.shape[0], samples_per_pixel=spp,
                      target_spp=self._target_spp, samples_per_second=progress.samples_per_second,
                      elapsed_seconds=time.perf_counter() - self._restart_time, generation=self._generation,
                      preview=preview, converged=converged)
        self._published_spp = spp
        self._last_publish = time.perf_counter()
        with self._frame_lock:
            self._frame = frame
            signal = not self._frame_signalled
            self._frame_signalled = True
        if signal:
            self.frame_ready.emit()

    def _gpu_scene(self):
        session = self._session
        return getattr(session, "gpu_scene", None) or getattr(session, "_gpu_scene", None)

    def _compute_gbuffer(self) -> None:
        from lenslab.render.raycast import cast_rays

        session = self._session
        gpu_scene = self._gpu_scene()
        if gpu_scene is None:
            return
        w, h = self._size
        frame = session.camera.frame(w, h)
        origins, directions = frame.rays(frame.pixel_centres())
        hits = cast_rays(self._renderer, gpu_scene, origins, directions)
        prim_node = session.flat_scene.prim_node
        node_index = np.where(hits.prim >= 0, prim_node[np.maximum(hits.prim, 0)], -1).astype(np.int32)
        depth = np.where(hits.prim >= 0, hits.t * (directions @ frame.forward), np.inf).astype(np.float32)
        self._gbuffer_size = (w, h)
        self.gbuffer_ready.emit(GBuffer(node_index.reshape(h, w), depth.reshape(h, w), self._generation))

    def _pick(self, u: float, v: float, request_id: int) -> None:
        session = self._session
        if session is None or not (self._scene_ok and self._camera_ok):
            self.pick_ready.emit(PickResult(request_id, self._generation, False))
            return
        pick = session.pick(u * session.width, v * session.height)
        if pick is None:
            self.pick_ready.emit(PickResult(request_id, self._generation, False))
            return
        node_index = int(session.flat_scene.prim_node[pick.prim])
        self.pick_ready.emit(PickResult(request_id, self._generation, True, float(pick.depth),
                                        tuple(float(c) for c in pick.point), node_index))

    # -- export ----------------------------------------------------------------------------------------------
    def _start_export(self, request_id: int, request: ExportRequest) -> None:
        from lenslab.render.tracer import RenderSession

        if self._export is not None:
            self.export_failed.emit(request_id, "another export is still running")
            return
        try:
            w, h = request.scene.camera.resolution
            session = RenderSession(self._renderer, request.scene, width=w, height=h,
                                    dispatch_seconds=self.dispatch_seconds)
        except Exception as exc:
            self.export_failed.emit(request_id, _one_line(exc))
            return
        self._export = {"id": request_id, "request": request, "session": session,
                        "start": time.perf_counter(), "last": 0.0}

    def _cancel_export(self, request_id: int) -> None:
        export = self._export
        if export is None or export["id"] != request_id:
            return
        export["session"].release()
        self._export = None
        self.export_cancelled.emit(request_id)

    def _export_step(self) -> None:
        from lenslab.cli import image_metadata
        from lenslab.render.film import write_image

        export = self._export
        request: ExportRequest = export["request"]
        session = export["session"]
        elapsed = time.perf_counter() - export["start"]
        out_of_time = request.seconds is not None and elapsed >= request.seconds
        enough = request.target_spp is not None and session.samples_per_pixel >= request.target_spp
        if not (out_of_time or enough):
            budget = self.dispatch_seconds
            if request.seconds is not None:
                budget = max(0.0, min(budget, request.seconds - elapsed))
            progress = session.step(budget, request.target_spp)
            now = time.perf_counter()
            if now - export["last"] >= EXPORT_PROGRESS_INTERVAL:
                export["last"] = now
                elapsed = now - export["start"]
                fractions = []
                if request.target_spp:
                    fractions.append(progress.samples_per_pixel / request.target_spp)
                if request.seconds:
                    fractions.append(elapsed / request.seconds)
                self.export_progress.emit(ExportProgress(
                    export["id"], progress.samples_per_pixel, request.target_spp, elapsed, request.seconds,
                    min(1.0, max(fractions) if fractions else 0.0), progress.samples_per_second))
            return
        # Done: every pixel gets at least one sample, then the file is written whole (or not at all).
        self._export = None
        try:
            if session.samples_per_pixel == 0:
                session.step(0.0, 1)
            spp = session.samples_per_pixel
            path = write_image(request.path, session.image(), image_metadata(request.scene, spp),
                               exposure_stops=request.exposure_stops, tone_map_operator=request.tone_map)
        except Exception as exc:
            self.export_failed.emit(export["id"], _one_line(exc))
        else:
            self.export_finished.emit(export["id"], str(path))
        finally:
            session.release()


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__
