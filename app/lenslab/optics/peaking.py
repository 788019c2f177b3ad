"""Focus peaking: which pixels of a picture are sharp edges of something inside the depth of field.

A camera's peaking marks the edges of high contrast in the live view; because only what is in focus has crisp
edges, the marks gather where the focus is. A render knows more: the depth under every pixel. Here a pixel is
marked when both hold:

1. **It lies within the depth of field**: its depth along the view axis is between the near and far limits of
   acceptable sharpness (``ThinLensCamera.depth_of_field(..., reference="lens")``), which is where the blur disk
   ``c = A |d - s| / d * v / s`` of a point at depth d is no larger than the circle of confusion. The limits come
   from the camera, the one home of that formula; this module only compares depths with them (and, for the veil
   below, scales the blur between them: :func:`blur_in_cocs`).
2. **It is an edge of the picture**: the gradient of the displayed picture (central differences of each of its
   red, green and blue, the strongest taken, so that a red card on a grey wall of the same luma has an edge;
   after a 3 x 3 box blur, which keeps the sampling noise of an unconverged render from passing for detail) is
   at least ``threshold``, where a hard black-to-white edge is 1.

So a sharp edge out of the depth of field is not marked (the depth says so, even where the picture is still too
noisy to show the blur), and a flat wall inside it is not either (there is nothing to focus on). Nor is an edge
where a blurred foreground spreads over a sharp background (:func:`veiled_by_foreground`): the depth buffer sees
the background there, the picture the foreground's blur. Pure numpy, the edges in whole numbers: about 3 ms of
one core for an 800 x 600 picture, 7 with the veil of a blurred foreground (``benchmarks/overlays.py``).
"""

from __future__ import annotations

import numpy as np

#: Edge thresholds (:func:`edge_strength`: 1 is a black-to-white step) for the sensitivities a camera offers.
PEAKING_SENSITIVITY = {"low": 0.16, "medium": 0.10, "high": 0.06}
#: |gx| + |gy| of the 3 x 3 box sums beside a step from 0 to 255: a step spreads over three box sums, and the
#: central difference spans two of them, 6 x 255.
EDGE_SCALE = 6 * 255


def _gradient_l1(rgb8: np.ndarray) -> np.ndarray:
    """|gx| + |gy| of the 3 x 3 box sum of each channel of an (H, W) or (H, W, C) uint8 picture, the strongest
    channel, int16, (H, W); the outermost two pixels all round are 0. Whole-number arithmetic on contiguous
    planes: about 2 ms of one core for 800 x 600 x 3."""
    h, w = rgb8.shape[:2]
    channels = 1 if rgb8.ndim == 2 else min(3, rgb8.shape[2])
    planes = np.empty((channels, h, w), np.int16)
    if rgb8.ndim == 2:
        planes[0] = rgb8
    else:
        for c in range(channels):
            planes[c] = rgb8[..., c]
    out = np.zeros((h, w), np.int16)
    if h < 5 or w < 5:
        return out
    rows = planes[:, :-2] + planes[:, 1:-1]
    rows += planes[:, 2:]
    box = rows[:, :, :-2] + rows[:, :, 1:-1]  # at most 9 x 255: the sums fit in int16
    box += rows[:, :, 2:]
    gx = box[:, 1:-1, 2:] - box[:, 1:-1, :-2]
    gy = box[:, 2:, 1:-1] - box[:, :-2, 1:-1]
    np.abs(gx, out=gx)
    np.abs(gy, out=gy)
    gx += gy  # at most 2 x 6 x 255
    out[2:-2, 2:-2] = gx.max(axis=0)
    return out


def edge_strength(rgb8: np.ndarray) -> np.ndarray:
    """How strong an edge each pixel of an (H, W) or (H, W, 3 or 4) uint8 picture is, float32 (H, W): the
    gradient (|d/dx| + |d/dy|, central differences) of the picture blurred by a 3 x 3 box, in the strongest of
    its channels (so that a red card on a grey wall of the same luma has an edge), scaled so that a step from
    black to white gives 1 beside it."""
    return _gradient_l1(rgb8).astype(np.float32) * np.float32(1 / EDGE_SCALE)


def within_depth_of_field(depth: np.ndarray, near_m: float, far_m: float) -> np.ndarray:
    """True where a surface (finite depth) lies between the near and far limits of sharpness (``far_m`` may be
    infinite: focused at or beyond the hyperfocal distance; the background, at infinite depth, is still
    not a surface to mark)."""
    with np.errstate(invalid="ignore"):
        return np.isfinite(depth) & (depth >= near_m) & (depth <= far_m)


def resample_nearest(values: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """``values`` (H x W) at another size, nearest neighbour (a depth buffer never blends across an edge)."""
    h, w = values.shape[:2]
    if (h, w) == tuple(shape):
        return values
    rows = np.minimum((np.arange(shape[0]) + 0.5) * h / shape[0], h - 1).astype(np.intp)
    cols = np.minimum((np.arange(shape[1]) + 0.5) * w / shape[1], w - 1).astype(np.intp)
    return values[rows[:, None], cols[None, :]]


def blur_in_cocs(depth: np.ndarray, near_m: float, far_m: float) -> np.ndarray:
    """The blur disk of a point at each depth, in circles of confusion, from the limits of sharpness alone.

    The blur is ``c = A |d - s| / d * v / s = A v |1/d - 1/s|``: proportional to ``|1/d - 1/s|``, and one
    circle of confusion at either limit. So ``2 / s = 1/near + 1/far`` (the plane of focus is the limits'
    harmonic mean; twice the near limit when the far one is infinite) and the blur is
    ``|1/d - 1/s| / (1/near - 1/s)`` circles of confusion. The limits come from the camera; this only scales."""
    inv_near = 1.0 / near_m
    inv_s = 0.5 * (inv_near + (1.0 / far_m if np.isfinite(far_m) else 0.0))
    with np.errstate(divide="ignore"):
        return np.abs(1.0 / depth - inv_s) / (inv_near - inv_s)


#: The radii (pixels) a foreground's blur is rounded up to, to spread its veil in a few box filters.
VEIL_RADII = (2, 4, 8, 16, 32, 64)


def _dilate_square(mask: np.ndarray, radius: int) -> np.ndarray:
    """``mask`` grown by ``radius`` pixels each way (a square): along each axis, OR with copies of itself shifted
    by 1, 2, 4 ... pixels, so that the cost grows with the logarithm of the radius."""
    out = mask.copy()
    for axis in (0, 1):
        done, step = 0, 1
        while done < radius:
            s = min(step, radius - done)
            before = out.copy()
            if axis == 0:
                out[s:] |= before[:-s]
                out[:-s] |= before[s:]
            else:
                out[:, s:] |= before[:, :-s]
                out[:, :-s] |= before[:, s:]
            done += s
            step *= 2
    return out


def veiled_by_foreground(depth: np.ndarray, near_m: float, far_m: float, coc_px: float) -> np.ndarray:
    """Pixels that a surface nearer than the near limit, blurred, spreads over: within its blur disk's radius
    (``coc_px``: the circle of confusion in the picture's pixels) of it. The depth buffer sees what lies behind
    there, perhaps in focus, but the picture shows the foreground's blur over it: the rim of an out-of-focus
    highlight in front of a sharp background is not a sharp edge. (The radius is rounded up to one of
    :data:`VEIL_RADII`, and the disk taken as its square: a veil a little wide rather than a false mark.)"""
    veil = np.zeros(depth.shape, bool)
    with np.errstate(invalid="ignore"):
        front = np.isfinite(depth) & (depth < near_m)
    if coc_px <= 0 or not front.any():
        return veil
    radius = np.zeros(depth.shape, np.float32)
    radius[front] = 0.5 * coc_px * blur_in_cocs(depth[front], near_m, far_m)
    low = 1.0
    for r in VEIL_RADII:
        band = front & (radius >= low) & ((radius < r) if r != VEIL_RADII[-1] else True)
        if band.any():
            veil |= _dilate_square(band, r)
        low = r
    return veil


def peaking_mask(rgb8: np.ndarray, depth: np.ndarray, near_m: float, far_m: float,
                 threshold: float = PEAKING_SENSITIVITY["medium"], coc_px: float | None = None) -> np.ndarray:
    """Pixels to mark: edges of the displayed picture ``rgb8`` ((H, W) or (H, W, 3 or 4) uint8) at least
    ``threshold`` strong (:func:`edge_strength`), whose ``depth`` (any size: resampled to the picture's) lies
    within the depth of field from ``near_m`` to ``far_m``; given the circle of confusion in the picture's
    pixels, ``coc_px``, not where a blurred foreground lies over them (:func:`veiled_by_foreground`)."""
    depth = resample_nearest(depth, rgb8.shape[:2])
    zone = within_depth_of_field(depth, near_m, far_m)
    if not zone.any():
        return zone
    if coc_px:
        zone &= ~veiled_by_foreground(depth, near_m, far_m, coc_px)
    return zone & (_gradient_l1(rgb8) >= int(np.ceil(threshold * EDGE_SCALE)))
