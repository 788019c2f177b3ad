"""The controls of a real camera: sensor fit, focus from the sensor plane, aperture shapes measured on
rendered point lights, physical exposure and what the image files say. Expected values are worked out here from
the definitions (Blender's and Unity's fits, the Gaussian lens equation, ISO 12232), not taken from the code."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lenslab.render.film import read_image
from lenslab.render.job import RenderJob
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.io.native import FORMAT_VERSION, load_scene, save_scene
from lenslab.scene.scene import SceneError
from tests.scenes import axis_camera, point_light_scene


# -- sensor fit ---------------------------------------------------------------------------------------------
def fov_degrees(camera, width, height):
    frame = camera.frame(width, height)
    return math.degrees(frame.fov_x), math.degrees(frame.fov_y)


@pytest.mark.parametrize("fit, size, expected_mm", [
    ("auto", (1000, 1500), (24.0, 36.0)),  # a portrait: the camera turned, as Blender's Auto
    ("auto", (1500, 1000), (36.0, 24.0)),
    ("auto", (320, 320), (36.0, 36.0)),  # Blender's Auto fits the long side only
    ("horizontal", (1000, 1500), (36.0, 54.0)),
    ("vertical", (320, 320), (24.0, 24.0)),
    ("fill", (320, 320), (24.0, 24.0)),  # inside the sensor
    ("fill", (1600, 900), (36.0, 20.25)),
    ("overscan", (320, 320), (36.0, 36.0)),  # around the sensor
    ("overscan", (1600, 900), (42.666666, 24.0)),
])
def test_the_sensor_fit_decides_which_part_of_the_sensor_the_image_shows(fit, size, expected_mm):
    camera = ThinLensCamera(focal_length_mm=50.0, sensor_mm=(36.0, 24.0), sensor_fit=fit, focus_breathing=False)
    assert camera.imaged_area_mm(*size) == pytest.approx(expected_mm)
    fov_x, fov_y = fov_degrees(camera, *size)
    assert fov_x == pytest.approx(math.degrees(2 * math.atan(expected_mm[0] / 100.0)))
    assert fov_y == pytest.approx(math.degrees(2 * math.atan(expected_mm[1] / 100.0)))
    # The circle of confusion follows the area actually imaged.
    assert camera.coc_mm(*size) == pytest.approx(math.hypot(*expected_mm) / 1500)


def test_a_portrait_in_auto_fit_matches_blender():
    camera = ThinLensCamera(focal_length_mm=50.0, focus_breathing=False)
    fov_x, fov_y = fov_degrees(camera, 1000, 1500)
    assert (round(fov_x, 1), round(fov_y, 1)) == (27.0, 39.6)


def test_an_own_circle_of_confusion_overrides_the_diagonal_rule():
    assert ThinLensCamera(circle_of_confusion_mm=0.025).coc_mm(640, 480) == 0.025


# -- focus as a lens scale reads it -------------------------------------------------------------------------
def test_focus_from_the_sensor_plane_obeys_the_lens_equation():
    camera = ThinLensCamera(focal_length_mm=50.0, focus_distance_m=0.45)
    s, v = camera.plane_of_focus_m * 1000, camera.image_distance_mm
    assert 1 / s + 1 / v == pytest.approx(1 / 50.0)  # Gauss
    assert (s + v) / 1000 == pytest.approx(0.45)  # the scale's reading: sensor to subject
    # From the lens, the same number means the plane itself, 57 mm further (the 50 mm at 0.45 m).
    lens = ThinLensCamera(focal_length_mm=50.0, focus_distance_m=0.45, focus_from="lens")
    assert lens.plane_of_focus_m - camera.plane_of_focus_m == pytest.approx(0.0573, abs=5e-4)


def test_every_ray_of_a_pixel_meets_at_the_plane_the_lens_equation_gives():
    camera = ThinLensCamera(position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, -1.0), focal_length_mm=85.0,
                            f_number=1.4, focus_distance_m=1.2, resolution=(64, 48))
    frame = camera.frame()
    s = camera.plane_of_focus_m
    rng = np.random.default_rng(2)
    origins, directions = frame.rays(np.repeat([[40.3, 7.7]], 32, axis=0), rng.random((32, 2)))
    t = (s - origins @ frame.forward) / (directions @ frame.forward)
    points = origins + t[:, None] * directions
    assert np.ptp(points, axis=0).max() < 1e-9


def test_focus_breathing_narrows_the_view_as_focus_comes_closer_and_can_be_held():
    far = ThinLensCamera(focal_length_mm=50.0, focus_distance_m=100.0)
    near = ThinLensCamera(focal_length_mm=50.0, focus_distance_m=0.45)
    held = ThinLensCamera(focal_length_mm=50.0, focus_distance_m=0.45, focus_breathing=False)
    v = near.image_distance_mm
    assert near.frame().tan_half_fov[0] == pytest.approx(18.0 / v)
    assert near.frame().fov_x < far.frame().fov_x < held.frame().fov_x
    assert held.frame().tan_half_fov[0] == pytest.approx(18.0 / 50.0)


def test_click_to_focus_sets_the_reading_that_makes_the_point_sharp():
    camera = ThinLensCamera(focal_length_mm=50.0)
    camera.focus_distance_m = camera.focus_setting_for(2.0)
    assert camera.plane_of_focus_m == pytest.approx(2.0)


def test_nothing_nearer_than_four_focal_lengths_from_the_sensor(tmp_path):
    with pytest.raises(ValueError, match="nearer than any 100 mm lens can focus"):
        ThinLensCamera(focal_length_mm=100.0, focus_distance_m=0.39).validate()
    ThinLensCamera(focal_length_mm=100.0, focus_distance_m=0.4).validate()  # 1:1
    path = tmp_path / "scene.json"
    path.write_text(json.dumps({"lenslab_scene": 2, "camera": {"focal_length_mm": 100, "focus_distance_m": 0.3}}))
    with pytest.raises(SceneError, match=r"scene.json: camera: focus_distance_m 0.3 m from the sensor is nearer than any 100 mm lens"):
        load_scene(path)


def test_a_version_1_scene_keeps_its_meaning_and_saves_as_the_current_version(tmp_path):
    path = tmp_path / "old.json"
    path.write_text(json.dumps({"lenslab_scene": 1, "camera": {"focal_length_mm": 50, "focus_distance_m": 1.5,
                                                                "resolution": [60, 90]}}))
    old = load_scene(path).camera
    assert (old.focus_from, old.focus_breathing, old.sensor_fit) == ("lens", False, "horizontal")
    assert old.plane_of_focus_m == 1.5 and old.frame().tan_half_fov[0] == pytest.approx(0.36)
    save_scene(load_scene(path), tmp_path / "new.json")
    assert json.loads((tmp_path / "new.json").read_text())["lenslab_scene"] == FORMAT_VERSION
    again = load_scene(tmp_path / "new.json").camera
    assert again.frame().tan_half_fov == pytest.approx(old.frame().tan_half_fov)
    path.write_text(json.dumps({"lenslab_scene": 1, "camera": {"sensor_fit": "fill"}}))
    with pytest.raises(SceneError, match="camera.sensor_fit: unknown key in a version 1 scene"):
        load_scene(path)


def test_the_depth_of_field_readout_is_where_the_rendered_blur_equals_the_circle_of_confusion():
    camera = ThinLensCamera(position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, -1.0), focal_length_mm=50.0, f_number=2.8,
                            focus_distance_m=2.0, aperture_blades=7, resolution=(600, 400))
    dof = camera.depth_of_field()
    frame = camera.frame()
    mm_per_pixel = frame.film_mm[0] / frame.width
    v = camera.image_distance_mm
    for reading in (dof.near_m, dof.far_m):
        depth = reading - v / 1000  # the readout is from the sensor
        # Project the point through the two ends of a diameter of the round f/N stop onto the sensor: the
        # distance between the two images is the blur (worked out from the rays' geometry alone).
        point = np.array([0.0, 0.0, -depth])
        images = []
        for x in (-1.0, 1.0):
            lens = np.array([x * frame.lens_radius, 0.0, 0.0])
            towards = point - lens
            at_focus = lens + towards * (frame.focus_distance / depth)
            images.append(at_focus[0] / frame.focus_distance * v)  # on the sensor, mm (pinhole through the centre)
        assert abs(images[1] - images[0]) == pytest.approx(camera.coc_mm(), rel=1e-9)
        assert mm_per_pixel > 0


# -- aperture shapes, measured on rendered point lights -----------------------------------------------------
BOKEH_PIXELS = 48


def render_bokeh(renderer, spp=2048, **aperture):
    """A small lamp 5 m away, the camera focused at 0.25 m from the lens with the sensor held at f: its bokeh is the
    aperture's shape about 30 pixels across, as seen from behind the camera (a point beyond the plane of focus)."""
    camera = axis_camera(focal_length_mm=50.0, f_number=2.0, focus_distance_m=0.25, focus_from="lens",
                         focus_breathing=False, sensor_mm=(7.5, 7.5), resolution=(BOKEH_PIXELS, BOKEH_PIXELS),
                         **aperture)
    job = RenderJob(renderer, point_light_scene(5.0, 0.02, camera), spp=spp)
    image = job.run()[..., 0]
    job.release()
    return image


def bokeh_mask(image):
    plateau = np.median(image[image > 0.2 * image.max()])
    return image > 0.5 * plateau


def moments(mask):
    """Area in pixels, the ratio of the long to the short axis and the long axis' angle from +x (radians, image
    +y up)."""
    ys, xs = np.nonzero(mask)
    x, y = xs - xs.mean(), -(ys - ys.mean())
    cov = np.cov(np.stack([x, y]))
    values, vectors = np.linalg.eigh(cov)
    long_axis = vectors[:, 1]
    return mask.sum(), math.sqrt(values[1] / values[0]), math.atan2(long_axis[1], long_axis[0]) % math.pi


def test_every_stop_shape_passes_the_light_of_the_round_stop(renderer):
    round_stop = render_bokeh(renderer)
    expected_area = moments(bokeh_mask(round_stop))[0]
    assert 550 < expected_area < 850  # ~30 pixels across
    for shape in (dict(aperture_blades=5), dict(aperture_blades=7, blade_curvature=0.6),
                  dict(anamorphic_squeeze=2.0)):
        bokeh = render_bokeh(renderer, **shape)
        assert bokeh.sum() == pytest.approx(round_stop.sum(), rel=0.03), shape  # the same light
        assert moments(bokeh_mask(bokeh))[0] == pytest.approx(expected_area, rel=0.06), shape  # the same area


def test_anamorphic_squeeze_makes_oval_bokeh_standing_upright(renderer):
    area, aspect, angle = moments(bokeh_mask(render_bokeh(renderer, anamorphic_squeeze=2.0)))
    assert aspect == pytest.approx(2.0, rel=0.08)
    assert angle == pytest.approx(math.pi / 2, abs=0.05)
    _, aspect, _ = moments(bokeh_mask(render_bokeh(renderer, anamorphic_squeeze=0.5)))
    assert aspect == pytest.approx(2.0, rel=0.08)


def edge_profile(mask, blades, rotation):
    """The bokeh's radius towards the corners and towards the middles of the edges, pixels (from its centroid)."""
    ys, xs = np.nonzero(mask)
    cx, cy = xs.mean(), ys.mean()
    angles = np.arctan2(-(ys - cy), xs - cx)
    radii = np.hypot(xs - cx, ys - cy)

    def reach(direction):
        near = np.abs((angles - direction + np.pi) % (2 * np.pi) - np.pi) < 0.06
        return np.percentile(radii[near], 95)

    corners = [reach(rotation + 2 * np.pi * k / blades) for k in range(blades)]
    middles = [reach(rotation + 2 * np.pi * (k + 0.5) / blades) for k in range(blades)]
    return float(np.mean(corners)), float(np.mean(middles))


@pytest.mark.parametrize("curvature", [0.0, 0.5, 1.0])
def test_blade_curvature_rounds_the_edges_from_a_polygon_to_a_circle(renderer, curvature):
    blades, rotation = 5, math.radians(90.0)  # a corner straight up
    mask = bokeh_mask(render_bokeh(renderer, aperture_blades=blades, blade_rotation_deg=90.0,
                                   blade_curvature=curvature))
    corner, middle = edge_profile(mask, blades, rotation)
    ratio = middle / corner
    # Middle of an edge over corner radius: cos(pi/5) = 0.81 for straight blades, 1 for a circle, and for arcs of
    # radius 2 through the corners 0.905 (the arc's sagitta, worked out: 2 - sqrt(4 - sin^2(pi/5)) = 0.088).
    expected = {0.0: math.cos(math.pi / 5), 0.5: math.cos(math.pi / 5) + 2 - math.sqrt(4 - math.sin(math.pi / 5) ** 2),
                1.0: 1.0}[curvature]
    assert ratio == pytest.approx(expected, abs=0.045)


def test_the_blades_turn_with_their_rotation(renderer):
    """A triangle's corner points where the rotation says: its bokeh reaches furthest that way."""
    for rotation in (90.0, -90.0):
        mask = bokeh_mask(render_bokeh(renderer, aperture_blades=3, blade_rotation_deg=rotation))
        corner, middle = edge_profile(mask, 3, math.radians(rotation))
        assert corner > 1.6 * middle  # a triangle: corner 1, middle of the opposite edge cos(60) = 0.5


def test_barrel_clipping_gives_cats_eye_bokeh_and_darkens_the_corners(renderer):
    """A lamp near the frame's corner: the barrel's opening, shifted across the stop, cuts its bokeh into a cat's eye
    whose long axis is at right angles to the way to the centre, and takes light away (optical vignetting)."""
    images = {}
    for clipping in (0.0, 1.0):
        camera = axis_camera(focal_length_mm=50.0, f_number=2.0, focus_distance_m=0.25, focus_from="lens",
                             focus_breathing=False, sensor_mm=(24.0, 24.0), resolution=(144, 144),
                             barrel_clipping=clipping)
        scene = point_light_scene(5.0, 0.02, camera)
        scene.nodes[0].transform.translate = (0.8, 0.8, -5.0)  # 8 mm up and right of the sensor's centre
        job = RenderJob(renderer, scene, spp=1024)
        images[clipping] = job.run()[..., 0]
        job.release()
    _, round_aspect, _ = moments(bokeh_mask(images[0.0]))
    _, aspect, angle = moments(bokeh_mask(images[1.0]))
    assert round_aspect < 1.1 and aspect > 1.3  # the overlap of two disks, 0.67 of a radius apart
    assert angle == pytest.approx(3 * math.pi / 4, abs=0.15)  # long axis across the diagonal to the centre
    assert images[1.0].sum() < 0.8 * images[0.0].sum()


def test_an_aperture_image_shapes_the_bokeh(renderer, tmp_path):
    import OpenImageIO as oiio

    # A plus sign: five of the nine cells of a 3 x 3 grid.
    mask = np.zeros((30, 30), np.float32)
    mask[10:20, :] = 1.0
    mask[:, 10:20] = 1.0
    spec = oiio.ImageSpec(30, 30, 1, oiio.FLOAT)
    out = oiio.ImageOutput.create(str(tmp_path / "plus.exr"))
    out.open(str(tmp_path / "plus.exr"), spec)
    out.write_image(mask)
    out.close()
    camera = ThinLensCamera(aperture_image=str(tmp_path / "plus.exr"))
    assert camera.aperture().light_fraction == pytest.approx(4 * 5 / 9 / math.pi)
    bokeh = bokeh_mask(render_bokeh(renderer, aperture_image=str(tmp_path / "plus.exr")))
    ys, xs = np.nonzero(bokeh)
    cx, cy = int(round(xs.mean())), int(round(ys.mean()))
    span = xs.max() - xs.min()
    third = span / 3
    # The centre and the arms are lit, the four corners of the plus's square are dark.
    assert bokeh[cy, cx] and bokeh[cy, int(cx + third)] and bokeh[int(cy - third), cx]
    for dx, dy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        assert not bokeh[int(cy + dy * third), int(cx + dx * third)]
    assert bokeh.sum() == pytest.approx(5 / 9 * span ** 2, rel=0.15)


def test_a_missing_aperture_image_is_named_when_the_scene_opens(tmp_path):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps({"lenslab_scene": 2, "camera": {"aperture_image": "star.png"}}))
    with pytest.raises(SceneError, match=r"camera.aperture_image: aperture image not found: .*star.png"):
        load_scene(path)


# -- exposure ----------------------------------------------------------------------------------------------
def test_in_the_physical_mode_each_stop_of_aperture_is_a_stop_of_light(renderer, tmp_path):
    from tests.scenes import furnace_scene

    values = {}
    for mode, f_number in (("compensated", 2 ** 1.5), ("compensated", 4.0), ("physical", 2 ** 1.5),
                           ("physical", 4.0)):
        scene = furnace_scene(max_depth=1)
        scene.camera.exposure_mode, scene.camera.f_number = mode, f_number
        scene.camera.iso, scene.camera.shutter_s = 400.0, 1 / 30
        job = RenderJob(renderer, scene, spp=4)
        job.run()
        path = job.write(tmp_path / f"{mode}-{f_number:.2f}.exr")
        job.release()
        pixels, metadata = read_image(path)
        values[mode, f_number] = pixels.mean()
        if mode == "physical":
            assert metadata["ExposureTime"] == pytest.approx(1 / 30) and metadata["Exif:PhotographicSensitivity"] == 400
            # The sky's radiance is 1: the exposure scale 0.18 t S / (K N^2), K = 12.5 (ISO 2720's reflected-light
            # meter: its reading lands at middle grey, lenslab.optics.exposure).
            assert metadata["lenslab:ExposureScale"] == pytest.approx(0.18 * (1 / 30) * 400 / (12.5 * f_number ** 2),
                                                                      rel=1e-6)
    assert values["compensated", 4.0] == pytest.approx(values["compensated", 2 ** 1.5], rel=0.02)
    assert values["physical", 2 ** 1.5] / values["physical", 4.0] == pytest.approx(2.0, rel=0.02)


# -- what the files say ------------------------------------------------------------------------------------
def test_exported_files_carry_the_camera(renderer, tmp_path):
    camera = ThinLensCamera(position=(0.3, 0.2, 1.0), look_at=(0.0, 0.0, -3.0), resolution=(40, 30),
                            f_number=2 ** 3.5, exposure_mode="physical", iso=200.0, shutter_s=0.5)
    scene = point_light_scene(3.0, 0.1, camera)
    job = RenderJob(renderer, scene, spp=1)
    job.run()
    exr, png = job.write(tmp_path / "shot.exr"), job.write(tmp_path / "shot.png")
    frame = job.session.frame
    job.release()
    _, meta = read_image(exr)
    assert meta["chromaticities"] == pytest.approx((0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290), abs=1e-6)
    # worldToNDC takes a world point to where it is in the image: the pixel a ray through (13.5, 7.25) hits.
    origins, directions = frame.rays([(13.5, 7.25)])
    point = np.append(origins[0] + 2.7 * directions[0], 1.0)
    ndc = point @ np.asarray(meta["worldToNDC"]).reshape(4, 4)
    assert ndc[:2] / ndc[3] == pytest.approx((13.5 / 40, 7.25 / 30), abs=1e-5)
    camera_space = point @ np.asarray(meta["worldToCamera"]).reshape(4, 4)
    assert camera_space[2] == pytest.approx(frame.depth_of(point[:3]), abs=1e-5)  # z: the viewing direction
    _, meta = read_image(png)
    assert meta["FNumber"] == pytest.approx(2 ** 3.5, rel=1e-6) and meta["lenslab:Aperture"] == "f/11"
    assert meta["ExposureTime"] == pytest.approx(0.5) and meta["Exif:PhotographicSensitivity"] == 200
    assert meta["lenslab:SamplesPerPixel"] == "1" and meta["lenslab:Seed"] == str(scene.render.seed)
    assert meta["lenslab:ExposureMode"] == "physical"


def test_every_shipped_lens_can_focus_as_close_as_it_is_marked():
    """A lens's marked minimum focus (from the sensor) is within reach of a thin lens: four focal lengths."""
    from lenslab.optics.lenses import load_lens_presets

    for lens in load_lens_presets(include_user=False):
        if lens.min_focus_distance_m is not None:
            assert lens.min_focus_distance_m >= 4 * lens.max_focal_length_mm / 1000, lens.name
