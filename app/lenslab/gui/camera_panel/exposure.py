"""The camera panel's exposure section: compensated (the brightness holds at every aperture), physical (the ISO and
the shutter speed on the dial of the chosen stop scale, and the exposure value they make) or auto (aperture
priority: the meter chooses the shutter); and the light meter.

The meter reads the render's scene-linear luminance inside the frame (the render loop meters each linear image it
reads, a few times a second: ``Frame.meter``), centre-weighted or at a spot (the frame's centre, or the point last
clicked with the focus tool), and suggests the shutter at the camera's f-number and ISO, on a third stop;
**Apply** sets it, as one undo step (a camera in another mode turns physical: the exposure is held)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from PySide6.QtWidgets import QComboBox, QGridLayout, QHBoxLayout, QLabel, QPushButton, QToolButton

from lenslab.gui.camera_panel.aperture import STEP_WORDS
from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.widgets import hint
from lenslab.optics.exposure import (SHUTTER_RANGE_S, ev100, ev100_to_luminance, format_shutter, metered_ev100,
                                     nearest_third_stop_shutter, parse_shutter, shutter_for)
from lenslab.optics.stops import DEFAULT_STOP_SCALE, format_f_number
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.fields import control_range

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel

ISO_SPEEDS = (50, 64, 80, 100, 125, 160, 200, 250, 320, 400, 500, 640, 800, 1000, 1250, 1600, 2000, 2500, 3200, 4000,
              5000, 6400, 12800, 25600, 51200, 102400)
#: The shutter speeds a camera's dial shows, seconds, longest first, on each stop scale (30 s to 1/8000 s).
SHUTTER_SCALES = {
    "full": (30, 15, 8, 4, 2, 1, 1 / 2, 1 / 4, 1 / 8, 1 / 15, 1 / 30, 1 / 60, 1 / 125, 1 / 250, 1 / 500, 1 / 1000,
             1 / 2000, 1 / 4000, 1 / 8000),
    "half": (30, 20, 15, 10, 8, 6, 4, 3, 2, 1.5, 1, 0.7, 1 / 2, 1 / 3, 1 / 4, 1 / 6, 1 / 8, 1 / 10, 1 / 15, 1 / 20,
             1 / 30, 1 / 45, 1 / 60, 1 / 90, 1 / 125, 1 / 180, 1 / 250, 1 / 350, 1 / 500, 1 / 750, 1 / 1000, 1 / 1500,
             1 / 2000, 1 / 3000, 1 / 4000, 1 / 6000, 1 / 8000),
    "third": (30, 25, 20, 15, 13, 10, 8, 6, 5, 4, 3.2, 2.5, 2, 1.6, 1.3, 1, 0.8, 0.6, 1 / 2, 0.4, 1 / 3, 1 / 4, 1 / 5,
              1 / 6, 1 / 8, 1 / 10, 1 / 13, 1 / 15, 1 / 20, 1 / 25, 1 / 30, 1 / 40, 1 / 50, 1 / 60, 1 / 80, 1 / 100,
              1 / 125, 1 / 160, 1 / 200, 1 / 250, 1 / 320, 1 / 400, 1 / 500, 1 / 640, 1 / 800, 1 / 1000, 1 / 1250,
              1 / 1600, 1 / 2000, 1 / 2500, 1 / 3200, 1 / 4000, 1 / 5000, 1 / 6400, 1 / 8000),
}
SHUTTER_SPEEDS = SHUTTER_SCALES["full"]


def metered_shutter(reading_cd_m2: float, f_number: float, iso: float,
                    light_fraction: float = 1.0) -> tuple[float, float]:
    """(EV100, shutter seconds) a meter reading of ``reading_cd_m2`` suggests at ``f_number`` and ``iso``: the EV100
    of the reading (the light the aperture passes counted, as the auto exposure counts it) and the shutter time
    that gives it on the nearest third stop (``nearest_third_stop_shutter``), as the third-stop dial marks it
    (2^-7 s is the mark 1/125: a camera's speeds are its marks), within the shutter's range."""
    ev = metered_ev100(reading_cd_m2, light_fraction)
    seconds = nearest_third_stop_shutter(shutter_for(ev, f_number, iso))
    return ev, dial_mark(min(max(seconds, SHUTTER_RANGE_S[0]), SHUTTER_RANGE_S[1]))


def dial_mark(seconds: float) -> float:
    """The third-stop dial's mark for a third-stop time (1/125 for 2^-7 s, 1/8 for 2^-3): the mark within a sixth of
    a stop of it; the time itself off the dial's ends (beyond 30 s or 1/8000 s)."""
    mark = min(SHUTTER_SCALES["third"], key=lambda t: abs(math.log2(t / seconds)))
    return float(mark) if abs(math.log2(mark / seconds)) < 1 / 6 else float(seconds)


def step_shutter(seconds: float, steps: int, scale: str = DEFAULT_STOP_SCALE) -> float:
    """Move ``steps`` marks of the shutter dial of ``scale`` from ``seconds`` (positive: a longer time, more
    light). From a time between marks the first step lands on the next mark that way; the dial's ends hold."""
    marks = SHUTTER_SCALES[scale][::-1]  # shortest first: a positive step is a longer time
    same = [i for i, mark in enumerate(marks) if math.isclose(mark, seconds, rel_tol=1e-3)]
    if same:
        i = same[0] + steps
    elif steps > 0:
        longer = [i for i, mark in enumerate(marks) if mark > seconds]
        if not longer:
            return float(seconds)
        i = longer[0] + steps - 1
    elif steps < 0:
        shorter = [i for i, mark in enumerate(marks) if mark < seconds]
        if not shorter:
            return float(seconds)
        i = shorter[-1] + steps + 1
    else:
        return float(min(marks, key=lambda mark: abs(math.log(mark / seconds))))
    return float(marks[min(max(i, 0), len(marks) - 1)])


class ExposureSection(CameraSection):
    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "exposure", "Exposure")
        grid = QGridLayout()
        self.exposure_mode = QComboBox()
        self.exposure_mode.addItem("Compensated", "compensated")
        self.exposure_mode.addItem("Physical (ISO, shutter)", "physical")
        self.exposure_mode.addItem("Auto (aperture priority)", "auto")
        self.exposure_mode.setToolTip("Compensated: the brightness stays the same at every aperture, to judge "
                                      "depth of field. Physical: each stop of aperture, shutter or ISO is a stop "
                                      "of light (radiance in cd/m²). Auto: the meter chooses the shutter at the "
                                      "f-number and ISO you set")
        self.exposure_mode.currentIndexChanged.connect(
            lambda i: self._updating or self.doc.set_camera("Exposure mode", False,
                                                            exposure_mode=self.exposure_mode.itemData(i)))
        self.iso = QComboBox()
        self.iso.setEditable(True)
        self.iso.setInsertPolicy(QComboBox.NoInsert)
        for speed in ISO_SPEEDS:
            self.iso.addItem(f"{speed}", float(speed))
        self.iso.setToolTip("Sensor speed: any value")
        self.iso.lineEdit().editingFinished.connect(self._iso_typed)
        self.iso.activated.connect(lambda i: self._set_iso(self.iso.itemData(i)))
        self.shutter = QComboBox()
        self.shutter.setObjectName("shutter")
        self.shutter.setEditable(True)
        self.shutter.setInsertPolicy(QComboBox.NoInsert)
        self.shutter.setToolTip("Exposure time: choose a speed of the dial or type any (1/125, 0.5, 2 s)")
        self.shutter.lineEdit().editingFinished.connect(self._shutter_typed)
        self.shutter.activated.connect(lambda i: self._set_shutter(self.shutter.itemData(i)))
        self.shutter_shorter = QToolButton()
        self.shutter_shorter.setText("−")
        self.shutter_shorter.clicked.connect(lambda: self.step_shutter(-1))
        self.shutter_longer = QToolButton()
        self.shutter_longer.setText("+")
        self.shutter_longer.clicked.connect(lambda: self.step_shutter(+1))
        shutter_row = QHBoxLayout()
        shutter_row.setSpacing(2)
        shutter_row.addWidget(self.shutter_shorter)
        shutter_row.addWidget(self.shutter, 1)
        shutter_row.addWidget(self.shutter_longer)
        grid.addWidget(QLabel("Mode"), 0, 0)
        grid.addWidget(self.exposure_mode, 0, 1)
        grid.addWidget(QLabel("ISO"), 1, 0)
        grid.addWidget(self.iso, 1, 1)
        grid.addWidget(QLabel("Shutter"), 2, 0)
        grid.addLayout(shutter_row, 2, 1)
        # The meter: how it reads, what it read, and the button that takes its suggestion.
        self.metering = QComboBox()
        self.metering.setObjectName("metering")
        self.metering.addItem("Average (centre-weighted)", "average")
        self.metering.addItem("Spot", "spot")
        self.metering.setToolTip("How the meter reads the frame: the mean weighted towards its centre, or a spot of "
                                 "5 % of its diagonal at the centre (or where the focus tool last clicked)")
        self.metering.currentIndexChanged.connect(
            lambda i: self._updating or self.doc.set_camera("Metering", False, metering=self.metering.itemData(i)))
        grid.addWidget(QLabel("Meter"), 3, 0)
        grid.addWidget(self.metering, 3, 1)
        grid.setColumnStretch(1, 1)
        self.add(grid)
        self.meter_label = hint("Meter: waiting for the picture")
        self.meter_label.setObjectName("meterReading")
        self.meter_apply = QPushButton("Apply")
        self.meter_apply.setObjectName("meterApply")
        self.meter_apply.setToolTip("Set the shutter to the meter's suggestion (one undo step); a compensated or auto "
                                    "camera turns physical at that exposure")
        self.meter_apply.setEnabled(False)
        self.meter_apply.clicked.connect(self.apply_meter)
        meter_row = QHBoxLayout()
        meter_row.setSpacing(6)
        meter_row.addWidget(self.meter_label, 1)
        meter_row.addWidget(self.meter_apply)
        self.add(meter_row)
        self.exposure_info = hint("")
        self.add(self.exposure_info)
        self.reading = None  # the meter's latest reading (render_loop.MeterReading), from the frames
        self.auto_exposure = None  # the auto exposure of the latest picture (lenslab.optics.exposure.Exposure)

    # -- edits ----------------------------------------------------------------------------------------------------
    def _set_iso(self, value) -> None:
        low, high = control_range(ThinLensCamera, "iso")
        if value is None or not low <= float(value) <= high:
            self.panel.status_message.emit(f"ISO must lie between {low:g} and {high:g}")
            self.panel.refresh()
            return
        self.doc.set_camera(f"ISO {float(value):g}", False, iso=float(value))

    def _iso_typed(self) -> None:
        if self._updating:
            return
        text = self.iso.lineEdit().text().strip().lower().removeprefix("iso").strip()
        try:
            value = float(text)
        except ValueError:
            self.panel.status_message.emit(f"not an ISO speed: '{text}'")
            self.panel.refresh()
            return
        if not math.isclose(value, self.doc.scene.camera.iso):
            self._set_iso(value)

    def _set_shutter(self, seconds, merge: bool = False) -> None:
        if seconds is not None:
            self.doc.set_camera(f"Shutter {format_shutter(seconds)}", merge, shutter_s=float(seconds))

    def step_shutter(self, steps: int) -> None:
        """``steps`` marks of the shutter dial on the chosen stop scale (positive: longer, more light)."""
        current = self.doc.scene.camera.shutter_s
        seconds = step_shutter(current, steps, self.panel.scale_name)
        if not math.isclose(seconds, current, rel_tol=1e-9):
            self._set_shutter(seconds, merge=True)
        self.panel.refresh()

    def _shutter_typed(self) -> None:
        if self._updating:
            return
        try:
            seconds = parse_shutter(self.shutter.lineEdit().text())
        except ValueError as exc:
            self.panel.status_message.emit(str(exc))
            self.panel.refresh()
            return
        if not math.isclose(seconds, self.doc.scene.camera.shutter_s, rel_tol=1e-6):
            self._set_shutter(seconds)

    # -- the meter --------------------------------------------------------------------------------------------------
    def suggestion(self) -> tuple[float, float] | None:
        """(EV100, shutter seconds) the meter's latest reading suggests at the camera's f-number and ISO; None
        before a reading, or when it read nothing (a black frame)."""
        reading = self.reading
        if reading is None or not reading.luminance > 0:
            return None
        cam = self.doc.scene.camera
        return metered_shutter(reading.luminance, cam.f_number, cam.iso, self.panel.light_fraction())

    def apply_meter(self) -> None:
        """Set the shutter the meter suggests, as one undo step (a camera in another mode turns physical)."""
        suggested = self.suggestion()
        if suggested is None:
            return
        _ev, seconds = suggested
        cam = self.doc.scene.camera
        changes = {"shutter_s": seconds}
        if cam.exposure_mode != "physical":
            changes["exposure_mode"] = "physical"
        if math.isclose(seconds, cam.shutter_s, rel_tol=1e-9) and len(changes) == 1:
            self.panel.status_message.emit(f"The shutter is already the meter's {format_shutter(seconds)}")
            return
        self.doc.set_camera(f"Shutter {format_shutter(seconds)} (meter)", False, **changes)

    def show_frame(self, frame) -> None:
        """A new picture from the render: the meter's reading, and in the auto mode the shutter it chose."""
        self.reading = getattr(frame, "meter", None)
        exposure = getattr(frame, "exposure", None)
        camera = getattr(frame, "camera", None)
        self.auto_exposure = exposure if camera is not None and camera.exposure_mode == "auto" else None
        self._show_meter()
        cam = self.doc.scene.camera
        if cam.exposure_mode == "auto":  # the shutter alone: a refresh would overwrite an ISO being typed
            with self._showing_camera():
                self._show_shutter(cam, SHUTTER_SCALES[self.panel.scale_name])

    def _show_meter(self) -> None:
        reading = self.reading
        cam = self.doc.scene.camera
        suggested = self.suggestion()
        where = "spot" if cam.metering == "spot" else "average"
        if reading is None:
            text = "Meter: waiting for the picture"
        elif suggested is None:
            text = "Meter: nothing to read, the frame is black"
        else:
            ev, seconds = suggested
            text = (f"Meter: EV {ev:.1f} → {format_shutter(seconds)} at {format_f_number(cam.f_number)}"
                    f", ISO {cam.iso:g}")
            self.meter_label.setToolTip(f"The render's scene-linear luminance inside the frame reads "
                                        f"{reading.luminance:.4g} cd/m² ({where}"
                                        + (f" at {reading.spot[0]:.0%}, {reading.spot[1]:.0%} of the frame"
                                           if where == "spot" else ", weighted towards the centre")
                                        + "); the shutter on the nearest third stop")
        self.meter_label.setText(text)
        self.meter_apply.setEnabled(suggested is not None)

    # -- following the document ---------------------------------------------------------------------------------
    def refresh(self, cam: ThinLensCamera, scale_name: str) -> None:
        """Show ``cam``'s exposure, the shutter on the dial of the stop scale ``scale_name`` (in the auto mode, the
        one the meter chose for the latest picture, read-only)."""
        with self._showing_camera():
            physical = cam.exposure_mode == "physical"
            auto = cam.exposure_mode == "auto"
            self.exposure_mode.setCurrentIndex(self.exposure_mode.findData(cam.exposure_mode))
            self.metering.setCurrentIndex(max(0, self.metering.findData(cam.metering)))
            self.iso.setEditText(f"{cam.iso:g}")
            dial = SHUTTER_SCALES[scale_name]
            if [self.shutter.itemData(i) for i in range(self.shutter.count())] != [float(t) for t in dial]:
                self.shutter.clear()
                for seconds in dial:
                    self.shutter.addItem(format_shutter(seconds), float(seconds))
            step = STEP_WORDS[scale_name]
            self.shutter_shorter.setToolTip(f"Shorter by {step}: less light")
            self.shutter_longer.setToolTip(f"Longer by {step}: more light")
            self.shutter_shorter.setEnabled(physical and cam.shutter_s > dial[-1] * 1.0001)
            self.shutter_longer.setEnabled(physical and cam.shutter_s < dial[0] * 0.9999)
            self.iso.setEnabled(physical or auto)
            self.shutter.setEnabled(physical)
            self.shutter.setToolTip("The shutter the meter chose for the picture (auto exposure: read-only)" if auto
                                    else "Exposure time: choose a speed of the dial or type any (1/125, 0.5, 2 s)")
            self._show_shutter(cam, dial)
        self._show_meter()

    def _show_shutter(self, cam: ThinLensCamera, dial) -> None:
        """The shutter (in the auto mode the meter's choice for the latest picture) and the line under it."""
        physical = cam.exposure_mode == "physical"
        auto = cam.exposure_mode == "auto"
        shown = self.auto_exposure.shutter_s if auto and self.auto_exposure is not None else cam.shutter_s
        self.shutter.setCurrentIndex(next((i for i, t in enumerate(dial)
                                           if math.isclose(t, shown, rel_tol=1e-3)), -1))
        self.shutter.setEditText(format_shutter(shown))
        ev = ev100(cam.f_number, shown, cam.iso)
        if physical:
            info = f"EV₁₀₀ {ev:.1f}: a reflected-light meter calls {ev100_to_luminance(ev):.3g} cd/m² mid-grey."
        elif auto and self.auto_exposure is not None:
            info = (f"Auto: the meter chose {format_shutter(shown)} at {format_f_number(cam.f_number)}, ISO "
                    f"{cam.iso:g} (EV₁₀₀ {ev:.1f}), putting its reading at middle grey.")
        elif auto:
            info = "Auto: the meter chooses the shutter once it has read the picture."
        else:
            info = "The picture keeps its brightness whatever the aperture, shutter and ISO."
        self.exposure_info.setText(info)
