"""The aperture: the shape of the stop a camera ray leaves through, and where a lens sample lands on it.

Shapes, in *aperture units*: the round stop of an f/N lens is the unit disk (radius 1 = ``f / 2N``).

* **round**: the unit disk.
* **straight blades**: a regular polygon of ``blades`` corners, one corner at ``rotation``.
* **rounded blades**: each blade's edge an arc through two neighbouring corners, of curvature ``curvature``
  times the corners' circle (0: straight blades, 1: the corners' circle itself, a round stop), as HDRP's
  blade curvature. Modern lenses with "rounded blades" sit around 0.5 to 0.8.
* **an aperture image**: any grayscale image (a star, a heart), its transmission spanning the square around
  the f/N disk, as pbrt-v4's aperture image.

**Area.** A lens's iris is calibrated by area: each stop halves the light. So a bladed stop at f/N passes as
much light as the round f/N disk, and its corners reach a little beyond the unit circle (:attr:`Aperture.scale`:
1.07 for 7 straight blades). An aperture image is a mask over the f/N disk's square: it passes what its
transmission lets through (:attr:`Aperture.light_fraction`), and exposure and the depth-of-field readout use
that real area.

**Anamorphic squeeze** ``s`` (height over width of the bokeh, as Cycles' aperture ratio and Unreal's squeeze
factor) stretches the shape by ``sqrt(s)`` vertically and shrinks it by ``sqrt(s)`` horizontally: oval bokeh, the
same area.

**Sampling.** Every shape maps the unit square onto itself so that a stratified (Sobol) pattern stays
stratified on the lens, and returns a *weight*: the ratio of the density a uniform point on the shape has to the
density the map gives it. The round and straight-bladed maps are exact (weight 1); rounded blades are sampled
in polar coordinates with the angle drawn from a table (weight within a few parts in a thousand of 1, so the
estimate stays unbiased); an image is drawn in proportion to its transmission (weight 1: every pixel averages
the scene over the aperture weighted by the mask).

These functions are the numeric twins of glsl/sampling.glsl and glsl/camera.glsl, step by step, so that the
camera's Python rays (``lenslab.scene.camera.CameraFrame``) are the shader's; tests/test_camera_rays.py runs
both on the same numbers.

Vectorised: ``u`` is an (N, 2) array of numbers in [0, 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

__all__ = ["APERTURE_KINDS", "Aperture", "ROUNDED_BLADE_BINS", "MAX_APERTURE_IMAGE_SIDE", "sample_aperture",
           "sample_concentric_disk", "sample_polygon"]

#: How the shader tells the shapes apart (glsl/camera.glsl's cam_aperture_kind).
APERTURE_KINDS = {"round": 0, "blades": 1, "rounded_blades": 2, "image": 3}

#: Angular bins per blade of the rounded-blade table: enough that the weights stay within 0.3% of 1.
ROUNDED_BLADE_BINS = 64

#: An aperture image is reduced (by area averaging) to at most this many pixels a side: bokeh is rarely more
#: than a few hundred pixels across, and the shader's table search costs one step per doubling.
MAX_APERTURE_IMAGE_SIDE = 128


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
    """A point on a unit round stop (``blades`` = 0) or the polygon of straight blades inscribed in it."""
    return sample_polygon(u, blades, rotation_rad) if blades >= 3 else sample_concentric_disk(u)


def find_interval(cdf: np.ndarray, u) -> np.ndarray:
    """For each ``u``, the bin i with cdf[i] <= u < cdf[i + 1], clamped to the table (glsl: find_interval)."""
    return np.clip(np.searchsorted(cdf, u, side="right") - 1, 0, len(cdf) - 2)


def _reduce_image(image: np.ndarray, limit: int) -> np.ndarray:
    """Area-average ``image`` down so that neither side exceeds ``limit`` (whole-pixel blocks)."""
    height, width = image.shape
    step = max(1, math.ceil(max(height, width) / limit))
    if step == 1:
        return image
    pad_h, pad_w = (-height) % step, (-width) % step
    padded = np.pad(image, ((0, pad_h), (0, pad_w)))
    return padded.reshape(padded.shape[0] // step, step, padded.shape[1] // step, step).mean(axis=(1, 3))


@dataclass(frozen=True, eq=False)
class Aperture:
    """The stop's shape (see the module's docstring); :meth:`sample` puts lens samples on it."""

    blades: int = 0  # 0: round; else 3 or more
    rotation_rad: float = 0.0  # where the first corner is, counter-clockwise from +x seen from behind the camera
    curvature: float = 0.0  # of the blades' edges: 0 straight .. 1 round
    squeeze: float = 1.0  # anamorphic: bokeh height over width
    image: np.ndarray | None = field(default=None, repr=False)  # transmission in [0, 1], rows from the top

    def __post_init__(self):
        if self.image is not None:
            image = np.clip(np.asarray(self.image, dtype=np.float64), 0.0, 1.0)
            if image.ndim != 2 or not image.size:
                raise ValueError("an aperture image must be a grayscale image with at least one pixel")
            if not image.any():
                raise ValueError("an aperture image must let some light through: every pixel is black")
            object.__setattr__(self, "image", _reduce_image(image, MAX_APERTURE_IMAGE_SIDE))

    # -- what it is ---------------------------------------------------------------------------------------
    @property
    def kind(self) -> str:
        if self.image is not None:
            return "image"
        if self.blades >= 3 and self.curvature < 1.0:
            return "blades" if self.curvature == 0.0 else "rounded_blades"
        return "round"

    @cached_property
    def blade_geometry(self) -> tuple[float, float, float]:
        """For rounded blades, in units of the corners' circle: (distance from the centre to the centre of each
        edge's arc, the arc's radius, the area of the shape). Straight blades: arc radius infinite. The renderer
        passes these to the shader, which samples and scales the shape from them."""
        n = self.blades
        half_chord, apothem = math.sin(math.pi / n), math.cos(math.pi / n)
        polygon_area = n * half_chord * apothem
        if self.kind != "rounded_blades":
            return 0.0, math.inf, polygon_area
        radius = 1.0 / self.curvature
        chord_angle = 2.0 * math.asin(half_chord / radius)
        segment_area = 0.5 * radius * radius * (chord_angle - math.sin(chord_angle))
        centre = apothem - math.sqrt(radius * radius - half_chord * half_chord)
        return centre, radius, polygon_area + n * segment_area

    @property
    def scale(self) -> float:
        """Radius of the corners' circle in aperture units: a bladed stop is made as large as passes the light of
        the round stop (1 for a round stop and an image)."""
        if self.kind in ("blades", "rounded_blades"):
            return math.sqrt(math.pi / self.blade_geometry[2])
        return 1.0

    @property
    def light_fraction(self) -> float:
        """The light this stop passes, as a fraction of the round f/N stop's: 1 but for an aperture image."""
        if self.kind == "image":
            return float(4.0 * self.image.mean() / math.pi)
        return 1.0

    @property
    def axes(self) -> tuple[float, float]:
        """Horizontal and vertical scale of the shape: its size, and the anamorphic squeeze."""
        root = math.sqrt(self.squeeze)
        return self.scale / root, self.scale * root

    # -- tables for the shader ----------------------------------------------------------------------------
    def rounded_blade_radius(self, angle) -> np.ndarray:
        """Distance from the centre to the edge of one blade's wedge (unit corners' circle) at ``angle`` radians
        from the wedge's first corner: where the ray from the centre leaves the edge's arc."""
        centre, radius, _ = self.blade_geometry
        towards_arc = centre * np.cos(np.asarray(angle, dtype=float) - math.pi / self.blades)
        return towards_arc + np.sqrt(towards_arc * towards_arc - centre * centre + radius * radius)

    @cached_property
    def table(self) -> np.ndarray:
        """The cumulative tables the shader samples, one row each, as a float32 (rows, columns) array.

        Rounded blades: one row, the cumulative distribution of the angle over one blade's wedge
        (:data:`ROUNDED_BLADE_BINS` bins, each weighted by the area it spans, R^2 / 2). An image of H rows and
        W columns: rows 0 to H-1 the cumulative distribution along each image row (W + 1 entries), row H the
        distribution over the rows (H + 1 entries). Round and straight-bladed stops need none: one zero.
        """
        if self.kind == "rounded_blades":
            wedge = 2.0 * math.pi / self.blades
            fine = 16  # midpoints per bin: the area of each bin to well under a part in a million
            angles = (np.arange(ROUNDED_BLADE_BINS * fine) + 0.5) * wedge / (ROUNDED_BLADE_BINS * fine)
            area = (0.5 * self.rounded_blade_radius(angles) ** 2).reshape(ROUNDED_BLADE_BINS, fine).sum(axis=1)
            cdf = np.concatenate([[0.0], np.cumsum(area)]) / area.sum()
            return cdf[None, :].astype(np.float32)
        if self.kind == "image":
            image = self.image
            rows, cols = image.shape
            table = np.zeros((rows + 1, max(rows, cols) + 1))
            row_sums = image.sum(axis=1)
            for r in range(rows):
                if row_sums[r] > 0:
                    table[r, : cols + 1] = np.concatenate([[0.0], np.cumsum(image[r])]) / row_sums[r]
                else:  # never chosen: the marginal gives it no weight
                    table[r, : cols + 1] = np.linspace(0.0, 1.0, cols + 1)
            table[rows, : rows + 1] = np.concatenate([[0.0], np.cumsum(row_sums)]) / row_sums.sum()
            return table.astype(np.float32)
        return np.zeros((1, 1), np.float32)

    # -- sampling -----------------------------------------------------------------------------------------
    def sample(self, u) -> tuple[np.ndarray, np.ndarray]:
        """Points on the stop in aperture units (N, 2), squeeze applied, and each sample's weight (N,)."""
        u = np.asarray(u, dtype=float).reshape(-1, 2)
        weight = np.ones(len(u))
        kind = self.kind
        if kind == "round":
            point = sample_concentric_disk(u)
        elif kind == "blades":
            point = sample_polygon(u, self.blades, self.rotation_rad)
        elif kind == "rounded_blades":
            point, weight = self._sample_rounded_blades(u)
        else:
            point = self._sample_image(u)
        return point * np.asarray(self.axes), weight

    def _sample_rounded_blades(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # The table is float32 on the GPU: sample from the same numbers here.
        cdf = self.table[0].astype(np.float64)
        n = self.blades
        wedge = 2.0 * math.pi / n
        k = np.minimum(np.floor(u[:, 0] * n), n - 1.0)
        v = u[:, 0] * n - k
        i = find_interval(cdf, v)
        bin_mass = cdf[i + 1] - cdf[i]
        bin_width = wedge / ROUNDED_BLADE_BINS
        angle = (i + (v - cdf[i]) / bin_mass) * bin_width
        edge = self.rounded_blade_radius(angle)
        # pdf of the angle in its wedge: bin_mass / bin_width; a uniform point's: R^2 / 2 over the wedge's area.
        wedge_area = self.blade_geometry[2] / n
        weight = (0.5 * edge * edge / wedge_area) / (bin_mass / bin_width)
        theta = self.rotation_rad + k * wedge + angle
        radius = edge * np.sqrt(u[:, 1])
        return radius[:, None] * np.stack([np.cos(theta), np.sin(theta)], axis=-1), weight

    def _sample_image(self, u: np.ndarray) -> np.ndarray:
        table = self.table.astype(np.float64)
        rows, cols = self.image.shape
        marginal = table[rows, : rows + 1]
        row = find_interval(marginal, u[:, 1])
        y = row + (u[:, 1] - marginal[row]) / (marginal[row + 1] - marginal[row])
        x = np.empty(len(u))
        for r in np.unique(row):  # the shader searches each sample's own row
            chosen = row == r
            cdf = table[r, : cols + 1]
            col = find_interval(cdf, u[chosen, 0])
            x[chosen] = col + (u[chosen, 0] - cdf[col]) / (cdf[col + 1] - cdf[col])
        # The image spans the square around the unit disk, its first row at the top (+y).
        return np.stack([2.0 * x / cols - 1.0, 1.0 - 2.0 * y / rows], axis=-1)

    def contains(self, points) -> np.ndarray:
        """Whether aperture-unit ``points`` (N, 2), squeeze applied, lie inside the stop (an image: where it is
        not black). For tests and for drawing the stop."""
        p = np.asarray(points, dtype=float).reshape(-1, 2) / np.asarray(self.axes)
        kind = self.kind
        if kind == "round":
            return np.hypot(p[:, 0], p[:, 1]) <= 1.0
        if kind == "image":
            rows, cols = self.image.shape
            col = np.floor((p[:, 0] + 1.0) / 2.0 * cols).astype(int)
            row = np.floor((1.0 - p[:, 1]) / 2.0 * rows).astype(int)
            inside = (col >= 0) & (col < cols) & (row >= 0) & (row < rows)
            result = np.zeros(len(p), bool)
            result[inside] = self.image[row[inside], col[inside]] > 0
            return result
        angle = np.mod(np.arctan2(p[:, 1], p[:, 0]) - self.rotation_rad, 2.0 * math.pi / self.blades)
        if kind == "rounded_blades":
            edge = self.rounded_blade_radius(angle)
        else:
            edge = math.cos(math.pi / self.blades) / np.cos(angle - math.pi / self.blades)
        return np.hypot(p[:, 0], p[:, 1]) <= edge
