"""Thin-lens math, depth of field and f-stops against numbers worked out by hand.

Each expected value below is derived in the comment next to it, not taken
from the code under test.
"""

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lenslab.optics import dof, stops, thinlens
from lenslab.optics.dof import circle_of_confusion_mm, depth_of_field, hyperfocal_distance_m
from lenslab.optics.stops import (
    EXTENDED_THIRD_STOPS,
    STOP_SCALES,
    exact_f_number,
    marked_f_number,
    THIRD_STOPS,
    format_f_number,
    nearest_stop,
    parse_f_number,
    step_stop,
    stops_between,
)
from lenslab.optics.thinlens import (
    blur_diameter_mm,
    field_of_view_x,
    focal_length_for_fov,
    lens_radius_m,
    textbook_blur_diameter_mm,
)

APP_DIR = Path(__file__).resolve().parents[1] / "app"


# --- field of view --------------------------------------------------------------------------

def test_fov_18mm_on_36mm_is_a_right_angle():
    # w / 2f = 36 / 36 = 1, atan(1) = 45 deg, doubled = 90 deg.
    assert field_of_view_x(18, 36) == pytest.approx(math.pi / 2, rel=1e-12)


def test_fov_24mm_full_frame():
    # w / 2f = 36 / 48 = 3/4; atan(3/4) = 36.8699 deg (the 3-4-5 triangle) -> 73.7398 deg.
    assert math.degrees(field_of_view_x(24, 36)) == pytest.approx(73.7398, abs=1e-4)


def test_fov_50mm_full_frame():
    # atan(0.36) = 19.7989 deg -> 39.5978 deg, the usual "40 degrees" of a normal lens.
    assert math.degrees(field_of_view_x(50, 36)) == pytest.approx(39.5978, abs=1e-4)


@pytest.mark.parametrize("f", [8, 14, 35, 50, 200, 800])
def test_focal_length_for_fov_inverts_field_of_view(f):
    assert focal_length_for_fov(field_of_view_x(f, 36), 36) == pytest.approx(f, rel=1e-12)


def test_focal_length_for_fov_right_angle():
    assert focal_length_for_fov(math.pi / 2, 23.5) == pytest.approx(23.5 / 2, rel=1e-12)


@pytest.mark.parametrize("fov", [0.0, math.pi, -0.1, 4.0])
def test_focal_length_for_fov_rejects_impossible_angles(fov):
    with pytest.raises(ValueError):
        focal_length_for_fov(fov, 36)


@pytest.mark.parametrize("args", [(0, 36), (-50, 36), (50, 0), (math.nan, 36), (math.inf, 36)])
def test_field_of_view_rejects_bad_input(args):
    with pytest.raises(ValueError):
        field_of_view_x(*args)


# --- aperture -------------------------------------------------------------------------------

def test_lens_radius_is_in_metres():
    # Aperture diameter 50 / 2 = 25 mm, radius 12.5 mm = 0.0125 m.
    assert lens_radius_m(50, 2) == pytest.approx(0.0125, rel=1e-12)
    # 85 mm f/1.4: diameter 60.714 mm, radius 0.030357 m.
    assert lens_radius_m(85, 1.4) == pytest.approx(0.03035714, rel=1e-6)


def test_lens_radius_rejects_zero_f_number():
    with pytest.raises(ValueError):
        lens_radius_m(50, 0)


# --- defocus blur (docs/architecture.md: c = (f/N) |d - s| / d * f / s) ------------------

def test_blur_of_point_at_half_the_focus_distance():
    # 50 mm f/2 focused at 2 m, point at 1 m: A = 25 mm, |d - s| / d = 1,
    # magnification f / s = 50 / 2000 = 0.025 -> 25 * 1 * 0.025 = 0.625 mm.
    assert blur_diameter_mm(50, 2, 2.0, 1.0) == pytest.approx(0.625, rel=1e-12)


def test_blur_of_point_at_twice_the_focus_distance():
    # Same lens, point at 4 m: |4 - 2| / 4 = 0.5 -> 0.3125 mm.
    assert blur_diameter_mm(50, 2, 2.0, 4.0) == pytest.approx(0.3125, rel=1e-12)


def test_blur_at_infinity_is_aperture_times_magnification():
    # d -> inf: |d - s| / d -> 1, so c = (f/N) f / s = 25 * 0.025 = 0.625 mm.
    assert blur_diameter_mm(50, 2, 2.0, math.inf) == pytest.approx(0.625, rel=1e-12)


def test_blur_vanishes_on_the_plane_of_focus():
    assert blur_diameter_mm(85, 1.4, 3.7, 3.7) == 0.0


def test_blur_is_a_python_float_for_scalars():
    assert type(blur_diameter_mm(50, 2, 2.0, 3.0)) is float


def test_blur_is_vectorised():
    depths = np.array([[1.0, 2.0], [4.0, np.inf]])
    c = blur_diameter_mm(50, 2, 2.0, depths)
    assert isinstance(c, np.ndarray) and c.shape == (2, 2)
    np.testing.assert_allclose(c, [[0.625, 0.0], [0.3125, 0.625]], rtol=1e-12)
    # Broadcasting over f-numbers as well.
    c2 = blur_diameter_mm(50, np.array([2.0, 4.0, 8.0]), 2.0, 1.0)
    np.testing.assert_allclose(c2, [0.625, 0.3125, 0.15625], rtol=1e-12)


@pytest.mark.parametrize("n1,n2", [(1.4, 2.8), (2, 8), (4, 5.6), (2.8, 22)])
def test_blur_shrinks_by_the_f_number_ratio(n1, n2):
    depths = np.geomspace(0.3, 300.0, 50)
    ratio = blur_diameter_mm(50, n2, 3.0, depths) / np.maximum(
        blur_diameter_mm(50, n1, 3.0, depths), 1e-300
    )
    np.testing.assert_allclose(ratio[depths != 3.0], n1 / n2, rtol=1e-12)


def test_blur_grows_with_focal_length_squared_at_fixed_f_number():
    # c is proportional to f^2 at fixed N, s, d: doubling f quadruples the blur.
    assert blur_diameter_mm(100, 4, 5, 20) == pytest.approx(4 * blur_diameter_mm(50, 4, 5, 20))


def test_blur_rejects_points_behind_the_lens():
    with pytest.raises(ValueError):
        blur_diameter_mm(50, 2, 2.0, np.array([1.0, 0.0]))


def test_textbook_blur_differs_by_s_over_s_minus_f():
    # Sensor at v = f s / (s - f) instead of f: magnification f/(s-f) instead of f/s.
    # 50 mm focused at 0.2 m: factor 200 / 150 = 4/3.
    planar = blur_diameter_mm(50, 2, 0.2, 1.0)
    assert textbook_blur_diameter_mm(50, 2, 0.2, 1.0) == pytest.approx(planar * 4 / 3, rel=1e-12)
    with pytest.raises(ValueError):
        textbook_blur_diameter_mm(50, 2, 0.04, 1.0)  # focused inside the focal length


# --- circle of confusion and hyperfocal distance --------------------------------------------

def test_full_frame_circle_of_confusion():
    # diagonal sqrt(36^2 + 24^2) = 43.2666 mm; / 1500 = 0.028844 mm ("0.029").
    c = circle_of_confusion_mm(36, 24)
    assert c == pytest.approx(0.0288444, rel=1e-5)
    assert round(c, 3) == 0.029


def test_aps_c_circle_of_confusion():
    # sqrt(23.5^2 + 15.6^2) = 28.2066 mm; / 1500 = 0.018804 mm.
    assert circle_of_confusion_mm(23.5, 15.6) == pytest.approx(0.0188044, rel=1e-5)


def test_hyperfocal_50mm_f8_full_frame():
    # f^2 / (N c) = 2500 / (8 * 0.029) = 10775.86 mm; + f = 10825.86 mm = 10.826 m.
    assert hyperfocal_distance_m(50, 8, 0.029) == pytest.approx(10.82586, rel=1e-6)


def test_hyperfocal_35mm_f11():
    # 1225 / (11 * 0.03) = 3712.12 mm; + 35 = 3747.12 mm.
    assert hyperfocal_distance_m(35, 11, 0.03) == pytest.approx(3.74712, rel=1e-5)


# --- depth of field -------------------------------------------------------------------------

def test_dof_50mm_f8_at_5m_textbook():
    # c = 0.03: H - f = 2500 / 0.24 = 10416.67 mm, H = 10466.67 mm, s = 5000 mm.
    # near = 5000 * 10416.67 / (10466.67 + 5000 - 100) = 3389.37 mm
    # far  = 5000 * 10416.67 / (10466.67 - 5000)       = 9527.44 mm
    d = depth_of_field(50, 8, 5.0, 0.03)
    assert d.near_m == pytest.approx(3.38937, rel=1e-5)
    assert d.far_m == pytest.approx(9.52744, rel=1e-5)
    assert d.hyperfocal_m == pytest.approx(10.46667, rel=1e-5)
    assert d.total_m == pytest.approx(9.52744 - 3.38937, rel=1e-5)


def test_dof_50mm_f8_at_5m_planar():
    # H0 = 10416.67 mm: near = 5000 H0 / (H0 + 5000) = 3378.38 mm, far = 5000 H0 / (H0 - 5000) = 9615.38 mm.
    d = depth_of_field(50, 8, 5.0, 0.03, model="planar")
    assert d.near_m == pytest.approx(3.37838, rel=1e-5)
    assert d.far_m == pytest.approx(9.61538, rel=1e-5)
    assert d.hyperfocal_m == pytest.approx(10.41667, rel=1e-5)


@pytest.mark.parametrize("model", ["thin_lens", "planar"])
def test_focused_at_hyperfocal_far_is_infinite_near_is_half(model):
    h = depth_of_field(50, 8, 5.0, 0.029, model=model).hyperfocal_m
    d = depth_of_field(50, 8, h, 0.029, model=model)
    assert d.far_m == math.inf and d.total_m == math.inf
    assert d.near_m == pytest.approx(h / 2, rel=1e-12)


@pytest.mark.parametrize("model", ["thin_lens", "planar"])
def test_beyond_hyperfocal_far_stays_infinite(model):
    d = depth_of_field(24, 11, 100.0, 0.029, model=model)
    assert d.far_m == math.inf
    assert 0 < d.near_m < d.hyperfocal_m


def test_textbook_hyperfocal_matches_dof():
    assert depth_of_field(85, 2, 3, 0.029).hyperfocal_m == pytest.approx(
        hyperfocal_distance_m(85, 2, 0.029), rel=1e-12
    )


CASES = [  # focal mm, N, focus m, coc mm
    (50, 8, 5.0, 0.029),
    (85, 1.4, 2.0, 0.029),
    (24, 4, 1.0, 0.019),
    (135, 2, 10.0, 0.029),
    (100, 2.8, 0.3, 0.029),  # macro distance: the models part here
    (14, 2.8, 0.5, 0.029),
]


@pytest.mark.parametrize("f,n,s,c", CASES)
def test_planar_limits_are_where_the_renderer_blur_equals_coc(f, n, s, c):
    """The "planar" readout is consistent with blur_diameter_mm (what the renderer draws)."""
    d = depth_of_field(f, n, s, c, model="planar")
    assert blur_diameter_mm(f, n, s, d.near_m) == pytest.approx(c, rel=1e-9)
    if math.isfinite(d.far_m):
        assert blur_diameter_mm(f, n, s, d.far_m) == pytest.approx(c, rel=1e-9)
    # Inside the limits the blur is smaller, outside larger.
    inside, outside = (d.near_m + s) / 2, d.near_m * 0.9
    assert blur_diameter_mm(f, n, s, inside) < c < blur_diameter_mm(f, n, s, outside)


@pytest.mark.parametrize("f,n,s,c", CASES)
def test_textbook_limits_are_where_the_textbook_blur_equals_coc(f, n, s, c):
    d = depth_of_field(f, n, s, c)
    assert textbook_blur_diameter_mm(f, n, s, d.near_m) == pytest.approx(c, rel=1e-9)
    if math.isfinite(d.far_m):
        assert textbook_blur_diameter_mm(f, n, s, d.far_m) == pytest.approx(c, rel=1e-9)


def test_models_agree_at_ordinary_distances_and_differ_in_macro():
    # Near limits differ by less than f / s (relative); 50 mm at 5 m -> under 1 %.
    far_apart = depth_of_field(50, 8, 5.0, 0.029), depth_of_field(50, 8, 5.0, 0.029, model="planar")
    assert far_apart[0].near_m == pytest.approx(far_apart[1].near_m, rel=0.01)
    assert far_apart[0].hyperfocal_m - far_apart[1].hyperfocal_m == pytest.approx(0.05, rel=1e-9)
    # 100 mm macro at 0.3 m: f/s = 1/3, the textbook blur is 1.5x larger, so its DoF is smaller.
    macro = depth_of_field(100, 2.8, 0.3, 0.029), depth_of_field(100, 2.8, 0.3, 0.029, model="planar")
    assert macro[0].total_m < macro[1].total_m / 1.4


def test_stopping_down_deepens_the_depth_of_field():
    totals = [depth_of_field(50, n, 3.0, 0.029).total_m for n in THIRD_STOPS[:15]]
    assert all(a < b for a, b in zip(totals, totals[1:]))


def test_dof_rejects_bad_input():
    with pytest.raises(ValueError):
        depth_of_field(50, 8, 0.04, 0.029)  # focused inside the focal length
    with pytest.raises(ValueError):
        depth_of_field(50, 8, 5.0, 0.029, model="pinhole")
    with pytest.raises(ValueError):
        depth_of_field(50, 0, 5.0, 0.029)
    with pytest.raises(ValueError):
        hyperfocal_distance_m(50, 8, 0)


def test_dof_result_is_frozen():
    d = depth_of_field(50, 8, 5.0, 0.029)
    with pytest.raises(AttributeError):
        d.near_m = 1.0


# --- stops ----------------------------------------------------------------------------------

def test_third_stops_are_the_marked_scale():
    assert THIRD_STOPS[0] == 1.4 and THIRD_STOPS[-1] == 22 and len(THIRD_STOPS) == 25
    # Every mark is within 6 % of the exact third stop sqrt(2)^(k/3) starting at f/1.4.
    for k, mark in enumerate(THIRD_STOPS):
        assert mark == pytest.approx(2 ** ((k + 3) / 6), rel=0.06)


def test_extended_stops_continue_the_scale():
    assert EXTENDED_THIRD_STOPS[0] == 0.7 and EXTENDED_THIRD_STOPS[-1] == 128
    assert list(EXTENDED_THIRD_STOPS) == sorted(EXTENDED_THIRD_STOPS)
    start = EXTENDED_THIRD_STOPS.index(1.4)
    assert EXTENDED_THIRD_STOPS[start:start + len(THIRD_STOPS)] == THIRD_STOPS
    for k, mark in enumerate(EXTENDED_THIRD_STOPS):
        assert mark == pytest.approx(2 ** ((k - 3) / 6), rel=0.06)


def test_stops_between():
    assert stops_between(2.8, 5.6) == pytest.approx(2.0, abs=0.01)
    assert stops_between(8, 4) == pytest.approx(-2.0, abs=1e-12)


@pytest.mark.parametrize("n,expected", [(5.657, 5.6), (1.0, 1.4), (100, 22), (2.09, 2.0), (2.1, 2.2), (2.15, 2.2), (11.3, 11)])
def test_nearest_stop_on_the_marks(n, expected):
    # Distance is measured in stops: 2.1 is linearly midway between 2 and 2.2 but nearer 2.2 in log.
    assert nearest_stop(n, THIRD_STOPS) == expected


@pytest.mark.parametrize("n,k", [(5.6, 15), (5.657, 15), (11, 21), (11.3, 21), (3.0, 10), (100, 40), (0.5, -3)])
def test_nearest_stop_is_an_exact_third_stop(n, k):
    assert nearest_stop(n) == pytest.approx(2 ** (k / 6), rel=1e-12)  # f/1 is k = 0; f/0.7 (k = -3) is the end
    assert nearest_stop(n, "full") in STOP_SCALES["full"].exact


@pytest.mark.parametrize(
    "n,steps,expected",
    [
        (2.8, 1, 3.2), (2.8, 3, 4), (2.8, -3, 2), (5.6, 6, 11),
        (2.8, -100, 1.4), (2.8, 100, 22), (22, 1, 22), (1.4, -1, 1.4),
        (3.0, 1, 3.2), (3.0, -1, 2.8), (3.0, 2, 3.5), (3.0, -2, 2.5),  # between marks
        (1.2, -1, 1.2), (1.2, 1, 1.4), (32, 1, 32), (32, -1, 22),  # beyond the ends
        (5.657, 0, 5.6),
        (2 ** 1.5, 1, 3.2), (2 ** 3.5, -1, 10),  # an exact stop on a scale of marks is its mark
    ],
)
def test_step_stop_on_the_marks(n, steps, expected):
    assert step_stop(n, steps, THIRD_STOPS) == expected


@pytest.mark.parametrize(
    "n,steps,k",
    [
        (2 ** 1.5, 1, 10), (2 ** 1.5, 3, 12), (2 ** 1.5, -3, 6), (2 ** 2.5, 6, 21),
        (2.8, 1, 10), (5.6, 6, 21), (11, -1, 20),  # a mark is its exact stop
        (2.8, -100, -3), (2.8, 100, 42), (128, 1, 42), (0.7, -1, -3),  # clamped to f/0.7 .. f/128
        (3.0, 1, 10), (3.0, -1, 9), (3.0, 2, 11), (3.0, -2, 8),  # between marks: the next mark first
        (0.6, -1, None), (0.6, 1, -3), (2.9, 0, 9),
    ],
)
def test_step_stop_moves_between_exact_third_stops(n, steps, k):
    expected = n if k is None else 2 ** (k / 6)
    assert step_stop(n, steps) == pytest.approx(expected, rel=1e-12)


def test_step_stop_on_a_custom_scale():
    lens_scale = (1.2,) + THIRD_STOPS[:-3]  # an f/1.2 .. f/16 lens
    assert step_stop(1.4, -1, lens_scale) == 1.2
    assert step_stop(14, 5, lens_scale) == 16


def test_a_scale_argument_is_a_name_a_stop_scale_or_numbers():
    half = STOP_SCALES["half"]
    assert step_stop(4, 1, "half") == step_stop(4, 1, half) == step_stop(4, 1, half.exact) == 2 ** 2.25
    assert nearest_stop(4.5, half) == nearest_stop(4.5, "half") == 2 ** 2.25
    assert stops.stop_scale("half") is half and stops.stop_scale(half) is half
    assert stops.stop_scale() is STOP_SCALES[stops.DEFAULT_STOP_SCALE] is STOP_SCALES["third"]
    for call in (lambda: step_stop(4, 1, "quarter"), lambda: exact_f_number(4, "quarter"),
                 lambda: parse_f_number("4", "quarter"), lambda: marked_f_number(4, "quarter")):
        with pytest.raises(ValueError, match="quarter.*full, half, third"):
            call()


@pytest.mark.parametrize(
    "n,text", [(2.8, "f/2.8"), (2, "f/2"), (2.0, "f/2"), (22, "f/22"), (0.95, "f/0.95"), (5.657, "f/5.6"), (5.65, "f/5.7"), (128, "f/128")]
)
def test_format_f_number(n, text):
    assert format_f_number(n) == text


# Conventional marks further than 3 % from their stop: f/0.84 and f/13.45 are marked 0.8 and 13 on halves,
# f/1.26 is marked 1.2 on thirds (the f/1.2 lens).
_ROUGH_MARKS = {("half", 0.8), ("half", 13), ("third", 1.2)}


@pytest.mark.parametrize("scale, marks", [
    ("full", (0.7, 1, 1.4, 2, 2.8, 4, 5.6, 8, 11, 16, 22, 32, 45, 64, 90, 128)),
    ("half", (0.7, 0.8, 1, 1.2, 1.4, 1.7, 2, 2.4, 2.8, 3.3, 4, 4.8, 5.6, 6.7, 8, 9.5, 11, 13, 16, 19, 22, 27, 32, 38,
              45, 54, 64, 76, 90, 108, 128)),
    ("third", EXTENDED_THIRD_STOPS),
])
def test_every_mark_is_its_exact_stop_rounded(scale, marks):
    stops = STOP_SCALES[scale]
    assert stops.name == scale and stops.marks == marks and len(stops.exact) == len(marks)
    assert stops.exact[0] == pytest.approx(2 ** -0.5) and stops.exact[-1] == 128  # f/0.7 .. f/128 each
    per_stop = {"full": 1, "half": 2, "third": 3}[scale]
    assert stops.steps_per_stop == per_stop and stops.step_in_stops == pytest.approx(1 / per_stop)
    k0 = -marks.index(1)
    for i, (mark, exact) in enumerate(zip(marks, stops.exact)):
        assert exact == 2 ** ((k0 + i) / (2 * per_stop))  # f/1 is k = 0
        assert mark == pytest.approx(exact, rel=0.05 if (scale, mark) in _ROUGH_MARKS else 0.03), mark
        # ... and within half a step of its own stop (in stops of light), so nearer it than any other.
        assert abs(2 * math.log2(mark / exact)) < 0.5 / per_stop, mark
        assert nearest_stop(mark, scale) == exact
    assert all(m in STOP_SCALES[s].marks for s, m in _ROUGH_MARKS)  # the exceptions are real marks


def test_the_marked_names_are_the_third_stop_marks():
    assert THIRD_STOPS == EXTENDED_THIRD_STOPS[EXTENDED_THIRD_STOPS.index(1.4):EXTENDED_THIRD_STOPS.index(22) + 1]
    assert stops.FULL_STOPS == STOP_SCALES["full"].marks and stops.HALF_STOPS == STOP_SCALES["half"].marks
    # Every full stop is on the half and the third scales, with the same mark.
    for mark, exact in zip(STOP_SCALES["full"].marks, STOP_SCALES["full"].exact):
        for scale in ("half", "third"):
            assert exact_f_number(mark, scale) == pytest.approx(exact) and marked_f_number(exact, scale) == mark


@pytest.mark.parametrize("scale", ["full", "half", "third"])
def test_a_mark_reads_as_its_exact_stop_and_shows_as_its_mark(scale):
    stops = STOP_SCALES[scale]
    assert len(stops.marks) == len(stops.exact)
    for mark, exact in zip(stops.marks, stops.exact):
        assert parse_f_number(f"f/{mark:g}", scale) == exact
        assert exact_f_number(mark, scale) == exact
        assert exact_f_number(mark * (1 + 5e-4), scale) == exact  # float noise is the same mark
        assert marked_f_number(exact, scale) == mark
        assert marked_f_number(exact_f_number(mark, scale), scale) == mark  # round trip, both ways
        assert exact_f_number(marked_f_number(exact, scale), scale) == exact
        assert format_f_number(exact) == f"f/{mark:g}"


@pytest.mark.parametrize("scale, fraction", [("full", 1.0), ("half", 0.5), ("third", 1 / 3)])
def test_one_step_is_exactly_one_mark_of_the_scale(scale, fraction):
    exact = STOP_SCALES[scale].exact
    for n, after in zip(exact, exact[1:]):
        assert step_stop(n, 1, scale) == after and step_stop(after, -1, scale) == n
        assert 2 * math.log2(after / n) == pytest.approx(fraction, abs=1e-12)  # stops of light
    n = exact_f_number(2.8, scale)
    assert 2 * math.log2(step_stop(n, 3, scale) / n) == pytest.approx(3 * fraction, abs=1e-12)
    # By marks alone the steps are uneven: f/10 -> f/11 looks like 0.28 stop, f/11 -> f/13 like 0.48.
    assert 2 * math.log2(11 / 10) < 0.3 < 0.45 < 2 * math.log2(13 / 11)


def test_a_mark_two_scales_share_is_read_on_the_scale_given():
    assert exact_f_number(13, "third") == pytest.approx(2 ** (11 / 3))  # 12.70
    assert exact_f_number(13, "half") == pytest.approx(2 ** 3.75)  # 13.45
    assert exact_f_number(13, STOP_SCALES["half"]) == pytest.approx(2 ** 3.75)
    assert parse_f_number("f/13", "third") == pytest.approx(12.699, abs=1e-3)
    assert parse_f_number("f/13", "half") == pytest.approx(13.454, abs=1e-3)
    assert marked_f_number(2 ** 3.75) == 13 == marked_f_number(2 ** (11 / 3))  # either shows as f/13
    assert format_f_number(2 ** 3.75) == format_f_number(2 ** (11 / 3)) == "f/13"
    assert step_stop(13, 1, "third") == pytest.approx(2 ** 3.5 * 2 ** (1 / 3))  # 12.70 -> 14.25
    assert step_stop(13, 1, "half") == 16  # 13.45 -> 16
    assert exact_f_number(3.3, "third") == 3.3 and exact_f_number(3.3, "half") == pytest.approx(2 ** 1.75)
    assert exact_f_number(5.65) == 5.65  # not a mark: as written


def test_marked_f_number_leaves_other_numbers_alone():
    assert marked_f_number(2 ** 3.5) == 11 and marked_f_number(2 ** (5 / 6)) == 1.8
    assert marked_f_number(2 ** 1.75) == 3.3  # a half stop, not a third: found on the half scale
    assert marked_f_number(2 ** 1.75, "third") == 2 ** 1.75  # asked for thirds only
    assert marked_f_number(2 ** 3.5 * 1.01) == 2 ** 3.5 * 1.01  # 1 % off an exact stop is no stop
    assert marked_f_number(3.0) == 3.0 and marked_f_number(11) == 11


@pytest.mark.parametrize(
    "n,text", [(2 ** 3.5, "f/11"), (2 ** 2.5, "f/5.6"), (5.657, "f/5.6"), (2 ** (5 / 6), "f/1.8"), (2 ** 1.75, "f/3.3"),
               (2 ** (11 / 3), "f/13"), (2 ** (-1 / 6), "f/0.9"), (2 ** 6.5, "f/90"), (2 ** (41 / 6), "f/114"),
               (3.0, "f/3"), (11.2, "f/11.2"), (12, "f/12"), (0.95, "f/0.95")]
)
def test_format_f_number_shows_the_mark_of_an_exact_stop(n, text):
    assert format_f_number(n) == text


@pytest.mark.parametrize("text,exact", [("f/11", 2 ** 3.5), ("f/5.6", 2 ** 2.5), ("1.8", 2 ** (5 / 6)),
                                        ("F22", 2 ** 4.5), ("1:1.2", 2 ** (1 / 3)), ("f/3", 3.0), ("f/3.3", 3.3),
                                        ("11.31", 11.31), ("f/12", 12.0)])
def test_parse_f_number_gives_the_exact_stop_of_a_mark(text, exact):
    assert parse_f_number(text) == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize(
    "text,n", [("f/2.8", 2.8), ("2.8", 2.8), ("F/4", 4), ("f2.8", 2.8), (" f / 11 ", 11), ("1:1.4", 1.4), ("2,8", 2.8), ("ƒ/8", 8), (".95", 0.95)]
)
def test_parse_f_number(text, n):
    assert parse_f_number(text) == pytest.approx(exact_f_number(n))  # marks read as their exact stop


@pytest.mark.parametrize("text", ["", "f/", "f/abc", "2.8.1", "f/-2", "nan", "inf", "f/2.8 mm", "1/2.8x"])
def test_parse_f_number_rejects_garbage_naming_it(text):
    with pytest.raises(ValueError) as info:
        parse_f_number(text)
    assert repr(text) in str(info.value)


@pytest.mark.parametrize("text", ["f/0", "0,0", "0.0000001", "f/2000000"])
def test_parse_f_number_rejects_out_of_range(text):
    with pytest.raises(ValueError, match="out of range") as info:
        parse_f_number(text)
    assert repr(text) in str(info.value)


def test_f_number_range_bounds():
    # What a scene file accepts, the stop functions accept too; the studio's controls offer f/0.5 to f/128 of it.
    from lenslab.scene.camera import ThinLensCamera
    from lenslab.scene.fields import control_range, declared_range

    assert declared_range(ThinLensCamera, "f_number") == stops.F_NUMBER_RANGE == (1e-6, 1e6)
    assert control_range(ThinLensCamera, "f_number") == (0.5, 128)
    assert parse_f_number("f/128") == 128
    assert parse_f_number("0.5") == 0.5 and parse_f_number("0.49") == 0.49
    assert format_f_number(0.5) == "f/0.5" and format_f_number(0.49) == "f/0.49"
    with pytest.raises(ValueError):
        format_f_number(0)


# --- layering -------------------------------------------------------------------------------

def test_optics_imports_neither_gl_nor_qt():
    code = (
        "import sys, lenslab.optics as o; o.load_lens_presets(include_user=False); "
        "bad = [m for m in sys.modules if m.split('.')[0] in ('moderngl', 'PySide6', 'glcontext')]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True,
        env=dict(os.environ, PYTHONPATH=str(APP_DIR)),
    )
    assert result.returncode == 0, result.stdout + result.stderr


def test_modules_expose_documented_names():
    for module in (thinlens, dof, stops):
        for name in module.__all__:
            assert getattr(module, name).__doc__ or not callable(getattr(module, name)), name


def test_format_focal_length_reads_as_a_lens_barrel():
    from lenslab.optics import format_focal_length

    assert [format_focal_length(v) for v in (50, 31.1769, 24.04, 85.0)] == ["50 mm", "31.2 mm", "24 mm", "85 mm"]


@pytest.mark.parametrize("metres, text", [(1.5, "1.50 m"), (12.5, "12.5 m"), (120.0, "120 m"), (0.45, "45.0 cm"),
                                          (math.inf, "∞")])
def test_format_distance_as_a_focus_scale_reads(metres, text):
    from lenslab.optics import format_distance

    assert format_distance(metres) == text


def test_camera_settings_read_as_the_studio_shows_them():
    from lenslab.optics import format_camera_settings

    assert format_camera_settings(85.0, 1.4, 0.8) == "85 mm · f/1.4 · focus 80.0 cm"
