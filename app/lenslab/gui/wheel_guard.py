"""The wheel scrolls panels; it changes a value only in the control that has the keyboard focus.

Qt's sliders, spin boxes and lists take the wheel wherever the mouse happens to be, so scrolling a long panel
changes whatever passes under the cursor: a focus slider refocuses the camera and adds a row to the History. Most
pro tools (Blender, Resolve, Nuke) take the wheel only in a control the user has clicked or tabbed into, and
otherwise scroll the panel. One filter on the application does that for every such control, present and to come:
a wheel over an unfocused value control is passed on to its parents (the scroll area scrolls), and a control is
never given the focus by the wheel alone. Everything else keeps its wheel: the viewport's zoom and dolly, scroll
bars, lists of rows, a focused field.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QAbstractSlider, QAbstractSpinBox, QApplication, QComboBox, QScrollBar, QWidget


def is_value_control(widget) -> bool:
    """A control whose value the wheel would change: sliders, spin boxes (and their fields), drop-down lists;
    not scroll bars, whose wheel is scrolling."""
    return isinstance(widget, (QAbstractSlider, QAbstractSpinBox, QComboBox)) and not isinstance(widget, QScrollBar)


class WheelGuard(QObject):
    """An application event filter: see the module's docstring."""

    def eventFilter(self, watched, event) -> bool:
        kind = event.type()
        if kind == QEvent.Wheel and is_value_control(watched) and not watched.hasFocus():
            # Ignored and filtered: Qt offers the wheel to the control's parents, up to the scroll area.
            event.ignore()
            return True
        if kind == QEvent.Polish and is_value_control(watched):
            keep_wheel_from_giving_focus(watched)
        return False


def keep_wheel_from_giving_focus(widget: QWidget) -> None:
    """A drop-down list takes the focus from the wheel by default (Qt.WheelFocus), and would then take the turn
    it was given: it takes the focus from a click or the Tab key instead."""
    if widget.focusPolicy() == Qt.WheelFocus:
        widget.setFocusPolicy(Qt.StrongFocus)


def install_wheel_guard(app: QApplication) -> WheelGuard:
    """Guard every value control of ``app`` (once, however often it is called)."""
    guard = app.findChild(WheelGuard)
    if guard is None:
        guard = WheelGuard(app)
        app.installEventFilter(guard)
        for widget in app.allWidgets():  # those made before the guard was installed are polished already
            if is_value_control(widget):
                keep_wheel_from_giving_focus(widget)
    return guard
