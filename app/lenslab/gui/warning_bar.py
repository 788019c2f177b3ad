"""The bar above the picture that says what opening a scene warned about ("3 warnings while opening scene.xml"):
an unsupported Mitsuba plugin read as grey diffuse, a texture that is not there. The lines are one click away
(Details), the whole session's in the Log panel (Log); the bar goes when dismissed or when the next scene opens."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from PySide6.QtCore import Signal
from PySide6.QtGui import QTextOption
from PySide6.QtWidgets import QFrame, QHBoxLayout, QLabel, QPlainTextEdit, QToolButton, QVBoxLayout, QWidget

from lenslab.gui.theme import ACCENT
from lenslab.messages import one_line

#: The details show this many lines before they scroll: the picture keeps most of the window.
DETAIL_LINES = 8


class WarningBar(QFrame):
    """Hidden until :meth:`show_warnings` has something to say."""

    log_requested = Signal()

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("warningBar")
        self.setStyleSheet(f"QFrame#warningBar {{ background: #3a3124; border-bottom: 1px solid {ACCENT}; }}")
        self.summary = QLabel()
        self.details_button = QToolButton()
        self.details_button.setText("Details")
        self.details_button.setCheckable(True)
        self.details_button.toggled.connect(self._show_details)
        self.log_button = QToolButton()
        self.log_button.setText("Log")
        self.log_button.setToolTip("Show the Log panel: every warning of this session, with its time and file")
        self.log_button.clicked.connect(self.log_requested)
        self.close_button = QToolButton()
        self.close_button.setText("✕")
        self.close_button.setToolTip("Dismiss")
        self.close_button.clicked.connect(self.dismiss)
        row = QHBoxLayout()
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(self.summary, 1)
        for button in (self.details_button, self.log_button, self.close_button):
            row.addWidget(button)
        self.details = QPlainTextEdit()
        self.details.setReadOnly(True)
        self.details.setLineWrapMode(QPlainTextEdit.WidgetWidth)  # a long line whole, not cut at the edge
        self.details.setWordWrapMode(QTextOption.WrapAtWordBoundaryOrAnywhere)
        self.details.setMaximumHeight(self.details.fontMetrics().lineSpacing() * DETAIL_LINES + 12)
        self.details.hide()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(8, 4, 4, 4)
        layout.setSpacing(4)
        layout.addLayout(row)
        layout.addWidget(self.details)
        self.hide()

    def show_warnings(self, source: str, lines: Sequence[str]) -> None:
        """Say what opening ``source`` warned about; with nothing to say, the last scene's warnings go too."""
        if not lines:
            self.dismiss()
            return
        count = len(lines)
        self.summary.setText(f"{count} warning{'' if count == 1 else 's'} while opening {Path(source).name}")
        self.summary.setToolTip(source)
        # A file can hold anything: its lines are shown as printable text, as on the command line.
        self.details.setPlainText("\n".join(one_line(line) for line in lines))
        self.details_button.setChecked(False)
        self.show()

    def add_warnings(self, source: str, lines: Sequence[str]) -> None:
        """More about the scene on screen (what rendering it found, after it opened): added to the bar's lines."""
        if not lines:
            return
        kept = self.lines() if self.isVisible() else []
        expanded = bool(kept) and self.details_button.isChecked()
        self.show_warnings(source, [*kept, *lines])
        self.details_button.setChecked(expanded)  # the user's choice of seeing the lines or not stands

    def lines(self) -> list[str]:
        return self.details.toPlainText().splitlines()

    def dismiss(self) -> None:
        self.details_button.setChecked(False)
        self.hide()

    def _show_details(self, shown: bool) -> None:
        self.details.setVisible(shown)


__all__ = ["WarningBar"]
