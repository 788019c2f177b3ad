"""What every section of the camera panel shares: a header that folds it away (remembered), the panel it edits the
camera for, and the quiet while it shows the camera."""

from __future__ import annotations

from contextlib import contextmanager
from typing import TYPE_CHECKING

from lenslab.gui.widgets import Section

if TYPE_CHECKING:
    from lenslab.gui.camera_panel import CameraPanel


class CameraSection(Section):
    """One section of the camera panel: its widgets, the edits they make (through the document's undo commands)
    and ``refresh``, which shows a camera in them. A section speaks through the panel's ``status_message`` and, where
    an edit may leave the camera as it was (a refusal, a clamp), refreshes the whole panel to show the truth."""

    def __init__(self, panel: CameraPanel, key: str, title: str, expanded: bool = True):
        # A section that folds away, open or folded as the user left it last time (QSettings).
        settings = panel.settings
        if settings is not None:
            expanded = str(settings.value(f"camera/section/{key}", expanded)).lower() in ("true", "1")
        super().__init__(title, expanded=expanded)
        self.setObjectName(f"{key}Section")
        if settings is not None:
            self.toggled.connect(lambda on: settings.setValue(f"camera/section/{key}", bool(on)))
        self.key = key
        self.panel = panel
        self.doc = panel.doc
        self._updating = False

    @contextmanager
    def _showing_camera(self):
        """While ``refresh`` sets the widgets: their signals are not the user's edits."""
        self._updating = True
        try:
            yield
        finally:
            self._updating = False
