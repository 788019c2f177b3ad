"""Draws docs/screenshots/layout-minimum.png, layout-default.png and layout-4k.png: the studio on the depth-of-field
chart at the smallest size its window allows, at the size it opens at, and at 3840 x 2160, the near card selected
(its Properties shown). The viewport renders the export's own pixels (480 x 320), as the tests do, so that a 4K
window costs llvmpipe no more than a small one. Run under a display as large as the largest size, e.g.
    xvfb-run -a -s "-screen 0 3840x2160x24" python docs/screenshots/layout_sizes.py [SPP] [WHICH]
(WHICH: minimum, default, 4k, or all, the default)."""
import dataclasses
import subprocess
import sys
import tempfile

from PySide6.QtCore import QSettings, QTimer

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

SIZES = {"minimum": None, "default": (1480, 920), "4k": (3840, 2160)}
spp = int(sys.argv[1]) if len(sys.argv) > 1 else 64  # one of the toolbar's limits, so that its box shows it
which = sys.argv[2] if len(sys.argv) > 2 else "all"
if which == "all":  # one studio per process: each closes with its render thread
    for name in SIZES:
        subprocess.run([sys.executable, __file__, str(spp), name], check=True)
    sys.exit(0)
out = f"docs/screenshots/layout-{which}.png"
app = create_application()


def shoot() -> None:
    settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
    settings.setValue("viewport/sample_limit", spp)
    settings.setValue("viewport/quality", "export")
    scene = open_scene("dof_chart")
    scene.camera = dataclasses.replace(scene.camera, resolution=(480, 320))
    window = MainWindow(scene, settings=settings, restore_layout=False)
    window.show()
    window.doc.set_selection([("node", (0,))])

    def size() -> None:
        extent = SIZES[which]
        window.resize(*(extent or (window.minimumSize().width(), window.minimumSize().height())))
        QTimer.singleShot(1000, tick)

    def tick() -> None:
        frame = window.controller.last_frame
        if frame is None or not frame.converged:
            QTimer.singleShot(500, tick)
            return
        QTimer.singleShot(1000, finish)  # the histogram and the overlays are worked out within a second

    def finish() -> None:
        window.viewport.repaint()
        window.grab().save(out)
        print("wrote", out, f"({window.width()} x {window.height()})", flush=True)
        window.doc.undo_stack.setClean()
        window.close()
        app.quit()

    QTimer.singleShot(500, size)


QTimer.singleShot(0, shoot)
app.exec()
