"""The camera's rays: the Python frame against the conventions written out by hand, and the shader against the
Python frame (glsl/camera_probe.comp calls camera_ray() on the numbers the test chose)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lenslab.optics.aperture import sample_concentric_disk, sample_polygon
from lenslab.render.gl import make_current
from lenslab.render.gpu_layout import PROBE_IN_BINDING, PROBE_OUT_BINDING
from lenslab.render.tracer import ApertureTable, camera_uniforms
from lenslab.scene.camera import ThinLensCamera

PROBE_GROUP_SIZE = 64
CAMERA = ThinLensCamera(position=(1.0, 2.0, 3.0), look_at=(-0.5, 0.3, -1.0), up=(0.2, 1.0, 0.1),
                        focal_length_mm=35.0, f_number=1.4, focus_distance_m=2.5, resolution=(300, 200),
                        # The geometry of the rays alone: focus from the lens, the sensor one focal length behind
                        # it, the image across the sensor's width (tests/test_camera_controls.py covers the rest).
                        focus_from="lens", focus_breathing=False, sensor_fit="horizontal")


def camera_axes(camera):
    """Right, up and forward written out from look-at, independently of ThinLensCamera.basis."""
    forward = np.subtract(camera.look_at, camera.position)
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, camera.up)
    right /= np.linalg.norm(right)
    return right, np.cross(right, forward), forward


# -- the Python frame against the conventions -------------------------------------------------------------
def test_the_centre_of_the_image_looks_down_the_view_axis():
    frame = CAMERA.frame()
    _, _, forward = camera_axes(CAMERA)
    assert np.allclose(frame.pinhole_directions([(150, 100)]), forward)
    assert np.allclose(frame.forward, forward)


def test_the_edges_of_the_image_are_half_the_field_of_view_off_axis():
    right, up, forward = camera_axes(CAMERA)
    half_x = math.atan(36.0 / (2 * 35.0))  # fov_x = 2 atan(w / 2f), full-frame sensor
    half_y = math.atan(math.tan(half_x) * 200 / 300)  # the image's height is a cut of the sensor's width
    frame = CAMERA.frame()
    d_right, d_top = frame.pinhole_directions([(300, 100), (150, 0)])
    assert math.acos(d_right @ forward) == pytest.approx(half_x, abs=1e-12)
    assert d_right @ right > 0 and abs(d_right @ up) < 1e-12
    assert math.acos(d_top @ forward) == pytest.approx(half_y, abs=1e-12)
    assert d_top @ up > 0 and abs(d_top @ right) < 1e-12
    assert frame.fov_y == pytest.approx(2 * half_y, abs=1e-12)


def test_another_image_shape_crops_the_sensor_instead_of_stretching_it():
    wide, tall = CAMERA.frame(400, 100), CAMERA.frame(100, 400)
    assert wide.tan_half_fov[0] == tall.tan_half_fov[0] == pytest.approx(36.0 / 70.0)
    assert wide.tan_half_fov[1] == pytest.approx(36.0 / 70.0 / 4)
    assert tall.tan_half_fov[1] == pytest.approx(36.0 / 70.0 * 4)


def test_every_thin_lens_ray_of_a_pixel_meets_the_same_point_of_the_plane_of_focus():
    right, up, forward = camera_axes(CAMERA)
    frame = CAMERA.frame()
    rng = np.random.default_rng(1)
    for pixel in [(10.5, 20.25), (299.0, 0.0), (150.0, 100.0)]:
        lens = rng.random((64, 2))
        origins, directions = frame.rays(np.repeat([pixel], 64, axis=0), lens)
        # Where the pinhole ray through this pixel meets the plane at depth s, worked out here.
        x = 2 * pixel[0] / 300 - 1
        y = 1 - 2 * pixel[1] / 200
        tan_x = 36.0 / 70.0
        sharp = np.asarray(CAMERA.position) + 2.5 * (x * tan_x * right + y * tan_x * 200 / 300 * up + forward)
        t = (2.5 - (origins - CAMERA.position) @ forward) / (directions @ forward)
        assert np.allclose(origins + t[:, None] * directions, sharp, atol=1e-9)
        # The rays leave the lens disk: radius f / 2N in the plane through the lens centre facing forward.
        offsets = origins - CAMERA.position
        assert np.allclose(offsets @ forward, 0.0, atol=1e-12)
        assert np.all(np.linalg.norm(offsets, axis=1) <= 0.035 / (2 * 1.4) + 1e-12)
        assert np.allclose(np.linalg.norm(directions, axis=1), 1.0)


def test_depth_and_view_size_follow_the_view_axis():
    _, _, forward = camera_axes(CAMERA)
    frame = CAMERA.frame()
    point = np.asarray(CAMERA.position) + 4.0 * forward + (0.3, -0.2, 0.1)
    assert frame.depth_of(point) == pytest.approx(4.0 + np.dot((0.3, -0.2, 0.1), forward))
    assert np.allclose(frame.focus_point(), np.asarray(CAMERA.position) + 2.5 * forward)
    width, height = frame.view_size_at(2.0)
    assert width == pytest.approx(2 * 2.0 * 36.0 / 70.0) and height == pytest.approx(width * 200 / 300)


def test_pixel_centres_run_row_by_row_from_the_top_left():
    centres = ThinLensCamera(resolution=(3, 2)).frame().pixel_centres()
    assert centres.tolist() == [[0.5, 0.5], [1.5, 0.5], [2.5, 0.5], [0.5, 1.5], [1.5, 1.5], [2.5, 1.5]]


def test_the_aperture_maps_are_uniform_and_stay_inside_their_shapes():
    u = np.random.default_rng(2).random((200_000, 2))
    disk = sample_concentric_disk(u)
    radius2 = np.sum(disk**2, axis=1)
    assert radius2.max() <= 1 + 1e-12
    assert radius2.mean() == pytest.approx(0.5, abs=0.005)  # uniform by area: E[r^2] = 1/2
    for blades, rotation in [(3, 0.0), (6, 0.4), (9, -1.0)]:
        polygon = sample_polygon(u, blades, rotation)
        # Inside every edge: the apothem cos(pi / n) bounds the projection on each edge's normal.
        normals = rotation + 2 * np.pi * (np.arange(blades) + 0.5) / blades
        projections = polygon @ np.stack([np.cos(normals), np.sin(normals)])
        assert projections.max() <= math.cos(math.pi / blades) + 1e-12
        assert np.allclose(polygon.mean(axis=0), 0.0, atol=0.005)


# -- the shader against the Python frame ------------------------------------------------------------------
def shader_rays(renderer, camera, width, height, items, *, with_weights=False):
    ctx = renderer.ctx
    make_current(ctx)
    program = renderer.program("camera_probe.comp", LOCAL_SIZE_X=PROBE_GROUP_SIZE)
    frame = camera.frame(width, height)
    renderer.set_uniforms(program, {**camera_uniforms(frame), "item_count": len(items)})
    table = ApertureTable(ctx)
    table.bind(frame.aperture)
    source = ctx.buffer(np.asarray(items, np.float32).tobytes())
    result = ctx.buffer(reserve=len(items) * 48)
    source.bind_to_storage_buffer(PROBE_IN_BINDING)
    result.bind_to_storage_buffer(PROBE_OUT_BINDING)
    program.run((len(items) + PROBE_GROUP_SIZE - 1) // PROBE_GROUP_SIZE, 1, 1)
    out = np.frombuffer(result.read(), np.float32).reshape(-1, 3, 4).copy()
    source.release()
    result.release()
    table.release()
    if with_weights == "colour":  # (N, 3): a real lens weighs each channel
        return out[:, 0, :3], out[:, 1, :3], np.stack([out[:, 0, 3], out[:, 1, 3], out[:, 2, 0]], axis=-1)
    if with_weights:
        return out[:, 0, :3], out[:, 1, :3], out[:, 0, 3]
    return out[:, 0, :3], out[:, 1, :3]


@pytest.mark.parametrize("blades, pinhole", [(0, False), (6, False), (0, True)])
@pytest.mark.parametrize("size", [(300, 200), (64, 256)])
def test_the_shader_traces_the_rays_the_host_computes(renderer, blades, pinhole, size):
    camera = ThinLensCamera(position=CAMERA.position, look_at=CAMERA.look_at, up=CAMERA.up, focal_length_mm=35.0,
                            f_number=1.4, focus_distance_m=2.5, aperture_blades=blades, blade_rotation_deg=20.0,
                            resolution=(300, 200), pinhole=pinhole, focus_from="lens", focus_breathing=False,
                            sensor_fit="horizontal")
    rng = np.random.default_rng(3)
    width, height = size
    items = np.column_stack([rng.random(500) * width, rng.random(500) * height, rng.random((500, 2))])
    origins, directions = shader_rays(renderer, camera, width, height, items)
    expected_origins, expected_directions = camera.frame(width, height).rays(items[:, :2], items[:, 2:])
    assert np.allclose(origins, expected_origins, atol=2e-6)
    assert np.allclose(directions, expected_directions, atol=2e-6)
    if not pinhole:  # the probe really samples the lens: the origins spread over it
        assert np.ptp(np.linalg.norm(origins - CAMERA.position, axis=1)) > 0.005


@pytest.mark.parametrize("controls", [
    dict(aperture_blades=7, blade_curvature=0.5),
    dict(aperture_blades=5, blade_curvature=0.2, anamorphic_squeeze=1.8, barrel_clipping=0.9),
    dict(aperture_image="plus"),
    dict(sensor_fit="fill", focus_from="sensor", focus_breathing=True),
])
def test_the_shader_samples_every_stop_shape_as_the_host_does(renderer, controls, tmp_path):
    """Rounded blades, squeeze, the barrel and an aperture image: the same points on the lens, the same weights
    (the rounded blades' importance weight, 0 where the barrel blocks the ray)."""
    if controls.get("aperture_image") == "plus":
        import OpenImageIO as oiio

        mask = np.zeros((9, 12), np.float32)
        mask[3:6, :] = 1.0
        mask[:, 4:8] = 0.5
        out = oiio.ImageOutput.create(str(tmp_path / "plus.exr"))
        out.open(str(tmp_path / "plus.exr"), oiio.ImageSpec(12, 9, 1, oiio.FLOAT))
        out.write_image(mask)
        out.close()
        controls = dict(aperture_image=str(tmp_path / "plus.exr"))
    settings = dict(position=CAMERA.position, look_at=CAMERA.look_at, up=CAMERA.up, focal_length_mm=35.0,
                    f_number=1.4, focus_distance_m=2.5, resolution=(300, 200), focus_from="lens",
                    focus_breathing=False, sensor_fit="horizontal")
    camera = ThinLensCamera(**(settings | controls))
    rng = np.random.default_rng(5)
    items = np.column_stack([rng.random(800) * 300, rng.random(800) * 200, rng.random((800, 2))])
    origins, directions, weights = shader_rays(renderer, camera, 300, 200, items, with_weights=True)
    expected = camera.frame(300, 200).rays(items[:, :2], items[:, 2:], with_weights=True)
    assert np.allclose(weights, expected[2], atol=1e-4)
    unblocked = expected[2] > 0
    if controls.get("barrel_clipping"):
        assert 0.05 < 1 - unblocked.mean() < 0.6  # the barrel does block some rays, not all
    # float32 tables and trigonometry on the GPU: the lens points agree to a micrometre on a 12.5 mm stop.
    assert np.allclose(origins[unblocked], expected[0][unblocked], atol=2e-6)
    assert np.allclose(directions[unblocked], expected[1][unblocked], atol=2e-6)
