"""The camera panel's iris and bokeh section: the blades, their rotation and curvature, the anamorphic squeeze, the
barrel's clipping (cat's eye) and an image of the stop. The last three are the thin lens's stand-ins for what glass
does: with a real lens mounted they step aside."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtWidgets import QFileDialog, QGridLayout, QHBoxLayout, QLabel, QPushButton, QToolButton, QWidget

from lenslab.gui.camera_panel.section import CameraSection
from lenslab.gui.widgets import IntEdit, NumberEdit, hint
from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.editing import file_reference
from lenslab.scene.fields import control_range

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel


class BokehSection(CameraSection):
    """The iris's shape and the lens's optical quirks: what the out-of-focus highlights look like."""

    def __init__(self, panel: CameraPanel):
        super().__init__(panel, "bokeh", "Iris and bokeh")
        grid = QGridLayout()
        grid.setHorizontalSpacing(6)
        self.blades = IntEdit(*control_range(ThinLensCamera, "aperture_blades"))
        self.blades.setSpecialValueText("round")
        self.blades.setToolTip("Number of aperture blades: round (0) or 3 to 32. Shapes the bokeh.")
        self.blades.edited.connect(self._blades_edited)
        self.rotation = NumberEdit(*control_range(ThinLensCamera, "blade_rotation_deg"), decimals=1, step=1.0,
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
        self.labels: dict[QWidget, QLabel] = {}
        for i, (label, widget) in enumerate((("Blades", self.blades), ("Rotation", self.rotation),
                                             ("Curvature", self.curvature), ("Squeeze", self.squeeze),
                                             ("Cat's eye", self.barrel))):
            text = QLabel(label)
            text.setToolTip(widget.toolTip())
            self.labels[widget] = text
            grid.addWidget(text, i // 2, (i % 2) * 2)
            grid.addWidget(widget, i // 2, (i % 2) * 2 + 1)
        grid.setColumnStretch(1, 1)
        grid.setColumnStretch(3, 1)
        self.add(grid)
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
        self.add(image_row)
        # The thin lens's stand-ins for what glass does, and what each says while a real lens does it instead.
        self.thin_lens_only = {widget: widget.toolTip() for widget in (
            self.squeeze, self.barrel, self.aperture_image_button, self.aperture_image_clear)}

    def _camera_number(self, field: str, undo_text: str, decimals: int, step: float, tip: str) -> NumberEdit:
        """A number field that edits one of the camera's fields, within the range the field declares."""
        edit = NumberEdit(*control_range(ThinLensCamera, field), decimals=decimals, step=step)
        edit.setToolTip(tip)
        edit.edited.connect(lambda v, merge: self.doc.set_camera(f"{undo_text} {v:g}", merge, **{field: float(v)}))
        return edit

    # -- edits ----------------------------------------------------------------------------------------------------
    def _blades_edited(self, value: int, merge: bool) -> None:
        current = self.doc.scene.camera.aperture_blades
        if value in (1, 2):  # not a polygon: jump over, in the direction of travel
            value = 3 if current < value else 0
            self.blades.set_quietly(value)
        self.doc.set_camera(f"Aperture blades {value}" if value else "Round aperture", merge,
                            aperture_blades=int(value))

    def set_aperture_image(self, path: str) -> None:
        """Use the image at ``path`` as the stop ("" for the blades); a missing or black image is refused with a
        message, and the camera keeps its stop."""
        if path:
            from lenslab.scene.aperture_images import resolve

            trial = ThinLensCamera(aperture_image=path)
            try:
                trial.aperture(self.doc.scene.base_dir())
            except (ValueError, OSError) as exc:
                self.panel.status_message.emit(f"Aperture image not used: {exc}")
                self.panel.refresh()
                return
            # Named relative to the scene file, as meshes are (absolute while the scene has no file).
            path = file_reference(resolve(path, self.doc.scene.base_dir()), self.doc.path)
        self.doc.set_camera(f"Aperture image {Path(path).name}" if path else "No aperture image", False,
                            aperture_image=path)

    def _choose_aperture_image(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.panel, "Aperture image", str(self.doc.scene.base_dir()),
                                              "Images (*.png *.jpg *.jpeg *.exr *.hdr *.tif *.tiff)")
        if path:
            self.set_aperture_image(path)

    # -- following the document ---------------------------------------------------------------------------------
    def refresh(self, cam: ThinLensCamera) -> None:
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
        self._show_glass_takes_over(cam.real_lens)

    def _show_glass_takes_over(self, real_lens: str) -> None:
        """With a real lens mounted its glass makes the cat's eye, the vignetting and the stop's image: the thin
        lens's stand-ins for them step aside (the camera refuses them, ThinLensCamera.validate), and say why."""
        glass = lens_display_name(real_lens)
        for widget, thin_tip in self.thin_lens_only.items():
            tip = (f"{glass} is traced through its glass, which makes its own bokeh, cat's eye and vignetting: "
                   f"this thin-lens control does not apply (choose Free or a thin-lens preset to use it)"
                   if real_lens else thin_tip)
            widget.setToolTip(tip)
            if real_lens:
                widget.setEnabled(False)
            elif widget is not self.aperture_image_clear:  # enabled above, while there is an image to clear
                widget.setEnabled(True)
            if widget in self.labels:
                self.labels[widget].setEnabled(not real_lens)
                self.labels[widget].setToolTip(tip)


def lens_display_name(real_lens: str) -> str:
    """A camera's ``real_lens`` as a sentence names it: a preset's name, or a lens file's name without its folder."""
    from lenslab.optics.real_lenses import names_a_file

    return f"The {Path(real_lens).stem}" if names_a_file(real_lens) else f"The {real_lens}"
