"""The sRGB transfer function, both ways (IEC 61966-2-1), and luminance. Colours inside LensLab are linear
Rec. 709; sRGB-encoded values come in from 8-bit images and colour pickers and go out to PNGs and the screen.

Both directions take an array (float32 stays float32) or a single number (which gives a float back), and
clamp to [0, 1] first: sRGB encodes only what a display can show."""

from __future__ import annotations

import numpy as np


#: Rec. 709's luminance of linear red, green and blue (ITU-R BT.709, the Y of its primaries).
REC709_LUMINANCE = (0.2126, 0.7152, 0.0722)

# The sRGB curve's numbers (IEC 61966-2-1): encoded = SRGB_SCALE * linear ** (1 / SRGB_EXPONENT) - SRGB_OFFSET,
# and SRGB_LINEAR_SLOPE * linear at or below SRGB_LINEAR_CUTOFF (SRGB_ENCODED_CUTOFF on the encoded side). The
# only copy: glsl/display.comp gets the encoding ones as #defines of the same names (render/gpu_layout.py).
SRGB_SCALE = 1.055
SRGB_OFFSET = 0.055
SRGB_EXPONENT = 2.4
SRGB_LINEAR_SLOPE = 12.92
SRGB_LINEAR_CUTOFF = 0.0031308
SRGB_ENCODED_CUTOFF = 0.04045


def luminance(rgb):
    """Luminance of linear Rec. 709 colours: (..., 3) values (any float array) or one (r, g, b)."""
    rgb = np.asarray(rgb)
    return _as_given(rgb[..., 0] * REC709_LUMINANCE[0] + rgb[..., 1] * REC709_LUMINANCE[1]
                     + rgb[..., 2] * REC709_LUMINANCE[2])


def srgb_to_linear(c):
    c = np.asarray(c)
    c = np.clip(c.astype(np.result_type(c.dtype, np.float32), copy=False), 0.0, 1.0)
    return _as_given(np.where(c <= SRGB_ENCODED_CUTOFF, c / SRGB_LINEAR_SLOPE,
                              ((c + SRGB_OFFSET) / SRGB_SCALE) ** SRGB_EXPONENT))


def linear_to_srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return _as_given(np.where(x <= SRGB_LINEAR_CUTOFF, SRGB_LINEAR_SLOPE * x,
                              SRGB_SCALE * np.power(x, 1 / SRGB_EXPONENT) - SRGB_OFFSET))


def _as_given(values: np.ndarray):
    """An array for an array, a float for a single number."""
    return values if values.ndim else values.item()
