"""The viewport's A/B comparison: a snapshot (A, ``lenslab.gui.snapshots``) drawn with the live picture (B).

The viewport holds one :class:`Comparison` as ``viewport.compare`` and asks it to draw the picture and, over
everything else, the divider and the tags. What it shows is the store's ``view``:

- ``"wipe"``: A left of a vertical divider, B right of it, in the same rectangle at the same scale. The divider
  sits at a fraction of the picture's width (so it stays on the same column as you zoom); drag it (the cursor
  turns into a splitter within :data:`GRAB_PIXELS` of it). Tags either side of it say which is which. Left of
  it the readout reads A's radiance; clicks select and focus in the live scene everywhere, since both show the
  same frame.
- ``"side"``: the widget split in two halves, A in the left, B in the right, each the whole picture fitted to its
  half, zoomed and panned together. The viewport lays the live picture out in the right half (its
  ``image_rect``), so picking, the outline, the overlays and its ``layers`` act there as ever; the left half
  reads A's radiance under the cursor, and clicks there do nothing (the wheel zooms both about that point).
- ``"a"``: A alone in place of B (the quick A/B toggle); the readout reads A.

A snapshot of another size than the live picture (the window was resized since) is scaled into the same
rectangle; of another shape, fitted inside it, centred.

Mouse events reach the comparison through an event filter on the viewport, ahead of the viewport's own
handlers: a press it takes (the divider, the left half) never reaches the tools.
"""

from __future__ import annotations

from typing import Callable

from PySide6.QtCore import QEvent, QObject, QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QImage, QPainter, QPen

from lenslab.gui import theme
from lenslab.gui.corner_tags import COMPARE, camera_tag
from lenslab.gui.snapshots import Snapshot, SnapshotStore, compare_tags
from lenslab.gui.viewport import rgba_to_qimage

GRAB_PIXELS = 6  # the divider takes a press this near it
A_COLOUR = theme.ACCENT
B_COLOUR = "#e6e6e6"


def fitted(rect: QRectF, width: int, height: int) -> QRectF:
    """Where a picture of ``width`` x ``height`` goes in ``rect``: all of it when the shapes agree (within 1 %);
    otherwise the largest rectangle of the picture's shape, centred."""
    if width <= 0 or height <= 0 or rect.width() <= 0 or rect.height() <= 0:
        return QRectF(rect)
    if abs((width / height) / (rect.width() / rect.height()) - 1) <= 0.01:
        return QRectF(rect)
    s = min(rect.width() / width, rect.height() / height)
    w, h = width * s, height * s
    return QRectF(rect.center().x() - w / 2, rect.center().y() - h / 2, w, h)


class Comparison(QObject):
    def __init__(self, store: SnapshotStore, viewport, live_camera: Callable[[], object]):
        super().__init__(viewport)
        self.store = store
        self.viewport = viewport
        self.live_camera = live_camera
        self.hover_a: tuple[int, int] | None = None  # A's pixel under the cursor, where A is shown there
        self._image_key: tuple = ()
        self._image: QImage | None = None
        self._dragging = False
        self._near_divider = False
        self._saved_cursor = None
        self._swallowed_press = False
        self._last_pos: QPointF | None = None  # the cursor over the viewport, for the readout
        self._side = store.view == "side"
        store.events.connect(self._store_changed)
        viewport.compare = self
        viewport.installEventFilter(self)

    # -- state ----------------------------------------------------------------------------------------------------
    def view(self) -> str:
        return self.store.view

    def side_by_side(self) -> bool:
        return self.store.view == "side"

    def shows_a_alone(self) -> bool:
        """The snapshot is shown in place of the live picture (the quick A/B toggle): nothing live is in sight."""
        return self.store.view == "a" and self.store.a is not None

    def _store_changed(self, _what: str) -> None:
        v = self.viewport
        side = self.side_by_side()
        if side != self._side:  # the live picture moves to its half or back: the fit changes
            self._side = side
            v.zoom_changed.emit(v.scale())
        if self._last_pos is not None:  # what is under a cursor at rest changed
            self.hover_a = self.a_pixel_at(self._last_pos)
        v.update()

    def a_image(self) -> QImage | None:
        """A through the viewport's view transform (display, view, look, exposure, contrast)."""
        a: Snapshot | None = self.store.a
        if a is None:
            return None
        key = (a.id, self.viewport.view)
        if key != self._image_key:
            self._image = rgba_to_qimage(a.picture(self.viewport.view))
            self._image_key = key
        return self._image

    # -- geometry ---------------------------------------------------------------------------------------------------
    def half_width(self) -> float:
        return self.viewport.width() / 2

    def a_rect(self, rect: QRectF | None = None) -> QRectF:
        """Where A is drawn, given the live picture's rectangle: the same one, or its twin in the left half."""
        rect = self.viewport.image_rect() if rect is None else rect
        if self.side_by_side():
            rect = rect.translated(-self.half_width(), 0)
        a = self.store.a
        return fitted(rect, *a.size) if a is not None else rect

    def divider_x(self, rect: QRectF | None = None) -> float:
        rect = self.viewport.image_rect() if rect is None else rect
        return rect.left() + self.store.divider * rect.width()

    def near_divider(self, pos: QPointF) -> bool:
        if self.view() != "wipe":
            return False
        rect = self.viewport.image_rect()
        return abs(pos.x() - self.divider_x(rect)) <= GRAB_PIXELS and rect.top() <= pos.y() <= rect.bottom()

    def shows_a_at(self, pos: QPointF) -> bool:
        view = self.view()
        if view == "a":
            return True
        if view == "wipe":
            return pos.x() < self.divider_x()
        return view == "side" and pos.x() < self.half_width()

    def a_pixel_at(self, pos: QPointF) -> tuple[int, int] | None:
        """A's pixel under a widget position where the viewport shows A there, else None."""
        a = self.store.a
        if a is None or not self.shows_a_at(pos):
            return None
        r = self.a_rect()
        if r.width() <= 0 or not r.contains(pos):
            return None
        w, h = a.size
        x = int((pos.x() - r.left()) / r.width() * w)
        y = int((pos.y() - r.top()) / r.height() * h)
        return min(x, w - 1), min(y, h - 1)

    # -- painting ---------------------------------------------------------------------------------------------------
    def corner_texts(self, camera: str, state: str) -> tuple[str, str]:
        """The corner tags' texts for the picture shown, given the live picture's (its camera, its render's state):
        A's own while A is shown alone; the live ones, marked B, beside A in the wipe, whose left side (where the
        camera tag sits) shows A."""
        a = self.store.a
        if self.shows_a_alone():
            return f"A: {camera_tag(a.camera)}", f"A: {a.samples_per_pixel} spp"
        if self.view() == "wipe" and camera:
            return f"B: {camera}", state
        return camera, state

    def paint_picture(self, p: QPainter, rect: QRectF) -> bool:
        """Draw the picture for the current view in place of the live one; False: the view is the live picture
        alone, which the viewport draws itself. Side by side leaves the painter clipped to the right half, so that
        what the viewport draws over the live picture stays in its half (``paint_over`` lifts it)."""
        view = self.view()
        image = self.a_image()
        live = self.viewport.qimage
        if view == "off" or image is None:
            return False
        black = QColor("#000000")
        if view == "a":
            p.drawImage(self.a_rect(rect), image)
        elif view == "wipe":
            p.drawImage(rect, live)
            p.save()
            p.setClipRect(QRectF(rect.left(), rect.top(), self.divider_x(rect) - rect.left(), rect.height()))
            p.fillRect(rect, black)
            p.drawImage(self.a_rect(rect), image)
            p.restore()
        else:  # side by side
            half = self.half_width()
            height = self.viewport.height()
            p.save()
            p.setClipRect(QRectF(0, 0, half, height))
            p.fillRect(rect.translated(-half, 0).adjusted(-1, -1, 1, 1), black)
            p.drawImage(self.a_rect(rect), image)
            p.restore()
            p.setClipRect(QRectF(half, 0, self.viewport.width() - half, height))
            p.drawImage(rect, live)
        return True

    def paint_over(self, p: QPainter, rect: QRectF) -> None:
        """The divider and the A and B tags, over the picture and its overlays."""
        p.setClipping(False)
        view = self.view()
        a = self.store.a
        if view == "off" or a is None:
            return
        v = self.viewport
        a_tag, b_tag = compare_tags(a, self.live_camera())
        visible = QRectF(v.rect()).intersected(rect)
        # The tags sit at the bottom, by the divider or centred under each picture: the corners are the overlays'
        # (the plane of focus's distance, the gate's size).
        if view == "a":
            self._tag(p, visible, a_tag, A_COLOUR, "centre")
            return
        if view == "wipe":
            x = self.divider_x(rect)
            top, bottom = max(rect.top(), 0.0), min(rect.bottom(), float(v.height()))
            p.setPen(QPen(QColor(0, 0, 0, 160), 3))
            p.drawLine(QPointF(x, top), QPointF(x, bottom))
            p.setPen(QPen(QColor(A_COLOUR if self._dragging or self._near_divider else "#f2f2f2"), 1))
            p.drawLine(QPointF(x, top), QPointF(x, bottom))
            # A handle halfway down the visible part, to show it can be dragged.
            p.setRenderHint(QPainter.Antialiasing, True)
            p.setBrush(QColor(20, 20, 22, 220))
            centre = QPointF(x, (top + bottom) / 2)
            p.drawEllipse(centre, 9, 9)
            p.setPen(QPen(QColor("#f2f2f2"), 1.5))
            for sign in (-1, 1):
                p.drawLine(centre + QPointF(sign * 2, -4), centre + QPointF(sign * 6, 0))
                p.drawLine(centre + QPointF(sign * 6, 0), centre + QPointF(sign * 2, 4))
            p.setRenderHint(QPainter.Antialiasing, False)
            self._tag(p, QRectF(visible.left(), visible.top(), x - 10 - visible.left(), visible.height()), a_tag,
                      A_COLOUR, "right")
            self._tag(p, QRectF(x + 10, visible.top(), visible.right() - x - 10, visible.height()), b_tag,
                      B_COLOUR, "left")
            return
        half = self.half_width()
        p.setPen(QPen(QColor(theme.BACKGROUND), 4))
        p.drawLine(QPointF(half, 0), QPointF(half, v.height()))
        left = QRectF(0, 0, half, v.height()).intersected(self.a_rect(rect))
        right = QRectF(half, 0, v.width() - half, v.height()).intersected(rect)
        self._tag(p, left, a_tag, A_COLOUR, "centre")
        self._tag(p, right, b_tag, B_COLOUR, "centre")

    def _tag(self, p: QPainter, area: QRectF, text: str, colour: str, align: str) -> None:
        """A tag at the bottom of ``area``, against its left or right side or centred, shortened to fit it (the side
        of a divider dragged near the edge) or left out."""
        if area.height() < 40:
            return
        x = {"left": area.left(), "right": area.right()}.get(align, area.center().x())
        grows = {"left": "right", "right": "left"}.get(align, "both")
        self.viewport.tags.want(text, QPointF(x, area.bottom() - 10), colour, COMPARE, grows=grows, bounds=area)

    # -- the mouse --------------------------------------------------------------------------------------------------
    def eventFilter(self, obj, event) -> bool:
        if obj is not self.viewport:
            return False
        kind = event.type()
        if kind == QEvent.MouseButtonPress:
            return self._press(event)
        if kind == QEvent.MouseMove:
            return self._move(event)
        if kind == QEvent.MouseButtonRelease:
            return self._release(event)
        if kind == QEvent.Wheel:
            return self._wheel(event)
        if kind == QEvent.Leave:
            self.hover_a = self._last_pos = None
            self._set_near(False)
        return False

    def _panning(self, event) -> bool:
        return event.button() == Qt.MiddleButton or self.viewport.space_held

    def _press(self, event) -> bool:
        pos = event.position()
        if event.button() != Qt.LeftButton or self._panning(event):
            return False
        if self.near_divider(pos):
            self._dragging = True
            self._set_near(True)
            return True
        if self.side_by_side() and pos.x() < self.half_width() and not event.modifiers():
            self._swallowed_press = True  # the snapshot's half: nothing there to select or focus on
            return True
        return False

    def _move(self, event) -> bool:
        pos = event.position()
        if self._dragging:
            rect = self.viewport.image_rect()
            if rect.width() > 0:
                self.store.set_divider((pos.x() - rect.left()) / rect.width())
            return True
        self._last_pos = QPointF(pos)
        self.hover_a = self.a_pixel_at(pos)
        if not event.buttons():
            self._set_near(self.near_divider(pos))
        return False

    def _release(self, event) -> bool:
        if self._dragging and event.button() == Qt.LeftButton:
            self._dragging = False
            self._set_near(self.near_divider(event.position()))
            self.viewport.update()
            return True
        if self._swallowed_press and event.button() == Qt.LeftButton:
            self._swallowed_press = False
            return True
        return False

    def _wheel(self, event) -> bool:
        pos = event.position()
        steps = event.angleDelta().y()
        if not (self.side_by_side() and pos.x() < self.half_width() and steps) or event.modifiers():
            return False  # a modified wheel (Ctrl: dolly the camera) goes to the viewport
        # The halves are zoomed together: about the same point of the picture in the live half.
        self.viewport.zoom_step(1 if steps > 0 else -1, pos + QPointF(self.half_width(), 0))
        return True

    def _set_near(self, near: bool) -> None:
        if near == self._near_divider:
            return
        self._near_divider = near
        v = self.viewport
        if near:
            self._saved_cursor = v.cursor()
            v.setCursor(Qt.SplitHCursor)
        elif self._saved_cursor is not None:
            v.setCursor(self._saved_cursor)
            self._saved_cursor = None
        v.update()


__all__ = ["Comparison", "GRAB_PIXELS", "fitted"]
