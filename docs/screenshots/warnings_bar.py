"""Draws docs/screenshots/warnings-bar.png: a Mitsuba 3 scene with a BSDF LensLab does not have and a texture
that is not there, opened in the studio: the warning bar above the picture with its Details open, and the Log
panel (View > Log) with the same lines (docs/studio.md, "Warnings"). Run under a display, e.g.
    xvfb-run -a -s "-screen 0 1600x1000x24" python docs/screenshots/warnings_bar.py [OUT.png]"""
import sys
import tempfile
from pathlib import Path

from PySide6.QtCore import QSettings, QTimer

from lenslab.gui.app import create_application
from lenslab.gui.log_panel import show_dock
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

out = sys.argv[1] if len(sys.argv) > 1 else "docs/screenshots/warnings-bar.png"
folder = Path(tempfile.mkdtemp())
scene_file = folder / "product_on_table.xml"
scene_file.write_text(
    '<?xml version="1.0"?>\n<scene version="3.0.0">\n'
    '<sensor type="thinlens"><float name="fov" value="35"/><float name="aperture_radius" value="0.02"/>'
    '<float name="focus_distance" value="5"/><transform name="to_world"><lookat origin="0, 1, 5" '
    'target="0, 0.3, 0" up="0, 1, 0"/></transform><film type="hdrfilm"><integer name="width" value="600"/>'
    '<integer name="height" value="400"/></film></sensor>\n'
    '<emitter type="constant"><rgb name="radiance" value="0.8"/></emitter>\n'
    '<shape type="sphere"><point name="center" value="0, 0.5, 0"/><float name="radius" value="0.5"/>'
    '<bsdf type="hair"/></shape>\n'
    '<shape type="rectangle"><transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/>'
    '</transform><bsdf type="diffuse"><texture type="bitmap" name="reflectance">'
    '<string name="filename" value="textures/oak_table.jpg"/></texture></bsdf></shape>\n</scene>\n')
app = create_application()
settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
window = MainWindow(open_scene("cornell_box"), settings=settings, restore_layout=False)
window.resize(1400, 900)
window.show()
state = {"opened": False}


def tick() -> None:
    if not state["opened"]:
        window.files.open_path(str(scene_file), ask=False)
        window.warning_bar.details_button.setChecked(True)
        show_dock(window.docks["log"])
        state["opened"] = True
    frame = window.controller.last_frame
    if frame is None or frame.generation < window.controller.generation or frame.samples_per_pixel < 8:
        QTimer.singleShot(250, tick)
        return
    window.grab().save(out)
    print("wrote", out, "lines:", window.warning_bar.lines())
    window.doc.undo_stack.setClean()
    window.close()
    app.quit()


QTimer.singleShot(1500, tick)
app.exec()
