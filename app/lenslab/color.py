"""The sRGB transfer function, both ways (IEC 61966-2-1), and luminance. Colours inside LensLab are linear
Rec. 709; sRGB-encoded values come in from 8-bit images and colour pickers and go out to PNGs and the screen.

Both directions take an array (float32 stays float32) or a single number (which gives a float back), and
clamp to [0, 1] first: sRGB encodes only what a display can show."""

from __future__ import annotations

import numpy as np


#: Rec. 709's luminance of linear red, green and blue (ITU-R BT.709, the Y of its primaries).
REC709_LUMINANCE = (0.2126, 0.7152, 0.0722)


def luminance(rgb):
    """Luminance of linear Rec. 709 colours: (..., 3) values (any float array) or one (r, g, b)."""
    rgb = np.asarray(rgb)
    return _as_given(rgb[..., 0] * REC709_LUMINANCE[0] + rgb[..., 1] * REC709_LUMINANCE[1]
                     + rgb[..., 2] * REC709_LUMINANCE[2])


def srgb_to_linear(c):
    c = np.asarray(c)
    c = np.clip(c.astype(np.result_type(c.dtype, np.float32), copy=False), 0.0, 1.0)
    return _as_given(np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4))


def linear_to_srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return _as_given(np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055))


def _as_given(values: np.ndarray):
    """An array for an array, a float for a single number."""
    return values if values.ndim else values.item()
