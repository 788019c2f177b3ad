"""The camera panel's focal length section: a slider on a log scale, a field and the common focal lengths, within
the mounted zoom's range (a prime's are asleep), and the field of view they give.

A longer focal length cannot focus as near (four focal lengths from the sensor, or the lens's own minimum): a
focal length that ends nearer than the focus allows moves the focus out, in the same step. The focus is the
photographer's, though: each edit works it out from the focus as it was when its step began, so a drag out to
800 mm and back to 31 mm, or the arrow keys run up and down, leave it as it was.
"""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtWidgets import QHBoxLayout, QPushButton

from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.commands import push_values, value_before_step
from lenslab.gui.widgets import DragSlider, NumberEdit, hint, log_to_slider, slider_to_log
from lenslab.optics import LensPreset, format_distance, format_focal_length
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.editable import CAMERA
from lenslab.scene.editing import camera_changes_keeping_focus
from lenslab.scene.fields import control_range, range_holding

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel

COMMON_FOCAL_LENGTHS = (14, 24, 35, 50, 85, 135, 200)
FOCAL_RANGE = (8.0, 800.0)
_FOCAL_FIELDS = (("focal_length_mm",), ("focus_distance_m",))  # what a focal length edit sets, always both


def focal_limits_for(lens: LensPreset | None) -> tuple[float, float]:
    """The focal lengths the slider spans: the zoom's range, or any without a zoom."""
    if lens is not None and lens.is_zoom:
        return lens.focal_range_mm
    return FOCAL_RANGE


class FocalLengthSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "focal", "Focal length")
        row = QHBoxLayout()
        self.focal = NumberEdit(*control_range(ThinLensCamera, "focal_length_mm"), decimals=1, step=1.0, suffix=" mm")
        self.focal.setObjectName("focalLength")
        self.focal.edited.connect(lambda v, merge: self.set_focal_length(v, merge))
        self.focal_slider = DragSlider(Qt.Horizontal)
        self.focal_slider.setRange(0, 1000)
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
    def set_focal_length(self, mm: float, merge: bool, gesture: object | None = None) -> None:
        lens = self.doc.lens
        if lens is not None:
            if not lens.is_zoom and not math.isclose(mm, lens.focal_length_mm):
                self.panel.status_message.emit(f"The {lens.name} is a prime: choose Free or a zoom to change focal "
                                               "length")
                self.panel.refresh()
                return
            mm = lens.clamp_focal_length(mm)
        # The focus the photographer set: before this step began (a drag through a long lens moved it on the way).
        chosen = value_before_step(self.doc, CAMERA, ("focus_distance_m",), _FOCAL_FIELDS, merge, gesture)
        changes = camera_changes_keeping_focus(dataclasses.replace(self.doc.scene.camera, focus_distance_m=chosen),
                                               lens, focal_length_mm=float(mm))
        focus = changes.get("focus_distance_m", chosen)
        if focus != chosen:
            self.panel.status_message.emit(f"Focus moved out to {format_distance(focus)}: a "
                                           f"{format_focal_length(mm)} lens focuses no nearer")
        elif self.doc.scene.camera.focus_distance_m != chosen:  # this drag had moved it out: the message is past
            self.panel.status_message.emit(f"Focus back at {format_distance(chosen)}, where it was set")
        push_values(self.doc, CAMERA, dict(zip(_FOCAL_FIELDS, (float(mm), focus))), f"Focal length {mm:g} mm",
                    merge, gesture)
        self.panel.refresh()

    def _focal_slid(self, position: int) -> None:
        if self._updating:
            return
        lo, hi = focal_limits_for(self.doc.lens)
        mm = round(slider_to_log(position, lo, hi), 1)
        self.set_focal_length(mm, True, self.focal_slider.gesture)

    # -- following the document ---------------------------------------------------------------------------------
    def refresh(self, cam: ThinLensCamera, lens: LensPreset | None) -> None:
        with self._showing_camera():
            lo, hi = focal_limits_for(lens)
            prime = lens is not None and not lens.is_zoom
            self._show_focal_length(cam.focal_length_mm)
            if not self.focal_slider.isSliderDown():
                self.focal_slider.setValue(log_to_slider(cam.focal_length_mm, lo, hi))
            for widget in [self.focal, self.focal_slider] + self.focal_buttons:
                widget.setEnabled(not prime)
            for b, mm in zip(self.focal_buttons, COMMON_FOCAL_LENGTHS):
                b.setEnabled(not prime and (lens is None or lens.min_focal_length_mm <= mm <= lens.max_focal_length_mm))
            fov_y = math.degrees(cam.frame().fov_y)
            self.fov_info.setText(f"Field of view {math.degrees(cam.fov_x):.1f}° × {fov_y:.1f}°"
                                  + (" · fixed by the prime" if prime else ""))

    def _show_focal_length(self, mm: float) -> None:
        """Show ``mm`` in the field as the camera holds it: a scene's focal length beyond what the field offers
        (an imported 0.16 mm fisheye) widens the field's range to hold it rather than being clamped, with the
        decimals to read it; nothing is edited by showing it."""
        low, high = range_holding(*control_range(ThinLensCamera, "focal_length_mm"), mm)
        decimals = 1 if mm >= 1.0 else min(6, 2 - math.floor(math.log10(mm)))
        with QSignalBlocker(self.focal):  # a range or decimals change may move the value: not the user's edit
            self.focal.setDecimals(decimals)
            self.focal.setRange(low, high)
        self.focal.set_quietly(mm)
