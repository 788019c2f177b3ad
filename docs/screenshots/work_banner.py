"""Draws docs/screenshots/work-banner.png: the studio on the Cornell box, then File > Open of the marbles on sand,
grabbed while the new scene loads: the work banner over the last scene's picture, dimmed, says what is under way
(docs/studio.md, "It says what it is doing"). Run under a display, e.g.
    xvfb-run -a -s "-screen 0 1600x1000x24" python docs/screenshots/work_banner.py [OUT.png]"""
import sys
import tempfile

from PySide6.QtCore import QSettings, QTimer

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

out = sys.argv[1] if len(sys.argv) > 1 else "docs/screenshots/work-banner.png"
app = create_application()
settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
window = MainWindow(open_scene("cornell_box"), settings=settings, restore_layout=False)
window.resize(1400, 900)
window.show()
banner = window.render_status.work_banner
state = {"opened": False}


def tick() -> None:
    frame = window.controller.last_frame
    if not state["opened"]:
        if frame is None or frame.samples_per_pixel < 8:
            QTimer.singleShot(250, tick)
            return
        window.doc.undo_stack.setClean()
        window.files.open_path("marbles_on_sand", ask=False)
        state["opened"] = True
    if banner.text is None or not banner.text.startswith("Opening the scene:"):
        QTimer.singleShot(20, tick)
        return
    window.grab().save(out)
    print("wrote", out, "banner:", banner.text)
    window.doc.undo_stack.setClean()
    window.close()
    app.quit()


QTimer.singleShot(1000, tick)
app.exec()
