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
