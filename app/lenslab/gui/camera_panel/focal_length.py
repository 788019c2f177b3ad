"""The camera panel's focal length section: a slider on a log scale, a field and the common focal lengths, within
the mounted zoom's range (a prime's are asleep), and the field of view they give."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QHBoxLayout, QPushButton, QSlider

from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.widgets import NumberEdit, hint, log_to_slider, slider_to_log
from lenslab.optics import LensPreset, format_distance, format_focal_length
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.editing import camera_changes_keeping_focus
from lenslab.scene.fields import declared_range

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel

COMMON_FOCAL_LENGTHS = (14, 24, 35, 50, 85, 135, 200)
FOCAL_RANGE = (8.0, 800.0)


def focal_limits_for(lens: LensPreset | None) -> tuple[float, float]:
    """The focal lengths the slider spans: the zoom's range, or any without a zoom."""
    if lens is not None and lens.is_zoom:
        return lens.focal_range_mm
    return FOCAL_RANGE


class FocalLengthSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "focal", "Focal length")
        row = QHBoxLayout()
        self.focal = NumberEdit(*declared_range(ThinLensCamera, "focal_length_mm"), decimals=1, step=1.0, suffix=" mm")
        self.focal.setObjectName("focalLength")
        self.focal.edited.connect(lambda v, merge: self.set_focal_length(v, merge))
        self.focal_slider = QSlider(Qt.Horizontal)
        self.focal_slider.setRange(0, 1000)
        self.focal_slider.setFocusPolicy(Qt.StrongFocus)
        self.focal_slider.valueChanged.connect(self._focal_slid)
        row.addWidget(self.focal_slider, 1)
        row.addWidget(self.focal)
        self.focal.setFixedWidth(86)
        self.add(row)
        stops = QHBoxLayout()
        stops.setSpacing(2)
        self.focal_buttons = []
        for mm in COMMON_FOCAL_LENGTHS:
            b = QPushButton(str(mm))
            b.setObjectName("lensButton")
            b.setToolTip(f"{mm} mm")
            b.clicked.connect(lambda _c=False, mm=mm: self.set_focal_length(float(mm), False))
            stops.addWidget(b)
            self.focal_buttons.append(b)
        self.add(stops)
        self.fov_info = hint("")
        self.add(self.fov_info)

    # -- edits ----------------------------------------------------------------------------------------------------
    def set_focal_length(self, mm: float, merge: bool) -> None:
        lens = self.doc.lens
        if lens is not None:
            if not lens.is_zoom and not math.isclose(mm, lens.focal_length_mm):
                self.panel.status_message.emit(f"The {lens.name} is a prime: choose Free or a zoom to change focal "
                                               "length")
                self.panel.refresh()
                return
            mm = lens.clamp_focal_length(mm)
        changes = camera_changes_keeping_focus(self.doc.scene.camera, lens, focal_length_mm=float(mm))
        if "focus_distance_m" in changes:
            self.panel.status_message.emit(f"Focus moved out to {format_distance(changes['focus_distance_m'])}: a "
                                           f"{format_focal_length(mm)} lens focuses no nearer")
        self.doc.set_camera(f"Focal length {mm:g} mm", merge, **changes)
        self.panel.refresh()

    def _focal_slid(self, position: int) -> None:
        if self._updating:
            return
        lo, hi = focal_limits_for(self.doc.lens)
        mm = round(slider_to_log(position, lo, hi), 1)
        self.set_focal_length(mm, True)

    # -- following the document ---------------------------------------------------------------------------------
    def refresh(self, cam: ThinLensCamera, lens: LensPreset | None) -> None:
        with self._showing_camera():
            lo, hi = focal_limits_for(lens)
            prime = lens is not None and not lens.is_zoom
            self.focal.set_quietly(cam.focal_length_mm)
            if not self.focal_slider.isSliderDown():
                self.focal_slider.setValue(log_to_slider(cam.focal_length_mm, lo, hi))
            for widget in [self.focal, self.focal_slider] + self.focal_buttons:
                widget.setEnabled(not prime)
            for b, mm in zip(self.focal_buttons, COMMON_FOCAL_LENGTHS):
                b.setEnabled(not prime and (lens is None or lens.min_focal_length_mm <= mm <= lens.max_focal_length_mm))
            fov_y = math.degrees(cam.frame().fov_y)
            self.fov_info.setText(f"Field of view {math.degrees(cam.fov_x):.1f}° × {fov_y:.1f}°"
                                  + (" · fixed by the prime" if prime else ""))
