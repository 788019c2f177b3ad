"""The sRGB transfer function, both ways (IEC 61966-2-1). Colours inside LensLab are linear Rec. 709;
sRGB-encoded values come in from 8-bit images and colour pickers and go out to PNGs and the screen."""

from __future__ import annotations

import numpy as np


def srgb_to_linear(c):
    c = np.asarray(c, dtype=np.result_type(c, np.float32))  # keep float32 images float32
    return np.where(c <= 0.04045, c / 12.92, ((np.maximum(c, 0.0) + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
