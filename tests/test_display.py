"""The studio's picture made on the GPU (display.comp with OpenColorIO's GLSL) is the picture an export makes on
the CPU (film.display_pixels, OCIO's CPU processor): within one 8-bit level, for every kind of view."""

from __future__ import annotations

import numpy as np
import pytest

from lenslab.colour_management.config import ColourConfigError
from lenslab.colour_management.view import ViewTransform
from lenslab.render.film import display_pixels, resolve, to_8bit
from lenslab.render.tracer import RenderSession
from lenslab.scene.io.loader import open_scene
from tests.helpers import render_to_spp

pytestmark = pytest.mark.gl

VIEWS = [
    ViewTransform(),  # sRGB display, ACES 2.0 SDR: lookup tables of OCIO's in textures
    ViewTransform(view="Un-tone-mapped"),  # sRGB's curve alone
    ViewTransform(display="Display P3 - Display", exposure_stops=-2.5),
    ViewTransform(display="Rec.1886 Rec.709 - Display", contrast=1.4, exposure_stops=1.0),
    ViewTransform(looks="ACES 1.3 Reference Gamut Compression", working_space="acescg"),
]


def make_test_image():
    """A test image: a ramp of greys from deep shadow to 64 times white, beside saturated colours at several
    exposures (where the view's gamut mapping works hardest), and pure black."""
    ramp = np.geomspace(1e-4, 64.0, 48, dtype=np.float32)
    grey = np.repeat(ramp[None, :, None], 3, axis=2)
    hues = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [0, 1, 1], [1, 0, 1], [1, .5, .1], [.1, .3, 1]],
                    np.float32)
    colours = hues[:, None, :] * np.geomspace(0.01, 16.0, 48, dtype=np.float32)[None, :, None]
    image = np.concatenate([grey, colours, np.zeros((1, 48, 3), np.float32)], axis=0)
    return np.ascontiguousarray(image)


@pytest.fixture(scope="module")
def half_rendered(renderer):
    """The Cornell box with 3 samples per pixel and the fourth pass stopped part way: bright light, dark
    corners, and pixels with no sample yet once reset."""
    session = RenderSession(renderer, open_scene("cornell_box"), width=48, height=10)
    render_to_spp(session, 3)
    yield session
    session.release()


def agree_within_one_level(picture: np.ndarray, expected: np.ndarray) -> None:
    difference = np.abs(picture[..., :3].astype(int) - expected.astype(int))
    # The same transform in float32 on both; pow() and table lookups may differ in the last bits: one level at most.
    assert difference.max() <= 1, f"{int(difference.max())} levels apart"
    assert (difference == 0).mean() > 0.9


@pytest.mark.parametrize("view", VIEWS, ids=lambda v: f"{v.display or 'default'}-{v.view or 'default'}-{v.looks}")
def test_gpu_and_cpu_agree_within_one_level_on_a_test_image(half_rendered, view):
    image = make_test_image()
    picture = half_rendered.display_image(image, view)
    expected = to_8bit(display_pixels(image, view))
    agree_within_one_level(picture, expected)
    assert (picture[..., 3] == 255).all()
    assert len(np.unique(picture[..., :3])) > 40  # a picture, not a constant


@pytest.mark.parametrize("view", VIEWS[:2], ids=["aces", "untonemapped"])
def test_the_film_is_displayed_as_an_export_makes_it(half_rendered, view):
    expected = to_8bit(display_pixels(resolve(half_rendered.accumulation()), view))
    agree_within_one_level(half_rendered.display(view), expected)


def test_the_view_changes_the_picture(half_rendered):
    """The transform is really in the shader: ACES's tone curve holds a highlight that the un-tone-mapped view
    clips, and darkens mid grey; exposure and contrast move it on the GPU as on the CPU."""
    image = np.full((10, 48, 3), 0.18, np.float32)
    image[:, :24] = 8.0
    aces = half_rendered.display_image(image, ViewTransform())
    plain = half_rendered.display_image(image, ViewTransform(view="Un-tone-mapped"))
    assert plain[0, 0, 0] == 255 and aces[0, 0, 0] < 250
    assert aces[0, 40, 0] < plain[0, 40, 0]
    brighter = half_rendered.display_image(image, ViewTransform(exposure_stops=1.0))
    assert brighter[0, 40, 0] > aces[0, 40, 0]
    halved = half_rendered.display_image(image * 0.5, ViewTransform(exposure_stops=1.0))
    assert abs(int(halved[0, 40, 0]) - int(aces[0, 40, 0])) <= 1  # one stop up of half the light: the same


def test_pixels_without_samples_are_transparent(renderer):
    session = RenderSession(renderer, open_scene("cornell_box"), width=160, height=160)
    try:
        session.step(0.0, target_spp=1)  # one dispatch: the first takes 16384 of the 25600 pixels
        picture = session.display()
        sampled = session.accumulation()[..., 3] > 0
        assert 0 < sampled.mean() < 1
        assert (picture[..., 3] == np.where(sampled, 255, 0)).all()
        assert (picture[~sampled] == 0).all()
    finally:
        session.release()


def test_an_unknown_view_is_refused_by_name(half_rendered):
    with pytest.raises(ColourConfigError, match="sepia.*ACES 2.0"):
        half_rendered.display(ViewTransform(view="sepia"))


def test_an_image_of_another_size_is_refused(half_rendered):
    with pytest.raises(ValueError, match="41 x 10"):
        half_rendered.display_image(np.zeros((10, 41, 3), np.float32))
