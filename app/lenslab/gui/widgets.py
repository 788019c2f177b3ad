"""Small widgets the panels are built from: collapsible sections, spin boxes you can scrub by dragging their
label (Blender style: Shift for fine steps, Ctrl for coarse), sliders that know their drags, vector and colour
editors."""

from __future__ import annotations

import math

from typing import Callable

from PySide6.QtCore import QPoint, QSize, Qt, Signal
from PySide6.QtGui import QColor, QCursor, QPainter
from PySide6.QtWidgets import (
    QColorDialog,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QSizePolicy,
    QSlider,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from lenslab.color import linear_to_srgb, srgb_to_linear
from lenslab.gui.theme import DIM_TEXT


class Section(QWidget):
    """A panel section with a header that folds it away, as in Lightroom's develop panels."""

    toggled = Signal(bool)

    def __init__(self, title: str, parent: QWidget | None = None, expanded: bool = True):
        super().__init__(parent)
        self.header = QToolButton(self)
        self.header.setObjectName("sectionHeader")
        self.header.setText(title)
        self.header.setCheckable(True)
        self.header.setChecked(expanded)
        self.header.setToolButtonStyle(Qt.ToolButtonTextBesideIcon)
        self.header.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
        self.header.setArrowType(Qt.DownArrow if expanded else Qt.RightArrow)
        self.body = QWidget(self)
        self.body_layout = QVBoxLayout(self.body)
        self.body_layout.setContentsMargins(4, 6, 4, 10)
        self.body_layout.setSpacing(6)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.header)
        layout.addWidget(self.body)
        self.body.setVisible(expanded)
        self.header.toggled.connect(self._toggle)

    def _toggle(self, on: bool) -> None:
        self.header.setArrowType(Qt.DownArrow if on else Qt.RightArrow)
        self.body.setVisible(on)
        self.toggled.emit(on)

    def add(self, widget_or_layout) -> None:
        if isinstance(widget_or_layout, QWidget):
            self.body_layout.addWidget(widget_or_layout)
        else:
            self.body_layout.addLayout(widget_or_layout)


class ScrubLabel(QLabel):
    """A label that drags the value of a spin box: one step per few pixels, or ``rate()`` per pixel where the
    field has a rate of its own (a position: as far as the object moves on screen, see ``properties.py``).
    Shift scrubs a tenth as fast, Ctrl ten times as fast."""

    scrub_started = Signal()
    scrub_finished = Signal()

    PIXELS_PER_STEP = 4

    def __init__(self, text: str, spin, colour: str | None = None, parent: QWidget | None = None):
        super().__init__(text, parent)
        self.spin = spin
        self.setCursor(QCursor(Qt.SizeHorCursor))
        self.setToolTip("Drag to change (Shift: fine, Ctrl: coarse)")
        if colour:
            self.setStyleSheet(f"color: {colour}; font-weight: 600;")
        self._origin: QPoint | None = None
        self._value = 0.0
        self.rate: Callable[[], float] | None = None  # value per pixel; None: a step per PIXELS_PER_STEP
        self._per_pixel = 0.0

    def mousePressEvent(self, event) -> None:
        if event.button() == Qt.LeftButton and self.spin.isEnabled():
            self._origin = event.globalPosition().toPoint()
            self._value = self.spin.value()
            # Asked once per drag: the object's depth, and so the rate, changes as it moves.
            rate = self.rate() if self.rate is not None else None
            self._per_pixel = rate if rate else self.spin.singleStep() / self.PIXELS_PER_STEP
            self.scrub_started.emit()
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event) -> None:
        if self._origin is None:
            return
        # Each move adds its own pixels at the speed of the keys held now: pressing Shift mid-drag slows the
        # rest of the drag down, it does not make the value jump.
        x = event.globalPosition().toPoint().x()
        dx, self._origin = x - self._origin.x(), QPoint(x, self._origin.y())
        factor = 0.1 if event.modifiers() & Qt.ShiftModifier else 10.0 if event.modifiers() & Qt.ControlModifier else 1.0
        self._value = min(max(self._value + dx * factor * self._per_pixel, self.spin.minimum()), self.spin.maximum())
        self.spin.setValue(round(self._value) if isinstance(self.spin, QSpinBox) else self._value)

    def mouseReleaseEvent(self, event) -> None:
        if self._origin is not None:
            self._origin = None
            self.scrub_finished.emit()
        super().mouseReleaseEvent(event)


def _decimals_for(lo: float, hi: float) -> int:
    return 3 if hi <= 1e4 else 2


class NumberEdit(QDoubleSpinBox):
    """A float spin box that commits on Enter, focus out, arrows and the wheel (not on every key typed)."""

    edited = Signal(float, bool)  # value, merge with the previous edit of this field

    def __init__(self, lo: float = -1e6, hi: float = 1e6, decimals: int | None = None, step: float | None = None,
                 suffix: str = "", parent: QWidget | None = None):
        super().__init__(parent)
        self.setRange(lo, hi)
        self.setDecimals(decimals if decimals is not None else _decimals_for(lo, hi))
        self.setSingleStep(step if step is not None else (0.01 if hi - lo <= 2 else 0.1))
        self.setKeyboardTracking(False)
        self.setAccelerated(True)
        self.setFocusPolicy(Qt.StrongFocus)  # the wheel only edits a focused field: scrolling a panel is safe
        if suffix:
            self.setSuffix(suffix)
        self.setProperty("noButtons", True)  # styled away: QSS + NoButtons hides the text
        self.setAlignment(Qt.AlignRight)
        self.valueChanged.connect(self._changed)
        self._quiet = False

    def wheelEvent(self, event) -> None:
        if self.hasFocus():
            super().wheelEvent(event)
        else:
            event.ignore()

    def set_quietly(self, value: float) -> None:
        self._quiet = True
        try:
            self.setValue(value)
        finally:
            self._quiet = False

    def _changed(self, value: float) -> None:
        if not self._quiet:
            self.edited.emit(value, True)


class IntEdit(QSpinBox):
    edited = Signal(int, bool)

    def __init__(self, lo: int = 0, hi: int = 1 << 30, suffix: str = "", parent: QWidget | None = None):
        super().__init__(parent)
        self.setRange(int(lo), int(min(hi, 2**31 - 1)))
        self.setKeyboardTracking(False)
        self.setFocusPolicy(Qt.StrongFocus)
        self.setProperty("noButtons", True)
        self.setAlignment(Qt.AlignRight)
        if suffix:
            self.setSuffix(suffix)
        self.valueChanged.connect(self._changed)
        self._quiet = False

    def wheelEvent(self, event) -> None:
        if self.hasFocus():
            super().wheelEvent(event)
        else:
            event.ignore()

    def set_quietly(self, value: int) -> None:
        self._quiet = True
        try:
            self.setValue(int(value))
        finally:
            self._quiet = False

    def _changed(self, value: int) -> None:
        if not self._quiet:
            self.edited.emit(value, True)


class SignedNumberEdit(QDoubleSpinBox):
    """A number shown with its sign, as a camera shows exposure compensation: +1.5, -0.7, 0.0. Commits on Enter,
    focus out, the arrows and the wheel (a focused field only)."""

    def __init__(self, lo: float, hi: float, decimals: int = 1, step: float = 0.1, suffix: str = "",
                 parent: QWidget | None = None):
        super().__init__(parent)
        self.setRange(lo, hi)
        self.setDecimals(decimals)
        self.setSingleStep(step)
        self.setKeyboardTracking(False)
        self.setFocusPolicy(Qt.StrongFocus)
        self.setAlignment(Qt.AlignRight)
        if suffix:
            self.setSuffix(suffix)

    def textFromValue(self, value: float) -> str:
        places = self.decimals()
        return f"{value:+.{places}f}" if round(value, places) else f"{0:.{places}f}"

    def wheelEvent(self, event) -> None:
        if self.hasFocus():
            super().wheelEvent(event)
        else:
            event.ignore()


class DragSlider(QSlider):
    """A slider that knows its drags: ``gesture`` is one token from the press on its handle to the release, and
    None otherwise (the keys, a focused slider's wheel, a click beside the handle). The edits a drag makes carry it,
    so that they are one step in the History however long the hand pauses on the way (lenslab.gui.commands)."""

    def __init__(self, orientation=Qt.Horizontal, parent: QWidget | None = None):
        super().__init__(orientation, parent)
        self.setFocusPolicy(Qt.StrongFocus)  # the wheel changes it only once clicked or tabbed into
        self.gesture: object | None = None
        self.sliderPressed.connect(self._pressed)
        self.sliderReleased.connect(self._released)

    def _pressed(self) -> None:
        self.gesture = object()

    def _released(self) -> None:
        self.gesture = None


class ResetSlider(QSlider):
    """A slider that goes back to ``default`` on a double click (as Lightroom's sliders do)."""

    def __init__(self, orientation=Qt.Horizontal, default: int = 0, parent: QWidget | None = None):
        super().__init__(orientation, parent)
        self.default = default

    def mouseDoubleClickEvent(self, event) -> None:
        if event.button() == Qt.LeftButton:
            self.setValue(self.default)
            event.accept()
        else:
            super().mouseDoubleClickEvent(event)


AXIS_COLOURS = ("#e06c6c", "#7fc56b", "#6b9be0")


class VectorEdit(QWidget):
    """N numbers in a row, each with a scrub label (X Y Z in the axis colours, or W H, or R G B)."""

    edited = Signal(tuple, bool)

    def __init__(self, labels=("X", "Y", "Z"), lo: float = -1e6, hi: float = 1e6, integer: bool = False,
                 decimals: int | None = None, step: float | None = None, colours=AXIS_COLOURS,
                 parent: QWidget | None = None):
        super().__init__(parent)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(3)
        self.spins = []
        self.labels: list[ScrubLabel] = []
        for i, text in enumerate(labels):
            spin = IntEdit(int(lo), int(hi)) if integer else NumberEdit(lo, hi, decimals, step)
            spin.setMinimumWidth(48)
            label = ScrubLabel(text, spin, colours[i] if colours and i < len(colours) else None)
            label.setFixedWidth(12)
            spin.edited.connect(self._emit)
            layout.addWidget(label)
            layout.addWidget(spin, 1)
            self.spins.append(spin)
            self.labels.append(label)

    def value(self) -> tuple:
        return tuple(s.value() for s in self.spins)

    def set_scrub_rate(self, rate: Callable[[], float] | None) -> None:
        """Scrub every number at ``rate()`` per pixel of drag (None: a step per few pixels)."""
        for label in self.labels:
            label.rate = rate

    def set_value(self, values) -> None:
        for spin, v in zip(self.spins, values):
            spin.set_quietly(v)

    def _emit(self, _value, merge: bool) -> None:
        self.edited.emit(self.value(), merge)


class ColorSwatch(QToolButton):
    """A flat colour chip showing a linear RGB colour as the display would (sRGB)."""

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self._rgb = (0.0, 0.0, 0.0)
        self.setFixedSize(QSize(36, 22))
        self.setToolTip("Pick a colour")

    def set_rgb(self, rgb) -> None:
        self._rgb = tuple(float(c) for c in rgb)
        self.update()

    def display_colour(self) -> QColor:
        peak = max(max(self._rgb), 1e-12)
        scale = 1.0 / peak if peak > 1.0 else 1.0  # show the hue of an emitter, not a clipped white
        r, g, b = (linear_to_srgb(c * scale) for c in self._rgb)
        return QColor.fromRgbF(r, g, b)

    def paintEvent(self, event) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.Antialiasing)
        painter.setPen(QColor("#101010"))
        painter.setBrush(self.display_colour())
        painter.drawRoundedRect(self.rect().adjusted(1, 1, -1, -1), 3, 3)
        painter.end()


class ColorEdit(QWidget):
    """A colour as linear RGB numbers with a swatch that opens a colour picker. Values above 1 (emitters) keep
    their strength: the picker chooses the hue, the brightest channel keeps its value."""

    edited = Signal(tuple, bool)

    def __init__(self, lo: float = 0.0, hi: float = 1.0, parent: QWidget | None = None):
        super().__init__(parent)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(4)
        self.swatch = ColorSwatch(self)
        self.swatch.clicked.connect(self._pick)
        self.vector = VectorEdit(("R", "G", "B"), lo, hi, decimals=3 if hi <= 1 else 2,
                                 step=0.01 if hi <= 1 else 0.1)
        self.vector.edited.connect(self._edited)
        layout.addWidget(self.swatch)
        layout.addWidget(self.vector, 1)
        self.hi = hi

    def value(self) -> tuple:
        return self.vector.value()

    def set_value(self, rgb) -> None:
        self.vector.set_value(rgb)
        self.swatch.set_rgb(rgb)

    def _edited(self, rgb, merge) -> None:
        self.swatch.set_rgb(rgb)
        self.edited.emit(rgb, merge)

    def _pick(self) -> None:
        current = self.value()
        peak = max(current)
        chosen = QColorDialog.getColor(self.swatch.display_colour(), self, "Colour")
        if not chosen.isValid():
            return
        rgb = tuple(srgb_to_linear(c) for c in (chosen.redF(), chosen.greenF(), chosen.blueF()))
        if peak > 1.0 and max(rgb) > 0:
            rgb = tuple(c / max(rgb) * peak for c in rgb)
        rgb = tuple(round(min(c, self.hi), 4) for c in rgb)
        self.set_value(rgb)
        self.edited.emit(rgb, False)


def hint(text: str) -> QLabel:
    label = QLabel(text)
    label.setObjectName("hint")
    label.setWordWrap(True)
    return label


def readout(text: str = "") -> QLabel:
    label = QLabel(text)
    label.setObjectName("readout")
    label.setTextInteractionFlags(Qt.TextSelectableByMouse)
    return label


def log_to_slider(value: float, lo: float, hi: float, steps: int = 1000) -> int:
    value = min(max(value, lo), hi)
    return round((math.log(value) - math.log(lo)) / (math.log(hi) - math.log(lo)) * steps)


def slider_to_log(position: int, lo: float, hi: float, steps: int = 1000) -> float:
    return math.exp(math.log(lo) + position / steps * (math.log(hi) - math.log(lo)))


__all__ = ["Section", "ScrubLabel", "NumberEdit", "IntEdit", "SignedNumberEdit", "DragSlider", "ResetSlider",
           "VectorEdit",
           "ColorEdit", "ColorSwatch", "hint", "readout", "log_to_slider", "slider_to_log", "DIM_TEXT"]
