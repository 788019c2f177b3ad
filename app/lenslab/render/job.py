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
from typing import Callable

import numpy as np

from lenslab import __version__
from lenslab.colour_management.view import ViewTransform
from lenslab.colour_management.working_space import luminance
from lenslab.optics.exposure import camera_exposure
from lenslab.optics.sensors import crop_factor
from lenslab.optics.stops import format_f_number
from lenslab.render.tracer import DEFAULT_DISPATCH_SECONDS, Renderer, RenderSession
from lenslab.scene.camera import CameraFrame
from lenslab.scene.options import OPTIONS
from lenslab.scene.scene import Scene

#: :meth:`RenderJob.run` renders for about this long between progress reports.
REPORT_SECONDS = 0.5
#: The GPU time of one dispatch for a job no one watches sample by sample (``--headless``, batch parts, validate):
#: longer than the session's default, so less of it goes to launching kernels and reading progress back.
OFFLINE_DISPATCH_SECONDS = 0.25


#: The channels a denoised EXR keeps beside its R, G, B (RenderJob.denoised): noisy.RGB, albedo.RGB, normal.XYZ.
DENOISED_LAYER_CHANNELS = 9


def estimated_export_bytes(path: str | os.PathLike, width: int, height: int, denoise: bool = False) -> int:
    """What :meth:`RenderJob.write` will need on disk for a ``width`` x ``height`` image at ``path``: for a check of
    the output folder before the render (lenslab.atomic.check_output_folder)."""
    from lenslab.render.film import estimated_file_bytes

    return estimated_file_bytes(path, width, height, DENOISED_LAYER_CHANNELS if denoise else 0)


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


def _check_terms(spp: int | None, time_limit: float | None) -> None:
    if spp is not None and spp < 1:
        raise ValueError(f"a render needs at least 1 sample per pixel, not {spp}")
    if time_limit is not None and not time_limit > 0:
        raise ValueError(f"a time limit must be positive, not {time_limit}")


class RenderJob:
    """Render ``scene`` to ``spp`` samples per pixel, or for ``time_limit`` seconds, or both (whichever comes
    first). With neither, the scene's own sample count. The image is the scene camera's resolution.
    ``first_sample`` starts the sample indices elsewhere than 0: one part of a render split across workers.
    ``feature_buffers`` accumulates the denoiser's albedo and normal guides beside the image, for
    ``write(denoise=True)``; the image itself is the same with or without them."""

    def __init__(self, renderer: Renderer, scene: Scene, *, spp: int | None = None, time_limit: float | None = None,
                 dispatch_seconds: float = DEFAULT_DISPATCH_SECONDS, first_sample: int = 0,
                 feature_buffers: bool = False):
        _check_terms(spp, time_limit)  # before the session: refused without building anything
        session = RenderSession(renderer, scene, dispatch_seconds=dispatch_seconds, first_sample=first_sample,
                                feature_buffers=feature_buffers)
        self._take(session, spp, time_limit)

    @classmethod
    def of_session(cls, session: RenderSession, *, spp: int | None = None,
                   time_limit: float | None = None) -> RenderJob:
        """A job that renders a session made elsewhere (another size, kernel, view or render region than a job
        makes from the scene, or one already edited), on the same terms: ``spp``, ``time_limit``, or the scene's
        own sample count. The session stays its maker's to release."""
        job = cls.__new__(cls)
        job._take(session, spp, time_limit)
        return job

    def _take(self, session: RenderSession, spp: int | None, time_limit: float | None) -> None:
        _check_terms(spp, time_limit)
        self.scene = session.scene
        self.target_spp = spp if spp is not None else (None if time_limit else session.scene.render.spp)
        self.time_limit = time_limit
        self.session = session
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

    def render(self, on_progress=None) -> None:
        """Render until finished, calling ``on_progress(JobProgress)`` after each slice."""
        while not self.finished:
            progress = self.step(REPORT_SECONDS)
            if on_progress is not None:
                on_progress(progress)

    def run(self, on_progress=None) -> np.ndarray:
        """Render until finished (:meth:`render`); the linear image."""
        self.render(on_progress)
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

    def metadata(self, image: np.ndarray | None = None) -> dict[str, object]:
        """The image's metadata; an auto exposure meters ``image`` (the finished image when not given)."""
        metadata = image_metadata(self.scene, self.session.samples_per_pixel, self.session.frame)
        if self.scene.camera.exposure_mode == "auto":
            metadata.update(exposure_metadata(metadata, self.image() if image is None else image))
        return metadata

    def write(self, path: str | os.PathLike, *, view: ViewTransform = ViewTransform(),
              before_rename: Callable[[], None] | None = None, denoise: bool = False) -> Path:
        """Write the finished image with its metadata (.exr linear, a picture through the view transform ``view``),
        whole or not at all. A camera in the physical or auto exposure mode exposes both (docs/colour.md,
        "Exposure"); the auto mode meters the image that is written. ``before_rename``
        runs once the file is whole, just before it takes the name (lenslab.atomic.atomic_path).

        ``denoise``: the main image is the denoised one (:meth:`denoised`), and the metadata says so; an EXR also
        keeps the noisy image and the guides as layers ``noisy.RGB``, ``albedo.RGB`` and ``normal.XYZ``. Never
        without being asked."""
        from lenslab.render.film import ExportError, write_image
        from lenslab.render.denoise import DenoiseError

        if not denoise:
            image, layers, denoiser = self.image(), (), None
        else:
            try:
                image, layers, denoiser = self.denoised()
            except DenoiseError as exc:  # before anything is written: the file is not touched
                raise ExportError(f"{path}: cannot denoise ({exc})") from None
        metadata = self.metadata(image)
        if denoiser is not None:
            metadata.update({"lenslab:Denoiser": denoiser, "lenslab:Denoised": 1})
        return write_image(path, image, metadata, sensor_exposure=metadata["lenslab:ExposureScale"],
                           view=view, before_rename=before_rename, layers=layers)

    def denoised(self) -> tuple[np.ndarray, tuple, str]:
        """(the denoised image, the EXR layers to keep beside it, how it was denoised). A final frame: the guides
        are prefiltered (render/denoise.py); a job without feature buffers is denoised from its colour alone."""
        from lenslab.render.denoise import denoise, describe
        from lenslab.render.film import Layer

        noisy = self.image()
        if not self.session.feature_buffers:
            return denoise(noisy), (Layer("noisy", noisy),), f"{describe()}; RT filter, no guides"
        albedo, normal = self.session.features_image()
        layers = (Layer("noisy", noisy), Layer("albedo", albedo, radiance=False),
                  Layer("normal", normal, ("X", "Y", "Z"), radiance=False))
        return (denoise(noisy, albedo, normal, prefilter=True), layers,
                f"{describe()}; RT filter, first-hit albedo and normal guides, prefiltered")

    def release(self) -> None:
        self.session.release()


def image_metadata(scene: Scene, spp: int, frame: CameraFrame) -> dict[str, object]:
    """What a photograph's file says about how it was made: Exif's names (as OpenImageIO spells them) where Exif
    has one, the OpenEXR standard camera matrices, and LensLab's own names for the rest.

    ``frame`` is the camera as it made this image (its size, the part of the sensor it shows, its aperture)."""
    cam = scene.camera
    film_w, film_h = frame.film_mm
    sensor_w, sensor_h = cam.sensor_mm
    pixels_per_cm = float(frame.width / (film_w / 10.0))  # the picture spans film_w of the focal plane
    light_fraction = frame.aperture.light_fraction
    # What the render used for each option a user can give (scene/options.py), under the option's metadata name.
    used: dict[str, object] = {
        "f_number": float(cam.f_number),
        "focal_length": float(cam.focal_length_mm),
        "focus_distance": float(cam.focus_distance_m),
        "sensor_fit": cam.sensor_fit,
        "focus_from": cam.focus_from,
        "focus_breathing": int(cam.focus_breathing),
        "circle_of_confusion": float(cam.coc_mm(frame.width, frame.height)),
        "aperture_blades": int(cam.aperture_blades),
        "blade_curvature": float(cam.blade_curvature),
        "anamorphic_squeeze": float(cam.anamorphic_squeeze),
        "barrel_clipping": float(cam.barrel_clipping),
        "exposure_mode": cam.exposure_mode,
        "metering": cam.metering,
        "working_space": scene.render.working_space,
        "spp": int(spp),
        "seed": int(scene.render.seed),
        "max_depth": int(scene.render.max_depth),
        "sampler": scene.render.sampler,
        "clamp": float(scene.render.clamp),
    }
    if cam.aperture_image:
        used["aperture_image"] = cam.aperture_image
    if frame.real_lens is not None:  # the thin lens's stand-ins: the glass does their work, they do nothing
        for name in ("anamorphic_squeeze", "barrel_clipping", "focus_breathing"):
            del used[name]
        used["dispersion"] = int(cam.dispersion)
    if cam.exposure_mode != "compensated":
        used.update(shutter=float(cam.shutter_s), iso=int(round(cam.iso)))
    metadata: dict[str, object] = {
        "Software": f"LensLab {__version__}",
        **{OPTIONS[name].metadata: value for name, value in used.items()},
        "Exif:FocalLengthIn35mmFilm": int(round(cam.focal_length_mm * crop_factor(sensor_w, sensor_h))),
        "Exif:SubjectDistance": float(cam.focus_distance_m),
        # Sensor size in Exif's terms: pixels per centimetre of focal plane.
        "Exif:FocalPlaneXResolution": pixels_per_cm,
        "Exif:FocalPlaneYResolution": pixels_per_cm,
        "Exif:FocalPlaneResolutionUnit": 3,
        "Exif:ExposureMode": 1 if cam.exposure_mode == "physical" else 0,  # manual, or auto
        "Exif:ExposureProgram": EXIF_EXPOSURE_PROGRAM[cam.exposure_mode],
        "lenslab:Aperture": format_f_number(cam.f_number),  # the marked stop ("f/11" for 11.31)
        "lenslab:SensorWidthMM": float(sensor_w),
        "lenslab:SensorHeightMM": float(sensor_h),
        "lenslab:ImageWidthMM": float(film_w),
        "lenslab:ImageHeightMM": float(film_h),
        "lenslab:PlaneOfFocusM": float(frame.focus_distance),
        "lenslab:ImageDistanceMM": float(frame.image_distance_mm),
        "lenslab:ApertureLightFraction": float(light_fraction),
        "lenslab:ExposureScale": float(cam.exposure_scale(light_fraction)),
        "worldtocamera": world_to_camera(frame),
        "worldtoNDC": world_to_ndc(frame),
    }
    if cam.exposure_mode == "physical":
        metadata["lenslab:EV100"] = camera_exposure("physical", cam.f_number, cam.shutter_s, cam.iso).ev100
    if frame.real_lens is not None:
        metadata.update(real_lens_metadata(frame))
    return metadata


#: Exif's ExposureProgram: 0 not defined (compensated: no camera setting made the brightness), 1 manual, 3 aperture
#: priority (the auto mode keeps the f-number and chooses the shutter).
EXIF_EXPOSURE_PROGRAM = {"compensated": 0, "physical": 1, "auto": 3}


def exposure_metadata(metadata: dict[str, object], image: np.ndarray) -> dict[str, object]:
    """The entries of an auto exposure's metadata once ``image`` (the linear picture, before exposure) is metered:
    the scale, the shutter the meter chose, its EV100 and the reading. From the metadata alone, so that a batch shot
    merged from parts meters the merged image."""
    exposure = camera_exposure("auto", float(metadata[OPTIONS["f_number"].metadata]),
                               float(metadata[OPTIONS["shutter"].metadata]), float(metadata[OPTIONS["iso"].metadata]),
                               float(metadata["lenslab:ApertureLightFraction"]),
                               luminance(image, str(metadata[OPTIONS["working_space"].metadata])),
                               str(metadata[OPTIONS["metering"].metadata]))
    return {"lenslab:ExposureScale": exposure.scale, OPTIONS["shutter"].metadata: exposure.shutter_s,
            "lenslab:EV100": exposure.ev100, "lenslab:MeteredLuminance": exposure.metered_cd_m2}


def real_lens_metadata(frame: CameraFrame) -> dict[str, object]:
    """A real lens named as Exif names a lens (LensModel), with what its glass did for this image: how far it
    moved to focus, its stop, and where its numbers come from."""
    setting = frame.real_lens
    system = setting.system
    return {
        "Exif:LensModel": system.name,
        "lenslab:RealLens": system.name,
        "lenslab:RealLensSource": system.prescription.source or system.prescription.description,
        "lenslab:RealLensFile": str(system.prescription.path or ""),
        "lenslab:RealLensSurfaces": len(system.radius),
        "lenslab:RealLensFocusShiftMM": float(setting.shift),
        "lenslab:RealLensStopDiameterMM": float(2.0 * setting.stop_radius),
        "lenslab:RealLensDispersive": int(setting.dispersive),
    }


def world_to_camera(frame: CameraFrame) -> np.ndarray:
    """OpenEXR's ``worldToCamera``: a 4 x 4 matrix for row vectors (p_camera = p_world M), to a left-handed camera
    space with x right, y up and z the viewing direction."""
    rotation = np.stack([frame.right, frame.up, frame.forward])  # rows: the camera's axes in the world
    matrix = np.eye(4)
    matrix[:3, :3] = rotation.T
    matrix[3, :3] = -frame.position @ rotation.T
    return matrix


def world_to_ndc(frame: CameraFrame) -> np.ndarray:
    """OpenEXR's ``worldToNDC``: world points to the image, (0, 0) its top-left corner and (1, 1) its bottom-right,
    after division by w (row vectors). The pinhole projection through the lens centre; z / w is 1 / depth."""
    tan_x, tan_y = frame.tan_half_fov
    projection = np.array([[0.5 / tan_x, 0.0, 0.0, 0.0],
                           [0.0, -0.5 / tan_y, 0.0, 0.0],
                           [0.5, 0.5, 0.0, 1.0],
                           [0.0, 0.0, 1.0, 0.0]])
    return world_to_camera(frame) @ projection
