"""One shot, or one range of its samples, rendered on a worker; and the parts put back together.

A shot of ``split = k`` is rendered as k parts. Accumulation is a weighted sum (render/tracer.py), so parts that
take disjoint ranges of one seed's sample indices add up to the render of all of them: a shot of 256 samples
split in four renders indices 0-63, 64-127, 128-191 and 192-255 on four workers, and their sum is the
single-machine render of 256 samples, to float rounding. A shot with a time limit and no sample count cannot
know its ranges in advance: its parts start ``PART_INDEX_STRIDE`` indices apart and each renders what its
time allows, disjoint ranges again.

The worker never writes the shot's file: it sends its accumulation back, and the machine that runs the batch
merges the parts and writes the image, whole or not at all (lenslab.atomic). Workers need only read the scene.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from lenslab.batch.spec import MAX_SPLIT, Shot
from lenslab.scene.options import OPTIONS
from lenslab.render.film import merge
from lenslab.render.job import JobProgress

#: Where each part of a time-limited shot starts in the sample sequence: room for 2^24 samples per pixel
#: (RenderSettings' most) in each of MAX_SPLIT parts within the kernel's 32-bit sample index.
PART_INDEX_STRIDE = 1 << 24
assert MAX_SPLIT * PART_INDEX_STRIDE <= 1 << 32

#: Environment variable that pins a worker to a GPU (EGL device index), for workers a cluster starts.
DEVICE_ENVIRONMENT = "LENSLAB_DEVICE"

log = logging.getLogger(__name__)


class PartFailed(RuntimeError):
    """A part that could not be rendered; the message is one line for the user. Plain, so that it crosses
    from a worker to the client intact (not every exception of ours survives pickling)."""


@dataclass(frozen=True)
class PartProgress:
    """How far one part is, as a worker reports it while it renders."""

    output: str  # the shot's output path: which shot
    part: int
    parts: int
    progress: JobProgress
    worker: str = ""  # the worker's address
    pid: int = 0  # the worker's process

    # Dask's events carry msgpack's plain types only.
    def to_message(self) -> dict:
        return {"output": self.output, "part": self.part, "parts": self.parts, "worker": self.worker,
                "pid": self.pid, "progress": dataclasses.asdict(self.progress)}

    @classmethod
    def from_message(cls, message: dict) -> "PartProgress":
        return cls(message["output"], message["part"], message["parts"], JobProgress(**message["progress"]),
                   message["worker"], message["pid"])


@dataclass
class PartResult:
    part: int
    accumulation: np.ndarray | None  # (H, W, 4) radiance sums and weights; None when the part had no samples
    samples_per_pixel: int
    seconds: float
    metadata: dict[str, object] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def sample_range(total_spp: int | None, part: int, parts: int) -> tuple[int, int | None]:
    """(first sample index, samples) of part ``part`` of ``parts``: contiguous ranges that cover 0..total_spp-1;
    with no total (a time limit alone), ranges PART_INDEX_STRIDE apart and as many samples as time allows."""
    if not 0 <= part < parts <= MAX_SPLIT:
        raise ValueError(f"part {part} of {parts} does not exist")
    if total_spp is None:
        return part * PART_INDEX_STRIDE, None
    first, end = total_spp * part // parts, total_spp * (part + 1) // parts
    return first, end - first


# -- on the worker -------------------------------------------------------------------------------------------
_renderers = threading.local()  # a GL context is current in one thread: one Renderer per thread and device


def _renderer(device: int | None):
    from lenslab.render.tracer import Renderer

    cache = _renderers.__dict__.setdefault("by_device", {})
    if device not in cache:
        cache[device] = Renderer(device)
    return cache[device]


def render_part(shot: Shot, part: int, parts: int, *, device: int | None = None,
                on_progress: Callable[[JobProgress], None] | None = None) -> PartResult:
    """Render part ``part`` of ``parts`` of ``shot`` on this process's GL context for ``device``."""
    from lenslab.render.job import OFFLINE_DISPATCH_SECONDS, RenderJob
    from lenslab.scene.scene import SceneError

    warnings: list[str] = []
    scene = shot.open_scene(warn=warnings.append)
    total = scene.render.spp if shot.overrides.spp is None and shot.time_limit is None else shot.overrides.spp
    first, spp = sample_range(total, part, parts)
    if spp == 0:  # more parts than samples: this one has none to take
        return PartResult(part, None, 0, 0.0, warnings=warnings)
    try:
        job = RenderJob(_renderer(device), scene, spp=spp, time_limit=shot.time_limit,
                        dispatch_seconds=OFFLINE_DISPATCH_SECONDS, first_sample=first)
    except (SceneError, ValueError) as exc:  # found only when the scene is packed for the GPU: name its file
        raise SceneError.in_file(scene.source_path or shot.scene, exc) from None
    try:
        warnings.extend(job.session.warnings)
        job.run(on_progress=on_progress)
        return PartResult(part, job.session.accumulation(), job.samples_per_pixel, job.elapsed_seconds,
                          metadata=job.metadata(), warnings=warnings)
    finally:
        job.release()


PROGRESS_TOPIC = "lenslab-progress"  # the Dask event topic parts report their progress on


def run_part(shot: Shot, part: int, parts: int, devices: tuple[int, ...] = ()) -> PartResult:
    """:func:`render_part` as a Dask task: reports progress on PROGRESS_TOPIC, picks the worker's GPU (its
    LENSLAB_DEVICE, else ``devices`` by the worker's number in a local cluster) and turns any failure into a
    one-line PartFailed."""
    from distributed import get_worker

    worker = get_worker()
    device = _worker_device(worker.name, devices)

    def report(progress: JobProgress) -> None:
        worker.log_event(PROGRESS_TOPIC, PartProgress(str(shot.output), part, parts, progress, worker.address,
                                                      os.getpid()).to_message())

    try:
        return render_part(shot, part, parts, device=device, on_progress=report)
    except Exception as exc:
        raise PartFailed(_one_line(exc)) from None


def _worker_device(worker_name, devices: tuple[int, ...]) -> int | None:
    pinned = os.environ.get(DEVICE_ENVIRONMENT)
    if pinned:
        try:
            return int(pinned)
        except ValueError:
            raise PartFailed(f"{DEVICE_ENVIRONMENT}={pinned!r} on this worker is not a device number") from None
    if devices:
        try:
            return devices[int(worker_name) % len(devices)]
        except (TypeError, ValueError):  # a worker not numbered by a local cluster
            return devices[0]
    return None


def _one_line(exc: Exception) -> str:
    """What the user reads for a failed part: our own errors already say it in one line; anything else is a
    bug, logged in full on the worker and named by its type."""
    from lenslab.optics.presetfiles import PresetError
    from lenslab.render.buffers import SceneTooLarge
    from lenslab.render.film import ExportError
    from lenslab.render.gl import GLUnavailable

    if isinstance(exc, (ValueError, PresetError, SceneTooLarge, ExportError, GLUnavailable, OSError)):
        return " ".join(str(exc).split())
    log.exception("a part failed")
    return f"{type(exc).__name__}: {' '.join(str(exc).split())} (a bug: the worker's log has the traceback)"


# -- back on the client ----------------------------------------------------------------------------------------
class ShotAssembly:
    """The parts of one shot as they come back; once all are in, the image and its metadata."""

    def __init__(self, shot: Shot):
        self.shot = shot
        self.results: dict[int, PartResult] = {}
        self._sum: np.ndarray | None = None

    def add(self, result: PartResult) -> None:
        if result.part in self.results:
            return  # a part the scheduler ran twice (a worker lost after finishing it): keep the first
        self.results[result.part] = result
        if result.accumulation is not None:
            # Added as they arrive, so a shot split in 64 holds one image in memory, not 64.
            self._sum = result.accumulation if self._sum is None else merge(self._sum, result.accumulation)
            result.accumulation = None

    @property
    def complete(self) -> bool:
        return len(self.results) == self.shot.split

    @property
    def samples_per_pixel(self) -> int:
        return sum(r.samples_per_pixel for r in self.results.values())

    @property
    def seconds(self) -> float:
        """Sampling time summed over the parts (machine time, not wall time)."""
        return sum(r.seconds for r in self.results.values())

    def accumulation(self) -> np.ndarray:
        if not self.complete or self._sum is None:
            raise RuntimeError(f"{self.shot.name}: not every part is in")
        return self._sum

    def metadata(self) -> dict[str, object]:
        first = next(r for r in sorted(self.results.values(), key=lambda r: r.part) if r.metadata)
        return {**first.metadata, "lenslab:SamplesPerPixel": self.samples_per_pixel,
                "lenslab:RenderParts": self.shot.split}

    def write(self) -> Path:
        """Merge, resolve and write the shot's image (its folder made if missing), whole or not at all."""
        from lenslab.render.film import resolve, write_image
        from lenslab.render.job import exposure_metadata

        self.shot.output.parent.mkdir(parents=True, exist_ok=True)
        metadata = self.metadata()
        image = resolve(self.accumulation())
        if metadata.get(OPTIONS["exposure_mode"].metadata) == "auto":  # metered on the merged image
            metadata.update(exposure_metadata(metadata, image))
        return write_image(self.shot.output, image, metadata,
                           sensor_exposure=float(metadata.get("lenslab:ExposureScale", 1.0)),
                           view=dataclasses.replace(self.shot.view,
                                                    working_space=str(metadata[OPTIONS["working_space"].metadata])))

