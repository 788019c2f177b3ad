"""The headless command line: renders, metadata, and every error path (one line on stderr, no traceback)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lenslab.cli import main
from lenslab.render.film import read_image
from tests.helpers import run_cli

SMALL = ["--spp", "2", "--width", "32", "--height", "24"]


def test_headless_exr_is_linear_float_with_camera_metadata(renderer, tmp_path, capsys):
    out = tmp_path / "shot.exr"
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", out, *SMALL, "--f-stop", "2.8",
                          "--focal-length", "35", "--focus-distance", "1.5", "--seed", "7")
    assert status == 0, err
    pixels, meta = read_image(out)
    assert pixels.shape == (24, 32, 3) and pixels.dtype == np.float32
    assert pixels.max() > 1.0  # linear radiance: the light is brighter than display white
    assert meta["FNumber"] == pytest.approx(2 ** 1.5)  # --f-stop 2.8: the exact stop
    assert meta["Exif:FocalLength"] == pytest.approx(35.0)
    assert meta["Exif:SubjectDistance"] == pytest.approx(1.5)
    assert meta["lenslab:SensorWidthMM"] == pytest.approx(36.0) and meta["lenslab:SensorHeightMM"] == pytest.approx(24.0)
    assert meta["lenslab:ImageHeightMM"] == pytest.approx(36.0 * 24 / 32)  # the picture: 32 x 24 pixels
    assert meta["lenslab:SamplesPerPixel"] == 2 and meta["lenslab:Seed"] == 7
    assert meta["Software"].startswith("LensLab ")
    assert "wrote" in err and "\n" == err[-1]


def test_headless_png_is_the_exr_through_the_view_transform(renderer, tmp_path, capsys):
    from lenslab.colour_management.view import ViewTransform
    from lenslab.render.film import display_pixels

    for suffix in (".exr", ".png"):
        status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / f"shot{suffix}", *SMALL,
                              "--display", "Display P3 - Display", "--look", "ACES 1.3 Reference Gamut Compression",
                              "--exposure", "1", "--contrast", "1.2")
        assert status == 0, err
    linear, _ = read_image(tmp_path / "shot.exr")
    display, metadata = read_image(tmp_path / "shot.png")
    assert display.shape == (24, 32, 3)
    # The same seed gives the same samples: the PNG is the EXR through OCIO's view, a stop brighter, 8 bits.
    view = ViewTransform(display="Display P3 - Display", looks="ACES 1.3 Reference Gamut Compression",
                         exposure_stops=1.0, contrast=1.2)
    assert np.abs(display - display_pixels(linear, view)).max() <= 0.5 / 255 + 1e-6
    assert np.abs(display - display_pixels(linear)).max() > 0.05  # and not the default view: the options took effect
    assert metadata["lenslab:Display"] == "Display P3 - Display"
    assert metadata["lenslab:View"] == "ACES 2.0 - SDR 100 nits (P3 D65)"  # the display's default view, named


def test_the_old_tone_map_names_are_views(renderer, tmp_path, capsys):
    """--tone-map is an older name of --view; clamp is the un-tone-mapped view, filmic the display's default."""
    from lenslab.colour_management.view import ViewTransform
    from lenslab.render.film import display_pixels

    for name in ("exr", "clamp", "filmic"):
        args = ("--tone-map", name) if name != "exr" else ()
        status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / f"{name}.{'exr' if name == 'exr' else 'png'}",
                              *SMALL, *args)
        assert status == 0, err
    linear, _ = read_image(tmp_path / "exr.exr")
    for name, view in (("clamp", "Un-tone-mapped"), ("filmic", "")):
        picture, metadata = read_image(tmp_path / f"{name}.png")
        assert np.abs(picture - display_pixels(linear, ViewTransform(view=view))).max() <= 0.5 / 255 + 1e-6
    status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / "r.png", *SMALL, "--tone-map", "reinhard")
    assert status != 0 and "reinhard" in err and "Un-tone-mapped" in err and not (tmp_path / "r.png").exists()


def test_time_limit_alone_renders_what_fits(renderer, tmp_path, capsys):
    out = tmp_path / "quick.exr"
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", out, "--width", "16", "--height", "16",
                          "--time-limit", "0.5")
    assert status == 0, err
    _, meta = read_image(out)
    assert meta["lenslab:SamplesPerPixel"] >= 1


def test_a_time_limit_shorter_than_one_pass_still_samples_every_pixel(renderer, tmp_path, capsys):
    # 65,536 pixels: more than the first dispatch takes, so the pass cannot end inside the limit.
    out = tmp_path / "short.exr"
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", out, "--width", "256", "--time-limit", "0.001")
    assert status == 0, err
    pixels, meta = read_image(out)
    assert pixels.shape == (256, 256, 3)
    assert meta["lenslab:SamplesPerPixel"] == 1
    # At 1 spp some paths find no light (a few percent of the ceiling's); a band of rows without a sample finds none.
    lit_per_band = (pixels.sum(axis=2) > 0).reshape(32, 8 * 256).mean(axis=1)
    assert lit_per_band.min() > 0.01, f"rows {8 * lit_per_band.argmin()}+ are black"
    assert "the time limit ended before every pixel had a sample" in err and "1 spp" in err


@pytest.mark.parametrize(
    "argv, message",
    [
        (["cornell_box", "--headless", "-o", "x.png", "--f-stop", "0"],
         r"argument --f-number/--f-stop: f-number out of range \[1e-06, 1e\+06\]: .0."),  # the older flag still read
        (["cornell_box", "--headless", "-o", "x.png", "--spp", "many"], r"--spp: expected a whole number, not 'many'"),
        (["cornell_box", "--headless", "-o", "x.png", "--spp", "-1"], r"--spp: -1 is out of range \[1, 16777216\]"),
        (["cornell_box", "--headless", "-o", "x.png", "--focus-distance", "-2"], r"--focus-distance: -2 is out of range"),
        (["cornell_box", "--headless", "-o", "x.png", "--width", "0"], r"--width: 0 is out of range"),
        (["cornell_box", "--headless", "-o", "."], r"\. is a folder: name the image file, e.g\. render\.exr"),
        (["cornell_box", "--headless", "-o", "x.png", "--bokeh"], r"unrecognized arguments: --bokeh"),
        (["cornell_box", "--headless"], r"--headless needs an output file"),
        (["--headless", "-o", "x.png"], r"--headless needs a scene"),
        (["cornell_box", "--headless", "-o", "x.bmp"],
         r"x\.bmp: unsupported output type '\.bmp' \(use \.exr, \.png, \.tif, \.tiff, \.jpg or \.jpeg\)"),
        (["cornell_box", "--headless", "-o", "no/such/dir/x.png"], r"folder 'no/such/dir' does not exist"),
        (["no_such_scene", "--headless", "-o", "x.png"], r"no_such_scene: no such scene file \(or a shipped scene: cornell_box"),
    ],
)
def test_bad_arguments_exit_non_zero_with_one_line(tmp_path, monkeypatch, capsys, argv, message):
    import re

    monkeypatch.chdir(tmp_path)
    status, err = run_cli(capsys, *argv)
    assert status != 0
    assert err.count("\n") == 1 and err.startswith("lenslab: error: ")
    assert re.search(message, err), err
    assert list(tmp_path.iterdir()) == []


def test_output_problems_name_the_file_the_user_asked_for(tmp_path, capsys):
    (tmp_path / "file.png").write_bytes(b"")
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "file.png" / "x.png")
    assert status == 1 and f"'{tmp_path / 'file.png'}' is a file, not a folder" in err
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    if os.access(locked, os.W_OK):  # root writes anywhere: let the temporary file fail to be made instead
        target = Path("/proc/x.png")
    else:
        target = locked / "x.png"
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", target, "--spp", "1", "--width", "8")
    assert status == 1 and err.count("\n") == 1
    assert str(target) in err and f"{target.parent}" in err and "/." not in err  # not our temporary name


def test_scene_errors_found_when_packing_name_the_scene_file(tmp_path, capsys):
    for name, changes, message in (
        ("two_suns.json", {"lights": [{"type": "sun", "name": "a"}, {"type": "sun", "name": "b"}]},
         "lights: only one sun per scene (found 'a', 'b')"),
        ("ellipsoid.json", {"nodes": [{"name": "egg", "shape": {"type": "sphere", "radius": 0.5},
                                       "transform": {"scale": [1, 2, 1]}}]},
         "node 'egg': a sphere needs a uniform scale, not (1, 2, 1)"),
    ):
        scene = tmp_path / name
        scene.write_text(json.dumps({"lenslab_scene": 1} | changes))
        status, err = run_cli(capsys, scene, "--headless", "-o", tmp_path / "x.png")
        assert status == 1 and err.startswith(f"lenslab: error: {scene}: {message}"), err
    assert not (tmp_path / "x.png").exists()


def test_exposure_on_an_exr_is_a_warning(tmp_path, capsys):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.exr", "--exposure", "1",
                          "--spp", "1", "--width", "8")
    assert status == 0 and "lenslab: warning: --exposure applies to pictures only" in err


def test_broken_scene_exits_with_file_and_key(tmp_path, capsys):
    scene = tmp_path / "broken.json"
    scene.write_text(json.dumps({"lenslab_scene": 1, "camera": {"f_number": "wide"}}))
    status, err = run_cli(capsys, scene, "--headless", "-o", tmp_path / "x.png")
    assert status == 1
    assert err.strip() == f'lenslab: error: {scene}: camera.f_number: expected a number, got "wide"'
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("failure, package", [
    ("libEGL.so.1: cannot open shared object file: No such file or directory", "libegl1"),
    ("libEGL.so not loaded", "libegl1"),  # moderngl's own words
    ("libGL.so not loaded", "libgl1"),
    ("libOpenGL.so.0 not loaded", "libopengl0"),
])
def test_missing_gl_driver_is_one_line_with_the_packages_to_install(tmp_path, monkeypatch, capsys, failure,
                                                                    package):
    import moderngl

    def no_egl(**kwargs):
        raise Exception(failure)

    monkeypatch.setattr(moderngl, "create_context", no_egl)
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png")
    assert status == 1
    assert err.count("\n") == 1
    assert f"is missing: on Debian/Ubuntu `apt-get install {package}`" in err
    assert "apt-get install libegl1 libgl1 libopengl0 libegl-mesa0 libgl1-mesa-dri" in err
    status, err = run_cli(capsys, "--info")
    assert status == 1 and "apt-get install" in err


def test_interrupted_render_writes_nothing(renderer, tmp_path, monkeypatch, capsys):
    from lenslab.render.tracer import RenderSession

    calls = []
    real_step = RenderSession.step

    def step_then_interrupt(self, seconds, target_spp=None):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt  # what Ctrl-C raises in the main thread
        return real_step(self, seconds, 1)  # one pass only, however fast the device: the render is mid-way

    monkeypatch.setattr(RenderSession, "step", step_then_interrupt)
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.exr", "--spp", "1000",
                          "--width", "16", "--height", "16")
    assert status == 130
    assert err.strip() == "lenslab: interrupted; nothing was written"
    assert list(tmp_path.iterdir()) == []  # neither the image nor a temporary file


def test_info_prints_the_gl_renderer_and_limits(renderer, capsys):
    run = run_cli(capsys, "--info")
    status, out = run.status, run.out
    assert status == 0
    assert "renderer" in out and renderer.ctx.info["GL_RENDERER"] in out
    assert "max storage block" in out and "MiB" in out


@pytest.mark.parametrize("renderer_name, version, advised", [
    ("llvmpipe (LLVM 15.0.6, 256 bits)", "4.5 (Core Profile) Mesa 22.3.6", True),
    ("llvmpipe (LLVM 15.0.6, 256 bits)", "4.5 (Core Profile) Mesa 25.0.7-2~bpo12+1", False),
    ("NVIDIA H100 80GB HBM3/PCIe/SSE2", "4.6.0 NVIDIA 550.54.15", False),
    ("AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 15.0.6)", "4.6 (Core Profile) Mesa 22.3.6", False),
])
def test_info_advises_a_newer_mesa_only_for_an_old_llvmpipe(renderer_name, version, advised):
    from lenslab.render.gl import slow_driver_note

    note = slow_driver_note(renderer_name, version)
    assert (note is not None) == advised
    if advised:
        assert "Mesa 22" in note and "bookworm-backports" in note


def test_help_speaks_photography(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--help"])
    assert info.value.code == 0
    text = capsys.readouterr().out
    for phrase in ("--f-number", "--f-stop", "f-number", "--focus-distance", "plane of focus", "--focal-length",
                   "millimetres"):
        assert phrase in text


def test_headless_in_a_real_process_never_imports_qt(renderer, tmp_path):
    code = (
        "import sys; from lenslab.cli import main; "
        f"status = main(['cornell_box', '--headless', '-o', {str(tmp_path / 'x.png')!r}, '--spp', '1', '--width', '8', '--height', '8']); "
        "assert 'PySide6' not in sys.modules, 'Qt was imported'; sys.exit(status)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    assert (tmp_path / "x.png").is_file()


MITSUBA_SCENE = """<scene version="3.0.0">
    <default name="spp" value="2"/>
    <default name="albedo" value="0.5"/>
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
            <rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="$albedo"/></bsdf></shape>
</scene>
"""


def test_mitsuba_scene_with_parameters_renders_headless(renderer, tmp_path, capsys):
    scene = tmp_path / "ball.xml"
    scene.write_text(MITSUBA_SCENE)
    out = tmp_path / "ball.exr"
    status, err = run_cli(capsys, scene, "--headless", "-o", out, "-D", "spp=3", "-D", "albedo=1")
    assert status == 0, err
    pixels, meta = read_image(out)
    assert pixels.shape == (16, 16, 3)
    assert meta["lenslab:SamplesPerPixel"] == 3  # from -D, over the file's default
    assert pixels[8, 8].mean() == pytest.approx(1.0, abs=0.2)  # albedo 1 under a white sky: a furnace


def test_bad_define_is_a_usage_error(tmp_path, capsys):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", "-D", "nonsense")
    assert status == 2 and "-D nonsense: expected NAME=VALUE" in err
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", "-D", "a=1")
    assert status == 1 and "-D parameters apply to Mitsuba XML scenes only" in err


def test_a_missing_texture_is_one_warning_and_the_render_goes_on(tmp_path, capsys):
    scene = tmp_path / "textured.json"
    scene.write_text(json.dumps({
        "lenslab_scene": 1,
        "materials": {"card": {"type": "diffuse", "albedo_texture": {"type": "image", "file": "nosuch.png"}}},
        "nodes": [{"name": "card", "shape": {"type": "rectangle"}, "material": "card",
                   "transform": {"translate": [0, 0, -3]}}],
    }))
    status, err = run_cli(capsys, scene, "--headless", "-o", tmp_path / "x.png", "--spp", "1", "--width", "8")
    assert status == 0 and (tmp_path / "x.png").exists()
    lines = [line for line in err.splitlines() if "nosuch.png" in line]
    assert lines == [f"lenslab: warning: {tmp_path / 'nosuch.png'}: texture file not found; "
                     "showing a magenta checkerboard instead"]


# -- the camera's own language -----------------------------------------------------------------------------
def test_every_camera_flag_reaches_the_rendered_camera(renderer, tmp_path, capsys):
    out = tmp_path / "shot.exr"
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", out, *SMALL, "--sensor", "aps-c",
                          "--sensor-fit", "fill", "--blades", "6", "--blade-curvature", "0.5", "--anamorphic",
                          "1.5", "--barrel-clipping", "0.3", "--coc", "0.02", "--iso", "800", "--shutter",
                          "1/30", "--f-stop", "f/4", "--focus-from", "lens", "--no-focus-breathing")
    assert status == 0, err
    _, meta = read_image(out)
    assert (meta["lenslab:SensorWidthMM"], meta["lenslab:SensorHeightMM"]) == pytest.approx((23.5, 15.6))
    assert meta["lenslab:SensorFit"] == "fill" and meta["lenslab:ImageHeightMM"] == pytest.approx(15.6)
    assert meta["lenslab:ApertureBlades"] == 6 and meta["lenslab:BladeCurvature"] == pytest.approx(0.5)
    assert meta["lenslab:AnamorphicSqueeze"] == pytest.approx(1.5)
    assert meta["lenslab:BarrelClipping"] == pytest.approx(0.3)
    assert meta["lenslab:CircleOfConfusionMM"] == pytest.approx(0.02)
    assert meta["lenslab:ExposureMode"] == "physical"  # --iso and --shutter imply it
    assert meta["ExposureTime"] == pytest.approx(1 / 30) and meta["Exif:PhotographicSensitivity"] == 800
    assert meta["FNumber"] == pytest.approx(4.0)
    assert meta["lenslab:FocusFrom"] == "lens" and meta["lenslab:FocusBreathing"] == 0
    assert meta["lenslab:PlaneOfFocusM"] == pytest.approx(meta["lenslab:FocusDistanceM"])


def test_a_lens_mounts_and_focus_nearer_than_it_can_is_refused(renderer, tmp_path, capsys):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "a.png", *SMALL,
                          "--lens", "85mm f/1.4", "--focus-distance", "0.5")
    assert status == 1
    assert err == ("lenslab: error: --focus-distance 0.5 m from the sensor is nearer than the 85 mm f/1.4 lens's "
                   "minimum focus of 0.8 m from the sensor\n")
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "b.exr", *SMALL,
                          "--lens", "85mm f/1.4")
    assert status == 0, err
    _, meta = read_image(tmp_path / "b.exr")
    assert meta["Exif:FocalLength"] == 85.0 and meta["lenslab:ApertureBlades"] == 11
    assert meta["lenslab:BladeCurvature"] == pytest.approx(0.8)  # the preset's blade roundness
    # No lens at all: nothing nearer than four focal lengths from the sensor.
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "c.png", *SMALL,
                          "--focal-length", "200", "--focus-distance", "0.5")
    assert status == 1 and "nearer than any 200 mm lens can focus: at least 0.8 m" in err and err.count("\n") == 1


@pytest.mark.parametrize("flag, value, message", [
    ("--blades", "2", "a stop has 0 blades (round) or at least 3"),
    ("--blade-curvature", "1.5", "out of range [0, 1]"),
    ("--anamorphic", "9", "out of range [0.25, 4]"),
    ("--shutter", "fast", "not a shutter time: 'fast'"),
    ("--iso", "-3", "out of range"),
    ("--sensor-fit", "stretch", "invalid choice: 'stretch'"),
    ("--f-stop", "f/0", "f-number out of range"),  # f/0.2 is a lens a scene may hold; f/0 is none
    ("--f-stop", "wide", "wide"),
    ("--blades", "33", "out of range [0, 32]"),
    ("--barrel-clipping", "2", "out of range [0, 1]"),
    ("--coc", "0", "out of range [0.0005, 1]"),
    ("--focus-from", "film", "invalid choice: 'film'"),
    ("--exposure-mode", "manual", "invalid choice: 'manual'"),
    ("--shutter", "1/0", "not a shutter time: '1/0'"),
    ("--aperture-image", "no_such_star.png", "no such file: no_such_star.png"),
])
def test_nonsense_camera_values_are_one_usage_line(capsys, flag, value, message):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", "x.png", flag, value)
    assert status == 2 and message in err and err.count("\n") == 1 and flag in err


def test_an_unknown_sensor_or_lens_names_the_ones_there_are(capsys, tmp_path):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", "--sensor", "super 8")
    assert status == 2 and err.count("\n") == 1
    assert "argument --sensor: no sensor preset called 'super 8' (there are: " in err and "APS-C" in err
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", "--lens", "400mm")
    assert status == 2 and err.count("\n") == 1
    assert "argument --lens: no lens preset called '400mm' (there are: " in err and "85 mm f/1.4" in err
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "x.png", "--lens", "24")
    assert status == 2 and err.count("\n") == 1
    assert "argument --lens: '24' could be any of 24 mm f/1.4, 24-70 mm f/2.8: name one whole" in err


def test_the_presets_are_listed(capsys):
    run = run_cli(capsys, "--list-lenses")
    status, out = run.status, run.out
    assert status == 0 and "85 mm f/1.4" in out and "f/1.4 to f/16" in out and "80.0 cm" in out
    run = run_cli(capsys, "--list-sensors")
    status, out = run.status, run.out
    assert status == 0 and "APS-C" in out and "23.5 x 15.6 mm" in out and "1.53x" in out and "29 µm" in out


def _camera(*argv):
    """The camera the command line would render: the arguments parsed and applied to the Cornell box."""
    from lenslab.cli import build_parser, scene_overrides
    from lenslab.scene.io.loader import open_scene

    return scene_overrides(build_parser().parse_args(["cornell_box", *argv])).apply(open_scene("cornell_box")).camera


def test_each_camera_flag_reaches_the_camera(tmp_path, monkeypatch):
    from lenslab.optics.stops import exact_f_number

    import OpenImageIO as oiio

    star = oiio.ImageBuf(oiio.ImageSpec(4, 4, 1, oiio.UINT8))
    oiio.ImageBufAlgo.fill(star, (1.0,))
    assert star.write(str(tmp_path / "star.png"))  # read as the option is parsed: a real image
    monkeypatch.chdir(tmp_path)
    cases = [
        (["--sensor", "Micro Four Thirds"], "sensor_mm", (17.3, 13.0)),
        (["--sensor-fit", "overscan"], "sensor_fit", "overscan"),
        (["--focus-from", "lens"], "focus_from", "lens"),
        (["--no-focus-breathing"], "focus_breathing", False),
        (["--coc", "0.025"], "circle_of_confusion_mm", 0.025),
        (["--blades", "0"], "aperture_blades", 0),
        (["--blades", "9"], "aperture_blades", 9),
        (["--blade-curvature", "0.25"], "blade_curvature", 0.25),
        (["--anamorphic", "2"], "anamorphic_squeeze", 2.0),
        (["--barrel-clipping", "0.75"], "barrel_clipping", 0.75),
        (["--aperture-image", "star.png"], "aperture_image", str(tmp_path / "star.png")),
        (["--exposure-mode", "physical"], "exposure_mode", "physical"),
        (["--iso", "1600"], "iso", 1600.0),
        (["--shutter", "1/125"], "shutter_s", 1 / 125),
        (["--shutter", "0.5"], "shutter_s", 0.5),
        (["--shutter", "2s"], "shutter_s", 2.0),
        (["--f-stop", "f/11"], "f_number", exact_f_number(11)),  # the exact stop, 2^3.5
        (["--f-stop", "2.8"], "f_number", exact_f_number(2.8)),
        (["--lens", "135mm f/2"], "focal_length_mm", 135.0),
        (["--lens", "85mm"], "focal_length_mm", 85.0),  # the only 85 mm lens there is
    ]
    for argv, field_name, expected in cases:
        assert getattr(_camera(*argv), field_name) == pytest.approx(expected), argv
    assert _camera("--f-stop", "f/11").f_number == pytest.approx(2 ** 3.5)
    assert _camera("--no-focus-breathing").focus_breathing is False and _camera().focus_breathing is True
    mounted = _camera("--lens", "24-70 mm f/2.8", "--focal-length", "35", "--f-stop", "4")
    assert (mounted.focal_length_mm, mounted.f_number, mounted.aperture_blades) == (35.0, 4.0, 9)
    assert mounted.blade_curvature == pytest.approx(0.6)


@pytest.mark.parametrize("argv, mode", [(["--iso", "400"], "physical"), (["--shutter", "1/60"], "physical"),
                                        (["--iso", "400", "--exposure-mode", "compensated"], "compensated"),
                                        (["--exposure-mode", "compensated"], "compensated"),
                                        ([], "physical")])  # the scene's own: the Cornell box is shot physically
def test_an_iso_or_a_shutter_switches_to_a_physical_exposure(argv, mode):
    assert _camera(*argv).exposure_mode == mode


def test_settings_a_lens_does_not_have_are_one_usage_line(capsys):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", "x.png", "--lens", "85mm f/1.4",
                          "--f-stop", "1.2")
    assert status == 2 and err.count("\n") == 1
    assert err.startswith("lenslab: error: f/1.2 is not on the lens '85 mm f/1.4' (f/1.4 to f/16)")


def test_a_focus_from_the_lens_nearer_than_the_lens_focuses_is_refused(capsys, tmp_path):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "a.png", *SMALL,
                          "--lens", "135 mm f/2", "--focus-from", "lens", "--focus-distance", "0.7")
    assert status == 1 and err.count("\n") == 1
    assert err.startswith("lenslab: error: --focus-distance 0.7 m from the lens is nearer than the 135 mm f/2 lens's "
                          "minimum focus of 0.9 m from the sensor (the plane of focus 0.7")
    assert not (tmp_path / "a.png").exists()


def test_the_listed_presets_are_the_shipped_ones(capsys):
    from lenslab.optics import load_lens_presets, load_sensor_presets

    run = run_cli(capsys, "--list-lenses")
    status, out, err = run.status, run.out, run.err
    lines = out.splitlines()
    assert status == 0 and not err and lines[0].split() == ["lens", "focal", "length", "stops", "blades", "closest",
                                                            "focus", "model"]
    assert [line.startswith(lens.name + " ") for line, lens in zip(lines[1:], load_lens_presets())] == \
        [True] * len(load_lens_presets()) and len(lines) == 1 + len(load_lens_presets())
    assert "70-200 mm" in out and "f/2.8 to f/22" in out
    # Real lenses say they are traced through glass, and how many surfaces it has.
    double_gauss = next(line for line in lines if line.startswith("50 mm f/2 double-Gauss"))
    assert double_gauss.endswith("glass, 11 surfaces") and "50.4 mm" in double_gauss
    run = run_cli(capsys, "--list-sensors")
    status, out, err = run.status, run.out, run.err
    lines = out.splitlines()
    assert status == 0 and not err and len(lines) == 1 + len(load_sensor_presets())
    assert all(line.startswith(sensor.name + " ") for line, sensor in zip(lines[1:], load_sensor_presets()))
    assert "Full frame" in out and "36 x 24 mm" in out and "1.00x" in out


def test_info_with_an_output_says_it_renders_nothing(capsys, tmp_path):
    status, err = run_cli(capsys, "cornell_box", "--info", "--headless", "-o", tmp_path / "c.png")
    assert status == 2 and "--info prints the device and exits without rendering" in err
    assert not (tmp_path / "c.png").exists()


def test_picture_only_options_on_an_exr_are_each_named(renderer, capsys, tmp_path):
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "c.exr", "--spp", "1", "--width",
                          "8", "--height", "8", "--tone-map", "filmic", "--exposure", "1")
    assert status == 0
    assert "--view applies to pictures only" in err and "--exposure applies to pictures only" in err


def test_a_folder_without_a_scene_is_called_a_folder(capsys, tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    status, err = run_cli(capsys, tmp_path, "--headless", "-o", tmp_path / "c.png")
    assert status == 1 and f"{tmp_path}: a folder with no scene.json in it" in err


# -- camera values checked once, and named in the command line's words --------------------------------------------
@pytest.mark.parametrize("given", [
    ["--lens", "50mm f/1.2", "--focus-from", "lens", "--focus-distance", "0.055"],  # the sensor 550 mm back
    ["--focal-length", "100", "--focus-from", "lens", "--focus-distance", "0.101"],  # the sensor 10 m back
])
def test_focus_from_the_lens_meets_the_limits_focus_from_the_sensor_does(capsys, tmp_path, given):
    status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / "a.png", *SMALL, *given)
    assert status == 1 and err.count("\n") == 1 and not (tmp_path / "a.png").exists()
    assert err.startswith(f"lenslab: error: --focus-distance {given[-1]} m from the lens is nearer than")


def test_a_negative_fraction_reaches_the_options_own_check(capsys, tmp_path):
    status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / "a.png", "--shutter", "-1/60")
    assert status == 2 and err.count("\n") == 1
    assert err.startswith("lenslab: error: argument --shutter: time '-1/60' is out of range")


def test_an_unreadable_aperture_image_is_blamed_on_the_option(capsys, tmp_path):
    (tmp_path / "stop.png").write_bytes(b"\x89PNG but not really")
    status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / "a.png", *SMALL,
                          "--aperture-image", tmp_path / "stop.png")
    assert status == 2 and err.count("\n") == 1
    assert err.startswith(f"lenslab: error: argument --aperture-image: {tmp_path / 'stop.png'}: cannot read")
    assert "scene.json" not in err


def test_a_reader_that_stops_reading_gets_no_error_line(tmp_path):
    """``lenslab --list-lenses | head -3``: the pipe's reader gone before the listing is written."""
    read_end, write_end = os.pipe()
    os.close(read_end)  # every write now fails with EPIPE (Python ignores SIGPIPE)
    try:
        result = subprocess.run([sys.executable, "-m", "lenslab", "--list-lenses"], stdout=write_end,
                                stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write_end)
    assert result.stderr == "" and result.returncode == 141


STUDIO_CONFIG = """ocio_profile_version: 2
roles: {default: Linear Rec.709 (sRGB), scene_linear: Linear Rec.709 (sRGB)}
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  Studio Monitor:
    - !<View> {name: Gamma 2.2, colorspace: Studio Display}
colorspaces:
  - !<ColorSpace> {name: Linear Rec.709 (sRGB), isdata: false}
  - !<ColorSpace>
    name: Studio Display
    from_scene_reference: !<ExponentTransform> {value: 2.2, direction: inverse}
"""


def test_a_studios_own_config_from_ocio_rules_the_picture(renderer, tmp_path, capsys, monkeypatch):
    """$OCIO as every OCIO application reads it: its display and view make the PNG (here a plain gamma 2.2 of the
    exposed EXR), and the file says so; --ocio-config names one for a single render, before $OCIO."""
    config = tmp_path / "studio.ocio"
    config.write_text(STUDIO_CONFIG)
    monkeypatch.setenv("OCIO", str(config))
    for suffix in (".exr", ".png"):
        status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / f"shot{suffix}", *SMALL)
        assert status == 0, err
    linear, _ = read_image(tmp_path / "shot.exr")
    picture, metadata = read_image(tmp_path / "shot.png")
    assert np.abs(picture - np.clip(linear, 0, 1) ** (1 / 2.2)).max() <= 0.5 / 255 + 1e-4
    assert metadata["lenslab:Display"] == "Studio Monitor" and metadata["lenslab:View"] == "Gamma 2.2"
    assert metadata["lenslab:OCIOConfig"] == str(config)
    # The built-in config for one render, by its URI, whatever $OCIO says.
    status, err = run_cli(capsys, "dof_chart", "--headless", "-o", tmp_path / "aces.png", *SMALL,
                          "--ocio-config", "ocio://cg-config-v4.0.0_aces-v2.0_ocio-v2.5")
    assert status == 0, err
    _, metadata = read_image(tmp_path / "aces.png")
    assert metadata["lenslab:Display"] == "sRGB - Display" and metadata["lenslab:View"].startswith("ACES 2.0")


def test_a_broken_ocio_config_stops_the_render_naming_the_file(renderer, tmp_path, capsys, monkeypatch):
    broken = tmp_path / "broken.ocio"
    broken.write_text("ocio_profile_version: 2\nroles: [\n")
    monkeypatch.setenv("OCIO", str(broken))
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "c.png", *SMALL)
    assert status == 1 and f"{broken} (from $OCIO): not a usable OCIO config" in err
    assert err.count("\n") == 1 and not (tmp_path / "c.png").exists()
    status, err = run_cli(capsys, "cornell_box", "--headless", "-o", tmp_path / "c.png", *SMALL,
                          "--ocio-config", tmp_path / "none.ocio")
    assert status == 2 and "--ocio-config: no such file" in err
