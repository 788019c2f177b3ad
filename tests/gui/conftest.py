"""Fixtures for the studio's tests: pytest-qt on the offscreen platform, the render worker on llvmpipe.

Windows render tiny images (64 x 48); every window is closed at the end of its test, and the test fails if its
render thread did not stop. The studio's tests are the slow tier (docs/testing.md) but for its smoke tests,
marked ``smoke``: the window opens on a scene and renders, the camera panel edits and undoes, an export is
written, the scene's events reach the widgets.
"""

from __future__ import annotations

import dataclasses

import pytest

pytest.importorskip("PySide6")
pytest.importorskip("pytestqt")

SMALL = (64, 48)


@pytest.hookimpl(tryfirst=True)  # before -m deselects: the marks must be on the items by then
def pytest_collection_modifyitems(config, items):
    """Every studio test not marked ``smoke`` is in the slow tier."""
    here = __import__("pathlib").Path(__file__).parent
    for item in items:
        if here in item.path.parents and item.get_closest_marker("smoke") is None:
            item.add_marker(pytest.mark.slow)


@pytest.fixture
def settings(tmp_path):
    """A QSettings file of the test's own, so that no test reads or writes the user's layout or recent files."""
    from PySide6.QtCore import QSettings

    settings = QSettings(str(tmp_path / "studio.ini"), QSettings.IniFormat)
    # The studio's tests render the export's tiny pixels (not the viewport widget's, which the tests of the
    # viewport's own size choose), without the denoiser (whose tests turn it on).
    settings.setValue("viewport/quality", "export")
    settings.setValue("viewport/denoise", False)
    return settings


@pytest.fixture
def small_scene():
    from lenslab.scene.io.loader import open_scene

    scene = open_scene("cornell_box")
    scene.camera = dataclasses.replace(scene.camera, resolution=SMALL)
    return scene


@pytest.fixture
def gl_available(renderer):
    """Skips (with the reason) where no OpenGL 4.3 context can be made; the shared fixture knows how."""
    return renderer


@pytest.fixture
def make_window(qtbot, settings, gl_available):
    from lenslab.gui.app import create_application
    from lenslab.gui.main_window import MainWindow

    create_application()
    windows = []

    def make(scene, path=None, **kwargs):
        window = MainWindow(scene, path, settings=settings, restore_layout=False, **kwargs)
        window.show()
        windows.append(window)
        return window

    yield make
    for window in windows:
        window.doc.undo_stack.setClean()
        if window.isVisible():
            window.close()
        window.controller.shutdown()
        assert window.controller.worker.isFinished(), "the render thread did not stop"


@pytest.fixture
def window(make_window, small_scene):
    return make_window(small_scene)
