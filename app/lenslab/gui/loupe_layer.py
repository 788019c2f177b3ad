"""The loupe: a square beside the cursor showing the picture's pixels around it at 1:1, 2:1 or 4:1 (one image
pixel to one, two or four screen pixels, nearest neighbour, a pixel grid at 4:1), the pixel under the cursor
framed in its middle, and under it a caption with that pixel's position, linear RGB and depth. It follows the
viewport's ``pixel_hovered`` and hides when the cursor leaves the picture."""

from __future__ import annotations

import math

from PySide6.QtCore import QObject, QPointF, QRect, QRectF, Qt
from PySide6.QtGui import QColor, QPainter, QPen

from lenslab.gui.layer_support import draw_tag, tag_size
from lenslab.optics import format_distance

LOUPE_ZOOMS = (1, 2, 4)
LOUPE_SIDE = 168  # screen pixels, about; the exact side is a whole number of image pixels, odd, times the zoom
LOUPE_OFFSET = 28  # from the cursor to the loupe's nearest corner
GRID_FROM_ZOOM = 4


class LoupeLayer(QObject):
    def __init__(self, viewport, parent: QObject | None = None):
        super().__init__(parent)
        self.viewport = viewport
        self.visible = False
        self.zoom = 2
        self.pixel: tuple[int, int] | None = None  # image pixel under the cursor; None: the cursor is off it
        self.last_box: QRectF | None = None  # where it was last drawn, widget pixels (None: it was not)
        viewport.pixel_hovered.connect(self.set_pixel)

    def set_visible(self, visible: bool) -> None:
        self.visible = bool(visible)
        self.viewport.update()

    def set_zoom(self, zoom: int) -> None:
        if zoom not in LOUPE_ZOOMS:
            raise ValueError(f"the loupe magnifies {', '.join(f'{z}:1' for z in LOUPE_ZOOMS)}, not {zoom}:1")
        self.zoom = zoom
        self.viewport.update()

    def set_pixel(self, xy) -> None:
        self.pixel = None if xy is None else (int(xy[0]), int(xy[1]))
        if self.visible:
            self.viewport.update()

    # -- what it shows -------------------------------------------------------------------------------------------
    def span(self) -> int:
        """Image pixels across the loupe: odd, so that the cursor's pixel is the middle one."""
        n = max(3, LOUPE_SIDE // self.zoom)
        return n if n % 2 else n + 1

    def source_rect(self) -> QRect | None:
        """The image pixels the loupe shows (may reach past the picture's edges), or None when hidden."""
        if self.pixel is None:
            return None
        n = self.span()
        x, y = self.pixel
        return QRect(x - n // 2, y - n // 2, n, n)

    def caption(self) -> str:
        if self.pixel is None:
            return ""
        x, y = self.pixel
        depth = self.viewport.depth_at(x, y)
        lines = [f"x {x}  y {y}   " + (format_distance(depth) if math.isfinite(depth) else "background")]
        linear = self.viewport.linear
        if linear is not None and 0 <= y < linear.shape[0] and 0 <= x < linear.shape[1]:
            r, g, b = (float(c) for c in linear[y, x])
            lines.append(f"R {r:.4f}  G {g:.4f}  B {b:.4f}")
        return "\n".join(lines)

    def box(self, anchor: QPointF, side: float, caption_height: float) -> QRectF:
        """Where the loupe goes: above and right of the cursor, flipped to stay inside the viewport."""
        v = self.viewport
        x = anchor.x() + LOUPE_OFFSET
        if x + side > v.width() - 4:
            x = anchor.x() - LOUPE_OFFSET - side
        y = anchor.y() - LOUPE_OFFSET - side - caption_height
        if y < 4:
            y = anchor.y() + LOUPE_OFFSET
        return QRectF(max(4.0, x), max(4.0, y), side, side)

    # -- painting -------------------------------------------------------------------------------------------------
    def paint(self, p: QPainter, viewport, image_rect: QRectF) -> None:
        source = self.source_rect()
        image = viewport.qimage
        self.last_box = None
        if source is None or image is None:
            return
        n, zoom = source.width(), self.zoom
        ratio = viewport.devicePixelRatioF() or 1.0
        side = n * zoom / ratio  # 1:1 means one image pixel to one pixel of the screen
        x, y = self.pixel
        anchor = viewport.image_to_widget(x + 0.5, y + 0.5)
        text = self.caption()
        caption_w, caption_h = tag_size(p, text)
        box = self.last_box = self.box(anchor, side, caption_h + 2)
        p.save()
        p.setRenderHint(QPainter.SmoothPixmapTransform, False)
        p.setRenderHint(QPainter.Antialiasing, False)
        p.fillRect(box.adjusted(-2, -2, 2, 2), QColor(12, 12, 13))
        p.drawImage(box, image.copy(source))  # outside the picture, copy() gives transparent pixels
        cell = zoom / ratio
        if zoom >= GRID_FROM_ZOOM:
            p.setPen(QPen(QColor(0, 0, 0, 34), 0))
            for i in range(1, n):
                p.drawLine(QPointF(box.left() + i * cell, box.top()), QPointF(box.left() + i * cell, box.bottom()))
                p.drawLine(QPointF(box.left(), box.top() + i * cell), QPointF(box.right(), box.top() + i * cell))
        middle = QRectF(box.left() + (n // 2) * cell, box.top() + (n // 2) * cell, cell, cell)
        p.setPen(QPen(QColor(0, 0, 0, 200), 1))
        p.setBrush(Qt.NoBrush)
        p.drawRect(middle.adjusted(-2, -2, 1, 1))
        p.setPen(QPen(QColor(255, 255, 255, 230), 1))
        p.drawRect(middle.adjusted(-1, -1, 0, 0))
        p.setPen(QPen(QColor(110, 110, 115), 1))
        p.drawRect(box.adjusted(-1, -1, 0, 0))
        caption_x = min(box.left() - 2, viewport.width() - 4 - caption_w)
        draw_tag(p, QPointF(caption_x, box.bottom() + 2 + caption_h), text, QColor(225, 225, 225),
                 QColor(20, 20, 22, 225))
        label = f"{zoom}:1"
        draw_tag(p, QPointF(box.left() + 2, box.top() + 2 + tag_size(p, label)[1]), label, QColor(200, 200, 200),
                 QColor(20, 20, 22, 170))
        p.restore()
