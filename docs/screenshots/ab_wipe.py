"""Draws docs/screenshots/ab-wipe.png: the depth-of-field chart in the studio, a snapshot at f/1.4 (A, left of the
divider) against the live picture at f/8 (B). Run under a display, e.g.
    xvfb-run -a -s "-screen 0 1600x1000x24" python docs/screenshots/ab_wipe.py [SPP] [OUT.png] [MODE]
(MODE: wipe, the default, or side)."""
import sys
import tempfile

from PySide6.QtCore import QSettings, QTimer

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

spp = int(sys.argv[1]) if len(sys.argv) > 1 else 256
out = sys.argv[2] if len(sys.argv) > 2 else "docs/screenshots/ab-wipe.png"
mode = sys.argv[3] if len(sys.argv) > 3 else "wipe"
app = create_application()
settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
settings.setValue("viewport/sample_limit", spp)
window = MainWindow(open_scene("dof_chart"), settings=settings, restore_layout=False)
window.resize(1400, 900)
window.show()
window.docks["snapshots"].raise_()
steps = iter(["f1.4", "snapshot", "f8", "compare", "grab"])
state = {"step": next(steps), "generation": None}


def converged() -> bool:
    frame = window.controller.last_frame
    return (frame is not None and frame.converged and state["generation"] is not None
            and frame.generation >= state["generation"])


def tick() -> None:
    step = state["step"]
    if step in ("f1.4", "f8"):
        window.doc.set_camera(f_number=1.4 if step == "f1.4" else 8.0)
        state["generation"] = window.controller.generation
    elif step in ("snapshot", "compare"):
        if not converged():
            QTimer.singleShot(250, tick)
            return
        if step == "snapshot":
            window.snapshots.take()
        else:
            window.snapshots.store.set_mode(mode)
            window.viewport.hide_focus_overlay()
    else:
        window.grab().save(out)
        print("wrote", out)
        window.doc.undo_stack.setClean()
        window.close()
        app.quit()
        return
    state["step"] = next(steps)
    QTimer.singleShot(1500 if step == "compare" else 250, tick)


QTimer.singleShot(1000, tick)
app.exec()
