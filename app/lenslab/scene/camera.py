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

import math
from dataclasses import dataclass, field

import numpy as np

from lenslab.optics.aperture import sample_aperture
from lenslab.optics.lenses import MAX_APERTURE_BLADES
from lenslab.optics.sensors import SENSOR_SIDE_RANGE_MM
from lenslab.optics.stops import F_NUMBER_RANGE
from lenslab.optics.thinlens import FOCAL_LENGTH_RANGE_MM, FOCUS_DISTANCE_RANGE_M, field_of_view_x, lens_radius_m

Vec3 = tuple[float, float, float]

#: The widest and tallest image LensLab renders, pixels.
MAX_IMAGE_SIDE = 16384


@dataclass
class ThinLensCamera:
    position: Vec3 = field(default=(0.0, 1.0, 5.0), metadata={"doc": "centre of the lens, metres"})
    look_at: Vec3 = field(default=(0.0, 1.0, 0.0), metadata={"doc": "a point on the view axis"})
    up: Vec3 = field(default=(0.0, 1.0, 0.0), metadata={"doc": "which way is up in the image"})
    focal_length_mm: float = field(default=50.0, metadata={"range": FOCAL_LENGTH_RANGE_MM})
    f_number: float = field(default=2.8, metadata={"range": F_NUMBER_RANGE, "doc": "N; aperture diameter is f/N"})
    focus_distance_m: float = field(default=5.0, metadata={"range": FOCUS_DISTANCE_RANGE_M,
                                                                  "doc": "distance to the plane of focus"})
    sensor_mm: tuple[float, float] = field(default=(36.0, 24.0), metadata={"range": SENSOR_SIDE_RANGE_MM})
    aperture_blades: int = field(default=0, metadata={"range": (0, MAX_APERTURE_BLADES),
                                                          "doc": "0 = round; otherwise >= 3"})
    blade_rotation_deg: float = field(default=0.0, metadata={"range": (-360.0, 360.0)})
    resolution: tuple[int, int] = field(default=(640, 480), metadata={"range": (1, MAX_IMAGE_SIDE)})
    pinhole: bool = field(default=False, metadata={"doc": "an ideal pinhole: everything sharp, the f-number ignored"})

    # -- derived quantities -------------------------------------------------------------------------------
    @property
    def fov_x(self) -> float:
        return field_of_view_x(self.focal_length_mm, self.sensor_mm[0])

    @property
    def lens_radius(self) -> float:
        return 0.0 if self.pinhole else lens_radius_m(self.focal_length_mm, self.f_number)

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

    def validate(self) -> None:
        if self.aperture_blades in (1, 2):
            raise ValueError("aperture_blades must be 0 (round) or at least 3")
        self.basis()

    def frame(self, width: int | None = None, height: int | None = None) -> "CameraFrame":
        """The camera as it makes an image of ``width`` x ``height`` pixels (default: its own resolution).

        The image spans the sensor's width; its height follows the image's shape, so a viewport of another
        aspect ratio than the scene's shows more or less above and below, never a stretched picture."""
        width = int(width or self.resolution[0])
        height = int(height or self.resolution[1])
        if width < 1 or height < 1:
            raise ValueError(f"an image needs at least one pixel each way, not {width} x {height}")
        right, up, back = self.basis()
        tan_x = math.tan(self.fov_x / 2.0)
        return CameraFrame(position=np.asarray(self.position, dtype=float), right=right, up=up, back=back,
                           tan_half_fov=(tan_x, tan_x * height / width), lens_radius=self.lens_radius,
                           focus_distance=float(self.focus_distance_m), blades=int(self.aperture_blades),
                           blade_rotation=math.radians(self.blade_rotation_deg), width=width, height=height)


@dataclass(frozen=True, eq=False)
class CameraFrame:
    """A camera at work on an image of ``width`` x ``height`` pixels: everything its rays are made from.

    Pixel coordinates are continuous, (0, 0) at the top-left corner of the image and (width, height) at the
    bottom-right; pixel (i, j)'s centre is (i + 0.5, j + 0.5). A pinhole ray through an image point has, in
    the camera's frame, the direction (x tan(fov_x / 2), y tan(fov_y / 2), -1) with x, y in [-1, 1] (+y up);
    it meets the plane of focus at that direction times ``focus_distance``. A thin-lens ray leaves a point of
    the aperture (a disk of radius ``lens_radius``, or a polygon of ``blades`` corners) and passes through
    that same point of focus, so everything on the plane of focus is sharp.
    """

    position: np.ndarray  # centre of the lens, world space
    right: np.ndarray  # unit axes of the camera in world space; it looks down -back
    up: np.ndarray
    back: np.ndarray
    tan_half_fov: tuple[float, float]  # tan(fov_x / 2), tan(fov_y / 2)
    lens_radius: float  # metres; 0 for a pinhole
    focus_distance: float  # metres along the view axis to the plane of focus
    blades: int  # 0: a round aperture
    blade_rotation: float  # radians
    width: int
    height: int

    @property
    def forward(self) -> np.ndarray:
        """The view axis: the direction the camera looks."""
        return -self.back

    @property
    def to_world(self) -> np.ndarray:
        """3 x 3 rotation from the camera's frame to the world's; its columns are right, up, back."""
        return np.stack([self.right, self.up, self.back], axis=1)

    @property
    def fov_y(self) -> float:
        """Vertical field of view of this image, radians."""
        return 2.0 * math.atan(self.tan_half_fov[1])

    def view_size_at(self, distance: float) -> tuple[float, float]:
        """Width and height in metres of what the image shows on a plane ``distance`` ahead of the lens."""
        return 2.0 * distance * self.tan_half_fov[0], 2.0 * distance * self.tan_half_fov[1]

    def focus_point(self) -> np.ndarray:
        """The point where the view axis meets the plane of focus."""
        return self.position + self.focus_distance * self.forward

    def depth_of(self, points) -> np.ndarray | float:
        """Distance along the view axis to world ``points`` (..., 3): the focus distance that makes each sharp."""
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
        directions = local @ self.to_world.T
        return directions / np.linalg.norm(directions, axis=-1, keepdims=True)

    def rays(self, pixels, lens_samples=None) -> tuple[np.ndarray, np.ndarray]:
        """World origins and unit directions (each (N, 3)) of the camera rays through image points ``pixels``
        (N, 2). ``lens_samples`` (N, 2) in [0, 1) choose each ray's point on the aperture, as the renderer's
        sampler does; without them every ray leaves the lens centre (the pinhole rays)."""
        pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
        focus = self._pinhole_local(pixels) * self.focus_distance
        lens = np.zeros_like(focus)
        if lens_samples is not None:
            aperture = sample_aperture(np.asarray(lens_samples, dtype=float).reshape(-1, 2), self.blades,
                                       self.blade_rotation)
            lens[:, :2] = self.lens_radius * aperture
        directions = (focus - lens) @ self.to_world.T
        directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
        origins = self.position + lens @ self.to_world.T
        return origins, directions

    def _pinhole_local(self, pixels) -> np.ndarray:
        pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
        ndc_x = 2.0 * pixels[:, 0] / self.width - 1.0
        ndc_y = 1.0 - 2.0 * pixels[:, 1] / self.height
        tan_x, tan_y = self.tan_half_fov
        return np.stack([ndc_x * tan_x, ndc_y * tan_y, -np.ones_like(ndc_x)], axis=-1)
