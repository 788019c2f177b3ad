"""Lights (point, sun, environment maps) and textures against closed-form answers."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from tests.helpers import render_to_spp
from tests.scenes import FIXED_SENSOR

from lenslab.render.film import write_image
from lenslab.render.tracer import RenderSession
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.lights import PointLight, SunLight
from lenslab.scene.materials import Diffuse
from lenslab.scene.scene import ConstantEnvironment, EnvironmentMap, Node, RenderSettings, Scene
from lenslab.scene.shapes import Rectangle, Sphere
from lenslab.scene.textures import Checkerboard, ImageTexture
from lenslab.scene.transform import Transform

ALBEDO = 0.6


def looking_down_at_floor(**scene_args) -> Scene:
    """A camera 2 m above a large diffuse floor, looking straight down at its centre."""
    defaults = dict(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 2, 0), look_at=(0, 0, 0), up=(0, 0, -1), focal_length_mm=200,
                              f_number=16, focus_distance_m=2, resolution=(16, 16)),
        render=RenderSettings(max_depth=2),
        materials={"floor": Diffuse((ALBEDO, ALBEDO, ALBEDO))},
        nodes=[Node("floor", Transform(rotate_deg=(-90, 0, 0)), Rectangle((100, 100)), "floor")],
    )
    return Scene(**(defaults | scene_args))


def render(renderer, scene, spp, **session_args):
    session = RenderSession(renderer, scene, **session_args)
    render_to_spp(session, spp)
    image, warnings = session.image(), session.warnings
    session.release()
    return image, warnings


def test_point_light_follows_the_inverse_square_law(renderer):
    intensity, height = 20.0, 1.5
    scene = looking_down_at_floor(lights=[PointLight("bulb", position=(0, height, 0), intensity=(intensity,) * 3)])
    image, _ = render(renderer, scene, 4)
    expected = ALBEDO / math.pi * intensity / height**2  # radiance of a Lambertian floor right under the bulb
    assert image[6:10, 6:10].mean() == pytest.approx(expected, rel=0.01)


@pytest.mark.parametrize("diameter", [0.0, 0.53, 5.0])
def test_sun_irradiance_gives_lambertian_radiance(renderer, diameter):
    irradiance, elevation = 4.0, 60.0
    direction = (math.cos(math.radians(elevation)), math.sin(math.radians(elevation)), 0.0)
    sun = SunLight("sun", direction=direction, irradiance=(irradiance,) * 3, angular_diameter_deg=diameter)
    image, _ = render(renderer, looking_down_at_floor(lights=[sun]), 32)
    expected = ALBEDO / math.pi * irradiance * math.sin(math.radians(elevation))
    # A disk of finite size spreads its irradiance over a cone: the cosine factor averages almost unchanged.
    assert image.mean() == pytest.approx(expected, rel=0.01)


def test_the_sun_disk_is_seen_by_rays_that_escape(renderer):
    # A camera looking straight at a 5-degree sun sees its radiance inside the disk and black sky outside.
    sun = SunLight("sun", direction=(0, 0, 1), irradiance=(1.0, 1.0, 1.0), angular_diameter_deg=5.0)
    scene = Scene(camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 0, 0), look_at=(0, 0, 1), focal_length_mm=200, f_number=16,
                                        focus_distance_m=100, resolution=(32, 32)),
                  render=RenderSettings(max_depth=1), lights=[sun])
    image, _ = render(renderer, scene, 4)
    assert image[16, 16, 0] == pytest.approx(sun.radiance()[0], rel=1e-3)
    assert image[0, 0].max() == 0.0


def write_sky(path, sun_pixels=True):
    """A small HDR panorama: a dim blue sky, a bright sun above the horizon, a darker ground."""
    h, w = 64, 128
    sky = np.zeros((h, w, 3), np.float32)
    sky[: h // 2] = (0.3, 0.4, 0.6)
    sky[h // 2 :] = (0.1, 0.08, 0.05)
    if sun_pixels:
        sky[12:15, 40:43] = (4000.0, 3800.0, 3500.0)
    write_image(path, sky)
    return sky


def sphere_under_sky(path, **env):
    return Scene(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 0, 4), look_at=(0, 0, 0), focal_length_mm=70, f_number=8,
                              focus_distance_m=4, resolution=(24, 24)),
        environment=EnvironmentMap(file=str(path), **env),
        render=RenderSettings(max_depth=2),
        materials={"white": Diffuse((0.8, 0.8, 0.8))},
        nodes=[Node("ball", shape=Sphere(1.0), material="white")],
    )


def test_uniform_environment_map_is_a_white_furnace(renderer, tmp_path):
    write_image(tmp_path / "white.exr", np.ones((32, 64, 3), np.float32))
    scene = sphere_under_sky(tmp_path / "white.exr")
    scene = dataclasses.replace(scene, materials={"white": Diffuse((1, 1, 1))}, render=RenderSettings(max_depth=64))
    image, _ = render(renderer, scene, 32)
    assert image.mean() == pytest.approx(1.0, abs=0.01)


def test_environment_importance_sampling_lowers_the_error_at_equal_samples(renderer, tmp_path):
    write_sky(tmp_path / "sky.exr")
    scene = sphere_under_sky(tmp_path / "sky.exr", rotation_deg=30.0)
    reference, _ = render(renderer, scene, 1024)
    importance, _ = render(renderer, dataclasses.replace(scene, render=RenderSettings(max_depth=2, seed=5)), 16)
    uniform, _ = render(renderer, dataclasses.replace(scene, render=RenderSettings(max_depth=2, seed=5)), 16,
                        environment_importance=False)
    mse_importance = np.mean((importance - reference) ** 2)
    mse_uniform = np.mean((uniform - reference) ** 2)
    assert mse_importance < 0.2 * mse_uniform
    # Both estimators are unbiased: their means agree with the reference within noise.
    assert importance.mean() == pytest.approx(reference.mean(), rel=0.02)
    assert uniform.mean() == pytest.approx(reference.mean(), rel=0.25)


def test_a_sun_brighter_than_half_floats_hold_still_lights_the_scene(renderer, tmp_path):
    # Real HDR panoramas put their sun at 1e5 or more, beyond half floats (65504). The same sky written at a
    # millionth of its brightness and scaled back up by `strength` must give the same picture.
    sky = write_sky(tmp_path / "dim.exr")
    write_image(tmp_path / "bright.exr", sky * 1e6)
    assert sky.max() * 1e6 > 65504
    images = [render(renderer, sphere_under_sky(tmp_path / name, strength=strength), 16)[0]
              for name, strength in (("bright.exr", 1.0), ("dim.exr", 1e6))]
    assert np.isfinite(images[0]).all() and images[0].mean() > 1e4
    assert np.allclose(images[0], images[1], rtol=2e-3, atol=0.0)


def test_environment_rotation_turns_the_lighting(renderer, tmp_path):
    write_sky(tmp_path / "sky.exr")
    lit_side = []
    for rotation in (0.0, 180.0):
        image, _ = render(renderer, sphere_under_sky(tmp_path / "sky.exr", rotation_deg=rotation), 32)
        lit_side.append(image[:, :12].mean() > image[:, 12:].mean())
    assert lit_side[0] != lit_side[1]


def textured_card(texture) -> Scene:
    """A card filling the view, lit evenly by a white sky: its radiance equals its albedo."""
    return Scene(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 0, 2), look_at=(0, 0, 0), focal_length_mm=72, f_number=16,
                              focus_distance_m=2, sensor_mm=(36, 36), resolution=(32, 32)),
        environment=ConstantEnvironment((1.0, 1.0, 1.0)),
        render=RenderSettings(max_depth=2),
        materials={"card": Diffuse(albedo_texture=texture)},
        nodes=[Node("card", shape=Rectangle((1.0, 1.0)), material="card")],
    )


def quarters(image):
    """Mean colour of the middle of each quarter of the card (which spans the middle half of the frame)."""
    return [image[y : y + 4, x : x + 4].reshape(-1, 3).mean(axis=0) for y in (10, 18) for x in (10, 18)]


def test_image_texture_is_linearised_and_oriented(renderer, tmp_path):
    import OpenImageIO as oiio

    # A 16x16 sRGB PNG in quarters: top-left red, top-right green, bottom-left blue, bottom-right mid grey
    # (sRGB 128). Quarters of 8x8 texels keep bilinear filtering away from the colour boundaries we sample.
    quad = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [128, 128, 128]]], np.uint8)
    pixels = np.ascontiguousarray(quad.repeat(8, axis=0).repeat(8, axis=1))
    out = oiio.ImageOutput.create(str(tmp_path / "quad.png"))
    out.open(str(tmp_path / "quad.png"), oiio.ImageSpec(16, 16, 3, oiio.UINT8))
    out.write_image(pixels)
    out.close()
    image, warnings = render(renderer, textured_card(ImageTexture(file=str(tmp_path / "quad.png"))), 64)
    assert warnings == []
    top_left, top_right, bottom_left, bottom_right = quarters(image)
    assert top_left.argmax() == 0 and top_right.argmax() == 1 and bottom_left.argmax() == 2
    grey = ((128 / 255 + 0.055) / 1.055) ** 2.4  # sRGB 128 in linear light: 0.216, not 0.5
    np.testing.assert_allclose(bottom_right, grey, rtol=0.03)


def test_checkerboard_texture(renderer):
    card = textured_card(Checkerboard(color_a=(0.9, 0.9, 0.9), color_b=(0.1, 0.1, 0.1), tiles=(2, 2)))
    image, _ = render(renderer, card, 64)
    q = [c[0] for c in quarters(image)]
    # Squares alternate along both axes: diagonal quarters match, and the two colours are the two given.
    assert q[0] == pytest.approx(q[3], rel=0.03) and q[1] == pytest.approx(q[2], rel=0.03)
    assert sorted([q[0], q[1]]) == pytest.approx([0.1, 0.9], rel=0.03)


def test_missing_texture_warns_and_shows_a_placeholder(renderer, tmp_path):
    image, warnings = render(renderer, textured_card(ImageTexture(file=str(tmp_path / "gone.png"))), 4)
    assert len(warnings) == 1 and "gone.png: texture file not found" in warnings[0] and "magenta" in warnings[0]
    centre = image[12:20, 12:20].reshape(-1, 3)
    assert centre[:, 0].max() > 0.5 and centre[:, 1].max() < 0.05  # magenta (and black) squares


def test_missing_environment_map_warns_and_still_renders(renderer, tmp_path):
    image, warnings = render(renderer, sphere_under_sky(tmp_path / "nowhere.exr"), 2)
    assert len(warnings) == 1 and "nowhere.exr: environment map not found" in warnings[0]
    assert image.max() > 0


def test_area_light_straight_above_a_floor_matches_the_form_factor(renderer):
    """A floor facing a rectangular lamp head-on (the case a shadow ray nudged towards the lamp gets wrong):
    Lambertian radiance rho L F, with F the view factor from a point to a parallel rectangle centred above it
    (four corner rectangles of the classic formula)."""
    from lenslab.scene.materials import Emissive

    radiance, a, b, h = 10.0, 0.5, 0.3, 1.0
    x, y = a / 2 / h, b / 2 / h
    corner = (x / math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x))
              + y / math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))) / (2 * math.pi)
    expected = ALBEDO * radiance * 4 * corner
    scene = Scene(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 0.5, 2), look_at=(0, 0, 0), focal_length_mm=400, f_number=16,
                              focus_distance_m=2, resolution=(16, 16)),
        render=RenderSettings(max_depth=2),
        materials={"floor": Diffuse((ALBEDO,) * 3), "lamp": Emissive((radiance,) * 3)},
        nodes=[Node("floor", Transform(rotate_deg=(-90, 0, 0)), Rectangle((10, 10)), "floor"),
               Node("lamp", Transform(translate=(0, h, 0), rotate_deg=(90, 0, 0)), Rectangle((a, b)), "lamp")],
    )
    image, _ = render(renderer, scene, 64)
    assert image[6:10, 6:10].mean() == pytest.approx(expected, rel=0.02)


@pytest.mark.parametrize("rows", ["centred", "pole_to_pole"])
def test_environment_map_rows_meet_the_sphere_as_their_layout_says(renderer, tmp_path, rows):
    # A map whose row i holds the value i, seen straight up, at 45 degrees and straight down through a
    # narrow pinhole: the bilinear lookup must read the row coordinate the layout puts at that polar angle.
    # Centred rows sit at pi (i + 1/2) / H and clamp at the poles (no blend with the other pole); Mitsuba's
    # pole-to-pole rows sit at pi i / (H - 1).
    h = 8
    write_image(tmp_path / "rows.exr", np.repeat(np.arange(h, dtype=np.float32)[:, None, None], 16, axis=1)
                .repeat(3, axis=2))
    for theta_deg, up in ((0.0, (0, 0, -1)), (45.0, (0, 1, 0)), (180.0, (0, 0, -1))):
        theta = math.radians(theta_deg)
        look = (0.0, math.cos(theta), -math.sin(theta))
        camera = ThinLensCamera(**FIXED_SENSOR, position=(0, 0, 0), look_at=look, up=up, focal_length_mm=2000.0, pinhole=True,
                                resolution=(1, 1))
        scene = Scene(camera=camera, environment=EnvironmentMap(file=str(tmp_path / "rows.exr"), rows=rows),
                      render=RenderSettings(max_depth=1))
        image, _ = render(renderer, scene, 4)
        polar = theta / math.pi
        row = polar * (h - 1) if rows == "pole_to_pole" else min(max(polar * h - 0.5, 0.0), h - 1.0)
        assert image[0, 0, 0] == pytest.approx(row, abs=0.02), theta_deg


def test_nan_and_infinite_texels_read_as_black_with_a_warning(tmp_path, caplog):
    from lenslab.render.textures import read_texture_image

    pixels = np.full((4, 4, 3), 0.5, np.float32)
    pixels[1, 2] = (np.nan, np.inf, -np.inf)
    write_image(tmp_path / "broken.exr", pixels)
    with caplog.at_level("WARNING", logger="lenslab.textures"):
        rgb = read_texture_image(tmp_path / "broken.exr")
    assert np.isfinite(rgb).all() and np.all(rgb[1, 2] == 0.0) and rgb[0, 0, 0] == 0.5
    assert "broken.exr: 1 texel is NaN or infinite" in caplog.text


def test_a_large_panorama_is_sampled_through_coarser_tables_without_bias(renderer, tmp_path, monkeypatch):
    # Sampling tables are capped in size (a 4096 x 2048 map's full tables would fill llvmpipe's storage
    # block); a cell takes the brightest of its pixels, so no lit direction gets zero density: the estimate
    # agrees with full-size tables' and keeps most of importance sampling's advantage over uniform sampling.
    from lenslab.render import environment

    sky = write_sky(tmp_path / "sky.exr")
    coarse = environment.EnvironmentDistribution.from_image(sky, max_size=(40, 24))
    assert coarse.pdf.shape == (24, 40)
    assert np.trapezoid(np.trapezoid(coarse.pdf, dx=1 / 40, axis=1), dx=1 / 24) == pytest.approx(1.0, rel=0.05)
    rows, cols = np.nonzero(sky[..., 0] > 1000)  # the sun: its cells carry the most density
    assert coarse.pdf[(rows * 24) // 64, (cols * 40) // 128].min() > 0.5 * coarse.pdf.max()

    scene = sphere_under_sky(tmp_path / "sky.exr", rotation_deg=30.0)
    reference, _ = render(renderer, scene, 1024)  # full-size tables
    monkeypatch.setattr(environment, "TABLE_MAX_SIZE", (40, 24))
    importance, _ = render(renderer, dataclasses.replace(scene, render=RenderSettings(max_depth=2, seed=5)), 16)
    uniform, _ = render(renderer, dataclasses.replace(scene, render=RenderSettings(max_depth=2, seed=5)), 16,
                        environment_importance=False)
    assert importance.mean() == pytest.approx(reference.mean(), rel=0.02)
    assert np.mean((importance - reference) ** 2) < 0.3 * np.mean((uniform - reference) ** 2)


def test_lights_chosen_by_what_reaches_the_point_agree_with_lights_chosen_by_power_and_are_less_noisy(
        renderer, monkeypatch):
    """Every kind of light at once over a wide floor: a small lamp close above it, a sphere lamp and a point
    light far off, a sun and a dim sky. Choosing lights by power hands the sky (whose power is measured over
    the whole 100 m floor) most shadow rays; choosing by the irradiance each light brings to the shading
    point gives the lamp beside the subject its due. Both are unbiased: their converged images agree."""
    from lenslab.render import buffers
    from lenslab.scene.materials import Emissive

    scene = looking_down_at_floor(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 1.5, 1.5), look_at=(0, 0, 0), focal_length_mm=35, f_number=16,
                              focus_distance_m=2, resolution=(24, 24)),
        render=RenderSettings(max_depth=3),
        environment=ConstantEnvironment((0.05, 0.05, 0.07)),
        materials={"floor": Diffuse((ALBEDO,) * 3), "lamp": Emissive((20.0,) * 3), "far lamp": Emissive((500.0,) * 3)},
        nodes=[Node("floor", Transform(rotate_deg=(-90, 0, 0)), Rectangle((100, 100)), "floor"),
               Node("lamp", Transform(translate=(0.3, 0.8, 0), rotate_deg=(90, 0, 0)), Rectangle((0.3, 0.3)), "lamp"),
               Node("far lamp", Transform(translate=(-20, 3, -30)), Sphere(0.2), "far lamp")],
        lights=[PointLight("bulb", position=(15, 4, -25), intensity=(30.0,) * 3),
                SunLight("sun", direction=(0.3, 0.2, 0.9), irradiance=(0.3,) * 3, angular_diameter_deg=0.53)],
    )
    at_point_reference, _ = render(renderer, scene, 1024)
    at_point, _ = render(renderer, dataclasses.replace(scene, render=RenderSettings(max_depth=3, seed=9)), 16)
    monkeypatch.setattr(buffers, "LIGHTS_AT_POINT_LIMIT", 0)
    by_power_reference, _ = render(renderer, scene, 1024)
    by_power, _ = render(renderer, dataclasses.replace(scene, render=RenderSettings(max_depth=3, seed=9)), 16)

    assert by_power_reference.mean() == pytest.approx(at_point_reference.mean(), rel=0.01)
    quadrants = lambda image: image.reshape(2, 12, 2, 12, 3).mean(axis=(1, 3))  # noqa: E731
    assert np.allclose(quadrants(by_power_reference), quadrants(at_point_reference), rtol=0.02)
    error = lambda image: np.mean((image - at_point_reference) ** 2)  # noqa: E731
    assert error(at_point) < 0.1 * error(by_power)


@pytest.mark.parametrize("diameter", [1e-200, 5e-324, 1e-7])
def test_a_sun_too_small_to_be_a_disk_is_refused_not_divided_by_zero(tmp_path, diameter):
    """1e-200 degrees squared in the disk's solid angle is 0 in floating point: a ZeroDivisionError, shown as an
    internal error. Between 0 (a point at infinity) and SMALLEST_SUN_DEG the disk's radiance leaves float32."""
    import json

    from lenslab.scene.io.native import load_scene
    from lenslab.scene.lights import SMALLEST_SUN_DEG
    from lenslab.scene.scene import SceneError

    sun = SunLight("tiny", direction=(0, 1, 0), angular_diameter_deg=diameter)
    with pytest.raises(ValueError, match=f"sun 'tiny': angular_diameter_deg {diameter:g} is too small to be a disk: "
                                         f"give 0 \\(a point at infinity, sharp shadows\\) or at least 1e-06"):
        sun.radiance()
    path = tmp_path / "scene.json"
    path.write_text(json.dumps({"lenslab_scene": 2, "lights": [{"type": "sun", "name": "tiny",
                                                                 "angular_diameter_deg": diameter}]}))
    with pytest.raises(SceneError, match=rf"lights\[0\]\.angular_diameter_deg: {json.dumps(diameter)} is too small: "
                                         rf"give 0 or at least 1e-06"):
        load_scene(path)
    point = SunLight("point", irradiance=(2.0, 3.0, 4.0), angular_diameter_deg=0.0)
    assert point.radiance() == (2.0, 3.0, 4.0)  # 0 stays a delta light
    smallest = SunLight("smallest", irradiance=(1e9,) * 3, angular_diameter_deg=SMALLEST_SUN_DEG).radiance()
    assert np.isfinite(np.float32(smallest)).all()  # the smallest disk's radiance is within float32
