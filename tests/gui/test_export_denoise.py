"""The export dialog's Denoise checkbox: off unless ticked, carried by the ExportRequest to the render job's writer."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

pytest.importorskip("pyoidn")


def test_the_denoise_checkbox_is_off_by_default_and_reaches_the_request(window, tmp_path):
    from lenslab.gui.export_dialog import ExportDialog

    dialog = ExportDialog(window.doc, window.viewport.view, samples_per_second=1e5)
    dialog.path_edit.setText(str(tmp_path / "a.exr"))
    assert not dialog.denoise_check.isChecked()
    assert dialog.request().denoise is False  # never denoised unless asked
    dialog.denoise_check.setChecked(True)
    assert dialog.request().denoise is True


@pytest.mark.smoke
def test_a_denoised_export_writes_the_noisy_image_and_the_guides_as_layers(qtbot, window, tmp_path):
    import OpenImageIO as oiio

    from lenslab.gui.document import copy_scene
    from lenslab.gui.worker import ExportRequest
    from lenslab.render.film import read_image

    scene = copy_scene(window.doc.scene)
    scene.camera = dataclasses.replace(scene.camera, resolution=(32, 24))
    out = tmp_path / "shot.exr"
    with qtbot.waitSignal(window.controller.export_finished, timeout=60000) as done:
        window.start_export(ExportRequest(scene=scene, path=Path(out), target_spp=2, denoise=True))
    assert done.args[1] == str(out)
    image = oiio.ImageInput.open(str(out))
    names = set(image.spec().channelnames)
    image.close()
    assert {"noisy.R", "albedo.G", "normal.Z"} <= names
    assert read_image(out)[1]["lenslab:Denoised"] == 1
