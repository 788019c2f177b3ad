"""Focus peaking over the viewport's picture: the edges of what lies within the depth of field, in a vivid colour,
as a camera's peaking shows them (the math is :mod:`lenslab.optics.peaking`).

It is worked out again, at most four times a second, when the picture, the depth buffer or the camera changes;
:meth:`FocusPeakingLayer.refresh` does it at once.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from PySide6.QtCore import QObject
from PySide6.QtGui import QColor

from lenslab.gui.layer_support import MaskLayer, masks_to_qimage, qimage_to_array
from lenslab.optics.peaking import PEAKING_SENSITIVITY, peaking_mask

#: Peaking colours offered, in menu order (the usual choices of a camera's menu).
PEAKING_COLOURS = {"red": QColor(255, 38, 38), "yellow": QColor(255, 232, 0), "green": QColor(40, 255, 80),
                   "cyan": QColor(0, 230, 255), "white": QColor(255, 255, 255)}
DEFAULT_PEAKING_COLOUR = "yellow"  # red and green are the Cornell box's walls and the focus card of dof_chart
PEAKING_INTERVAL_MS = 250
HALO = QColor(0, 0, 0, 150)  # a dark rim around the marks, so that they read on light surfaces too


def grow(mask: np.ndarray) -> np.ndarray:
    """``mask`` and its 4-neighbours."""
    out = mask.copy()
    out[1:] |= mask[:-1]
    out[:-1] |= mask[1:]
    out[:, 1:] |= mask[:, :-1]
    out[:, :-1] |= mask[:, 1:]
    return out


class FocusPeakingLayer(MaskLayer):
    """``limits`` answers the near and far limits of sharpness, in metres from the lens along the view axis (the
    depth buffer's distances), and the circle of confusion in pixels of the viewport's picture (to keep the marks
    off what a blurred foreground covers; leave it out to mark without), or None when there are none to show."""

    def __init__(self, viewport, limits: Callable[[], tuple[float, ...] | None], parent: QObject | None = None):
        super().__init__(viewport, PEAKING_INTERVAL_MS, parent)
        self.limits = limits
        self.colour = DEFAULT_PEAKING_COLOUR
        self.sensitivity = "medium"
        self.mask: np.ndarray | None = None  # the marked pixels of the last picture worked out

    def forget(self) -> None:
        self.mask = None

    def set_colour(self, name: str) -> None:
        if name not in PEAKING_COLOURS:
            raise ValueError(f"unknown peaking colour {name!r} (choose from {', '.join(PEAKING_COLOURS)})")
        self.colour = name
        self._paint_mask()

    def set_sensitivity(self, name: str) -> None:
        if name not in PEAKING_SENSITIVITY:
            raise ValueError(f"unknown sensitivity {name!r} (choose from {', '.join(PEAKING_SENSITIVITY)})")
        self.sensitivity = name
        self.refresh()

    def refresh(self) -> None:
        if not self.visible:
            return
        v = self.viewport
        limits = self.limits()
        if v.qimage is None or v.gbuffer is None or limits is None or not v.worth_judging:
            self.mask = None
        else:
            near, far, *coc_px = limits
            self.mask = peaking_mask(qimage_to_array(v.qimage), v.gbuffer.depth, near, far,
                                     PEAKING_SENSITIVITY[self.sensitivity], coc_px[0] if coc_px else None)
        self._paint_mask()

    def _paint_mask(self) -> None:
        if self.mask is None:
            self._overlay = None
        else:
            self._overlay = masks_to_qimage(self.mask.shape, [(grow(self.mask), HALO),
                                                              (self.mask, PEAKING_COLOURS[self.colour])])
        self.viewport.update()

