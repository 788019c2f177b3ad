"""The camera panel's sensor section: a sensor preset or a custom size, how an image of another shape fits on it,
and the circle of confusion the depth of field is judged by."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtWidgets import QComboBox, QGridLayout, QHBoxLayout, QLabel

from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.widgets import NumberEdit, hint
from lenslab.optics.dof import COC_DIAGONAL_DIVISOR
from lenslab.optics.sensors import crop_factor
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.fields import control_range, declared_choices

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel

SENSOR_FIT_NAMES = {"auto": "Auto (long sides together)", "horizontal": "Horizontal", "vertical": "Vertical",
                    "fill": "Fill (crop the sensor)", "overscan": "Overscan (whole sensor)"}


class AutoNumberEdit(NumberEdit):
    """A number field whose lowest value means "auto", shown with the value auto stands for; the first step up
    from auto starts from that value rather than from zero."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.auto_value = 0.0
        self.setSpecialValueText("auto")

    def set_auto_value(self, value: float) -> None:
        self.auto_value = float(value)
        self.setSpecialValueText(f"auto · {value:.{self.decimals()}f}{self.suffix()}")

    def stepBy(self, steps: int) -> None:
        if steps > 0 and self.value() <= self.minimum() and self.auto_value > self.minimum():
            self.setValue(round(self.auto_value, self.decimals()))
            steps -= 1
        if steps:
            super().stepBy(steps)


class SensorSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "sensor", "Sensor")
        self.sensors = panel.sensors
        self.sensor_combo = QComboBox()
        for sensor in self.sensors:
            self.sensor_combo.addItem(f"{sensor.name}  ({sensor.width_mm:g} × {sensor.height_mm:g})", sensor)
        self.sensor_combo.addItem("Custom", None)
        self.sensor_combo.currentIndexChanged.connect(self._sensor_chosen)
        self.add(self.sensor_combo)
        row = QHBoxLayout()
        self.sensor_w = NumberEdit(*control_range(ThinLensCamera, "sensor_mm"), decimals=2, step=0.1, suffix=" mm")
        self.sensor_h = NumberEdit(*control_range(ThinLensCamera, "sensor_mm"), decimals=2, step=0.1, suffix=" mm")
        self.sensor_w.edited.connect(lambda v, merge: self._sensor_edited(merge))
        self.sensor_h.edited.connect(lambda v, merge: self._sensor_edited(merge))
        row.addWidget(QLabel("W"))
        row.addWidget(self.sensor_w)
        row.addWidget(QLabel("H"))
        row.addWidget(self.sensor_h)
        self.add(row)
        grid = QGridLayout()
        self.sensor_fit = QComboBox()
        for fit in declared_choices(ThinLensCamera, "sensor_fit"):
            self.sensor_fit.addItem(SENSOR_FIT_NAMES.get(fit, fit), fit)
        self.sensor_fit.setToolTip("Which part of the sensor an image of another shape shows (Blender's and "
                                   "Unity's fits)")
        self.sensor_fit.currentIndexChanged.connect(
            lambda i: self._updating or self.doc.set_camera("Sensor fit", False,
                                                            sensor_fit=self.sensor_fit.itemData(i)))
        low, high = control_range(ThinLensCamera, "circle_of_confusion_mm")
        self.coc = AutoNumberEdit(0.0, high, decimals=4, step=0.001, suffix=" mm")
        self.coc.setObjectName("circleOfConfusion")
        self.coc.setToolTip("Circle of confusion, the blur the depth-of-field readout calls sharp: auto is the "
                            "diagonal of the sensor area the image shows / 1500; type a value for a stricter or "
                            "looser standard, or 0 for auto")
        self.coc.edited.connect(lambda v, merge: self.doc.set_camera(
            f"Circle of confusion {f'{v:g} mm' if v >= low else 'auto'}", merge,
            circle_of_confusion_mm=float(v) if v >= low else None))
        grid.addWidget(QLabel("Fit"), 0, 0)
        grid.addWidget(self.sensor_fit, 0, 1)
        coc_label = QLabel("CoC")
        coc_label.setToolTip(self.coc.toolTip())
        grid.addWidget(coc_label, 1, 0)
        grid.addWidget(self.coc, 1, 1)
        grid.setColumnStretch(1, 1)
        self.add(grid)
        self.sensor_info = hint("")
        self.add(self.sensor_info)

    # -- edits ----------------------------------------------------------------------------------------------------
    def _sensor_chosen(self, index: int) -> None:
        if self._updating:
            return
        sensor = self.sensor_combo.itemData(index)
        if sensor is None:
            self.panel.refresh()
            return
        self.doc.set_camera(f"Sensor {sensor.name}", False, sensor_mm=(sensor.width_mm, sensor.height_mm),
                            circle_of_confusion_mm=sensor.circle_of_confusion_mm)

    def _sensor_edited(self, merge: bool) -> None:
        if self._updating:
            return
        w, h = self.sensor_w.value(), self.sensor_h.value()
        self.doc.set_camera(f"Sensor size {w:g} × {h:g} mm", merge, sensor_mm=(w, h))

    # -- following the document ---------------------------------------------------------------------------------
    def refresh(self, cam: ThinLensCamera) -> None:
        with self._showing_camera():
            sw, sh = cam.sensor_mm
            index = next((i for i, s in enumerate(self.sensors)
                          if math.isclose(s.width_mm, sw, rel_tol=1e-4) and math.isclose(s.height_mm, sh, rel_tol=1e-4)),
                         len(self.sensors))
            self.sensor_combo.setCurrentIndex(index)
            self.sensor_w.set_quietly(sw)
            self.sensor_h.set_quietly(sh)
            crop = crop_factor(sw, sh)
            width, height = cam.resolution
            coc = cam.coc_mm(width, height)
            film_w, film_h = cam.imaged_area_mm(width, height)
            self.sensor_fit.setCurrentIndex(self.sensor_fit.findData(cam.sensor_fit))
            self.coc.set_auto_value(math.hypot(film_w, film_h) / COC_DIAGONAL_DIVISOR)
            self.coc.set_quietly(cam.circle_of_confusion_mm or 0.0)
            self.sensor_info.setText(f"Crop factor {crop:.2f} · the image shows {film_w:.1f} × {film_h:.1f} mm · "
                                     f"circle of confusion {coc * 1000:.0f} µm · "
                                     f"{cam.focal_length_mm * crop:.0f} mm full-frame equivalent")
