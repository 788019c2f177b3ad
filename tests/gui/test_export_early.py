"""Export that fails early: a folder that cannot take the file, or has no room for it, is refused before anything
renders, in a message naming the folder and the problem; only a written export makes its folder the next one's;
and closing the window during an export asks what to do with it, instead of the close being lost or the export
dropped without a word.

The tests may run as root, whom permission bits do not stop, so a folder that refuses files is one whose probe
(our temporary file, as the writer makes it) is refused, and a full disk is shutil.disk_usage saying so."""

from __future__ import annotations

import dataclasses
import errno
import os
import re
import shutil
import tempfile
import types
from pathlib import Path

import pytest
from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication, QMessageBox

from tests.gui.helpers import wait_for_frame

pytestmark = pytest.mark.gl


def export_request(window, path, size=(32, 24), **kwargs):
    from lenslab.gui.document import copy_scene
    from lenslab.gui.worker import ExportRequest

    scene = copy_scene(window.doc.scene)
    scene.camera = dataclasses.replace(scene.camera, resolution=size)
    return ExportRequest(scene=scene, path=Path(path), **kwargs)


def record_error_boxes(monkeypatch) -> list[str]:
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "critical", staticmethod(lambda _parent, _title, text, *_a: shown.append(text)))
    return shown


def refuse_files_in(monkeypatch, folder: Path) -> None:
    """``folder`` refuses new files, as a read-only mount does, for root too: making a temporary file there fails."""
    make = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and Path(dir) == folder:
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(folder))
        return make(*args, dir=dir, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)


def leave_free(monkeypatch, folder: Path, free: int) -> None:
    usage = shutil.disk_usage

    def disk_usage(path):
        if Path(path) == folder:
            return types.SimpleNamespace(total=free * 10, used=free * 9, free=free)
        return usage(path)

    monkeypatch.setattr(shutil, "disk_usage", disk_usage)


# -- the checks themselves, without a window ----------------------------------------------------------------------
def test_the_size_estimate_counts_pixels_channels_bytes_and_the_denoise_layers():
    from lenslab.render.film import HEADER_ALLOWANCE_BYTES
    from lenslab.render.job import estimated_export_bytes

    assert estimated_export_bytes("a.png", 100, 50) == 100 * 50 * 3 + HEADER_ALLOWANCE_BYTES  # 8-bit RGB
    assert estimated_export_bytes("a.exr", 100, 50) == 100 * 50 * 3 * 4 + HEADER_ALLOWANCE_BYTES  # float RGB
    # Denoised: noisy, albedo and normal beside the image in an EXR; a PNG has no room for them.
    assert estimated_export_bytes("a.exr", 100, 50, denoise=True) == 100 * 50 * 12 * 4 + HEADER_ALLOWANCE_BYTES
    assert estimated_export_bytes("a.png", 100, 50, denoise=True) == 100 * 50 * 3 + HEADER_ALLOWANCE_BYTES


def test_the_folder_check_names_the_file_the_folder_and_the_problem_and_leaves_nothing(tmp_path, monkeypatch):
    from lenslab.atomic import WriteFailed, check_output_folder

    check_output_folder(tmp_path / "fine.png", 1000)
    assert list(tmp_path.iterdir()) == []  # the probe is gone
    (tmp_path / "file.txt").write_text("")
    with pytest.raises(WriteFailed, match=re.escape(f"{tmp_path / 'file.txt'} is a file, not a folder")):
        check_output_folder(tmp_path / "file.txt" / "shot.png")
    with pytest.raises(WriteFailed, match="does not exist"):
        check_output_folder(tmp_path / "missing" / "shot.png")
    locked = tmp_path / "locked"
    locked.mkdir()
    refuse_files_in(monkeypatch, locked)
    with pytest.raises(WriteFailed, match=re.escape(f"cannot write in {locked} (Permission denied)")):
        check_output_folder(locked / "shot.png")
    leave_free(monkeypatch, tmp_path, 3 << 20)
    with pytest.raises(WriteFailed, match=re.escape(f"not enough space in {tmp_path}: the file needs about 8.0 MiB, "
                                                    f"3.0 MiB is free")):
        check_output_folder(tmp_path / "big.exr", 8 << 20)
    check_output_folder(tmp_path / "small.exr", 2 << 20)


# -- in the studio ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("problem", ["refuses files", "is a file", "no room"])
def test_an_export_the_folder_cannot_take_fails_at_once_without_rendering(window, tmp_path, monkeypatch, problem):
    earlier = tmp_path / "earlier"
    earlier.mkdir()
    window.files.remember_folder("images", earlier / "shot.png")
    folder = tmp_path / "target"
    folder.mkdir()
    if problem == "refuses files":
        refuse_files_in(monkeypatch, folder)
        expected = f"cannot write in {folder} (Permission denied)"
    elif problem == "is a file":
        folder = tmp_path / "a file"
        folder.write_text("")
        expected = f"{folder} is a file, not a folder"
    else:
        leave_free(monkeypatch, folder, 10_000)
        expected = f"not enough space in {folder}"
    shown = record_error_boxes(monkeypatch)
    started = []
    monkeypatch.setattr(window.controller, "start_export", lambda request: started.append(request) or 1)

    result = window.start_export(export_request(window, folder / "shot.exr", target_spp=64))

    assert started == [] and result is None  # refused before any render started (not timed: no test needs an idle machine)
    assert len(shown) == 1 and expected in shown[0] and str(folder / "shot.exr") in shown[0]
    assert window.export_progress_dialog is None and window.export_id is None
    assert window.files.last_folder("images") == earlier  # the next export does not start there
    assert window.export_flow.last_path is None


def test_the_export_dialog_refuses_such_a_folder_and_stays_open(window, tmp_path, monkeypatch):
    from lenslab.gui.export_dialog import ExportDialog

    folder = tmp_path / "locked"
    folder.mkdir()
    refuse_files_in(monkeypatch, folder)
    dialog = ExportDialog(window.doc, window.viewport.view)
    dialog.path_edit.setText(str(folder / "shot.png"))
    dialog.accept()  # refused, with the reason under the settings: the path can be fixed in place
    assert dialog.result() != ExportDialog.Accepted
    assert f"cannot write in {folder} (Permission denied)" in dialog.estimate.text()
    leave_free(monkeypatch, tmp_path, 1 << 20)
    dialog.path_edit.setText(str(tmp_path / "shot.exr"))
    dialog.width_spin.setValue(1000)  # 1000 x 750 float RGB: about 8.6 MiB
    assert "not enough space" in dialog.validate()
    dialog.width_spin.setValue(200)
    assert dialog.validate() is None
    not_a_folder = tmp_path / "notes.txt"
    not_a_folder.write_text("a file where a folder is named")
    dialog.path_edit.setText(str(not_a_folder / "shot.png"))
    assert f"{not_a_folder} is a file, not a folder" in dialog.validate()  # not "does not exist": it does


def test_only_a_written_export_makes_its_folder_the_next_ones(qtbot, window, tmp_path, monkeypatch):
    from lenslab.render.film import ExportError
    from lenslab.render.job import RenderJob

    earlier, failing, good = (tmp_path / name for name in ("earlier", "failing", "good"))
    for folder in (earlier, failing, good):
        folder.mkdir()
    window.files.remember_folder("images", earlier / "shot.png")
    shown = record_error_boxes(monkeypatch)
    write = RenderJob.write

    def full_disk(job, path, **kwargs):
        if Path(path).parent == failing:
            raise ExportError(f"{path}: cannot write the image (No space left on device)")
        return write(job, path, **kwargs)

    monkeypatch.setattr(RenderJob, "write", full_disk)  # the disk fills while the picture renders
    with qtbot.waitSignal(window.controller.export_failed, timeout=30000):
        window.start_export(export_request(window, failing / "shot.png", target_spp=1))
    assert shown and "No space left on device" in shown[0]
    assert window.files.last_folder("images") == earlier
    assert window.export_flow.last_path is None

    with qtbot.waitSignal(window.controller.export_finished, timeout=30000):
        window.start_export(export_request(window, good / "shot.png", target_spp=1))
    assert window.files.last_folder("images") == good
    assert window.export_flow.last_path == good / "shot.png"


# -- closing during an export -------------------------------------------------------------------------------------
def answer_export_question(window, button, tries: int = 250) -> list[str]:
    """Click ``button`` on the question a close asks during an export, once it is asked (given up after ~5 s)."""
    seen: list[str] = []

    def answer(left: int = tries):
        box = getattr(window.export_flow, "close_box", None)
        if box is None:
            if left:
                QTimer.singleShot(20, lambda: answer(left - 1))
            return
        seen.append(box.text())
        box.button(button).click()

    QTimer.singleShot(0, answer)
    return seen


def start_long_export(qtbot, window, path, **kwargs):
    window.start_export(export_request(window, path, **kwargs))
    qtbot.waitSignal(window.controller.export_progress, timeout=20000).wait()


def test_the_window_still_hears_a_close_while_exporting(qtbot, window, tmp_path):
    """A window blocked by a modal dialog never hears the window manager's close button (Qt drops it): the export's
    progress dialog must leave the window free."""
    start_long_export(qtbot, window, tmp_path / "never.exr", target_spp=1_000_000)
    assert window.export_progress_dialog is not None and window.export_progress_dialog.isVisible()
    assert QApplication.activeModalWidget() is None
    seen = answer_export_question(window, QMessageBox.Discard)
    assert window.close()
    assert seen


def test_closing_during_an_export_asks_and_keep_the_window_keeps_both(qtbot, window, tmp_path):
    out = tmp_path / "never.exr"
    start_long_export(qtbot, window, out, target_spp=1_000_000)
    seen = answer_export_question(window, QMessageBox.Cancel)  # Keep Window Open
    assert not window.close()
    assert seen and "never.exr" in seen[0]
    assert window.isVisible() and window.export_id is not None  # the export goes on
    with qtbot.waitSignal(window.controller.export_progress, timeout=20000):
        pass

    seen = answer_export_question(window, QMessageBox.Discard)  # Stop Export and Close
    assert window.close()
    assert seen and window.controller.worker.isFinished()
    assert not out.exists()


def test_closing_during_an_export_can_wait_for_it_to_be_written(qtbot, window, tmp_path):
    out = tmp_path / "awaited.png"
    wait_for_frame(qtbot, window)  # a window that has settled, as a user's is when they export
    # An export that does not end by itself, so that the question is surely answered while it runs (with a time
    # limit, a loaded machine once took longer to answer than the export took to finish).
    start_long_export(qtbot, window, out, target_spp=1_000_000)
    seen = answer_export_question(window, QMessageBox.Ok)  # Close When Done
    assert not window.close()  # not yet: the export goes on
    assert seen and window.isVisible() and window.export_id is not None
    with qtbot.waitSignal(window.closed, timeout=30000):
        # Now let it end: its job's time is up once every pixel has a sample (a number the render thread reads at
        # its next step), and the file is written as any export's is.
        window.controller.worker._loop._export.job.time_limit = 0.0
    assert out.is_file() and not window.isVisible()


def test_the_window_hears_an_exports_progress_while_it_renders(qtbot, window, tmp_path):
    """The render thread holds the interpreter for a whole dispatch: a Python filter on every event of the
    application (a wheel guard once was one) made the window wait for each, and the export's progress reached it
    only when the export was over. It must arrive while the export still runs."""
    window.start_export(export_request(window, tmp_path / "long.exr", seconds=30.0))
    with qtbot.waitSignal(window.controller.export_progress, timeout=12000):
        pass
    assert window.export_id is not None  # still rendering: the progress came while it ran
    window.export_flow.cancel()
    qtbot.waitSignal(window.controller.export_cancelled, timeout=20000).wait()
