"""A scene renders as it is written: the importers, the scene file, the command line and batch files keep every
value the renderer can draw (any aperture, field of view, filter width), and refuse, naming the file, only what it
cannot. What the studio's controls offer (f/0.5 to f/128, 1 to 2000 mm, 0.05 to 4 px) is a range of its own that
limits the controls, never a scene (scene/fields.py: "range" and "controls")."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import pytest

from lenslab.optics import format_f_number, parse_f_number, step_stop
from lenslab.optics.stops import F_NUMBER_CONTROL_RANGE, F_NUMBER_RANGE, is_offered_f_number, is_valid_f_number
from lenslab.optics.thinlens import FOCAL_LENGTH_CONTROL_RANGE_MM, FOCAL_LENGTH_RANGE_MM, field_of_view_x
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.fields import control_range, declared_range, range_holding
from lenslab.scene.io.mitsuba_xml import load_mitsuba_scene
from lenslab.scene.io.native import load_scene, save_scene
from lenslab.scene.options import OPTIONS
from lenslab.scene.scene import RenderSettings, Scene, SceneError

# Mitsuba's documentation scene sensor_thinlens (mitsuba-data docs/scenes/sensor_thinlens.xml), its sensor as written.
SENSOR_THINLENS = """<sensor type="thinlens">
    <string name="fov_axis" value="smaller"/>
    <float name="focus_distance" value="5.9"/>
    <float name="aperture_radius" value="{radius}"/>
    <float name="fov" value="28.8415"/>
    <transform name="to_world"><lookat target="3.04072, -2.85176, 2.80939" origin="3.69558, -3.46243, 3.25463"
        up="-0.317366, 0.312466, 0.895346"/></transform>
    <film type="hdrfilm"><integer name="width" value="960"/><integer name="height" value="720"/>
        <rfilter type="gaussian"/></film>
</sensor>"""


def mitsuba(tmp_path: Path, body: str):
    path = tmp_path / "scene.xml"
    path.write_text(f'<?xml version="1.0"?>\n<scene version="3.0.0">\n{body}\n<shape type="sphere"/>\n</scene>\n')
    warnings: list[str] = []
    return load_mitsuba_scene(path, warn=warnings.append), warnings


def sensor(kind="perspective", params="", film='<rfilter type="box"/>'):
    return (f'<sensor type="{kind}">{params}<transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" '
            f'up="0, 1, 0"/></transform><film type="hdrfilm"><integer name="width" value="64"/>'
            f'<integer name="height" value="48"/>{film}</film></sensor>')


# -- the importer -------------------------------------------------------------------------------------------------
def test_mitsubas_sensor_thinlens_keeps_its_f_0_13_lens_without_a_warning(tmp_path):
    scene, warnings = mitsuba(tmp_path, SENSOR_THINLENS.format(radius=0.2))
    cam = scene.camera
    assert warnings == []
    # fov 28.8415 degrees across the 720-pixel side: 37.8 degrees across, a 52.5 mm lens; r = f / 2N = 0.2 m
    assert cam.f_number == pytest.approx(0.1313, abs=1e-4) and cam.f_number < F_NUMBER_CONTROL_RANGE[0]
    assert cam.lens_radius == pytest.approx(0.2, rel=1e-12)  # the lens Mitsuba draws, to the last digit
    assert not cam.pinhole
    assert cam.frame().lens_radius == pytest.approx(0.2, rel=1e-12)  # what the GPU is given


def test_a_cornell_box_lens_of_7_cm_radius_is_kept(tmp_path):
    scene, warnings = mitsuba(tmp_path, sensor("thinlens", '<float name="fov" value="39.3"/>'
                                                          '<float name="aperture_radius" value="0.07"/>'
                                                          '<float name="focus_distance" value="3.9"/>'))
    assert warnings == []
    assert scene.camera.f_number == pytest.approx(0.36, abs=5e-3) and scene.camera.lens_radius == pytest.approx(0.07)


@pytest.mark.parametrize("fov", [179.0, 120.0, 0.5, 0.01])
def test_a_field_of_view_beyond_the_focal_lengths_the_studio_offers_is_kept(tmp_path, fov):
    scene, warnings = mitsuba(tmp_path, sensor(params=f'<float name="fov" value="{fov}"/>'))
    cam = scene.camera
    assert warnings == []
    assert math.degrees(cam.fov_x) == pytest.approx(fov, rel=1e-9)
    if fov != 120.0:  # 179 degrees is a 0.157 mm lens on 36 mm, 0.5 degrees a 4125 mm one
        low, high = FOCAL_LENGTH_CONTROL_RANGE_MM
        assert not low <= cam.focal_length_mm <= high


def test_a_field_of_view_of_180_degrees_or_a_negative_aperture_is_refused_naming_the_file(tmp_path):
    mitsuba(tmp_path, sensor(params='<float name="fov" value="179.99"/>'))  # just short of 180: rendered
    with pytest.raises(SceneError, match=r"scene\.xml: line \d+: .*field of view \(180 degrees\) must lie between"):
        mitsuba(tmp_path, sensor(params='<float name="fov" value="180"/>'))
    with pytest.raises(SceneError, match=r"scene\.xml: line \d+: <sensor type=\"thinlens\">: aperture_radius -0\.1 "
                                         r"is negative"):
        mitsuba(tmp_path, sensor("thinlens", '<float name="aperture_radius" value="-0.1"/>'))
    with pytest.raises(SceneError, match=r"scene\.xml: line \d+: .*not a finite number|scene\.xml: line \d+: .*finite"):
        mitsuba(tmp_path, sensor("thinlens", '<float name="aperture_radius" value="nan"/>'))


def test_a_lens_of_radius_zero_is_the_pinhole_it_is(tmp_path):
    scene, warnings = mitsuba(tmp_path, sensor("thinlens", '<float name="aperture_radius" value="0"/>'))
    assert warnings == [] and scene.camera.pinhole and scene.camera.lens_radius == 0.0


def test_apertures_beyond_what_float32_carries_are_the_nearest_it_does_with_a_warning(tmp_path):
    # f/20800: far past the studio's f/128, still a lens: kept as written.
    scene, warnings = mitsuba(tmp_path, sensor("thinlens", '<float name="aperture_radius" value="1e-6"/>'))
    assert warnings == [] and scene.camera.f_number == pytest.approx(scene.camera.focal_length_mm / 1e3 / 2e-6)
    # A lens 1e-10 m across is a pinhole to float32 beside a 42 mm focal length (f/2e8): drawn as one, said so.
    scene, warnings = mitsuba(tmp_path, sensor("thinlens", '<float name="aperture_radius" value="1e-10"/>'))
    assert scene.camera.pinhole and len(warnings) == 1 and "rendered as a pinhole" in warnings[0]


@pytest.mark.parametrize("stddev", [0.02, 0.05, 4.0, 8.0, 25.0])
def test_a_gaussian_filter_beyond_the_studios_0_05_to_4_pixels_is_kept(tmp_path, stddev):
    scene, warnings = mitsuba(tmp_path, sensor(film=f'<rfilter type="gaussian"><float name="stddev" '
                                                    f'value="{stddev}"/></rfilter>'))
    assert warnings == []
    assert (scene.render.pixel_filter, scene.render.filter_stddev) == ("gaussian", stddev)


def test_a_filter_the_film_cannot_draw_is_refused_or_the_nearest_it_can(tmp_path):
    with pytest.raises(SceneError, match=r"scene\.xml: line \d+: <rfilter type=\"gaussian\">: stddev 0 must be positive"):
        mitsuba(tmp_path, sensor(film='<rfilter type="gaussian"><float name="stddev" value="0"/></rfilter>'))
    scene, warnings = mitsuba(tmp_path, sensor(film='<rfilter type="gaussian"><float name="stddev" value="100"/>'
                                                    '</rfilter>'))
    assert scene.render.filter_stddev == declared_range(RenderSettings, "filter_stddev")[1] == 32.0
    assert len(warnings) == 1 and "32 used" in warnings[0]


# -- the native scene file --------------------------------------------------------------------------------------
def native(tmp_path: Path, **camera) -> Path:
    scene = Scene()
    scene.camera = dataclasses.replace(scene.camera, **camera)
    path = tmp_path / "shot.json"
    save_scene(scene, path)
    return path


def test_a_scene_file_at_f_0_2_with_a_half_millimetre_lens_loads_as_written(tmp_path):
    path = native(tmp_path, f_number=0.2, focal_length_mm=0.5, focus_from="lens", focus_breathing=False)
    cam = load_scene(path).camera
    assert (cam.f_number, cam.focal_length_mm) == (0.2, 0.5)
    save_scene(load_scene(path), tmp_path / "again.json")
    assert load_scene(tmp_path / "again.json").camera.f_number == 0.2


def test_a_render_settings_filter_beyond_the_studios_range_loads(tmp_path):
    scene = Scene()
    scene.render = dataclasses.replace(scene.render, pixel_filter="gaussian", filter_stddev=8.0)
    save_scene(scene, tmp_path / "wide.json")
    assert load_scene(tmp_path / "wide.json").render.filter_stddev == 8.0


@pytest.mark.parametrize("key, value, message", [
    ("f_number", 0, r"camera\.f_number: 0 is out of range \[1e-06, 1e\+06\]"),
    ("f_number", -2.8, r"camera\.f_number: -2\.8 is out of range"),
    ("focal_length_mm", 0, r"camera\.focal_length_mm: 0 is out of range \[0\.0001, 2\.5e\+08\]"),
])
def test_what_no_lens_can_be_is_refused_naming_the_file(tmp_path, key, value, message):
    path = native(tmp_path, f_number=0.2)  # f/0.2 is a lens (the file loads); f/0 is none
    load_scene(path)
    data = json.loads(path.read_text())
    data["camera"][key] = value
    path.write_text(json.dumps(data))
    with pytest.raises(SceneError, match=r"shot\.json: " + message):
        load_scene(path)
    path.write_text(path.read_text().replace(f'"{key}": {json.dumps(value)}', f'"{key}": NaN'))
    with pytest.raises(SceneError, match=r"shot\.json: camera\.\w+: nan is not a finite number"):
        load_scene(path)


# -- the command line and batch files: what the camera accepts -----------------------------------------------------
def test_the_command_line_and_batch_files_take_any_f_number_a_scene_may_hold():
    option = OPTIONS["f_number"]
    assert option.from_text("f/0.2") == 0.2  # typed as users type them: not refused for being past f/0.5
    assert option.from_text("0.13") == 0.13 and option.check(0.13) == 0.13  # a batch file's number
    assert option.from_text("f/11") == pytest.approx(2 ** 3.5)  # a mark is still its exact stop
    assert OPTIONS["focal_length"].check(0.5) == 0.5 and OPTIONS["focal_length"].check(5000.0) == 5000.0
    for text in ("f/0", "0,0"):
        with pytest.raises(ValueError, match="out of range"):
            option.from_text(text)
    assert parse_f_number("f/0.13") == 0.13


def test_a_batch_file_takes_any_f_number_a_scene_may_hold(tmp_path):
    from lenslab.batch.spec import read_batch

    path = tmp_path / "shots.toml"
    path.write_text('[[shots]]\nscene = "cornell_box"\noutput = "c_{index}.png"\nf_number = [0.13, 0.36, 2.8]\n')
    shots = read_batch(path).shots
    assert [s.overrides.f_number for s in shots] == [0.13, 0.36, 2 ** 1.5]  # a mark is its exact stop


# -- the two ranges -----------------------------------------------------------------------------------------------
def test_the_controls_offer_less_than_a_value_may_be():
    assert control_range(ThinLensCamera, "f_number") == F_NUMBER_CONTROL_RANGE == (0.5, 128)
    assert declared_range(ThinLensCamera, "f_number") == F_NUMBER_RANGE
    assert control_range(ThinLensCamera, "focal_length_mm") == FOCAL_LENGTH_CONTROL_RANGE_MM == (1, 2000)
    assert declared_range(ThinLensCamera, "focal_length_mm") == FOCAL_LENGTH_RANGE_MM
    assert control_range(RenderSettings, "filter_stddev") == (0.05, 4.0)
    assert control_range(ThinLensCamera, "iso") == declared_range(ThinLensCamera, "iso")  # where no control range
    assert is_valid_f_number(0.13) and not is_offered_f_number(0.13) and is_offered_f_number(0.5)
    assert not is_valid_f_number(0) and not is_valid_f_number(math.nan) and not is_valid_f_number(math.inf)
    assert range_holding(0.5, 128, 0.13) == (0.13, 128) and range_holding(0.5, 128, 8) == (0.5, 128)
    # Both ends of the value ranges still give a field of view strictly inside (0, 180) degrees, in float32 too.
    for mm in FOCAL_LENGTH_RANGE_MM:
        for sensor_mm in (1.0, 36.0, 500.0):
            assert 0.0 < math.degrees(field_of_view_x(mm, sensor_mm)) < 180.0
            assert 1e-12 < sensor_mm / (2 * mm) < 2 ** 24


def test_the_studios_words_for_an_aperture_past_its_stops():
    assert format_f_number(0.13) == "f/0.13" and format_f_number(0.0123) == "f/0.012"
    assert format_f_number(0.5) == "f/0.5" and format_f_number(2 ** 3.5) == "f/11"
    assert step_stop(0.13, 1) == pytest.approx(2 ** -0.5)  # one step narrower: onto the scale's widest stop
    assert step_stop(0.13, -1) == 0.13  # already wider than the scale: left as it is


# -- indices of refraction ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("int_ior, ext_ior", [(1.0, 1.333), (1.333, 1.0), (2.42, 1.0)])
def test_a_dielectrics_relative_index_is_kept_below_one_as_well_as_above(tmp_path, int_ior, ext_ior):
    """An air bubble in water (1.0 inside, 1.333 outside: 0.75) was clamped to 1.0001, a surface that bends nothing."""
    from lenslab.scene.materials import Dielectric

    scene, warnings = mitsuba(tmp_path, f'<shape type="sphere"><bsdf type="dielectric"><float name="int_ior" '
                                        f'value="{int_ior}"/><float name="ext_ior" value="{ext_ior}"/></bsdf></shape>')
    (glass,) = [m for m in scene.materials.values() if isinstance(m, Dielectric)]
    assert glass.ior == pytest.approx(int_ior / ext_ior, rel=1e-12)
    assert not [w for w in warnings if "index of refraction" in w]
