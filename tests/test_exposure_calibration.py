"""A camera's exposure as docs/colour.md states it: EV100 from the settings, a reflected-light meter's calibration
(ISO 2720, K = 12.5) with its reading at middle grey, the stop arithmetic, and the auto mode's meter, down to the
metadata of a written file."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenslab.optics.exposure import (MIDDLE_GREY, REFLECTED_METER_K, camera_exposure, ev100, exposure_scale,
                                     meter_luminance, metered_ev100, nearest_third_stop_shutter, shutter_for)
from lenslab.render.film import read_image
from tests.helpers import run_cli


def test_ev100_of_familiar_settings():
    assert ev100(8.0, 1 / 125, 100) == pytest.approx(12.966, abs=1e-3)
    assert ev100(16.0, 1 / 100, 100) == pytest.approx(14.644, abs=1e-3)  # sunny 16
    assert ev100(16.0, 1 / 400, 400) == pytest.approx(ev100(16.0, 1 / 100, 100))  # sunny 16 at any ISO


def test_a_meter_reading_suggests_the_ev_of_iso_2720():
    """L = K 2^EV / 100: the luminance a meter reads at EV100 0 is 0.125 cd/m^2, and each EV doubles it."""
    assert REFLECTED_METER_K == 12.5 and MIDDLE_GREY == 0.18
    assert metered_ev100(0.125) == pytest.approx(0.0)
    assert metered_ev100(0.125 * 2 ** 14.644) == pytest.approx(14.644)


@pytest.mark.parametrize("f_number, iso", [(1.4, 100), (4.0, 400), (16.0, 100), (22.0, 6400)])
@pytest.mark.parametrize("luminance", [0.5, 40.0, 3200.0])
def test_settings_the_meter_suggests_put_the_reading_at_middle_grey(f_number, iso, luminance):
    shutter = shutter_for(metered_ev100(luminance), f_number, iso)
    assert ev100(f_number, shutter, iso) == pytest.approx(metered_ev100(luminance))
    assert exposure_scale(f_number, shutter, iso) * luminance == pytest.approx(MIDDLE_GREY)


@pytest.mark.parametrize("change, factor", [
    (dict(f_number=2.8 * math.sqrt(2)), 0.5), (dict(f_number=2.8 / math.sqrt(2)), 2.0),
    (dict(shutter_s=2 / 125), 2.0), (dict(shutter_s=0.5 / 125), 0.5),
    (dict(iso=200.0), 2.0), (dict(iso=50.0), 0.5)])
def test_each_stop_is_a_stop_of_light(change, factor):
    settings = dict(f_number=2.8, shutter_s=1 / 125, iso=100.0)
    base = exposure_scale(**settings)
    assert exposure_scale(**{**settings, **change}) == pytest.approx(base * factor, rel=1e-12)
    assert ev100(**{**settings, **change}) == pytest.approx(ev100(**settings) - math.log2(factor))


def test_third_stops():
    assert nearest_third_stop_shutter(1 / 120) == pytest.approx(2 ** (-7))  # 1/128: a camera's "1/125"
    assert nearest_third_stop_shutter(1 / 100) == pytest.approx(2 ** (-20 / 3))  # a camera's "1/100"
    assert 3 * math.log2(nearest_third_stop_shutter(0.0173)) == pytest.approx(round(3 * math.log2(0.0173)))


def test_the_average_is_centre_weighted_and_the_spot_reads_its_disk():
    image = np.full((90, 120), 10.0)
    image[:, :10] = 1000.0  # a bright strip at the edge
    average = meter_luminance(image)
    assert 10.0 < average < image.mean()  # the edge counts, but less than its share of the frame
    assert meter_luminance(image, "spot") == pytest.approx(10.0)
    assert meter_luminance(image, "spot", spot=(2 / 120, 0.5)) == pytest.approx(1000.0)
    with pytest.raises(ValueError, match="matrix"):
        meter_luminance(image, "matrix")


def test_auto_exposure_puts_the_reading_at_middle_grey_with_the_aperture_kept():
    luminance = np.full((30, 40), 250.0)
    exposure = camera_exposure("auto", 5.6, 1 / 60, 200, luminance=luminance)
    assert exposure.metered_cd_m2 == pytest.approx(250.0)
    assert exposure.scale * 250.0 == pytest.approx(MIDDLE_GREY)
    assert exposure.ev100 == pytest.approx(metered_ev100(250.0))
    assert exposure.shutter_s == pytest.approx(shutter_for(metered_ev100(250.0), 5.6, 200))
    # An aperture passing half the round stop's light: the meter sees half, the shutter doubles, grey stays grey.
    half = camera_exposure("auto", 5.6, 1 / 60, 200, light_fraction=0.5, luminance=luminance)
    assert half.shutter_s == pytest.approx(2 * exposure.shutter_s)
    assert half.scale * 250.0 == pytest.approx(MIDDLE_GREY)
    # Nothing to meter: the camera's own shutter stays.
    dark = camera_exposure("auto", 5.6, 1 / 60, 200, luminance=np.zeros((4, 4)))
    assert dark.shutter_s == pytest.approx(1 / 60)
    assert camera_exposure("compensated", 5.6, 1 / 60, 200).scale == 1.0


@pytest.mark.gl
def test_an_auto_exposed_file_says_what_the_meter_chose(renderer, tmp_path, capsys):
    """The Cornell box in auto: the written EXR's centre-weighted luminance is middle grey, and its metadata holds
    the chosen shutter, its EV100 and the reading."""
    from lenslab.colour_management.working_space import luminance

    out = tmp_path / "auto.exr"
    result = run_cli(capsys, "cornell_box", "--headless", "-o", out, "--spp", "4", "--width", "32", "--height", "32",
                     "--exposure-mode", "auto", "--f-number", "4", "--iso", "200")
    assert result.status == 0, result.err
    pixels, metadata = read_image(out)
    assert meter_luminance(luminance(pixels)) == pytest.approx(MIDDLE_GREY, rel=1e-4)
    reading = float(metadata["lenslab:MeteredLuminance"])
    assert float(metadata["ExposureTime"]) == pytest.approx(shutter_for(metered_ev100(reading), 4.0, 200), rel=1e-5)
    assert float(metadata["lenslab:EV100"]) == pytest.approx(metered_ev100(reading), abs=1e-5)
    assert metadata["Exif:ExposureProgram"] == 3 and metadata["lenslab:ExposureMode"] == "auto"


def test_a_reading_taken_already_is_the_same_as_metering_the_image():
    image = np.full((20, 30), 75.0)
    assert camera_exposure("auto", 2.8, 1 / 60, 100, reading=75.0) == camera_exposure("auto", 2.8, 1 / 60, 100,
                                                                                      luminance=image)
    with pytest.raises(ValueError, match="needs the image to meter"):
        camera_exposure("auto", 2.8, 1 / 60, 100)


def test_a_meter_behind_a_smaller_aperture_asks_for_a_longer_shutter():
    """Half the round stop's light (an aperture image, a cat's eye): the meter reads a stop less, and the shutter it
    suggests, in the auto mode and in the studio's meter alike, doubles."""
    assert metered_ev100(400.0, light_fraction=0.5) == pytest.approx(metered_ev100(400.0) - 1.0)
    full = camera_exposure("auto", 4.0, 1 / 60, 100, reading=400.0)
    half = camera_exposure("auto", 4.0, 1 / 60, 100, light_fraction=0.5, reading=400.0)
    assert half.shutter_s == pytest.approx(2 * full.shutter_s)
