"""The scene's events: a plain Python emitter, no Qt, that the studio's widgets listen to directly."""

import subprocess
import sys

import pytest

from lenslab.scene.events import EventEmitter, SceneChange, SceneEvents

pytestmark = pytest.mark.smoke  # in the quick tier (docs/testing.md)


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


def test_a_failing_listener_is_reported_and_the_others_still_hear_the_change(monkeypatch):
    """As with a Qt signal's slots: one broken observer neither silences the rest nor unwinds the edit."""
    changed = SceneEvents().changed
    reported, heard = [], []
    monkeypatch.setattr(sys, "excepthook", lambda kind, error, trace: reported.append(error))

    def broken(change):
        raise RuntimeError("a bug in one listener")

    changed.connect(broken)
    changed.connect(heard.append)
    change = SceneChange("camera", ("camera",), ("f_number",))
    changed.emit(change)
    assert heard == [change]
    assert [str(e) for e in reported] == ["a bug in one listener"]


def test_a_listening_widget_is_disconnected_when_it_is_destroyed(qtbot):
    from PySide6.QtCore import QCoreApplication, QEvent
    from PySide6.QtWidgets import QWidget

    from lenslab.gui.document import listen

    changed = SceneEvents().changed

    class Listener(QWidget):
        def __init__(self):
            super().__init__()
            self.heard = []

        def on_change(self, change):
            self.heard.append(change)

    widget = Listener()
    listen(changed, widget, widget.on_change)
    changed.emit(SceneChange("scene"))
    assert len(widget.heard) == 1 and len(changed) == 1
    widget.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.DeferredDelete)
    assert len(changed) == 0
    changed.emit(SceneChange("scene"))  # would call into a deleted widget, and raise, if still connected


@pytest.mark.gl
def test_the_studio_hears_an_edit_made_on_the_scene_itself(qtbot, window):
    """No Qt signal in between: an edit made on the model, as a script would, reaches the property editor, the
    camera panel, the viewport's tag and the render worker's feeder."""
    doc = window.doc
    assert not hasattr(doc, "changed")  # nothing re-emits the scene's events as a Qt signal
    tall = next(p for p, n in doc.model.walk_nodes() if n.name == "tall box")
    doc.set_selection([("node", tall)])
    generation = window.controller.generation
    doc.model.apply_value(("node", tall), ("name",), "giant box")
    assert window.properties.title.text() == "giant box"
    assert window.controller.generation == generation + 1
    doc.model.apply_value(("camera",), ("f_number",), 5.6)
    assert window.camera_panel.aperture_combo.currentText() == "f/5.6"
    assert window.controller.generation == generation + 2
    # The viewport's camera tag describes the picture on screen: it follows once the edit's picture comes.
    qtbot.waitUntil(lambda: "f/5.6" in window.viewport.hud_text, timeout=20000)


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


def test_changing_an_emitters_type_keeps_its_unit_only_where_the_new_type_has_it():
    from lenslab.gui.properties import convert_type
    from lenslab.scene.lights import PointLight, SpotLight
    from lenslab.scene.scene import ConstantEnvironment, EnvironmentMap

    assert convert_type(PointLight("bulb", unit="lumens"), SpotLight).unit == "lumens"
    assert convert_type(EnvironmentMap(file="sky.exr", unit="ev"), ConstantEnvironment).unit == "ev"
    # A map's plain scale is no unit a constant sky has: the new sky takes its own default.
    assert convert_type(EnvironmentMap(file="sky.exr"), ConstantEnvironment).unit == "nits"
