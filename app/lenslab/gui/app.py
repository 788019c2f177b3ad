"""Starting the studio: ``lenslab`` opens the window, ``lenslab SCENE`` opens it on a scene.

``run_studio`` is called by ``lenslab.cli`` with its parsed arguments (the scene, ``--device`` and the camera
overrides such as ``--f-stop``), builds the QApplication with LensLab's look and desktop identity, and returns the
exit status of the event loop.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

DESKTOP_ID = "io.github.lenslab.LensLab"


def create_application(argv: list[str] | None = None):
    from PySide6.QtGui import QGuiApplication
    from PySide6.QtWidgets import QApplication

    from lenslab import __version__
    from lenslab.gui.main_window import app_icon
    from lenslab.gui.qtcompat import guard_singletons
    from lenslab.gui.theme import apply_theme

    app = QApplication.instance()
    if app is None:
        app = QApplication(argv if argv is not None else sys.argv[:1])
    app.setApplicationName("LensLab")
    app.setApplicationDisplayName("LensLab")
    app.setOrganizationName("LensLab")
    app.setOrganizationDomain("lenslab.github.io")
    app.setApplicationVersion(__version__)
    QGuiApplication.setDesktopFileName(DESKTOP_ID)
    app.setWindowIcon(app_icon())
    apply_theme(app)
    guard_singletons(app)
    return app


def _camera_overrides(scene, args):
    """Apply the command line's camera settings (--f-stop, --focal-length, --focus-distance, --width, --height)."""
    changes = {}
    for attr, field in (("f_stop", "f_number"), ("focal_length", "focal_length_mm"),
                        ("focus_distance", "focus_distance_m")):
        value = getattr(args, attr, None)
        if value is not None:
            changes[field] = value
    width, height = getattr(args, "width", None), getattr(args, "height", None)
    if width or height:
        w, h = scene.camera.resolution
        if width and not height:
            height = max(1, round(width * h / w))
        elif height and not width:
            width = max(1, round(height * w / h))
        changes["resolution"] = (width, height)
    if changes:
        scene.camera = dataclasses.replace(scene.camera, **changes)
    render = {k: getattr(args, k, None) for k in ("seed", "max_depth", "sampler", "spp")}
    render = {k: v for k, v in render.items() if v is not None}
    if render:
        scene.render = dataclasses.replace(scene.render, **render)
    return scene


def run_studio(args) -> int:
    """Open the studio window; returns the process exit status."""
    from PySide6.QtWidgets import QMessageBox

    from lenslab.gui.document import Document  # noqa: F401  (imports Qt: fail here, before any window)
    from lenslab.gui.main_window import MainWindow
    from lenslab.scene.io.loader import open_scene, resolve_scene_path
    from lenslab.scene.scene import SceneError

    app = create_application()
    scene = path = None
    problem = None
    scene_arg = getattr(args, "scene", None)
    if scene_arg:
        try:
            path = resolve_scene_path(scene_arg)
            scene = _camera_overrides(open_scene(scene_arg), args)
        except (SceneError, OSError) as exc:
            problem = str(exc)
            scene = path = None
    window = MainWindow(scene, Path(path) if path else None, device_index=getattr(args, "device", None))
    window.show()
    if problem:
        QMessageBox.critical(window, "Cannot open scene", problem)
    _close_on_interrupt(window)
    return app.exec()


def _close_on_interrupt(window) -> None:
    """Ctrl+C in the terminal closes the window as the close button would (asking about unsaved changes)."""
    import signal

    from PySide6.QtCore import QTimer

    def interrupted(_signum, _frame):
        QTimer.singleShot(0, window.close)

    signal.signal(signal.SIGINT, interrupted)
    # Python runs signal handlers only between bytecodes: give it a moment several times a second.
    timer = QTimer(window)
    timer.timeout.connect(lambda: None)
    timer.start(250)


__all__ = ["run_studio", "create_application", "DESKTOP_ID"]
