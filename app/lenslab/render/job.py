"""One render job: from a scene to an image file, the same wherever it is asked for.

A :class:`RenderJob` renders one scene until its samples are in or its time is up, in slices a caller
interleaves with whatever it must keep alive (the CLI's progress bar, the studio's event loop), then writes
the image with the camera's settings as metadata. The CLI's ``--headless``, the studio's export and
``lenslab validate`` all drive this one class, so they stop, guarantee and label their images alike.

The guarantee: **every pixel has at least one sample before an image leaves the job.** A time limit ends the
job at the first slice past it, but never inside the first full pass: a pass that is under way is finished
first (``overran_time_limit`` then says by how much), since an image with unsampled rows is not a render.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lenslab import __version__
from lenslab.optics.sensors import crop_factor
from lenslab.render.tracer import DEFAULT_DISPATCH_SECONDS, Renderer, RenderSession
from lenslab.scene.scene import Scene

#: :meth:`RenderJob.run` renders for about this long between progress reports.
REPORT_SECONDS = 0.5


@dataclass(frozen=True)
class JobProgress:
    samples_per_pixel: int  # every pixel has at least this many
    target_spp: int | None
    elapsed_seconds: float  # wall time spent sampling (the time limit's clock)
    time_limit: float | None
    samples_per_second: float

    @property
    def fraction(self) -> float:
        """How far the job is, 0 to 1, by samples or by time, whichever is further."""
        fractions = [0.0]
        if self.target_spp:
            fractions.append(self.samples_per_pixel / self.target_spp)
        if self.time_limit:
            fractions.append(self.elapsed_seconds / self.time_limit)
        return min(1.0, max(fractions))


class RenderJob:
    """Render ``scene`` to ``spp`` samples per pixel, or for ``time_limit`` seconds, or both (whichever comes
    first). With neither, the scene's own sample count. The image is the scene camera's resolution.
    ``first_sample`` starts the sample indices elsewhere than 0: one part of a render split across workers."""

    def __init__(self, renderer: Renderer, scene: Scene, *, spp: int | None = None, time_limit: float | None = None,
                 dispatch_seconds: float = DEFAULT_DISPATCH_SECONDS, first_sample: int = 0):
        if spp is not None and spp < 1:
            raise ValueError(f"a render needs at least 1 sample per pixel, not {spp}")
        if time_limit is not None and not time_limit > 0:
            raise ValueError(f"a time limit must be positive, not {time_limit}")
        self.scene = scene
        self.target_spp = spp if spp is not None else (None if time_limit else scene.render.spp)
        self.time_limit = time_limit
        self.session = RenderSession(renderer, scene, dispatch_seconds=dispatch_seconds, first_sample=first_sample)
        self.overran_time_limit = 0.0  # seconds past the time limit spent finishing the first full pass
        self._start = time.perf_counter()  # the time limit counts sampling, not building and compiling

    # -- rendering ----------------------------------------------------------------------------------------
    @property
    def elapsed_seconds(self) -> float:
        return time.perf_counter() - self._start

    @property
    def samples_per_pixel(self) -> int:
        return self.session.samples_per_pixel

    @property
    def finished(self) -> bool:
        """True once the samples are in, or the time is up and every pixel has a sample."""
        if self.target_spp is not None and self.session.done(self.target_spp):
            return True
        return self._out_of_time() and self.session.samples_per_pixel >= 1

    def _out_of_time(self) -> bool:
        return self.time_limit is not None and self.elapsed_seconds >= self.time_limit

    def step(self, seconds: float) -> JobProgress:
        """Render for about ``seconds`` (at least one dispatch, never past the time limit unless the first
        pass is still unfinished) and report. Does nothing once the job is finished."""
        if not self.finished:
            if self._out_of_time():  # only the first pass is left to finish
                self.session.step(seconds, 1)
                if self.session.samples_per_pixel >= 1:
                    self.overran_time_limit = self.elapsed_seconds - self.time_limit
            else:
                if self.time_limit is not None:
                    seconds = min(seconds, self.time_limit - self.elapsed_seconds)
                self.session.step(max(0.0, seconds), self.target_spp)
        return self.progress()

    def run(self, on_progress=None) -> np.ndarray:
        """Render until finished, calling ``on_progress(JobProgress)`` after each slice; the linear image."""
        while not self.finished:
            progress = self.step(REPORT_SECONDS)
            if on_progress is not None:
                on_progress(progress)
        return self.image()

    def progress(self) -> JobProgress:
        rate = self.session.progress().samples_per_second
        return JobProgress(self.session.samples_per_pixel, self.target_spp, self.elapsed_seconds, self.time_limit,
                           rate)

    # -- the result ---------------------------------------------------------------------------------------
    def image(self) -> np.ndarray:
        """(H, W, 3) float32 linear radiance. Only a finished job has one: every pixel sampled."""
        if not self.finished:
            raise RuntimeError("the render job is not finished: some pixels may have no sample yet")
        return self.session.image()

    def metadata(self) -> dict[str, object]:
        return image_metadata(self.scene, self.session.samples_per_pixel, self.session.width, self.session.height)

    def write(self, path: str | os.PathLike, *, exposure_stops: float = 0.0, tone_map: str = "clamp") -> Path:
        """Write the finished image with its metadata (.exr linear, .png tone mapped), whole or not at all."""
        from lenslab.render.film import write_image

        return write_image(path, self.image(), self.metadata(), exposure_stops=exposure_stops,
                           tone_map_operator=tone_map)

    def release(self) -> None:
        self.session.release()


def image_metadata(scene: Scene, spp: int, width: int, height: int) -> dict[str, object]:
    """Camera settings under Exif's names where it has one, LensLab's own otherwise."""
    cam = scene.camera
    sensor_w, sensor_h = cam.sensor_mm
    pixels_per_cm = float(width / (sensor_w / 10.0))  # the picture spans the sensor's width (square pixels)
    return {
        "Software": f"LensLab {__version__}",
        "Exif:FNumber": float(cam.f_number),
        "Exif:FocalLength": float(cam.focal_length_mm),
        "Exif:FocalLengthIn35mmFilm": int(round(cam.focal_length_mm * crop_factor(sensor_w, sensor_h))),
        "Exif:SubjectDistance": float(cam.focus_distance_m),
        # Sensor size in Exif's terms: pixels per centimetre of focal plane.
        "Exif:FocalPlaneXResolution": pixels_per_cm,
        "Exif:FocalPlaneYResolution": pixels_per_cm,
        "Exif:FocalPlaneResolutionUnit": 3,
        "lenslab:SensorWidthMM": float(sensor_w),
        "lenslab:SensorHeightMM": float(sensor_h),
        # The picture spans the sensor's width; its height follows the image's shape.
        "lenslab:ImageHeightMM": float(sensor_w * height / width),
        "lenslab:FocusDistanceM": float(cam.focus_distance_m),
        "lenslab:ApertureBlades": int(cam.aperture_blades),
        "lenslab:SamplesPerPixel": int(spp),
        "lenslab:Seed": int(scene.render.seed),
        "lenslab:MaxDepth": int(scene.render.max_depth),
        "lenslab:Sampler": scene.render.sampler,
        "lenslab:Clamp": float(scene.render.clamp),
    }
