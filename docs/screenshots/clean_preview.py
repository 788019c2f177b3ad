"""Draws docs/screenshots/clean-preview.png: the studio on the Cornell box, its lens zoomed from 50 to 60 mm once
its picture is clean, grabbed at the edit's first picture: the denoised quarter-resolution preview, tagged as
one, with the camera tag already the new focal length's and focus peaking (on) waiting for a picture worth
judging (docs/studio.md, "Clean after every edit"). Run under a display, e.g.
    xvfb-run -a -s "-screen 0 1600x1000x24" python docs/screenshots/clean_preview.py [OUT.png]"""
import sys
import tempfile

from PySide6.QtCore import QSettings, QTimer

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

out = sys.argv[1] if len(sys.argv) > 1 else "docs/screenshots/clean-preview.png"
app = create_application()
settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
settings.setValue("viewport/denoise", True)
settings.setValue("overlays/peaking", True)
window = MainWindow(open_scene("cornell_box"), settings=settings, restore_layout=False)
window.resize(1400, 900)
window.show()
controller = window.controller
state = {"edited": None}


def shoot(frame) -> None:
    if state["edited"] is None or frame.generation < state["edited"] or not frame.preview:
        return
    window.grab().save(out)
    print("wrote", out, "tag:", window.viewport.hud_text, "| state:", samples_shown())
    window.doc.undo_stack.setClean()
    window.close()
    app.quit()


def samples_shown() -> str:
    return window.render_status.spp_label.text()


def tick() -> None:
    frame = controller.last_frame
    if frame is None or frame.preview or frame.samples_per_pixel < 16:
        QTimer.singleShot(250, tick)
        return
    window.doc.set_camera(focal_length_mm=window.doc.scene.camera.focal_length_mm * 1.2)
    state["edited"] = controller.generation


controller.frame_ready.connect(shoot)
QTimer.singleShot(500, tick)
app.exec()
