"""Photometric light units (scene/light_units.py; docs/colour.md, "Light units"): each conversion against its
closed form, the native format keeping the unit, legacy and Mitsuba scenes keeping their numbers, and a sunlit
grey card exposed by sunny 16 and by a light meter."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lenslab.colour_management.working_space import luminance
from lenslab.optics.exposure import ev100, exposure_scale, meter_luminance, metered_ev100, shutter_for
from lenslab.render import buffers
from lenslab.render.film import read_image, write_image
from lenslab.render.gpu_layout import LIGHT_ROWS
from lenslab.render.job import RenderJob
from lenslab.scene import light_units
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.io.mitsuba_xml import load_mitsuba_string
from lenslab.scene.io.native import load_scene, save_scene
from lenslab.scene.lights import PointLight, SpotLight, SunLight
from lenslab.scene.materials import Blend, Diffuse, Emissive
from lenslab.scene.scene import ConstantEnvironment, EnvironmentMap, Node, RenderSettings, Scene, SceneError
from lenslab.scene.shapes import Rectangle, Sphere
from lenslab.scene.transform import Transform

WARM = (1361.0, 961.0, 320.0)  # a warm white of luminance ~1000


def lit(material: Emissive, *nodes: Node) -> Scene:
    return Scene(materials={"light": material}, nodes=list(nodes))


def flat_light(scene: Scene) -> Emissive:
    flat = scene.flatten()
    return flat.materials[flat.material_names.index("light")]


def lum(rgb, space: str = "lin_rec709") -> float:
    return float(luminance(rgb, space))


# -- area lights ----------------------------------------------------------------------------------------------
def test_lumens_on_a_quad_spread_over_its_world_area():
    # 1 m x 0.5 m, scaled to 2 m x 0.5 m by its node: 1 m^2, so 1000 lm is 1000 / pi nits.
    quad = Node("panel", Transform(scale=(2.0, 1.0, 1.0)), Rectangle((1.0, 0.5)), "light")
    given = Emissive(WARM, unit="lumens")
    light = flat_light(lit(given, quad))
    assert light.unit == "nits" and lum(light.radiance) == pytest.approx(lum(WARM) / math.pi, rel=1e-6)
    assert np.allclose(np.array(light.radiance) / np.array(WARM), 1.0 / math.pi)  # the colour as given
    assert given.unit == "lumens" and given.radiance == WARM  # the scene's own material is left as it was


def test_lumens_on_a_sphere_and_on_every_shape_carrying_the_material():
    ball = Node("bulb", Transform(scale=(2.0, 2.0, 2.0)), Sphere(0.5), "light")  # radius 1: 4 pi m^2
    light = flat_light(lit(Emissive((1000.0,) * 3, unit="lumens"), ball))
    assert light.radiance[0] == pytest.approx(1000.0 / (math.pi * 4.0 * math.pi), rel=1e-6)
    # Two quads of 1 m^2 carry one material: the flux is shared over 2 m^2.
    quads = [Node(f"q{i}", Transform(translate=(3.0 * i, 0.0, 0.0)), Rectangle((1.0, 1.0)), "light") for i in (0, 1)]
    light = flat_light(lit(Emissive((1000.0,) * 3, unit="lumens"), *quads))
    assert light.radiance[0] == pytest.approx(1000.0 / (2.0 * math.pi), rel=1e-6)


def test_a_two_sided_light_in_lumens_has_half_the_radiance():
    quad = Node("panel", shape=Rectangle((1.0, 1.0)), material="light")
    one = flat_light(lit(Emissive((1000.0,) * 3, unit="lumens"), quad)).radiance[0]
    two = flat_light(lit(Emissive((1000.0,) * 3, unit="lumens", two_sided=True), quad)).radiance[0]
    assert two == pytest.approx(one / 2.0, rel=1e-9) and one == pytest.approx(1000.0 / math.pi, rel=1e-6)


def test_a_light_held_by_another_material_is_converted_too():
    held = Blend(first=Emissive((1000.0,) * 3, unit="lumens"), second=Diffuse((0.5,) * 3), weight=0.5)
    scene = Scene(materials={"light": held}, nodes=[Node("panel", shape=Rectangle((1.0, 1.0)), material="light")])
    inner = flat_light(scene).first
    assert inner.unit == "nits" and inner.radiance[0] == pytest.approx(1000.0 / math.pi, rel=1e-6)


def test_nits_and_legacy_scenes_are_left_as_they_are():
    quad = Node("panel", shape=Rectangle((1.0, 1.0)), material="light")
    given = Emissive((17.0, 12.0, 4.0))
    assert given.unit == "nits" and flat_light(lit(given, quad)) is given  # not even copied


def test_an_unknown_unit_in_a_scene_made_in_code_names_the_material():
    quad = Node("panel", shape=Rectangle((1.0, 1.0)), material="light")
    with pytest.raises(SceneError, match="material 'light': emissive: unknown unit 'watts'"):
        lit(Emissive(unit="watts"), quad).flatten()


# -- point and spot lights --------------------------------------------------------------------------------------
def test_a_point_light_of_4_pi_lumens_is_one_candela():
    light = light_units.light_in_candela(PointLight("bulb", intensity=(4 * math.pi,) * 3, unit="lumens"))
    assert light.unit == "candela" and light.intensity == pytest.approx((1.0, 1.0, 1.0))
    legacy = PointLight("bulb", intensity=(5.0, 6.0, 7.0))
    assert light_units.light_in_candela(legacy) is legacy


def test_a_spot_in_lumens_sends_all_of_it_through_its_cone():
    spot = SpotLight("spot", intensity=(800.0, 700.0, 600.0), unit="lumens", cutoff_angle_deg=30.0,
                     beam_width_deg=10.0)
    converted = light_units.light_in_candela(spot)
    solid_angle = 2 * math.pi * (1 - (math.sin(math.radians(30)) - math.sin(math.radians(10))) / math.radians(20))
    assert converted.intensity == pytest.approx(tuple(c / solid_angle for c in spot.intensity), rel=1e-9)
    narrow = light_units.light_in_candela(SpotLight("s", intensity=(800.0,) * 3, unit="lumens", cutoff_angle_deg=10.0,
                                                    beam_width_deg=10.0))
    assert narrow.intensity[0] == pytest.approx(800.0 / (2 * math.pi * (1 - math.cos(math.radians(10)))))


def test_the_packed_light_table_carries_candela():
    scene = Scene(nodes=[Node("floor", Transform(rotate_deg=(-90.0, 0.0, 0.0)), Rectangle((2.0, 2.0)))])
    lights = [PointLight("bulb", intensity=(4 * math.pi * 3,) * 3, unit="lumens"),
              SpotLight("spot", intensity=(2.0,) * 3)]
    packed = buffers.pack_scene(scene.flatten(), scene.environment, lights=lights)
    table = packed.arrays["lights"].reshape(-1, LIGHT_ROWS, 4)
    assert table[0, 2, :3] == pytest.approx((3.0, 3.0, 3.0), rel=1e-6)  # the point light's intensity, in cd
    assert table[1, 2, :3] == pytest.approx((2.0, 2.0, 2.0))
    assert lights[0].unit == "lumens"  # the scene's own light is left as it was


# -- the sky ----------------------------------------------------------------------------------------------------------
def test_ev_is_hdrps_luminance():
    assert light_units.ev100_to_luminance(0.0) == 0.125  # 2^(EV - 3)
    assert light_units.ev100_to_luminance(15.0) == 4096.0
    assert metered_ev100(light_units.ev100_to_luminance(11.3)) == pytest.approx(11.3)  # the meter reads it back


@pytest.mark.parametrize("space", ["lin_rec709", "acescg"])
def test_a_sky_given_as_an_ev_keeps_its_colour(space):
    colour = np.array([0.6, 0.8, 1.2])
    rgb = tuple(colour * 12.0 / lum(colour, space))  # EV 12 of a blue
    sky = light_units.environment_in_nits(ConstantEnvironment(rgb, unit="ev"), space)
    assert sky.unit == "nits" and lum(sky.radiance, space) == pytest.approx(0.125 * 2**12, rel=1e-9)
    assert np.allclose(np.array(sky.radiance) / colour, sky.radiance[0] / colour[0])
    assert light_units.environment_in_nits(ConstantEnvironment((0.0,) * 3, unit="ev")).radiance == (0.0,) * 3


def write_map(path, rows: list[float], width: int = 8):
    pixels = np.repeat(np.array(rows, np.float32)[:, None, None], width, axis=1).repeat(3, axis=2)
    write_image(path, np.ascontiguousarray(pixels))
    return path


def test_the_mean_luminance_over_the_sphere_weighs_each_row_by_its_solid_angle():
    upper_lower = np.array([3.0, 1.0])[:, None, None] * np.ones((2, 4, 3))
    assert light_units.sphere_mean_luminance(upper_lower) == pytest.approx(2.0)  # each half is half the sphere
    # Pole to pole, three rows: the poles' rows cover 1 - cos 45 deg each of the 2 (cos 0 - cos 180) of the sphere.
    poles_and_equator = np.array([5.0, 1.0, 5.0])[:, None, None] * np.ones((3, 4, 3))
    pole = 1 - math.cos(math.pi / 4)
    assert light_units.sphere_mean_luminance(poles_and_equator, "pole_to_pole") == pytest.approx(
        (5.0 * 2 * pole + 1.0 * (2 - 2 * pole)) / 2)
    rows = np.linspace(0.5, 4.0, 64)[:, None, None] * np.ones((64, 8, 3))  # many rows: the integral of sin
    theta = math.pi * (np.arange(64) + 0.5) / 64
    assert light_units.sphere_mean_luminance(rows) == pytest.approx(
        float((np.linspace(0.5, 4.0, 64) * np.sin(theta)).sum() / np.sin(theta).sum()), rel=1e-3)


@pytest.mark.parametrize("unit, strength, mean", [("scale", 2.5, 2.5 * 2.0), ("nits", 50.0, 50.0),
                                                  ("ev", 10.0, 128.0), ("ev", -3.0, 0.125 / 8)])
def test_an_environment_map_in_nits_or_ev_has_that_mean_luminance(tmp_path, unit, strength, mean):
    write_map(tmp_path / "sky.exr", [3.0, 1.0])  # mean luminance 2 as written
    environment = EnvironmentMap(file="sky.exr", strength=strength, unit=unit)
    scene = Scene(environment=environment, nodes=[Node("ball", shape=Sphere(0.5))])
    packed = buffers.pack_scene(scene.flatten(), environment, base_dir=tmp_path)
    assert packed.uniforms["env_strength"] * 2.0 == pytest.approx(mean, rel=1e-5)


def test_only_an_ev_may_be_negative(tmp_path):
    write_map(tmp_path / "sky.exr", [1.0, 1.0])
    for unit in ("scale", "nits"):
        path = tmp_path / f"{unit}.json"
        path.write_text(json.dumps({"lenslab_scene": 4, "environment": {"type": "map", "file": "sky.exr",
                                                                        "strength": -2, "unit": unit}}))
        with pytest.raises(SceneError, match=rf"{unit}.json: environment.strength: .*negative: only an EV"):
            load_scene(path)
    path.write_text(json.dumps({"lenslab_scene": 4, "environment": {"type": "map", "file": "sky.exr",
                                                                    "strength": -2, "unit": "ev"}}))
    assert load_scene(path).environment.strength == -2.0


# -- the native format and the importers -----------------------------------------------------------------------
def photometric_scene() -> Scene:
    return Scene(
        environment=ConstantEnvironment((9.0, 10.0, 12.0), unit="ev"),
        materials={"light": Emissive(WARM, unit="lumens", two_sided=True)},
        nodes=[Node("panel", shape=Rectangle((1.0, 1.0)), material="light")],
        lights=[PointLight("bulb", intensity=(800.0,) * 3, unit="lumens"),
                SpotLight("spot", intensity=(1200.0,) * 3, unit="lumens"), SunLight("sun", irradiance=(1e5,) * 3)])


def test_the_native_format_keeps_every_unit(tmp_path):
    scene = photometric_scene()
    save_scene(scene, tmp_path / "scene.json")
    written = json.loads((tmp_path / "scene.json").read_text())
    assert written["materials"]["light"]["unit"] == "lumens" and written["environment"]["unit"] == "ev"
    assert [light.get("unit") for light in written["lights"]] == ["lumens", "lumens", None]  # a sun is in lux
    again = load_scene(tmp_path / "scene.json")
    again.source_path = None
    assert again == scene
    sky = EnvironmentMap(file="sky.exr", strength=120.0, unit="nits")
    write_map(tmp_path / "sky.exr", [1.0, 1.0])
    save_scene(Scene(environment=sky), tmp_path / "map.json")
    assert load_scene(tmp_path / "map.json").environment == sky


@pytest.mark.parametrize("where, key, field, value", [("materials", "light", "materials.light.unit", "watts"),
                                                      ("environment", None, "environment.unit", "lux"),
                                                      ("lights", 0, "lights[0].unit", "lux")])
def test_an_unknown_unit_is_refused_naming_the_file_and_the_field(tmp_path, where, key, field, value):
    save_scene(photometric_scene(), tmp_path / "scene.json")
    data = json.loads((tmp_path / "scene.json").read_text())
    (data[where][key] if key is not None else data[where])["unit"] = value
    (tmp_path / "bad.json").write_text(json.dumps(data))
    with pytest.raises(SceneError) as caught:
        load_scene(tmp_path / "bad.json")
    message = str(caught.value)
    assert message.startswith(str(tmp_path / "bad.json")) and f"{field}: '{value}' is not one of" in message


def test_a_mitsuba_scene_keeps_its_radiance_as_it_is(tmp_path):
    scene = load_mitsuba_string(
        '<scene version="3.0.0"><emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>'
        '<emitter type="point"><rgb name="intensity" value="5"/></emitter>'
        '<emitter type="spot"><rgb name="intensity" value="7"/></emitter>'
        '<shape type="rectangle"><emitter type="area"><rgb name="radiance" value="10"/></emitter></shape></scene>',
        base_dir=tmp_path)
    (light,) = [m for m in scene.materials.values() if isinstance(m, Emissive)]
    assert (light.unit, light.radiance) == ("nits", (10.0, 10.0, 10.0))
    assert [(light.unit, light.intensity) for light in scene.lights] == [("candela", (5.0,) * 3),
                                                                         ("candela", (7.0,) * 3)]
    assert (scene.environment.unit, scene.environment.radiance) == ("nits", (0.5, 0.5, 0.5))
    assert any(material is light for material in scene.flatten().materials)  # not converted: it is in nits


# -- a camera's exposure: stop arithmetic, sunny 16 and the meter -----------------------------------------------
def test_each_stop_of_aperture_shutter_or_iso_is_a_factor_of_two():
    base = exposure_scale(8.0, 1 / 125, 100.0)
    assert base == pytest.approx(0.18 * (1 / 125) * 100 / (12.5 * 64))  # 0.18 t S / (K N^2), K = 12.5
    assert exposure_scale(8.0 * math.sqrt(2), 1 / 125, 100.0) == pytest.approx(base / 2)
    assert exposure_scale(8.0, 2 / 125, 100.0) == pytest.approx(base * 2)
    assert exposure_scale(8.0, 1 / 125, 200.0) == pytest.approx(base * 2)
    assert ev100(8.0 * math.sqrt(2), 1 / 125, 100.0) - ev100(8.0, 1 / 125, 100.0) == pytest.approx(1.0)
    camera = ThinLensCamera(f_number=8.0, shutter_s=1 / 125, iso=100.0, exposure_mode="physical")
    assert camera.exposure_scale() == pytest.approx(base)
    camera.exposure_mode = "compensated"
    assert camera.exposure_scale() == 1.0


SUN_LUX = 100_000.0
SKY_NITS = 3000.0
CARD = 0.18


def sunlit_card(**camera) -> Scene:
    """An 18% grey card facing up under a sun of 100,000 lux at 45 degrees (70,700 lux on the card) and a blue sky
    of 3000 cd/m^2, filling the frame of a camera looking down at it from the sun's side."""
    sky = np.array([0.55, 0.7, 1.0])
    return Scene(
        camera=ThinLensCamera(position=(0.0, 1.5, 1.5), look_at=(0.0, 0.0, 0.0), focal_length_mm=100.0,
                              focus_distance_m=2.2, resolution=(24, 16), **camera),
        environment=ConstantEnvironment(tuple(sky * SKY_NITS / lum(sky))),
        render=RenderSettings(max_depth=2, spp=64),
        materials={"card": Diffuse((CARD,) * 3)},
        nodes=[Node("card", Transform(rotate_deg=(-90.0, 0.0, 0.0)), Rectangle((3.0, 3.0)), "card")],
        lights=[SunLight("sun", direction=(0.5, math.sqrt(0.5), 0.5), irradiance=(SUN_LUX,) * 3)])


def rendered(renderer, scene: Scene, path) -> np.ndarray:
    """The image as written (the physical exposure applied as a file gets it), as luminance."""
    job = RenderJob(renderer, scene)
    job.run()
    written = job.write(path)
    job.release()
    pixels, _ = read_image(written)
    return luminance(pixels[..., :3])


@pytest.mark.gl
def test_sunny_16_and_a_spot_meter_put_a_sunlit_grey_card_at_middle_grey(renderer, tmp_path):
    card_nits = CARD / math.pi * (SUN_LUX * math.sqrt(0.5) + math.pi * SKY_NITS)
    scene_linear = rendered(renderer, sunlit_card(exposure_mode="compensated"), tmp_path / "linear.exr")
    assert scene_linear.mean() == pytest.approx(card_nits, rel=0.03)  # the card's luminance, in cd/m^2
    # Sunny 16: f/16 at 1/ISO s in sunlight.
    sunny = rendered(renderer, sunlit_card(exposure_mode="physical", f_number=16.0, shutter_s=1 / 100, iso=100.0),
                     tmp_path / "sunny16.exr")
    assert abs(math.log2(sunny.mean() / 0.18)) < 1.0
    # A spot meter reads the card; the camera set as it suggests puts the card at middle grey.
    reading = meter_luminance(scene_linear, "spot")
    shutter = shutter_for(metered_ev100(reading), 16.0, 100.0)
    metered = rendered(renderer, sunlit_card(exposure_mode="physical", f_number=16.0, shutter_s=shutter, iso=100.0),
                       tmp_path / "metered.exr")
    assert metered.mean() == pytest.approx(0.18, rel=0.04)


@pytest.mark.gl
def test_an_environment_map_in_nits_is_seen_at_that_luminance(renderer, tmp_path):
    write_map(tmp_path / "sky.exr", [0.5, 0.5])
    scene = Scene(camera=ThinLensCamera(position=(0.0, 0.0, 0.0), look_at=(0.0, 0.3, -1.0), resolution=(8, 6),
                                        pinhole=True),
                  environment=EnvironmentMap(file=str(tmp_path / "sky.exr"), strength=40.0, unit="nits"),
                  render=RenderSettings(max_depth=1, spp=1))
    assert rendered(renderer, scene, tmp_path / "sky_seen.exr") == pytest.approx(40.0, rel=1e-4)
