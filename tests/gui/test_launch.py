"""Launching: the headless CLI never imports Qt; the studio's entry point opens a window on a scene."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.smoke  # in the quick tier (docs/testing.md)


def test_headless_render_never_imports_qt(tmp_path):
    out = tmp_path / "x.png"
    code = textwrap.dedent(f"""
        import sys
        from lenslab.cli import main
        status = main(["cornell_box", "--headless", "-o", {str(out)!r}, "--spp", "1", "--width", "16", "--height", "16"])
        qt = sorted(m for m in sys.modules if m.startswith(("PySide6", "shiboken6", "lenslab.gui")))
        print("status", status, "qt", qt)
        sys.exit(status or (1 if qt else 0))
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    if "OpenGL" in result.stderr and result.returncode != 0:
        pytest.skip(result.stderr.strip())
    assert result.returncode == 0, result.stdout + result.stderr
    assert "qt []" in result.stdout
    assert out.is_file()


@pytest.mark.gl
def test_run_studio_opens_the_window_on_a_scene(qtbot, monkeypatch, tmp_path, gl_available):
    from PySide6.QtCore import QSettings, QTimer
    from PySide6.QtGui import QGuiApplication
    from PySide6.QtWidgets import QApplication

    from lenslab import cli
    from lenslab.gui import app as studio
    from lenslab.gui import main_window

    monkeypatch.setattr(main_window, "studio_settings", lambda: QSettings(str(tmp_path / "s.ini"), QSettings.IniFormat))
    seen = {}

    def look_and_close():
        if "title" in seen:  # scheduled twice (before and inside the event loop): the first call did it
            return
        # The window run_studio opened: the only one showing (earlier tests' closed windows may not be deleted yet).
        window = next((w for w in QApplication.topLevelWidgets()
                       if isinstance(w, main_window.MainWindow) and w.isVisible()), None)
        if window is None:  # not shown yet: the call scheduled inside the event loop will find it
            return
        seen["title"] = window.windowTitle()
        seen["f"] = window.doc.scene.camera.f_number
        seen["resolution"] = window.doc.scene.camera.resolution
        seen["render"] = window.doc.scene.render
        window.close()

    monkeypatch.setattr(QApplication, "exec", lambda self: (QTimer.singleShot(0, look_and_close), 0)[1] or
                        (QApplication.processEvents(), 0)[1])
    QTimer.singleShot(0, look_and_close)
    # Through the command line, as a user starts it: the studio applies every override a headless render does.
    assert cli.run(["cornell_box", "--f-stop", "8", "--width", "48", "--clamp", "5", "--seed", "3"]) == 0
    qtbot.waitUntil(lambda: "title" in seen, timeout=10000)
    assert seen["title"].startswith("Cornell Box (example)")
    assert seen["f"] == 8.0 and seen["resolution"] == (48, 48)
    assert seen["render"].clamp == 5.0 and seen["render"].seed == 3
    assert QGuiApplication.desktopFileName() == studio.DESKTOP_ID
