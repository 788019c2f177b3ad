"""The numbers behind the viewport's judging aids (no Qt): aspect presets, composition guides and safe areas,
focus peaking, the histogram and its clipping."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenslab.optics.aspect import (ASPECT_PRESETS, aspect_name, aspect_preset, matching_preset,
                                   resolution_for_aspect)
from lenslab.optics.composition import (ACTION_SAFE, GOLDEN_FRACTIONS, PHI, TITLE_SAFE, guide_lines, safe_rect,
                                        sensor_rect)
from lenslab.optics.histogram import clipping_masks, histogram
from lenslab.optics.peaking import (EDGE_SCALE, PEAKING_SENSITIVITY, blur_in_cocs, edge_strength, peaking_mask,
                                    resample_nearest, veiled_by_foreground, within_depth_of_field)
from lenslab.scene.camera import ThinLensCamera


# -- aspect ------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, start, expected", [
    ("3:2", (1920, 1080), (1920, 1280)),
    ("4:5", (1920, 1080), (1536, 1920)),
    ("1:1", (1920, 1080), (1920, 1920)),
    ("16:9", (1920, 1280), (1920, 1080)),
    ("3:2", (480, 640), (640, 427)),  # a portrait's long edge becomes the width: 3:2 is landscape
    ("16:9", (64, 48), (64, 36)),
])
def test_an_aspect_preset_keeps_the_long_edge(name, start, expected):
    assert resolution_for_aspect(start, aspect_preset(name)) == expected


def test_a_resolution_has_the_preset_that_gives_it_back():
    assert matching_preset((640, 427)).name == "3:2"
    assert matching_preset((1080, 1350)).name == "4:5"
    assert matching_preset((640, 480)) is None
    for preset in ASPECT_PRESETS:  # every preset's own result is recognised as that preset
        assert matching_preset(resolution_for_aspect((1000, 700), preset)) is preset
    with pytest.raises(ValueError, match="choose from 3:2, 4:5, 1:1, 16:9"):
        aspect_preset("5:3")


@pytest.mark.parametrize("size, name", [((1920, 1280), "3:2"), ((640, 427), "3:2"), ((640, 480), "4:3"),
                                        ((1920, 1080), "16:9"), ((1080, 1350), "4:5"), ((700, 500), "7:5"),
                                        ((1998, 1080), "1.85:1"), ((1000, 487), "2.05:1"), ((487, 1000), "1:2.05")])
def test_aspect_names(size, name):
    assert aspect_name(*size) == name


# -- guides and safe areas ------------------------------------------------------------------------------------------
def test_thirds_cut_the_frame_in_three_each_way():
    lines = guide_lines("thirds", (30, 10, 900, 600))
    assert lines == [(330, 10, 330, 610), (630, 10, 630, 610), (30, 210, 930, 210), (30, 410, 930, 410)]


def test_golden_section_lines_divide_each_side_in_the_golden_ratio():
    x, y, w, h = 0, 0, 1000, 600
    (v1, _, _, _), (v2, _, _, _), (_, h1, _, _), (_, h2, _, _) = guide_lines("golden", (x, y, w, h))
    assert v1 == pytest.approx(381.966, abs=1e-3) and v2 == pytest.approx(618.034, abs=1e-3)
    assert (w - v1) / v1 == pytest.approx(PHI) and v2 / (w - v2) == pytest.approx(PHI)
    assert h1 == pytest.approx(600 * GOLDEN_FRACTIONS[0]) and h2 / (h - h2) == pytest.approx(PHI)


def test_centre_cross_and_none():
    cross = guide_lines("centre", (100, 100, 400, 200))
    assert cross == [(300, 192, 300, 208), (292, 200, 308, 200)]  # arms 4 % of the short side
    assert guide_lines("none", (0, 0, 10, 10)) == []
    with pytest.raises(ValueError):
        guide_lines("diagonal", (0, 0, 10, 10))


def test_safe_areas_are_smpte_and_ebu_figures():
    assert (ACTION_SAFE, TITLE_SAFE) == (0.93, 0.90)
    action = safe_rect((0, 0, 1920, 1080), ACTION_SAFE)
    assert action == pytest.approx((67.2, 37.8, 1785.6, 1004.4))  # 3.5 % in from each edge
    title = safe_rect((100, 50, 1000, 500), TITLE_SAFE)
    assert title == pytest.approx((150, 75, 900, 450))


def test_sensor_outline_with_each_fit():
    camera = ThinLensCamera(sensor_mm=(36.0, 24.0), resolution=(1000, 1000))  # auto fit: 36 x 36 mm imaged
    frame = (0, 0, 600, 600)
    assert sensor_rect(frame, camera.sensor_mm, camera.imaged_area_mm()) == pytest.approx((0, 100, 600, 400))
    camera.sensor_fit = "fill"  # a crop of the sensor: the sensor reaches out past the frame
    assert sensor_rect(frame, camera.sensor_mm, camera.imaged_area_mm()) == pytest.approx((-150, 0, 900, 600))
    camera.resolution = (1500, 1000)  # the sensor's own shape: the same rectangle
    assert sensor_rect((0, 0, 900, 600), camera.sensor_mm, camera.imaged_area_mm()) == pytest.approx((0, 0, 900, 600))


# -- focus peaking ----------------------------------------------------------------------------------------------------
def test_edge_strength_is_one_beside_a_black_to_white_step_and_zero_on_flat_ground():
    picture = np.zeros((12, 12, 4), np.uint8)
    picture[:, 6:, :3] = 255
    strength = edge_strength(picture)
    assert strength[6, 5] == pytest.approx(1.0) and strength[6, 6] == pytest.approx(1.0)
    assert strength[6, 2] == 0 and strength[6, 9] == 0
    # A red edge on a grey of about the same luma is an edge all the same (the strongest channel counts).
    colour = np.full((12, 12, 3), 60, np.uint8)
    colour[:, 6:] = (200, 20, 20)  # luma 58 against 60
    assert edge_strength(colour)[6, 6] == pytest.approx(140 / 255, abs=1e-3)
    assert EDGE_SCALE == 6 * 255


def test_within_depth_of_field_leaves_out_the_background():
    depth = np.array([[0.5, 1.0, 2.0, 3.0, np.inf]], np.float32)
    assert within_depth_of_field(depth, 1.0, 2.5).tolist() == [[False, True, True, False, False]]
    assert within_depth_of_field(depth, 1.0, math.inf).tolist() == [[False, True, True, True, False]]


def test_resample_nearest():
    depth = np.arange(6, dtype=np.float32).reshape(2, 3)
    assert resample_nearest(depth, (4, 6)).tolist() == [[0, 0, 1, 1, 2, 2]] * 2 + [[3, 3, 4, 4, 5, 5]] * 2
    assert resample_nearest(depth, (2, 3)) is depth


def synthetic_scene(width: int = 96, height: int = 64):
    """Two cards with the same hard-edged checkerboard, the left at 2 m (in focus), the right at 6 m (not), on a
    background at infinity. The picture keeps the right card's edges hard, as an unconverged render might: only
    the depth can say it is out of focus."""
    picture = np.full((height, width, 4), 40, np.uint8)
    picture[..., 3] = 255
    depth = np.full((height, width), np.inf, np.float32)
    yy, xx = np.mgrid[0:height, 0:width]
    checks = ((xx // 8 + yy // 8) % 2 == 0)
    for x0, d in ((8, 2.0), (56, 6.0)):
        card = (xx >= x0) & (xx < x0 + 32) & (yy >= 16) & (yy < 48)
        picture[card & checks, :3] = 230
        picture[card & ~checks, :3] = 90
        depth[card] = d
    return picture, depth


def test_peaking_marks_the_edges_in_focus_and_not_those_out_of_focus():
    picture, depth = synthetic_scene()
    camera = ThinLensCamera(position=(0, 0, 0), look_at=(0, 0, -1), focal_length_mm=50, f_number=2.8,
                            focus_distance_m=2.0, focus_from="lens", resolution=(96, 64))
    dof = camera.depth_of_field(reference="lens")
    assert dof.near_m < 2.0 < dof.far_m < 6.0
    mask = peaking_mask(picture, depth, dof.near_m, dof.far_m)
    in_focus, out_of_focus = depth == 2.0, depth == 6.0
    assert mask[in_focus].sum() > 100  # the checks' edges on the near card
    assert not mask[out_of_focus].any()  # the far card's edges are just as hard, but it lies beyond the far limit
    assert not mask[~np.isfinite(depth)].any()
    # Flat squares of the near card are not marked: only edges.
    assert not mask[20:22, 12:14].any() and mask[20, 8:40].any()
    # Focused on the far card, the marks move there.
    far = peaking_mask(picture, depth, 5.0, 7.0)
    assert far[out_of_focus].sum() > 100 and not far[in_focus].any()
    # A lower sensitivity marks fewer pixels, a higher one more.
    soft = picture.copy()
    soft[..., :3] = (soft[..., :3].astype(np.float32) * 0.3 + 40).astype(np.uint8)  # a low-contrast chart
    counts = [peaking_mask(soft, depth, 1.5, 2.5, PEAKING_SENSITIVITY[s]).sum() for s in ("low", "medium", "high")]
    assert counts[0] < counts[1] <= counts[2]


def test_peaking_takes_a_depth_buffer_of_another_size():
    picture, depth = synthetic_scene()
    half = depth[::2, ::2]
    mask = peaking_mask(picture, half, 1.5, 2.5)
    assert mask.shape == picture.shape[:2] and mask[:, :48].sum() > 100 and not mask[:, 56:].any()


# -- histogram and clipping --------------------------------------------------------------------------------------------
def test_histogram_counts_and_clipping():
    picture = np.zeros((10, 20, 4), np.uint8)
    picture[..., 3] = 255
    picture[:, :5, :3] = 0  # 50 black pixels: crushed
    picture[:, 5:10, :3] = 128  # 50 mid grey
    picture[:, 10:15] = (255, 200, 100, 255)  # 50 with red clipped
    picture[:, 15:20, :3] = 255  # 50 white: all channels clipped
    h = histogram(picture)
    assert h.pixels == 200
    assert h.counts[0, 0] == 50 and h.counts[0, 128] == 50 and h.counts[0, 255] == 100
    assert h.counts[1, 200] == 50 and h.counts[2, 100] == 50 and h.counts[1, 255] == 50
    assert h.counts.sum(axis=1).tolist() == [200] * 4
    assert h.luma[0] == 50 and h.luma[128] == 50 and h.luma[255] == 50
    luma_orange = round(0.2126 * 255 + 0.7152 * 200 + 0.0722 * 100)
    assert h.luma[luma_orange] == 50
    assert h.clipped.tolist() == [0.5, 0.25, 0.25] and h.clipped_any == 0.5
    assert h.crushed.tolist() == [0.25, 0.25, 0.25] and h.crushed_all == 0.25
    high, low = clipping_masks(picture)
    assert high.sum() == 100 and high[:, 10:].all() and not high[:, :10].any()
    assert low.sum() == 50 and low[:, :5].all()
    # A saturated colour with no blue at all is its colour, not a crushed shadow; the blue channel's figure has it.
    picture[:, 5:10, :3] = (120, 8, 0)
    h = histogram(picture)
    assert h.crushed_all == 0.25 and h.crushed[2] == 0.5 and not clipping_masks(picture)[1][:, 5:10].any()


def test_histogram_of_an_empty_frame_and_bad_input():
    empty = histogram(np.zeros((0, 0, 4), np.uint8))
    assert empty.pixels == 0 and empty.clipped_any == 0
    with pytest.raises(ValueError, match="uint8"):
        histogram(np.zeros((4, 4, 3), np.float32))


def test_blur_in_circles_of_confusion_is_the_renderers_blur():
    from lenslab.optics.thinlens import blur_diameter_mm

    camera = ThinLensCamera(focal_length_mm=50, f_number=2.8, focus_distance_m=2.0, focus_from="lens",
                            focus_breathing=False, resolution=(600, 400))
    dof = camera.depth_of_field(reference="lens")
    depths = np.array([0.5, 1.0, 1.9, 2.0, 3.0, 10.0])
    expected = blur_diameter_mm(50, 2.8, 2.0, depths) / camera.coc_mm()
    np.testing.assert_allclose(blur_in_cocs(depths, dof.near_m, dof.far_m), expected, rtol=1e-9)
    assert blur_in_cocs(np.array([dof.near_m, dof.far_m]), dof.near_m, dof.far_m) == pytest.approx([1, 1])


def test_a_blurred_foreground_veils_the_sharp_background_behind_it():
    """A post 0.5 m away, far out of focus, in front of a chart at the plane of focus: the chart's edges within the
    post's blur are not marked, those beyond it are."""
    height, width = 64, 160
    yy, xx = np.mgrid[0:height, 0:width]
    picture = np.full((height, width, 3), 40, np.uint8)
    picture[(xx // 8 + yy // 8) % 2 == 0] = 230
    depth = np.full((height, width), 2.0, np.float32)
    depth[:, 80:82] = 0.5  # the post (the picture still shows the chart there, as a noisy render might)
    near, far = 1.6, 2.6
    radius = 0.5 * 1.0 * blur_in_cocs(np.array([0.5]), near, far)[0]  # with a circle of confusion of 1 pixel
    assert 4 < radius < 8  # rounded up to 8
    veil = veiled_by_foreground(depth, near, far, coc_px=1.0)
    assert veil[30, 72:90].all() and not veil[30, :72].any() and not veil[30, 90:].any()
    marked = peaking_mask(picture, depth, near, far, coc_px=1.0)
    unveiled = peaking_mask(picture, depth, near, far)
    assert marked[:, 72:90].sum() == 0 < unveiled[:, 72:80].sum()
    assert (marked[:, :70] == unveiled[:, :70]).all() and marked[:, :70].sum() > 100
    # Nothing in front: nothing veiled.
    assert not veiled_by_foreground(np.full((8, 8), 2.0), near, far, 1.0).any()


def test_the_benchmark_prints_a_row_per_size(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "benchmarks" / "overlays.py"
    result = subprocess.run([sys.executable, str(script), "--sizes", "40x30", "64x48", "--repeat", "1"],
                            capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    rows = [line.split() for line in result.stdout.splitlines()[1:]]
    assert [row[0] for row in rows] == ["40x30", "64x48"] and all(len(row) == 5 for row in rows)
