"""The wheel scrolls panels; it changes a value only in the control that has the keyboard focus.

Qt's sliders, spin boxes and lists take the wheel wherever the mouse happens to be, so scrolling a long panel
changes whatever passes under the cursor: a focus slider refocuses the camera and adds a row to the History. Most
pro tools (Blender, Resolve, Nuke) take the wheel only in a control the user has clicked or tabbed into, and
otherwise scroll the panel. Each panel hands its value controls to ``guard_wheels`` once it has made them (the
property editor each time it rebuilds, the window once more for everything it holds): a wheel over an unfocused
control is passed on to its parents (the scroll area scrolls), and a control is never given the focus by the
wheel alone. Everything else keeps its wheel: the viewport's zoom and dolly, scroll bars, lists of rows, a
focused field.

The guard watches those controls alone, never the whole application: an application-wide filter written in
Python would make every event of the window wait for the interpreter, which the render thread holds for a
whole dispatch (a tenth of a second during an export), and the window would freeze while it renders.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QAbstractSlider, QAbstractSpinBox, QApplication, QComboBox, QScrollBar, QWidget

VALUE_CONTROLS = (QAbstractSlider, QAbstractSpinBox, QComboBox)
_GUARDED = "lenslabWheelGuarded"  # a dynamic property: the control has the guard already


def is_value_control(widget) -> bool:
    """A control whose value the wheel would change: sliders, spin boxes, drop-down lists; not scroll bars, whose
    wheel is scrolling."""
    return isinstance(widget, VALUE_CONTROLS) and not isinstance(widget, QScrollBar)


class WheelGuard(QObject):
    """The event filter on each guarded control: see the module's docstring."""

    def eventFilter(self, watched, event) -> bool:
        if event.type() == QEvent.Wheel and not watched.hasFocus():
            # Ignored and filtered: Qt offers the wheel to the control's parents, up to the scroll area.
            event.ignore()
            return True
        return False


def guard_wheels(root: QWidget) -> None:
    """Guard every value control in ``root`` (``root`` too, if it is one) not guarded yet."""
    app = QApplication.instance()
    guard = app.findChild(WheelGuard)
    if guard is None:
        guard = WheelGuard(app)
    controls = root.findChildren(QWidget)
    for widget in [root, *controls]:
        if is_value_control(widget) and not widget.property(_GUARDED):
            widget.setProperty(_GUARDED, True)
            widget.installEventFilter(guard)
            keep_wheel_from_giving_focus(widget)


def keep_wheel_from_giving_focus(widget: QWidget) -> None:
    """A drop-down list takes the focus from the wheel by default (Qt.WheelFocus), and would then take the turn
    it was given: it takes the focus from a click or the Tab key instead."""
    if widget.focusPolicy() == Qt.WheelFocus:
        widget.setFocusPolicy(Qt.StrongFocus)
