"""What the viewport's layers (the gate and guides, focus peaking, clipping warnings, the loupe) and the histogram
share: where the export frame lies, the viewport's picture as numpy, a mask as a picture to draw, a small tag,
a throttle, and a watch that says when the picture under them changed.

Layers are drawn by ``Viewport.paintEvent`` as ``layer.paint(painter, viewport, image_rect)`` for each layer in
``viewport.layers`` whose ``visible`` is true (``lenslab/gui/viewport.py``).
"""

from __future__ import annotations

import time
from typing import Callable

import numpy as np
from PySide6.QtCore import QObject, QPointF, QRect, QRectF, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QImage, QPainter


def gate_in_image(viewport) -> QRectF:
    """The export frame in image pixels of the viewport's picture: ``viewport.gate_rect``, or the whole picture
    when the viewport does not say."""
    gate = getattr(viewport, "gate_rect", None)
    if gate is not None:
        return QRectF(gate)
    w, h = viewport.image_size()
    return QRectF(0, 0, w, h)


def image_rect_to_widget(image_rect: QRectF, image_size: tuple[int, int], rect: QRectF) -> QRectF:
    """``rect`` in image pixels, in the widget's coordinates, the picture being drawn into ``image_rect``."""
    w, h = image_size
    if w <= 0 or h <= 0:
        return QRectF()
    sx, sy = image_rect.width() / w, image_rect.height() / h
    return QRectF(image_rect.left() + rect.left() * sx, image_rect.top() + rect.top() * sy,
                  rect.width() * sx, rect.height() * sy)


def gate_in_widget(viewport, image_rect: QRectF) -> QRectF:
    return image_rect_to_widget(image_rect, viewport.image_size(), gate_in_image(viewport))


def qimage_to_array(image: QImage) -> np.ndarray:
    """An (H, W, 4) uint8 RGBA copy of a picture."""
    if image.format() != QImage.Format_RGBA8888:
        image = image.convertToFormat(QImage.Format_RGBA8888)
    w, h, stride = image.width(), image.height(), image.bytesPerLine()
    rows = np.frombuffer(image.constBits(), np.uint8, count=stride * h).reshape(h, stride)
    return rows[:, : 4 * w].reshape(h, w, 4).copy()


def gate_bounds(viewport, shape: tuple[int, ...]) -> tuple[int, int, int, int]:
    """The export frame as whole pixels (x0, y0, x1, y1) of an array of ``shape`` (H, W, ...): the viewport's
    picture."""
    gate = gate_in_image(viewport)
    h, w = shape[:2]
    x0, y0 = min(w, max(0, int(round(gate.left())))), min(h, max(0, int(round(gate.top()))))
    x1, y1 = min(w, max(x0, int(round(gate.right())))), min(h, max(y0, int(round(gate.bottom()))))
    return x0, y0, x1, y1


def crop_to_gate(picture: np.ndarray, viewport) -> np.ndarray:
    """The pixels of ``picture`` (the viewport's, H x W x ...) inside the export frame."""
    x0, y0, x1, y1 = gate_bounds(viewport, picture.shape)
    return picture[y0:y1, x0:x1]


def only_in_gate(mask: np.ndarray, viewport) -> np.ndarray:
    """``mask`` (H x W, the viewport's picture) with everything outside the export frame cleared, in place."""
    x0, y0, x1, y1 = gate_bounds(viewport, mask.shape)
    mask[:y0] = False
    mask[y1:] = False
    mask[:, :x0] = False
    mask[:, x1:] = False
    return mask


def masks_to_qimage(shape: tuple[int, int], masks: list[tuple[np.ndarray, QColor]]) -> QImage:
    """A transparent picture of ``shape`` (H, W) with each mask painted in its colour (later masks on top)."""
    rgba = np.zeros(tuple(shape) + (4,), np.uint8)
    for mask, colour in masks:
        rgba[mask] = (colour.red(), colour.green(), colour.blue(), colour.alpha())
    h, w = shape
    return QImage(rgba.data, w, h, 4 * w, QImage.Format_RGBA8888).copy()


def tag_size(p: QPainter, text: str) -> tuple[float, float]:
    """The size of :func:`draw_tag`'s box for ``text`` (which may have several lines)."""
    bounds = p.fontMetrics().boundingRect(QRect(0, 0, 4000, 4000), Qt.AlignLeft, text)
    return bounds.width() + 12, bounds.height() + 4


def draw_tag(p: QPainter, box_bottom_left: QPointF, text: str, colour: QColor | str,
             background: QColor = QColor(20, 20, 22, 200)) -> QRectF:
    """A small label on a dark rounded box, as the viewport's corner tags; returns the box."""
    w, h = tag_size(p, text)
    box = QRectF(box_bottom_left.x(), box_bottom_left.y() - h, w, h)
    p.save()
    p.setPen(Qt.NoPen)
    p.setBrush(background)
    p.drawRoundedRect(box, 3, 3)
    p.setPen(QColor(colour))
    p.drawText(box.adjusted(6, 2, -6, -2), Qt.AlignLeft | Qt.AlignVCenter, text)
    p.restore()
    return box


class Throttle(QObject):
    """Runs ``callback`` soon after a :meth:`poke`, but not more often than once every ``interval_ms``: a burst
    of pokes costs one run, at once if the last run is long past, else when the interval is up."""

    def __init__(self, callback: Callable[[], None], interval_ms: int, parent: QObject | None = None):
        super().__init__(parent)
        self.callback = callback
        self.interval = interval_ms / 1000.0
        self._last = -float("inf")
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self._run)

    def poke(self) -> None:
        if not self._timer.isActive():
            wait = max(0.0, self._last + self.interval - time.monotonic())
            self._timer.start(round(wait * 1000))

    def pending(self) -> bool:
        return self._timer.isActive()

    def _run(self) -> None:
        self._last = time.monotonic()
        self.callback()


class MaskLayer(QObject):
    """A layer that draws a picture worked out from the viewport's (a mask painted in colours), worked out again
    at most every ``interval_ms`` after :meth:`changed`, and at once by :meth:`refresh`. Subclasses fill
    ``_overlay`` (a QImage of the picture's size, or None) in :meth:`refresh` and say in :meth:`forget` what
    they drop when hidden. The marks judge the picture (its sharp edges, its clipped pixels): none is drawn over
    a picture not worth judging (``viewport.worth_judging``: a preview, a few raw samples), whose own would follow
    the noise and whose last ones, until the layer works them out again, are another picture's."""

    def __init__(self, viewport, interval_ms: int, parent: QObject | None = None):
        super().__init__(parent)
        self.viewport = viewport
        self.visible = False
        self._overlay: QImage | None = None
        self._throttle = Throttle(self.refresh, interval_ms, self)

    def set_visible(self, visible: bool) -> None:
        self.visible = bool(visible)
        if self.visible:
            self.refresh()
        else:
            self._overlay = None
            self.forget()
            self.viewport.update()

    def changed(self) -> None:
        """What the layer is worked out from changed: work it out again soon."""
        if self.visible:
            self._throttle.poke()

    def refresh(self) -> None:
        raise NotImplementedError

    def forget(self) -> None:
        """Drop what was worked out (the layer is hidden)."""

    def paint(self, p: QPainter, viewport, image_rect: QRectF) -> None:
        if self._overlay is not None and viewport.worth_judging:
            p.drawImage(image_rect, self._overlay)


class PictureWatch(QObject):
    """An invisible layer that says when the viewport paints another picture, depth buffer or frame (a new render
    frame, another display exposure or tone map, a snapshot shown instead): whatever changed the viewport's
    ``qimage`` repaints it, so the paint is where to notice. Put it first in ``viewport.layers``."""

    changed = Signal()
    visible = True

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent)
        self._seen = None

    def paint(self, p: QPainter, viewport, image_rect: QRectF) -> None:
        image, gate = viewport.qimage, getattr(viewport, "gate_rect", None)
        state = (image.cacheKey() if image is not None else None, id(viewport.gbuffer),
                 None if gate is None else gate.getRect())
        if state != self._seen:
            self._seen = state
            self.changed.emit()
