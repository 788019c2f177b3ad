"""The viewport's tags, laid out so that none covers another: the camera's settings and the render's state in the
top corners, the frame's shape and size under it, the plane of focus's distance, the sensor's size, A and B.

Whoever draws over the picture asks the viewport's :class:`TagBoard` for a tag (:meth:`TagBoard.want`) instead of
drawing it: its text, its colours, where it is anchored (the bottom-left, bottom-right or bottom-centre of its box)
and how much it matters. At the end of the paint the board places them, the most important first, and draws them
on top of everything. A tag that would cover one already placed is shortened to the room left before it (its text
elided: "50 mm · f/1.8 · fo…"), or left out when not even a few letters would fit. So at the smallest window the
camera's settings stay whole and the sample count gives way, and nothing is drawn over anything else."""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QPainter

from lenslab.gui.layer_support import draw_tag, tag_size
from lenslab.optics import format_camera_settings
from lenslab.optics.exposure import format_shutter

#: How much each tag matters: the higher keeps its place and its text when two would overlap.
CAMERA, FOCUSING, COMPARE, FRAME, FOCUS_PLANE, STATE, SENSOR = 100, 95, 90, 80, 70, 60, 40
#: The work banner (gui/work_banner.py) is no tag, but the tags below it in importance keep out of its box.
BANNER = 85
GAP = 6  # pixels kept between two tags
MIN_LETTERS = 4  # a tag shortened to fewer letters than this is left out: "f/1…" says nothing
BACKGROUND = QColor(20, 20, 22, 200)


def camera_tag(camera, exposure=None) -> str:
    """What the camera tag says of a camera: "50 mm · f/1.8 · focus 1.67 m", with the shutter and ISO in the
    physical exposure mode, and in the auto mode the shutter the meter chose (``exposure``, the picture's:
    "A 1/250 s", as a camera's aperture-priority mode shows it) and the ISO."""
    text = format_camera_settings(camera.focal_length_mm, camera.f_number, camera.focus_distance_m)
    if camera.exposure_mode == "physical":
        text += f" \u00b7 {format_shutter(camera.shutter_s)} \u00b7 ISO {camera.iso:g}"
    elif camera.exposure_mode == "auto":
        shutter = f"A {format_shutter(exposure.shutter_s)}" if exposure is not None else "auto"
        text += f" \u00b7 {shutter} \u00b7 ISO {camera.iso:g}"
    return text


@dataclass
class Tag:
    text: str
    at: QPointF  # the anchored point of the box's bottom edge
    grows: str  # "right" (``at`` is its bottom-left), "left" (bottom-right) or "both" (bottom-centre)
    colour: QColor | str
    priority: int
    background: QColor
    opacity: float = 1.0
    bounds: QRectF | None = None  # the box stays inside this (the board's area when None)


class TagBoard:
    """The tags wanted in one paint of the viewport, and where they went (``placed``: text and box, for whoever
    needs to know, the tests among them)."""

    def __init__(self, area: QRectF):
        self.area = QRectF(area)
        self.wanted: list[Tag] = []
        self.placed: list[tuple[str, QRectF]] = []
        # Boxes drawn by others, each with the priority below which tags keep out of it.
        self.reserved: list[tuple[QRectF, int]] = []

    def begin(self, area: QRectF) -> None:
        """A new paint, over ``area``: no tag wanted yet, no box reserved."""
        self.area = QRectF(area)
        self.wanted = []
        self.reserved = []

    def reserve(self, box: QRectF, priority: int) -> None:
        """Something else is drawn in ``box`` (the work banner): tags less important than ``priority`` keep out
        of it."""
        self.reserved.append((QRectF(box), priority))

    def want(self, text: str, at: QPointF, colour: QColor | str, priority: int, grows: str = "right",
             background: QColor = BACKGROUND, opacity: float = 1.0, bounds: QRectF | None = None) -> None:
        if text and opacity > 0:
            self.wanted.append(Tag(text, QPointF(at), grows, colour, priority, background, opacity, bounds))

    def draw(self, p: QPainter) -> None:
        """Place the tags wanted, the most important first, and draw them."""
        self.placed = []
        order = sorted(range(len(self.wanted)), key=lambda i: (-self.wanted[i].priority, i))
        for i in order:
            tag = self.wanted[i]
            fitted = self._fit(p, tag)
            if fitted is None:
                continue
            text, box = fitted
            p.save()
            p.setClipping(False)
            p.setOpacity(tag.opacity)
            drawn = draw_tag(p, box.bottomLeft(), text, tag.colour, tag.background)
            p.restore()
            self.placed.append((text, QRectF(drawn)))
        self.wanted = []

    # -- layout -----------------------------------------------------------------------------------------------------
    def _fit(self, p: QPainter, tag: Tag) -> tuple[str, QRectF] | None:
        """The text and box of ``tag`` where it covers no tag placed before it, or None: no room."""
        text = tag.text
        width, height = tag_size(p, text)
        bounds = self.area if tag.bounds is None else tag.bounds.intersected(self.area)
        bottom = max(tag.at.y(), bounds.top() + height)  # not above the top of its bounds
        left, right = self._room(tag, bottom - height, bottom, bounds)
        room = right - left
        if width > room:
            metrics = p.fontMetrics()
            budget = round(room) - 12  # the box's padding
            while True:
                text = metrics.elidedText(tag.text, Qt.ElideRight, max(0, budget))
                if len(text.rstrip("\u2026")) < MIN_LETTERS:
                    return None
                width = tag_size(p, text)[0]
                if width <= room:
                    break
                budget -= 2
        x = {"right": tag.at.x(), "left": tag.at.x() - width}.get(tag.grows, tag.at.x() - width / 2)
        # Into the room left, as near its anchor as it can be: that room holds no other tag.
        x = max(left, min(x, right - width))
        return text, QRectF(x, bottom - height, width, height)

    def _room(self, tag: Tag, top: float, bottom: float, bounds: QRectF) -> tuple[float, float]:
        """The stretch of the tag's row, left to right, that it may take: its bounds, less what the tags already
        placed on that row take on either side of its anchor."""
        left, right = bounds.left(), bounds.right()
        anchor = tag.at.x()
        obstacles = [box for _text, box in self.placed]
        obstacles += [box for box, priority in self.reserved if tag.priority < priority]
        for box in obstacles:
            if box.bottom() + GAP / 2 <= top or box.top() - GAP / 2 >= bottom:
                continue  # another row
            if box.right() + GAP <= anchor:
                left = max(left, box.right() + GAP)
            elif box.left() - GAP >= anchor:
                right = min(right, box.left() - GAP)
            else:  # it covers the anchor itself
                return 0.0, 0.0
        # A tag anchored at its left never reaches left of its anchor, nor one anchored at its right right of it.
        if tag.grows == "right":
            left = max(left, anchor)
        elif tag.grows == "left":
            right = min(right, anchor)
        return left, right


__all__ = ["TagBoard", "Tag", "camera_tag", "CAMERA", "FOCUSING", "COMPARE", "FRAME", "FOCUS_PLANE", "STATE",
           "SENSOR", "BANNER"]
