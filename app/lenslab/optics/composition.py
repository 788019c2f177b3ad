"""Lines a photographer composes with, and the broadcast safe areas, for a frame given as a rectangle.

A rectangle is ``(x, y, width, height)`` in any units with y pointing down (image pixels, screen pixels); a line is
``(x1, y1, x2, y2)`` in the same units. Nothing here knows who draws them.

Guides:

* ``thirds``: the rule of thirds, the frame cut in three each way.
* ``golden``: the golden section (the "phi grid"): lines at 1/phi^2 = 0.382 and 1/phi = 0.618 of each side, so that
  each line divides the side in the golden ratio phi = (1 + sqrt 5) / 2.
* ``centre``: a cross at the centre of the frame, its arms :data:`CENTRE_MARK` of the short side long each way.
* ``none``.

Safe areas (:func:`safe_rect`), centred rectangles of a fraction of the frame's width and height, as SMPTE ST
2046-1:2009, EBU R 95 (2008) and ITU-R BT.1848 define them for 16:9 television: essential action inside the
**action safe** area, 93 % (3.5 % in from each edge); titles and graphics inside the **title safe** area, 90 % (5 %
in). The older 4:3 figures (SMPTE RP 27.3: 90 % and 80 %) allowed for the overscan of tube television sets.
"""

from __future__ import annotations

import math

Rect = tuple[float, float, float, float]
Line = tuple[float, float, float, float]

#: The composition guides, in menu order, and their names.
GUIDES = ("none", "thirds", "golden", "centre")
GUIDE_NAMES = {"none": "None", "thirds": "Rule of Thirds", "golden": "Golden Section", "centre": "Centre"}

PHI = (1.0 + math.sqrt(5.0)) / 2.0
#: Where the golden section's lines cut each side, as fractions of it.
GOLDEN_FRACTIONS = (1.0 - 1.0 / PHI, 1.0 / PHI)  # 0.382, 0.618
THIRDS_FRACTIONS = (1.0 / 3.0, 2.0 / 3.0)
#: Half the length of the centre cross's arms, as a fraction of the frame's short side.
CENTRE_MARK = 0.04

#: SMPTE ST 2046-1 / EBU R 95: the action safe and title (graphics) safe areas, fractions of width and height.
ACTION_SAFE = 0.93
TITLE_SAFE = 0.90


def _grid(rect: Rect, fractions: tuple[float, ...]) -> list[Line]:
    x, y, w, h = rect
    lines = [(x + f * w, y, x + f * w, y + h) for f in fractions]  # verticals, left to right
    lines += [(x, y + f * h, x + w, y + f * h) for f in fractions]  # horizontals, top to bottom
    return lines


def guide_lines(kind: str, rect: Rect) -> list[Line]:
    """The lines of guide ``kind`` (one of :data:`GUIDES`) inside ``rect``: the vertical lines first, left to
    right, then the horizontal ones, top to bottom."""
    if kind == "none":
        return []
    if kind == "thirds":
        return _grid(rect, THIRDS_FRACTIONS)
    if kind == "golden":
        return _grid(rect, GOLDEN_FRACTIONS)
    if kind == "centre":
        x, y, w, h = rect
        cx, cy, arm = x + w / 2, y + h / 2, CENTRE_MARK * min(w, h)
        return [(cx, cy - arm, cx, cy + arm), (cx - arm, cy, cx + arm, cy)]
    raise ValueError(f"unknown guide {kind!r} (choose from {', '.join(GUIDES)})")


def safe_rect(rect: Rect, fraction: float) -> Rect:
    """The centred rectangle of ``fraction`` of ``rect``'s width and height (:data:`ACTION_SAFE`,
    :data:`TITLE_SAFE`)."""
    if not 0.0 < fraction <= 1.0:
        raise ValueError(f"a safe area is a fraction of the frame in (0, 1], not {fraction}")
    x, y, w, h = rect
    return (x + w * (1 - fraction) / 2, y + h * (1 - fraction) / 2, w * fraction, h * fraction)


def sensor_rect(rect: Rect, sensor_mm: tuple[float, float], imaged_mm: tuple[float, float]) -> Rect:
    """Where the whole sensor lies relative to a frame ``rect`` that shows ``imaged_mm`` of it (the camera's
    imaged area, ``ThinLensCamera.imaged_area_mm``): the same rectangle when the image spans the sensor, inside
    it when the image overscans, around it when the image is a crop (the sensor fit "fill")."""
    x, y, w, h = rect
    sw, sh = w * sensor_mm[0] / imaged_mm[0], h * sensor_mm[1] / imaged_mm[1]
    return (x + (w - sw) / 2, y + (h - sh) / 2, sw, sh)
