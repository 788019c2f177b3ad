"""Exporting from the studio: the export dialog, the output folder checked before anything renders, the export
started (and cancelled) through the render controller, its progress in a progress dialog, the finished, failed or
cancelled message at the end, and the question a window closed during an export asks."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QObject, Qt, QTimer
from PySide6.QtWidgets import QMainWindow, QMessageBox, QProgressDialog

from lenslab.gui.controller import RenderController, elapsed_text, rate_text
from lenslab.gui.export_dialog import ExportDialog, default_export_path, export_problem


class ExportFlow(QObject):
    """One export at a time, for the window (the dialogs' parent, its status bar the messages'). ``folders`` is
    what remembers the last folder of each kind of file (the window's file controller); ``make_dialog`` makes
    the export dialog (ExportDialog's arguments)."""

    def __init__(self, window: QMainWindow, controller: RenderController, folders,
                 make_dialog: Callable[..., ExportDialog] = ExportDialog):
        super().__init__(window)
        self.window = window
        self.controller = controller
        self.folders = folders
        self.make_dialog = make_dialog
        self.export_id: int | None = None
        self.progress_dialog: QProgressDialog | None = None
        self.last_path: Path | None = None  # the last export written: where the next dialog starts
        self.running_path: Path | None = None
        self.closing = False  # the window is closing: a failure is not worth a message box
        self.close_when_done = False  # the window was closed during the export and waits for it
        self.close_box: QMessageBox | None = None  # the question, while it is asked (tests answer it)
        controller.export_progress.connect(self._progress)
        controller.export_finished.connect(self._finished)
        controller.export_failed.connect(self._failed)
        controller.export_cancelled.connect(self._cancelled)

    @property
    def running(self) -> bool:
        return self.export_id is not None

    def open_dialog(self) -> None:
        if self.export_id is not None:  # one at a time: show the one running
            self.progress_dialog.raise_()
            self.progress_dialog.activateWindow()
            return
        window, viewport = self.window, self.window.viewport
        frame = self.controller.last_frame
        folder = self.folders.last_folder("images")
        last = self.last_path or (folder / default_export_path(window.doc).name if folder else None)
        dialog = self.make_dialog(window.doc, viewport.view, frame.samples_per_second if frame else None, last,
                                  window)
        if dialog.exec() == ExportDialog.Accepted:
            self.start(dialog.request())

    def start(self, request) -> int | None:
        """Start rendering ``request``; its id, or None when its file could not be written (said in a message box),
        found out before the render rather than after it. The folder becomes the next export's only once the
        file is written."""
        w, h = request.scene.camera.resolution
        problem = export_problem(Path(request.path), w, h, request.denoise)
        if problem:
            if not self.closing:
                QMessageBox.critical(self.window, "Cannot export", problem)
            return None
        self.running_path = Path(request.path)
        self.export_id = self.controller.start_export(request)
        dialog = QProgressDialog(f"Rendering {w}×{h} to {Path(request.path).name}…", "Cancel", 0, 1000, self.window)
        dialog.setObjectName("exportProgress")
        dialog.setWindowTitle("Export")
        # Not modal: a window blocked by a modal dialog never hears the window manager's close, and the close
        # would be dropped without a word; it asks about the export instead (may_close).
        dialog.setWindowModality(Qt.NonModal)
        dialog.setMinimumDuration(0)
        dialog.setAutoClose(False)
        dialog.setAutoReset(False)
        dialog.setValue(0)
        dialog.canceled.connect(self.cancel)
        self.progress_dialog = dialog
        dialog.show()
        return self.export_id

    def cancel(self) -> None:
        if self.export_id is not None:
            self.controller.cancel_export(self.export_id)

    def may_close(self) -> bool:
        """Whether the window may close now. During an export it asks: close once the file is written (the window
        stays until then), stop the export and close, or keep the window. Stopping is left to the window, after
        its other questions (unsaved changes), so that cancelling one of those keeps the export too."""
        if not self.running:
            return True
        box = QMessageBox(QMessageBox.Question, "Export in progress",
                          f"“{self.running_path.name}” is still being rendered.",
                          QMessageBox.Ok | QMessageBox.Discard | QMessageBox.Cancel, self.window)
        box.setInformativeText("Close the window once the export is written, or stop the export (nothing is "
                               "written) and close now?")
        box.button(QMessageBox.Ok).setText("Close When Done")
        box.button(QMessageBox.Discard).setText("Stop Export and Close")
        box.button(QMessageBox.Cancel).setText("Keep Window Open")
        box.setDefaultButton(QMessageBox.Ok)
        box.setEscapeButton(QMessageBox.Cancel)
        box.setObjectName("exportRunningBox")
        self.close_box = box
        try:
            answer = box.exec()
        finally:
            self.close_box = None
        if answer == QMessageBox.Ok and not self.running:  # it ended while the question was open
            return True
        self.close_when_done = answer == QMessageBox.Ok
        if self.close_when_done:
            self.window.statusBar().showMessage("The window will close once the export is written")
        return answer == QMessageBox.Discard

    def _progress(self, update) -> None:
        dialog = self.progress_dialog
        if dialog is None or update.request_id != self.export_id:
            return
        progress = update.progress
        dialog.setValue(round(progress.fraction * 1000))
        goal = f" / {progress.target_spp}" if progress.target_spp else ""
        limit = f" of {elapsed_text(progress.time_limit)}" if progress.time_limit else ""
        remaining = ""
        if 0.02 < progress.fraction < 1:
            remaining = f" · about {elapsed_text(progress.elapsed_seconds * (1 - progress.fraction) / progress.fraction)} left"
        dialog.setLabelText(f"{progress.samples_per_pixel}{goal} spp · {elapsed_text(progress.elapsed_seconds)}{limit}"
                            f"{remaining} · {rate_text(progress.samples_per_second)}")

    def _close_progress_dialog(self) -> None:
        dialog = self.progress_dialog
        self.progress_dialog = None
        self.export_id = None
        self.running_path = None
        if dialog is not None:
            dialog.canceled.disconnect(self.cancel)
            dialog.close()
            dialog.deleteLater()

    def _finished(self, request_id: int, path: str) -> None:
        if request_id != self.export_id:
            return
        self.last_path = Path(path)
        self.folders.remember_folder("images", path)
        self._close_progress_dialog()
        self.window.statusBar().showMessage(f"Exported {path}", 8000)
        if self.close_when_done:
            self.close_when_done = False
            QTimer.singleShot(0, self.window.close)  # once this signal's other slots have seen the export end

    def _failed(self, request_id: int, message: str) -> None:
        if request_id != self.export_id:
            return
        self.close_when_done = False  # the user hears why, in the window they meant to close
        self._close_progress_dialog()
        if not self.closing:
            QMessageBox.critical(self.window, "Export failed", message)

    def _cancelled(self, request_id: int) -> None:
        if request_id != self.export_id:
            return
        self.close_when_done = False
        self._close_progress_dialog()
        self.window.statusBar().showMessage("Export cancelled: nothing was written", 5000)


__all__ = ["ExportFlow"]
