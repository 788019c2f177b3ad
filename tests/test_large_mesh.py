"""A million-triangle mesh builds, fits and renders correctly (its build time is benchmarks/bsp_build.py's)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers import render_to_spp
from tests.scenes import FIXED_SENSOR
import trimesh

from lenslab.render.tracer import RenderSession
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
from lenslab.scene.shapes import MeshFile
from lenslab.scene.transform import Transform


@pytest.fixture(scope="module")
def million_triangle_scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("big")
    ball = trimesh.creation.icosphere(subdivisions=8, radius=1.0)  # 1,310,720 triangles
    ball.export(folder / "ball.ply")
    return Scene(
        camera=ThinLensCamera(**FIXED_SENSOR, position=(0, 0, 4), look_at=(0, 0, 0), focal_length_mm=50, f_number=4,
                              focus_distance_m=3, resolution=(48, 32)),
        environment=ConstantEnvironment((1.0, 1.0, 1.0)),
        render=RenderSettings(max_depth=2),
        nodes=[Node("ball", Transform(translate=(0.2, 0.1, 0)), MeshFile("ball.ply"))],
        source_path=folder / "scene.json",
    )


@pytest.mark.slow
def test_million_triangles_render_like_the_sphere_they_approximate(renderer, million_triangle_scene):
    session = RenderSession(renderer, million_triangle_scene)
    flat = session.flat_scene
    assert flat.placed_triangle_count > 1_000_000
    assert len(flat.instances) == 1, "a mesh this large keeps its own tree (render/instancing.py)"

    # Rays from the camera through a grid of image points: each hit lies on the unit sphere (the mesh's
    # chords sag by at most 1 - cos(half the edge angle), about 1e-5 here), and misses only outside it.
    ys, xs = np.mgrid[0:32:4, 0:48:4] + 2.0
    centre, camera = np.array([0.2, 0.1, 0.0]), million_triangle_scene.camera
    assert camera.resolution == (48, 32)
    right, up, back = camera.basis()
    tan_x = camera.sensor_mm[0] / (2 * camera.focal_length_mm)  # the pinhole camera's half width at unit depth
    for x, y in zip(xs.ravel(), ys.ravel()):
        pick = session.pick(float(x), float(y))
        direction = (2 * x / 48 - 1) * tan_x * right + (1 - 2 * y / 32) * tan_x * 32 / 48 * up - back
        direction /= np.linalg.norm(direction)
        origin = np.array(camera.position, float)
        b = (origin - centre) @ direction
        disc = b * b - ((origin - centre) @ (origin - centre) - 1.0)
        if disc > 1e-3:
            assert pick is not None
            assert np.linalg.norm(pick.point - centre) == pytest.approx(1.0, abs=2e-4)
            assert np.linalg.norm(pick.point - origin) == pytest.approx(-b - np.sqrt(disc), abs=2e-4)
        elif disc < -1e-3:
            assert pick is None

    image = render_to_spp(session, 1).image()
    assert np.isfinite(image).all() and image.max() > 0
    session.release()
