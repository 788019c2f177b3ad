"""Where a lens sample lands on the aperture: a round stop or a polygon of straight blades.

The numeric twins of ``sample_concentric_disk`` and ``sample_polygon`` in glsl/sampling.glsl, written the same
way step by step so that the camera's Python rays (``lenslab.scene.camera.CameraFrame``) are the shader's rays;
tests/test_camera_rays.py runs both on the same numbers. Both map the unit square onto a shape of unit radius
uniformly by area, so a stratified (Sobol) pattern stays stratified on the lens.

Vectorised: ``u`` is an (N, 2) array of numbers in [0, 1); the result is (N, 2).
"""

from __future__ import annotations

import numpy as np

__all__ = ["sample_aperture", "sample_concentric_disk", "sample_polygon"]


def sample_concentric_disk(u) -> np.ndarray:
    """Shirley and Chiu's concentric map of the square onto the unit disk (area-preserving, low distortion)."""
    o = 2.0 * np.asarray(u, dtype=float) - 1.0
    x, y = o[..., 0], o[..., 1]
    wide = np.abs(x) > np.abs(y)
    safe_x = np.where(x == 0.0, 1.0, x)
    safe_y = np.where(y == 0.0, 1.0, y)
    r = np.where(wide, x, y)
    theta = np.where(wide, (np.pi / 4.0) * (y / safe_x), np.pi / 2.0 - (np.pi / 4.0) * (x / safe_y))
    disk = r[..., None] * np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    centre = (x == 0.0) & (y == 0.0)
    return np.where(centre[..., None], 0.0, disk)


def sample_polygon(u, blades: int, rotation_rad: float) -> np.ndarray:
    """A regular polygon of ``blades`` corners inscribed in the unit circle, one corner at ``rotation_rad``:
    choose one of its equal triangles (centre, corner k, corner k + 1) with u.x, reuse the remainder of u.x
    and u.y for a uniform point inside it."""
    u = np.asarray(u, dtype=float)
    n = float(blades)
    k = np.minimum(np.floor(u[..., 0] * n), n - 1.0)
    v = u[..., 0] * n - k
    a0 = rotation_rad + 2.0 * np.pi * k / n
    a1 = rotation_rad + 2.0 * np.pi * (k + 1.0) / n
    p0 = np.stack([np.cos(a0), np.sin(a0)], axis=-1)
    p1 = np.stack([np.cos(a1), np.sin(a1)], axis=-1)
    su = np.sqrt(v)[..., None]
    return su * ((1.0 - u[..., 1:2]) * p0 + u[..., 1:2] * p1)


def sample_aperture(u, blades: int, rotation_rad: float) -> np.ndarray:
    """A point on the unit aperture: the disk for ``blades`` = 0, else the polygon (as the shader chooses)."""
    return sample_polygon(u, blades, rotation_rad) if blades >= 3 else sample_concentric_disk(u)
