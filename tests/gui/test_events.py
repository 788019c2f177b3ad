"""The scene's event emitter: plain Python, no Qt."""

import subprocess
import sys

import pytest

from lenslab.scene.events import EventEmitter, SceneChange, SceneEvents


def test_emitter_calls_connected_callbacks_in_order_and_can_block():
    emitter = EventEmitter()
    seen = []
    emitter.connect(lambda e: seen.append(("a", e)))
    second = emitter.connect(lambda e: seen.append(("b", e)))
    emitter.emit(1)
    with emitter.blocked():
        emitter.emit(2)
    emitter.disconnect(second)
    emitter.emit(3)
    assert seen == [("a", 1), ("b", 1), ("a", 3)]


def test_scene_change_says_whether_the_view_moved():
    assert not SceneChange("camera", ("camera",), ("f_number",)).geometry
    assert not SceneChange("camera", ("camera",), ("focus_distance_m",)).geometry
    assert SceneChange("camera", ("camera",), ("position",)).geometry
    assert SceneChange("node", ("node", (0,)), ("transform", "translate")).geometry
    assert not SceneChange("node", ("node", (0,)), ("material",)).geometry
    assert not SceneChange("material", ("material", "red"), ("albedo",)).geometry
    with pytest.raises(ValueError):
        SceneChange("colour")


def test_events_module_does_not_import_qt():
    code = "import sys, lenslab.scene.events; print(any(m.startswith('PySide6') for m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
    assert isinstance(SceneEvents().changed, EventEmitter)


def test_qt_calls_do_not_exhaust_none_and_true(qtbot):
    """PySide6 6.12.0 drops a reference to None on every void C++ call and one to True on every Python-side emit:
    without the studio's guard these loops run the counts to zero and the interpreter aborts."""
    import sys

    from PySide6.QtCore import QObject, Signal

    from lenslab.gui.app import create_application
    from lenslab.gui.qtcompat import binding_leaks, guard_active

    create_application()
    assert guard_active() == (binding_leaks() and sys.version_info < (3, 12))

    class Emitter(QObject):
        ping = Signal(int)

    emitter = Emitter()
    seen = []
    emitter.ping.connect(seen.append)
    for i in range(20000):
        emitter.ping.emit(i)
        emitter.setObjectName("x")  # a void call
        emitter.setObjectName("y")
    assert len(seen) == 20000
    assert sys.getrefcount(True) > 1000 and sys.getrefcount(None) > 1000


def test_changing_a_shapes_type_keeps_its_extent_and_its_colour():
    from lenslab.gui.properties import convert_type
    from lenslab.scene.materials import Diffuse, Emissive
    from lenslab.scene.shapes import Box, Rectangle, Sphere

    assert convert_type(Box(size=(0.2, 0.3, 0.1)), Sphere) == Sphere(radius=0.15)
    assert convert_type(Sphere(radius=0.25), Box) == Box(size=(0.5, 0.5, 0.5))
    assert convert_type(Sphere(radius=0.25), Rectangle) == Rectangle(size=(0.5, 0.5))
    assert convert_type(Diffuse((0.8, 0.1, 0.1)), Emissive).radiance == (0.8, 0.1, 0.1)
