"""Draws docs/screenshots/export-refused.png: File > Export to a folder that cannot take the file (here a path
whose "folder" is a file) is refused at once, before anything renders, with the folder and the problem named
(docs/studio.md, "Export"). Run under a display, e.g.
    xvfb-run -a -s "-screen 0 1400x900x24" python docs/screenshots/export_refused.py [OUT.png]"""
import dataclasses
import sys
import tempfile
from pathlib import Path

from PySide6.QtCore import QSettings, QTimer
from PySide6.QtWidgets import QApplication

from lenslab.gui.app import create_application
from lenslab.gui.document import copy_scene
from lenslab.gui.main_window import MainWindow
from lenslab.gui.worker import ExportRequest
from lenslab.scene.io.loader import open_scene

out = sys.argv[1] if len(sys.argv) > 1 else "docs/screenshots/export-refused.png"
not_a_folder = Path(tempfile.mkdtemp()) / "renders"
not_a_folder.write_text("a file where the folder should be")
app = create_application()
settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
window = MainWindow(open_scene("dof_chart"), settings=settings, restore_layout=False)
window.resize(1400, 900)
window.move(0, 0)
window.show()
state = {"asked": False}


def tick() -> None:
    frame = window.controller.last_frame
    if frame is None or frame.samples_per_pixel < 4:
        QTimer.singleShot(250, tick)
        return
    scene = copy_scene(window.doc.scene)
    scene.camera = dataclasses.replace(scene.camera, resolution=(6000, 4000))
    QTimer.singleShot(800, grab)  # the refusal is a modal message box: grab the screen while it is up
    window.export_flow.start(ExportRequest(scene=scene, path=not_a_folder / "chart.exr"))


def grab() -> None:
    box = QApplication.activeModalWidget()
    QApplication.primaryScreen().grabWindow(0).save(out)
    print("wrote", out, "render started:", window.export_flow.running)
    if box is not None:
        box.close()
    window.doc.undo_stack.setClean()
    window.close()
    app.quit()


QTimer.singleShot(1000, tick)
app.exec()
