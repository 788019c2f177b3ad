"""Starting the studio: ``lenslab`` opens the window, ``lenslab SCENE`` opens it on a scene.

``run_studio`` is called by ``lenslab.cli`` with the scene, the command line's overrides (``--f-number``,
``--spp``, ``--clamp``, ``-D`` ...: the same :class:`~lenslab.scene.overrides.SceneOverrides` a headless render
applies) and ``--device``, builds the QApplication with LensLab's look and desktop identity, and returns the
exit status of the event loop.
"""

from __future__ import annotations

import sys
from pathlib import Path

from lenslab.scene.overrides import SceneOverrides

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


def run_studio(scene_ref: str | None = None, overrides: SceneOverrides | None = None,
               device_index: int | None = None) -> int:
    """Open the studio window, on ``scene_ref`` with the command line's ``overrides`` if given (the same
    :class:`SceneOverrides` a headless render applies); returns the process exit status."""
    from PySide6.QtWidgets import QMessageBox

    from lenslab.gui.document import Document  # noqa: F401  (imports Qt: fail here, before any window)
    from lenslab.gui.main_window import MainWindow
    from lenslab.scene.io.loader import resolve_scene_path
    from lenslab.scene.scene import SceneError

    app = create_application()
    scene = path = None
    problem = None
    warnings: list[str] = []  # what the scene's reader approximated or left out: shown in the window
    if scene_ref:
        try:
            path = resolve_scene_path(scene_ref)
            scene = (overrides or SceneOverrides()).open(scene_ref, warn=warnings.append)
        except (SceneError, OSError, ValueError) as exc:
            problem = str(exc)
            scene = path = None
    window = MainWindow(scene, Path(path) if path else None, device_index=device_index)
    window.show()
    if path is not None:
        window.report_warnings(str(path), warnings)
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
