"""Command-line overrides, applied the same way by the headless render, the studio and validation."""

from __future__ import annotations

import pytest

from lenslab.scene.io.loader import open_scene
from lenslab.optics.stops import exact_f_number
from lenslab.scene.overrides import SceneOverrides
from lenslab.validate.runner import scene_path


def test_only_the_given_settings_change_and_the_scene_itself_does_not():
    scene = open_scene("cornell_box")
    before = (scene.camera.f_number, scene.camera.focal_length_mm, scene.render.spp, scene.render.clamp)
    changed = SceneOverrides(f_number=1.4, focus_distance_m=2.5, spp=7, clamp=5.0, sampler="independent").apply(scene)
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


@pytest.mark.parametrize("bad", [{"f_number": 0.2}, {"focal_length_mm": 5000.0}, {"width": 0}, {"spp": 0},
                                 {"sampler": "halton"}, {"focus_distance_m": float("nan")}, {"clamp": -1.0}])
def test_nonsense_is_refused_by_name(bad):
    name = next(iter(bad))
    with pytest.raises(ValueError, match=name):
        SceneOverrides(**bad)


def test_a_lens_mounts_its_focal_length_aperture_range_and_iris():
    scene = open_scene("cornell_box")
    scene.camera.f_number = 1.2
    mounted = SceneOverrides(lens="85 mm f/1.4").apply(scene).camera
    assert (mounted.focal_length_mm, mounted.f_number, mounted.aperture_blades) == (85.0, exact_f_number(1.4), 11)  # f/1.2 clamped
    zoom = SceneOverrides(lens="70-200mm-f2.8", focal_length_mm=135, f_number=4).apply(scene).camera
    assert (zoom.focal_length_mm, zoom.f_number) == (135.0, 4.0)
    nearest = SceneOverrides(lens="70-200 mm f/2.8").apply(scene).camera
    assert nearest.focal_length_mm == 70.0  # the zoom's nearest length to the scene's own 50 mm


@pytest.mark.parametrize("bad, message", [
    ({"lens": "400mm"}, "no lens preset called '400mm' (there are: 14 mm f/2.8, "),
    ({"lens": "85mm f1.4", "f_number": 1.2}, "f/1.2 is not on the lens '85 mm f/1.4'"),
    ({"lens": "24-70 mm f/2.8", "focal_length_mm": 85}, "focal_length 85 mm is not on the lens '24-70 mm f/2.8'"),
])
def test_a_setting_the_lens_does_not_have_is_refused(bad, message):
    with pytest.raises(ValueError) as caught:
        SceneOverrides(**bad)
    assert message in str(caught.value)
