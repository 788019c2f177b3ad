"""The camera panel's lens section: Free (no lens limits), one of the thin-lens presets, or a real lens traced
through its glass; what the mounted lens allows, and for a real lens a side view of its glass (gui/lens_diagram.py)
with a one-line readout of what the glass does."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtWidgets import QCheckBox, QGridLayout, QPushButton

from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.commands import LensCommand
from lenslab.gui.lens_diagram import LensDiagram, LensView, lens_view
from lenslab.gui.widgets import hint
from lenslab.optics import LensPreset, format_f_number, format_focal_length
from lenslab.optics.real_lenses import system_for

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel
    from lenslab.scene.camera import ThinLensCamera

#: Columns of lens buttons.
COLUMNS = 3


def lens_short_name(lens: LensPreset) -> str:
    """A lens button's label: "50 f/1.2", "24-70 f/2.8"; a real lens by its glass's focal length in whole
    millimetres, as its name rounds it (50.36 mm for the "50 mm" double-Gauss: a button has no room for decimals)."""
    if lens.is_zoom:
        focal = f"{lens.focal_range_mm[0]:g}-{lens.focal_range_mm[1]:g}"
    elif lens.is_real:
        focal = f"{round(lens.focal_length_mm):d}"
    else:
        focal = f"{lens.focal_length_mm:g}"
    return f"{focal} {format_f_number(lens.widest_f_number)}"


def glass_summary(lens: LensPreset) -> str:
    """What a real lens is made of, in a line: "11 surfaces, 6 elements"."""
    surfaces = lens.prescription.surfaces
    # An element is the glass between two surfaces (cemented ones share a surface, and count apart).
    elements = sum(1 for surface in surfaces[:-1] if surface.ior > 1.0)
    return f"{len(surfaces)} surfaces, {elements} elements"


def lens_tooltip(lens: LensPreset, shortcut: str) -> str:
    """A lens button's tooltip; a real lens's says that it is traced through its glass, what the glass gives (its
    focal length and widest aperture: the paraxial numbers, which the maker's marking rounds) and where the
    numbers come from."""
    text = f"<b>{lens.name}</b>{shortcut}"
    if not lens.is_real:
        return f"{text}<br>{lens.description}"
    system = system_for(lens.prescription)
    text += (f"<br>Traced through its glass: {glass_summary(lens)}."
             f"<br>From the glass: focal length {system.efl:.2f} mm, widest f/{system.widest_f_number:.2f}"
             f" (set as {format_f_number(lens.widest_f_number)}).")
    if lens.prescription.description:
        text += f"<br>{lens.prescription.description}"
    if lens.prescription.source:
        text += f"<br><i>Source: {lens.prescription.source}</i>"
    return text


def diagram_readout(view: LensView) -> str:
    """The line under the side view: focal length and widest aperture of the glass, how far the lens has moved out
    to focus, and the diagonal field of view its chief rays trace (or the image circle, where the frame's corner
    lies outside it)."""
    system = view.system
    parts = [f"EFL {system.efl:.1f} mm", f"f/{system.widest_f_number:.2f}", f"ext. {view.shift:+.2f} mm"]
    if view.corner_half_angle_deg is not None:
        parts.append(f"{2.0 * view.corner_half_angle_deg:.1f}° diagonal")
    else:  # the frame's corners are dark: how far the image circle reaches, and the angle it covers
        parts.append(f"{2.0 * view.covered_half_angle_deg:.0f}° in Ø{2.0 * view.covered_radius_mm:.0f} mm")
    return " · ".join(parts)


class LensSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "lens", "Lens")
        self.lenses = panel.lenses
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
            button.setProperty("glass", lens.is_real)
            shortcut = f" (Alt+{i + 1})" if i < 9 else ""
            button.setToolTip(lens_tooltip(lens, shortcut))
            button.clicked.connect(lambda _checked=False, lens=lens: self.choose_lens(lens))
            self.lens_buttons.append(button)
        # The thin-lens presets first, then, under a heading of their own, the lenses traced through their glass:
        # they behave differently (the glass sets the focal length, and the bokeh controls step aside).
        thin = [b for b, lens in zip(self.lens_buttons, [None, *self.lenses]) if lens is None or not lens.is_real]
        real = [b for b, lens in zip(self.lens_buttons[1:], self.lenses) if lens.is_real]
        self.add(self._grid(thin))
        self.glass_heading = hint("Real lenses, traced through their glass:")
        self.glass_heading.setVisible(bool(real))
        self.add(self.glass_heading)
        if real:
            self.add(self._grid(real))
        self.lens_info = hint("")
        self.add(self.lens_info)
        self.lens_diagram = LensDiagram()
        self.lens_diagram.setToolTip("The lens in profile: its glass, the stop at its opening and the sensor "
                                     "(right). Green: rays from the point in focus on the axis; amber: from the "
                                     "frame's corner. A dot marks where the glass stops a ray.")
        self.add(self.lens_diagram)
        self.lens_diagram_info = hint("")
        self.lens_diagram_info.setToolTip("From the glass: its effective focal length and widest aperture "
                                          "(paraxial), how far the lens has moved forward to focus, and the "
                                          "diagonal field of view its chief ray at the frame's corner traces (or, "
                                          "where the corners fall outside the lens's image circle, that circle)")
        self.add(self.lens_diagram_info)
        self.dispersion = QCheckBox("Colour fringes (dispersion)")
        self.dispersion.setToolTip("The glass's dispersion: each sample traced at one colour's wavelength, so its "
                                   "colour fringes show (and colour noise, until the picture converges). Off: "
                                   "every colour at one wavelength, an achromatic preview without that noise.")
        self.dispersion.toggled.connect(self._dispersion_toggled)
        self.add(self.dispersion)

    def _dispersion_toggled(self, on: bool) -> None:
        if bool(on) != self.doc.scene.camera.dispersion:
            self.doc.set_camera("Colour fringes" if on else "Achromatic preview", False, dispersion=bool(on))

    @staticmethod
    def _grid(buttons: list[QPushButton]) -> QGridLayout:
        grid = QGridLayout()
        grid.setSpacing(4)
        for i, button in enumerate(buttons):
            grid.addWidget(button, i // COLUMNS, i % COLUMNS)
        return grid

    def choose_lens(self, lens: LensPreset | None) -> None:
        if lens == self.doc.lens and (lens is not None or not self.doc.scene.camera.real_lens):
            self.panel.refresh()
            return
        self.doc.push(LensCommand(self.doc, lens))
        if lens is not None:
            cam = self.doc.scene.camera
            self.panel.status_message.emit(
                f"{lens.name}: {format_focal_length(cam.focal_length_mm)}, {format_f_number(cam.f_number)}")

    def refresh(self, lens: LensPreset | None, cam: ThinLensCamera | None = None) -> None:
        for i, button in enumerate(self.lens_buttons):
            button.setChecked((i == 0 and lens is None) or (i > 0 and self.lenses[i - 1] == lens))
        if lens is None:
            self.lens_info.setText("Free: any focal length and aperture.")
        else:
            glass = f" · traced through its glass ({glass_summary(lens)})" if lens.is_real else ""
            self.lens_info.setText(f"{lens.name}{glass} · {format_f_number(lens.widest_f_number)}–"
                                   f"{format_f_number(lens.narrowest_f_number)}"
                                   + (f" · {lens.aperture_blades} blades" if lens.aperture_blades else ""))
        self._show_glass(cam)

    def _show_glass(self, cam: ThinLensCamera | None) -> None:
        """The side view and its readout for the camera's real lens at its focus and f-number; hidden for the thin
        lens, and for a lens or focus the camera cannot have (the render says why)."""
        view = None
        if cam is not None and cam.real_lens:
            try:
                system = cam.lens_system()
                focus_mm = cam.real_focus_from_sensor_mm()
                film = cam.imaged_area_mm()
                # The renderer's own setting (the focus found by tracing), from the same cache as its frame's.
                setting = cam.real_lens_setting(film, self.doc.scene.base_dir())
                view = lens_view(system, round(setting.shift, 6), round(setting.stop_radius, 6), focus_mm,
                                 (float(film[0]), float(film[1])))
            except ValueError:
                view = None
        self.lens_diagram.show_view(view)
        self.lens_diagram.setVisible(view is not None)
        self.lens_diagram_info.setVisible(view is not None)
        self.lens_diagram_info.setText(diagram_readout(view) if view is not None else "")
        # The dispersion switch, for glass that disperses (a lens without Abbe numbers is achromatic anyway).
        self.dispersion.setVisible(view is not None and view.system.dispersive)
        if cam is not None:
            self.dispersion.blockSignals(True)
            self.dispersion.setChecked(cam.dispersion)
            self.dispersion.blockSignals(False)
