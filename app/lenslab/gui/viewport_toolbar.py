"""The viewport's toolbar: the tools, fit and the zoom, the display exposure (a slider, a field and a reset, one
setting), the view transform's button (it names the display and view, and opens the View, Display and Look menus
and the contrast: :mod:`.display_view`), the viewport's resolution, the denoiser, the sample limit, pause and
restart. The display settings change what the picture looks like, never what is rendered.

Where the window is too narrow for all of it, the toolbar's extension button (») at its right end opens it into
more rows over the top of the picture (:func:`under_toolbar`)."""

from __future__ import annotations

from PySide6.QtCore import QObject, QSize, Qt
from PySide6.QtGui import QAction, QFontMetrics
from PySide6.QtWidgets import QComboBox, QLabel, QMainWindow, QMenu, QSizePolicy, QToolBar, QToolButton, QWidget

from lenslab.gui import theme
from lenslab.gui.controller import SAMPLE_LIMITS, RenderController
from lenslab.gui.display_view import DISPLAY_EXPOSURE_STOPS, DisplayView, ViewMenus, saved_view
from lenslab.gui.viewport import Viewport
from lenslab.gui.widgets import ResetSlider, SignedNumberEdit

#: The view button's text is cut to this width (the whole of it is its tooltip).
VIEW_BUTTON_TEXT_PX = 130


class _Spacer(QWidget):
    """The room between the display controls and the render's: as wide as the bar leaves, and asking for none (a
    plain widget's size hint would push the bar's last controls behind its » first)."""

    def sizeHint(self) -> QSize:
        return QSize(0, 0)


def under_toolbar(bar: QToolBar, picture: QWidget) -> QMainWindow:
    """``picture`` with ``bar`` above it, in a QMainWindow of their own (a plain widget inside the window).

    A QToolBar hides what it has no room for behind its extension button; only in a QMainWindow does the button
    open the bar into more rows with every control in them. Anywhere else it opens a menu of the hidden actions,
    which leaves the boxes out (the resolution, the sample limit, the aspect ratio)."""
    host = QMainWindow()
    host.setObjectName("viewportArea")
    host.setWindowFlags(Qt.Widget)
    host.setAnimated(False)  # the extension opens and closes at once
    bar.setFloatable(False)
    bar.setContextMenuPolicy(Qt.PreventContextMenu)  # no menu to hide the bar with: nothing would bring it back
    host.addToolBar(Qt.TopToolBarArea, bar)
    host.setCentralWidget(picture)
    extension = bar.findChild(QToolButton, "qt_toolbar_ext_button")
    if extension is not None:  # the style's own arrow is drawn for light toolbars: nearly black on ours
        extension.setIcon(theme.icon("more"))
        extension.setToolTip("More of the toolbar: what the window has no room for")
    return host


class ViewportToolbar(QObject):
    """The toolbar above the viewport (``bar``, named "viewportBar") and what its own widgets do: the display
    exposure and the view transform go to ``display`` (the window's :class:`DisplayView`, which the viewport and
    the controller follow), the resolution and sample limit to the controller. The window's actions (tools, fit,
    denoise, pause, restart) are placed on it as they are."""

    def __init__(self, actions: dict[str, QAction], viewport: Viewport, controller: RenderController,
                 display: DisplayView, menus: ViewMenus, parent: QObject | None = None):
        super().__init__(parent)
        self.viewport = viewport
        self.controller = controller
        self.display = display
        self.menus = menus
        bar = self.bar = QToolBar()
        bar.setObjectName("viewportBar")
        bar.setMovable(False)
        bar.setIconSize(QSize(20, 20))  # compact: the whole bar fits beside the panels at the default window size
        for name in ("tool_select", "tool_focus", "tool_pan", "tool_region"):
            bar.addAction(actions[name])
        bar.addSeparator()
        bar.addAction(actions["fit"])
        self.zoom_label = QLabel("Fit")
        self.zoom_label.setObjectName("readout")
        self.zoom_label.setMinimumWidth(40)
        bar.addWidget(self.zoom_label)
        bar.addSeparator()
        exposure_label = QLabel("EV")
        exposure_label.setToolTip("Display exposure")
        bar.addWidget(exposure_label)
        # The slider, a field to type a value into (1.5 is +1.5 EV; the arrows step a tenth) and a reset to 0,
        # all three the same setting (display only).
        self.exposure_slider = ResetSlider(Qt.Horizontal, default=0)
        self.exposure_slider.setRange(round(-10 * DISPLAY_EXPOSURE_STOPS), round(10 * DISPLAY_EXPOSURE_STOPS))
        self.exposure_slider.setFixedWidth(64)
        self.exposure_slider.setValue(round(display.view.exposure_stops * 10))
        self.exposure_slider.setToolTip("Display exposure in stops (display only: the render is not restarted); "
                                        "double-click: back to 0")
        self.exposure_spin = SignedNumberEdit(-DISPLAY_EXPOSURE_STOPS, DISPLAY_EXPOSURE_STOPS, 1, 0.1, " EV")
        self.exposure_spin.setObjectName("displayExposure")
        self.exposure_spin.setFixedWidth(58)
        self.exposure_spin.setToolTip("Display exposure in stops: type a value (1.5 is +1.5 EV); the arrow keys "
                                      "and the wheel step a tenth")
        self.exposure_reset = QToolButton()
        self.exposure_reset.setObjectName("exposureReset")
        self.exposure_reset.setText("\u21ba")  # ↺
        self.exposure_reset.setStyleSheet("QToolButton { border: 1px solid #45464b; padding: 0px 2px; }"
                                          "QToolButton:disabled { color: #5c5e62; border-color: #38393c; }")
        self.exposure_reset.setToolTip("Display exposure back to 0 EV (or double-click the slider)")
        bar.addWidget(self.exposure_slider)
        bar.addWidget(self.exposure_spin)
        bar.addWidget(self.exposure_reset)
        # The view transform: the button names the display and view, its menu chooses them, the look and contrast.
        self.view_button = QToolButton()
        self.view_button.setObjectName("viewButton")
        self.view_button.setPopupMode(QToolButton.InstantPopup)
        self.view_button.setToolButtonStyle(Qt.ToolButtonTextOnly)
        self.view_menu = QMenu(self.view_button)
        self.view_menu.setObjectName("viewButtonMenu")
        self.view_menu.aboutToShow.connect(lambda: self.menus.fill_button_menu(self.view_menu))
        self.menus.fill_button_menu(self.view_menu)
        self.view_button.setMenu(self.view_menu)
        bar.addWidget(self.view_button)
        spacer = _Spacer()
        spacer.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        bar.addWidget(spacer)
        self.quality_combo = QComboBox()
        for name, label in (("auto", "Auto res"), ("full", "Full res"), ("half", "½ res"), ("quarter", "¼ res"),
                            ("export", "Export res")):
            self.quality_combo.addItem(label, name)
        self.quality_combo.setCurrentIndex(max(0, self.quality_combo.findData(self.controller.quality)))
        self.quality_combo.setToolTip("The viewport's resolution: a fraction of its own size in pixels (Auto: all "
                                      "of them on a GPU, at most 800 on the long side on the CPU), or the "
                                      "export's own pixels")
        bar.addWidget(self.quality_combo)
        bar.addAction(actions["denoise"])
        self.limit_combo = QComboBox()
        for spp in SAMPLE_LIMITS:
            self.limit_combo.addItem(f"{spp} spp" if spp else "∞ spp", spp)
        self.limit_combo.setCurrentIndex(max(0, self.limit_combo.findData(self.controller.target_spp)))
        self.limit_combo.setToolTip("The viewport stops refining at this many samples per pixel")
        bar.addWidget(self.limit_combo)
        bar.addAction(actions["pause"])
        bar.addAction(actions["restart"])
        self._update_exposure_label()
        self._update_view_button()
        display.changed.connect(self._view_changed)
        v = viewport
        v.zoom_changed.connect(lambda s: self.zoom_label.setText("Fit" if v.zoom is None else f"{s * 100:.0f}%"))
        self.exposure_slider.valueChanged.connect(lambda tenths: self.set_display_exposure(tenths / 10))
        self.exposure_spin.valueChanged.connect(self.set_display_exposure)
        self.exposure_reset.clicked.connect(lambda: self.set_display_exposure(0.0))
        self.quality_combo.currentIndexChanged.connect(self._quality_changed)
        self.limit_combo.currentIndexChanged.connect(self._limit_changed)

    def frame_shown(self, _frame=None) -> None:
        """A new picture in the viewport: the zoom says "Fit" while the picture fits the window."""
        if self.viewport.zoom is None:
            self.zoom_label.setText("Fit")

    def set_display_exposure(self, stops: float) -> None:
        """The viewport's display exposure, from the slider, the field or the reset: each shows it after."""
        self.display.set_exposure(stops)
        self._update_exposure_label()

    def _view_changed(self, _view=None) -> None:
        self._update_exposure_label()
        self._update_view_button()

    def _update_exposure_label(self) -> None:
        """The slider and the field show the viewport's exposure (without telling anyone again)."""
        exposure = self.display.view.exposure_stops
        for widget, value in ((self.exposure_slider, round(exposure * 10)), (self.exposure_spin, exposure)):
            widget.blockSignals(True)
            widget.setValue(value)
            widget.blockSignals(False)
        self.exposure_reset.setEnabled(exposure != 0)

    def _update_view_button(self) -> None:
        """The button names the view (cut to its width: "ACES 2.0 SDR"), as a viewer's view menu does; its
        tooltip names the display and the view in full. The status bar names both (RenderStatus)."""
        text = self.display.short_view_text()
        metrics = QFontMetrics(self.view_button.font())
        self.view_button.setText(metrics.elidedText(text, Qt.ElideRight, VIEW_BUTTON_TEXT_PX))
        view = self.display.view
        self.view_button.setToolTip(
            f"<b>{self.display.describe()}</b><br>contrast {view.contrast:.2f}, exposure {view.exposure_stops:+.1f} "
            "EV<br>The view transform (OpenColorIO): click to choose the view, the display, a look and the "
            "contrast. Display only: the render goes on.")

    def _quality_changed(self, _index: int) -> None:
        self.controller.set_quality(self.quality_combo.currentData())

    def _limit_changed(self, _index: int) -> None:
        self.controller.set_target_spp(self.limit_combo.currentData())


__all__ = ["ViewportToolbar", "DISPLAY_EXPOSURE_STOPS", "saved_view", "under_toolbar"]
