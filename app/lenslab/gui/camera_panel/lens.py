"""The camera panel's lens section: Free (no lens limits) or one of the lens presets, and what the mounted lens
allows."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtWidgets import QGridLayout, QPushButton

from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.commands import LensCommand
from lenslab.gui.widgets import hint
from lenslab.optics import LensPreset, format_f_number, format_focal_length

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel


def lens_short_name(lens: LensPreset) -> str:
    focal = (f"{lens.focal_range_mm[0]:g}-{lens.focal_range_mm[1]:g}" if lens.is_zoom else f"{lens.focal_length_mm:g}")
    return f"{focal} {format_f_number(lens.widest_f_number)}"


class LensSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "lens", "Lens")
        self.lenses = panel.lenses
        grid = QGridLayout()
        grid.setSpacing(4)
        self.lens_buttons: list[QPushButton] = []
        free = QPushButton("Free")
        free.setObjectName("lensButton")
        free.setCheckable(True)
        free.setToolTip("No lens limits: any focal length and aperture (Alt+0)")
        free.clicked.connect(lambda: self.choose_lens(None))
        self.lens_buttons.append(free)
        for i, lens in enumerate(self.lenses):
            button = QPushButton(lens_short_name(lens))
            button.setObjectName("lensButton")
            button.setCheckable(True)
            shortcut = f" (Alt+{i + 1})" if i < 9 else ""
            button.setToolTip(f"<b>{lens.name}</b>{shortcut}<br>{lens.description}")
            button.clicked.connect(lambda _checked=False, lens=lens: self.choose_lens(lens))
            self.lens_buttons.append(button)
        for i, button in enumerate(self.lens_buttons):
            grid.addWidget(button, i // 3, i % 3)
        self.add(grid)
        self.lens_info = hint("")
        self.add(self.lens_info)

    def choose_lens(self, lens: LensPreset | None) -> None:
        if lens == self.doc.lens:
            self.panel.refresh()
            return
        self.doc.push(LensCommand(self.doc, lens))
        if lens is not None:
            cam = self.doc.scene.camera
            self.panel.status_message.emit(
                f"{lens.name}: {format_focal_length(cam.focal_length_mm)}, {format_f_number(cam.f_number)}")

    def refresh(self, lens: LensPreset | None) -> None:
        for i, button in enumerate(self.lens_buttons):
            button.setChecked((i == 0 and lens is None) or (i > 0 and self.lenses[i - 1] == lens))
        if lens is None:
            self.lens_info.setText("Free: any focal length and aperture.")
        else:
            self.lens_info.setText(f"{lens.name} · {format_f_number(lens.widest_f_number)}–"
                                   f"{format_f_number(lens.narrowest_f_number)}"
                                   + (f" · {lens.aperture_blades} blades" if lens.aperture_blades else ""))
