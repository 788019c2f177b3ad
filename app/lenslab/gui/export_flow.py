"""Exporting from the studio: the export dialog, the export started (and cancelled) through the render controller,
its progress in a window-modal progress dialog, and the finished, failed or cancelled message at the end."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QObject, Qt
from PySide6.QtWidgets import QMainWindow, QMessageBox, QProgressDialog

from lenslab.gui.controller import RenderController, elapsed_text, rate_text
from lenslab.gui.export_dialog import ExportDialog, default_export_path


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
        self.last_path: Path | None = None
        self.closing = False  # the window is closing: a failure is not worth a message box
        controller.export_progress.connect(self._progress)
        controller.export_finished.connect(self._finished)
        controller.export_failed.connect(self._failed)
        controller.export_cancelled.connect(self._cancelled)

    @property
    def running(self) -> bool:
        return self.export_id is not None

    def open_dialog(self) -> None:
        if self.export_id is not None:
            return
        window, viewport = self.window, self.window.viewport
        frame = self.controller.last_frame
        folder = self.folders.last_folder("images")
        last = self.last_path or (folder / default_export_path(window.doc).name if folder else None)
        dialog = self.make_dialog(window.doc, viewport.exposure, viewport.tone_map,
                                  frame.samples_per_second if frame else None, last, window)
        if dialog.exec() == ExportDialog.Accepted:
            self.start(dialog.request())

    def start(self, request) -> int:
        self.last_path = Path(request.path)
        self.folders.remember_folder("images", request.path)
        self.export_id = self.controller.start_export(request)
        w, h = request.scene.camera.resolution
        dialog = QProgressDialog(f"Rendering {w}×{h} to {Path(request.path).name}…", "Cancel", 0, 1000, self.window)
        dialog.setObjectName("exportProgress")
        dialog.setWindowTitle("Export")
        dialog.setWindowModality(Qt.WindowModal)
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
        if dialog is not None:
            dialog.canceled.disconnect(self.cancel)
            dialog.close()
            dialog.deleteLater()

    def _finished(self, request_id: int, path: str) -> None:
        if request_id != self.export_id:
            return
        self._close_progress_dialog()
        self.window.statusBar().showMessage(f"Exported {path}", 8000)

    def _failed(self, request_id: int, message: str) -> None:
        if request_id != self.export_id:
            return
        self._close_progress_dialog()
        if not self.closing:
            QMessageBox.critical(self.window, "Export failed", message)

    def _cancelled(self, request_id: int) -> None:
        if request_id != self.export_id:
            return
        self._close_progress_dialog()
        self.window.statusBar().showMessage("Export cancelled: nothing was written", 5000)


__all__ = ["ExportFlow"]
