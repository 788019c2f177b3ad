"""Draws docs/screenshots/real-lens-studio.png and real-lens-diagram.png: the depth-of-field chart in the studio
with the 50 mm f/2 double-Gauss mounted from the lens buttons, and a close crop of the lens section's side view.
Run under a display, e.g.
    xvfb-run -a -s "-screen 0 1600x1000x24" python real_lens_shots.py [LENS] [F_NUMBER] [SPP] [OUT_DIR]"""
import sys
import tempfile

from PySide6.QtCore import QSettings, QTimer

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

lens_name = sys.argv[1] if len(sys.argv) > 1 else "50 mm f/2 double-Gauss"
f_number = float(sys.argv[2]) if len(sys.argv) > 2 else 2.8
spp = int(sys.argv[3]) if len(sys.argv) > 3 else 16
out = sys.argv[4] if len(sys.argv) > 4 else "docs/screenshots"
app = create_application()
settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
window = MainWindow(open_scene("dof_chart"), settings=settings, restore_layout=False)
window.resize(1400, 900)
window.show()
panel = window.camera_panel
lens = next(lens for lens in panel.lenses if lens.name == lens_name)
panel.lens_buttons[1 + panel.lenses.index(lens)].click()
panel.set_f_number(f_number)


def tick() -> None:
    frame = window.controller.last_frame
    if frame is None or frame.samples_per_pixel < spp:
        QTimer.singleShot(250, tick)
        return
    window.grab().save(f"{out}/real-lens-studio.png")
    section = panel.sections["lens"]
    section.grab().save(f"{out}/real-lens-section.png")
    diagram = panel.lens_diagram
    rect = diagram.geometry().united(panel.lens_diagram_info.geometry()).adjusted(-4, -4, 4, 4)
    diagram.parentWidget().grab(rect).save(f"{out}/real-lens-diagram.png")
    print(panel.lens_diagram_info.text(), diagram.size(), flush=True)
    window.doc.undo_stack.setClean()
    window.close()
    app.quit()


QTimer.singleShot(500, tick)
app.exec()
