"""Real lenses traced through their glass (optics/lens_system.py, glsl/real_lens.glsl): the shader against the
host, and both against the optics (paraxial constants, focus, vignetting) checked by an independent tracer."""
from __future__ import annotations

import numpy as np
import pytest

from lenslab.optics.lenses import load_lens_presets
from lenslab.scene.camera import ThinLensCamera
from tests.test_camera_rays import shader_rays

REAL_LENSES = [lens for lens in load_lens_presets(include_user=False) if lens.is_real]


def mounted_camera(lens, **settings) -> ThinLensCamera:
    camera = ThinLensCamera(position=(0.3, 1.2, 4.0), look_at=(0.0, 1.0, 0.0), resolution=(300, 200),
                            focus_distance_m=3.0)
    for name, value in lens.mount(lens.focal_length_mm, lens.widest_f_number).items():
        setattr(camera, name, value)
    for name, value in settings.items():
        setattr(camera, name, value)
    return camera


def test_four_real_lenses_ship():
    assert {round(lens.focal_length_mm) for lens in REAL_LENSES} >= {10, 22, 50, 250}


@pytest.mark.parametrize("lens", REAL_LENSES, ids=lambda lens: lens.name)
def test_the_shader_traces_the_glass_as_the_host_does(renderer, lens):
    camera = mounted_camera(lens, aperture_blades=6, blade_curvature=0.3)
    rng = np.random.default_rng(7)
    width, height = 300, 200
    items = np.column_stack([rng.random(400) * width, rng.random(400) * height, rng.random((400, 2))])
    origins, directions, weights = shader_rays(renderer, camera, width, height, items, with_weights="colour")
    expected_origins, expected_directions, expected_weights = camera.frame(width, height).rays(
        items[:, :2], items[:, 2:], with_weights=True)
    through = expected_weights.max(axis=1) > 0
    assert through.mean() > 0.3  # the pupil table wastes few samples
    # A ray grazing a rim or the stop may go either way in float32: nearly all agree.
    agree = (weights.max(axis=1) > 0) == through
    assert agree.mean() > 0.99
    both = agree & through
    assert np.allclose(origins[both], expected_origins[both], atol=2e-5)
    assert np.allclose(directions[both], expected_directions[both], atol=2e-4)
    assert np.allclose(weights[both], expected_weights[both], rtol=2e-3, atol=1e-4)


# -- on the command line and in scene files ----------------------------------------------------------------------
DOUBLE_GAUSS_ROWS = """# a double-Gauss as pbrt's lens files write it: radius, thickness, index (0: air), aperture
29.475\t3.76\t1.67\t25.2
84.83\t0.12\t1\t25.2
19.275\t4.025\t1.67\t23
40.77\t3.275\t1.699\t23
12.75\t5.705\t1\t18
0\t4.5\t0\t17.1
-14.495\t1.18\t1.603\t17
40.77\t6.065\t1.658\t20
-20.385\t0.19\t1\t20
437.065\t3.22\t1.717\t20
-39.73\t0\t1\t20
"""


def test_the_command_line_mounts_a_real_lens_and_the_file_names_it(renderer, tmp_path, capsys):
    from lenslab.render.film import read_image
    from tests.helpers import run_cli

    out = tmp_path / "shot.exr"
    run = run_cli(capsys, "cornell_box", "--headless", "-o", out, "--lens", "50 mm f/2 double-Gauss", "--f-number",
                  "4", "--focus-distance", "1.5", "--spp", "2", "--width", "48", "--height", "48")
    assert run.status == 0, run.err
    pixels, metadata = read_image(out)
    assert metadata["Exif:LensModel"] == "50 mm f/2 double-Gauss"
    assert metadata["Exif:FocalLength"] == pytest.approx(50.358, abs=0.01)  # the glass's, not the name's
    assert float(metadata["lenslab:RealLensFocusShiftMM"]) > 1.0  # it moved forward to focus at 1.5 m
    # The thin lens's stand-ins did nothing: the file does not claim them.
    assert "lenslab:AnamorphicSqueeze" not in metadata and "lenslab:BarrelClipping" not in metadata
    assert np.isfinite(pixels).all() and pixels.mean() > 0.01


def test_a_pbrt_lens_file_is_a_lens_on_the_command_line(renderer, tmp_path, capsys):
    from lenslab.render.film import read_image
    from tests.helpers import run_cli

    lens_file = tmp_path / "dgauss.50mm.dat"
    lens_file.write_text(DOUBLE_GAUSS_ROWS)
    out = tmp_path / "shot.exr"
    # Its glass traces to f/2.03, a 50.36 mm: marked (and typed) as the f/2 50 mm it is.
    run = run_cli(capsys, "cornell_box", "--headless", "-o", out, "--lens", lens_file, "--spp", "1", "--width", "32",
                  "--height", "32", "--f-number", "2", "--focal-length", "50")
    assert run.status == 0, run.err
    _, metadata = read_image(out)
    assert metadata["Exif:LensModel"] == "dgauss.50mm" and metadata["lenslab:RealLensFile"] == str(lens_file)
    assert metadata["Exif:FocalLength"] == pytest.approx(50.358, abs=0.01) and metadata["FNumber"] == 2.0


@pytest.mark.parametrize("argv, words, status", [
    (["--lens", "50 mm f/2 double-Gauss", "--f-number", "1.4"], "f/1.4 is not on the lens", 2),
    (["--lens", "50 mm f/2 double-Gauss", "--focal-length", "35"], "not on the lens '50 mm f/2 double-Gauss' "
     "(50.36 mm)", 2),
    (["--lens", "50 mm f/2 double-Gauss", "--anamorphic-squeeze", "2"], "applies to the thin lens only", 1),
    (["--lens", "50 mm f/2 double-Gauss", "--focus-distance", "0.1"], "nearer than", 1),
])
def test_what_a_real_lens_cannot_do_is_refused_in_one_line(tmp_path, capsys, argv, words, status):
    """Exit 2 for what the options alone refuse, 1 for a camera the scene and the options together cannot make
    (as for the thin lens: tests/test_cli.py)."""
    from tests.helpers import run_cli

    run = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.exr", *argv)
    assert run.status == status and words in run.err and len(run.err.strip().splitlines()) == 1, run.err
    assert not (tmp_path / "x.exr").exists()


def test_a_broken_lens_file_is_named_with_its_line(tmp_path, capsys):
    from tests.helpers import run_cli

    lens_file = tmp_path / "broken.dat"
    lens_file.write_text(DOUBLE_GAUSS_ROWS.replace("40.77\t6.065", "40.77\tsix"))
    run = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.exr", "--lens", lens_file)
    assert run.status == 2 and "broken.dat" in run.err and "line 9" in run.err, run.err
    assert run.err.count("broken.dat") == 1 and len(run.err.strip().splitlines()) == 1


def test_a_scene_names_its_lens_file_relative_to_itself(tmp_path):
    import json

    from lenslab.scene.io.loader import open_scene

    (tmp_path / "lenses").mkdir()
    (tmp_path / "lenses" / "dg.dat").write_text(DOUBLE_GAUSS_ROWS)
    scene = {"lenslab_scene": 2, "camera": {"real_lens": "lenses/dg.dat", "focal_length_mm": 50.358, "f_number": 2.8,
                                      "focus_distance_m": 2.0}}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    camera = open_scene(tmp_path / "scene.json").camera
    assert camera.lens_system().name == "dg"
    assert camera.frame(64, 48).real_lens.shift > 0.5


# -- the exit pupil's table ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("lens", REAL_LENSES, ids=lambda lens: lens.name)
@pytest.mark.parametrize("stop", ["widest", 8.0, 22.0])
def test_the_pupil_table_holds_every_ray_that_gets_through(lens, stop):
    """Unbiased only if no ray that gets through the glass falls outside the box (or disk) its film point samples:
    a dense grid over the whole rear element, from film points across the image (at every channel's wavelength),
    and every ray that gets out must have started inside its bin's region. And few samples are wasted where the
    lens passes light at all."""
    from lenslab.optics.lens_system import PUPIL_BINS, trace_from_film
    from lenslab.optics.real_lenses import system_for

    system = system_for(lens.prescription)
    f_number = lens.widest_f_number if stop == "widest" else stop
    setting = system.setting(f_number, 2000.0, (36.0, 24.0))
    rear = system.aperture_radius[-1] * 1.5
    grid = np.linspace(-rear, rear, 121)
    gx, gy = (a.ravel() for a in np.meshgrid(grid, grid))
    rng = np.random.default_rng(11)
    for radius in rng.random(12) * setting.film_radius_mm:
        film = np.tile([radius, 0.0, setting.sensor_z], (len(gx), 1))
        target = np.stack([gx, gy, np.full_like(gx, setting.rear_z)], axis=-1)
        directions = (target - film) / np.linalg.norm(target - film, axis=-1, keepdims=True)
        passed = np.zeros(len(gx), bool)
        for ior in system.channel_iors().T:
            passed |= trace_from_film(system, film, directions, setting.shift, setting.stop_radius, ior,
                                      setting.stop_contains)[2]
        b = min(int(radius / setting.film_radius_mm * PUPIL_BINS), PUPIL_BINS - 1)
        x0, y0, x1, y1 = setting.pupil_bounds[b]
        cx, cy, r, on_disk = setting.pupil_disks[b]
        xs, ys = gx[passed], gy[passed]
        if on_disk:
            assert (np.hypot(xs - cx, ys - cy) <= r + 1e-9).all()
        else:
            assert ((xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1)).all()
    # Few samples wasted: of the samples of pixels that see anything, most get through.
    pixels = rng.random((20000, 2)) * [300, 200]
    frame = mounted_camera(lens, f_number=f_number).frame(300, 200)
    _, _, weights = frame.rays(pixels, rng.random((20000, 2)), with_weights=True)
    lit = frame.real_lens.pupil_bounds[np.minimum(
        (np.hypot(*frame.real_lens.film_points(pixels, 300, 200)[:, :2].T) / frame.real_lens.film_radius_mm
         * PUPIL_BINS).astype(int), PUPIL_BINS - 1), 2] != 0
    assert (weights[lit].max(axis=1) > 0).mean() > 0.5


# -- where a pixel looks: click-to-focus and picking ---------------------------------------------------------------
def test_click_to_focus_through_glass_makes_the_clicked_point_sharp():
    """Click-to-focus sets the focus reading that puts the plane of focus at the clicked depth (from the camera's
    position, where the depth buffer measures): the rays the centre pixel sends through every part of the pupil
    then meet again at that point, to within what the lens's aberrations leave (under a millimetre at 2 m)."""
    lens = next(lens for lens in REAL_LENSES if lens.name.startswith("50 mm"))
    camera = mounted_camera(lens)
    depth = 2.0
    camera.focus_distance_m = camera.focus_setting_for(depth)
    assert camera.plane_of_focus_m == pytest.approx(depth)
    frame = camera.frame(300, 200)
    rng = np.random.default_rng(2)
    origins, directions, weights = frame.rays(np.tile([150.0, 100.0], (400, 1)), rng.random((400, 2)),
                                              with_weights=True)
    through = weights.max(axis=1) > 0
    target = frame.position + depth * frame.forward
    to_target = target - origins[through]
    along = np.einsum("ij,ij->i", to_target, directions[through])
    miss = np.linalg.norm(to_target - along[:, None] * directions[through], axis=1)
    assert through.mean() > 0.5 and np.sqrt(np.mean(miss ** 2)) < 1e-3
    # Focused at 1 m, the same rays miss the point by millimetres: the test can tell.
    camera.focus_distance_m = camera.focus_setting_for(1.0)
    origins, directions, _ = camera.frame(300, 200).rays(np.tile([150.0, 100.0], (400, 1)), rng.random((400, 2)),
                                                         with_weights=True)
    to_target = target - origins
    along = np.einsum("ij,ij->i", to_target, directions)
    assert np.sqrt(np.mean(np.linalg.norm(to_target - along[:, None] * directions, axis=1) ** 2)) > 0.005


def test_a_pixel_beyond_the_fisheyes_image_circle_looks_nowhere():
    """The corners of a full-frame image through the 10 mm fisheye lie outside its image circle: no chief ray leaves
    the lens from there, so picking and the depth buffer find nothing (weight 0), while the centre looks ahead."""
    lens = next(lens for lens in REAL_LENSES if lens.name.startswith("10 mm"))
    frame = mounted_camera(lens).frame(300, 200)
    _, directions, looks_out = frame.rays([(0.5, 0.5), (150.0, 100.0)], with_weights=True)
    assert looks_out[0].max() == 0.0 and looks_out[1].min() == 1.0
    assert directions[1] @ frame.forward == pytest.approx(1.0, abs=1e-3)


def test_dispersion_off_traces_every_colour_at_the_d_line(tmp_path, capsys, renderer):
    """A preview without the colour noise: with dispersion off, a dispersive lens's samples weigh all three
    channels alike and follow the same path whatever their first third of u.x; on, one channel at a time (3, 0, 0
    and so on). The command line says --no-dispersion and the file records it."""
    from lenslab.render.film import read_image
    from tests.helpers import run_cli

    lens = next(lens for lens in REAL_LENSES if lens.name.startswith("50 mm"))
    rng = np.random.default_rng(4)
    pixels, u = rng.random((300, 2)) * [300, 200], rng.random((300, 2))
    _, _, on = mounted_camera(lens).frame(300, 200).rays(pixels, u, with_weights=True)
    _, _, off = mounted_camera(lens, dispersion=False).frame(300, 200).rays(pixels, u, with_weights=True)
    lit = on.max(axis=1) > 0
    assert ((on[lit] > 0).sum(axis=1) == 1).all() and np.allclose(on[lit].max(axis=1) / 3.0, on[lit].sum(axis=1) / 3.0)
    lit_off = off.max(axis=1) > 0
    assert np.allclose(off[lit_off, 0], off[lit_off, 1]) and np.allclose(off[lit_off, 1], off[lit_off, 2])
    out = tmp_path / "preview.exr"
    run = run_cli(capsys, "cornell_box", "--headless", "-o", out, "--lens", "50 mm f/2 double-Gauss",
                  "--no-dispersion", "--spp", "1", "--width", "16", "--height", "16")
    assert run.status == 0, run.err
    _, metadata = read_image(out)
    assert int(metadata["lenslab:Dispersion"]) == 0 and int(metadata["lenslab:RealLensDispersive"]) == 0
