"""Clipping warnings over the viewport's picture: clipped highlights (a channel at display code value 255) in red,
crushed shadows (black: every channel at 0) in blue, of the picture as displayed, the 8-bit code values the chosen
view transform gives (OpenColorIO's display, view and look after the display exposure and contrast: an Un-tone-mapped
view clips where an ACES view rolls the highlight off), :mod:`lenslab.optics.histogram` says which pixels, inside the
export frame (the pixels the histogram counts).
Worked out again at most four times a second."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QObject
from PySide6.QtGui import QColor

from lenslab.gui.layer_support import MaskLayer, masks_to_qimage, only_in_gate, qimage_to_array
from lenslab.optics.histogram import clipping_masks

HIGHLIGHT_WARNING = QColor(255, 40, 40, 235)
SHADOW_WARNING = QColor(40, 110, 255, 235)
CLIPPING_INTERVAL_MS = 250


class ClippingLayer(MaskLayer):
    def __init__(self, viewport, parent: QObject | None = None):
        super().__init__(viewport, CLIPPING_INTERVAL_MS, parent)
        self.highlights: np.ndarray | None = None  # the masks of the last picture worked out
        self.shadows: np.ndarray | None = None

    def forget(self) -> None:
        self.highlights = self.shadows = None

    def refresh(self) -> None:
        if not self.visible:
            return
        image = self.viewport.qimage
        if image is None or not self.viewport.worth_judging:
            self.highlights = self.shadows = self._overlay = None
        else:
            self.highlights, self.shadows = (only_in_gate(m, self.viewport)
                                             for m in clipping_masks(qimage_to_array(image)))
            self._overlay = masks_to_qimage(self.highlights.shape, [(self.shadows, SHADOW_WARNING),
                                                                    (self.highlights, HIGHLIGHT_WARNING)])
        self.viewport.update()

