"""The camera panel's depth-of-field section: the near and far limits of acceptable sharpness, the total and the
hyperfocal distance, with a diagram of them."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QFont, QPainter, QPainterPath, QPen
from PySide6.QtWidgets import QGridLayout, QLabel, QSizePolicy, QWidget

from lenslab.gui import theme
from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.widgets import hint, readout
from lenslab.optics import format_distance
from lenslab.scene.camera import ThinLensCamera

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel


class DofDiagram(QWidget):
    """Distance on a log scale from the camera: the zone of acceptable sharpness, the plane of focus and the
    hyperfocal distance."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumHeight(64)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
        self.focus = 1.0
        self.near = 0.9
        self.far = 1.1
        self.hyperfocal = 10.0

    def set_state(self, focus: float, near: float, far: float, hyperfocal: float) -> None:
        self.focus, self.near, self.far, self.hyperfocal = focus, near, far, hyperfocal
        self.update()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        w, h = self.width(), self.height()
        left, right = 22.0, w - 16.0
        axis_y = h * 0.48
        lo, hi = self.focus / 10.0, self.focus * 10.0

        def x_of(d: float) -> float:
            if math.isinf(d) or d >= hi:
                return right
            d = max(d, lo)
            return left + (math.log(d) - math.log(lo)) / (math.log(hi) - math.log(lo)) * (right - left)

        # Axis and the camera at its left end.
        p.setPen(QPen(QColor("#55575c"), 1))
        p.drawLine(QPointF(left, axis_y), QPointF(right, axis_y))
        cam = QPainterPath()
        cam.addRoundedRect(QRectF(4, axis_y - 6, 11, 12), 2, 2)
        p.fillPath(cam, QColor("#8c8f94"))
        # Decade ticks.
        font = QFont(self.font())
        font.setPointSizeF(max(7.0, font.pointSizeF() - 2))
        p.setFont(font)
        decade = 10 ** math.floor(math.log10(lo))
        while decade <= hi:
            for m in (1, 2, 5):
                d = decade * m
                if lo <= d <= hi:
                    x = x_of(d)
                    p.setPen(QPen(QColor("#45474b"), 1))
                    p.drawLine(QPointF(x, axis_y - 3), QPointF(x, axis_y + 3))
                    if m == 1:
                        p.setPen(QColor("#6c6f74"))
                        p.drawText(QRectF(x - 20, h - 14, 40, 12), Qt.AlignCenter, format_distance(d))
            decade *= 10
        # Zone of acceptable sharpness.
        x0, x1 = x_of(self.near), x_of(self.far)
        zone = QColor(theme.FOCUS)
        zone.setAlpha(70)
        p.fillRect(QRectF(x0, axis_y - 12, max(1.5, x1 - x0), 24), zone)
        p.setPen(QPen(QColor(theme.FOCUS), 1.2))
        p.drawLine(QPointF(x0, axis_y - 12), QPointF(x0, axis_y + 12))
        if not math.isinf(self.far) and self.far < hi:
            p.drawLine(QPointF(x1, axis_y - 12), QPointF(x1, axis_y + 12))
        else:
            p.drawText(QRectF(right - 2, axis_y - 8, 14, 16), Qt.AlignCenter, "∞")
        # Plane of focus.
        xf = x_of(self.focus)
        p.setPen(QPen(QColor(theme.ACCENT), 2))
        p.drawLine(QPointF(xf, axis_y - 16), QPointF(xf, axis_y + 16))
        # Hyperfocal distance.
        if lo <= self.hyperfocal <= hi:
            xh = x_of(self.hyperfocal)
            p.setPen(QPen(QColor("#8c8f94"), 1, Qt.DashLine))
            p.drawLine(QPointF(xh, 4), QPointF(xh, axis_y + 12))
            p.setPen(QColor("#8c8f94"))
            p.drawText(QRectF(xh + 2, 0, 14, 12), Qt.AlignLeft, "H")
        p.end()



class DepthOfFieldSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "dof", "Depth of field")
        grid = QGridLayout()
        grid.setHorizontalSpacing(10)
        grid.setVerticalSpacing(2)
        self.dof_near = readout()
        self.dof_far = readout()
        self.dof_total = readout()
        self.dof_hyper = readout()
        for i, (label, value) in enumerate((("Near", self.dof_near), ("Far", self.dof_far),
                                            ("Total", self.dof_total), ("Hyperfocal", self.dof_hyper))):
            grid.addWidget(QLabel(label), i // 2, (i % 2) * 2)
            grid.addWidget(value, i // 2, (i % 2) * 2 + 1)
        self.add(grid)
        self.dof_diagram = DofDiagram()
        self.add(self.dof_diagram)
        self.dof_info = hint("")
        self.add(self.dof_info)

    def refresh(self, cam: ThinLensCamera, light: float) -> None:
        """Show ``cam``'s depth of field, its stop passing ``light`` (a fraction of the round stop's light)."""
        width, height = cam.resolution
        coc = cam.coc_mm(width, height)
        # Depth of field: exactly the picture the renderer draws, with the aperture's real area.
        dof = cam.depth_of_field(width, height, light)
        self.dof_near.setText(format_distance(dof.near_m))
        self.dof_far.setText(format_distance(dof.far_m))
        self.dof_total.setText(format_distance(dof.total_m) if not math.isinf(dof.total_m) else "∞")
        self.dof_hyper.setText(format_distance(dof.hyperfocal_m))
        self.dof_diagram.set_state(cam.focus_distance_m, dof.near_m, max(dof.near_m, dof.far_m), dof.hyperfocal_m)
        self.dof_info.setText(f"Sharp from {format_distance(dof.near_m)} to {format_distance(dof.far_m)} for a "
                              f"{coc * 1000:.0f} µm circle of confusion. Focus at the hyperfocal distance to "
                              "keep everything from half of it to infinity sharp.")
