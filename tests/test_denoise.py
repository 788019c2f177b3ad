"""The denoiser: the tracer's albedo and normal guides (glsl/feature_buffers.glsl), render/denoise.py, and denoised
exports (EXR layers, metadata, the command line's --denoise)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lenslab.cli import main
from lenslab.render.film import read_image
from tests.helpers import render_to_spp

pytest.importorskip("pyoidn")


def session(renderer, scene, size=(48, 48), **kwargs):
    from lenslab.render.tracer import RenderSession

    return RenderSession(renderer, scene, width=size[0], height=size[1], **kwargs)


def pinhole(scene):
    return dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, pinhole=True))


def picked_nodes(s) -> np.ndarray:
    """The name of the node seen through the centre of each pixel ('' where nothing is)."""
    names = np.empty((s.height, s.width), dtype=object)
    for y in range(s.height):
        for x in range(s.width):
            pick = s.pick(x + 0.5, y + 0.5)
            names[y, x] = pick.node.name if pick else ""
    return names


def interior(names: np.ndarray, name: str) -> np.ndarray:
    """Pixels showing ``name`` whose eight neighbours show it too: no edge crosses their samples."""
    mask = names == name
    inside = np.zeros_like(mask)
    height, width = mask.shape
    inside[1:-1, 1:-1] = np.logical_and.reduce([mask[1 + dy:height - 1 + dy, 1 + dx:width - 1 + dx]
                                                for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
    return inside


@pytest.mark.gl
def test_albedo_and_normal_of_the_cornell_walls(renderer):
    from lenslab.scene.io.loader import open_scene

    scene = pinhole(open_scene("cornell_box"))
    s = session(renderer, scene, feature_buffers=True)
    render_to_spp(s, 4)
    albedo, normal = s.features_image()
    names = picked_nodes(s)
    expected = {"left wall": ((0.63, 0.065, 0.05), (1.0, 0.0, 0.0)),
                "right wall": ((0.14, 0.45, 0.091), (-1.0, 0.0, 0.0)),
                "back wall": ((0.73, 0.73, 0.73), (0.0, 0.0, 1.0)),
                "floor": ((0.73, 0.73, 0.73), (0.0, 1.0, 0.0))}
    for name, (reflectance, wall_normal) in expected.items():
        inside = interior(names, name)
        assert inside.sum() >= 20, name
        np.testing.assert_allclose(albedo[inside], np.broadcast_to(reflectance, albedo[inside].shape), atol=1e-5)
        np.testing.assert_allclose(normal[inside], np.broadcast_to(wall_normal, normal[inside].shape), atol=1e-5)
    light = names == "ceiling light"  # a strip too thin for an interior; the ceiling around it faces down too
    assert light.any() and albedo[light].max() == 1.0  # its radiance (17, 12, 4), clamped to [0, 1]
    np.testing.assert_allclose(normal[light], np.broadcast_to((0.0, -1.0, 0.0), normal[light].shape), atol=1e-5)
    s.release()


@pytest.mark.gl
def test_beauty_is_the_same_with_and_without_feature_buffers(renderer):
    """Same seed, same image: the guides read the path and never draw a sample. Glass, a mirror and depth of
    field (cornell_caustic), and a session whose buffers are turned on and off between renders."""
    from lenslab.scene.io.loader import open_scene

    scene = open_scene("cornell_caustic")
    plain = session(renderer, scene, (40, 40))
    render_to_spp(plain, 3)
    guided = session(renderer, scene, (40, 40), feature_buffers=True)
    render_to_spp(guided, 3)
    assert np.array_equal(plain.accumulation(), guided.accumulation())
    albedo, normal = guided.features_image()
    assert albedo.max() > 0 and np.abs(normal).max() > 0

    guided.set_feature_buffers(False)  # back to the kernel without them: the same image again
    render_to_spp(guided, 3)
    assert np.array_equal(plain.accumulation(), guided.accumulation())
    with pytest.raises(RuntimeError, match="no feature buffers"):
        guided.features_image()
    plain.set_feature_buffers(True)
    render_to_spp(plain, 3)
    assert np.array_equal(plain.features_image()[0], albedo)
    plain.release()
    guided.release()


@pytest.mark.gl
def test_guides_follow_a_delta_surface_and_the_sky_has_no_normal(renderer):
    """Through a thin glass pane the guides are those of the red wall behind it, weighted by the pane's
    transmission (OIDN: follow perfect specular paths to the first diffuse hit); what the pane reflects is the sky,
    whose albedo is its radiance and whose normal is 0, as at the image's corners, which see the sky directly."""
    from lenslab.scene.camera import ThinLensCamera
    from lenslab.scene.materials import Diffuse, ThinDielectric
    from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
    from lenslab.scene.shapes import Rectangle
    from lenslab.scene.transform import Transform

    red = (0.7, 0.1, 0.1)
    scene = Scene(camera=ThinLensCamera(position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, -1.0), pinhole=True,
                                        resolution=(24, 16)),
                  environment=ConstantEnvironment((0.5, 0.5, 0.5)), render=RenderSettings(max_depth=8),
                  materials={"red": Diffuse(red), "pane": ThinDielectric(ior=1.5)},
                  nodes=[Node("wall", Transform(translate=(0.0, 0.0, -2.0)), Rectangle((1.0, 1.0)), "red"),
                         Node("pane", Transform(translate=(0.0, 0.0, -1.0)), Rectangle((0.2, 0.2)), "pane")])
    s = session(renderer, scene, (24, 16), feature_buffers=True)
    render_to_spp(s, 256)
    albedo, normal = s.features_image()
    names = picked_nodes(s)
    r = 0.04 + 0.96 ** 2 * 0.04 / (1 - 0.04 ** 2)  # the pane's reflectance head-on, inter-reflections included
    pane = interior(names, "pane")
    assert pane.any()
    np.testing.assert_allclose(albedo[pane].mean(axis=0), (1 - r) * np.array(red) + r * 0.5, atol=0.02)
    np.testing.assert_allclose(normal[pane].mean(axis=0), (0.0, 0.0, 1 - r), atol=0.02)
    wall = interior(names, "wall")
    np.testing.assert_allclose(albedo[wall], np.broadcast_to(red, albedo[wall].shape), atol=1e-5)
    sky = interior(names, "")
    assert sky[1, 1] and np.allclose(albedo[sky], 0.5) and np.all(normal[sky] == 0.0)
    s.release()


def rel_mse(image, reference):
    return float(np.mean((image - reference) ** 2 / (reference ** 2 + 1e-2)))


@pytest.mark.slow
@pytest.mark.gl
def test_the_denoised_image_is_closer_to_the_converged_one(renderer):
    from lenslab.render.denoise import denoise
    from lenslab.scene.io.loader import open_scene

    scene = open_scene("cornell_box")
    reference = session(renderer, scene, (64, 64))
    render_to_spp(reference, 512)
    noisy = session(renderer, scene, (64, 64), feature_buffers=True)
    render_to_spp(noisy, 4)
    image = noisy.image()
    albedo, normal = noisy.features_image()
    raw_error = rel_mse(image, reference.image())
    for denoised in (denoise(image, albedo, normal), denoise(image, albedo, normal, prefilter=True),
                     denoise(image)):
        assert denoised.shape == image.shape and denoised.dtype == np.float32
        assert rel_mse(denoised, reference.image()) < 0.5 * raw_error
    reference.release()
    noisy.release()


def test_denoise_refuses_what_it_cannot_take():
    from lenslab.render.denoise import denoise

    color = np.ones((8, 8, 3), np.float32)
    with pytest.raises(ValueError, match="same size"):
        denoise(color, np.ones((8, 9, 3), np.float32))
    with pytest.raises(ValueError, match=r"\(height, width, 3\)"):
        denoise(np.ones((8, 8), np.float32))
    with pytest.raises(ValueError, match="needs an albedo"):
        denoise(color, normal=np.zeros((8, 8, 3), np.float32))
    with pytest.raises(ValueError, match="quality"):
        denoise(color, quality="best")
    bad = color.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        denoise(bad)


def channel_names(path) -> tuple[str, ...]:
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    try:
        return tuple(image.spec().channelnames)
    finally:
        image.close()


@pytest.mark.gl
def test_a_denoised_export_keeps_the_noisy_image_and_the_guides_as_exr_layers(renderer, tmp_path):
    from lenslab.render.job import RenderJob
    from lenslab.scene.io.loader import open_scene

    scene = open_scene("cornell_box")
    scene.camera = dataclasses.replace(scene.camera, resolution=(32, 24))
    job = RenderJob(renderer, scene, spp=2, feature_buffers=True)
    job.run()
    job.write(tmp_path / "plain.exr")  # never denoised unless asked
    assert channel_names(tmp_path / "plain.exr") == ("R", "G", "B")
    assert "lenslab:Denoised" not in read_image(tmp_path / "plain.exr")[1]

    job.write(tmp_path / "shot.exr", denoise=True)
    names = channel_names(tmp_path / "shot.exr")
    assert set(names) == {"R", "G", "B", "noisy.R", "noisy.G", "noisy.B", "albedo.R", "albedo.G", "albedo.B",
                          "normal.X", "normal.Y", "normal.Z"} and names[:3] == ("R", "G", "B")
    pixels, metadata = read_image(tmp_path / "shot.exr")
    layer = {name: pixels[..., i] for i, name in enumerate(names)}
    noisy = np.stack([layer[f"noisy.{c}"] for c in "RGB"], axis=-1)
    # Exposed as the main image is: the Cornell box is shot with a camera's physical exposure.
    assert np.array_equal(noisy, job.image() * np.float32(metadata["lenslab:ExposureScale"]))
    main_image = np.stack([layer[c] for c in "RGB"], axis=-1)
    assert not np.array_equal(main_image, noisy) and main_image.max() > 0
    albedo, normal = job.session.features_image()
    assert np.array_equal(np.stack([layer[f"albedo.{c}"] for c in "RGB"], axis=-1), albedo)
    assert np.array_equal(np.stack([layer[f"normal.{c}"] for c in "XYZ"], axis=-1), normal)
    assert metadata["lenslab:Denoised"] == 1 and "Open Image Denoise" in metadata["lenslab:Denoiser"]
    assert metadata["lenslab:SamplesPerPixel"] == 2  # beside the camera's metadata, as before

    job.write(tmp_path / "shot.png", denoise=True)  # a PNG: the denoised picture alone
    png, png_metadata = read_image(tmp_path / "shot.png")
    assert png.shape == (24, 32, 3) and png_metadata["lenslab:Denoised"] == "1"
    job.release()


@pytest.mark.gl
def test_cli_denoise_writes_the_denoised_file(renderer, tmp_path, capsys):
    out = tmp_path / "shot.exr"
    status = main(["dof_chart", "--headless", "-o", str(out), "--spp", "2", "--width", "24", "--height", "16",
                   "--denoise"])
    err = capsys.readouterr().err
    assert status == 0, err
    assert "denoised" in err
    assert "noisy.R" in channel_names(out) and read_image(out)[1]["lenslab:Denoised"] == 1


def test_cli_denoise_without_the_library_says_so_in_one_line_before_rendering(tmp_path, capsys, monkeypatch):
    import sys

    from lenslab.render import denoise

    monkeypatch.setattr(denoise, "_SHARED", denoise.Denoiser())  # none made yet
    monkeypatch.setitem(sys.modules, "pyoidn", None)  # as if it were not installed
    out = tmp_path / "shot.png"
    status = main(["cornell_box", "--headless", "-o", str(out), "--spp", "1", "--denoise"])
    err = capsys.readouterr().err
    assert status == 1 and not out.exists()
    assert err.count("\n") == 1 and "--denoise: denoising needs Intel Open Image Denoise: pip install pyoidn" in err


def test_an_image_too_large_for_its_feature_buffers_is_refused_in_one_line():
    from lenslab.limits import SceneTooLarge
    from lenslab.render.tracer import LLVMPIPE_BUFFER_BYTES, check_image_size

    check_image_size(12000, 11500, LLVMPIPE_BUFFER_BYTES, memory_bytes=None)  # its image alone fits
    with pytest.raises(SceneTooLarge, match="feature buffer"):  # 32 bytes a pixel: more than 4 GiB
        check_image_size(12000, 11500, LLVMPIPE_BUFFER_BYTES, memory_bytes=None, feature_buffers=True)
    with pytest.raises(SceneTooLarge, match=r"and 1\.0 GiB for the denoiser\); this machine holds at most"):
        check_image_size(4000, 4000, LLVMPIPE_BUFFER_BYTES, memory_bytes=4 << 30, feature_buffers=True)
    check_image_size(4000, 4000, LLVMPIPE_BUFFER_BYTES, memory_bytes=4 << 30)


def test_a_denoiser_of_ones_own_denoises_as_the_shared_one_does_and_beside_it():
    import threading

    from lenslab.render.denoise import Denoiser, denoise

    rng = np.random.default_rng(5)
    color = rng.random((40, 56, 3), dtype=np.float32)
    albedo = np.full_like(color, 0.5)
    normal = np.zeros_like(color)
    normal[..., 2] = 1.0
    expected = denoise(color, albedo, normal, quality="fast")
    own = Denoiser()
    try:
        results, errors = {}, []

        def run(name, fn):
            try:
                results[name] = fn(color, albedo, normal, quality="fast")
            except Exception as exc:  # reported below, not lost in the thread
                errors.append(exc)

        threads = [threading.Thread(target=run, args=("own", own.denoise)),
                   threading.Thread(target=run, args=("shared", denoise))]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60)
        assert not errors and set(results) == {"own", "shared"}
        np.testing.assert_allclose(results["own"], expected, rtol=1e-4, atol=1e-5)
        np.testing.assert_allclose(results["shared"], expected, rtol=1e-4, atol=1e-5)
        with pytest.raises(ValueError, match="unknown denoise quality"):
            own.denoise(color, quality="best")
    finally:
        own.release()
    own.release()  # twice is harmless
