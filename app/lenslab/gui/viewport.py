"""The viewport: the converging image, its display (the view transform, fit / zoom / pan), the selection
outline, the plane-of-focus overlay, and the tools that act on the picture (select, focus, pan).

The picture arrives from the render worker already made through the view transform (OpenColorIO's display, view
and look, the display exposure and contrast, on the GPU), with the linear radiance behind it; a new view
transform chosen before the worker's next picture is applied here to that radiance (OCIO's CPU processor, the same
transform), so changing the view never restarts the render, and the readout under the cursor shows the linear
values, not the displayed ones.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QFont, QImage, QPainter, QPen
from PySide6.QtWidgets import QWidget

from lenslab.colour_management.view import EXPOSURE_RANGE, ViewTransform
from lenslab.gui import theme
from lenslab.gui.corner_tags import CAMERA, FOCUS_PLANE, FOCUSING, STATE, TagBoard
from lenslab.render.film import display_pixels, to_8bit
from lenslab.scene.navigation import MouseTravel

ZOOM_STEPS = (0.125, 0.25, 1 / 3, 0.5, 2 / 3, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0)
OVERLAY_HOLD_SECONDS = 1.2
OVERLAY_FADE_SECONDS = 0.6


def numpy_to_qimage(rgb8: np.ndarray) -> QImage:
    h, w = rgb8.shape[:2]
    data = np.ascontiguousarray(rgb8)
    return QImage(data.data, w, h, 3 * w, QImage.Format_RGB888).copy()


def rgba_to_qimage(rgba8: np.ndarray) -> QImage:
    h, w = rgba8.shape[:2]
    data = np.ascontiguousarray(rgba8)
    return QImage(data.data, w, h, 4 * w, QImage.Format_RGBA8888).copy()


def outline_mask(mask: np.ndarray) -> np.ndarray:
    """Pixels of ``mask`` with a 4-neighbour outside it."""
    inner = mask.copy()
    inner[1:, :] &= mask[:-1, :]
    inner[:-1, :] &= mask[1:, :]
    inner[:, 1:] &= mask[:, :-1]
    inner[:, :-1] &= mask[:, 1:]
    return mask & ~inner


def focus_overlay(depth: np.ndarray, focus: float, near: float, far: float) -> np.ndarray:
    """RGBA: the zone of acceptable sharpness tinted, the plane of focus itself drawn as a bright band."""
    h, w = depth.shape
    out = np.zeros((h, w, 4), np.uint8)
    finite = np.isfinite(depth)
    zone = finite & (depth >= near) & (depth <= far)
    colour = np.array([89, 209, 140], np.uint8)  # theme.FOCUS
    out[zone, :3] = colour
    out[zone, 3] = 70
    # The plane: where the surface crosses the focus distance, a band about 1% of the distance thick (at least
    # a fifth of the depth of field, so that it reads at f/1.4 and at f/22 alike).
    band = max(0.004 * focus, 0.1 * min(far - near, focus) if math.isfinite(far) else 0.004 * focus)
    plane = finite & (np.abs(depth - focus) <= band)
    out[plane, :3] = (225, 255, 235)
    out[plane, 3] = 120
    return out


class Viewport(QWidget):
    pixel_hovered = Signal(object)  # (x, y) image pixel or None
    node_clicked = Signal(int, bool)  # depth-first node index (-1: background), add to selection
    focus_clicked = Signal(float, float)  # (u, v) in [0, 1], a click of the focus tool
    zoom_changed = Signal(float)
    resized = Signal(int, int)  # the widget's new size in device pixels
    region_drawn = Signal(object)  # (x, y, width, height) in image pixels, drawn with the region tool
    # Moving the camera with the mouse (docs/studio.md, "Moving the camera"): a gesture starts, moves by
    # (dx, dy) widget pixels since its start (the travel made with the fine modifier held counting a tenth), and
    # ends. The kind is "orbit", "pan" or "dolly".
    navigation_started = Signal(str, object)  # kind, the (x, y) image pixel it started on, or None
    navigation_moved = Signal(str, float, float)
    navigation_finished = Signal()
    dolly_wheel = Signal(float)  # wheel steps (+ towards the subject) with Ctrl held

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setObjectName("viewport")
        self.setMouseTracking(True)
        self.setFocusPolicy(Qt.StrongFocus)
        self.setMinimumSize(320, 240)
        self.setAttribute(Qt.WA_OpaquePaintEvent)
        self.linear: np.ndarray | None = None
        self.qimage: QImage | None = None
        self.view = ViewTransform()  # the view transform the window chose (gui/display_view.py)
        self.exposure_scale = 1.0  # the camera's exposure of the last picture (physical, auto): scales its radiance
        self.zoom: float | None = None  # None: fit the window
        # Space left around a fitted picture: none when the picture is rendered at the widget's size (it
        # carries its own margin around the sensor's gate), some when it is the export's pixels.
        self.fit_margin = 24
        self.region_rect: QRectF | None = None  # the render region being refined, image pixels
        self._region_start: QPointF | None = None
        self._region_end: QPointF | None = None
        self._navigation: tuple[str, MouseTravel, Qt.KeyboardModifier] | None = None  # kind, travel, fine key
        self.pan = QPointF(0, 0)
        self.tool = "select"
        self.gbuffer = None
        self.selected_indices: list[int] = []
        self._outline: QImage | None = None
        self._overlay: QImage | None = None
        self._overlay_until = 0.0
        self._overlay_label = ""
        self._drag_start: QPointF | None = None
        self._pan_start = QPointF(0, 0)
        self._press_pos: QPointF | None = None
        self.space_held = False  # a left drag pans whatever the tool, here and in the A/B comparison
        self.hud_text = ""
        self.message = ""  # an error to show over the image
        self.status_text = ""  # e.g. "Preview" in the corner
        self.idle_text = "Starting the renderer…"  # before the first picture: what is under way (work_banner.py)
        # Whether the picture is clean enough for the judging aids (peaking, clipping, the histogram) to mean
        # something: render_loop.Frame.worth_judging. Until one is, they wait rather than mark the noise.
        self.worth_judging = True
        self.focus_pending = False
        # Drawn over the picture in order, each by ``layer.paint(painter, viewport, image_rect)`` where it is
        # ``visible``: the sensor's gate and guides, focus peaking, clipping warnings, the loupe.
        self.layers: list = []
        # The export's frame (the sensor's gate) in image pixels of the viewport's picture; None: the whole picture.
        self.gate_rect: QRectF | None = None
        # The A/B comparison with a snapshot (lenslab.gui.compare.Comparison): it draws the picture in the live
        # one's place and, side by side, has the live picture laid out in the right half; None: live alone.
        self.compare = None
        # The tags wanted over the picture in a paint, laid out at its end so that none covers another.
        self.tags = TagBoard(QRectF())
        self._fade_timer = QTimer(self)
        self._fade_timer.setInterval(40)
        self._fade_timer.timeout.connect(self._fade_tick)

    # -- content ---------------------------------------------------------------------------------------------
    @property
    def exposure(self) -> float:
        """The display exposure in stops (the view transform's)."""
        return self.view.exposure_stops

    def set_frame(self, picture: np.ndarray, view: ViewTransform, linear: np.ndarray | None,
                  exposure_scale: float = 1.0) -> None:
        """Show a picture the render worker already made through ``view`` (RGBA8), with the camera's exposure
        ``exposure_scale`` on its radiance. ``linear`` is the radiance behind it for the pixel readout, or None to
        keep the last one (the render worker sends a picture of a new size with its own)."""
        h, w = picture.shape[:2]
        size_changed = self.linear is None or self.linear.shape[:2] != (h, w)
        self.exposure_scale = float(exposure_scale)
        if linear is not None:
            self.linear = linear
        if self.linear is None or self.linear.shape[:2] != (h, w):
            self.linear = None  # no readout until one comes; the picture is still shown
            self.qimage = rgba_to_qimage(picture)
            self.update()
        elif view == self.view:
            self.qimage = rgba_to_qimage(picture)
            self.update()
        else:  # the user changed the view since the worker made it: the next frame will have it
            self._redisplay()
        if size_changed:
            self._rebuild_outline()

    def picture_view(self) -> ViewTransform:
        """The view transform with the camera's exposure added, as the worker made the last picture."""
        stops = self.view.exposure_stops + math.log2(max(self.exposure_scale, 1e-30))
        return dataclasses.replace(self.view, exposure_stops=min(max(stops, EXPOSURE_RANGE[0]), EXPOSURE_RANGE[1]))

    def _redisplay(self) -> None:
        # Without a linear image (none yet, or the worker's newest picture came without one) the picture stays
        # as it is until the worker's next one, made with the new view.
        if self.linear is not None:
            self.qimage = numpy_to_qimage(to_8bit(display_pixels(self.linear, self.picture_view())))
        self.update()

    def set_view(self, view: ViewTransform) -> None:
        """Show the picture through ``view`` (a resolved ViewTransform) from now on."""
        if view != self.view:
            self.view = view
            self._redisplay()

    def display_image(self) -> QImage | None:
        return self.qimage

    def set_gbuffer(self, gbuffer) -> None:
        self.gbuffer = gbuffer
        self._rebuild_outline()

    def set_selection(self, indices: list[int]) -> None:
        self.selected_indices = list(indices)
        self._rebuild_outline()

    def _rebuild_outline(self) -> None:
        self._outline = None
        g = self.gbuffer
        if g is not None and self.selected_indices:
            mask = np.isin(g.node_index, np.asarray(self.selected_indices, np.int32))
            if mask.any():
                edge = outline_mask(mask)
                rgba = np.zeros(mask.shape + (4,), np.uint8)
                rgba[mask] = (232, 162, 58, 28)  # a faint fill
                rgba[edge] = (232, 162, 58, 255)
                self._outline = rgba_to_qimage(rgba)
        self.update()

    def show_focus_overlay(self, focus: float, near: float, far: float, hold: bool = False) -> None:
        """Show the plane of focus and the depth of field on the image; it fades out unless ``hold``."""
        g = self.gbuffer
        if g is None:
            return
        self._overlay = rgba_to_qimage(focus_overlay(g.depth, focus, near, far))
        self._overlay_label = f"focus {focus:.2f} m"
        self._overlay_until = math.inf if hold else time.monotonic() + OVERLAY_HOLD_SECONDS
        if not hold:
            self._fade_timer.start()
        self.update()

    def hide_focus_overlay(self) -> None:
        self._overlay_until = time.monotonic()
        self._fade_timer.start()

    def overlay_visible(self) -> bool:
        return self._overlay is not None and self._overlay_opacity() > 0

    def _overlay_opacity(self) -> float:
        remaining = self._overlay_until - time.monotonic()
        if remaining >= 0:
            return 1.0
        return max(0.0, 1.0 + remaining / OVERLAY_FADE_SECONDS)

    def _fade_tick(self) -> None:
        if self._overlay_opacity() <= 0:
            self._overlay = None
            self._fade_timer.stop()
        self.update()

    # -- geometry ---------------------------------------------------------------------------------------------
    def image_size(self) -> tuple[int, int]:
        if self.qimage is None:
            return (0, 0)
        return self.qimage.width(), self.qimage.height()

    def fit_scale(self) -> float:
        w, h = self.image_size()
        if w == 0:
            return 1.0
        margin = self.fit_margin
        area = self.picture_area()
        return max(0.01, min((area.width() - margin) / w, (area.height() - margin) / h))

    def picture_area(self) -> QRectF:
        """Where the live picture is fitted and centred: the whole widget, or its right half while a snapshot is
        compared side by side (the left half shows the snapshot)."""
        if self.compare is not None and self.compare.side_by_side():
            return QRectF(self.width() / 2, 0, self.width() / 2, self.height())
        return QRectF(0, 0, self.width(), self.height())

    def scale(self) -> float:
        return self.fit_scale() if self.zoom is None else self.zoom

    def image_rect(self) -> QRectF:
        w, h = self.image_size()
        s = self.scale()
        centre = self.picture_area().center() + (self.pan if self.zoom is not None else QPointF())
        return QRectF(centre.x() - w * s / 2, centre.y() - h * s / 2, w * s, h * s)

    def widget_to_image(self, pos: QPointF) -> tuple[float, float] | None:
        """Image coordinates in pixels (0, 0 = top-left corner of the top-left pixel), or None off the image."""
        rect = self.image_rect()
        if rect.width() <= 0 or not rect.contains(pos):
            return None
        if self.compare is not None and self.compare.side_by_side() and pos.x() < self.width() / 2:
            return None  # the snapshot's half, into which a zoomed live picture may reach
        s = self.scale()
        return (pos.x() - rect.left()) / s, (pos.y() - rect.top()) / s

    def image_to_widget(self, x: float, y: float) -> QPointF:
        rect = self.image_rect()
        s = self.scale()
        return QPointF(rect.left() + x * s, rect.top() + y * s)

    def fit(self) -> None:
        self.zoom = None
        self.pan = QPointF()
        self.update()
        self.zoom_changed.emit(self.scale())

    def set_zoom(self, zoom: float, anchor: QPointF | None = None) -> None:
        zoom = min(max(zoom, ZOOM_STEPS[0]), ZOOM_STEPS[-1])
        anchor = anchor if anchor is not None else QPointF(self.width() / 2, self.height() / 2)
        before = self.widget_to_image_unclamped(anchor)
        if self.zoom is None:
            self.pan = QPointF()
        self.zoom = zoom
        # Keep the image point under the anchor where it was.
        after = self.image_to_widget(*before)
        self.pan += anchor - after
        self.update()
        self.zoom_changed.emit(self.scale())

    def widget_to_image_unclamped(self, pos: QPointF) -> tuple[float, float]:
        rect = self.image_rect()
        s = self.scale()
        return (pos.x() - rect.left()) / s, (pos.y() - rect.top()) / s

    def zoom_step(self, direction: int, anchor: QPointF | None = None) -> None:
        current = self.scale()
        if direction > 0:
            target = next((z for z in ZOOM_STEPS if z > current * 1.001), ZOOM_STEPS[-1])
        else:
            target = next((z for z in reversed(ZOOM_STEPS) if z < current / 1.001), ZOOM_STEPS[0])
        self.set_zoom(target, anchor)

    # -- painting ---------------------------------------------------------------------------------------------
    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(theme.BACKGROUND))
        self.tags.begin(QRectF(self.rect()).adjusted(4, 4, -4, -4))
        if self.qimage is not None:
            rect = self.image_rect()
            # Pixel-peeping at 200% and above shows the pixels as they are; a fitted picture is always smooth.
            smooth = self.zoom is None or self.scale() < 2.0
            p.setRenderHint(QPainter.SmoothPixmapTransform, smooth)
            p.fillRect(rect.adjusted(-1, -1, 1, 1), QColor("#000000"))
            if self.compare is None or not self.compare.paint_picture(p, rect):
                p.drawImage(rect, self.qimage)
            if self.message:
                p.fillRect(rect, QColor(0, 0, 0, 140))
            if self._outline is not None and self._outline.size() == self.qimage.size():
                p.drawImage(rect, self._outline)
            if self._overlay is not None and self._overlay.size() == self.qimage.size():
                p.setOpacity(self._overlay_opacity())
                p.drawImage(rect, self._overlay)
                p.setOpacity(1.0)
                self.tags.want(self._overlay_label, QPointF(rect.left() + 10, rect.bottom() - 12), theme.FOCUS,
                               FOCUS_PLANE, opacity=self._overlay_opacity())
            for layer in self.layers:
                if getattr(layer, "visible", True):
                    layer.paint(p, self, rect)
            self._draw_region(p)
            if self.compare is not None:
                self.compare.paint_over(p, rect)
        self._draw_hud(p)
        self.tags.draw(p)
        if self.message:
            p.setPen(QColor("#f0c0a0"))
            font = QFont(self.font())
            if font.pointSizeF() > 0:
                font.setPointSizeF(font.pointSizeF() * 1.1)
            p.setFont(font)
            p.drawText(self.rect().adjusted(40, 40, -40, -40), Qt.AlignCenter | Qt.TextWordWrap, self.message)
        elif self.qimage is None:
            p.setPen(QColor(theme.DIM_TEXT))
            p.drawText(self.rect(), Qt.AlignCenter, self.idle_text)
        p.end()

    def _draw_region(self, p: QPainter) -> None:
        """The render region: the one being refined, and the one being drawn with the region tool."""
        rects = []
        if self.region_rect is not None:
            rects.append((self.region_rect, theme.ACCENT))
        if self._region_start is not None and self._region_end is not None:
            rects.append((self._drawn_region(), "#ffffff"))
        for region, colour in rects:
            top_left = self.image_to_widget(region.left(), region.top())
            bottom_right = self.image_to_widget(region.right(), region.bottom())
            pen = QPen(QColor(colour))
            pen.setStyle(Qt.DashLine)
            p.setPen(pen)
            p.setBrush(Qt.NoBrush)
            p.drawRect(QRectF(top_left, bottom_right))

    def _drawn_region(self) -> QRectF:
        a, b = self._region_start, self._region_end
        w, h = self.image_size()
        x0, x1 = sorted((min(max(a.x(), 0), w), min(max(b.x(), 0), w)))
        y0, y1 = sorted((min(max(a.y(), 0), h), min(max(b.y(), 0), h)))
        return QRectF(x0, y0, x1 - x0, y1 - y0)

    def _draw_hud(self, p: QPainter) -> None:
        """The corner tags: the camera's settings top left, the render's state top right (both of the picture shown:
        a snapshot's while the comparison shows it alone), and "focusing…" while a focus click is on its way."""
        rect = self.image_rect() if self.qimage is not None else QRectF(self.rect())
        top = max(4.0, rect.top() - 4)
        y = top + 22 if rect.top() < 26 else top
        hud, status = self.hud_text, self.status_text
        if self.compare is not None:
            hud, status = self.compare.corner_texts(hud, status)
        self.tags.want(hud, QPointF(max(4.0, rect.left()), y), "#e6e6e6", CAMERA)
        self.tags.want(status, QPointF(min(self.width() - 4.0, rect.right()), y), theme.DIM_TEXT, STATE, grows="left")
        if self.tool == "focus" and self.focus_pending:
            self.tags.want("focusing…", QPointF(8, self.height() - 8), theme.FOCUS, FOCUSING)

    # -- interaction --------------------------------------------------------------------------------------------
    def set_tool(self, tool: str) -> None:
        self.tool = tool
        self.setCursor({"select": Qt.ArrowCursor, "focus": Qt.CrossCursor, "pan": Qt.OpenHandCursor,
                        "region": Qt.CrossCursor}[tool])
        self.update()

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        ratio = self.devicePixelRatioF()
        self.resized.emit(round(self.width() * ratio), round(self.height() * ratio))

    def wheelEvent(self, event) -> None:
        steps = event.angleDelta().y()
        if steps and event.modifiers() & Qt.ControlModifier:
            self.dolly_wheel.emit(steps / 120)
        elif steps:
            self.zoom_step(1 if steps > 0 else -1, event.position())

    @staticmethod
    def navigation_kind(button, modifiers) -> str | None:
        """The camera move a mouse button starts (Blender's middle button, Maya's Alt), or None."""
        alt = bool(modifiers & Qt.AltModifier)
        if button == Qt.MiddleButton:
            if alt:
                return "pan"  # Maya: Alt + middle
            if modifiers & Qt.ShiftModifier:
                return "pan"  # Blender: Shift + middle
            if modifiers & Qt.ControlModifier:
                return "dolly"  # Blender: Ctrl + middle
            return "orbit"  # Blender: middle
        if alt and button == Qt.LeftButton:
            return "orbit"  # Maya: Alt + left
        if alt and button == Qt.RightButton:
            return "dolly"  # Maya: Alt + right
        return None

    @staticmethod
    def fine_modifier(modifiers) -> Qt.KeyboardModifier:
        """The key that makes a camera move fine while it is held: Shift, unless Shift chose the gesture
        (Blender's pan), where it is Ctrl. A key that chose the gesture may be held all through it."""
        return Qt.ControlModifier if modifiers & Qt.ShiftModifier else Qt.ShiftModifier

    def mousePressEvent(self, event) -> None:
        pos = event.position()
        kind = self.navigation_kind(event.button(), event.modifiers())
        if kind is not None and self._navigation is None:
            self._navigation = (kind, MouseTravel(pos.x(), pos.y()), self.fine_modifier(event.modifiers()))
            xy = self.widget_to_image(pos)
            self.setCursor(Qt.SizeAllCursor)
            self.navigation_started.emit(kind, None if xy is None else (int(xy[0]), int(xy[1])))
            return
        if event.button() == Qt.LeftButton and self.tool == "region" and not self.space_held:
            start = self.widget_to_image_unclamped(pos)
            self._region_start = self._region_end = QPointF(*start)
            return
        panning = event.button() == Qt.LeftButton and (self.tool == "pan" or self.space_held)
        if panning:
            if self.zoom is None:
                self.zoom = self.fit_scale()
                self.pan = QPointF()
            self._drag_start = pos
            self._pan_start = QPointF(self.pan)
            self.setCursor(Qt.ClosedHandCursor)
            return
        if event.button() == Qt.LeftButton:
            self._press_pos = pos
            if self.tool == "focus":
                self._preview_focus_at(pos)

    def mouseMoveEvent(self, event) -> None:
        pos = event.position()
        if self._navigation is not None:
            # The travel is summed stretch by stretch, each at the speed of the keys held as it was made, so
            # the camera depends on the mouse's path and not on how many events the system sent along it.
            kind, travel, fine = self._navigation
            dx, dy = travel.move_to(pos.x(), pos.y(), bool(event.modifiers() & fine))
            self.navigation_moved.emit(kind, dx, dy)
            return
        if self._region_start is not None:
            self._region_end = QPointF(*self.widget_to_image_unclamped(pos))
            self.update()
            return
        if self._drag_start is not None:
            self.pan = self._pan_start + (pos - self._drag_start)
            self.update()
            return
        xy = self.widget_to_image(pos)
        self.pixel_hovered.emit(None if xy is None else (int(xy[0]), int(xy[1])))
        if self.tool == "focus" and self._press_pos is not None:
            self._preview_focus_at(pos)

    def mouseReleaseEvent(self, event) -> None:
        pos = event.position()
        if self._navigation is not None:
            self._navigation = None
            self.set_tool(self.tool)
            self.navigation_finished.emit()
            return
        if self._region_start is not None:
            self._region_end = QPointF(*self.widget_to_image_unclamped(pos))
            region = self._drawn_region()
            self._region_start = self._region_end = None
            self.update()
            if region.width() >= 4 and region.height() >= 4:  # a click is not a region
                self.region_drawn.emit((region.left(), region.top(), region.width(), region.height()))
            return
        if self._drag_start is not None:
            self._drag_start = None
            self.set_tool(self.tool)
            return
        if event.button() != Qt.LeftButton or self._press_pos is None:
            return
        self._press_pos = None
        xy = self.widget_to_image(pos)
        if xy is None:
            if self.tool == "select":
                self.node_clicked.emit(-1, False)
            return
        w, h = self.image_size()
        if self.tool == "focus":
            self.focus_pending = True
            self.focus_clicked.emit(xy[0] / w, xy[1] / h)
        elif self.tool == "select":
            index = self.node_at(int(xy[0]), int(xy[1]))
            self.node_clicked.emit(index, bool(event.modifiers() & (Qt.ShiftModifier | Qt.ControlModifier)))

    def leaveEvent(self, event) -> None:
        self.pixel_hovered.emit(None)

    def keyPressEvent(self, event) -> None:
        if event.key() == Qt.Key_Space and not event.isAutoRepeat():
            self.space_held = True
            self.setCursor(Qt.OpenHandCursor)
            return
        super().keyPressEvent(event)

    def keyReleaseEvent(self, event) -> None:
        if event.key() == Qt.Key_Space and not event.isAutoRepeat():
            self.space_held = False
            self.set_tool(self.tool)
            return
        super().keyReleaseEvent(event)

    def node_at(self, x: int, y: int) -> int:
        g = self.gbuffer
        if g is None or not (0 <= y < g.node_index.shape[0] and 0 <= x < g.node_index.shape[1]):
            return -1
        return int(g.node_index[y, x])

    def depth_at(self, x: int, y: int) -> float:
        g = self.gbuffer
        if g is None or not (0 <= y < g.depth.shape[0] and 0 <= x < g.depth.shape[1]):
            return math.inf
        return float(g.depth[y, x])

    focus_preview = Signal(float)  # depth under the focus tool while the button is held

    def _preview_focus_at(self, pos: QPointF) -> None:
        xy = self.widget_to_image(pos)
        if xy is None:
            return
        depth = self.depth_at(int(xy[0]), int(xy[1]))
        if math.isfinite(depth):
            self.focus_preview.emit(depth)
