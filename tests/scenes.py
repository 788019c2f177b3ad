"""Small scenes built in code for the tests."""

from __future__ import annotations

from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.materials import Diffuse, Emissive
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
from lenslab.scene.shapes import Box, Rectangle, Sphere
from lenslab.scene.transform import Transform


def point_light_scene(depth_m: float, radius_m: float, camera: ThinLensCamera) -> Scene:
    """A small bright sphere on the view axis at ``depth_m``, camera at the origin looking down -Z, black sky."""
    return Scene(
        camera=camera,
        environment=ConstantEnvironment((0.0, 0.0, 0.0)),
        render=RenderSettings(max_depth=1),
        materials={"lamp": Emissive((1.0, 1.0, 1.0))},
        nodes=[Node("lamp", Transform(translate=(0.0, 0.0, -depth_m)), Sphere(radius_m), "lamp")],
    )


#: The thin lens of pbrt and Mitsuba: focus measured from the lens, the sensor one focal length behind it at every
#: focus, the image across the sensor's width. Tests that check the renderer against those formulas
#: (lenslab.optics.thinlens.blur_diameter_mm, fields of view) set it; tests/test_camera_controls.py covers the rest.
FIXED_SENSOR = dict(focus_from="lens", focus_breathing=False, sensor_fit="horizontal")


def axis_camera(**kwargs) -> ThinLensCamera:
    defaults = dict(position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, -1.0), up=(0.0, 1.0, 0.0), **FIXED_SENSOR)
    return ThinLensCamera(**(defaults | kwargs))


def furnace_scene(max_depth: int = 1024) -> Scene:
    """Albedo-1 diffuse shapes, concave together (a floor under a sphere and a box), under a sky of radiance 1."""
    return Scene(
        camera=ThinLensCamera(position=(0.0, 1.0, 3.0), look_at=(0.0, 0.4, 0.0), focal_length_mm=28.0,
                              f_number=2.0, focus_distance_m=3.0, resolution=(48, 32)),
        environment=ConstantEnvironment((1.0, 1.0, 1.0)),
        render=RenderSettings(max_depth=max_depth, rr_depth=3),
        materials={"white": Diffuse((1.0, 1.0, 1.0))},
        nodes=[
            Node("floor", Transform(rotate_deg=(-90.0, 0.0, 0.0)), Rectangle((3.0, 3.0)), "white"),
            Node("ball", Transform(translate=(-0.4, 0.5, 0.0)), Sphere(0.5), "white"),
            Node("box", Transform(translate=(0.6, 0.3, -0.2), rotate_deg=(0.0, 30.0, 0.0)), Box((0.5, 0.6, 0.5)), "white"),
        ],
    )
