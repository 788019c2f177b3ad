"""The camera panel: the lens, aperture, focal length, focus, sensor, iris and exposure in photographers' terms,
with a depth-of-field readout and diagram. Everything here edits ``scene.camera`` through undo commands (a slider drag
is one undo step) and follows the document when something else changes it (undo, click-to-focus)."""

from __future__ import annotations

import math
from pathlib import Path

from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QAction, QColor, QFont, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFileDialog,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from lenslab.gui import theme
from lenslab.gui.commands import LensCommand
from lenslab.gui.document import listen
from lenslab.gui.widgets import IntEdit, NumberEdit, Section, hint, log_to_slider, readout, slider_to_log
from lenslab.optics import (
    THIRD_STOPS,
    LensPreset,
    PresetError,
    SensorPreset,
    format_distance,
    format_f_number,
    format_focal_length,
    load_lens_presets,
    load_sensor_presets,
    parse_f_number,
    step_stop,
)
from lenslab.optics.dof import COC_DIAGONAL_DIVISOR
from lenslab.optics.exposure import ev100, format_shutter, parse_shutter
from lenslab.optics.sensors import crop_factor
from lenslab.optics.stops import DEFAULT_STOP_SCALE, STOP_SCALES, marked_f_number
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.editing import camera_changes_keeping_focus, closest_focus, file_reference
from lenslab.scene.fields import declared_choices, declared_range

FULL_STOPS = STOP_SCALES["full"].exact  # labelled under the aperture slider
STOP_SCALE_NAMES = {"third": "Third stops", "half": "Half stops", "full": "Full stops"}
STEP_WORDS = {"third": "a third of a stop", "half": "half a stop", "full": "a stop"}
SENSOR_FIT_NAMES = {"auto": "Auto (long sides together)", "horizontal": "Horizontal", "vertical": "Vertical",
                    "fill": "Fill (crop the sensor)", "overscan": "Overscan (whole sensor)"}
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


COMMON_FOCAL_LENGTHS = (14, 24, 35, 50, 85, 135, 200)
FOCAL_RANGE = (8.0, 800.0)
FOCUS_RANGE = (0.05, 200.0)


def lens_short_name(lens: LensPreset) -> str:
    focal = (f"{lens.focal_range_mm[0]:g}-{lens.focal_range_mm[1]:g}" if lens.is_zoom else f"{lens.focal_length_mm:g}")
    return f"{focal} {format_f_number(lens.widest_f_number)}"


class AutoNumberEdit(NumberEdit):
    """A number field whose lowest value means "auto", shown with the value auto stands for; the first step up
    from auto starts from that value rather than from zero."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.auto_value = 0.0
        self.setSpecialValueText("auto")

    def set_auto_value(self, value: float) -> None:
        self.auto_value = float(value)
        self.setSpecialValueText(f"auto · {value:.{self.decimals()}f}{self.suffix()}")

    def stepBy(self, steps: int) -> None:
        if steps > 0 and self.value() <= self.minimum() and self.auto_value > self.minimum():
            self.setValue(round(self.auto_value, self.decimals()))
            steps -= 1
        if steps:
            super().stepBy(steps)


class IrisGlyph(QWidget):
    """The aperture as seen looking into the lens: a disc or a polygon of blades, its size following the f-number."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setFixedSize(QSize(46, 46))
        self.f_number = 2.8
        self.blades = 0
        self.rotation = 0.0

    def set_state(self, f_number: float, blades: int, rotation_deg: float) -> None:
        self.f_number, self.blades, self.rotation = f_number, blades, rotation_deg
        self.update()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        c = QPointF(self.width() / 2, self.height() / 2)
        outer = min(self.width(), self.height()) / 2 - 2
        p.setPen(QPen(QColor("#55575c"), 1.5))
        p.setBrush(QColor("#141517"))
        p.drawEllipse(c, outer, outer)
        # Opening radius relative to f/1.0, on an area (stop) scale that stays visible at f/22.
        r = outer * max(0.12, min(1.0, 1.2 / self.f_number ** 0.75))
        p.setPen(Qt.NoPen)
        p.setBrush(QColor(theme.ACCENT))
        if self.blades >= 3:
            poly = QPolygonF()
            for i in range(self.blades):
                a = math.radians(self.rotation) + 2 * math.pi * i / self.blades
                poly.append(QPointF(c.x() + r * math.cos(a), c.y() - r * math.sin(a)))
            p.drawPolygon(poly)
        else:
            p.drawEllipse(c, r, r)
        p.end()


class DofDiagram(QWidget):
    """Distance on a log scale from the camera: the zone of acceptable sharpness, the plane of focus and the
    hyperfocal distance."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumHeight(64)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
        self.focus = 1.0
        self.near = 0.9
        self.far = 1.1
        self.hyperfocal = 10.0

    def set_state(self, focus: float, near: float, far: float, hyperfocal: float) -> None:
        self.focus, self.near, self.far, self.hyperfocal = focus, near, far, hyperfocal
        self.update()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        w, h = self.width(), self.height()
        left, right = 22.0, w - 16.0
        axis_y = h * 0.48
        lo, hi = self.focus / 10.0, self.focus * 10.0

        def x_of(d: float) -> float:
            if math.isinf(d) or d >= hi:
                return right
            d = max(d, lo)
            return left + (math.log(d) - math.log(lo)) / (math.log(hi) - math.log(lo)) * (right - left)

        # Axis and the camera at its left end.
        p.setPen(QPen(QColor("#55575c"), 1))
        p.drawLine(QPointF(left, axis_y), QPointF(right, axis_y))
        cam = QPainterPath()
        cam.addRoundedRect(QRectF(4, axis_y - 6, 11, 12), 2, 2)
        p.fillPath(cam, QColor("#8c8f94"))
        # Decade ticks.
        font = QFont(self.font())
        font.setPointSizeF(max(7.0, font.pointSizeF() - 2))
        p.setFont(font)
        decade = 10 ** math.floor(math.log10(lo))
        while decade <= hi:
            for m in (1, 2, 5):
                d = decade * m
                if lo <= d <= hi:
                    x = x_of(d)
                    p.setPen(QPen(QColor("#45474b"), 1))
                    p.drawLine(QPointF(x, axis_y - 3), QPointF(x, axis_y + 3))
                    if m == 1:
                        p.setPen(QColor("#6c6f74"))
                        p.drawText(QRectF(x - 20, h - 14, 40, 12), Qt.AlignCenter, format_distance(d))
            decade *= 10
        # Zone of acceptable sharpness.
        x0, x1 = x_of(self.near), x_of(self.far)
        zone = QColor(theme.FOCUS)
        zone.setAlpha(70)
        p.fillRect(QRectF(x0, axis_y - 12, max(1.5, x1 - x0), 24), zone)
        p.setPen(QPen(QColor(theme.FOCUS), 1.2))
        p.drawLine(QPointF(x0, axis_y - 12), QPointF(x0, axis_y + 12))
        if not math.isinf(self.far) and self.far < hi:
            p.drawLine(QPointF(x1, axis_y - 12), QPointF(x1, axis_y + 12))
        else:
            p.drawText(QRectF(right - 2, axis_y - 8, 14, 16), Qt.AlignCenter, "∞")
        # Plane of focus.
        xf = x_of(self.focus)
        p.setPen(QPen(QColor(theme.ACCENT), 2))
        p.drawLine(QPointF(xf, axis_y - 16), QPointF(xf, axis_y + 16))
        # Hyperfocal distance.
        if lo <= self.hyperfocal <= hi:
            xh = x_of(self.hyperfocal)
            p.setPen(QPen(QColor("#8c8f94"), 1, Qt.DashLine))
            p.drawLine(QPointF(xh, 4), QPointF(xh, axis_y + 12))
            p.setPen(QColor("#8c8f94"))
            p.drawText(QRectF(xh + 2, 0, 14, 12), Qt.AlignLeft, "H")
        p.end()


class StopSlider(QWidget):
    """A slider over a list of f-stops (indices), with the full stops marked underneath."""

    moved = Signal(float, bool)  # f-number, merge

    def __init__(self, parent=None):
        super().__init__(parent)
        self.slider = QSlider(Qt.Horizontal)
        self.slider.setFocusPolicy(Qt.StrongFocus)
        self.labels = QWidget()
        self.labels.setFixedHeight(14)
        self.labels.paintEvent = self._paint_labels
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(0)
        layout.addWidget(self.slider)
        layout.addWidget(self.labels)
        self.scale: tuple[float, ...] = THIRD_STOPS
        self.slider.valueChanged.connect(self._changed)
        self._quiet = False
        self.set_scale(THIRD_STOPS)

    def set_scale(self, scale) -> None:
        self.scale = tuple(scale)
        self._quiet = True
        self.slider.setRange(0, len(self.scale) - 1)
        self.slider.setPageStep(3)
        self._quiet = False
        self.labels.update()

    def set_f_number(self, n: float) -> None:
        index = min(range(len(self.scale)), key=lambda i: abs(math.log(self.scale[i] / n)))
        self._quiet = True
        self.slider.setValue(index)
        self._quiet = False

    def _changed(self, index: int) -> None:
        if not self._quiet:
            self.moved.emit(float(self.scale[index]), True)

    def _paint_labels(self, event) -> None:
        p = QPainter(self.labels)
        font = QFont(self.font())
        font.setPointSizeF(max(7.0, font.pointSizeF() - 2))
        p.setFont(font)
        p.setPen(QColor("#8c8f94"))
        metrics = p.fontMetrics()
        n = len(self.scale)
        handle = 12
        width = self.labels.width()
        span = width - handle
        # The ends, then the full stops between them, each where it fits without touching a label already drawn.
        marked = [i for i, stop in enumerate(self.scale) if any(math.isclose(stop, s, rel_tol=1e-3) for s in FULL_STOPS)]
        drawn: list[tuple[float, float]] = []
        for i in [0, n - 1] + [i for i in marked if i not in (0, n - 1)]:
            text = f"{marked_f_number(self.scale[i]):g}"
            half = metrics.horizontalAdvance(text) / 2 + 1
            x = min(max(handle / 2 + span * i / max(1, n - 1), half), width - half)  # never cut at the edges
            if any(x - half < right + 4 and x + half > left - 4 for left, right in drawn):
                continue
            drawn.append((x - half, x + half))
            p.drawText(QRectF(x - half, 0, 2 * half, 14), Qt.AlignCenter, text)
        p.end()


class CameraPanel(QWidget):
    status_message = Signal(str)
    stop_scale_changed = Signal(str)  # "full", "half" or "third": what one step of [ and ] now is

    def __init__(self, doc, focus_action: QAction | None = None, parent=None, settings=None):
        super().__init__(parent)
        self.doc = doc
        self.settings = settings  # QSettings: the stop scale chosen last time
        saved = settings.value("camera/stop_scale", DEFAULT_STOP_SCALE) if settings is not None else DEFAULT_STOP_SCALE
        self.scale_name = saved if saved in STOP_SCALES else DEFAULT_STOP_SCALE
        try:
            self.lenses = load_lens_presets()
        except PresetError as exc:
            self.lenses = []
            self.status_message.emit(f"Lens presets not loaded: {exc}")
        try:
            self.sensors: list[SensorPreset] = load_sensor_presets()
        except PresetError:
            self.sensors = [SensorPreset("Full frame", 36.0, 24.0)]
        self._updating = False
        layout = QVBoxLayout(self)
        layout.setContentsMargins(10, 6, 10, 6)
        layout.setSpacing(2)
        self.sections: dict[str, Section] = {}
        layout.addWidget(self._lens_section())
        layout.addWidget(self._aperture_section())
        layout.addWidget(self._bokeh_section())
        layout.addWidget(self._focal_section())
        layout.addWidget(self._focus_section(focus_action))
        layout.addWidget(self._dof_section())
        layout.addWidget(self._exposure_section())
        layout.addWidget(self._sensor_section())
        layout.addStretch(1)
        listen(doc.model.events.changed, self, self._on_change)
        doc.lens_changed.connect(self.refresh)
        self.refresh()

    # -- sections ----------------------------------------------------------------------------------------------
    def _lens_section(self) -> Section:
        section = self._section("lens", "Lens")
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
        section.add(grid)
        self.lens_info = hint("")
        section.add(self.lens_info)
        return section

    def _section(self, key: str, title: str, expanded: bool = True) -> Section:
        """A section that folds away, open or folded as the user left it last time (QSettings)."""
        if self.settings is not None:
            expanded = str(self.settings.value(f"camera/section/{key}", expanded)).lower() in ("true", "1")
        section = Section(title, expanded=expanded)
        section.setObjectName(f"{key}Section")
        if self.settings is not None:
            section.toggled.connect(lambda on: self.settings.setValue(f"camera/section/{key}", bool(on)))
        self.sections[key] = section
        return section

    def _aperture_section(self) -> Section:
        section = self._section("aperture", "Aperture")
        row = QHBoxLayout()
        self.iris = IrisGlyph()
        row.addWidget(self.iris)
        self.open_up = QToolButton()
        self.open_up.setText("−")
        self.open_up.setToolTip("Open up a third of a stop ([)")
        self.open_up.clicked.connect(lambda: self.step_aperture(-1))
        self.aperture_combo = QComboBox()
        self.aperture_combo.setObjectName("apertureCombo")
        self.aperture_combo.setEditable(True)
        self.aperture_combo.setInsertPolicy(QComboBox.NoInsert)
        self.aperture_combo.setMinimumWidth(90)
        self.aperture_combo.setToolTip("f-number: choose a stop or type any value (2.8, f/3, 1:2.8); a marked stop "
                                       "means its exact value (f/11 is 11.31)")
        self.aperture_combo.currentIndexChanged.connect(self._aperture_chosen)
        self.aperture_combo.lineEdit().editingFinished.connect(self._aperture_typed)
        self.stop_down = QToolButton()
        self.stop_down.setText("+")
        self.stop_down.setToolTip("Stop down a third of a stop (])")
        self.stop_down.clicked.connect(lambda: self.step_aperture(+1))
        row.addWidget(self.open_up)
        row.addWidget(self.aperture_combo, 1)
        row.addWidget(self.stop_down)
        section.add(row)
        self.stop_slider = StopSlider()
        self.stop_slider.moved.connect(lambda n, merge: self.set_f_number(n, merge))
        section.add(self.stop_slider)
        steps = QHBoxLayout()
        self.stop_scale_combo = QComboBox()
        self.stop_scale_combo.setObjectName("stopScale")
        for name, text in STOP_SCALE_NAMES.items():
            self.stop_scale_combo.addItem(text, name)
        self.stop_scale_combo.setToolTip("What one step of [ and ], the −/+ buttons and the shutter's steps move: "
                                         "the scale shows marked stops, the camera takes the exact ones (f/11 is "
                                         "11.31)")
        self.stop_scale_combo.currentIndexChanged.connect(self._stop_scale_chosen)
        steps.addWidget(QLabel("Steps"))
        steps.addWidget(self.stop_scale_combo)
        steps.addStretch(1)
        section.add(steps)
        self.aperture_info = hint("")
        section.add(self.aperture_info)
        return section

    def _bokeh_section(self) -> Section:
        """The iris's shape and the lens's optical quirks: what the out-of-focus highlights look like."""
        section = self._section("bokeh", "Iris and bokeh")
        grid = QGridLayout()
        grid.setHorizontalSpacing(6)
        self.blades = IntEdit(*declared_range(ThinLensCamera, "aperture_blades"))
        self.blades.setSpecialValueText("round")
        self.blades.setToolTip("Number of aperture blades: round (0) or 3 to 32. Shapes the bokeh.")
        self.blades.edited.connect(self._blades_edited)
        self.rotation = NumberEdit(*declared_range(ThinLensCamera, "blade_rotation_deg"), decimals=1, step=1.0,
                                   suffix=" °")
        self.rotation.setToolTip("Rotation of the blade polygon")
        self.rotation.edited.connect(lambda v, merge: self.doc.set_camera(f"Blade rotation {v:g}°", merge,
                                                                          blade_rotation_deg=v))
        self.curvature = self._camera_number("blade_curvature", "Blade curvature", 2, 0.05,
                                             "Blade edges: 0 straight (polygonal bokeh) to 1 round")
        self.squeeze = self._camera_number("anamorphic_squeeze", "Anamorphic squeeze", 2, 0.05,
                                           "Anamorphic squeeze, bokeh height over width: 1 spherical; 1.33, 1.5, "
                                           "1.8 or 2 anamorphic; below 1 the oval lies on its side")
        self.barrel = self._camera_number("barrel_clipping", "Barrel clipping", 2, 0.05,
                                          "Barrel clipping: cat's-eye bokeh and vignetting toward the corners, how "
                                          "far the barrel cuts into the stop at the frame's corner (0 none, 1 by "
                                          "the stop's radius)")
        for i, (label, widget) in enumerate((("Blades", self.blades), ("Rotation", self.rotation),
                                             ("Curvature", self.curvature), ("Squeeze", self.squeeze),
                                             ("Cat's eye", self.barrel))):
            text = QLabel(label)
            text.setToolTip(widget.toolTip())
            grid.addWidget(text, i // 2, (i % 2) * 2)
            grid.addWidget(widget, i // 2, (i % 2) * 2 + 1)
        grid.setColumnStretch(1, 1)
        grid.setColumnStretch(3, 1)
        section.add(grid)
        image_row = QHBoxLayout()
        self.aperture_image_button = QPushButton("Aperture image…")
        self.aperture_image_button.setToolTip("A grayscale image of the stop for custom bokeh (a star, a heart): "
                                              "white lets light through, black stops it")
        self.aperture_image_button.clicked.connect(self._choose_aperture_image)
        self.aperture_image_clear = QToolButton()
        self.aperture_image_clear.setText("×")
        self.aperture_image_clear.setToolTip("No aperture image: back to the blades")
        self.aperture_image_clear.clicked.connect(lambda: self.set_aperture_image(""))
        self.aperture_image_label = hint("")
        image_row.addWidget(self.aperture_image_button)
        image_row.addWidget(self.aperture_image_clear)
        image_row.addWidget(self.aperture_image_label, 1)
        section.add(image_row)
        return section

    def _camera_number(self, field: str, undo_text: str, decimals: int, step: float, tip: str) -> NumberEdit:
        """A number field that edits one of the camera's fields, within the range the field declares."""
        edit = NumberEdit(*declared_range(ThinLensCamera, field), decimals=decimals, step=step)
        edit.setToolTip(tip)
        edit.edited.connect(lambda v, merge: self.doc.set_camera(f"{undo_text} {v:g}", merge, **{field: float(v)}))
        return edit

    def _focal_section(self) -> Section:
        section = self._section("focal", "Focal length")
        row = QHBoxLayout()
        self.focal = NumberEdit(*declared_range(ThinLensCamera, "focal_length_mm"), decimals=1, step=1.0, suffix=" mm")
        self.focal.setObjectName("focalLength")
        self.focal.edited.connect(lambda v, merge: self.set_focal_length(v, merge))
        self.focal_slider = QSlider(Qt.Horizontal)
        self.focal_slider.setRange(0, 1000)
        self.focal_slider.setFocusPolicy(Qt.StrongFocus)
        self.focal_slider.valueChanged.connect(self._focal_slid)
        row.addWidget(self.focal_slider, 1)
        row.addWidget(self.focal)
        self.focal.setFixedWidth(86)
        section.add(row)
        stops = QHBoxLayout()
        stops.setSpacing(2)
        self.focal_buttons = []
        for mm in COMMON_FOCAL_LENGTHS:
            b = QPushButton(str(mm))
            b.setObjectName("lensButton")
            b.setToolTip(f"{mm} mm")
            b.clicked.connect(lambda _c=False, mm=mm: self.set_focal_length(float(mm), False))
            stops.addWidget(b)
            self.focal_buttons.append(b)
        section.add(stops)
        self.fov_info = hint("")
        section.add(self.fov_info)
        return section

    def _focus_section(self, focus_action: QAction | None) -> Section:
        section = self._section("focus", "Focus")
        row = QHBoxLayout()
        self.focus_slider = QSlider(Qt.Horizontal)
        self.focus_slider.setRange(0, 1000)
        self.focus_slider.setFocusPolicy(Qt.StrongFocus)
        self.focus_slider.valueChanged.connect(self._focus_slid)
        self.focus = NumberEdit(*declared_range(ThinLensCamera, "focus_distance_m"), decimals=3, step=0.01, suffix=" m")
        self.focus.setObjectName("focusDistance")
        self.focus.setFixedWidth(86)
        self.focus.edited.connect(lambda v, merge: self.set_focus(v, merge))
        row.addWidget(self.focus_slider, 1)
        row.addWidget(self.focus)
        section.add(row)
        options = QHBoxLayout()
        self.focus_from = QComboBox()
        self.focus_from.addItem("from the sensor", "sensor")
        self.focus_from.addItem("from the lens", "lens")
        self.focus_from.setToolTip("What the focus distance is measured from: the sensor plane, as a lens's focus "
                                   "scale is marked, or the lens (pbrt's and Mitsuba's meaning). The plane of "
                                   "focus stays where it is.")
        self.focus_from.currentIndexChanged.connect(self._focus_from_chosen)
        self.breathing = QCheckBox("Focus breathing")
        self.breathing.setToolTip("The sensor moves to the image distance as a real lens focuses, so the framing "
                                  "tightens at close focus. Off: the framing is held (pbrt, Mitsuba).")
        self.breathing.toggled.connect(lambda on: self._updating or self.doc.set_camera(
            "Focus breathing" if on else "Hold framing", False, focus_breathing=bool(on)))
        options.addWidget(self.focus_from)
        options.addWidget(self.breathing)
        options.addStretch(1)
        section.add(options)
        self.focus_info = hint("")
        section.add(self.focus_info)
        buttons = QHBoxLayout()
        if focus_action is not None:
            tool = QToolButton()
            tool.setDefaultAction(focus_action)
            tool.setToolButtonStyle(Qt.ToolButtonTextBesideIcon)
            buttons.addWidget(tool)
        self.focus_selection_button = QPushButton("Focus on selection")
        self.focus_selection_button.setToolTip("Set the focus distance to the selected object's centre")
        buttons.addWidget(self.focus_selection_button)
        buttons.addStretch(1)
        section.add(buttons)
        return section

    def _dof_section(self) -> Section:
        section = self._section("dof", "Depth of field")
        grid = QGridLayout()
        grid.setHorizontalSpacing(10)
        grid.setVerticalSpacing(2)
        self.dof_near = readout()
        self.dof_far = readout()
        self.dof_total = readout()
        self.dof_hyper = readout()
        for i, (label, value) in enumerate((("Near", self.dof_near), ("Far", self.dof_far),
                                            ("Total", self.dof_total), ("Hyperfocal", self.dof_hyper))):
            grid.addWidget(QLabel(label), i // 2, (i % 2) * 2)
            grid.addWidget(value, i // 2, (i % 2) * 2 + 1)
        section.add(grid)
        self.dof_diagram = DofDiagram()
        section.add(self.dof_diagram)
        self.dof_info = hint("")
        section.add(self.dof_info)
        return section

    def _sensor_section(self) -> Section:
        section = self._section("sensor", "Sensor")
        self.sensor_combo = QComboBox()
        for sensor in self.sensors:
            self.sensor_combo.addItem(f"{sensor.name}  ({sensor.width_mm:g} × {sensor.height_mm:g})", sensor)
        self.sensor_combo.addItem("Custom", None)
        self.sensor_combo.currentIndexChanged.connect(self._sensor_chosen)
        section.add(self.sensor_combo)
        row = QHBoxLayout()
        self.sensor_w = NumberEdit(*declared_range(ThinLensCamera, "sensor_mm"), decimals=2, step=0.1, suffix=" mm")
        self.sensor_h = NumberEdit(*declared_range(ThinLensCamera, "sensor_mm"), decimals=2, step=0.1, suffix=" mm")
        self.sensor_w.edited.connect(lambda v, merge: self._sensor_edited(merge))
        self.sensor_h.edited.connect(lambda v, merge: self._sensor_edited(merge))
        row.addWidget(QLabel("W"))
        row.addWidget(self.sensor_w)
        row.addWidget(QLabel("H"))
        row.addWidget(self.sensor_h)
        section.add(row)
        grid = QGridLayout()
        self.sensor_fit = QComboBox()
        for fit in declared_choices(ThinLensCamera, "sensor_fit"):
            self.sensor_fit.addItem(SENSOR_FIT_NAMES.get(fit, fit), fit)
        self.sensor_fit.setToolTip("Which part of the sensor an image of another shape shows (Blender's and "
                                   "Unity's fits)")
        self.sensor_fit.currentIndexChanged.connect(
            lambda i: self._updating or self.doc.set_camera("Sensor fit", False,
                                                            sensor_fit=self.sensor_fit.itemData(i)))
        low, high = declared_range(ThinLensCamera, "circle_of_confusion_mm")
        self.coc = AutoNumberEdit(0.0, high, decimals=4, step=0.001, suffix=" mm")
        self.coc.setObjectName("circleOfConfusion")
        self.coc.setToolTip("Circle of confusion, the blur the depth-of-field readout calls sharp: auto is the "
                            "diagonal of the sensor area the image shows / 1500; type a value for a stricter or "
                            "looser standard, or 0 for auto")
        self.coc.edited.connect(lambda v, merge: self.doc.set_camera(
            f"Circle of confusion {f'{v:g} mm' if v >= low else 'auto'}", merge,
            circle_of_confusion_mm=float(v) if v >= low else None))
        grid.addWidget(QLabel("Fit"), 0, 0)
        grid.addWidget(self.sensor_fit, 0, 1)
        coc_label = QLabel("CoC")
        coc_label.setToolTip(self.coc.toolTip())
        grid.addWidget(coc_label, 1, 0)
        grid.addWidget(self.coc, 1, 1)
        grid.setColumnStretch(1, 1)
        section.add(grid)
        self.sensor_info = hint("")
        section.add(self.sensor_info)
        return section

    def _exposure_section(self) -> Section:
        section = self._section("exposure", "Exposure")
        grid = QGridLayout()
        self.exposure_mode = QComboBox()
        self.exposure_mode.addItem("Compensated", "compensated")
        self.exposure_mode.addItem("Physical (ISO, shutter)", "physical")
        self.exposure_mode.setToolTip("Compensated: the brightness stays the same at every aperture, to judge "
                                      "depth of field. Physical: each stop of aperture, shutter or ISO is a stop "
                                      "of light (radiance in cd/m²)")
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
        grid.setColumnStretch(1, 1)
        section.add(grid)
        self.exposure_info = hint("")
        section.add(self.exposure_info)
        return section

    # -- edits ----------------------------------------------------------------------------------------------------
    def stop_scale(self) -> tuple[float, ...]:
        """The exact f-numbers one step moves between: the chosen scale, within the mounted lens."""
        lens = self.doc.lens
        return lens.available_stops(self.scale_name) if lens is not None else STOP_SCALES[self.scale_name].exact

    def _stop_scale_chosen(self, index: int) -> None:
        if self._updating or index < 0:
            return
        self.scale_name = self.stop_scale_combo.itemData(index)
        if self.settings is not None:
            self.settings.setValue("camera/stop_scale", self.scale_name)
        self.refresh()
        self.stop_scale_changed.emit(self.scale_name)

    def focus_limits(self) -> tuple[float, float]:
        """The focus distances the camera (and its lens) can set, in its reference."""
        return closest_focus(self.doc.scene.camera, self.doc.lens), FOCUS_RANGE[1]

    def set_focus(self, metres: float, merge: bool = False, text: str | None = None) -> bool:
        """Focus at ``metres`` (in the camera's reference), or refuse and say why when the lens cannot. The undo
        step reads ``text``, by default "Focus" and the distance."""
        closest, _ = self.focus_limits()
        if metres < closest * (1 - 1e-9):
            lens = self.doc.lens
            why = (f"the {lens.name} focuses no nearer than {format_distance(lens.min_focus_distance_m)} from the "
                   "sensor" if lens is not None and lens.min_focus_distance_m is not None
                   and closest > self.doc.scene.camera.closest_focus_m else
                   f"a {format_focal_length(self.doc.scene.camera.focal_length_mm)} lens focuses no nearer than "
                   f"{format_distance(closest)}")
            self.status_message.emit(f"Cannot focus at {format_distance(metres)}: {why}")
            self.refresh()
            return False
        self.doc.set_camera(text or f"Focus {format_distance(metres)}", merge, focus_distance_m=float(metres))
        return True

    def _focus_from_chosen(self, index: int) -> None:
        if self._updating or index < 0:
            return
        cam = self.doc.scene.camera
        reference = self.focus_from.itemData(index)
        if reference == cam.focus_from:
            return
        # The plane of focus stays put: the reading changes by the lens-to-sensor distance.
        plane = cam.plane_of_focus_m
        reading = plane if reference == "lens" else plane + cam.image_distance_mm / 1000
        self.doc.set_camera("Focus measured from the " + reference, False, focus_from=reference,
                            focus_distance_m=float(reading))

    def set_aperture_image(self, path: str) -> None:
        """Use the image at ``path`` as the stop ("" for the blades); a missing or black image is refused with a
        message, and the camera keeps its stop."""
        if path:
            from lenslab.scene.aperture_images import resolve

            trial = ThinLensCamera(aperture_image=path)
            try:
                trial.aperture(self.doc.scene.base_dir())
            except (ValueError, OSError) as exc:
                self.status_message.emit(f"Aperture image not used: {exc}")
                self.refresh()
                return
            # Named relative to the scene file, as meshes are (absolute while the scene has no file).
            path = file_reference(resolve(path, self.doc.scene.base_dir()), self.doc.path)
        self.doc.set_camera(f"Aperture image {Path(path).name}" if path else "No aperture image", False,
                            aperture_image=path)

    def _choose_aperture_image(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Aperture image", str(self.doc.scene.base_dir()),
                                              "Images (*.png *.jpg *.jpeg *.exr *.hdr *.tif *.tiff)")
        if path:
            self.set_aperture_image(path)

    def _set_iso(self, value) -> None:
        low, high = declared_range(ThinLensCamera, "iso")
        if value is None or not low <= float(value) <= high:
            self.status_message.emit(f"ISO must lie between {low:g} and {high:g}")
            self.refresh()
            return
        self.doc.set_camera(f"ISO {float(value):g}", False, iso=float(value))

    def _iso_typed(self) -> None:
        if self._updating:
            return
        text = self.iso.lineEdit().text().strip().lower().removeprefix("iso").strip()
        try:
            value = float(text)
        except ValueError:
            self.status_message.emit(f"not an ISO speed: '{text}'")
            self.refresh()
            return
        if not math.isclose(value, self.doc.scene.camera.iso):
            self._set_iso(value)

    def _set_shutter(self, seconds, merge: bool = False) -> None:
        if seconds is not None:
            self.doc.set_camera(f"Shutter {format_shutter(seconds)}", merge, shutter_s=float(seconds))

    def step_shutter(self, steps: int) -> None:
        """``steps`` marks of the shutter dial on the chosen stop scale (positive: longer, more light)."""
        current = self.doc.scene.camera.shutter_s
        seconds = step_shutter(current, steps, self.scale_name)
        if not math.isclose(seconds, current, rel_tol=1e-9):
            self._set_shutter(seconds, merge=True)
        self.refresh()

    def _shutter_typed(self) -> None:
        if self._updating:
            return
        try:
            seconds = parse_shutter(self.shutter.lineEdit().text())
        except ValueError as exc:
            self.status_message.emit(str(exc))
            self.refresh()
            return
        if not math.isclose(seconds, self.doc.scene.camera.shutter_s, rel_tol=1e-6):
            self._set_shutter(seconds)

    def choose_lens(self, lens: LensPreset | None) -> None:
        if lens == self.doc.lens:
            self.refresh()
            return
        self.doc.push(LensCommand(self.doc, lens))
        if lens is not None:
            cam = self.doc.scene.camera
            self.status_message.emit(
                f"{lens.name}: {format_focal_length(cam.focal_length_mm)}, {format_f_number(cam.f_number)}")

    def set_f_number(self, n: float, merge: bool = False) -> None:
        lens = self.doc.lens
        if lens is not None:
            clamped = lens.clamp_f_number(n)
            if not math.isclose(clamped, n, rel_tol=1e-9):
                self.status_message.emit(f"The {lens.name} goes from {format_f_number(lens.widest_f_number)} to "
                                         f"{format_f_number(lens.narrowest_f_number)}")
            n = clamped
        self.doc.set_camera(f"Aperture {format_f_number(n)}", merge, f_number=float(n))
        self.refresh()  # the clamp may leave the camera as it was; show the truth either way

    def step_aperture(self, steps: int) -> None:
        self.set_f_number(step_stop(self.doc.scene.camera.f_number, steps, self.stop_scale()), merge=True)

    def _aperture_chosen(self, index: int) -> None:
        if self._updating or index < 0:
            return
        value = self.aperture_combo.itemData(index)
        if value is not None:
            self.set_f_number(float(value))

    def _aperture_typed(self) -> None:
        if self._updating:
            return
        text = self.aperture_combo.lineEdit().text()
        try:
            n = parse_f_number(text, self.scale_name)
        except ValueError as exc:
            self.status_message.emit(str(exc))
            self.refresh()
            return
        if not math.isclose(n, self.doc.scene.camera.f_number, rel_tol=1e-9):
            self.set_f_number(n)

    def set_focal_length(self, mm: float, merge: bool) -> None:
        lens = self.doc.lens
        if lens is not None:
            if not lens.is_zoom and not math.isclose(mm, lens.focal_length_mm):
                self.status_message.emit(f"The {lens.name} is a prime: choose Free or a zoom to change focal length")
                self.refresh()
                return
            mm = lens.clamp_focal_length(mm)
        changes = camera_changes_keeping_focus(self.doc.scene.camera, lens, focal_length_mm=float(mm))
        if "focus_distance_m" in changes:
            self.status_message.emit(f"Focus moved out to {format_distance(changes['focus_distance_m'])}: a "
                                     f"{format_focal_length(mm)} lens focuses no nearer")
        self.doc.set_camera(f"Focal length {mm:g} mm", merge, **changes)
        self.refresh()

    def _focal_slid(self, position: int) -> None:
        if self._updating:
            return
        lo, hi = self._focal_limits()
        mm = round(slider_to_log(position, lo, hi), 1)
        self.set_focal_length(mm, True)

    def _focal_limits(self) -> tuple[float, float]:
        lens = self.doc.lens
        if lens is not None and lens.is_zoom:
            return lens.focal_range_mm
        return FOCAL_RANGE

    def _focus_slid(self, position: int) -> None:
        if self._updating:
            return
        closest, far = self.focus_limits()
        metres = max(closest, float(f"{slider_to_log(position, closest, far):.3g}"))
        self.doc.set_camera(f"Focus {format_distance(metres)}", True, focus_distance_m=metres)

    def _blades_edited(self, value: int, merge: bool) -> None:
        current = self.doc.scene.camera.aperture_blades
        if value in (1, 2):  # not a polygon: jump over, in the direction of travel
            value = 3 if current < value else 0
            self.blades.set_quietly(value)
        self.doc.set_camera(f"Aperture blades {value}" if value else "Round aperture", merge,
                            aperture_blades=int(value))

    def _sensor_chosen(self, index: int) -> None:
        if self._updating:
            return
        sensor = self.sensor_combo.itemData(index)
        if sensor is None:
            self.refresh()
            return
        self.doc.set_camera(f"Sensor {sensor.name}", False, sensor_mm=(sensor.width_mm, sensor.height_mm),
                            circle_of_confusion_mm=sensor.circle_of_confusion_mm)

    def _sensor_edited(self, merge: bool) -> None:
        if self._updating:
            return
        w, h = self.sensor_w.value(), self.sensor_h.value()
        self.doc.set_camera(f"Sensor size {w:g} × {h:g} mm", merge, sensor_mm=(w, h))

    # -- following the document ---------------------------------------------------------------------------------
    def _on_change(self, change) -> None:
        if change.kind in ("camera", "scene"):
            self.refresh()

    def refresh(self) -> None:
        cam = self.doc.scene.camera
        lens = self.doc.lens
        self._updating = True
        try:
            # Lens.
            for i, button in enumerate(self.lens_buttons):
                button.setChecked((i == 0 and lens is None) or (i > 0 and self.lenses[i - 1] == lens))
            if lens is None:
                self.lens_info.setText("Free: any focal length and aperture.")
            else:
                self.lens_info.setText(f"{lens.name} · {format_f_number(lens.widest_f_number)}–"
                                       f"{format_f_number(lens.narrowest_f_number)}"
                                       + (f" · {lens.aperture_blades} blades" if lens.aperture_blades else ""))
            # Aperture.
            scale = self.stop_scale()
            if [self.aperture_combo.itemData(i) for i in range(self.aperture_combo.count())] != list(scale):
                self.aperture_combo.clear()
                for stop in scale:
                    self.aperture_combo.addItem(format_f_number(stop), float(stop))
            index = next((i for i, s in enumerate(scale) if math.isclose(s, cam.f_number, rel_tol=1e-3)), -1)
            self.aperture_combo.setCurrentIndex(index)
            self.aperture_combo.setEditText(format_f_number(cam.f_number))
            if not self.stop_slider.slider.isSliderDown():  # never fight the hand on the slider
                self.stop_slider.set_scale(scale)
                self.stop_slider.set_f_number(cam.f_number)
            self.open_up.setEnabled(cam.f_number > scale[0] * 1.0001)
            self.stop_down.setEnabled(cam.f_number < scale[-1] * 0.9999)
            diameter = cam.focal_length_mm / cam.f_number
            light = self.light_fraction()
            brightness = ("Brightness stays the same at every aperture (exposure is compensated)."
                          if cam.exposure_mode != "physical" else "Each stop is a stop of light (physical exposure).")
            if cam.aperture_image:
                iris = f"the stop is {Path(cam.aperture_image).name}"
            else:
                iris = (f"{cam.aperture_blades} blades" if cam.aperture_blades >= 3 else "round")
                extras = [f"squeeze {cam.anamorphic_squeeze:g}" if cam.anamorphic_squeeze != 1 else "",
                          f"cat's eye {cam.barrel_clipping:g}" if cam.barrel_clipping > 0 else ""]
                iris = ", ".join([iris] + [e for e in extras if e])
            self.aperture_info.setText(f"Entrance pupil {diameter:.1f} mm ({iris})"
                                       + (f", passing {light:.0%} of the round stop's light" if light < 0.999 else "")
                                       + f". {brightness}")
            step = STEP_WORDS[self.scale_name]
            self.open_up.setToolTip(f"Open up {step} ([)")
            self.stop_down.setToolTip(f"Stop down {step} (])")
            self.stop_scale_combo.setCurrentIndex(self.stop_scale_combo.findData(self.scale_name))
            self.stop_slider.slider.setPageStep(STOP_SCALES[self.scale_name].steps_per_stop)
            self.iris.set_state(cam.f_number, cam.aperture_blades, cam.blade_rotation_deg)
            self.blades.set_quietly(cam.aperture_blades)
            self.rotation.set_quietly(cam.blade_rotation_deg)
            bladed = cam.aperture_blades >= 3 and not cam.aperture_image
            self.rotation.setEnabled(bladed)
            self.curvature.set_quietly(cam.blade_curvature)
            self.curvature.setEnabled(bladed)
            self.squeeze.set_quietly(cam.anamorphic_squeeze)
            self.barrel.set_quietly(cam.barrel_clipping)
            self.aperture_image_label.setText(Path(cam.aperture_image).name if cam.aperture_image else "blades")
            self.aperture_image_clear.setEnabled(bool(cam.aperture_image))
            # Focal length.
            lo, hi = self._focal_limits()
            prime = lens is not None and not lens.is_zoom
            self.focal.set_quietly(cam.focal_length_mm)
            if not self.focal_slider.isSliderDown():
                self.focal_slider.setValue(log_to_slider(cam.focal_length_mm, lo, hi))
            for widget in [self.focal, self.focal_slider] + self.focal_buttons:
                widget.setEnabled(not prime)
            for b, mm in zip(self.focal_buttons, COMMON_FOCAL_LENGTHS):
                b.setEnabled(not prime and (lens is None or lens.min_focal_length_mm <= mm <= lens.max_focal_length_mm))
            fov_y = math.degrees(cam.frame().fov_y)
            self.fov_info.setText(f"Field of view {math.degrees(cam.fov_x):.1f}° × {fov_y:.1f}°"
                                  + (" · fixed by the prime" if prime else ""))
            # Focus.
            closest, far = self.focus_limits()
            self.focus.set_quietly(cam.focus_distance_m)
            if not self.focus_slider.isSliderDown():
                self.focus_slider.setValue(log_to_slider(max(closest, cam.focus_distance_m), closest, far))
            self.focus_from.setCurrentIndex(self.focus_from.findData(cam.focus_from))
            self.breathing.setChecked(cam.focus_breathing)
            reference = "sensor" if cam.focus_from == "sensor" else "lens"
            self.focus_info.setText(f"Measured from the {reference}; nearest {format_distance(closest)}. Plane of "
                                    f"focus {format_distance(cam.plane_of_focus_m)} ahead of the lens, sensor "
                                    f"{cam.image_distance_mm:.1f} mm behind it.")
            # Sensor.
            sw, sh = cam.sensor_mm
            index = next((i for i, s in enumerate(self.sensors)
                          if math.isclose(s.width_mm, sw, rel_tol=1e-4) and math.isclose(s.height_mm, sh, rel_tol=1e-4)),
                         len(self.sensors))
            self.sensor_combo.setCurrentIndex(index)
            self.sensor_w.set_quietly(sw)
            self.sensor_h.set_quietly(sh)
            crop = crop_factor(sw, sh)
            width, height = cam.resolution
            coc = cam.coc_mm(width, height)
            film_w, film_h = cam.imaged_area_mm(width, height)
            self.sensor_fit.setCurrentIndex(self.sensor_fit.findData(cam.sensor_fit))
            self.coc.set_auto_value(math.hypot(film_w, film_h) / COC_DIAGONAL_DIVISOR)
            self.coc.set_quietly(cam.circle_of_confusion_mm or 0.0)
            self.sensor_info.setText(f"Crop factor {crop:.2f} · the image shows {film_w:.1f} × {film_h:.1f} mm · "
                                     f"circle of confusion {coc * 1000:.0f} µm · "
                                     f"{cam.focal_length_mm * crop:.0f} mm full-frame equivalent")
            # Exposure.
            physical = cam.exposure_mode == "physical"
            self.exposure_mode.setCurrentIndex(self.exposure_mode.findData(cam.exposure_mode))
            self.iso.setEditText(f"{cam.iso:g}")
            dial = SHUTTER_SCALES[self.scale_name]
            if [self.shutter.itemData(i) for i in range(self.shutter.count())] != [float(t) for t in dial]:
                self.shutter.clear()
                for seconds in dial:
                    self.shutter.addItem(format_shutter(seconds), float(seconds))
            self.shutter.setCurrentIndex(next((i for i, t in enumerate(dial)
                                               if math.isclose(t, cam.shutter_s, rel_tol=1e-3)), -1))
            self.shutter.setEditText(format_shutter(cam.shutter_s))
            self.shutter_shorter.setToolTip(f"Shorter by {step}: less light")
            self.shutter_longer.setToolTip(f"Longer by {step}: more light")
            self.shutter_shorter.setEnabled(physical and cam.shutter_s > dial[-1] * 1.0001)
            self.shutter_longer.setEnabled(physical and cam.shutter_s < dial[0] * 0.9999)
            self.iso.setEnabled(physical)
            self.shutter.setEnabled(physical)
            ev = ev100(cam.f_number, cam.shutter_s, cam.iso)
            self.exposure_info.setText(
                f"EV₁₀₀ {ev:.1f}: a reflected-light meter calls {0.125 * 2 ** ev:.3g} cd/m² mid-grey."
                if physical else "The picture keeps its brightness whatever the aperture, shutter and ISO.")
            # Depth of field: exactly the picture the renderer draws, with the aperture's real area.
            dof = cam.depth_of_field(width, height, light)
            self.dof_near.setText(format_distance(dof.near_m))
            self.dof_far.setText(format_distance(dof.far_m))
            self.dof_total.setText(format_distance(dof.total_m) if not math.isinf(dof.total_m) else "∞")
            self.dof_hyper.setText(format_distance(dof.hyperfocal_m))
            self.dof_diagram.set_state(cam.focus_distance_m, dof.near_m, max(dof.near_m, dof.far_m), dof.hyperfocal_m)
            self.dof_info.setText(f"Sharp from {format_distance(dof.near_m)} to {format_distance(dof.far_m)} for a "
                                  f"{coc * 1000:.0f} µm circle of confusion. Focus at the hyperfocal distance to "
                                  "keep everything from half of it to infinity sharp.")
        finally:
            self._updating = False

    def light_fraction(self) -> float:
        """The light the camera's stop passes, as a fraction of the round f/N stop's (an aperture image's mask)."""
        try:
            return self.doc.scene.camera.aperture(self.doc.scene.base_dir()).light_fraction
        except ValueError:  # an aperture image gone missing since: the render says so; the readout goes on
            return 1.0
