"""The scene File > New starts from: a small studio set (floor, a few objects at different depths, a softbox),
so that a new document shows a picture and some depth of field at once."""

from __future__ import annotations

from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.materials import Diffuse, Emissive
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
from lenslab.scene.shapes import Box, Rectangle, Sphere
from lenslab.scene.transform import Transform


def studio_scene() -> Scene:
    materials = {
        "floor": Diffuse(albedo=(0.55, 0.55, 0.56)),
        "clay": Diffuse(albedo=(0.78, 0.42, 0.26)),
        "slate": Diffuse(albedo=(0.18, 0.24, 0.33)),
        "chalk": Diffuse(albedo=(0.85, 0.85, 0.82)),
        "softbox": Emissive(radiance=(9.0, 8.6, 8.0), two_sided=False),
    }
    nodes = [
        Node("floor", Transform(rotate_deg=(-90.0, 0.0, 0.0)), Rectangle(size=(12.0, 12.0)), "floor"),
        Node("subject", Transform(translate=(0.0, 0.35, 0.0)), Sphere(radius=0.35), "clay"),
        Node("foreground cube", Transform(translate=(-0.75, 0.15, 1.1), rotate_deg=(0.0, 25.0, 0.0)),
             Box(size=(0.3, 0.3, 0.3)), "slate"),
        Node("background ball", Transform(translate=(0.9, 0.3, -2.2)), Sphere(radius=0.3), "chalk"),
        Node("softbox", Transform(translate=(0.9, 2.4, 0.9), rotate_deg=(65.0, 0.0, 0.0)),
             Rectangle(size=(1.6, 1.6)), "softbox"),
    ]
    camera = ThinLensCamera(position=(0.0, 0.9, 3.6), look_at=(0.0, 0.35, 0.0), focal_length_mm=50.0, f_number=2.8,
                            focus_distance_m=3.6, resolution=(600, 400))
    return Scene(camera=camera, environment=ConstantEnvironment(radiance=(0.12, 0.13, 0.15)),
                 render=RenderSettings(spp=64), materials=materials, nodes=nodes)
