"""Environment maps: the lat-long mapping and the piecewise-constant distribution that importance-samples
them (pbrt-v4's PiecewiseConstant2D over (u, v), weighted by sin(theta) for the sphere's area).

Directions map to (u, v) in [0, 1)^2 with v = 0 straight up (+Y, the image's top row) and u = 0.5 looking
down -Z, in the panorama's own frame; ``rotation`` orients that frame in the world: the 3x3
``EnvironmentMap.world_from_map()``, or a number, radians about +Y as ``rotation_deg`` turns it. The GPU gets the
transpose (glsl/lights.glsl's ``env_world_to_map``) and applies it in the lookup, the pdf and the sampling alike.
The same mapping is in glsl/lights.glsl.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lenslab.color import luminance


Rotation = float | np.ndarray  # a turn about +Y in radians, or a 3x3 rotation matrix


def world_from_map(rotation: Rotation = 0.0) -> np.ndarray:
    """The 3x3 rotation from the panorama's frame to the world: ``rotation`` itself, or for a number the turn
    about +Y that ``rotation_deg`` (in radians here) means: clockwise seen from above, -rotation right-handed."""
    if np.ndim(rotation) == 2:
        return np.asarray(rotation, float)
    c, s = math.cos(rotation), math.sin(rotation)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def direction_to_uv(d: np.ndarray, rotation: Rotation = 0.0) -> np.ndarray:
    local = np.asarray(d, float) @ world_from_map(rotation)  # each row times the matrix: its transpose applied
    phi = np.arctan2(local[..., 0], -local[..., 2])
    u = np.mod(0.5 + phi / (2 * np.pi), 1.0)
    v = np.arccos(np.clip(local[..., 1], -1, 1)) / np.pi
    return np.stack([u, v], axis=-1)


def uv_to_direction(uv: np.ndarray, rotation: Rotation = 0.0) -> np.ndarray:
    phi = (uv[..., 0] - 0.5) * 2 * np.pi
    theta = uv[..., 1] * np.pi
    s = np.sin(theta)
    local = np.stack([s * np.sin(phi), np.cos(theta), -s * np.cos(phi)], axis=-1)
    return local @ world_from_map(rotation).T




TABLE_MAX_SIZE = (1024, 512)  # cells of the sampling tables: a third of a degree on a side at the horizon


@dataclass(frozen=True)
class EnvironmentDistribution:
    """Sampling tables for an (H, W) lat-long image: the pdf per pixel over (u, v), cumulative tables."""

    pdf: np.ndarray  # (H, W) density over [0,1]^2 (integrates to 1), per table cell
    marginal_cdf: np.ndarray  # (H + 1,) over rows
    conditional_cdf: np.ndarray  # (H, W + 1) over columns of each row

    @classmethod
    def from_image(cls, rgb: np.ndarray, max_size: tuple[int, int] | None = None) -> "EnvironmentDistribution":
        """Tables over at most ``max_size`` (width, height) cells: a larger image shares a cell between several
        pixels, whose brightest sets the cell's weight (a 4096 x 2048 panorama's full-size tables alone would
        need 64 MiB of GPU memory, for no visible gain in noise)."""
        h_img, w_img = rgb.shape[:2]
        lum = np.maximum(luminance(rgb.astype(np.float64)), 0.0)
        # Bilinear lookups reach into neighbouring pixels: weight each pixel by the brightest it can show,
        # so that the pdf is never zero where the radiance is not (that would bias the estimate).
        padded = np.pad(lum, 1, mode="edge")
        padded[:, 0], padded[:, -1] = padded[:, -2], padded[:, 1]  # u wraps around
        shifted = [padded[1 + dy : 1 + dy + h_img, 1 + dx : 1 + dx + w_img] for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
        func = np.max(shifted, axis=0)
        max_size = max_size or TABLE_MAX_SIZE
        w, h = min(w_img, max_size[0]), min(h_img, max_size[1])
        # Cell j spans pixels [floor(j n / cells), floor((j + 1) n / cells)); the one-pixel reach above covers the
        # pixel a cell only partly overlaps at its far end.
        func = np.maximum.reduceat(func, (np.arange(h) * h_img) // h, axis=0)
        func = np.maximum.reduceat(func, (np.arange(w) * w_img) // w, axis=1)
        sin_theta = np.sin(np.pi * (np.arange(h) + 0.5) / h)[:, None]
        func = func * sin_theta
        func += 1e-6 * max(func.mean(), 1e-12)  # never exactly zero: every direction stays reachable
        row_sums = func.sum(axis=1)
        conditional = np.concatenate([np.zeros((h, 1)), np.cumsum(func, axis=1) / row_sums[:, None]], axis=1)
        marginal = np.concatenate([[0.0], np.cumsum(row_sums) / row_sums.sum()])
        pdf = func / func.sum() * (h * w)
        return cls(pdf.astype(np.float32), marginal.astype(np.float32), conditional.astype(np.float32))

    def pdf_direction(self, d: np.ndarray, rotation: Rotation = 0.0) -> np.ndarray:
        """Density per steradian of choosing direction d."""
        h, w = self.pdf.shape
        uv = direction_to_uv(d, rotation)
        row = np.clip((uv[..., 1] * h).astype(int), 0, h - 1)
        col = np.clip((uv[..., 0] * w).astype(int), 0, w - 1)
        sin_theta = np.sin(uv[..., 1] * np.pi)
        return np.where(sin_theta > 0, self.pdf[row, col] / (2 * math.pi**2 * np.maximum(sin_theta, 1e-12)), 0.0)

    def packed(self) -> np.ndarray:
        """As float32 for the GPU: marginal cdf, then conditional cdfs row by row, then the pdf."""
        return np.concatenate([self.marginal_cdf, self.conditional_cdf.reshape(-1), self.pdf.reshape(-1)])


def infinite_light_power(radiance_integral: float, scene_radius: float) -> float:
    """The weight with which next-event estimation chooses light from infinity (sky, environment map)
    against area lights, given the sky's radiance integrated over all directions.

    pbrt-v4 uses the flux through a disk of the scene's radius, pi r^2 times that integral. A surface,
    though, only receives its hemisphere, cosine-weighted: pi L rather than 4 pi L for a uniform sky. We
    weigh by that quarter, which compares the sky with an area light by the irradiance each gives a surface
    at the scene's scale. (With pbrt's weight a large ground plane hands the sky most shadow rays, and the
    area lights that light the subject go noisy; the validation scene glass_metal showed it.)
    """
    return math.pi * scene_radius**2 * radiance_integral / 4.0


def environment_power(rgb: np.ndarray, strength: float, scene_radius: float) -> float:
    """infinite_light_power of a lat-long map: its radiance integrated over the sphere is the sum of
    L sin(theta) dphi dtheta over its pixels."""
    h = rgb.shape[0]
    sin_theta = np.sin(np.pi * (np.arange(h) + 0.5) / h)[:, None]
    radiance_integral = 2.0 * math.pi**2 * float((luminance(rgb) * sin_theta).mean())
    return infinite_light_power(strength * radiance_integral, scene_radius)
