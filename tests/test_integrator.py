"""The integrator neither gains nor loses energy, and the same seed gives the same image."""

from __future__ import annotations

import dataclasses
import types

import numpy as np
import pytest

from lenslab.render.tracer import RenderSession
from tests.helpers import render_to_spp
from tests.scenes import furnace_scene


def block_means(image, size=4):
    h, w = image.shape[:2]
    return image[: h // size * size, : w // size * size].reshape(h // size, size, w // size, size, -1).mean(axis=(1, 3))


def render(renderer, scene, spp, **session_args):
    session = RenderSession(renderer, scene, **session_args)
    accumulation = render_to_spp(session, spp).accumulation()
    session.release()
    return accumulation


def with_settings(scene, **changes):
    return dataclasses.replace(scene, render=dataclasses.replace(scene.render, **changes))


GAUSSIAN = dict(pixel_filter="gaussian", filter_stddev=0.5)


@pytest.mark.parametrize("sampler", ["sobol", "independent"])
@pytest.mark.parametrize("pixel_filter", ["box", "gaussian-expected", "gaussian-sampled"])
def test_white_furnace_renders_one_everywhere(renderer, sampler, pixel_filter):
    # Albedo-1 diffuse surfaces under a uniform sky of radiance 1: every path ends in the sky with weight 1
    # however it bounces (the floor, ball and box light each other), so every pixel must be 1 within noise.
    # A splatted gaussian filter must keep it so up to the image's edges, where fewer samples reach a pixel.
    scene = with_settings(furnace_scene(), sampler=sampler)
    if pixel_filter != "box":
        scene = with_settings(scene, **GAUSSIAN, filter_weights=pixel_filter.split("-")[1])
    spp = 64
    accumulation = render(renderer, scene, spp)
    image = accumulation[..., :3] / accumulation[..., 3:4]
    if pixel_filter == "box":
        assert np.all(accumulation[..., 3] == spp)
    assert image.mean() == pytest.approx(1.0, abs=0.005)
    # Russian roulette and MIS make single samples differ from 1, but 4x4-pixel blocks of 64 samples each
    # stay close; a lost or doubled bounce would shift whole regions (contact shadows, the sky-lit tops).
    assert np.abs(block_means(image) - 1.0).max() < 0.05


def test_furnace_with_short_paths_loses_energy_as_expected(renderer):
    # The same scene cut at max_depth 2 (direct light only) is darker where surfaces see each other:
    # a check that the furnace test above could fail.
    accumulation = render(renderer, furnace_scene(max_depth=2), 16)
    blocks = block_means(accumulation[..., :3] / accumulation[..., 3:4])
    assert blocks.min() < 0.8
    assert blocks.max() < 1.03


@pytest.mark.parametrize("pixel_filter", ["box", "gaussian"])
def test_same_seed_gives_the_same_image_however_the_work_is_split(renderer, pixel_filter):
    scene = furnace_scene(max_depth=8)
    if pixel_filter == "gaussian":
        scene = with_settings(scene, **GAUSSIAN)
    coarse = render(renderer, scene, 8, dispatch_seconds=10.0)
    fine = render(renderer, scene, 8, dispatch_seconds=1e-4)  # many tiny dispatches
    assert np.array_equal(coarse, fine)
    other_seed = dataclasses.replace(scene, render=dataclasses.replace(scene.render, seed=1))
    assert not np.array_equal(coarse, render(renderer, other_seed, 8))


def test_step_returns_between_bounded_dispatches(renderer):
    scene = furnace_scene(max_depth=8)
    session = RenderSession(renderer, scene, width=256, height=128, dispatch_seconds=0.01)
    progress = session.step(0.0)  # one dispatch, then back to the caller
    counts = session.accumulation()[..., 3]
    assert progress.samples_per_pixel == 0 and 0 < np.count_nonzero(counts) < counts.size
    session.step(30.0, target_spp=2)
    assert session.samples_per_pixel == 2
    assert np.all(session.accumulation()[..., 3] == 2)
    session.release()


def test_step_starts_no_dispatch_it_expects_to_end_past_its_deadline(renderer, monkeypatch):
    """The studio asks for a frame's worth of work and must have its picture within the frame: a dispatch
    that would end after the deadline waits for the next step instead of overrunning this one."""
    from lenslab.render import tracer

    session = RenderSession(renderer, furnace_scene(max_depth=1), width=64, height=64, dispatch_seconds=0.04)
    clock = [0.0]
    monkeypatch.setattr(tracer, "time", types.SimpleNamespace(perf_counter=lambda: clock[0]))
    real_dispatch = session._dispatch

    def dispatch_taking_40_ms(pixels, samples):  # a device on which every dispatch takes 0.04 s
        real_dispatch(pixels, samples)
        clock[0] += 0.04
        session._seconds_per_pixel_sample = 0.04 / (pixels * samples)

    monkeypatch.setattr(session, "_dispatch", dispatch_taking_40_ms)
    session.step(0.1)  # dispatches end at 0.04 and 0.08 s; a third would end at 0.12 s
    assert clock[0] == pytest.approx(0.08)
    session.step(0.01)  # shorter than any dispatch: one all the same, or the render would never advance
    assert clock[0] == pytest.approx(0.12)
    session.release()


def test_firefly_clamp_is_off_by_default_and_caps_samples_when_asked(renderer):
    from lenslab.scene.materials import Emissive

    scene = furnace_scene(max_depth=4)
    bright = dataclasses.replace(scene, environment=dataclasses.replace(scene.environment, radiance=(5.0, 5.0, 5.0)),
                                 materials={"white": Emissive((0.0, 0.0, 0.0))})
    unclamped = render(renderer, bright, 2)
    assert (unclamped[..., :3] / unclamped[..., 3:4]).max() == pytest.approx(5.0)  # the default is unbiased
    clamped_scene = dataclasses.replace(bright, render=dataclasses.replace(bright.render, clamp=2.0))
    clamped = render(renderer, clamped_scene, 2)
    assert (clamped[..., :3] / clamped[..., 3:4]).max() == pytest.approx(2.0)


# -- the gaussian pixel filter ---------------------------------------------------------------------------------
@pytest.mark.parametrize("weights", ["expected", "sampled"])
def test_splatting_lowers_the_noise_per_pixel(renderer, monkeypatch, weights):
    # Each sample serves the pixels its filter reaches, so at equal samples the splatted image of a noisy
    # scene (the Cornell box: small light, many bounces) is smoother than the same filter by importance
    # sampling (both estimate the same image: see the edge test).
    from lenslab.render import tracer
    from lenslab.scene.io.loader import open_scene

    scene = open_scene("cornell_box")
    scene = dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, resolution=(48, 48)))
    scene = with_settings(scene, **GAUSSIAN, filter_weights=weights, sampler="independent")

    def seed_difference():
        images = [render(renderer, with_settings(scene, seed=seed), 8) for seed in (1, 2)]
        a, b = (acc[..., :3] / acc[..., 3:4] for acc in images)
        return float(np.var(a - b))

    splatted = seed_difference()
    monkeypatch.setattr(tracer, "SPLAT_MEMORY_BYTES", 0)
    importance = seed_difference()
    assert splatted < 0.6 * importance


def test_a_renderer_keeps_its_context_when_another_is_made_in_the_same_thread(renderer):
    # A standalone GL context is current only until the next one is made; `lenslab --info` or a second
    # renderer in the same process must not leave this one rendering black.
    from lenslab.render.tracer import Renderer

    scene = furnace_scene(max_depth=2)
    before = render(renderer, scene, 2)
    other = Renderer()
    render(other, scene, 1)
    other.release()
    assert np.array_equal(render(renderer, scene, 2), before)
    assert before[..., :3].mean() > 0.5
