"""Draws docs/screenshots/render-region.png: the marbles on sand in the studio, the camera orbited a little with
the middle button (one undo step), and a render region drawn over the glass marble refining it alone. Run under a
display, e.g.
    xvfb-run -a -s "-screen 0 1600x1000x24" python docs/screenshots/render_region.py [REGION_SPP] [OUT.png]"""
import sys
import tempfile

from PySide6.QtCore import QEvent, QPointF, QSettings, Qt, QTimer
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

region_spp = int(sys.argv[1]) if len(sys.argv) > 1 else 64
out = sys.argv[2] if len(sys.argv) > 2 else "docs/screenshots/render-region.png"
app = create_application()
settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
settings.setValue("viewport/sample_limit", None)
window = MainWindow(open_scene("marbles_on_sand"), settings=settings, restore_layout=False)
window.resize(1400, 900)
window.show()
viewport = window.viewport
state = {"step": "orbit"}


def mouse(kind, pos, button, buttons):
    event = QMouseEvent(kind, QPointF(*pos), viewport.mapToGlobal(QPointF(*pos)), button, buttons, Qt.NoModifier)
    QApplication.sendEvent(viewport, event)


def drag(start, end, button):
    mouse(QEvent.MouseButtonPress, start, button, button)
    for i in range(1, 9):
        t = i / 8
        mouse(QEvent.MouseMove, (start[0] + (end[0] - start[0]) * t, start[1] + (end[1] - start[1]) * t),
              Qt.NoButton, button)
    mouse(QEvent.MouseButtonRelease, end, button, Qt.NoButton)


def tick() -> None:
    frame = window.controller.last_frame
    if frame is None or frame.samples_per_pixel < 2:
        QTimer.singleShot(250, tick)
        return
    if state["step"] == "orbit":
        centre = (viewport.width() / 2, viewport.height() / 2)
        drag(centre, (centre[0] - 12, centre[1] + 6), Qt.MiddleButton)  # orbit: one undo step
        state["step"] = "region"
        QTimer.singleShot(1500, tick)
    elif state["step"] == "region":
        window.set_tool("region")
        rect = viewport.image_rect()
        drag((rect.center().x() - 150, rect.center().y() - 120), (rect.center().x() + 150, rect.center().y() + 120),
             Qt.LeftButton)
        state["step"] = "wait"
        QTimer.singleShot(500, tick)
    elif frame.region is None or frame.samples_per_pixel < region_spp:
        QTimer.singleShot(250, tick)
    else:
        window.statusBar().showMessage("Refining the render region; Alt+R renders the whole picture again.")
        QTimer.singleShot(300, grab)


def grab() -> None:
    window.grab().save(out)
    print("wrote", out, "history:", [window.doc.undo_stack.text(i) for i in range(window.doc.undo_stack.count())])
    window.doc.undo_stack.setClean()
    window.close()
    app.quit()


QTimer.singleShot(1000, tick)
app.exec()
