"""The camera panel's focus section: the focus distance on a log slider and a field, what it is measured from,
focus breathing, and the tools that focus on a point or on the selection."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QCheckBox, QComboBox, QHBoxLayout, QPushButton, QToolButton

from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.commands import push_values
from lenslab.gui.widgets import DragSlider, NumberEdit, hint, log_to_slider, slider_to_log
from lenslab.optics import LensPreset, format_distance
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.editable import CAMERA
from lenslab.scene.fields import control_range

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel

FOCUS_RANGE = (0.05, 200.0)


def focus_limits_for(cam: ThinLensCamera, lens: LensPreset | None) -> tuple[float, float]:
    """The focus distances the camera (and its lens) can set, in its reference."""
    return cam.closest_focus_with(lens), FOCUS_RANGE[1]


class FocusSection(CameraSection):
    def __init__(self, panel: CameraPanel, focus_action: QAction | None = None):
        super().__init__(panel, "focus", "Focus")
        row = QHBoxLayout()
        self.focus_slider = DragSlider(Qt.Horizontal)
        self.focus_slider.setRange(0, 1000)
        self.focus_slider.valueChanged.connect(self._focus_slid)
        self.focus = NumberEdit(*control_range(ThinLensCamera, "focus_distance_m"), decimals=3, step=0.01, suffix=" m")
        self.focus.setObjectName("focusDistance")
        self.focus.setFixedWidth(86)
        self.focus.edited.connect(lambda v, merge: self.set_focus(v, merge))
        row.addWidget(self.focus_slider, 1)
        row.addWidget(self.focus)
        self.add(row)
        options = QHBoxLayout()
        self.focus_from = QComboBox()
        self.focus_from.addItem("from the sensor", "sensor")
        self.focus_from.addItem("from the lens", "lens")
        self.focus_from.setToolTip("What the focus distance is measured from: the sensor plane, as a lens's focus "
                                   "scale is marked, or the lens (pbrt's and Mitsuba's meaning). The plane of "
                                   "focus stays where it is.")
        self.focus_from.currentIndexChanged.connect(self._focus_from_chosen)
        self.breathing = QCheckBox("Focus breathing")
        self.breathing.setToolTip("The sensor moves to the image distance as a real lens focuses, so the framing "
                                  "tightens at close focus. Off: the framing is held (pbrt, Mitsuba).")
        self.breathing.toggled.connect(lambda on: self._updating or self.doc.set_camera(
            "Focus breathing" if on else "Hold framing", False, focus_breathing=bool(on)))
        options.addWidget(self.focus_from)
        options.addWidget(self.breathing)
        options.addStretch(1)
        self.add(options)
        self.focus_info = hint("")
        self.add(self.focus_info)
        buttons = QHBoxLayout()
        if focus_action is not None:
            tool = QToolButton()
            tool.setDefaultAction(focus_action)
            tool.setToolButtonStyle(Qt.ToolButtonTextBesideIcon)
            buttons.addWidget(tool)
        self.focus_selection_button = QPushButton("Focus on selection")
        self.focus_selection_button.setToolTip("Set the focus distance to the selected object's centre")
        buttons.addWidget(self.focus_selection_button)
        buttons.addStretch(1)
        self.add(buttons)

    # -- edits ----------------------------------------------------------------------------------------------------
    def focus_limits(self) -> tuple[float, float]:
        """The focus distances the document's camera (and its lens) can set, in its reference."""
        return focus_limits_for(self.doc.scene.camera, self.doc.lens)

    def set_focus(self, metres: float, merge: bool = False, text: str | None = None) -> bool:
        """Focus at ``metres`` (in the camera's reference), or refuse and say why when the lens cannot. The undo
        step reads ``text``, by default "Focus" and the distance."""
        camera = dataclasses.replace(self.doc.scene.camera, focus_distance_m=float(metres))
        problem = camera.focus_problem(self.doc.lens)  # the camera's own check, as the command line makes it
        if problem is not None:
            self.panel.status_message.emit(f"Cannot focus there: {problem.worded('focus')}")
            self.panel.refresh()
            return False
        self.doc.set_camera(text or f"Focus {format_distance(metres)}", merge, focus_distance_m=float(metres))
        return True

    def _focus_slid(self, position: int) -> None:
        if self._updating:
            return
        closest, far = self.focus_limits()
        metres = max(closest, float(f"{slider_to_log(position, closest, far):.3g}"))
        push_values(self.doc, CAMERA, {("focus_distance_m",): metres}, f"Focus {format_distance(metres)}", True,
                    self.focus_slider.gesture)

    def _focus_from_chosen(self, index: int) -> None:
        if self._updating or index < 0:
            return
        cam = self.doc.scene.camera
        reference = self.focus_from.itemData(index)
        if reference == cam.focus_from:
            return
        # The plane of focus stays put: the reading changes by the lens-to-sensor distance.
        plane = cam.plane_of_focus_m
        reading = plane if reference == "lens" else plane + cam.image_distance_mm / 1000
        self.doc.set_camera("Focus measured from the " + reference, False, focus_from=reference,
                            focus_distance_m=float(reading))

    # -- following the document ---------------------------------------------------------------------------------
    def refresh(self, cam: ThinLensCamera, lens: LensPreset | None) -> None:
        with self._showing_camera():
            closest, far = focus_limits_for(cam, lens)
            self.focus.set_quietly(cam.focus_distance_m)
            if not self.focus_slider.isSliderDown():
                self.focus_slider.setValue(log_to_slider(max(closest, cam.focus_distance_m), closest, far))
            self.focus_from.setCurrentIndex(self.focus_from.findData(cam.focus_from))
            self.breathing.setChecked(cam.focus_breathing)
            reference = "sensor" if cam.focus_from == "sensor" else "lens"
            self.focus_info.setText(f"Measured from the {reference}; nearest {format_distance(closest)}. Plane of "
                                    f"focus {format_distance(cam.plane_of_focus_m)} ahead of the lens, sensor "
                                    f"{cam.image_distance_mm:.1f} mm behind it.")
