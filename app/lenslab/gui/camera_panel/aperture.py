"""The camera panel's aperture section: the f-number as a glyph of the iris, a combo of stops, −/+ buttons and a
slider, and the stop scale that one step moves on."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QColor, QFont, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QToolButton, QVBoxLayout, QWidget

from lenslab.gui import theme
from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.commands import push_values
from lenslab.gui.widgets import DragSlider, hint
from lenslab.optics import THIRD_STOPS, format_f_number, parse_f_number, step_stop
from lenslab.optics.stops import STOP_SCALES, marked_f_number
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.editable import CAMERA

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel

FULL_STOPS = STOP_SCALES["full"].exact  # labelled under the aperture slider
STOP_SCALE_NAMES = {"third": "Third stops", "half": "Half stops", "full": "Full stops"}
STEP_WORDS = {"third": "a third of a stop", "half": "half a stop", "full": "a stop"}


class IrisGlyph(QWidget):
    """The aperture as seen looking into the lens: a disc or a polygon of blades, its size following the f-number."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setFixedSize(QSize(46, 46))
        self.f_number = 2.8
        self.blades = 0
        self.rotation = 0.0

    def set_state(self, f_number: float, blades: int, rotation_deg: float) -> None:
        self.f_number, self.blades, self.rotation = f_number, blades, rotation_deg
        self.update()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        c = QPointF(self.width() / 2, self.height() / 2)
        outer = min(self.width(), self.height()) / 2 - 2
        p.setPen(QPen(QColor("#55575c"), 1.5))
        p.setBrush(QColor("#141517"))
        p.drawEllipse(c, outer, outer)
        # Opening radius relative to f/1.0, on an area (stop) scale that stays visible at f/22.
        r = outer * max(0.12, min(1.0, 1.2 / self.f_number ** 0.75))
        p.setPen(Qt.NoPen)
        p.setBrush(QColor(theme.ACCENT))
        if self.blades >= 3:
            poly = QPolygonF()
            for i in range(self.blades):
                a = math.radians(self.rotation) + 2 * math.pi * i / self.blades
                poly.append(QPointF(c.x() + r * math.cos(a), c.y() - r * math.sin(a)))
            p.drawPolygon(poly)
        else:
            p.drawEllipse(c, r, r)
        p.end()



class StopSlider(QWidget):
    """A slider over a list of f-stops (indices), with the full stops marked underneath."""

    moved = Signal(float, bool)  # f-number, merge

    def __init__(self, parent=None):
        super().__init__(parent)
        self.slider = DragSlider(Qt.Horizontal)
        self.labels = QWidget()
        self.labels.setFixedHeight(14)
        self.labels.paintEvent = self._paint_labels
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.slider)
        layout.addWidget(self.labels)
        self.scale: tuple[float, ...] = THIRD_STOPS
        self.slider.valueChanged.connect(self._changed)
        self._quiet = False
        self.set_scale(THIRD_STOPS)

    def set_scale(self, scale) -> None:
        self.scale = tuple(scale)
        self._quiet = True
        self.slider.setRange(0, len(self.scale) - 1)
        self.slider.setPageStep(3)
        self._quiet = False
        self.labels.update()

    def set_f_number(self, n: float) -> None:
        index = min(range(len(self.scale)), key=lambda i: abs(math.log(self.scale[i] / n)))
        self._quiet = True
        self.slider.setValue(index)
        self._quiet = False

    def _changed(self, index: int) -> None:
        if not self._quiet:
            self.moved.emit(float(self.scale[index]), True)

    def _paint_labels(self, event) -> None:
        p = QPainter(self.labels)
        font = QFont(self.font())
        font.setPointSizeF(max(7.0, font.pointSizeF() - 2))
        p.setFont(font)
        p.setPen(QColor("#8c8f94"))
        metrics = p.fontMetrics()
        n = len(self.scale)
        handle = 12
        width = self.labels.width()
        span = width - handle
        # The ends, then the full stops between them, each where it fits without touching a label already drawn.
        marked = [i for i, stop in enumerate(self.scale) if any(math.isclose(stop, s, rel_tol=1e-3) for s in FULL_STOPS)]
        drawn: list[tuple[float, float]] = []
        for i in [0, n - 1] + [i for i in marked if i not in (0, n - 1)]:
            text = f"{marked_f_number(self.scale[i]):g}"
            half = metrics.horizontalAdvance(text) / 2 + 1
            x = min(max(handle / 2 + span * i / max(1, n - 1), half), width - half)  # never cut at the edges
            if any(x - half < right + 4 and x + half > left - 4 for left, right in drawn):
                continue
            drawn.append((x - half, x + half))
            p.drawText(QRectF(x - half, 0, 2 * half, 14), Qt.AlignCenter, text)
        p.end()



class ApertureSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "aperture", "Aperture")
        row = QHBoxLayout()
        self.iris = IrisGlyph()
        row.addWidget(self.iris)
        self.open_up = QToolButton()
        self.open_up.setText("−")
        self.open_up.setToolTip("Open up a third of a stop ([)")
        self.open_up.clicked.connect(lambda: self.step_aperture(-1))
        self.aperture_combo = QComboBox()
        self.aperture_combo.setObjectName("apertureCombo")
        self.aperture_combo.setEditable(True)
        self.aperture_combo.setInsertPolicy(QComboBox.NoInsert)
        self.aperture_combo.setMinimumWidth(90)
        self.aperture_combo.setToolTip("f-number: choose a stop or type any value (2.8, f/3, 1:2.8); a marked stop "
                                       "means its exact value (f/11 is 11.31)")
        self.aperture_combo.currentIndexChanged.connect(self._aperture_chosen)
        self.aperture_combo.lineEdit().editingFinished.connect(self._aperture_typed)
        self.stop_down = QToolButton()
        self.stop_down.setText("+")
        self.stop_down.setToolTip("Stop down a third of a stop (])")
        self.stop_down.clicked.connect(lambda: self.step_aperture(+1))
        row.addWidget(self.open_up)
        row.addWidget(self.aperture_combo, 1)
        row.addWidget(self.stop_down)
        self.add(row)
        self.stop_slider = StopSlider()
        self.stop_slider.moved.connect(lambda n, merge: self.set_f_number(n, merge, self.stop_slider.slider.gesture))
        self.add(self.stop_slider)
        steps = QHBoxLayout()
        self.stop_scale_combo = QComboBox()
        self.stop_scale_combo.setObjectName("stopScale")
        for name, text in STOP_SCALE_NAMES.items():
            self.stop_scale_combo.addItem(text, name)
        self.stop_scale_combo.setToolTip("What one step of [ and ], the −/+ buttons and the shutter's steps move: "
                                         "the scale shows marked stops, the camera takes the exact ones (f/11 is "
                                         "11.31)")
        self.stop_scale_combo.currentIndexChanged.connect(self._stop_scale_chosen)
        steps.addWidget(QLabel("Steps"))
        steps.addWidget(self.stop_scale_combo)
        steps.addStretch(1)
        self.add(steps)
        self.aperture_info = hint("")
        self.add(self.aperture_info)

    # -- edits ----------------------------------------------------------------------------------------------------
    def _stop_scale_chosen(self, index: int) -> None:
        if self._updating or index < 0:
            return
        self.panel.choose_stop_scale(self.stop_scale_combo.itemData(index))

    def set_f_number(self, n: float, merge: bool = False, gesture: object | None = None) -> None:
        lens = self.doc.lens
        if lens is not None:
            clamped = lens.clamp_f_number(n)
            if not math.isclose(clamped, n, rel_tol=1e-9):
                self.panel.status_message.emit(f"The {lens.name} goes from {format_f_number(lens.widest_f_number)} "
                                               f"to {format_f_number(lens.narrowest_f_number)}")
            n = clamped
        push_values(self.doc, CAMERA, {("f_number",): float(n)}, f"Aperture {format_f_number(n)}", merge, gesture)
        self.panel.refresh()  # the clamp may leave the camera as it was; show the truth either way

    def step_aperture(self, steps: int) -> None:
        self.set_f_number(step_stop(self.doc.scene.camera.f_number, steps, self.panel.stop_scale()), merge=True)

    def _aperture_chosen(self, index: int) -> None:
        if self._updating or index < 0:
            return
        value = self.aperture_combo.itemData(index)
        if value is not None:
            self.set_f_number(float(value))

    def _aperture_typed(self) -> None:
        if self._updating:
            return
        text = self.aperture_combo.lineEdit().text()
        if text.strip() == format_f_number(self.doc.scene.camera.f_number):
            return  # the camera's own value as shown (f/0.1234 shows "f/0.12"): leaving the field changes nothing
        try:
            n = parse_f_number(text, self.panel.scale_name)
        except ValueError as exc:
            self.panel.status_message.emit(str(exc))
            self.panel.refresh()
            return
        if not math.isclose(n, self.doc.scene.camera.f_number, rel_tol=1e-9):
            self.set_f_number(n)

    # -- following the document ---------------------------------------------------------------------------------
    def refresh(self, cam: ThinLensCamera, stops: tuple[float, ...], scale_name: str, light: float) -> None:
        """Show ``cam``'s aperture on the scale ``stops`` (the exact f-numbers of ``scale_name`` the lens has), with
        ``light``, the fraction of the round stop's light its stop passes."""
        with self._showing_camera():
            if [self.aperture_combo.itemData(i) for i in range(self.aperture_combo.count())] != list(stops):
                self.aperture_combo.clear()
                for stop in stops:
                    self.aperture_combo.addItem(format_f_number(stop), float(stop))
            index = next((i for i, s in enumerate(stops) if math.isclose(s, cam.f_number, rel_tol=1e-3)), -1)
            self.aperture_combo.setCurrentIndex(index)
            self.aperture_combo.setEditText(format_f_number(cam.f_number))
            if not self.stop_slider.slider.isSliderDown():  # never fight the hand on the slider
                self.stop_slider.set_scale(stops)
                self.stop_slider.set_f_number(cam.f_number)
            self.open_up.setEnabled(cam.f_number > stops[0] * 1.0001)
            self.stop_down.setEnabled(cam.f_number < stops[-1] * 0.9999)
            diameter = cam.focal_length_mm / cam.f_number
            brightness = {"physical": "Each stop is a stop of light (physical exposure).",
                          "auto": "The auto exposure's shutter makes up for each stop (aperture priority)."}.get(
                cam.exposure_mode, "Brightness stays the same at every aperture (exposure is compensated).")
            if cam.aperture_image:
                iris = f"the stop is {Path(cam.aperture_image).name}"
            else:
                iris = (f"{cam.aperture_blades} blades" if cam.aperture_blades >= 3 else "round")
                extras = [f"squeeze {cam.anamorphic_squeeze:g}" if cam.anamorphic_squeeze != 1 else "",
                          f"cat's eye {cam.barrel_clipping:g}" if cam.barrel_clipping > 0 else ""]
                iris = ", ".join([iris] + [e for e in extras if e])
            self.aperture_info.setText(f"Entrance pupil {diameter:.1f} mm ({iris})"
                                       + (f", passing {light:.0%} of the round stop's light" if light < 0.999 else "")
                                       + f". {brightness}")
            step = STEP_WORDS[scale_name]
            self.open_up.setToolTip(f"Open up {step} ([)")
            self.stop_down.setToolTip(f"Stop down {step} (])")
            self.stop_scale_combo.setCurrentIndex(self.stop_scale_combo.findData(scale_name))
            self.stop_slider.slider.setPageStep(STOP_SCALES[scale_name].steps_per_stop)
            self.iris.set_state(cam.f_number, cam.aperture_blades, cam.blade_rotation_deg)
