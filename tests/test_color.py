"""The one sRGB transfer curve serves images (arrays) and the studio's colour pickers (single numbers) alike."""

from __future__ import annotations

import numpy as np

from lenslab.color import linear_to_srgb, srgb_to_linear


def test_a_number_gives_a_float_and_an_array_keeps_its_type():
    assert isinstance(srgb_to_linear(0.5), float) and isinstance(linear_to_srgb(0.5), float)
    image = np.linspace(0.0, 1.0, 12, dtype=np.float32).reshape(2, 2, 3)
    assert srgb_to_linear(image).dtype == np.float32 and linear_to_srgb(image).dtype == np.float32


def test_both_directions_clamp_to_what_sRGB_encodes():
    assert srgb_to_linear(-0.5) == 0.0 and srgb_to_linear(1.5) == 1.0
    assert linear_to_srgb(-2.0) == 0.0 and linear_to_srgb(40.0) == linear_to_srgb(1.0)


def test_the_curve_meets_its_reference_points_and_inverts():
    assert np.isclose(srgb_to_linear(0.5), 0.21404114)  # IEC 61966-2-1
    assert np.isclose(srgb_to_linear(0.04045), 0.04045 / 12.92)
    values = np.linspace(0.0, 1.0, 101)
    assert np.allclose(linear_to_srgb(srgb_to_linear(values)), values, atol=1e-12)
