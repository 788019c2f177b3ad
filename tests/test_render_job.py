"""The render job that the CLI, the studio's export and validation share: when it stops, what it guarantees,
what it writes."""

from __future__ import annotations

import numpy as np
import pytest

from lenslab.render.film import read_image
from lenslab.render.job import RenderJob
from lenslab.scene.io.loader import open_scene
from lenslab.scene.overrides import SceneOverrides


def small_scene(width=64, height=48, **render):
    return SceneOverrides(width=width, height=height, **render).open("cornell_box")


def test_a_sample_target_stops_at_exactly_that_many(renderer):
    job = RenderJob(renderer, small_scene(), spp=3)
    try:
        assert not job.finished
        with pytest.raises(RuntimeError, match="not finished"):
            job.image()
        image = job.run()
        assert job.finished and job.samples_per_pixel == 3
        assert image.shape == (48, 64, 3) and np.all(job.session.accumulation()[..., 3] == 3)
    finally:
        job.release()


def test_without_a_target_or_a_limit_the_scene_says_how_many(renderer):
    job = RenderJob(renderer, small_scene(width=16, height=16, spp=2))
    try:
        job.run()
        assert job.samples_per_pixel == 2
    finally:
        job.release()


def test_a_time_limit_never_leaves_a_pixel_without_a_sample(renderer):
    job = RenderJob(renderer, small_scene(width=320, height=240), time_limit=1e-6)
    try:
        progress = job.step(0.0)
        assert progress.time_limit == 1e-6 and progress.fraction == 1.0
        job.run()
        assert job.samples_per_pixel == 1
        assert np.all(job.session.accumulation()[..., 3] >= 1)
        assert job.overran_time_limit > 0
    finally:
        job.release()


def test_both_limits_stop_at_whichever_comes_first(renderer):
    job = RenderJob(renderer, small_scene(width=8, height=8), spp=4, time_limit=1e6)
    try:
        job.run()
        assert job.samples_per_pixel == 4 and job.overran_time_limit == 0.0
    finally:
        job.release()


def test_the_written_file_carries_the_camera_and_the_samples(renderer, tmp_path):
    scene = SceneOverrides(width=32, height=24, f_number=4.0, seed=9).open("cornell_box")
    job = RenderJob(renderer, scene, spp=2)
    try:
        job.run()
        path = job.write(tmp_path / "job.exr")
    finally:
        job.release()
    pixels, meta = read_image(path)
    assert pixels.shape == (24, 32, 3)
    assert meta["FNumber"] == pytest.approx(4.0) and meta["lenslab:SamplesPerPixel"] == 2
    assert meta["lenslab:Seed"] == 9
    # 35 mm equivalent focal length: the full-frame sensor's own.
    assert meta["Exif:FocalLengthIn35mmFilm"] == round(scene.camera.focal_length_mm)


@pytest.mark.parametrize("bad", [{"spp": 0}, {"time_limit": 0.0}, {"time_limit": -1.0}])
def test_nonsense_limits_are_refused(renderer, bad):
    with pytest.raises(ValueError):
        RenderJob(renderer, open_scene("cornell_box"), **bad)


def test_a_time_limit_that_ends_inside_a_pass_of_many_dispatches_finishes_that_pass(renderer, tmp_path, monkeypatch):
    """At 4096 x 4096 a pass takes many dispatches, and a time limit that ended after the first few
    wrote "0 spp" with 0.5% of the pixels lit. Forced here on a small image with dispatches of a few pixels."""
    from lenslab.render.tracer import RenderSession

    dispatches = []
    dispatch = RenderSession._dispatch

    def counted(self, pixels, samples):
        dispatches.append((self.samples_per_pixel, pixels))
        dispatch(self, pixels, samples)

    monkeypatch.setattr(RenderSession, "_dispatch", counted)
    job = RenderJob(renderer, small_scene(width=136, height=128), time_limit=1e-4, dispatch_seconds=1e-6)
    try:
        job.run()
        path = job.write(tmp_path / "short.exr")
        first_pass = [pixels for spp, pixels in dispatches if spp == 0]
        assert len(first_pass) > 3 and sum(first_pass) == 136 * 128  # the pass was split, and all of it was run
        assert job.samples_per_pixel >= 1 and job.overran_time_limit > 0
        assert np.all(job.session.accumulation()[..., 3] >= 1)
    finally:
        job.release()
    assert read_image(path)[1]["lenslab:SamplesPerPixel"] == job.samples_per_pixel
