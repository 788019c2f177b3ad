"""The viewport's render loop: what the render worker's thread does, without the thread and without Qt.

The GUI thread never touches the GPU. It sends the worker immutable copies of what changed (a whole scene, a
camera, render settings) through a queue; the loop applies only the latest of each, restarts accumulation and
goes on rendering in bounded dispatches (``RenderSession.step``), publishing the image several times a second.
Edits are therefore seen within one dispatch (about a sixtieth of a second) however long a render has run.

The viewport's image is the widget's size (times a resolution scale), framed by ``ThinLensCamera.view_frame``:
the export's frame (the sensor's gate) with some of the scene around it. After each restart the loop first
renders one pass at a quarter of the resolution (a preview, enlarged smoothly), then the full resolution, whose
first pass fills in over the preview tile by tile. The picture on screen is never thrown away for a worse one:
after an edit the previous picture stays up until the new render has as many samples (up to HOLD_SPP), or for
at most HOLD_SECONDS, so a drag still shows the newest state several times a second. Pixels not rendered yet
(a first pass under way, or outside a render region) show the last picture. With the denoiser on, the pictures
are Intel Open Image Denoise's, from the beauty and the first-hit albedo and normal the tracer accumulates, and
raw samples are never shown: the denoised preview (marked as one) stands until the first full pass is done and
denoised in its turn. The full-resolution pictures are denoised off this thread, by a denoiser of their own
(``_DenoiseJob``), so that an edit made while one is denoised is rendered at once instead of waiting for a
picture it makes stale (on a CPU that takes a few tenths of a second). While the picture does not show the
latest edit yet, ``working`` says what the loop is doing and how far along (a scene's load step by step, a
kernel compiling, the preview, the first pass). Each frame's picture is made on the GPU through the viewport's
view transform (OpenColorIO's display, view and looks, the display exposure and contrast:
``RenderSession.display``), with the camera's own exposure added to the transform's exposure, so making it costs the
CPU no work per pixel; the linear image, for the viewport's pixel readout, comes along a few times a second, and the
light meter reads it as it comes (the frame's scene-linear luminance inside the sensor's gate,
``lenslab.optics.exposure.meter_luminance``). In the auto exposure mode that reading sets the picture's exposure
(``ThinLensCamera.exposure``). Once per change of view it casts one ray per pixel through the same kd-tree to find
the node and the depth under every pixel: the viewport outlines the selection with the first and shows the plane of
focus with the second. Click-to-focus picks and exports (a second ``RenderSession`` on the same context, a
``RenderJob``) run here too.

``RenderLoop`` is driven by its owner, one call at a time on one thread: ``handle(messages)`` with what the GUI
sent since the last call, then ``step()`` (one dispatch, while ``busy``). Its state is ``phase``, a ``Phase``.
Results go out through a ``LoopEvents`` object (the worker's turns each into a Qt signal, queued across
threads). Frames are coalesced: the loop keeps only the newest and reports ``frame_ready`` once until the GUI has
taken it (``take_frame``, from any thread), so a busy GUI never builds up a backlog.

No Qt here, directly or indirectly (tests/gui/test_worker_messages.py checks): gui/worker.py carries the loop to
a thread and its results to Qt signals.
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from concurrent.futures import wait as wait_for_futures
from dataclasses import dataclass
from enum import Enum
from pathlib import Path
from typing import Callable, Protocol

import numpy as np

from lenslab.colour_management.view import EXPOSURE_RANGE, ViewTransform
from lenslab.colour_management.working_space import luminance
from lenslab.messages import one_line
from lenslab.optics.exposure import Exposure, meter_luminance
from lenslab.render.film import display_pixels, to_8bit

PREVIEW_DIVISOR = 4  # the preview pass renders at 1/4 of the width and height
PREVIEW_MIN_PIXELS = 256 * 256  # images smaller than this skip the preview pass
# The viewport's dispatches aim at a display frame: an edit is seen within one, and on a GPU that traces a
# sample per pixel faster than that, each frame adds a pass. llvmpipe loses nothing by it (docs/performance.md).
VIEWPORT_DISPATCH_SECONDS = 1 / 60
FRAME_INTERVAL = 0.25  # seconds between published frames while a pass is in progress
LINEAR_INTERVAL = 0.5  # seconds between linear images (the pixel readout's) while the render goes on
# After an edit the previous picture stays up until the new render has this many samples per pixel (or as many
# as the previous picture had, if fewer), or until HOLD_SECONDS have passed since the first edit it does not show.
HOLD_SPP = 4
HOLD_SECONDS = 0.15
# The denoiser runs at most every DENOISE_MIN_INTERVAL seconds, and never more than a third of the time: it waits
# twice as long as it took the last time before it runs again.
DENOISE_MIN_INTERVAL = 0.25
# OIDN's "fast" quality is the one its documentation gives interactive previews: about half the time of "high" on
# the CPU. Exports that ask for the denoiser take "high" (render/job.py).
VIEWPORT_DENOISE_QUALITY = "fast"
GBUFFER_INTERVAL = 0.3  # during a drag, the selection's outline and the depth buffer follow this often
EXPORT_PROGRESS_INTERVAL = 0.1
WORK_NOTE_INTERVAL = 0.1  # seconds between notes on the first pass's progress
# A raw picture is worth judging by eye (focus peaking, the histogram, the clipping warnings) from this many
# samples per pixel; a denoised one at full resolution from its first pass. Below it their marks follow the noise.
JUDGE_MIN_SPP = 16
# The meter reads at most this many pixels of the frame (a regular subsample of a larger one): its reading is a
# weighted mean, which a quarter of the pixels of an 800 x 600 picture give as well as all of them, in a quarter of
# the time (about 12 ms against 48 on one core).
METER_MAX_PIXELS = 160_000
# An auto exposure whose reading moved by more than this many stops since the picture was made remakes it at once.
AUTO_EXPOSURE_TOLERANCE_STOPS = 1 / 12


@dataclass(frozen=True)
class MeterReading:
    """What the light meter read of a picture: the scene-linear luminance (cd/m² on a photometric scene) inside
    the sensor's gate, weighted as the camera's ``metering`` says (``average``: centre-weighted; ``spot``: a disk at
    ``spot``, fractions of the frame's width and height from its top left), and the light the aperture passed."""

    luminance: float
    mode: str
    spot: tuple[float, float]
    light_fraction: float
    generation: int


@dataclass(frozen=True)
class Frame:
    display: np.ndarray  # (H, W, 4) uint8 RGBA, made through ``view``; unsampled pixels show the preview
    view: ViewTransform  # the viewport's view transform the picture was made with (the camera's exposure aside)
    image: np.ndarray | None  # (H, W, 3) float32 linear radiance, or None: the last frame's still holds
    width: int
    height: int
    samples_per_pixel: int
    target_spp: int | None
    samples_per_second: float
    elapsed_seconds: float  # wall time since the last restart
    generation: int
    preview: bool  # only the quarter-resolution preview so far
    converged: bool  # reached the target sample count
    gate: tuple[float, float, float, float] | None = None  # the export's frame in the picture: x, y, w, h pixels
    region: tuple[int, int, int, int] | None = None  # the render region being refined, pixels
    denoised: bool = False  # the picture (and linear image) are the denoiser's
    camera: object = None  # the ThinLensCamera the picture was rendered with: what its tags describe
    exposure: Exposure | None = None  # the camera's exposure of the picture (auto: the one the meter chose)
    meter: MeterReading | None = None  # the meter's latest reading of the render (None: none yet)

    @property
    def worth_judging(self) -> bool:
        """Clean enough for focus peaking, the histogram and the clipping warnings to mean something."""
        if self.preview:
            return False
        return self.converged or self.samples_per_pixel >= (1 if self.denoised else JUDGE_MIN_SPP)


@dataclass(frozen=True)
class WorkNote:
    """What the loop is doing for an edit whose picture is not on screen yet."""

    generation: int
    stage: str  # e.g. "building the kd-tree", "compiling trace.comp", "preview", "first pass"
    step: int = 0  # for a scene's load: this stage's number (1-based) of ``steps``
    steps: int = 0
    fraction: float | None = None  # how far the stage is, 0 to 1, where it is known


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
    view: ViewTransform = ViewTransform()  # how a picture (PNG) is made from the render; an EXR stays linear
    denoise: bool = False  # write the denoised image (and, in an EXR, the noisy one and the guides as layers)


@dataclass(frozen=True)
class ExportProgress:
    request_id: int
    progress: object  # lenslab.render.job.JobProgress of the export's render job


# -- messages from the GUI thread to the worker (through its queue) ---------------------------------------
@dataclass(frozen=True)
class SceneEdit:
    scene: object  # a Scene copy
    size: tuple[int, int]  # the viewport image, pixels
    generation: int
    margin: float | None = None  # framing: None, the export's; else ThinLensCamera.view_frame with this margin


@dataclass(frozen=True)
class CameraEdit:
    camera: object  # a ThinLensCamera copy
    size: tuple[int, int]
    generation: int
    view_changed: bool  # what the camera sees moved (not only its aperture or focus): refresh the g-buffer
    margin: float | None = None  # as SceneEdit's


@dataclass(frozen=True)
class SettingsEdit:
    settings: object  # RenderSettings
    generation: int


@dataclass(frozen=True)
class DisplayEdit:
    view: ViewTransform  # the viewport's view transform, resolved (lenslab.colour_management.view)


@dataclass(frozen=True)
class MeterSpot:
    spot: tuple[float, float]  # where the spot meter reads: fractions of the frame's width and height, top left


@dataclass(frozen=True)
class RegionEdit:
    region: tuple[int, int, int, int] | None  # x, y, width, height in viewport pixels; None: the whole picture
    generation: int


@dataclass(frozen=True)
class DenoiseEdit:
    on: bool


@dataclass(frozen=True)
class Pause:
    paused: bool


@dataclass(frozen=True)
class TargetSpp:
    spp: int | None  # None: render on until paused


@dataclass(frozen=True)
class PickRequest:
    u: float  # [0, 1] image coordinates, (0, 0) top left
    v: float
    request_id: int


@dataclass(frozen=True)
class ExportStart:
    request_id: int
    request: ExportRequest


@dataclass(frozen=True)
class ExportCancel:
    request_id: int


@dataclass(frozen=True)
class Stop:
    pass


def preview_size(width: int, height: int) -> tuple[int, int]:
    return max(1, math.ceil(width / PREVIEW_DIVISOR)), max(1, math.ceil(height / PREVIEW_DIVISOR))


def upscale_smooth(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """``image`` (h, w, c) enlarged to (height, width, c) by bilinear interpolation between pixel centres (the
    preview pass seen as a soft picture, not as blocks); uint8 in, uint8 out."""
    h, w = image.shape[:2]
    ys = np.clip((np.arange(height) + 0.5) * h / height - 0.5, 0, h - 1)
    xs = np.clip((np.arange(width) + 0.5) * w / width - 0.5, 0, w - 1)
    y0, x0 = np.floor(ys).astype(np.intp), np.floor(xs).astype(np.intp)
    y1, x1 = np.minimum(y0 + 1, h - 1), np.minimum(x0 + 1, w - 1)
    fy, fx = (ys - y0).astype(np.float32)[:, None, None], (xs - x0).astype(np.float32)[None, :, None]
    # Separably, along the rows first and then down the columns: the second pass blends whole rows of the
    # first, a fifth of the work of blending four gathered corners per output pixel (the preview's 20 ms,
    # not 90, at 800 x 766, which an edit waits for).
    src = image.astype(np.float32)
    rows = src[:, x0]
    rows += (src[:, x1] - rows) * fx
    out = rows[y0]
    out += (rows[y1] - out) * fy
    return np.clip(np.rint(out), 0, 255).astype(np.uint8) if image.dtype == np.uint8 else out.astype(image.dtype)


def opaque(rgb8: np.ndarray) -> np.ndarray:
    """RGBA8 with alpha 255 from RGB8."""
    return np.concatenate([rgb8, np.full(rgb8.shape[:2] + (1,), 255, np.uint8)], axis=2)


class Phase(Enum):
    """Where the viewport's render stands since the last restart."""

    IDLE = "idle"  # nothing to render yet: no scene
    PREVIEW = "preview"  # the quarter-resolution preview pass
    FULL = "full"  # full-resolution passes, towards the target
    DONE = "done"  # the target sample count is reached
    ERROR = "error"  # the scene or camera cannot be rendered (scene_failed said why)


class LoopEvents(Protocol):
    """What the loop reports, each from the thread that drives it (the render worker's: gui/worker.py turns each
    into the Qt signal of the same name)."""

    def device_ready(self, info: dict) -> None: ...  # renderer.describe()

    def frame_ready(self) -> None: ...  # take it with take_frame()

    def gbuffer_ready(self, gbuffer: GBuffer) -> None: ...

    def pick_ready(self, result: PickResult) -> None: ...

    def restarted(self, generation: int) -> None: ...  # accumulation restarted for this edit

    def working(self, note: WorkNote) -> None: ...  # what the loop does before the edit's picture is shown

    def render_warnings(self, lines: list) -> None: ...  # what the scene's packing warned about, each line once

    def scene_failed(self, generation: int, reason: str) -> None: ...  # one line: the scene cannot be rendered

    def export_progress(self, progress: ExportProgress) -> None: ...

    def export_finished(self, request_id: int, path: str) -> None: ...  # the path written

    def export_failed(self, request_id: int, reason: str) -> None: ...

    def export_cancelled(self, request_id: int) -> None: ...


@dataclass
class _DenoiseJob:
    """A full-resolution picture being denoised on the denoising thread: the linear image to come, of this edit
    (``generation``) at ``spp`` samples per pixel."""

    generation: int
    spp: int
    image: Future
    started: float


def _denoise_into(denoiser, base: np.ndarray, rect: tuple[int, int, int, int], image: np.ndarray,
                  albedo: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """``base`` with the rectangle ``rect`` (x, y, w, h) replaced by the denoised ``image``, ``albedo``, ``normal``
    inside it (on the denoising thread: numpy arrays only, no GL)."""
    x, y, w, h = rect
    base[y:y + h, x:x + w] = denoiser.denoise(image[y:y + h, x:x + w], albedo[y:y + h, x:x + w],
                                              normal[y:y + h, x:x + w], quality=VIEWPORT_DENOISE_QUALITY)
    return base


class RenderLoop:
    """The viewport's progressive render, its picks, g-buffers and exports, on one renderer (its GL context).

    Every method but ``take_frame`` is called on the thread that made the renderer's context current. ``handle``
    applies what the GUI sent through ``apply_scene``, ``apply_camera``, ``apply_settings``, ``apply_display``,
    ``apply_denoise``, ``apply_region``, ``apply_meter_spot``, ``pick``, ``start_export``, ``cancel_export`` and
    ``republish``.
    """

    def __init__(self, renderer, events: LoopEvents, dispatch_seconds: float = VIEWPORT_DISPATCH_SECONDS,
                 more_messages: Callable[[], bool] = lambda: False):
        """``renderer``: a lenslab.render.tracer.Renderer, released by ``release``. ``more_messages``: whether
        the GUI has sent more since the last ``handle`` (a drag under way)."""
        self.dispatch_seconds = dispatch_seconds
        self._events = events
        self._more_messages = more_messages
        self._stopped = False
        self._frame_lock = threading.Lock()
        self._frame: Frame | None = None
        self._frame_signalled = False
        self._renderer = renderer
        if renderer is not None:
            renderer.on_compile = self._compiling
        self._work_generation = 0  # the edit being applied, for the notes on its progress
        self._warned: set[str] = set()  # the scene's warnings already reported (since the last SceneEdit)
        self._last_note = 0.0
        self._session = None
        self._size = (0, 0)
        self._generation = 0
        self._phase = Phase.IDLE
        self._paused = False
        self._target_spp: int | None = 1024
        self._scene_ok = False
        self._camera_ok = True
        self._preview_image = None
        self._preview_linear = None  # the preview pass's linear image at the viewport's size
        self._preview_display: tuple[ViewTransform, np.ndarray] | None = None  # (its view, RGBA8 at full size)
        self._view = ViewTransform()  # the viewport's, as the GUI chose it
        self._spot = (0.5, 0.5)  # where the spot meter reads, fractions of the frame
        self._reading: MeterReading | None = None  # the meter's latest (kept across edits: the scene's light)
        self._exposure: Exposure | None = None  # the camera's exposure of the latest picture made
        self._last_linear = 0.0
        self._gbuffer_due = False
        self._gbuffer_size: tuple[int, int] | None = None
        self._gbuffer_time = 0.0
        self._margin: float | None = None
        self._region: tuple[int, int, int, int] | None = None
        self._denoise = False
        self._denoised: tuple | None = None  # (generation, spp, picture, view, linear): the last denoised frame
        self._denoise_ready_at = 0.0
        # The full-resolution pictures' denoiser and its thread, made on first use, and the picture it is on.
        self._picture_denoiser = None  # lenslab.render.denoise.Denoiser
        self._denoise_thread: ThreadPoolExecutor | None = None
        self._denoise_job: _DenoiseJob | None = None
        # Never blank: the last picture shown at the viewport's size fills what the new render has not reached.
        self._backdrop: np.ndarray | None = None  # RGBA8
        self._backdrop_linear: np.ndarray | None = None
        self._stale_since: float | None = None  # when the picture on screen stopped showing the latest edit
        self._held: tuple | None = None  # the latest edit's picture held back by _offer: shown once the hold ends
        self._shown_quality = -1  # its samples per pixel; -1 for a preview
        self._restart_time = 0.0
        self._last_publish = 0.0
        self._published_spp = -1
        self._export = None

    # -- the state, read-only ----------------------------------------------------------------------------------
    @property
    def phase(self) -> Phase:
        return self._phase

    @property
    def paused(self) -> bool:
        return self._paused

    @property
    def target_spp(self) -> int | None:
        return self._target_spp

    @property
    def generation(self) -> int:
        """The edit the loop last applied (rendered, or failed)."""
        return self._generation

    @property
    def stopped(self) -> bool:
        """A Stop message came: the owner ends the loop (and calls release)."""
        return self._stopped

    @property
    def busy(self) -> bool:
        """``step`` has work to do: an export, a viewport render short of its target, or a picture being
        denoised."""
        return self._export is not None or self._rendering or self._denoise_job is not None

    @property
    def _renderable(self) -> bool:
        """A session whose scene and camera can be rendered (neither failed)."""
        return self._session is not None and self._scene_ok and self._camera_ok

    @property
    def _rendering(self) -> bool:
        return not self._paused and self._renderable and self._phase in (Phase.PREVIEW, Phase.FULL)

    # -- the frame hand-off (any thread) -----------------------------------------------------------------------
    def take_frame(self) -> Frame | None:
        with self._frame_lock:
            frame, self._frame = self._frame, None
            self._frame_signalled = False
        return frame

    # -- driving the loop --------------------------------------------------------------------------------------
    def start(self) -> None:
        """Report the device (``device_ready``); once, before the first ``handle``."""
        self._events.device_ready(self._renderer.describe())

    def step(self) -> None:
        """One bounded dispatch of the export, or else of the viewport's render if it is short of its target, or
        else a dispatch's wait for the picture being denoised; and a picture held back shown once its hold ends."""
        self._show_held_picture()
        if self._export is not None:
            self._export_step()
        elif self._rendering:
            self._viewport_step()
        elif self._denoise_job is not None:
            self._finish_denoising()

    def release(self) -> None:
        """Free the export, the denoising thread, the session and the renderer (on the thread that made them)."""
        if self._denoise_thread is not None:
            self._denoise_thread.shutdown(wait=True, cancel_futures=True)
            self._denoise_thread = None
            self._denoise_job = None
        if self._picture_denoiser is not None:
            self._picture_denoiser.release()
            self._picture_denoiser = None
        if self._export is not None:
            self._export.job.release()
            self._export = None
        if self._session is not None:
            self._session.release()
            self._session = None
        if self._renderer is not None:
            self._renderer.release()
            self._renderer = None

    def handle(self, messages: list) -> None:
        """Apply the messages the GUI sent since the last call, in order, coalesced. A Stop ends the handling at
        once (``stopped``): nothing else in the list is applied."""
        # Only the latest scene, camera and settings matter: a new scene supersedes the edits before it.
        scene_edit: SceneEdit | None = None
        camera_edit: CameraEdit | None = None
        settings_edit: SettingsEdit | None = None
        display_edit: DisplayEdit | None = None
        region_edit: RegionEdit | None = None
        denoise_edit: DenoiseEdit | None = None
        spot_edit: MeterSpot | None = None
        holding = False  # the viewport is about to stop making frames by itself
        for message in messages:
            if isinstance(message, Stop):
                self._stopped = True
                return
            if isinstance(message, SceneEdit):
                scene_edit, camera_edit, settings_edit = message, None, None
            elif isinstance(message, CameraEdit):
                # Keep "the view moved" if any of the coalesced camera edits moved it.
                moved = message.view_changed or (camera_edit is not None and camera_edit.view_changed)
                camera_edit = dataclasses.replace(message, view_changed=moved)
            elif isinstance(message, SettingsEdit):
                settings_edit = message
            elif isinstance(message, DisplayEdit):
                display_edit = message
            elif isinstance(message, RegionEdit):
                region_edit = message
            elif isinstance(message, DenoiseEdit):
                denoise_edit = message
            elif isinstance(message, MeterSpot):
                spot_edit = message
            elif isinstance(message, Pause):
                holding = holding or (message.paused and not self._paused)
                self._paused = message.paused
                if not self._paused and self._phase is Phase.DONE:
                    self._phase = Phase.FULL  # the target may have been raised meanwhile
            elif isinstance(message, TargetSpp):
                self._target_spp = message.spp
                if self._phase is Phase.DONE:
                    self._phase = Phase.FULL
        if scene_edit is not None:
            self.apply_scene(scene_edit)
        if camera_edit is not None:
            self.apply_camera(camera_edit)
        if settings_edit is not None:
            self.apply_settings(settings_edit)
        if spot_edit is not None:
            self.apply_meter_spot(spot_edit)
        if display_edit is not None:
            self.apply_display(display_edit)
        if denoise_edit is not None:
            self.apply_denoise(denoise_edit)
        if region_edit is not None:
            self.apply_region(region_edit)
        for message in messages:
            if isinstance(message, PickRequest):
                self.pick(message)
            elif isinstance(message, ExportStart):
                holding = self.start_export(message) or holding
            elif isinstance(message, ExportCancel):
                self.cancel_export(message.request_id)
        if holding:
            # Paused, or the device turns to an export: the last picture stays up for a while, so it comes
            # with its linear image, or the pixel readout would answer from an older one.
            self.republish(with_linear=True)

    # -- applying edits ------------------------------------------------------------------------------------
    def apply_scene(self, edit: SceneEdit) -> None:
        from lenslab.render.tracer import RenderSession

        scene, size, generation = edit.scene, edit.size, edit.generation
        self._work_generation = generation
        try:
            if self._session is None:
                self._session = RenderSession(self._renderer, scene, width=size[0], height=size[1],
                                              dispatch_seconds=self.dispatch_seconds, on_stage=self._loading)
                # The viewport always gathers the denoiser's albedo and normal, so that turning it on or off
                # shows at once, without a restart.
                self._session.set_feature_buffers(True)
            else:
                self._session.set_scene(scene, width=size[0], height=size[1])
            self._session.set_view(*size, edit.margin)
        except Exception as exc:  # SceneError, SceneTooLarge, a camera ValueError, a mesh that fails to load
            self._scene_ok = False
            self._phase = Phase.ERROR
            self._generation = generation
            self._events.scene_failed(generation, _one_line(exc))
            return
        self._scene_ok = self._camera_ok = True
        self._warned = set()
        self._set_size(size, edit.margin)
        self._restart(generation, view_changed=True)

    def apply_camera(self, edit: CameraEdit) -> None:
        if self._session is None:
            return
        generation = edit.generation
        self._work_generation = generation
        try:
            self._session.set_camera(edit.camera)
        except Exception as exc:
            self._camera_ok = False
            self._phase = Phase.ERROR
            self._generation = generation
            self._events.scene_failed(generation, _one_line(exc))
            return
        self._camera_ok = True
        if not self._scene_ok:
            self._generation = generation
            return
        self._set_size(edit.size, edit.margin)
        self._restart(generation, view_changed=edit.view_changed or edit.size != self._gbuffer_size)

    def apply_settings(self, edit: SettingsEdit) -> None:
        if self._session is None:
            return
        self._work_generation = edit.generation
        self._session.set_settings(edit.settings)
        if self._scene_ok and self._camera_ok:
            self._restart(edit.generation, view_changed=False)

    def _set_size(self, size: tuple[int, int], margin: float | None) -> None:
        if size != self._size or margin != self._margin:
            self._region = None  # its pixels were another picture's
        self._size, self._margin = size, margin

    def apply_region(self, edit: RegionEdit) -> None:
        self._region = edit.region
        if self._renderable:
            self._restart(edit.generation, view_changed=False)

    def apply_denoise(self, edit: DenoiseEdit) -> None:
        if edit.on != self._denoise:
            self._denoise = edit.on
            self._denoised = None
            self.republish(with_linear=True)

    def apply_display(self, edit: DisplayEdit) -> None:
        self._view = edit.view
        # Show the picture in the new look now: a finished or paused render makes no more frames by itself.
        self.republish(with_linear=False)

    def apply_meter_spot(self, edit: MeterSpot) -> None:
        """Move the spot meter; the picture on screen is read again there at once."""
        spot = (min(max(float(edit.spot[0]), 0.0), 1.0), min(max(float(edit.spot[1]), 0.0), 1.0))
        if spot == self._spot:
            return
        self._spot = spot
        session = self._session
        linear = self._backdrop_linear
        if session is not None and linear is not None and linear.shape[:2] == (session.height, session.width) \
                and self._phase in (Phase.FULL, Phase.DONE):
            self._meter(linear)
            self.republish(with_linear=False)

    def republish(self, with_linear: bool) -> None:
        """Publish the full-size picture as it stands again, if there is one."""
        if self._renderable and self._phase in (Phase.FULL, Phase.DONE) and self._published_spp >= 0:
            self._publish_session(converged=self._phase is Phase.DONE, with_linear=with_linear)

    def _resize(self, width: int, height: int, region=None) -> None:
        # RenderSession keeps the scene on the GPU; a new size needs the camera framed again for it and a new
        # accumulation buffer (set_view does both).
        self._session.set_view(width, height, self._margin)
        if region is not None:
            self._session.set_region(region)

    def _restart(self, generation: int, view_changed: bool) -> None:
        self._generation = generation
        self._held = None  # an older edit's
        self._preview_image = None
        self._preview_display = None
        self._last_linear = 0.0
        self._published_spp = -1
        self._restart_time = time.perf_counter()
        if self._stale_since is None:
            self._stale_since = self._restart_time
        w, h = self._size
        if self._region is None and w * h >= PREVIEW_MIN_PIXELS:
            self._resize(*preview_size(w, h))
            self._phase = Phase.PREVIEW
        else:
            self._resize(w, h, self._region)
            self._phase = Phase.FULL
        if view_changed:
            self._gbuffer_due = True
        self._events.restarted(generation)
        self._report_warnings()

    def _report_warnings(self) -> None:
        """What the session warned about (a missing texture, an unmapped mesh material, a pixel filter the image
        is too large to splat), each line once per scene: the window shows them beside the load's own."""
        new = [line for line in self._session.warnings if line not in self._warned]
        if new:
            self._warned.update(new)
            self._events.render_warnings(new)

    # -- saying what the loop is doing -----------------------------------------------------------------------
    def _note(self, stage: str, step: int = 0, steps: int = 0, fraction: float | None = None) -> None:
        self._last_note = time.perf_counter()
        self._events.working(WorkNote(self._work_generation, stage, step, steps, fraction))

    def _loading(self, stage: str) -> None:
        """RenderSession.set_scene's steps, as each begins."""
        from lenslab.render.tracer import SCENE_STAGES

        self._note(stage, SCENE_STAGES.index(stage) + 1, len(SCENE_STAGES))

    def _compiling(self, shader: str) -> None:
        self._note(f"compiling {shader}")

    # -- rendering the viewport ------------------------------------------------------------------------------
    def _viewport_step(self) -> None:
        session = self._session
        if self._phase is Phase.PREVIEW:
            if time.perf_counter() - self._last_note >= WORK_NOTE_INTERVAL:
                self._note("preview")
            session.step(self.dispatch_seconds / 2, target_spp=1)
            if session.samples_per_pixel >= 1:
                image = session.image()
                if self._denoise:
                    image = self._denoise_image(image, *session.features_image())
                self._meter(image)  # the first picture of an auto exposure is exposed by its own light
                self._preview_image = image
                w, h = self._size
                # Enlarged once: the frames of the first full pass fill their unreached pixels from it.
                self._preview_linear = upscale_smooth(image, w, h)
                self._offer(self._preview_picture(), self._preview_linear, preview=True, denoised=self._denoise)
                self._resize(w, h)
                self._phase = Phase.FULL
                self._gbuffer_if_due()  # during a drag every edit restarts here: the outline must keep up
            return
        if self._gbuffer_if_due():
            return
        target = self._target_spp
        progress = session.step(self.dispatch_seconds, target)
        done = target is not None and progress.samples_per_pixel >= target
        now = time.perf_counter()
        if progress.samples_per_pixel == 0 and now - self._last_note >= WORK_NOTE_INTERVAL:
            self._note("first pass", fraction=session.pass_fraction)
        denoised = self._denoise_job is not None and self._denoise_job.image.done()
        if done or denoised or progress.samples_per_pixel != self._published_spp \
                or now - self._last_publish >= FRAME_INTERVAL:
            self._publish_session(done)
        if done:
            self._phase = Phase.DONE

    def _gbuffer_if_due(self) -> bool:
        """Remake the depth and selection buffer if the view moved: between edits, or every GBUFFER_INTERVAL
        while they keep coming (a drag), so that the selection's outline follows a lens change."""
        if not self._gbuffer_due:
            return False
        if self._more_messages() and time.perf_counter() - self._gbuffer_time < GBUFFER_INTERVAL:
            return False
        self._gbuffer_due = False
        self._compute_gbuffer()
        return True

    def _preview_picture(self) -> np.ndarray:
        """The preview pass through the view transform at its own quarter size (OpenColorIO's CPU processor: a
        sixteenth of the pixels), then enlarged: RGBA8 at the viewport's size."""
        view = self._picture_view()
        if self._preview_display is None or self._preview_display[0] != view:
            rgb = to_8bit(display_pixels(self._preview_image, view))
            w, h = self._size
            self._preview_display = (view, opaque(upscale_smooth(rgb, w, h)))
        return self._preview_display[1]

    # -- the exposure and the meter ------------------------------------------------------------------------------
    def _camera_exposure(self) -> Exposure:
        """The camera's exposure of the picture: none in the compensated mode, its f-number, shutter and ISO in the
        physical one, and in the auto mode the shutter that puts the meter's latest reading at middle grey
        (until the meter has read anything, the camera's own)."""
        session = self._session
        camera = session.camera
        light = session.frame.aperture.light_fraction
        if camera.exposure_mode != "auto":
            return camera.exposure(light)
        reading = self._reading
        if reading is None or not reading.luminance > 0:
            return dataclasses.replace(camera, exposure_mode="physical").exposure(light)
        return camera.exposure(light, reading=reading.luminance)

    def _picture_view(self) -> ViewTransform:
        """The viewport's view transform with the camera's exposure added to its exposure (so a stop of aperture
        in the physical mode darkens the picture by a stop, as the exported file will be): what the picture is
        made with. ``_exposure`` keeps the camera's exposure it used."""
        exposure = self._exposure = self._camera_exposure()
        stops = self._view.exposure_stops + math.log2(max(exposure.scale, 1e-30))
        stops = min(max(stops, EXPOSURE_RANGE[0]), EXPOSURE_RANGE[1])
        return dataclasses.replace(self._view, exposure_stops=stops)

    def _meter(self, image: np.ndarray, unsampled: np.ndarray | None = None) -> None:
        """Read ``image`` (the linear picture, at the session's size) with the light meter: its luminance in the
        scene's working space inside the sensor's gate, pixels ``unsampled`` (True: no sample yet) left out."""
        session = self._session
        camera = session.camera
        h, w = image.shape[:2]
        gx, gy, gw, gh = session.frame.gate_pixels
        sx, sy = w / session.width, h / session.height  # the preview is metered at its own size
        x0, y0 = max(0, int(round(gx * sx))), max(0, int(round(gy * sy)))
        x1, y1 = min(w, max(x0 + 1, int(round((gx + gw) * sx)))), min(h, max(y0 + 1, int(round((gy + gh) * sy))))
        lum = np.asarray(luminance(image[y0:y1, x0:x1, :3], session.scene.render.working_space), np.float32)
        if unsampled is not None and unsampled.shape[:2] == (h, w):
            lum = np.where(unsampled[y0:y1, x0:x1], np.float32(np.nan), lum)
        stride = max(1, math.ceil(math.sqrt(lum.size / METER_MAX_PIXELS)))
        if stride > 1:
            lum = lum[stride // 2::stride, stride // 2::stride]
        if not np.isfinite(lum).any():
            return  # nothing rendered in the frame yet: the last reading stands
        reading = meter_luminance(lum, camera.metering, self._spot)
        if not math.isfinite(reading):
            return
        self._reading = MeterReading(float(reading), camera.metering, self._spot,
                                     float(session.frame.aperture.light_fraction), self._generation)

    def _exposure_moved(self, used: Exposure | None) -> bool:
        """The auto exposure the picture was made with is off the meter's latest reading by more than the
        tolerance (the picture is made again)."""
        if used is None or self._session.camera.exposure_mode != "auto":
            return False
        now = self._camera_exposure()
        return abs(math.log2(max(now.scale, 1e-30) / max(used.scale, 1e-30))) > AUTO_EXPOSURE_TOLERANCE_STOPS

    def _publish_session(self, converged: bool, with_linear: bool = False) -> None:
        session = self._session
        now = time.perf_counter()
        if self._denoise:
            if session.samples_per_pixel < 1:
                # Raw samples are never shown with the denoiser on: the denoised preview (or the last picture)
                # stands until the first pass is whole and can be denoised.
                return
            denoised = self._denoised_frame(converged)
            if denoised is not None:  # else the last picture stands until this edit's first is denoised
                self._offer(*denoised, preview=False, converged=converged, denoised=True)
            return
        picture = session.display(self._picture_view())
        used = self._exposure
        empty = picture[..., 3] == 0  # pixels without a sample: a first pass under way, or outside the region
        has_empty = bool(empty.any())
        image = None
        auto_unmetered = session.camera.exposure_mode == "auto" and self._reading is None
        if with_linear or converged or self._paused or not self.busy or auto_unmetered \
                or now - self._last_linear >= LINEAR_INTERVAL:
            image = session.image()  # resolved from the read-back itself, without a copy of the sums
            fill_linear = self._fill_linear()
            if has_empty and fill_linear is not None:
                image[empty] = fill_linear[empty]
            # The meter reads the whole frame: where nothing is rendered yet, what shows there (the preview, the
            # last picture); pixels with neither do not count.
            self._meter(image, empty if has_empty and fill_linear is None else None)
            if self._exposure_moved(used):  # auto: the reading moved; the picture is made at the new exposure
                picture = session.display(self._picture_view())
            self._last_linear = now
        fill = self._fill_picture() if has_empty else None
        if has_empty and fill is not None:
            picture[empty] = fill[empty]
        elif has_empty:
            picture[empty, 3] = 255  # black
        self._offer(picture, image, preview=False, converged=converged)

    def _fill_picture(self) -> np.ndarray | None:
        """What shows where the render has no sample yet: this edit's preview, else the last picture shown."""
        if self._preview_image is not None:
            return self._preview_picture()
        return self._backdrop if self._has_backdrop() else None

    def _fill_linear(self) -> np.ndarray | None:
        """The linear image of :meth:`_fill_picture`'s picture (None where there is none), without making the
        picture: the pixel readout and the meter need only this."""
        if self._preview_image is not None:
            return self._preview_linear
        linear = self._backdrop_linear
        fits = self._has_backdrop() and linear is not None and linear.shape[:2] == self._backdrop.shape[:2]
        return linear if fits else None

    def _has_backdrop(self) -> bool:
        w, h = self._size
        return self._backdrop is not None and self._backdrop.shape[:2] == (h, w)

    # -- the denoiser ------------------------------------------------------------------------------------------
    def _denoise_image(self, image: np.ndarray, albedo: np.ndarray, normal: np.ndarray) -> np.ndarray:
        from lenslab.render.denoise import denoise

        return denoise(image, albedo, normal, quality=VIEWPORT_DENOISE_QUALITY)

    def _denoised_frame(self, converged: bool) -> tuple[np.ndarray, np.ndarray] | None:
        """The picture and linear image of this edit through the denoiser (the render region's pixels over the
        last picture, or the whole image), or None while it has none. The denoiser is not cheap (a CPU network):
        it runs on its own thread (``_DenoiseJob``) and meanwhile this edit's last denoised picture is shown
        again; it starts on a newer one at most every DENOISE_MIN_INTERVAL, and for no more than a third of the
        time, but at once for an edit's first picture and for the last, converged one."""
        self._collect_denoised()
        session = self._session
        spp = session.samples_per_pixel
        cached = self._denoised
        current = cached is not None and cached[0] == self._generation
        if self._denoise_job is None and not (current and cached[1] == spp) \
                and (not current or converged or time.perf_counter() >= self._denoise_ready_at):
            self._start_denoising()
        if not current:
            return None
        view = self._picture_view()
        if cached[3] != view:  # another view or exposure: the same denoised image, shown anew
            self._denoised = (*cached[:2], session.display_image(cached[4], view), view, cached[4])
        return self._denoised[2], self._denoised[4]

    def _start_denoising(self) -> None:
        """Hand the render as it stands to the denoising thread (its read-back happens here, on the GL thread)."""
        from lenslab.render.denoise import Denoiser

        session = self._session
        image = session.image()
        albedo, normal = session.features_image()
        base = image
        if session.region is not None:  # outside the region: the last picture shown
            fill_linear = self._fill_linear()
            if fill_linear is not None:
                base = fill_linear.copy()
        if self._denoise_thread is None:
            self._picture_denoiser = Denoiser()
            self._denoise_thread = ThreadPoolExecutor(max_workers=1, thread_name_prefix="lenslab-denoise")
        future = self._denoise_thread.submit(_denoise_into, self._picture_denoiser, base, session.region_pixels,
                                             image, albedo, normal)
        self._denoise_job = _DenoiseJob(self._generation, session.samples_per_pixel, future, time.perf_counter())

    def _collect_denoised(self) -> None:
        """Take the denoising thread's picture if it is done: this edit's becomes the one shown (metered, and made
        through the view on the GPU); an older edit's is dropped. A failure is raised here, on the loop's thread."""
        job = self._denoise_job
        if job is None or not job.image.done():
            return
        self._denoise_job = None
        image = job.image.result()
        if job.generation != self._generation or not self._denoise:
            return
        self._meter(image)  # the denoised picture: the meter reads it without the noise
        view = self._picture_view()
        picture = self._session.display_image(image, view)  # through the view on the GPU, as the raw pictures are
        cost = time.perf_counter() - job.started
        self._denoise_ready_at = time.perf_counter() + max(DENOISE_MIN_INTERVAL, 2.0 * cost)
        self._denoised = (job.generation, job.spp, picture, view, image)

    def _finish_denoising(self) -> None:
        """Nothing to render (the target reached, paused): wait a dispatch's time for the picture being denoised,
        and show it once it comes, if it is still this edit's."""
        wait_for_futures([self._denoise_job.image], timeout=self.dispatch_seconds)
        if not self._denoise_job.image.done():
            return
        if self._renderable and self._phase in (Phase.FULL, Phase.DONE) and self._denoise:
            self._publish_session(converged=self._phase is Phase.DONE)
        else:
            self._collect_denoised()

    # -- what the viewport shows -------------------------------------------------------------------------------
    def _offer(self, picture: np.ndarray, image: np.ndarray | None, preview: bool, converged: bool = False,
               denoised: bool = False) -> None:
        """Show this picture of the latest edit, unless the one on screen is still the better (HOLD_SPP and
        HOLD_SECONDS): the viewport never trades a clean picture for a worse one of the same view at once."""
        quality = -1 if preview else self._session.samples_per_pixel
        if self._stale_since is not None:
            on_screen = self._backdrop
            comparable = on_screen is not None and on_screen.shape[:2] == picture.shape[:2]
            enough = quality >= min(self._shown_quality, HOLD_SPP)
            waited = time.perf_counter() - self._stale_since >= HOLD_SECONDS
            if comparable and not (enough or waited or converged):
                # Held back, not dropped: if nothing better comes before the hold ends, this is shown then
                # (a preview made within HOLD_SECONDS would otherwise give way to nothing until the full pass).
                self._held = (picture, image, preview, converged, denoised)
                return
            self._stale_since = None
        self._held = None
        self._shown_quality = quality
        self._backdrop = picture
        if image is not None:
            self._backdrop_linear = image
        self._publish(picture, image, preview=preview, converged=converged, denoised=denoised)

    def _show_held_picture(self) -> None:
        """The picture _offer held back, once HOLD_SECONDS have passed since the edit it shows was made."""
        if self._held is not None and self._stale_since is not None \
                and time.perf_counter() - self._stale_since >= HOLD_SECONDS:
            self._offer(*self._held)

    def _publish(self, picture: np.ndarray, image: np.ndarray | None, preview: bool, converged: bool = False,
                 denoised: bool = False) -> None:
        session = self._session
        progress = session.progress(self._target_spp)
        spp = 0 if preview else session.samples_per_pixel
        w, h = self._size
        gx, gy, gw, gh = session.frame.gate_pixels
        sx, sy = w / session.width, h / session.height  # the preview pass is smaller than the picture
        frame = Frame(display=picture, view=self._view, image=image,
                      width=picture.shape[1], height=picture.shape[0], samples_per_pixel=spp,
                      target_spp=self._target_spp, samples_per_second=progress.samples_per_second,
                      elapsed_seconds=time.perf_counter() - self._restart_time, generation=self._generation,
                      preview=preview, converged=converged, gate=(gx * sx, gy * sy, gw * sx, gh * sy),
                      region=session.region, denoised=denoised, camera=session.camera,
                      exposure=self._exposure, meter=self._reading)
        self._published_spp = spp
        self._last_publish = time.perf_counter()
        with self._frame_lock:
            untaken = self._frame
            if image is None and untaken is not None and untaken.image is not None \
                    and untaken.image.shape[:2] == picture.shape[:2]:
                # This frame replaces one the GUI never took: keep the linear image that one carried.
                frame = dataclasses.replace(frame, image=untaken.image)
            self._frame = frame
            signal = not self._frame_signalled
            self._frame_signalled = True
        if signal:
            self._events.frame_ready()

    def _compute_gbuffer(self) -> None:
        from lenslab.render.raycast import cast_rays

        session = self._session
        w, h = self._size
        frame = session.frame  # the full-size picture's, as the g-buffer is only made between full passes
        self._gbuffer_time = time.perf_counter()
        origins, directions, looks_out = frame.rays(frame.pixel_centres(), with_weights=True)
        hits = cast_rays(self._renderer, session.gpu_scene, origins, directions)
        # A pixel no ray leaves the lens from (beyond a fisheye's image circle) sees nothing.
        seen = (hits.prim >= 0) & (np.reshape(looks_out, (len(origins), -1)).max(axis=1) > 0.0)
        node_index = np.where(seen, session.hit_nodes(hits), -1)
        # Depth along the view axis from the camera's position (a real lens's chief rays leave its front element).
        along = (origins - frame.position) @ frame.forward + hits.t * (directions @ frame.forward)
        depth = np.where(seen, along, np.inf).astype(np.float32)
        self._gbuffer_size = (w, h)
        self._events.gbuffer_ready(GBuffer(node_index.reshape(h, w), depth.reshape(h, w), self._generation))

    def pick(self, request: PickRequest) -> None:
        session = self._session
        if not self._renderable:
            self._events.pick_ready(PickResult(request.request_id, self._generation, False))
            return
        pick = session.pick(request.u * session.width, request.v * session.height)
        if pick is None:
            self._events.pick_ready(PickResult(request.request_id, self._generation, False))
            return
        self._events.pick_ready(PickResult(request.request_id, self._generation, True, float(pick.depth),
                                           tuple(float(c) for c in pick.point), pick.node_index))

    # -- export ----------------------------------------------------------------------------------------------
    def start_export(self, start: ExportStart) -> bool:
        """Start the export; False if it could not start (the reason goes out by export_failed)."""
        from lenslab.render.job import RenderJob

        if self._export is not None:
            self._events.export_failed(start.request_id, "another export is still running")
            return False
        request = start.request
        try:
            # An export's dispatches are the viewport's (a display frame), not the headless job's longer ones
            # (job.OFFLINE_DISPATCH_SECONDS): the thread holds Python's interpreter for a whole dispatch (moderngl
            # does not release it), and the window, whose every Python slot and filter waits for it, must stay
            # responsive while the studio exports.
            job = RenderJob(self._renderer, request.scene, spp=request.target_spp, time_limit=request.seconds,
                            dispatch_seconds=self.dispatch_seconds,
                            feature_buffers=request.denoise)
        except Exception as exc:
            self._events.export_failed(start.request_id, _one_line(exc))
            return False
        self._export = _Export(start.request_id, request, job)
        return True

    def cancel_export(self, request_id: int) -> None:
        export = self._export
        if export is None or export.request_id != request_id:
            return
        export.job.release()
        self._export = None
        self._events.export_cancelled(request_id)

    def _export_step(self) -> None:
        export = self._export
        job = export.job
        if not job.finished:
            progress = job.step(EXPORT_PROGRESS_INTERVAL)
            now = time.perf_counter()
            if now - export.last_report >= EXPORT_PROGRESS_INTERVAL:
                export.last_report = now
                self._events.export_progress(ExportProgress(export.request_id, progress))
            return
        # Done: the job has a sample in every pixel; the file is written whole or not at all.
        self._export = None
        try:
            path = job.write(export.request.path, view=export.request.view, denoise=export.request.denoise)
        except Exception as exc:
            self._events.export_failed(export.request_id, _one_line(exc))
        else:
            self._events.export_finished(export.request_id, str(path))
        finally:
            job.release()


@dataclass
class _Export:
    """The export in progress (the loop's thread only)."""

    request_id: int
    request: ExportRequest
    job: object  # lenslab.render.job.RenderJob
    last_report: float = 0.0


def _one_line(exc: BaseException) -> str:
    """The studio shows an error as the command line prints it (lenslab.messages): one line, shortened."""
    return one_line(str(exc).strip() or type(exc).__name__)
