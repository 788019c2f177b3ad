"""The camera panel: the lens, aperture, focal length, focus, sensor, iris and exposure in photographers' terms,
with a depth-of-field readout and diagram. Everything here edits ``scene.camera`` through undo commands (a slider drag
is one undo step) and follows the document when something else changes it (undo, click-to-focus).

Each section of the panel is a widget of its own, in a module of its own, with its widgets, its edits and a
``refresh`` that shows the camera in them; :class:`CameraPanel` assembles them and refreshes them together."""

from __future__ import annotations

from PySide6.QtCore import Signal
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QVBoxLayout, QWidget

from lenslab.gui.camera_panel.aperture import (
    FULL_STOPS,
    STEP_WORDS,
    STOP_SCALE_NAMES,
    ApertureSection,
    IrisGlyph,
    StopSlider,
)
from lenslab.gui.camera_panel.bokeh import BokehSection
from lenslab.gui.camera_panel.depth_of_field import DepthOfFieldSection, DofDiagram
from lenslab.gui.camera_panel.exposure import (ISO_SPEEDS, SHUTTER_SCALES, SHUTTER_SPEEDS, ExposureSection,
                                               dial_mark, metered_shutter, step_shutter)
from lenslab.gui.camera_panel.focal_length import COMMON_FOCAL_LENGTHS, FOCAL_RANGE, FocalLengthSection
from lenslab.gui.camera_panel.focus import FOCUS_RANGE, FocusSection
from lenslab.gui.camera_panel.lens import LensSection, lens_short_name
from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.camera_panel.sensor import SENSOR_FIT_NAMES, AutoNumberEdit, SensorSection
from lenslab.gui.document import listen
from lenslab.gui.wheel_guard import guard_wheels
from lenslab.optics import LensPreset, PresetError, SensorPreset, load_lens_presets, load_sensor_presets
from lenslab.optics.stops import DEFAULT_STOP_SCALE, STOP_SCALES

__all__ = [
    "CameraPanel", "CameraSection", "LensSection", "ApertureSection", "BokehSection", "FocalLengthSection",
    "FocusSection", "DepthOfFieldSection", "ExposureSection", "SensorSection",
    # What this module held before its sections had modules of their own.
    "AutoNumberEdit", "IrisGlyph", "DofDiagram", "StopSlider", "lens_short_name", "step_shutter",
    "metered_shutter", "dial_mark", "FULL_STOPS",
    "STOP_SCALE_NAMES", "STEP_WORDS", "SENSOR_FIT_NAMES", "ISO_SPEEDS", "SHUTTER_SCALES", "SHUTTER_SPEEDS",
    "COMMON_FOCAL_LENGTHS", "FOCAL_RANGE", "FOCUS_RANGE",
]


class _SectionWidget:
    """A widget of one of the sections, reachable as the panel's own attribute of the same name, where the main
    window and the tests find it (``panel.aperture_combo`` is ``panel.sections["aperture"].aperture_combo``)."""

    def __init__(self, section: str):
        self.section = section

    def __set_name__(self, owner, name: str) -> None:
        self.name = name

    def __get__(self, panel, owner=None):
        if panel is None:
            return self
        return getattr(panel.sections[self.section], self.name)


class CameraPanel(QWidget):
    status_message = Signal(str)
    stop_scale_changed = Signal(str)  # "full", "half" or "third": what one step of [ and ] now is

    lens_buttons = _SectionWidget("lens")
    lens_info = _SectionWidget("lens")
    lens_diagram = _SectionWidget("lens")
    lens_diagram_info = _SectionWidget("lens")
    dispersion = _SectionWidget("lens")
    iris = _SectionWidget("aperture")
    open_up = _SectionWidget("aperture")
    aperture_combo = _SectionWidget("aperture")
    stop_down = _SectionWidget("aperture")
    stop_slider = _SectionWidget("aperture")
    stop_scale_combo = _SectionWidget("aperture")
    aperture_info = _SectionWidget("aperture")
    blades = _SectionWidget("bokeh")
    rotation = _SectionWidget("bokeh")
    curvature = _SectionWidget("bokeh")
    squeeze = _SectionWidget("bokeh")
    barrel = _SectionWidget("bokeh")
    aperture_image_button = _SectionWidget("bokeh")
    aperture_image_clear = _SectionWidget("bokeh")
    aperture_image_label = _SectionWidget("bokeh")
    focal = _SectionWidget("focal")
    focal_slider = _SectionWidget("focal")
    focal_buttons = _SectionWidget("focal")
    fov_info = _SectionWidget("focal")
    focus_slider = _SectionWidget("focus")
    focus = _SectionWidget("focus")
    focus_from = _SectionWidget("focus")
    breathing = _SectionWidget("focus")
    focus_info = _SectionWidget("focus")
    focus_selection_button = _SectionWidget("focus")
    dof_near = _SectionWidget("dof")
    dof_far = _SectionWidget("dof")
    dof_total = _SectionWidget("dof")
    dof_hyper = _SectionWidget("dof")
    dof_diagram = _SectionWidget("dof")
    dof_info = _SectionWidget("dof")
    exposure_mode = _SectionWidget("exposure")
    iso = _SectionWidget("exposure")
    shutter = _SectionWidget("exposure")
    shutter_shorter = _SectionWidget("exposure")
    shutter_longer = _SectionWidget("exposure")
    exposure_info = _SectionWidget("exposure")
    metering = _SectionWidget("exposure")
    meter_label = _SectionWidget("exposure")
    meter_apply = _SectionWidget("exposure")
    sensor_combo = _SectionWidget("sensor")
    sensor_w = _SectionWidget("sensor")
    sensor_h = _SectionWidget("sensor")
    sensor_fit = _SectionWidget("sensor")
    coc = _SectionWidget("sensor")
    sensor_info = _SectionWidget("sensor")

    def __init__(self, doc, focus_action: QAction | None = None, parent=None, settings=None):
        super().__init__(parent)
        self.doc = doc
        self.settings = settings  # QSettings: the stop scale chosen last time
        saved = settings.value("camera/stop_scale", DEFAULT_STOP_SCALE) if settings is not None else DEFAULT_STOP_SCALE
        self.scale_name = saved if saved in STOP_SCALES else DEFAULT_STOP_SCALE
        try:
            # The thin-lens presets first, then the real lenses (each group by focal length), as the lens section
            # shows them: Alt+1 to Alt+9 keep mounting the thin presets they always did.
            self.lenses = sorted(load_lens_presets(), key=lambda lens: lens.is_real)
        except PresetError as exc:
            self.lenses = []
            self.status_message.emit(f"Lens presets not loaded: {exc}")
        try:
            self.sensors: list[SensorPreset] = load_sensor_presets()
        except PresetError:
            self.sensors = [SensorPreset("Full frame", 36.0, 24.0)]
        layout = QVBoxLayout(self)
        layout.setContentsMargins(10, 6, 10, 6)
        layout.setSpacing(2)
        self.sections: dict[str, CameraSection] = {}
        self.lens_section = self._add(LensSection(self))
        self.aperture_section = self._add(ApertureSection(self))
        self.bokeh_section = self._add(BokehSection(self))
        self.focal_section = self._add(FocalLengthSection(self))
        self.focus_section = self._add(FocusSection(self, focus_action))
        self.dof_section = self._add(DepthOfFieldSection(self))
        self.exposure_section = self._add(ExposureSection(self))
        self.sensor_section = self._add(SensorSection(self))
        layout.addStretch(1)
        listen(doc.model.events.changed, self, self._on_change)
        doc.lens_changed.connect(self.refresh)
        self.refresh()
        guard_wheels(self)  # the wheel scrolls the panel; it turns only the control that has the focus

    def _add(self, section: CameraSection):
        self.sections[section.key] = section
        self.layout().addWidget(section)
        return section

    # -- the sections' edits, where the main window and the tests make them ---------------------------------------
    def choose_lens(self, lens: LensPreset | None) -> None:
        self.lens_section.choose_lens(lens)

    def set_f_number(self, n: float, merge: bool = False) -> None:
        self.aperture_section.set_f_number(n, merge)

    def step_aperture(self, steps: int) -> None:
        self.aperture_section.step_aperture(steps)

    def set_aperture_image(self, path: str) -> None:
        self.bokeh_section.set_aperture_image(path)

    def set_focal_length(self, mm: float, merge: bool) -> None:
        self.focal_section.set_focal_length(mm, merge)

    def focus_limits(self) -> tuple[float, float]:
        return self.focus_section.focus_limits()

    def set_focus(self, metres: float, merge: bool = False, text: str | None = None) -> bool:
        return self.focus_section.set_focus(metres, merge, text)

    def step_shutter(self, steps: int) -> None:
        self.exposure_section.step_shutter(steps)

    def show_frame(self, frame) -> None:
        """A new picture from the render: the meter's reading and the auto exposure's shutter follow it."""
        self.exposure_section.show_frame(frame)

    # -- the stop scale, which the aperture and the shutter step on -----------------------------------------------
    def stop_scale(self) -> tuple[float, ...]:
        """The exact f-numbers one step moves between: the chosen scale, within the mounted lens."""
        lens = self.doc.lens
        return lens.available_stops(self.scale_name) if lens is not None else STOP_SCALES[self.scale_name].exact

    def choose_stop_scale(self, name: str) -> None:
        """Make one step ``name``'s ("full", "half" or "third"), and remember it for next time."""
        self.scale_name = name
        if self.settings is not None:
            self.settings.setValue("camera/stop_scale", self.scale_name)
        self.refresh()
        self.stop_scale_changed.emit(self.scale_name)

    # -- following the document ---------------------------------------------------------------------------------
    def _on_change(self, change) -> None:
        if change.kind in ("camera", "scene"):
            self.refresh()

    def refresh(self) -> None:
        cam = self.doc.scene.camera
        lens = self.doc.lens
        light = self.light_fraction()
        self.lens_section.refresh(lens, cam)
        self.aperture_section.refresh(cam, self.stop_scale(), self.scale_name, light)
        self.bokeh_section.refresh(cam)
        self.focal_section.refresh(cam, lens)
        self.focus_section.refresh(cam, lens)
        self.sensor_section.refresh(cam)
        self.exposure_section.refresh(cam, self.scale_name)
        self.dof_section.refresh(cam, light)

    def light_fraction(self) -> float:
        """The light the camera's stop passes, as a fraction of the round f/N stop's (an aperture image's mask)."""
        try:
            return self.doc.scene.camera.aperture(self.doc.scene.base_dir()).light_fraction
        except ValueError:  # an aperture image gone missing since: the render says so; the readout goes on
            return 1.0
