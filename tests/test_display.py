"""The studio's picture made on the GPU (display.comp) is the picture film.py makes on the CPU."""

from __future__ import annotations

import numpy as np
import pytest

from lenslab.render.film import TONE_MAPS, resolve, to_8bit, tone_map
from lenslab.render.tracer import TONE_MAP_CODES, RenderSession
from lenslab.scene.io.loader import open_scene

pytestmark = pytest.mark.gl


@pytest.fixture(scope="module")
def half_rendered(renderer):
    """The Cornell box with 3 samples per pixel and the fourth pass stopped part way: bright light, dark
    corners, and pixels with no sample yet once reset."""
    session = RenderSession(renderer, open_scene("cornell_box"), width=40, height=30)
    session.step(60.0, target_spp=3)
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
