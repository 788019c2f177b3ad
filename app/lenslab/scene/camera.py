"""The thin-lens camera, in photographic terms.

Conventions (see docs/scene-format.md and DESIGN.md): the camera sits at ``position`` and looks towards
``look_at``; in its local frame it looks down -Z with +Y up, as in OpenGL, glTF and Blender. The horizontal
field of view follows from the focal length and the sensor width, ``2 atan(w / 2f)``; the image's aspect ratio
decides how much of the sensor height is used (the sensor is cropped, never stretched). The aperture
diameter is ``f / N``; the plane of focus is a plane at ``focus_distance_m`` along the view axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from lenslab.optics.thinlens import field_of_view_x, lens_radius_m

Vec3 = tuple[float, float, float]


@dataclass
class ThinLensCamera:
    position: Vec3 = field(default=(0.0, 1.0, 5.0), metadata={"doc": "centre of the lens, metres"})
    look_at: Vec3 = field(default=(0.0, 1.0, 0.0), metadata={"doc": "a point on the view axis"})
    up: Vec3 = field(default=(0.0, 1.0, 0.0), metadata={"doc": "which way is up in the image"})
    focal_length_mm: float = field(default=50.0, metadata={"range": (1.0, 2000.0)})
    f_number: float = field(default=2.8, metadata={"range": (0.5, 128.0), "doc": "N; aperture diameter is f/N"})
    focus_distance_m: float = field(default=5.0, metadata={"range": (0.01, 1e6), "doc": "distance to the plane of focus"})
    sensor_mm: tuple[float, float] = field(default=(36.0, 24.0), metadata={"range": (1.0, 500.0)})
    aperture_blades: int = field(default=0, metadata={"range": (0, 32), "doc": "0 = round; otherwise >= 3"})
    blade_rotation_deg: float = field(default=0.0, metadata={"range": (-360.0, 360.0)})
    resolution: tuple[int, int] = field(default=(640, 480), metadata={"range": (1, 16384)})
    pinhole: bool = field(default=False, metadata={"doc": "an ideal pinhole: everything sharp, the f-number ignored"})

    # -- derived quantities -------------------------------------------------------------------------------
    @property
    def fov_x(self) -> float:
        return field_of_view_x(self.focal_length_mm, self.sensor_mm[0])

    @property
    def lens_radius(self) -> float:
        return 0.0 if self.pinhole else lens_radius_m(self.focal_length_mm, self.f_number)

    @property
    def aspect(self) -> float:
        return self.resolution[0] / self.resolution[1]

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

    def primary_ray_direction(self, ndc_x: float, ndc_y: float) -> np.ndarray:
        """World direction of the pinhole ray through a point of the image, ndc in [-1, 1], +y up."""
        tan_x = math.tan(self.fov_x / 2)
        tan_y = tan_x / self.aspect
        right, up, back = self.basis()
        d = ndc_x * tan_x * right + ndc_y * tan_y * up - back
        return d / np.linalg.norm(d)
