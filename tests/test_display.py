"""The studio's picture made on the GPU (display.comp) is the picture film.py makes on the CPU."""

from __future__ import annotations

import numpy as np
import pytest

from lenslab.render.film import TONE_MAPS, resolve, to_8bit, tone_map
from lenslab.render.tracer import TONE_MAP_CODES, RenderSession
from lenslab.scene.io.loader import open_scene
from tests.helpers import render_to_spp

pytestmark = pytest.mark.gl


@pytest.fixture(scope="module")
def half_rendered(renderer):
    """The Cornell box with 3 samples per pixel and the fourth pass stopped part way: bright light, dark
    corners, and pixels with no sample yet once reset."""
    session = RenderSession(renderer, open_scene("cornell_box"), width=40, height=30)
    render_to_spp(session, 3)
    yield session
    session.release()


def test_every_tone_map_of_the_film_has_a_gpu_code():
    assert set(TONE_MAP_CODES) == set(TONE_MAPS)


@pytest.mark.parametrize("operator", TONE_MAPS)
@pytest.mark.parametrize("stops", [0.0, -2.5, 3.0])
def test_gpu_picture_matches_the_cpu_picture(half_rendered, operator, stops):
    expected = to_8bit(tone_map(resolve(half_rendered.accumulation()), stops, operator))
    picture = half_rendered.display(stops, operator)
    assert picture.shape == (30, 40, 4) and picture.dtype == np.uint8
    difference = np.abs(picture[..., :3].astype(int) - expected.astype(int))
    # The same float32 steps; pow() and rounding may differ in the last bit, so one level at most, rarely.
    assert difference.max() <= 1 and (difference == 0).mean() > 0.99
    assert (picture[..., 3] == 255).all()
    assert len(np.unique(picture[..., :3])) > 20  # a picture, not a constant


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


def test_an_unknown_tone_map_is_refused_by_name(half_rendered):
    with pytest.raises(ValueError, match="sepia"):
        half_rendered.display(0.0, "sepia")


@pytest.mark.parametrize("operator", TONE_MAPS)
def test_another_linear_image_is_displayed_as_the_film_would(half_rendered, operator):
    """display_image: the denoiser's image tone-mapped on the GPU, the same as film.py would on the CPU."""
    rng = np.random.default_rng(3)
    image = (rng.random((30, 40, 3)) ** 3 * 8).astype(np.float32)  # values from black to well past white
    picture = half_rendered.display_image(image, 1.5, operator)
    expected = to_8bit(tone_map(image, 1.5, operator))
    difference = np.abs(picture[..., :3].astype(int) - expected.astype(int))
    assert difference.max() <= 1 and (difference == 0).mean() > 0.99
    assert (picture[..., 3] == 255).all()
    # The session's own picture is untouched by it.
    again = half_rendered.display(0.0, operator)
    assert (again[..., :3] == to_8bit(tone_map(resolve(half_rendered.accumulation()), 0.0, operator))).mean() > 0.99


def test_an_image_of_another_size_is_refused(half_rendered):
    with pytest.raises(ValueError, match="41 x 30"):
        half_rendered.display_image(np.zeros((30, 41, 3), np.float32))
