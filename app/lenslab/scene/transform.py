"""Node transforms: translation, rotation and scale, composed as T * R * S.

Rotation is given as Euler angles in degrees, applied about X, then Y, then Z (the matrix is Rz @ Ry @ Rx),
as in Blender's default "XYZ" mode, so that what a user types matches what they know from other tools.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

Vec3 = tuple[float, float, float]


def _rotation_matrix(degrees_xyz: Vec3) -> np.ndarray:
    ax, ay, az = (math.radians(a) for a in degrees_xyz)
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


@dataclass
class Transform:
    """Where a node sits relative to its parent."""

    translate: Vec3 = field(default=(0.0, 0.0, 0.0), metadata={"doc": "offset in metres"})
    rotate_deg: Vec3 = field(default=(0.0, 0.0, 0.0), metadata={"doc": "Euler angles in degrees, X then Y then Z"})
    scale: Vec3 = field(default=(1.0, 1.0, 1.0), metadata={"doc": "scale factors", "nonzero": True})

    def matrix(self) -> np.ndarray:
        """The 4x4 matrix taking local points to the parent's space."""
        m = np.eye(4)
        m[:3, :3] = _rotation_matrix(self.rotate_deg) @ np.diag(self.scale)
        m[:3, 3] = self.translate
        return m

    def is_identity(self) -> bool:
        return self == Transform()


def transform_points(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def transform_normals(matrix: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Normals transform by the inverse transpose, so that they stay normal under non-uniform scale."""
    n = normals @ np.linalg.inv(matrix[:3, :3])
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    return n / np.maximum(length, 1e-30)
