"""The render as the window shows it: each frame into the viewport (its picture, the export's gate, the render
region), the depth buffer, the status bar's sample count, progress, rate, elapsed time and device, the
viewport's corner tags (paused, done, denoised; the camera the picture was rendered with), the work banner
while the picture is not the latest edit's, and the render's errors."""

from __future__ import annotations

from PySide6.QtCore import QObject, QRectF
from PySide6.QtWidgets import QLabel, QMainWindow, QProgressBar

from lenslab.gui import theme
from lenslab.gui.controller import RenderController, elapsed_text, rate_text, samples_text
from lenslab.gui.viewport import Viewport
from lenslab.gui.work_banner import WorkBanner


class RenderStatus(QObject):
    """The controller's frames, depth buffers, device and errors shown in the window's viewport and status bar
    (whose permanent labels it adds)."""

    def __init__(self, window: QMainWindow, viewport: Viewport, controller: RenderController):
        super().__init__(window)
        self.window = window
        self.viewport = viewport
        self.controller = controller
        status = window.statusBar()
        self.spp_label = QLabel("—")
        self.spp_label.setObjectName("sppLabel")
        self.progress_bar = QProgressBar()
        self.progress_bar.setFixedWidth(120)
        self.progress_bar.setTextVisible(False)
        self.progress_bar.setRange(0, 1000)
        self.rate_label = QLabel("")
        self.elapsed_label = QLabel("")
        self.device_label = QLabel("starting renderer…")
        self.device_label.setObjectName("deviceLabel")
        for widget in (self.spp_label, self.progress_bar, self.rate_label, self.elapsed_label, self.device_label):
            status.addPermanentWidget(widget)
        self.work_banner = WorkBanner(viewport, controller, self)

    def show_frame(self, frame) -> None:
        export_pixels = self.controller.quality == "export"
        self.viewport.fit_margin = 24 if export_pixels else 0
        self.viewport.gate_rect = QRectF(*frame.gate) if frame.gate is not None and not export_pixels else None
        self.viewport.region_rect = QRectF(*frame.region) if frame.region is not None else None
        self.viewport.worth_judging = frame.worth_judging
        self.viewport.set_frame(frame.display, frame.view, frame.image,
                                frame.exposure.scale if frame.exposure is not None else 1.0)
        self.spp_label.setText(samples_text(frame))
        if frame.target_spp:
            self.progress_bar.setValue(round(1000 * min(1.0, frame.samples_per_pixel / frame.target_spp)))
        self.progress_bar.setVisible(bool(frame.target_spp))
        self.rate_label.setText(rate_text(frame.samples_per_second) if frame.samples_per_second else "")
        self.elapsed_label.setText(elapsed_text(frame.elapsed_seconds))
        self.update_corner_state(frame)
        self.window.update_camera_tag()

    def set_paused(self, paused: bool) -> None:
        """Pause or resume the viewport's render: the pause action and the corner tag say which."""
        self.controller.set_paused(bool(paused))
        pause = self.window.actions["pause"]
        pause.setIcon(theme.icon("play" if paused else "pause"))
        pause.setText("Resume Rendering" if paused else "Pause Rendering")
        self.update_corner_state(self.controller.last_frame)

    def update_corner_state(self, frame) -> None:
        """The viewport's corner tag: the status bar's sample count (one text for both, so they never disagree),
        and whether the render is paused or done and the picture denoised."""
        if frame is None:
            return
        state = [samples_text(frame)]
        if self.controller.paused:
            state.append("paused")
        elif frame.converged:
            state.append("done")
        if frame.denoised:
            state.append("denoised")
        self.viewport.status_text = " · ".join(state)
        self.viewport.update()

    def show_gbuffer(self, gbuffer) -> None:
        self.viewport.set_gbuffer(gbuffer)

    def show_device(self, info: dict) -> None:
        self.device_label.setText(info.get("renderer", "GPU"))
        self.device_label.setToolTip("\n".join(f"{k}: {v}" for k, v in info.items()))

    def show_error(self, message: str) -> None:
        self.viewport.message = message
        self.viewport.update()
        if message:
            self.window.statusBar().showMessage(message, 8000)
        if self.controller.device_error:
            self.device_label.setText("no GPU")


__all__ = ["RenderStatus"]
