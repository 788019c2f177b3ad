"""The thin-lens camera, in photographic terms, and the one place its rays are worked out.

Conventions (docs/architecture.md, "The camera"; docs/scene-format.md): the camera sits at ``position`` and
looks towards ``look_at``; in its local frame it looks down -Z with +Y up, as in OpenGL, glTF and Blender. The
horizontal field of view follows from the focal length and the sensor width, ``2 atan(w / 2f)``; the image's
aspect ratio decides how much of the sensor height is used (the sensor is cropped, never stretched). The
aperture diameter is ``f / N``; the plane of focus is a plane at ``focus_distance_m`` along the view axis.

:class:`ThinLensCamera` is what a scene stores and a user edits. :meth:`ThinLensCamera.frame` derives, for an
image of a given size, the :class:`CameraFrame`: the camera's axes in the world, the tangents of the half
fields of view, the lens radius and the plane of focus, and the functions from pixels to rays. Everything that
needs a camera ray asks the frame: the shader's uniforms, click-to-focus picking, the studio's depth and
selection buffers, the placement of new objects. glsl/camera.glsl mirrors :meth:`CameraFrame.rays`
(tests/test_camera_rays.py runs both on the same numbers).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lenslab.optics.aperture import Aperture
from lenslab.optics.dof import COC_DIAGONAL_DIVISOR, DepthOfField
from lenslab.optics.exposure import (EXPOSURE_MODES, ISO_RANGE, METER_MODES, SHUTTER_RANGE_S, Exposure,
                                     camera_exposure, exposure_scale)
from lenslab.optics.framing import SENSOR_FITS, imaged_area_mm
from lenslab.optics.lens_system import LensSetting, LensSystem
from lenslab.optics.lenses import MAX_APERTURE_BLADES, LensPreset
from lenslab.optics.real_lenses import lens_setting, real_lens_system
from lenslab.optics.sensors import SENSOR_SIDE_RANGE_MM
from lenslab.optics.stops import F_NUMBER_CONTROL_RANGE, F_NUMBER_RANGE, format_f_number
from lenslab.optics.thinlens import (FOCAL_LENGTH_CONTROL_RANGE_MM, FOCAL_LENGTH_RANGE_MM, FOCUS_DISTANCE_RANGE_M,
                                     FOCUS_REFERENCES, MM_PER_M,
                                     closest_focus_m, image_distance_mm, lens_radius_m,
                                     object_distance_m, sensor_distance_m)

Vec3 = tuple[float, float, float]

#: The widest and tallest image LensLab renders, pixels.
MAX_IMAGE_SIDE = 16384
#: Anamorphic squeeze (bokeh height over width) LensLab accepts: 1 is a spherical lens; 1.33, 1.5, 1.8 and 2 are
#: the usual anamorphics; below 1 the oval lies on its side.
SQUEEZE_RANGE = (0.25, 4.0)
#: Circles of confusion LensLab accepts, mm: 0.5 um (a microscope) to 1 mm (a billboard seen from its foot).
COC_RANGE_MM = (0.0005, 1.0)


class CameraValueError(ValueError):
    """A camera value the camera cannot take, kept with its field so that each path names it in the user's words:
    the command line its option (``--focus-distance 0.01 m is nearer than ...``), a scene file its key, the studio
    its control. ``str()`` names the field as the scene format does."""

    def __init__(self, field_name: str, value, reason: str):
        self.field_name, self.value, self.reason = field_name, value, reason
        super().__init__(self.worded(field_name))

    def worded(self, name: str) -> str:
        """The message with the value called ``name`` ("--focus-distance", "camera.focus_distance_m", "Focus")."""
        unit = " m" if self.field_name.endswith("_m") else " mm" if self.field_name.endswith("_mm") else ""
        value = f"{self.value:g}" if isinstance(self.value, (int, float)) else str(self.value)
        return f"{name} {value}{unit} {self.reason}"


@dataclass
class ThinLensCamera:
    position: Vec3 = field(default=(0.0, 1.0, 5.0), metadata={"doc": "centre of the lens, metres"})
    look_at: Vec3 = field(default=(0.0, 1.0, 0.0), metadata={"doc": "a point on the view axis"})
    up: Vec3 = field(default=(0.0, 1.0, 0.0), metadata={"doc": "which way is up in the image"})
    # "range": what the field may hold (scene files, importers, the command line); "controls": what the studio's
    # controls offer, where that is less (scene/fields.py).
    focal_length_mm: float = field(default=50.0, metadata={"range": FOCAL_LENGTH_RANGE_MM,
                                                            "controls": FOCAL_LENGTH_CONTROL_RANGE_MM})
    f_number: float = field(default=2.8, metadata={"range": F_NUMBER_RANGE, "controls": F_NUMBER_CONTROL_RANGE,
                                                   "doc": "N; aperture diameter is f/N"})
    focus_distance_m: float = field(default=5.0, metadata={"range": FOCUS_DISTANCE_RANGE_M,
                                                                  "doc": "distance to the plane of focus"})
    focus_from: str = field(default="sensor", metadata={"choices": FOCUS_REFERENCES,
                                                        "doc": "what focus_distance_m is measured from"})
    focus_breathing: bool = field(default=True, metadata={
        "doc": "the sensor sits at the image distance, so framing changes with focus; false: one focal length"})
    sensor_mm: tuple[float, float] = field(default=(36.0, 24.0), metadata={"range": SENSOR_SIDE_RANGE_MM})
    sensor_fit: str = field(default="auto", metadata={"choices": SENSOR_FITS,
                                                      "doc": "which of the sensor's sides the image spans"})
    circle_of_confusion_mm: float | None = field(default=None, metadata={
        "range": COC_RANGE_MM, "doc": "sharpness criterion; null: the imaged area's diagonal / 1500"})
    aperture_blades: int = field(default=0, metadata={"range": (0, MAX_APERTURE_BLADES),
                                                          "doc": "0 = round; otherwise >= 3"})
    blade_rotation_deg: float = field(default=0.0, metadata={"range": (-360.0, 360.0)})
    blade_curvature: float = field(default=0.0, metadata={"range": (0.0, 1.0),
                                                          "doc": "0: straight blades .. 1: a round stop"})
    anamorphic_squeeze: float = field(default=1.0, metadata={"range": SQUEEZE_RANGE,
                                                             "doc": "bokeh height over width"})
    barrel_clipping: float = field(default=0.0, metadata={
        "range": (0.0, 1.0), "doc": "cat's-eye bokeh: how far the barrel cuts into the stop at the frame's corner"})
    aperture_image: str = field(default="", metadata={"doc": "a grayscale image of the stop; relative to the scene"})
    exposure_mode: str = field(default="compensated", metadata={"choices": EXPOSURE_MODES})
    iso: float = field(default=100.0, metadata={"range": ISO_RANGE})
    shutter_s: float = field(default=1.0 / 125.0, metadata={"range": SHUTTER_RANGE_S, "doc": "seconds"})
    metering: str = field(default="average", metadata={
        "choices": METER_MODES, "doc": "how the auto exposure meters: the centre-weighted average, or a spot at "
                                       "the frame's centre"})
    resolution: tuple[int, int] = field(default=(640, 480), metadata={"range": (1, MAX_IMAGE_SIDE)})
    pinhole: bool = field(default=False, metadata={"doc": "an ideal pinhole: everything sharp, the f-number ignored"})
    real_lens: str = field(default="", metadata={
        "doc": "a lens traced through its glass: a real lens preset's name or a prescription file (.toml, .json, "
               "pbrt's .dat; relative to the scene); empty: the thin lens (docs/lenses.md)"})
    dispersion: bool = field(default=True, metadata={
        "doc": "a real lens whose glass has Abbe numbers traces each sample at one colour's wavelength (its colour "
               "fringes, and colour noise until it converges); false: every colour at the d line, achromatic"})

    # -- the real lens ------------------------------------------------------------------------------------
    def lens_system(self) -> LensSystem | None:
        """The real lens this camera traces its rays through, or None for the thin lens. Its focal length is the
        glass's (``focal_length_mm`` holds it for the readouts); its sensor sits at its rear focal point at
        infinity focus, one focal length behind ``position``, and it focuses by moving forward."""
        return real_lens_system(self.real_lens) if self.real_lens else None

    def _real_focal_length_mm(self) -> float:
        return self.lens_system().efl

    def real_focus_from_sensor_mm(self) -> float:
        """The focus distance from the sensor, mm, in whichever reference it is given (the lens reference of a
        real lens is ``position``, one focal length ahead of the sensor)."""
        distance = float(self.focus_distance_m) * MM_PER_M
        return distance + (self._real_focal_length_mm() if self.focus_from == "lens" else 0.0)

    # -- derived quantities -------------------------------------------------------------------------------
    @property
    def fov_x(self) -> float:
        """Horizontal field of view of an image of the camera's own resolution, radians."""
        return self.frame().fov_x

    @property
    def lens_radius(self) -> float:
        """The entrance pupil's radius, metres (a thin lens's radius; a real lens's, paraxially)."""
        if self.real_lens:
            return lens_radius_m(self._real_focal_length_mm(), self.f_number)
        return 0.0 if self.pinhole else lens_radius_m(self.focal_length_mm, self.f_number)

    @property
    def plane_of_focus_m(self) -> float:
        """Distance from the lens to the plane in focus, metres (what the renderer needs)."""
        if self.real_lens:
            return (self.real_focus_from_sensor_mm() - self._real_focal_length_mm()) / MM_PER_M
        if self.focus_from == "lens" or self.pinhole:  # a pinhole has everything sharp: no plane to work out
            return float(self.focus_distance_m)
        return object_distance_m(self.focal_length_mm, self.focus_distance_m)

    @property
    def image_distance_mm(self) -> float:
        """Distance from the lens to the sensor, mm: the image distance of the plane of focus (focus breathing), or
        one focal length (framing held, as pbrt and Mitsuba). A real lens: its focal length and the distance it
        has moved forward to focus (paraxially; the renderer refines it by tracing)."""
        if self.real_lens:
            system = self.lens_system()
            return system.efl + system.paraxial_shift_for(self.real_focus_from_sensor_mm())
        if not self.focus_breathing or self.pinhole:
            return float(self.focal_length_mm)
        return image_distance_mm(self.focal_length_mm, self.plane_of_focus_m)

    @property
    def closest_focus_m(self) -> float:
        """The nearest focus distance this camera's lens can set, in its own reference (thin-lens limit): life
        size, the sensor two focal lengths behind the lens and the plane of focus two ahead, whichever reference
        the distance is read in. With the sensor held at one focal length (pbrt's and Mitsuba's camera, no
        breathing) the plane of focus may be anywhere: no sensor moves to follow it. A real lens reaches life size
        too, where it has moved one focal length forward (paraxially)."""
        if self.real_lens:
            system = self.lens_system()
            shift = system.efl if self.focus_from == "lens" else 0.0
            return (system.closest_focus_mm - shift) / MM_PER_M
        if self.pinhole or (self.focus_from == "lens" and not self.focus_breathing):
            return FOCUS_DISTANCE_RANGE_M[0]
        return closest_focus_m(self.focal_length_mm, self.focus_from)

    def closest_focus_with(self, lens: "LensPreset | None" = None) -> float:
        """The nearest focus distance (in this camera's reference) the camera can set with ``lens`` mounted: the
        thin lens's limit, and the lens's marked minimum, which a focus scale reads from the sensor plane."""
        closest = self.closest_focus_m
        if lens is None or lens.min_focus_distance_m is None or self.pinhole:
            return closest
        marked = float(lens.min_focus_distance_m)
        if self.real_lens and self.focus_from == "lens":  # position is one focal length ahead of the sensor
            return max(closest, marked - self._real_focal_length_mm() / MM_PER_M)
        if self.focus_from == "lens":  # the plane of focus that reading puts the sensor behind
            marked = object_distance_m(self.focal_length_mm, max(marked, 4.0 * self.focal_length_mm / MM_PER_M))
        return max(closest, marked)

    def focus_problem(self, lens: "LensPreset | None" = None) -> "CameraValueError | None":
        """Why the focus distance cannot be set on this camera (with ``lens`` mounted), or None. The one check
        every path makes: the scene files, the command line, batch shots and the studio."""
        distance = float(self.focus_distance_m)
        reference = "from the sensor" if self.focus_from == "sensor" else "from the lens"
        closest = self.closest_focus_with(lens)
        if distance >= closest * (1 - 1e-9):
            return None
        if closest > self.closest_focus_m:  # the lens's marked minimum says more than the thin lens's limit
            where = "" if self.focus_from == "sensor" else f" (the plane of focus {closest:.4g} m from the lens)"
            return CameraValueError("focus_distance_m", distance, f"{reference} is nearer than the {lens.name} "
                                    f"lens's minimum focus of {lens.min_focus_distance_m:g} m from the sensor{where}")
        if self.real_lens:
            return CameraValueError("focus_distance_m", distance, f"{reference} is nearer than the "
                                    f"{self.lens_system().name} can focus: at least {closest:.4g} m, where the "
                                    "image is life size")
        return CameraValueError("focus_distance_m", distance, f"{reference} is nearer than any "
                                f"{self.focal_length_mm:g} mm lens can focus: at least {closest:.4g} m, where the "
                                "image is life size")

    def focus_setting_for(self, depth_m: float) -> float:
        """The focus distance (in this camera's reference) that makes a point ``depth_m`` ahead of the lens, along
        the view axis, sharp: the value click-to-focus sets."""
        if self.focus_from == "lens":
            return float(depth_m)
        if self.real_lens:  # the sensor is one focal length behind position, whatever the focus
            return float(depth_m) + self._real_focal_length_mm() / MM_PER_M
        return sensor_distance_m(self.focal_length_mm, depth_m)

    def imaged_area_mm(self, width: int | None = None, height: int | None = None) -> tuple[float, float]:
        """The part of the sensor (mm) an image of ``width`` x ``height`` shows (default: the camera's own)."""
        width, height = int(width or self.resolution[0]), int(height or self.resolution[1])
        return imaged_area_mm(*self.sensor_mm, width, height, self.sensor_fit)

    def coc_mm(self, width: int | None = None, height: int | None = None) -> float:
        """The circle of confusion the depth-of-field readout uses: the camera's own, or the diagonal of the area
        the image shows / 1500."""
        if self.circle_of_confusion_mm is not None:
            return float(self.circle_of_confusion_mm)
        return math.hypot(*self.imaged_area_mm(width, height)) / COC_DIAGONAL_DIVISOR

    def aperture(self, base_dir: Path | None = None) -> Aperture:
        """The stop's shape; an aperture image is read relative to ``base_dir`` (the scene's folder)."""
        image = None
        if self.aperture_image:
            from lenslab.scene.aperture_images import read_aperture_image

            image = read_aperture_image(self.aperture_image, base_dir)
        return Aperture(blades=self.aperture_blades, rotation_rad=math.radians(self.blade_rotation_deg),
                        curvature=self.blade_curvature, squeeze=self.anamorphic_squeeze, image=image)

    def exposure_scale(self, light_fraction: float = 1.0) -> float:
        """What the image's radiance is multiplied by: 1 in the compensated mode; in the physical mode
        0.18 t S / (12.5 N^2) times the light the aperture passes (lenslab.optics.exposure). The auto mode's
        depends on the picture: :meth:`exposure`."""
        if self.exposure_mode != "physical":
            return 1.0
        return exposure_scale(self.f_number, self.shutter_s, self.iso, light_fraction)

    def exposure(self, light_fraction: float = 1.0, luminance: np.ndarray | None = None,
                 spot: tuple[float, float] = (0.5, 0.5), reading: float | None = None) -> Exposure:
        """This camera's exposure of a picture whose scene-linear luminance is ``luminance`` (H, W; the auto mode
        meters it with ``metering``), or of which the meter's ``reading`` was taken already:
        lenslab.optics.exposure.camera_exposure."""
        return camera_exposure(self.exposure_mode, self.f_number, self.shutter_s, self.iso, light_fraction,
                               luminance, self.metering, spot, reading)

    def depth_of_field(self, width: int | None = None, height: int | None = None,
                       light_fraction: float = 1.0, reference: str | None = None) -> DepthOfField:
        """Near and far limits of acceptable sharpness and the hyperfocal distance, in the camera's focus
        reference (or ``reference``: "lens" for depths along the view axis, as a depth buffer holds them), for
        exactly the picture the renderer draws.

        A point at depth d ahead of the lens makes a blur disk of diameter ``c = A |d - s| / d * v / s`` on the
        sensor (A the aperture's diameter, s the plane of focus, v the lens-to-sensor distance); the limits are
        the depths where c equals the circle of confusion. An aperture that passes less light than the round f/N
        stop counts with the diameter of a disk of its area."""
        f = self.focal_length_mm
        s = self.plane_of_focus_m * MM_PER_M
        v = self.image_distance_mm
        aperture = f / self.f_number * math.sqrt(light_fraction)
        c = self.coc_mm(width, height)
        blur_at_infinity = aperture * v / s  # c of a point at d = infinity: A v / s
        near = s / (1.0 + c / blur_at_infinity)
        far = s / (1.0 - c / blur_at_infinity) if c < blur_at_infinity else math.inf
        # The hyperfocal distance: the focus whose blur at infinity is c. With v = f s / (s - f) that is
        # s = f + A f / c (the textbook H = f^2 / (N c) + f); with v = f it is A f / c.
        hyperfocal = aperture * f / c + (f if self.focus_breathing else 0.0)
        from_sensor = (reference or self.focus_from) == "sensor"
        reference_shift = v if from_sensor else 0.0
        near_m, far_m = (near + reference_shift) / MM_PER_M, (far + reference_shift) / MM_PER_M
        if from_sensor:
            hyperfocal_m = (sensor_distance_m(f, hyperfocal / MM_PER_M) if self.focus_breathing
                            else (hyperfocal + f) / MM_PER_M)
        else:
            hyperfocal_m = hyperfocal / MM_PER_M
        return DepthOfField(near_m=near_m, far_m=far_m, hyperfocal_m=hyperfocal_m, total_m=far_m - near_m)

    def basis(self) -> np.ndarray:
        """Rows: right, up, back (+Z of the camera frame; the camera looks down -Z) in world space."""
        forward = np.subtract(self.look_at, self.position).astype(float)
        norm = np.linalg.norm(forward)
        if norm == 0:
            raise ValueError("camera look_at equals its position: no view direction")
        forward /= norm
        right = np.cross(forward, self.up)
        if np.linalg.norm(right) < 1e-9:
            raise ValueError("camera up is parallel to the view direction")
        right /= np.linalg.norm(right)
        true_up = np.cross(right, forward)
        return np.stack([right, true_up, -forward])

    def validate(self, lens: "LensPreset | None" = None) -> None:
        """Raise ValueError (CameraValueError for a value of one field) if the renderer cannot draw this camera,
        with ``lens`` mounted: the checks the field ranges cannot make alone."""
        if self.aperture_blades in (1, 2):
            raise ValueError("aperture_blades must be 0 (round) or at least 3")
        if self.real_lens:
            self._validate_real_lens()
        problem = self.focus_problem(lens)
        if problem is not None:
            raise problem
        self.basis()

    def _validate_real_lens(self) -> None:
        try:
            system = self.lens_system()
        except ValueError as exc:
            raise CameraValueError("real_lens", self.real_lens, f"cannot be mounted: {exc}") from None
        widest = system.marked_f_number
        if self.f_number < widest * (1 - 1e-3):
            raise CameraValueError("f_number", self.f_number, f"is wider than the {system.name} opens: "
                                   f"{format_f_number(widest)} at most")
        # The thin lens's stand-ins for what glass does: a real lens's glass does it (cat's eye, its own stop).
        for name, idle in (("anamorphic_squeeze", 1.0), ("barrel_clipping", 0.0), ("aperture_image", ""),
                           ("pinhole", False)):
            if getattr(self, name) != idle:
                raise CameraValueError(name, getattr(self, name), f"applies to the thin lens only: the "
                                       f"{system.name} is traced through its glass, which does this itself")

    def real_lens_setting(self, film_mm: tuple[float, float], base_dir: Path | None = None) -> LensSetting:
        """The real lens at this camera's f-number and focus, making an image of ``film_mm`` of sensor."""
        return lens_setting(self.lens_system(), self.f_number, self.real_focus_from_sensor_mm(), film_mm,
                            0.5 * math.hypot(*film_mm), self.aperture(base_dir), self.dispersion)

    def frame(self, width: int | None = None, height: int | None = None, *,
              base_dir: Path | None = None) -> "CameraFrame":
        """The camera as it makes an image of ``width`` x ``height`` pixels (default: its own resolution).

        The image shows the part of the sensor its sensor fit gives (lenslab.optics.framing): a viewport of
        another aspect ratio than the scene's shows more or less of the sensor, never a stretched picture. The
        field of view is that area seen from the lens-to-sensor distance. ``base_dir`` is where a relative
        aperture image is read from (the scene's folder)."""
        width = int(width or self.resolution[0])
        height = int(height or self.resolution[1])
        if width < 1 or height < 1:
            raise ValueError(f"an image needs at least one pixel each way, not {width} x {height}")
        right, up, back = self.basis()
        film_w, film_h = self.imaged_area_mm(width, height)
        if self.real_lens:
            setting = self.real_lens_setting((film_w, film_h), base_dir)
            v = setting.image_distance_mm
            return CameraFrame(position=np.asarray(self.position, dtype=float), right=right, up=up, back=back,
                               tan_half_fov=(film_w / (2.0 * v), film_h / (2.0 * v)), lens_radius=self.lens_radius,
                               focus_distance=self.plane_of_focus_m, aperture=setting.aperture,
                               barrel_clipping=0.0, film_mm=(film_w, film_h), image_distance_mm=v, width=width,
                               height=height, real_lens=setting)
        v = self.image_distance_mm
        return CameraFrame(position=np.asarray(self.position, dtype=float), right=right, up=up, back=back,
                           tan_half_fov=(film_w / (2.0 * v), film_h / (2.0 * v)), lens_radius=self.lens_radius,
                           focus_distance=self.plane_of_focus_m, aperture=self.aperture(base_dir),
                           barrel_clipping=float(self.barrel_clipping), film_mm=(film_w, film_h),
                           image_distance_mm=v, width=width, height=height)

    def view_frame(self, width: int, height: int, margin: float = 0.0, *,
                   base_dir: Path | None = None) -> "CameraFrame":
        """The camera as a viewport of ``width`` x ``height`` pixels shows it: the whole of the export's frame (the
        camera's resolution, framed as its sensor fit gives) centred, with at least ``margin`` of the frame's size
        to spare on each side, and more of the scene beyond it wherever the viewport's shape differs from the
        frame's (as a camera's viewfinder shows past the frame lines). Inside the frame the rays are the export's;
        the barrel's clipping keeps the export frame's corner as its reference, so cat's-eye bokeh matches."""
        frame = self.frame(width, height, base_dir=base_dir)
        export_w, export_h = self.imaged_area_mm(*self.resolution)
        aspect = width / height
        film_w = max(export_w, export_h * aspect) * (1.0 + 2.0 * margin)
        film_h = film_w / aspect
        v = frame.image_distance_mm
        # A real lens's pupil table reaches as far as the viewport's film: made again for it.
        setting = self.real_lens_setting((film_w, film_h), base_dir) if self.real_lens else None
        return dataclasses.replace(frame, tan_half_fov=(film_w / (2.0 * v), film_h / (2.0 * v)),
                                   film_mm=(film_w, film_h), gate_mm=(export_w, export_h), real_lens=setting)


@dataclass(frozen=True, eq=False)
class CameraFrame:
    """A camera at work on an image of ``width`` x ``height`` pixels: everything its rays are made from.

    Pixel coordinates are continuous, (0, 0) at the top-left corner of the image and (width, height) at the
    bottom-right; pixel (i, j)'s centre is (i + 0.5, j + 0.5). A pinhole ray through an image point has, in
    the camera's frame, the direction (x tan(fov_x / 2), y tan(fov_y / 2), -1) with x, y in [-1, 1] (+y up);
    it meets the plane of focus at that direction times ``focus_distance``. A thin-lens ray leaves a point of
    the aperture (``aperture``, in units of ``lens_radius``) and passes through that same point of focus, so
    everything on the plane of focus is sharp. With ``barrel_clipping``, the lens barrel's opening, seen from
    an image point off the axis, is shifted across the stop (by that fraction of the stop's radius at the
    frame's corner): rays outside it are blocked, giving cat's-eye bokeh and optical vignetting.
    """

    position: np.ndarray  # centre of the lens, world space
    right: np.ndarray  # unit axes of the camera in world space; it looks down -back
    up: np.ndarray
    back: np.ndarray
    tan_half_fov: tuple[float, float]  # tan(fov_x / 2), tan(fov_y / 2)
    lens_radius: float  # metres: the round f/N stop's radius; 0 for a pinhole
    focus_distance: float  # metres along the view axis from the lens to the plane of focus
    aperture: Aperture  # the stop's shape, in units of lens_radius
    barrel_clipping: float  # 0: none; 1: the barrel's opening shifted by the stop's radius at the corner
    film_mm: tuple[float, float]  # width and height of the sensor area the image shows
    image_distance_mm: float  # lens to sensor
    width: int
    height: int
    # The export's frame (mm of film) where this image shows more than it (a viewport's view_frame); None: the
    # image is the export's frame.
    gate_mm: tuple[float, float] | None = None
    # A real lens at this frame's focus and f-number (its rays come from tracing its glass); None: the thin lens.
    real_lens: LensSetting | None = None

    @property
    def gate_pixels(self) -> tuple[float, float, float, float]:
        """The export's frame in this image: (left, top, width, height) in pixels, centred."""
        if self.gate_mm is None:
            return 0.0, 0.0, float(self.width), float(self.height)
        w = self.width * self.gate_mm[0] / self.film_mm[0]
        h = self.height * self.gate_mm[1] / self.film_mm[1]
        return (self.width - w) / 2.0, (self.height - h) / 2.0, w, h

    @property
    def forward(self) -> np.ndarray:
        """The view axis: the direction the camera looks."""
        return -self.back

    @property
    def to_world(self) -> np.ndarray:
        """3 x 3 rotation from the camera's frame to the world's; its columns are right, up, back."""
        return np.stack([self.right, self.up, self.back], axis=1)

    @property
    def fov_x(self) -> float:
        """Horizontal field of view of this image, radians."""
        return 2.0 * math.atan(self.tan_half_fov[0])

    @property
    def fov_y(self) -> float:
        """Vertical field of view of this image, radians."""
        return 2.0 * math.atan(self.tan_half_fov[1])

    @property
    def barrel_opening(self) -> tuple[tuple[float, float], float]:
        """The barrel's opening in aperture units: (its shift per unit of image coordinate x and y in [-1, 1], its
        radius). The opening is the circle around the stop; at the frame's corner it is shifted by
        ``barrel_clipping`` times its radius, and in between in proportion to the distance from the centre on the
        film (so in proportion to the tangent of the field angle, as the projection of an opening in front of the
        stop would be)."""
        radius = max(self.aperture.axes)
        half_w, half_h = self.film_mm[0] / 2.0, self.film_mm[1] / 2.0
        corner_w, corner_h = (self.gate_mm or self.film_mm)[0] / 2.0, (self.gate_mm or self.film_mm)[1] / 2.0
        gain = self.barrel_clipping * radius / math.hypot(corner_w, corner_h)
        return (gain * half_w, gain * half_h), radius

    def view_size_at(self, distance: float) -> tuple[float, float]:
        """Width and height in metres of what the image shows on a plane ``distance`` ahead of the lens."""
        return 2.0 * distance * self.tan_half_fov[0], 2.0 * distance * self.tan_half_fov[1]

    def focus_point(self) -> np.ndarray:
        """The point where the view axis meets the plane of focus."""
        return self.position + self.focus_distance * self.forward

    def depth_of(self, points) -> np.ndarray | float:
        """Distance along the view axis from the lens to world ``points`` (..., 3)."""
        depth = (np.asarray(points, dtype=float) - self.position) @ self.forward
        return float(depth) if np.ndim(depth) == 0 else depth

    def pixel_centres(self) -> np.ndarray:
        """(H * W, 2) continuous coordinates of every pixel's centre, row by row from the top."""
        xs = np.arange(self.width) + 0.5
        ys = np.arange(self.height) + 0.5
        return np.stack(np.broadcast_arrays(xs[None, :], ys[:, None]), axis=-1).reshape(-1, 2)

    def pinhole_directions(self, pixels) -> np.ndarray:
        """Unit world directions (N, 3) of the rays through the lens centre and the image points ``pixels``
        (N, 2), in continuous pixel coordinates."""
        local = self._pinhole_local(pixels)
        if self.real_lens is not None:  # the chief rays: through the centre of the stop
            return self.rays(pixels)[1]
        directions = local @ self.to_world.T
        return directions / np.linalg.norm(directions, axis=-1, keepdims=True)

    def rays(self, pixels, lens_samples=None, *, with_weights: bool = False):
        """World origins and unit directions (each (N, 3)) of the camera rays through image points ``pixels``
        (N, 2). ``lens_samples`` (N, 2) in [0, 1) choose each ray's point on the aperture, as the renderer's
        sampler does; without them every ray leaves the lens centre (the pinhole rays). ``with_weights`` adds
        each ray's weight (N,): 0 where the barrel blocks it, else the aperture sample's weight.

        A real lens's rays are traced through its glass (:meth:`LensSetting.rays`, glsl/real_lens.glsl): without
        lens samples they are its chief rays, leaving the front element; their weights are (N, 3), one per colour
        channel (a dispersive lens traces each sample at one channel's wavelength)."""
        pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
        if self.real_lens is not None:
            origins, directions, weights = self.real_lens.rays(pixels, self.width, self.height, lens_samples)
            origins = self.position + (origins / MM_PER_M) @ self.to_world.T
            directions = directions @ self.to_world.T
            return (origins, directions, weights) if with_weights else (origins, directions)
        focus = self._pinhole_local(pixels) * self.focus_distance
        lens = np.zeros_like(focus)
        weights = np.ones(len(pixels))
        if lens_samples is not None:
            points, weights = self.aperture.sample(np.asarray(lens_samples, dtype=float).reshape(-1, 2))
            if self.barrel_clipping > 0.0:
                (gain_x, gain_y), radius = self.barrel_opening
                ndc = self._ndc(pixels)
                shift = ndc * np.array([gain_x, gain_y])
                weights = np.where(np.linalg.norm(points - shift, axis=-1) <= radius, weights, 0.0)
            lens[:, :2] = self.lens_radius * points
        directions = (focus - lens) @ self.to_world.T
        directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
        origins = self.position + lens @ self.to_world.T
        return (origins, directions, weights) if with_weights else (origins, directions)

    def _ndc(self, pixels: np.ndarray) -> np.ndarray:
        """Image coordinates in [-1, 1], +y up."""
        return np.stack([2.0 * pixels[:, 0] / self.width - 1.0, 1.0 - 2.0 * pixels[:, 1] / self.height], axis=-1)

    def _pinhole_local(self, pixels) -> np.ndarray:
        ndc = self._ndc(np.asarray(pixels, dtype=float).reshape(-1, 2))
        tan_x, tan_y = self.tan_half_fov
        return np.stack([ndc[:, 0] * tan_x, ndc[:, 1] * tan_y, -np.ones(len(ndc))], axis=-1)
