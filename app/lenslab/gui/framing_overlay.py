"""The sensor's gate over the viewport's picture: the export frame outlined and labelled with its shape and
resolution, the picture outside it dimmed (the passepartout), the composition guides and the safe frame inside
it, and the sensor's own outline where the image shows more or less than the sensor (the sensor fit).

The geometry is :mod:`lenslab.optics.composition`'s; this layer only draws it. The frame is the viewport's
``gate_rect`` (the whole picture while the viewport does not set one).
"""

from __future__ import annotations

from PySide6.QtCore import QLineF, QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen

from lenslab.gui.corner_tags import FRAME, SENSOR
from lenslab.gui.layer_support import gate_in_widget, tag_size
from lenslab.optics.aspect import aspect_name
from lenslab.optics.composition import ACTION_SAFE, GUIDES, TITLE_SAFE, guide_lines, safe_rect, sensor_rect

#: Passepartout opacities offered, in menu order: (name, opacity of the black outside the frame).
PASSEPARTOUTS = (("Off", 0.0), ("Light", 0.35), ("Medium", 0.65), ("Dark", 0.9), ("Black", 1.0))
DEFAULT_PASSEPARTOUT = 0.65

GATE_COLOUR = QColor(235, 235, 235, 170)
GUIDE_COLOUR = QColor(255, 255, 255, 140)
GUIDE_SHADOW = QColor(0, 0, 0, 70)
SAFE_COLOUR = QColor(255, 255, 255, 110)
SENSOR_COLOUR = QColor(232, 162, 58, 150)  # theme.ACCENT, faint


def _rect_tuple(r: QRectF) -> tuple[float, float, float, float]:
    return (r.left(), r.top(), r.width(), r.height())


class FramingLayer:
    """Draws the gate, the passepartout, the guides and the safe frame. Its settings are plain attributes; the
    window's menus set them and repaint the viewport."""

    def __init__(self):
        self.visible = True
        self.guides = "none"  # one of composition.GUIDES
        self.safe_frame = False
        self.passepartout = DEFAULT_PASSEPARTOUT
        self.resolution: tuple[int, int] | None = None  # the export's, for the label
        self.sensor_mm: tuple[float, float] | None = None
        self.imaged_mm: tuple[float, float] | None = None  # the part of the sensor the export shows

    def set_camera(self, camera) -> None:
        self.resolution = tuple(camera.resolution)
        self.sensor_mm = tuple(camera.sensor_mm)
        self.imaged_mm = camera.imaged_area_mm()

    def set_guides(self, kind: str) -> None:
        if kind not in GUIDES:
            raise ValueError(f"unknown guide {kind!r} (choose from {', '.join(GUIDES)})")
        self.guides = kind

    def label(self) -> str:
        if self.resolution is None:
            return ""
        w, h = self.resolution
        return f"{aspect_name(w, h)}  {w} × {h}"

    # -- geometry, in the widget's coordinates ------------------------------------------------------------------
    def guide_lines(self, gate: QRectF) -> list[QLineF]:
        return [QLineF(*line) for line in guide_lines(self.guides, _rect_tuple(gate))]

    def safe_rects(self, gate: QRectF) -> list[QRectF]:
        if not self.safe_frame:
            return []
        return [QRectF(*safe_rect(_rect_tuple(gate), f)) for f in (ACTION_SAFE, TITLE_SAFE)]

    def sensor_outline(self, gate: QRectF) -> QRectF | None:
        """The whole sensor's outline where it differs from the frame by more than a pixel, else None."""
        if self.sensor_mm is None or self.imaged_mm is None:
            return None
        outline = QRectF(*sensor_rect(_rect_tuple(gate), self.sensor_mm, self.imaged_mm))
        if abs(outline.width() - gate.width()) < 1.5 and abs(outline.height() - gate.height()) < 1.5:
            return None
        return outline

    # -- painting ----------------------------------------------------------------------------------------------
    def paint(self, p: QPainter, viewport, image_rect: QRectF) -> None:
        gate = gate_in_widget(viewport, image_rect)
        if gate.isEmpty():
            return
        p.save()
        if self.passepartout > 0:
            outside = QPainterPath()
            outside.setFillRule(Qt.OddEvenFill)
            outside.addRect(image_rect)
            outside.addRect(gate)
            p.fillPath(outside, QColor(0, 0, 0, round(255 * self.passepartout)))
        p.setRenderHint(QPainter.Antialiasing, False)
        p.setBrush(Qt.NoBrush)
        p.setClipRect(image_rect.adjusted(-1, -1, 1, 1))
        sensor = self.sensor_outline(gate)
        if sensor is not None:
            p.setPen(QPen(SENSOR_COLOUR, 1, Qt.DashLine))
            p.drawRect(sensor)
        lines = self.guide_lines(gate)
        if lines:
            p.setPen(QPen(GUIDE_SHADOW, 3))
            p.drawLines(lines)
            p.setPen(QPen(GUIDE_COLOUR, 1))
            p.drawLines(lines)
        for i, rect in enumerate(self.safe_rects(gate)):
            p.setPen(QPen(SAFE_COLOUR, 1, Qt.SolidLine if i == 0 else Qt.DashLine))
            p.drawRect(rect)
        p.setPen(QPen(GATE_COLOUR, 1))
        p.drawRect(gate.adjusted(-0.5, -0.5, -0.5, -0.5))
        p.setClipping(False)
        self._paint_label(p, viewport, gate, sensor)
        p.restore()

    def _paint_label(self, p: QPainter, viewport, gate: QRectF, sensor: QRectF | None) -> None:
        """The frame's label under its bottom-right corner (inside it where there is no room below) and the sensor's
        size inside its top-left corner: tags the viewport lays out with its others (``viewport.tags``)."""
        text = self.label()
        if not text:
            return
        h = tag_size(p, text)[1]
        below = gate.bottom() + 3 + h <= viewport.height() - 2  # room under the frame: the label goes there
        y = gate.bottom() + 3 + h if below else gate.bottom() - 6
        viewport.tags.want(text, QPointF(gate.right() - (0 if below else 6), y),
                           QColor(220, 220, 220) if below else QColor(200, 200, 200), FRAME, grows="left",
                           background=QColor(20, 20, 22, 0 if below else 170),
                           bounds=QRectF(gate.left(), 0, gate.width(), viewport.height()))
        if sensor is not None and self.sensor_mm is not None:
            note = f"sensor {self.sensor_mm[0]:g} × {self.sensor_mm[1]:g} mm"
            inside = sensor.intersected(gate)
            viewport.tags.want(note, QPointF(inside.left() + 4, inside.top() + tag_size(p, note)[1] + 4),
                               SENSOR_COLOUR.lighter(130), SENSOR, background=QColor(20, 20, 22, 150), bounds=inside)
