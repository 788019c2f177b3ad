"""File > Export: render the scene to a file at a chosen size, to a sample count or a time limit, written by the
same writer and with the same metadata as ``lenslab --headless`` (EXR: scene-linear float; a picture, PNG, TIFF or
JPEG: through the view transform, OpenColorIO's display, view and look with an exposure and contrast, the viewport's
by default)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QButtonGroup,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QRadioButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from lenslab.atomic import check_output_folder
from lenslab.colour_management.config import load_config
from lenslab.colour_management.view import CONTRAST_RANGE, EXPOSURE_RANGE, ViewTransform
from lenslab.gui.controller import rate_text
from lenslab.gui.document import copy_scene
from lenslab.gui.worker import ExportRequest
from lenslab.messages import one_line
from lenslab.scene.camera import MAX_IMAGE_SIDE
from lenslab.scene.fields import declared_range
from lenslab.scene.scene import RenderSettings

FORMATS = (("OpenEXR — scene-linear float, for grading", ".exr"), ("PNG — 8-bit picture", ".png"),
           ("TIFF — 16-bit picture", ".tif"), ("JPEG — 8-bit picture", ".jpg"))
#: Other spellings of the formats' suffixes.
SUFFIX_ALIASES = {".tiff": ".tif", ".jpeg": ".jpg"}


def default_export_path(doc, suffix: str = ".png") -> Path:
    folder = Path(doc.path).parent if doc.path else Path.home()
    stem = doc.display_name if doc.display_name != "Untitled" else "render"
    return folder / f"{stem}{suffix}"


def export_problem(path: Path, width: int, height: int, denoise: bool = False) -> str | None:
    """Why an image of ``width`` x ``height`` cannot be written at ``path`` now (its folder refuses a new file, or
    lacks the space), in one line naming the file; None if it can. Asked before the render, not after it."""
    from lenslab.render.job import estimated_export_bytes  # here: it brings the tracer, left to the render thread

    try:
        check_output_folder(path, estimated_export_bytes(path, width, height, denoise))
    except OSError as exc:
        return one_line(exc)
    return None


def estimate_seconds(width: int, height: int, spp: int, samples_per_second: float | None) -> float | None:
    if not samples_per_second:
        return None
    return width * height * spp / samples_per_second


class ExportDialog(QDialog):
    def __init__(self, doc, view: ViewTransform, samples_per_second: float | None = None,
                 last_path: Path | None = None, parent: QWidget | None = None):
        """``view``: the view transform a PNG is made through to begin with (the viewport's)."""
        super().__init__(parent)
        self.setWindowTitle("Export image")
        self.doc = doc
        self.view = view.resolved()
        self.rate = samples_per_second
        cam = doc.scene.camera
        self._aspect = cam.resolution[0] / cam.resolution[1]

        self.path_edit = QLineEdit(str(last_path or default_export_path(doc)))
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        path_row = QHBoxLayout()
        path_row.addWidget(self.path_edit, 1)
        path_row.addWidget(browse)

        self.format_combo = QComboBox()
        for label, suffix in FORMATS:
            self.format_combo.addItem(label, suffix)
        self.format_combo.currentIndexChanged.connect(self._format_chosen)
        self.path_edit.textChanged.connect(self._path_edited)

        self.width_spin = QSpinBox()
        self.height_spin = QSpinBox()
        for spin, value in ((self.width_spin, cam.resolution[0]), (self.height_spin, cam.resolution[1])):
            spin.setRange(1, MAX_IMAGE_SIDE)
            spin.setValue(value)
            spin.setSuffix(" px")
        self.lock_aspect = QCheckBox("Keep aspect")
        self.lock_aspect.setChecked(True)
        self.width_spin.valueChanged.connect(self._width_changed)
        self.height_spin.valueChanged.connect(self._height_changed)
        size_row = QHBoxLayout()
        size_row.addWidget(self.width_spin)
        size_row.addWidget(QLabel("×"))
        size_row.addWidget(self.height_spin)
        size_row.addWidget(self.lock_aspect)
        for label, factor in (("½", 0.5), ("1×", 1.0), ("2×", 2.0)):
            b = QPushButton(label)
            b.setToolTip(f"{factor:g} × the camera's resolution")
            b.setFixedWidth(36)
            b.clicked.connect(lambda _c=False, f=factor: self._scale_size(f))
            size_row.addWidget(b)

        self.by_samples = QRadioButton("Samples per pixel")
        self.by_time = QRadioButton("Time limit")
        group = QButtonGroup(self)
        group.addButton(self.by_samples)
        group.addButton(self.by_time)
        self.by_samples.setChecked(True)
        self.spp_spin = QSpinBox()
        self.spp_spin.setRange(*declared_range(RenderSettings, "spp"))
        self.spp_spin.setValue(doc.scene.render.spp)
        self.seconds_spin = QDoubleSpinBox()
        self.seconds_spin.setRange(0.1, 1e6)
        self.seconds_spin.setDecimals(1)
        self.seconds_spin.setValue(60.0)
        self.seconds_spin.setSuffix(" s")
        quality = QFormLayout()
        quality.addRow(self.by_samples, self.spp_spin)
        quality.addRow(self.by_time, self.seconds_spin)

        # The view transform: the config's displays, the chosen display's views, its looks; exposure and contrast.
        config = load_config(self.view.config)
        self.display_combo = QComboBox()
        self.display_combo.addItems(list(config.getDisplays()))
        self.display_combo.setCurrentText(self.view.display)
        self.view_combo = QComboBox()
        self._fill_views(self.view.view)
        self.display_combo.currentTextChanged.connect(lambda _d: self._fill_views(self.view_combo.currentText()))
        self.look_combo = QComboBox()
        self.look_combo.addItem("None", "")
        for look in config.getLooks():
            self.look_combo.addItem(look.getName(), look.getName())
        self.look_combo.setCurrentIndex(max(0, self.look_combo.findData(self.view.looks)))
        self.exposure_spin = QDoubleSpinBox()
        self.exposure_spin.setRange(*EXPOSURE_RANGE)
        self.exposure_spin.setSingleStep(0.1)
        self.exposure_spin.setDecimals(2)
        self.exposure_spin.setSuffix(" EV")
        self.exposure_spin.setValue(self.view.exposure_stops)
        self.contrast_spin = QDoubleSpinBox()
        self.contrast_spin.setRange(*CONTRAST_RANGE)
        self.contrast_spin.setSingleStep(0.05)
        self.contrast_spin.setDecimals(2)
        self.contrast_spin.setValue(self.view.contrast)
        self.contrast_spin.setToolTip("Contrast about middle grey (1 = as the view makes it)")
        self.denoise_check = QCheckBox("Denoise")  # never on unless asked: an export is the render as it is
        self.denoise_check.setToolTip("Write the image denoised by Intel Open Image Denoise, guided by the albedo "
                                      "and normal rendered beside it. An EXR also keeps the noisy image, the albedo "
                                      "and the normal as layers (noisy, albedo, normal).")
        self.png_note = QLabel("The view transform, exposure and contrast make the picture (PNG, TIFF, JPEG); an EXR "
                               "keeps the scene-linear radiance, in the scene's working space.")
        self.png_note.setObjectName("hint")
        self.png_note.setWordWrap(True)

        self.estimate = QLabel()
        self.estimate.setObjectName("hint")
        for spin in (self.width_spin, self.height_spin, self.spp_spin):
            spin.valueChanged.connect(self._update_estimate)
        self.by_samples.toggled.connect(self._update_estimate)

        form = QFormLayout()
        form.addRow("File", path_row)
        form.addRow("Format", self.format_combo)
        form.addRow("Size", size_row)
        form.addRow("Stop at", quality)
        form.addRow("Display", self.display_combo)
        form.addRow("View", self.view_combo)
        form.addRow("Look", self.look_combo)
        form.addRow("Exposure", self.exposure_spin)
        form.addRow("Contrast", self.contrast_spin)
        form.addRow("", self.denoise_check)
        form.addRow("", self.png_note)
        buttons = QDialogButtonBox(QDialogButtonBox.Cancel)
        self.render_button = buttons.addButton("Render", QDialogButtonBox.AcceptRole)
        self.render_button.setDefault(True)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.estimate)
        layout.addWidget(buttons)
        self._path_edited(self.path_edit.text())
        self._update_estimate()

    # -- fields ---------------------------------------------------------------------------------------------------
    def _fill_views(self, keep: str) -> None:
        """The chosen display's views, keeping ``keep`` where the display has it (else its default view)."""
        config = load_config(self.view.config)
        display = self.display_combo.currentText()
        views = list(config.getViews(display))
        self.view_combo.blockSignals(True)
        self.view_combo.clear()
        self.view_combo.addItems(views)
        self.view_combo.setCurrentText(keep if keep in views else config.getDefaultView(display))
        self.view_combo.blockSignals(False)

    def chosen_view(self) -> ViewTransform:
        """The view transform the fields describe, over the scene's working space."""
        return dataclasses.replace(
            self.view, _resolved=False, display=self.display_combo.currentText(),
            view=self.view_combo.currentText(), looks=self.look_combo.currentData() or "",
            exposure_stops=self.exposure_spin.value(), contrast=self.contrast_spin.value(),
            working_space=self.doc.scene.render.working_space).resolved()

    def _browse(self) -> None:
        name, _ = QFileDialog.getSaveFileName(self, "Export image", self.path_edit.text(),
                                              "Images (*.exr *.png *.tif *.tiff *.jpg *.jpeg);;OpenEXR (*.exr);;"
                                              "PNG (*.png);;TIFF (*.tif *.tiff);;JPEG (*.jpg *.jpeg)")
        if name:
            if not _suffix(name):
                name += self.format_combo.currentData()
            self.path_edit.setText(name)

    def _format_chosen(self, _index: int) -> None:
        path = Path(self.path_edit.text())
        suffix = self.format_combo.currentData()
        if path.suffix.lower() != suffix:
            self.path_edit.setText(str(path.with_suffix(suffix)))

    def _path_edited(self, text: str) -> None:
        suffix = Path(text).suffix.lower()
        suffix = _suffix(text) or suffix
        for i, (_label, s) in enumerate(FORMATS):
            if s == suffix and self.format_combo.currentIndex() != i:
                self.format_combo.blockSignals(True)
                self.format_combo.setCurrentIndex(i)
                self.format_combo.blockSignals(False)
        png = suffix != ".exr"  # a picture: made through the view transform
        for widget in (self.display_combo, self.view_combo, self.look_combo, self.exposure_spin, self.contrast_spin):
            widget.setEnabled(png)
        self._update_estimate()  # a complaint about the previous path no longer applies

    def _width_changed(self, w: int) -> None:
        if self.lock_aspect.isChecked():
            self.height_spin.blockSignals(True)
            self.height_spin.setValue(max(1, round(w / self._aspect)))
            self.height_spin.blockSignals(False)
        self._update_estimate()

    def _height_changed(self, h: int) -> None:
        if self.lock_aspect.isChecked():
            self.width_spin.blockSignals(True)
            self.width_spin.setValue(max(1, round(h * self._aspect)))
            self.width_spin.blockSignals(False)
        self._update_estimate()

    def _scale_size(self, factor: float) -> None:
        w, h = self.doc.scene.camera.resolution
        self.width_spin.blockSignals(True)
        self.height_spin.blockSignals(True)
        self.width_spin.setValue(max(1, round(w * factor)))
        self.height_spin.setValue(max(1, round(h * factor)))
        self.width_spin.blockSignals(False)
        self.height_spin.blockSignals(False)
        self._update_estimate()

    def _update_estimate(self, *_args) -> None:
        w, h = self.width_spin.value(), self.height_spin.value()
        if self.by_samples.isChecked():
            seconds = estimate_seconds(w, h, self.spp_spin.value(), self.rate)
            if seconds is None:
                self.estimate.setText("")
            else:
                self.estimate.setText(f"About {_duration(seconds)} at the viewport's {rate_text(self.rate)}.")
        else:
            self.estimate.setText("Renders as many samples as fit in the time, at least one per pixel.")

    # -- result -----------------------------------------------------------------------------------------------------
    def request(self) -> ExportRequest:
        scene = copy_scene(self.doc.scene)
        scene.camera = dataclasses.replace(scene.camera, resolution=(self.width_spin.value(), self.height_spin.value()))
        by_samples = self.by_samples.isChecked()
        return ExportRequest(
            scene=scene, path=Path(self.path_edit.text()).expanduser(),
            target_spp=self.spp_spin.value() if by_samples else None,
            seconds=None if by_samples else self.seconds_spin.value(),
            view=self.chosen_view(), denoise=self.denoise_check.isChecked(),
        )

    def validate(self) -> str | None:
        path = Path(self.path_edit.text()).expanduser()
        if not _suffix(path):
            return f"{path.name}: choose a .exr, .png, .tif or .jpg file name"
        return export_problem(path, self.width_spin.value(), self.height_spin.value(), self.denoise_check.isChecked())

    def accept(self) -> None:
        problem = self.validate()
        if problem:
            self.estimate.setText(f"<span style='color:#f0a080'>{problem}</span>")
            return
        super().accept()


def _suffix(path) -> str | None:
    """The format's suffix of a file name (``.tiff`` is ``.tif``), None for one the writer does not take."""
    suffix = Path(path).suffix.lower()
    suffix = SUFFIX_ALIASES.get(suffix, suffix)
    return suffix if suffix in {s for _label, s in FORMATS} else None


def _duration(seconds: float) -> str:
    if seconds < 1:
        return "a second"
    if seconds < 90:
        return f"{math.ceil(seconds)} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


__all__ = ["ExportDialog", "default_export_path", "estimate_seconds", "export_problem", "Qt"]
