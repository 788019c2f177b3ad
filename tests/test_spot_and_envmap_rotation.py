"""Spot lights and environment maps under any rotation: the scene model, the renderer against closed forms,
the Mitsuba importer on small documents, and Mitsuba 3 itself where it is installed."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from tests.helpers import render_to_spp
from tests.scenes import FIXED_SENSOR

from lenslab.render import buffers
from lenslab.render.environment import EnvironmentDistribution, direction_to_uv, uv_to_direction
from lenslab.render.features import scene_features
from lenslab.render.film import write_image
from lenslab.render.tracer import RenderSession
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.io.mitsuba_xml import load_mitsuba_string
from lenslab.scene.io.native import load_scene, save_scene
from lenslab.scene.lights import PointLight, SpotLight
from lenslab.scene.materials import Diffuse
from lenslab.scene.scene import (EnvironmentMap, Node, RenderSettings, Scene, SceneError,
                                 environment_orientation)
from lenslab.scene.shapes import Rectangle
from lenslab.scene.textures import ImageTexture
from lenslab.scene.transform import Transform

ALBEDO = 0.6
SUBPIXELS = 8  # per side: the analytic images average this many points in each pixel


def random_rotations(count: int, seed: int = 0) -> list[np.ndarray]:
    """Uniformly random rotations (QR of gaussian matrices, signs fixed), plus the awkward ones: half turns
    that send +Y straight down, and the identity."""
    rng = np.random.default_rng(seed)
    out = [np.eye(3), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    for _ in range(count):
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        q = q * np.sign(np.diag(r))
        out.append(q if np.linalg.det(q) > 0 else -q)
    return out


def render(renderer, scene, spp, **session_args):
    session = RenderSession(renderer, scene, **session_args)
    try:
        render_to_spp(session, spp)
        return session.image(), session.warnings
    finally:
        session.release()


def floor_scene(lights, resolution=32, camera_height=3.0, focal_length_mm=30.0, **scene_args) -> Scene:
    """A pinhole camera above a large diffuse floor (the plane y = 0), looking straight down: +X to the right
    of the image, -Z up."""
    camera = ThinLensCamera(**FIXED_SENSOR, position=(0, camera_height, 0), look_at=(0, 0, 0), up=(0, 0, -1),
                            focal_length_mm=focal_length_mm, pinhole=True, resolution=(resolution, resolution))
    return Scene(camera=camera, render=RenderSettings(max_depth=2), materials={"floor": Diffuse((ALBEDO,) * 3)},
                 nodes=[Node("floor", Transform(rotate_deg=(-90, 0, 0)), Rectangle((100, 100)), "floor")],
                 lights=list(lights), **scene_args)


def floor_points(camera: ThinLensCamera) -> np.ndarray:
    """(H, W, SUBPIXELS^2, 3): where SUBPIXELS^2 evenly spread rays through each pixel meet the floor."""
    w, h = camera.resolution
    frame = camera.frame(w, h)
    g = (np.arange(SUBPIXELS) + 0.5) / SUBPIXELS
    rows, cols, sy, sx = np.meshgrid(np.arange(h), np.arange(w), g, g, indexing="ij")
    origins, directions = frame.rays(np.stack([cols + sx, rows + sy], -1).reshape(-1, 2))
    t = -origins[:, 1] / directions[:, 1]
    return (origins + t[:, None] * directions).reshape(h, w, SUBPIXELS**2, 3)


def angle_range(spot: SpotLight, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) least and greatest angle from the spot's axis (degrees) of each pixel's floor points; a pixel's
    corners reach a little beyond them (a sixteenth of the pixel)."""
    to_point = points - np.asarray(spot.position)
    cos_axis = (to_point / np.linalg.norm(to_point, axis=-1, keepdims=True)) @ spot.frame()[2]
    angles = np.degrees(np.arccos(np.clip(cos_axis, -1, 1)))
    return angles.min(axis=2), angles.max(axis=2)


def spot_on_floor(spot: SpotLight, points: np.ndarray, texture_rgb=None) -> np.ndarray:
    """(H, W, 3) radiance of the Lambertian floor lit by ``spot``: albedo / pi times I falloff cos / d^2,
    averaged over each pixel; ``texture_rgb(u, v)`` is the projected texture, if any."""
    to_point = points - np.asarray(spot.position)
    dist = np.linalg.norm(to_point, axis=-1)
    d = to_point / dist[..., None]
    right, top, axis = spot.frame()
    cos_axis = d @ axis
    irradiance = spot.falloff(cos_axis)[..., None] * np.asarray(spot.intensity) * (-d[..., 1:2]) / dist[..., None] ** 2
    if texture_rgb is not None:
        scale = 1.0 / (2.0 * math.tan(math.radians(spot.cutoff_angle_deg)) * np.maximum(cos_axis, 1e-9))
        irradiance = irradiance * texture_rgb(0.5 + (d @ right) * scale, 0.5 + (d @ top) * scale)
    return (ALBEDO / math.pi * irradiance).mean(axis=2)


# ---------------------------------------------------------------------------------------------------------
# The spot light: model
# ---------------------------------------------------------------------------------------------------------
def test_spot_falloff_is_mitsubas_linear_ramp_in_the_angle():
    spot = SpotLight("s", cutoff_angle_deg=30.0, beam_width_deg=10.0)
    angles = np.radians([0.0, 9.9, 10.0, 20.0, 25.0, 29.9, 30.0, 31.0, 90.0, 180.0])
    expected = [1.0, 1.0, 1.0, 0.5, 0.25, 0.1 / 20.0, 0.0, 0.0, 0.0, 0.0]
    assert spot.falloff(np.cos(angles)) == pytest.approx(expected, abs=1e-6)
    # A beam wider than the cutoff is a hard edge at the cutoff, as in Mitsuba (where cos theta >= cos beam wins).
    hard = SpotLight("h", cutoff_angle_deg=20.0, beam_width_deg=25.0)
    assert hard.falloff(np.cos(np.radians([19.9, 20.1]))).tolist() == [1.0, 0.0]


@pytest.mark.parametrize("cutoff, beam", [(30.0, 10.0), (20.0, 20.0), (60.0, 0.0), (120.0, 90.0)])
def test_spot_power_is_the_falloff_integrated_over_the_sphere(cutoff, beam):
    spot = SpotLight("s", cutoff_angle_deg=cutoff, beam_width_deg=beam)
    theta = (np.arange(200_000) + 0.5) / 200_000 * math.pi  # midpoint rule over the polar angle
    numeric = 2 * math.pi * np.sum(spot.falloff(np.cos(theta)) * np.sin(theta)) * (math.pi / theta.size)
    assert spot.weighted_solid_angle() == pytest.approx(numeric, rel=1e-4)


def test_spot_frame_puts_the_texture_top_towards_up():
    spot = SpotLight("s", direction=(0.0, -2.0, 0.0), up=(0.3, 0.5, -1.0))
    right, top, axis = spot.frame()
    assert np.allclose(axis, (0, -1, 0)) and np.allclose(top, np.array([0.3, 0, -1]) / math.hypot(0.3, 1))
    assert np.allclose(np.cross(axis, top), right) and abs(np.dot(right, top)) < 1e-12
    along = SpotLight("s", direction=(0, 0, 1), up=(0, 0, 5)).frame()  # up along the axis: any perpendicular
    assert np.allclose(np.array(along) @ np.array(along).T, np.eye(3))


# ---------------------------------------------------------------------------------------------------------
# The spot light: rendered against the closed form
# ---------------------------------------------------------------------------------------------------------
def test_spot_on_a_floor_gives_intensity_times_falloff_times_cos_over_d_squared(renderer):
    spot = SpotLight("spot", position=(0.2, 1.5, 0.1), direction=(0.15, -1.0, 0.1), intensity=(5.0, 4.0, 3.0),
                     cutoff_angle_deg=30.0, beam_width_deg=15.0)
    scene = floor_scene([spot])
    image, warnings = render(renderer, scene, 64)
    expected = spot_on_floor(spot, floor_points(scene.camera))
    assert not warnings
    # Pixels wholly in the beam, wholly in the soft edge, wholly outside the cutoff (by a margin for corners).
    least, most = angle_range(spot, floor_points(scene.camera))
    beam, edge, outside = most < 14.5, (least > 15.5) & (most < 29.5), least > 30.5
    assert beam.sum() > 20 and edge.sum() > 20 and outside.sum() > 100
    assert image[beam] == pytest.approx(expected[beam], rel=0.01)
    assert image[edge] == pytest.approx(expected[edge], rel=0.03, abs=2e-3)
    assert np.all(image[outside] == 0.0)
    assert image.mean(axis=(0, 1)) == pytest.approx(expected.mean(axis=(0, 1)), rel=0.005)


def quadrants(path: Path) -> np.ndarray:
    """A 32 x 32 linear image of four coloured quadrants: red top left, green top right, blue bottom left,
    white bottom right."""
    image = np.zeros((32, 32, 3), np.float32)
    image[:16, :16], image[:16, 16:], image[16:, :16], image[16:, 16:] = (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)
    write_image(path, image)
    return image


def quadrant_lookup(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The quadrants image where LensLab's textures read it: v = 1 is the top row (nearest texel)."""
    top, right = v > 0.5, u > 0.5
    rgb = np.where((top & ~right)[..., None], (1, 0, 0), 0.0)
    rgb = np.where((top & right)[..., None], (0, 1, 0), rgb)
    rgb = np.where((~top & ~right)[..., None], (0, 0, 1), rgb)
    return np.where((~top & right)[..., None], (1, 1, 1), rgb)


def test_a_spot_projects_its_texture_with_the_top_towards_up(renderer, tmp_path):
    quadrants(tmp_path / "quad.exr")
    # Straight down, the image's top towards -Z (the top of the camera's picture): the picture shows the slide
    # as it is, red top left. A hard edge keeps the falloff out of it.
    spot = SpotLight("slide", position=(0.0, 1.0, 0.0), direction=(0, -1, 0), up=(0, 0, -1), intensity=(2.0,) * 3,
                     cutoff_angle_deg=40.0, beam_width_deg=40.0, texture=ImageTexture(str(tmp_path / "quad.exr")))
    scene = floor_scene([spot], camera_height=1.5)  # the slide's disk 30 pixels across
    image, _ = render(renderer, scene, 16)
    expected = spot_on_floor(spot, floor_points(scene.camera), quadrant_lookup)
    n = scene.camera.resolution[0]

    def quadrant_colours(picture):
        """The colour in each quadrant of the picture, off the seams: top left, top right, bottom left, right."""
        near, far = slice(n // 2 - 8, n // 2 - 3), slice(n // 2 + 3, n // 2 + 8)
        blocks = [picture[near, near], picture[near, far], picture[far, near], picture[far, far]]
        return [tuple(np.round(b.mean(axis=(0, 1)) / b.mean(axis=(0, 1)).max(), 2)) for b in blocks]

    assert quadrant_colours(image) == [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]
    # Pixel by pixel, away from the quadrants' seams (where the bilinear lookup blends) and the cutoff.
    seams = np.zeros(image.shape[:2], bool)
    seams[n // 2 - 2 : n // 2 + 2], seams[:, n // 2 - 2 : n // 2 + 2] = True, True
    lit = (angle_range(spot, floor_points(scene.camera))[1] < 39.0) & ~seams
    assert lit.sum() > 300
    assert image[lit] == pytest.approx(expected[lit], rel=0.03, abs=2e-3)
    # Turned a quarter: with up towards +X (the picture's right) the slide's top row lies along the right,
    # its left column (red above blue) along the top.
    turned, _ = render(renderer, dataclasses.replace(scene, lights=[dataclasses.replace(spot, up=(1, 0, 0))]), 4)
    assert quadrant_colours(turned) == [(0, 0, 1), (1, 0, 0), (1, 1, 1), (0, 1, 0)]


def test_spots_share_next_event_estimation_fairly_by_power_or_at_the_point(renderer, monkeypatch):
    # A spot beside a point light: choosing lights at the shading point or by power alone are both unbiased.
    spot = SpotLight("spot", position=(-0.4, 1.2, 0.0), direction=(0.3, -1, 0), intensity=(6.0,) * 3,
                     cutoff_angle_deg=35.0, beam_width_deg=20.0)
    scene = floor_scene([spot, PointLight("bulb", position=(0.8, 1.0, 0.3), intensity=(1.0, 1.0, 1.0))], resolution=24)
    points = floor_points(scene.camera)
    to_bulb = points - np.array([0.8, 1.0, 0.3])
    bulb = (ALBEDO / math.pi * (-to_bulb[..., 1]) / np.linalg.norm(to_bulb, axis=-1) ** 3).mean(axis=2)
    expected = spot_on_floor(spot, points) + bulb[..., None]
    at_point, _ = render(renderer, scene, 256)
    monkeypatch.setattr(buffers, "LIGHTS_AT_POINT_LIMIT", 0)
    by_power, _ = render(renderer, scene, 256)
    for image in (at_point, by_power):
        assert image.mean(axis=(0, 1)) == pytest.approx(expected.mean(axis=(0, 1)), rel=0.01)


@pytest.mark.slow  # compiles the general kernel: minutes on llvmpipe with a cold shader cache
def test_a_scene_with_a_spot_compiles_a_kernel_with_spots_that_matches_the_general_one(renderer):
    spot = SpotLight("spot", position=(0.0, 1.5, 0.0), intensity=(3.0,) * 3, cutoff_angle_deg=25.0)
    scene = floor_scene([spot], resolution=16)
    packed = buffers.pack_scene(scene.flatten(), scene.environment, lights=scene.lights)
    features = scene_features(packed)
    assert features.spot_lights and not features.point_lights and not features.sun
    specialised, _ = render(renderer, scene, 4)
    general, _ = render(renderer, scene, 4, specialise=False)
    assert np.allclose(specialised, general, rtol=1e-4, atol=1e-6)


# ---------------------------------------------------------------------------------------------------------
# The environment under any rotation
# ---------------------------------------------------------------------------------------------------------
def test_any_rotation_is_one_zenith_and_one_turn():
    for rotation in random_rotations(200):
        zenith, turn = environment_orientation(rotation)
        environment = EnvironmentMap(file="sky.exr", rotation_deg=turn, zenith=zenith)
        assert np.allclose(environment.world_from_map(), rotation, atol=1e-9)
        assert -180.0 < turn <= 180.0
    # rotation_deg alone keeps its meaning (a turn about +Y that takes the centre column towards +X), and the
    # uv mapping reads a number as that turn in radians.
    assert np.allclose(EnvironmentMap(file="x", rotation_deg=90.0).world_from_map() @ (0, 0, -1), (1, 0, 0))
    d = np.random.default_rng(2).normal(size=(100, 3))
    assert np.allclose(direction_to_uv(d, 0.4), direction_to_uv(d, EnvironmentMap(
        file="x", rotation_deg=math.degrees(0.4)).world_from_map()))


def test_uv_mapping_and_pdf_follow_the_rotation():
    rng = np.random.default_rng(3)
    image = rng.uniform(0.1, 1.0, (16, 32, 3)) ** 4
    distribution = EnvironmentDistribution.from_image(image)
    for rotation in random_rotations(5, seed=4):
        uv = rng.uniform(0.01, 0.99, (500, 2))
        d = uv_to_direction(uv, rotation)
        assert np.allclose(np.linalg.norm(d, axis=-1), 1.0) and np.allclose(direction_to_uv(d, rotation), uv)
        # The pdf over directions still integrates to one over the sphere (a rotation keeps solid angle).
        dirs = rng.normal(size=(200_000, 3))
        dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
        assert np.mean(distribution.pdf_direction(dirs, rotation)) * 4 * math.pi == pytest.approx(1.0, rel=0.02)


def smooth_sky(direction_in_map: np.ndarray) -> np.ndarray:
    """Radiance of a smooth panorama (so that bilinear lookups of a 64 x 128 image match it within 0.1%) with a
    broad bright lobe towards (0.8, 0.2, 0.57) of its own frame and a tint that varies with the direction."""
    lobe = np.exp(6.0 * (direction_in_map @ np.array([0.8, 0.2, 0.57]) - 1.0))
    base = 0.2 + 0.1 * direction_in_map[..., 1:2] * np.array([1.0, 0.5, -0.5])
    return base + 4.0 * lobe[..., None] * np.array([1.0, 0.9, 0.7])


def write_smooth_sky(path: Path, height: int = 128) -> None:
    """smooth_sky as a centred lat-long image (row i at polar angle pi (i + 1/2) / H)."""
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(2 * height) + 0.5) / (2 * height)
    uu, vv = np.meshgrid(u, v)
    write_image(path, smooth_sky(uv_to_direction(np.stack([uu, vv], -1))).astype(np.float32))


TILTED = EnvironmentMap(file="sky.exr", rotation_deg=35.0, zenith=(0.5, 0.6, -0.62))


def test_a_rotated_map_is_seen_through_its_rotation(renderer, tmp_path):
    write_smooth_sky(tmp_path / "sky.exr")
    environment = dataclasses.replace(TILTED, file=str(tmp_path / "sky.exr"))
    camera = ThinLensCamera(**FIXED_SENSOR, position=(0, 0, 0), look_at=(0.3, 0.2, -1), focal_length_mm=12,
                            pinhole=True, resolution=(32, 32))
    scene = Scene(camera=camera, environment=environment, render=RenderSettings(max_depth=1))
    image, _ = render(renderer, scene, 4)
    frame = camera.frame(32, 32)
    _, directions = frame.rays(frame.pixel_centres().reshape(-1, 2))
    expected = smooth_sky(directions @ environment.world_from_map()).reshape(32, 32, 3)
    assert image == pytest.approx(expected, rel=0.01)
    unturned = smooth_sky(directions).reshape(32, 32, 3)
    assert np.abs(image / unturned - 1).max() > 0.3  # the test sees a rotation left out


def hemisphere_irradiance(environment: EnvironmentMap, n: int = 1000) -> np.ndarray:
    """Irradiance on an upward-facing surface under ``smooth_sky`` turned by the environment: a midpoint
    rule over (cos theta, phi) about +Y, so that cos theta d(cos theta) d(phi) is the measure."""
    mu = (np.arange(n) + 0.5) / n
    phi = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * math.pi
    m, p = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - m**2)
    world = np.stack([s * np.cos(p), m, s * np.sin(p)], -1)
    radiance = smooth_sky(world @ environment.world_from_map())
    return (radiance * m[..., None]).sum(axis=(0, 1)) * (1.0 / n) * (2 * math.pi / (2 * n))


def test_a_rotated_map_lights_a_floor_as_the_integral_says_sampled_or_not(renderer, tmp_path):
    # A floor lit by the turned map alone: importance sampling (the tables in the map's frame) and uniform
    # sampling both give albedo / pi times the irradiance integrated over the turned sky.
    write_smooth_sky(tmp_path / "sky.exr")
    environment = dataclasses.replace(TILTED, file=str(tmp_path / "sky.exr"))
    scene = floor_scene([], resolution=8, environment=environment)
    expected = ALBEDO / math.pi * hemisphere_irradiance(environment)
    unturned = ALBEDO / math.pi * hemisphere_irradiance(dataclasses.replace(environment, rotation_deg=0.0,
                                                                           zenith=(0, 1, 0)))
    assert np.abs(expected / unturned - 1).max() > 0.2  # the lobe lights the floor quite differently unturned
    importance, _ = render(renderer, scene, 512)
    uniform, _ = render(renderer, scene, 512, environment_importance=False)
    assert importance.mean(axis=(0, 1)) == pytest.approx(expected, rel=0.005)  # measured: within 0.06%
    assert uniform.mean(axis=(0, 1)) == pytest.approx(expected, rel=0.005)


# ---------------------------------------------------------------------------------------------------------
# The scene file
# ---------------------------------------------------------------------------------------------------------
def test_spots_and_tilted_maps_survive_the_native_format(tmp_path):
    scene = Scene(environment=TILTED, lights=[
        SpotLight("key", position=(1.0, 2.0, 3.0), direction=(0.0, -1.0, 0.5), intensity=(3.0, 2.0, 1.0),
                  cutoff_angle_deg=25.0, beam_width_deg=5.0, texture=ImageTexture("slide.png"), up=(1.0, 0.0, 0.0))])
    save_scene(scene, tmp_path / "scene.json")
    loaded = load_scene(tmp_path / "scene.json")
    assert loaded.lights == scene.lights and loaded.environment == scene.environment
    text = (tmp_path / "scene.json").read_text().replace('"cutoff_angle_deg": 25.0', '"cutoff_angle_deg": 0')
    (tmp_path / "bad.json").write_text(text)
    with pytest.raises(SceneError, match=r"lights\[0\]\.cutoff_angle_deg: 0 is out of range"):
        load_scene(tmp_path / "bad.json")


# ---------------------------------------------------------------------------------------------------------
# The Mitsuba importer
# ---------------------------------------------------------------------------------------------------------
def load(text: str, base_dir: Path | None = None):
    warnings: list[str] = []
    scene = load_mitsuba_string(f'<scene version="3.0.0">{text}</scene>', base_dir=base_dir, warn=warnings.append)
    return scene, [w for w in warnings if "no sensor" not in w]


def test_importer_reads_a_spot_from_its_to_world():
    scene, warnings = load('<emitter type="spot" id="key"><rgb name="intensity" value="3, 2, 1"/>'
                           '<float name="cutoff_angle" value="25"/><float name="beam_width" value="10"/>'
                           '<transform name="to_world"><lookat origin="1, 2, 3" target="1, 0, 3" up="0, 0, 1"/>'
                           '<scale value="1"/></transform></emitter><emitter type="spot"/>')
    key, default = scene.lights
    assert warnings == []
    assert key == SpotLight("key", position=(1.0, 2.0, 3.0), direction=(0.0, -1.0, 0.0), intensity=(3.0, 2.0, 1.0),
                            cutoff_angle_deg=25.0, beam_width_deg=10.0, up=(0.0, 0.0, -1.0))
    # Mitsuba's defaults: intensity 1, cutoff 20, beam 3/4 of it, shining along +Z from the origin, and the
    # image's top row (v = 0) along its -Y.
    assert default == SpotLight("spot", position=(0.0, 0.0, 0.0), direction=(0.0, 0.0, 1.0), intensity=(1.0,) * 3,
                                cutoff_angle_deg=20.0, beam_width_deg=15.0, up=(0.0, -1.0, 0.0))


def test_importer_reads_a_spots_texture_and_refuses_what_mitsuba_refuses(tmp_path):
    quadrants(tmp_path / "quad.exr")
    scene, warnings = load('<emitter type="spot"><texture type="bitmap" name="texture">'
                           '<string name="filename" value="quad.exr"/></texture></emitter>', tmp_path)
    assert isinstance(scene.lights[0].texture, ImageTexture) and scene.lights[0].texture.file.endswith("quad.exr")
    assert warnings == []
    with pytest.raises(SceneError, match=r"line 1: .*cutoff_angle must be in \(0, 180\]"):
        load('<emitter type="spot"><float name="cutoff_angle" value="0"/></emitter>')
    with pytest.raises(SceneError, match="intensity cannot vary over space"):
        load('<emitter type="spot"><texture type="bitmap" name="intensity"><string name="filename" '
             'value="quad.exr"/></texture></emitter>', tmp_path)
    with pytest.raises(SceneError, match="texture must vary over space"):
        load('<emitter type="spot"><rgb name="texture" value="1, 0, 0"/></emitter>')
    _, warnings = load('<emitter type="spot"><transform name="to_world"><scale x="2"/></transform></emitter>')
    assert len(warnings) == 1 and "elliptical" in warnings[0] and ":1:" in warnings[0]


def test_importer_keeps_any_envmap_rotation_exactly(tmp_path):
    # Mitsuba looks d up at u = atan2(x, -z) / 2pi, v = acos(y) / pi of to_world^-1 d; ours at u + 1/2 of the
    # same picture in our map's frame. Every direction must find the texel Mitsuba reads.
    (tmp_path / "sky.exr").write_bytes(b"not read while importing")
    rng = np.random.default_rng(5)
    for axis, angle in [((1, 0, 0), 90.0), ((0.6, 0.0, 0.8), 55.0), ((0, 0, 1), 180.0), ((0, 1, 0), 30.0),
                        (tuple(np.array([0.3, -0.8, 0.52]) / np.linalg.norm([0.3, -0.8, 0.52])), 130.0)]:
        x, y, z = (f"{float(c):.17g}" for c in axis)
        scene, warnings = load(f'<emitter type="envmap"><string name="filename" value="sky.exr"/><transform '
                               f'name="to_world"><rotate x="{x}" y="{y}" z="{z}" angle="{angle}"/></transform>'
                               '</emitter>', tmp_path)
        assert warnings == []
        from lenslab.scene.io import mitsuba_values as mv

        to_world = mv.rotate_matrix(axis, angle)[:3, :3]
        d = rng.normal(size=(200, 3))
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        local = d @ to_world  # to_world^-1 d, row by row
        u_mitsuba = np.mod(np.arctan2(local[:, 0], -local[:, 2]) / (2 * np.pi), 1.0)
        v_mitsuba = np.arccos(np.clip(local[:, 1], -1, 1)) / np.pi
        uv = direction_to_uv(d, scene.environment.world_from_map())
        assert np.allclose(np.mod(uv[:, 0] - u_mitsuba + 0.5, 1.0), 0.5, atol=1e-9)
        assert np.allclose(uv[:, 1], v_mitsuba, atol=1e-7)
    scene, _ = load('<emitter type="envmap"><string name="filename" value="sky.exr"/></emitter>', tmp_path)
    assert scene.environment.zenith == (0.0, 1.0, 0.0) and scene.environment.rotation_deg == 180.0
    _, warnings = load('<emitter type="envmap"><string name="filename" value="sky.exr"/><transform name="to_world">'
                       '<scale value="2"/></transform></emitter>', tmp_path)
    assert len(warnings) == 1 and "scales or shears the map" in warnings[0]


# ---------------------------------------------------------------------------------------------------------
# Against Mitsuba 3 (skipped where it is not installed or cannot render)
# ---------------------------------------------------------------------------------------------------------
def test_spot_falloff_and_projection_match_mitsubas_emitter(mitsuba, tmp_path):
    mi = mitsuba
    quadrants(tmp_path / "quad.exr")
    xml = ('<scene version="3.0.0"><emitter type="spot"><float name="cutoff_angle" value="40"/>'
           '<float name="beam_width" value="25"/><texture type="bitmap" name="texture"><string name="filename" '
           'value="quad.exr"/></texture><transform name="to_world"><rotate z="1" angle="25"/><lookat origin="0.3, 2, '
           '0.1" target="0.5, 0, -0.2" up="1, 0, 1"/></transform></emitter></scene>')
    (tmp_path / "spot.xml").write_text(xml)
    emitter = mi.load_file(str(tmp_path / "spot.xml")).emitters()[0]
    spot = load_mitsuba_string(xml, base_dir=tmp_path, warn=lambda _: None).lights[0]
    rng = np.random.default_rng(6)
    points = np.c_[rng.uniform(-2.0, 2.5, 1000), np.zeros(1000), rng.uniform(-2.5, 2.0, 1000)]
    interaction = mi.Interaction3f()
    interaction.p = mi.Point3f(points[:, 0], points[:, 1], points[:, 2])
    _, weight = emitter.sample_direction(interaction, mi.Point2f(0.5, 0.5))
    to_point = points - np.asarray(spot.position)
    theirs = np.array(weight).T * (np.linalg.norm(to_point, axis=-1) ** 2)[:, None]  # intensity x falloff x texture
    d = to_point / np.linalg.norm(to_point, axis=-1, keepdims=True)
    right, top, axis = spot.frame()
    scale = 1.0 / (2.0 * math.tan(math.radians(spot.cutoff_angle_deg)) * np.maximum(d @ axis, 1e-9))
    u, v = 0.5 + (d @ right) * scale, 0.5 + (d @ top) * scale
    ours = spot.falloff(d @ axis)[:, None] * quadrant_lookup(u, v)
    # Off the seams, where the bilinear lookups blend (the image's edges too: it repeats).
    clear = (np.abs(np.abs(u - 0.5) - 0.25) < 0.25 - 2 / 32) & (np.abs(np.abs(v - 0.5) - 0.25) < 0.25 - 2 / 32)
    lit = (d @ axis > math.cos(math.radians(40)))
    assert clear[lit].sum() > 200 and (~lit).sum() > 200
    assert np.allclose(ours[clear], theirs[clear], atol=2e-5)


@pytest.mark.parametrize("name", ["spot", "rotated_env"])
def test_validation_scene_matches_mitsuba(mitsuba, renderer, name):
    # The validation scene, small: 1.5% on the whole image and 5% on each 16 x 16 block mean leave room for
    # noise (measured over four seeds: at most 0.5% and 2.4%).
    from lenslab.validate import metrics, runner

    path = runner.SCENES_DIR / f"{name}.xml"
    ours = runner.render_lenslab(path, 256, 1, 48, renderer, lambda _: None).image
    theirs = runner.mitsuba_image(mitsuba, mitsuba.load_file(str(path), res="48", spp="512"), 512, 7)
    assert ours.mean() == pytest.approx(theirs.mean(), rel=0.015)
    bias = metrics.block_bias(ours, theirs)
    assert np.nanmax(np.abs(bias)) < 0.05
