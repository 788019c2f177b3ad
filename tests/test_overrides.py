"""Command-line overrides, applied the same way by the headless render, the studio and validation."""

from __future__ import annotations

import dataclasses

import pytest

from lenslab.scene.io.loader import open_scene
from lenslab.optics.lenses import find_lens
from lenslab.optics.stops import exact_f_number
from lenslab.scene.overrides import SceneOverrides
from lenslab.validate.runner import scene_path


def test_only_the_given_settings_change_and_the_scene_itself_does_not():
    scene = open_scene("cornell_box")
    before = (scene.camera.f_number, scene.camera.focal_length_mm, scene.render.spp, scene.render.clamp)
    changed = SceneOverrides(f_number=1.4, focus_distance=2.5, spp=7, clamp=5.0, sampler="independent").apply(scene)
    assert (changed.camera.f_number, changed.camera.focus_distance_m) == (exact_f_number(1.4), 2.5)  # f/1.4 as typed is the exact stop
    assert (changed.render.spp, changed.render.clamp, changed.render.sampler) == (7, 5.0, "independent")
    assert changed.camera.focal_length_mm == scene.camera.focal_length_mm
    assert (scene.camera.f_number, scene.camera.focal_length_mm, scene.render.spp, scene.render.clamp) == before


@pytest.mark.parametrize("given, expected", [({"width": 300}, (300, 200)), ({"height": 100}, (150, 100)),
                                             ({"width": 64, "height": 64}, (64, 64))])
def test_a_width_or_height_alone_keeps_the_scenes_aspect_ratio(given, expected):
    scene = open_scene("cornell_box")
    scene.camera.resolution = (600, 400)
    assert SceneOverrides(**given).apply(scene).camera.resolution == expected


def test_defines_reach_a_mitsuba_scenes_parameters():
    scene = SceneOverrides(defines={"res": "24", "spp": "3"}).open(scene_path("point_sun"))
    assert scene.camera.resolution == (24, 24) and scene.render.spp == 3


@pytest.mark.parametrize("bad", [{"f_number": 0.0}, {"focal_length": 0.0}, {"width": 0}, {"spp": 0},
                                 {"sampler": "halton"}, {"focus_distance": float("nan")}, {"clamp": -1.0}])
def test_nonsense_is_refused_by_name(bad):
    name = next(iter(bad))
    with pytest.raises(ValueError, match=name):
        SceneOverrides(**bad)


def test_a_lens_mounts_its_focal_length_aperture_range_and_iris():
    scene = open_scene("cornell_box")
    scene.camera.f_number = 1.2
    mounted = SceneOverrides(lens="85 mm f/1.4").apply(scene).camera
    assert (mounted.focal_length_mm, mounted.f_number, mounted.aperture_blades) == (85.0, exact_f_number(1.4), 11)  # f/1.2 clamped
    zoom = SceneOverrides(lens="70-200mm-f2.8", focal_length=135, f_number=4).apply(scene).camera
    assert (zoom.focal_length_mm, zoom.f_number) == (135.0, 4.0)
    nearest = SceneOverrides(lens="70-200 mm f/2.8").apply(scene).camera
    assert nearest.focal_length_mm == 70.0  # the zoom's nearest length to the scene's own 50 mm


@pytest.mark.parametrize("bad, message", [
    ({"lens": "400mm"}, "no lens preset called '400mm' (there are: 10 mm f/4 fisheye, 14 mm f/2.8, "),
    ({"lens": "85mm f1.4", "f_number": 1.2}, "f/1.2 is not on the lens '85 mm f/1.4'"),
    ({"lens": "24-70 mm f/2.8", "focal_length": 85}, "focal_length 85 mm is not on the lens '24-70 mm f/2.8'"),
])
def test_a_setting_the_lens_does_not_have_is_refused(bad, message):
    with pytest.raises(ValueError) as caught:
        SceneOverrides(**bad)
    assert message in str(caught.value)


# -- every camera control ------------------------------------------------------------------------------------
def test_every_camera_control_reaches_the_camera(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    changed = SceneOverrides(sensor="aps-c", sensor_fit="fill", focus_from="lens", focus_breathing=False,
                             circle_of_confusion=0.02, aperture_blades=6, blade_curvature=0.5,
                             anamorphic_squeeze=1.5, barrel_clipping=0.3, aperture_image="star.png",
                             exposure_mode="physical", iso=800.0, shutter=1 / 30).apply(open_scene("cornell_box"))
    camera = changed.camera
    assert camera.sensor_mm == (23.5, 15.6) and camera.sensor_fit == "fill"
    assert (camera.focus_from, camera.focus_breathing, camera.circle_of_confusion_mm) == ("lens", False, 0.02)
    assert (camera.aperture_blades, camera.blade_curvature, camera.anamorphic_squeeze) == (6, 0.5, 1.5)
    assert camera.barrel_clipping == 0.3
    assert camera.aperture_image == str(tmp_path / "star.png")  # the working folder's, made absolute
    assert (camera.exposure_mode, camera.iso, camera.shutter_s) == ("physical", 800.0, 1 / 30)


@pytest.mark.parametrize("given, mode", [({"iso": 400.0}, "physical"), ({"shutter": 0.5}, "physical"),
                                         ({"iso": 400.0, "exposure_mode": "compensated"}, "compensated"),
                                         ({}, "compensated")])
def test_an_iso_or_a_shutter_means_a_physical_exposure(given, mode):
    scene = open_scene("cornell_box")
    scene.camera.exposure_mode = "compensated"  # as a scene in arbitrary units is (the shipped ones are physical)
    assert SceneOverrides(**given).apply(scene).camera.exposure_mode == mode


def test_a_sensor_brings_its_own_circle_of_confusion_or_the_diagonal_rule(tmp_path, monkeypatch):
    scene = open_scene("cornell_box")
    scene.camera.circle_of_confusion_mm = 0.03  # the old sensor's: not the new one's
    assert SceneOverrides(sensor="Micro Four Thirds").apply(scene).camera.circle_of_confusion_mm is None
    assert SceneOverrides(sensor="APS-C", circle_of_confusion=0.015).apply(scene).camera.circle_of_confusion_mm \
        == 0.015  # given with it: the one given
    user = tmp_path / "config" / "lenslab" / "presets"
    user.mkdir(parents=True)
    (user / "sensors.json").write_text('{"sensors": [{"name": "Super 35 (cinema)", "width_mm": 24.89, '
                                       '"height_mm": 18.66, "circle_of_confusion_mm": 0.025}]}')
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    camera = SceneOverrides(sensor="super 35 (cinema)").apply(scene).camera
    assert (camera.sensor_mm, camera.circle_of_confusion_mm) == ((24.89, 18.66), 0.025)


def test_a_lens_mounts_its_blade_roundness_as_curvature():
    camera = SceneOverrides(lens="85 mm f/1.4").apply(open_scene("cornell_box")).camera
    assert (camera.aperture_blades, camera.blade_curvature) == (11, 0.8)
    straight = SceneOverrides(lens="85 mm f/1.4", blade_curvature=0.0).apply(open_scene("cornell_box")).camera
    assert straight.blade_curvature == 0.0  # given with the lens: the one given


def _focused(**given):
    scene = open_scene("cornell_box")
    return SceneOverrides(**given).apply(scene).camera


def test_a_lens_focuses_no_nearer_than_its_minimum_from_the_sensor():
    assert _focused(lens="85mm f/1.4", focus_distance=0.8).focus_distance_m == 0.8  # the minimum itself
    with pytest.raises(ValueError) as caught:
        _focused(lens="85mm f/1.4", focus_distance=0.79)
    assert str(caught.value) == ("--focus-distance 0.79 m from the sensor is nearer than the 85 mm f/1.4 lens's "
                                 "minimum focus of 0.8 m from the sensor")
    with pytest.raises(ValueError, match="minimum focus of 0.8 m"):  # holding the framing does not move the sensor mark
        _focused(lens="85mm f/1.4", focus_distance=0.79, focus_breathing=False)


def test_a_focus_measured_from_the_lens_is_compared_from_the_sensor():
    # 0.72 m ahead of an 85 mm lens: the sensor is 96.4 mm behind it, 81.6 cm from the plane of focus.
    assert _focused(lens="85mm f/1.4", focus_from="lens", focus_distance=0.72).focus_distance_m == 0.72
    for breathing in (True, False):
        with pytest.raises(ValueError) as caught:
            _focused(lens="85mm f/1.4", focus_from="lens", focus_distance=0.6, focus_breathing=breathing)
        assert str(caught.value) == ("--focus-distance 0.6 m from the lens is nearer than the 85 mm f/1.4 lens's "
                                     "minimum focus of 0.8 m from the sensor (the plane of focus 0.7033 m from "
                                     "the lens)")


def test_nothing_nearer_than_the_thin_lens_can_focus():
    with pytest.raises(ValueError, match=r"nearer than any 200 mm lens can focus: at least 0\.8 m"):
        _focused(focal_length=200.0, focus_distance=0.5)
    with pytest.raises(ValueError, match="nearer than any 50 mm lens can focus"):
        _focused(focal_length=50.0, focus_from="lens", focus_distance=0.04)
    with pytest.raises(ValueError, match="minimum focus of 0.4 m"):  # a lens's marked minimum says more
        _focused(lens="50mm f/1.2", focus_from="lens", focus_distance=0.04)


@pytest.mark.parametrize("bad, message", [
    ({"sensor": "super 8"}, "no sensor preset called 'super 8'"),
    ({"sensor_fit": "stretch"}, "sensor_fit 'stretch' is not one of auto, horizontal"),
    ({"focus_from": "film"}, "focus_from 'film' is not one of sensor, lens"),
    ({"exposure_mode": "manual"}, "exposure_mode 'manual' is not one of compensated, physical, auto"),
    ({"circle_of_confusion": 2.0}, "circle_of_confusion 2 is out of range"),
    ({"aperture_blades": 2}, "aperture_blades 2: a stop has 0 blades (round) or at least 3"),
    ({"aperture_blades": 40}, "aperture_blades 40 is out of range [0, 32]"),
    ({"blade_curvature": 1.5}, "blade_curvature 1.5 is out of range [0, 1]"),
    ({"anamorphic_squeeze": 0.1}, "anamorphic_squeeze 0.1 is out of range [0.25, 4]"),
    ({"barrel_clipping": -0.5}, "barrel_clipping -0.5 is out of range [0, 1]"),
    ({"iso": 0.0}, "iso 0 is out of range"),
    ({"shutter": 1e5}, "shutter 100000 is out of range"),
])
def test_nonsense_camera_controls_are_refused_by_name(bad, message):
    with pytest.raises(ValueError) as caught:
        SceneOverrides(**bad)
    assert message in str(caught.value)


def test_focus_from_the_lens_meets_the_same_limits_as_focus_from_the_sensor():
    """Both readings of one lens stop at the same plane of focus: life size for the thin lens (a sensor 550 mm behind
    a 50 mm lens focused at 55 mm was accepted from the lens and refused from the sensor), and the lens's marked
    minimum."""
    from lenslab.optics.thinlens import sensor_distance_m

    for given in (dict(lens="50mm f/1.2", focus_distance=0.055), dict(focal_length=100.0, focus_distance=0.101)):
        with pytest.raises(ValueError, match=r"^--focus-distance 0\.\d+ m from the lens is nearer than"):
            _focused(focus_from="lens", **given)
    for given in (dict(focal_length=100.0), dict(lens="50mm f/1.2")):
        from_lens = _focused(focus_from="lens", focus_distance=1.0, **given)
        from_sensor = _focused(focus_from="sensor", focus_distance=1.0, **given)
        lens = find_lens(given["lens"]) if "lens" in given else None
        nearest_from_lens = from_lens.closest_focus_with(lens)
        nearest_from_sensor = from_sensor.closest_focus_with(lens)
        # The same plane: the nearest lens reading, read from the sensor, is the nearest sensor reading.
        assert sensor_distance_m(from_lens.focal_length_mm, nearest_from_lens) == pytest.approx(nearest_from_sensor)
        _focused(focus_from="lens", focus_distance=nearest_from_lens * 1.0001, **given)
        with pytest.raises(ValueError):
            _focused(focus_from="lens", focus_distance=nearest_from_lens * 0.999, **given)


def test_a_scene_value_is_named_as_the_scene_holds_it_and_an_option_by_its_flag():
    scene = open_scene("cornell_box")
    near = dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, focus_distance_m=0.5))
    with pytest.raises(ValueError, match=r"^the scene's focus distance 0\.5 m from the sensor is nearer than the "
                                         r"85 mm f/1\.4 lens's minimum focus of 0\.8 m"):
        SceneOverrides(lens="85mm f/1.4").apply(near)
    with pytest.raises(ValueError, match=r"^--focus-distance 0\.5 m from the sensor"):
        SceneOverrides(lens="85mm f/1.4", focus_distance=0.5).apply(scene)
