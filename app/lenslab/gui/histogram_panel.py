"""The histogram dock: the red, green, blue and luminance histograms of the picture inside the export frame, as
displayed: the 8-bit code values the view transform gives the chosen display (OpenColorIO's display, view and look,
after the display exposure and contrast; the RGBA8 picture the GPU makes, :mod:`lenslab.optics.histogram`), with a
clipping indicator at each end that lights up when pixels are crushed to black (left, blue: every channel at 0)
or clipped (right, red: a channel at 255) and says how many. Clicking an indicator turns the clipping warnings
on the picture on or off. Worked out again at most four times a second, and only while the dock is shown."""

from __future__ import annotations

from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QAction, QColor, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import QHBoxLayout, QLabel, QToolButton, QVBoxLayout, QWidget

from lenslab.gui import theme
from lenslab.gui.layer_support import Throttle, crop_to_gate, qimage_to_array
from lenslab.optics.histogram import LEVELS, Histogram, histogram

HISTOGRAM_INTERVAL_MS = 250
CHANNEL_COLOURS = (QColor(225, 60, 60, 150), QColor(70, 200, 80, 150), QColor(70, 120, 235, 150))
LUMA_COLOUR = QColor(230, 230, 230, 210)
SHADOW_LIT = QColor(70, 140, 255)
HIGHLIGHT_LIT = QColor(255, 70, 60)
INDICATOR_OFF = QColor(90, 92, 97)
INDICATOR = 11  # the clipping triangles' side, pixels
#: The histogram's height: enough to read its shape, and no more however tall the window (the camera panel under it
#: has better use for the room).
MIN_PLOT_HEIGHT, MAX_PLOT_HEIGHT = 90, 140


def percent(fraction: float) -> str:
    """A share of the pixels as the indicators write it: "0 %", "< 0.01 %", "0.35 %", "12 %"."""
    if fraction <= 0:
        return "0 %"
    value = 100 * fraction
    if value < 0.01:
        return "< 0.01 %"
    return f"{value:.2f} %" if value < 10 else f"{value:.0f} %"


class HistogramView(QWidget):
    """Draws a :class:`Histogram`; the clipping triangles in its top corners are buttons."""

    shadows_clicked = Signal()
    highlights_clicked = Signal()

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("histogramView")
        self.histogram: Histogram | None = None
        self.setMinimumHeight(MIN_PLOT_HEIGHT)
        self.setMaximumHeight(MAX_PLOT_HEIGHT)
        self.setCursor(Qt.ArrowCursor)

    def sizeHint(self) -> QSize:
        return QSize(300, 120)

    def set_histogram(self, h: Histogram | None) -> None:
        self.histogram = h
        self.update()

    def plot_rect(self) -> QRectF:
        return QRectF(self.rect()).adjusted(4, INDICATOR + 6, -4, -4)

    def shadow_indicator(self) -> QRectF:
        return QRectF(4, 3, INDICATOR, INDICATOR)

    def highlight_indicator(self) -> QRectF:
        return QRectF(self.width() - 4 - INDICATOR, 3, INDICATOR, INDICATOR)

    def mousePressEvent(self, event) -> None:
        pos = event.position()
        if self.shadow_indicator().adjusted(-4, -4, 4, 4).contains(pos):
            self.shadows_clicked.emit()
        elif self.highlight_indicator().adjusted(-4, -4, 4, 4).contains(pos):
            self.highlights_clicked.emit()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(theme.BASE))
        plot = self.plot_rect()
        p.fillRect(plot, QColor(22, 23, 25))
        p.setPen(QPen(QColor(255, 255, 255, 18), 1))
        for i in range(1, 4):
            x = plot.left() + plot.width() * i / 4
            p.drawLine(QPointF(x, plot.top()), QPointF(x, plot.bottom()))
        h = self.histogram
        if h is not None and h.pixels:
            counts = h.counts
            # Scaled to the tallest level between the ends: a spike of clipped pixels would flatten the rest (it is
            # drawn cut off at the top, and the indicators say how big it is).
            peak = float(counts[:, 1:LEVELS - 1].max()) or float(counts.max()) or 1.0
            p.setRenderHint(QPainter.Antialiasing, True)
            p.setPen(Qt.NoPen)
            p.setCompositionMode(QPainter.CompositionMode_Plus)
            for c, colour in enumerate(CHANNEL_COLOURS):
                p.setBrush(colour)
                p.drawPath(self._area(plot, counts[c], peak))
            p.setCompositionMode(QPainter.CompositionMode_SourceOver)
            p.setBrush(Qt.NoBrush)
            p.setPen(QPen(LUMA_COLOUR, 1.2))
            p.drawPolyline(self._curve(plot, counts[3], peak))
        self._indicator(p, self.shadow_indicator(), h is not None and h.crushed_all > 0, SHADOW_LIT, left=True)
        self._indicator(p, self.highlight_indicator(), h is not None and h.clipped_any > 0, HIGHLIGHT_LIT,
                        left=False)
        p.end()

    def _points(self, plot: QRectF, counts, peak: float) -> list[QPointF]:
        step = plot.width() / (LEVELS - 1)
        return [QPointF(plot.left() + i * step, plot.bottom() - plot.height() * min(1.0, float(n) / peak))
                for i, n in enumerate(counts)]

    def _curve(self, plot: QRectF, counts, peak: float) -> QPolygonF:
        return QPolygonF(self._points(plot, counts, peak))

    def _area(self, plot: QRectF, counts, peak: float) -> QPainterPath:
        path = QPainterPath(QPointF(plot.left(), plot.bottom()))
        for point in self._points(plot, counts, peak):
            path.lineTo(point)
        path.lineTo(QPointF(plot.right(), plot.bottom()))
        path.closeSubpath()
        return path

    @staticmethod
    def _indicator(p: QPainter, box: QRectF, lit: bool, colour: QColor, left: bool) -> None:
        corner = box.topLeft() if left else box.topRight()
        other = box.topRight() if left else box.topLeft()
        triangle = QPolygonF([corner, other, box.bottomLeft() if left else box.bottomRight()])
        p.setRenderHint(QPainter.Antialiasing, True)
        p.setPen(QPen(colour if lit else INDICATOR_OFF, 1))
        p.setBrush(colour if lit else Qt.NoBrush)
        p.drawPolygon(triangle)


class HistogramPanel(QWidget):
    """The dock's contents: the histogram, the clipping figures and the clipping warnings' toggle
    (``warnings_action``). ``viewport`` is read when the picture changes (:meth:`changed`)."""

    def __init__(self, viewport, warnings_action: QAction, parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("histogramPanel")
        self.viewport = viewport
        self.histogram: Histogram | None = None
        self._stale = True
        self.view = HistogramView()
        self.view.setToolTip("The picture inside the frame as displayed: the display's 8-bit code values through the "
                             "chosen view (View > View Transform), after the display exposure and contrast. Click a "
                             "triangle to show the clipped pixels on the picture.")
        self.view.shadows_clicked.connect(warnings_action.toggle)
        self.view.highlights_clicked.connect(warnings_action.toggle)
        self.shadows_label = QLabel()
        self.shadows_label.setObjectName("shadowClipping")
        self.highlights_label = QLabel()
        self.highlights_label.setObjectName("highlightClipping")
        self.shadows_label.setToolTip("Black pixels (every channel at 0): shadow detail crushed")
        self.highlights_label.setToolTip("Pixels with a channel at 255: highlight detail clipped to white")
        self.warnings_button = QToolButton()
        self.warnings_button.setDefaultAction(warnings_action)
        self.warnings_button.setToolButtonStyle(Qt.ToolButtonTextOnly)
        row = QHBoxLayout()
        row.setContentsMargins(6, 0, 6, 2)
        row.addWidget(self.shadows_label)
        row.addStretch(1)
        row.addWidget(self.warnings_button)
        row.addStretch(1)
        row.addWidget(self.highlights_label)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.setSpacing(2)
        layout.addWidget(self.view, 1)
        layout.addLayout(row)
        self._throttle = Throttle(self.refresh, HISTOGRAM_INTERVAL_MS, self)
        self._show_figures()
        # The dock holding the panel grows no taller than the plot's limit and the row under it.
        margins = layout.contentsMargins()
        self.setMaximumHeight(margins.top() + MAX_PLOT_HEIGHT + layout.spacing() + row.sizeHint().height()
                              + margins.bottom())

    def changed(self) -> None:
        """The viewport's picture or frame changed: count again soon (or when the dock is next shown)."""
        self._stale = True
        if self.isVisible():
            self._throttle.poke()

    def showEvent(self, event) -> None:
        super().showEvent(event)
        if self._stale:
            self._throttle.poke()

    def refresh(self) -> None:
        image = self.viewport.qimage
        if image is not None and not self.viewport.worth_judging and self.histogram is not None:
            return  # the last clean picture's histogram stands until the new picture is worth one
        self._stale = False
        self.histogram = None if image is None else histogram(crop_to_gate(qimage_to_array(image), self.viewport))
        self.view.set_histogram(self.histogram)
        self._show_figures()

    def _show_figures(self) -> None:
        h = self.histogram
        crushed = h.crushed_all if h is not None else 0.0
        clipped = h.clipped_any if h is not None else 0.0
        self.shadows_label.setText(f"◀ {percent(crushed)}")
        self.highlights_label.setText(f"{percent(clipped)} ▶")
        self.shadows_label.setStyleSheet(f"color: {SHADOW_LIT.name() if crushed > 0 else theme.DIM_TEXT};")
        self.highlights_label.setStyleSheet(f"color: {HIGHLIGHT_LIT.name() if clipped > 0 else theme.DIM_TEXT};")
