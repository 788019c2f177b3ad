"""Draws docs/screenshots/guides-and-peaking.png (the marbles on sand: rule of thirds, focus peaking) and
docs/screenshots/histogram-loupe.png (the Cornell box: the histogram, clipping warnings, the loupe at 4:1 on the
short box's corner) in a 1400 x 900 studio. Run under a display, e.g.
    xvfb-run -a -s "-screen 0 1600x1000x24" python docs/screenshots/judging_aids.py [SPP] [WHICH]
(WHICH: peaking, histogram or both, the default). The loupe follows the cursor, which a grab does not show: it
is put on its pixel by hand."""
import subprocess
import sys
import tempfile

from PySide6.QtCore import QSettings, QTimer

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

spp = int(sys.argv[1]) if len(sys.argv) > 1 else 24
which = sys.argv[2] if len(sys.argv) > 2 else "both"
if which == "both":  # one studio per process: each closes with its render thread
    for name in ("peaking", "histogram"):
        subprocess.run([sys.executable, __file__, str(spp), name], check=True)
    sys.exit(0)
app = create_application()


def peaking(aids, viewport) -> None:
    aids.set_guides("thirds")
    aids.set_peaking(True)


def histogram(aids, viewport) -> None:
    aids.set_clipping(True)
    aids.set_loupe(True)
    aids.set_loupe_zoom(4)
    gate = viewport.gate_rect
    aids.loupe.set_pixel((int(gate.left() + gate.width() * 0.515), int(gate.top() + gate.height() * 0.665)))


shots = {"peaking": ("marbles_on_sand", peaking, "docs/screenshots/guides-and-peaking.png"),
         "histogram": ("cornell_box", histogram, "docs/screenshots/histogram-loupe.png")}
scene, setup, out = shots[which]


def shoot() -> None:
    settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
    settings.setValue("viewport/sample_limit", spp)
    window = MainWindow(open_scene(scene), settings=settings, restore_layout=False)
    window.resize(1400, 900)
    window.show()

    def tick() -> None:
        frame = window.controller.last_frame
        if frame is None or not frame.converged or window.viewport.gate_rect is None:
            QTimer.singleShot(500, tick)
            return
        setup(window.viewing, window.viewport)
        QTimer.singleShot(1000, finish)  # the overlays are worked out within a quarter of a second

    def finish() -> None:
        window.viewport.repaint()
        window.grab().save(out)
        print("wrote", out, flush=True)
        window.doc.undo_stack.setClean()
        window.close()
        app.quit()

    QTimer.singleShot(1000, tick)


QTimer.singleShot(0, shoot)
app.exec()
