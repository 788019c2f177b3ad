"""Draws docs/screenshots/bokeh-shapes.png: six small lamps 6 m away, the camera focused at 0.35 m, under each
aperture the camera offers. Usage: python docs/screenshots/bokeh_shapes.py [SPP] [OUT.png]"""
import sys
import tempfile

import numpy as np
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.materials import Emissive
from lenslab.scene.scene import ConstantEnvironment, Node, RenderSettings, Scene
from lenslab.scene.shapes import Sphere
from lenslab.scene.transform import Transform
from lenslab.render.tracer import Renderer
from lenslab.render.job import RenderJob
from lenslab.colour_management.view import ViewTransform
from lenslab.render.film import display_pixels, to_8bit
import OpenImageIO as oiio

star = np.zeros((64, 64)); yy, xx = np.mgrid[0:64, 0:64] + 0.5
ang = np.arctan2(yy - 32, xx - 32); rad = np.hypot(yy - 32, xx - 32)
star[rad < 30 * (0.55 + 0.45 * np.cos(5 * (ang + np.pi / 2)))] = 1.0
buf = oiio.ImageBuf(oiio.ImageSpec(64, 64, 1, oiio.FLOAT)); buf.set_pixels(oiio.ROI(0, 64, 0, 64, 0, 1, 0, 1), star.astype(np.float32))
star_file = tempfile.NamedTemporaryFile(suffix=".exr", delete=False).name
buf.write(star_file)

panels = [("round", {}), ("7 straight blades", dict(aperture_blades=7, blade_rotation_deg=90)),
          ("7 rounded blades (0.6)", dict(aperture_blades=7, blade_curvature=0.6, blade_rotation_deg=90)),
          ("anamorphic 1.8x", dict(anamorphic_squeeze=1.8)), ("cat's eye (barrel 0.9)", dict(barrel_clipping=0.9)),
          ("aperture image: a star", dict(aperture_image=star_file))]
lamps = [Node(f"lamp{i}{j}", Transform(translate=(x, y, -6.0)), Sphere(0.035), "lamp")
         for i, x in enumerate(np.linspace(-1.15, 1.15, 3)) for j, y in enumerate(np.linspace(-0.6, 0.6, 2))]
r = Renderer()
tiles = []
for name, kw in panels:
    cam = ThinLensCamera(position=(0, 0, 0), look_at=(0, 0, -1), focal_length_mm=50, f_number=1.4, focus_distance_m=0.35,
                         resolution=(300, 200), **kw)
    scene = Scene(camera=cam, environment=ConstantEnvironment((0.0, 0.0, 0.0)), render=RenderSettings(max_depth=1),
                  materials={"lamp": Emissive((4.0, 3.2, 2.2))}, nodes=lamps)
    job = RenderJob(r, scene, spp=int(sys.argv[1]) if len(sys.argv) > 1 else 512)
    img = job.run(); job.release()
    tile = to_8bit(display_pixels(img, ViewTransform(exposure_stops=3.0)))
    tb = oiio.ImageBuf(oiio.ImageSpec(300, 200, 3, oiio.UINT8)); tb.set_pixels(oiio.ROI(0, 300, 0, 200, 0, 1, 0, 3), tile)
    oiio.ImageBufAlgo.render_text(tb, 8, 190, name, 14, "", (1, 1, 1))
    tiles.append(np.asarray(tb.get_pixels(oiio.UINT8)))
    print(name, flush=True)
rows = [np.concatenate(tiles[i:i + 3], axis=1) for i in (0, 3)]
sheet = np.concatenate(rows, axis=0)
out = oiio.ImageBuf(oiio.ImageSpec(sheet.shape[1], sheet.shape[0], 3, oiio.UINT8)); out.set_pixels(oiio.ROI(0, sheet.shape[1], 0, sheet.shape[0], 0, 1, 0, 3), sheet)
out.write(sys.argv[2] if len(sys.argv) > 2 else "docs/screenshots/bokeh-shapes.png")
