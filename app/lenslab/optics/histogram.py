"""The histogram of a displayed picture and its clipping: how many pixels sit at each level, and how many are
lost at either end.

The picture is **display-referred**: the display's 8-bit code values after the view transform (OpenColorIO's
display, view and look, with the display exposure and contrast: lenslab.colour_management.view), exactly what the
viewport shows and what a PNG export writes. (The linear radiance behind it has no top: through an ACES view
nothing clips until the radiance is far above 1, through an un-tone-mapped one everything above 1 does, and this
histogram shows which, as a camera's histogram shows its JPEG and not its raw file.)

* The red, green and blue histograms count the pixels at each of the 256 levels of each channel; the luminance
  histogram counts Rec. 709 luma of the encoded values (:data:`LUMA_WEIGHTS_256`), rounded.
* A pixel's **highlights are clipped** when any of its channels is at :data:`HIGHLIGHT_LEVEL` (255): that channel
  lost whatever detail was above it, and the colour shifts (a red lamp turns orange, then white). Its **shadows
  are crushed** when it is black, every channel at :data:`SHADOW_LEVEL` (0): no detail is left. (A saturated
  colour has a channel at 0 long before it is dark, as the red wall of the Cornell box has no blue at all: that is
  its colour, not lost shadow detail; the per-channel figures count it all the same.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Rec. 709 luma weights (0.2126, 0.7152, 0.0722) in 256ths, summing to 256 so that white is 255, applied to the
#: display-encoded values (a histogram judges the picture as shown; a wide-gamut display's luma weights differ a
#: little, which a histogram's shape does not show).
LUMA_WEIGHTS_256 = (54, 183, 19)
LEVELS = 256
HIGHLIGHT_LEVEL = 255
SHADOW_LEVEL = 0
CHANNELS = ("red", "green", "blue")


@dataclass(frozen=True)
class Histogram:
    counts: np.ndarray  # (4, 256) int64: red, green, blue, luma
    pixels: int
    clipped: np.ndarray  # (3,) fraction of pixels with that channel at HIGHLIGHT_LEVEL
    crushed: np.ndarray  # (3,) fraction of pixels with that channel at SHADOW_LEVEL
    clipped_any: float  # fraction of pixels with any channel at HIGHLIGHT_LEVEL: clipped highlights
    crushed_all: float  # fraction of pixels with every channel at SHADOW_LEVEL: crushed shadows

    @property
    def luma(self) -> np.ndarray:
        return self.counts[3]


def clipping_masks(rgb8: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(clipped highlights: any channel at 255, crushed shadows: black): H x W booleans of an (H, W, 3 or 4) uint8
    picture."""
    r, g, b = rgb8[..., 0], rgb8[..., 1], rgb8[..., 2]
    return (np.maximum(np.maximum(r, g), b) >= HIGHLIGHT_LEVEL), (np.maximum(np.maximum(r, g), b) <= SHADOW_LEVEL)


def histogram(rgb8: np.ndarray) -> Histogram:
    """The histograms and clipping of an (H, W, 3 or 4) uint8 picture (alpha ignored)."""
    if rgb8.dtype != np.uint8 or rgb8.ndim != 3 or rgb8.shape[2] < 3:
        raise ValueError(f"a histogram needs an (H, W, 3 or 4) uint8 picture, not {rgb8.dtype} {rgb8.shape}")
    r, g, b = (np.ascontiguousarray(rgb8[..., c]).ravel() for c in range(3))
    n = r.size
    counts = np.zeros((4, LEVELS), np.int64)
    if n == 0:
        zeros = np.zeros(3)
        return Histogram(counts, 0, zeros, zeros, 0.0, 0.0)
    for c, channel in enumerate((r, g, b)):
        counts[c] = np.bincount(channel, minlength=LEVELS)
    wr, wg, wb = LUMA_WEIGHTS_256
    luma = r.astype(np.uint16) * wr  # at most 255 x 256 + 128: fits
    luma += g.astype(np.uint16) * wg
    luma += b.astype(np.uint16) * wb
    luma += 128
    counts[3] = np.bincount(luma >> 8, minlength=LEVELS)
    high, low = clipping_masks(rgb8)
    return Histogram(counts=counts, pixels=n,
                     clipped=counts[:3, HIGHLIGHT_LEVEL] / n, crushed=counts[:3, SHADOW_LEVEL] / n,
                     clipped_any=float(high.mean()), crushed_all=float(low.mean()))
