"""The frame's shape: aspect-ratio presets, the resolution a preset gives, and the name of a resolution's shape.

A preset is a width-to-height ratio with its orientation: 3:2 and 16:9 are landscape, 4:5 portrait (the print and
the social-media crop), 1:1 square. Choosing one keeps the image's **long edge** in pixels and works out the other
side from the ratio, rounded to the nearest pixel: 1920 x 1080 at 3:2 is 1920 x 1280, at 4:5 1536 x 1920. So the
export keeps its size class whatever shape it takes, and going back to the first shape gives the first
resolution again (1920 x 1280 at 16:9 is 1920 x 1080).

A resolution *is* a preset when the preset, applied to it, gives it back: 640 x 427 is 3:2 (427 is 640 / 1.5 to
the nearest pixel). :func:`aspect_name` names any shape, as the sensor's gate in the viewport is labelled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class AspectPreset:
    name: str  # as written on the menu: "3:2"
    width: int  # the ratio's terms, in the preset's orientation
    height: int
    use: str  # one line for the tooltip

    @property
    def ratio(self) -> float:
        return self.width / self.height


#: The presets the studio offers, in menu order.
ASPECT_PRESETS = (
    AspectPreset("3:2", 3, 2, "35 mm film and most interchangeable-lens cameras"),
    AspectPreset("4:5", 4, 5, "portrait: 8 x 10 in prints, the tall social-media crop"),
    AspectPreset("1:1", 1, 1, "square: medium format 6 x 6"),
    AspectPreset("16:9", 16, 9, "widescreen video and displays"),
)

#: Further shapes :func:`aspect_name` recognises by name (ratios and their names, landscape and portrait).
_NAMED_RATIOS = (("3:2", 1.5), ("2:3", 2 / 3), ("4:3", 4 / 3), ("3:4", 0.75), ("4:5", 0.8), ("5:4", 1.25),
                 ("1:1", 1.0), ("16:9", 16 / 9), ("9:16", 9 / 16), ("2:1", 2.0), ("1.85:1", 1.85),
                 ("2.39:1", 2.39), ("65:24", 65 / 24))


def aspect_preset(name: str) -> AspectPreset:
    """The preset called ``name`` ("3:2"); a ValueError names the choices."""
    for preset in ASPECT_PRESETS:
        if preset.name == name:
            return preset
    raise ValueError(f"unknown aspect ratio {name!r} (choose from {', '.join(p.name for p in ASPECT_PRESETS)})")


def resolution_for_aspect(resolution: tuple[int, int], preset: AspectPreset) -> tuple[int, int]:
    """The resolution of ``preset``'s shape with the long edge of ``resolution`` (in pixels)."""
    long_edge = max(int(resolution[0]), int(resolution[1]))
    if long_edge < 1:
        raise ValueError(f"a resolution needs at least one pixel each way, not {resolution[0]} x {resolution[1]}")
    if preset.width >= preset.height:
        return long_edge, max(1, round(long_edge * preset.height / preset.width))
    return max(1, round(long_edge * preset.width / preset.height)), long_edge


def matching_preset(resolution: tuple[int, int]) -> AspectPreset | None:
    """The preset ``resolution`` already has (the preset gives it back unchanged), or None: a custom shape."""
    size = (int(resolution[0]), int(resolution[1]))
    return next((p for p in ASPECT_PRESETS if resolution_for_aspect(size, p) == size), None)


def aspect_name(width: int, height: int) -> str:
    """The shape of a ``width`` x ``height`` image as a photographer names it: "3:2", "16:9", "4:5" when it is one of
    the usual shapes to the nearest pixel, otherwise the smallest whole-number ratio if its terms are small
    ("7:5"), otherwise width over height to two decimals ("2.06:1")."""
    w, h = int(width), int(height)
    if w < 1 or h < 1:
        raise ValueError(f"an image needs at least one pixel each way, not {width} x {height}")
    # Rounding either side to the nearest pixel moves the ratio by at most half a pixel's worth.
    tolerance = 0.5 * (w / h) * (1 / w + 1 / h) + 1e-12
    for name, ratio in _NAMED_RATIOS:
        if abs(w / h - ratio) <= tolerance:
            return name
    g = math.gcd(w, h)
    if w // g <= 32 and h // g <= 32:
        return f"{w // g}:{h // g}"
    return f"{w / h:.2f}:1" if w >= h else f"1:{h / w:.2f}"
