"""The Log panel: every warning of this session, one line each with its time and its file, so that what a scene's
reader approximated or left out can still be read after the bar above the picture has been dismissed. A dock,
hidden until asked for (View > Log, or the bar's Log button), at the bottom of the window."""

from __future__ import annotations

from collections.abc import Sequence
from datetime import datetime

from PySide6.QtCore import Qt
from PySide6.QtGui import QTextOption
from PySide6.QtWidgets import QDockWidget, QHBoxLayout, QMainWindow, QPlainTextEdit, QPushButton, QVBoxLayout, QWidget

from lenslab.messages import one_line

#: Lines kept: a session that opens many broken scenes does not grow without end.
MAX_LINES = 5000


class LogPanel(QWidget):
    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.view = QPlainTextEdit()
        self.view.setObjectName("log")
        self.view.setReadOnly(True)
        # Long lines wrap: unwrapped, each new line scrolled the view sideways to its end, hiding every line's
        # time and file; a path with no spaces breaks anywhere rather than run on.
        self.view.setLineWrapMode(QPlainTextEdit.WidgetWidth)
        self.view.setWordWrapMode(QTextOption.WrapAtWordBoundaryOrAnywhere)
        self.view.setMaximumBlockCount(MAX_LINES)
        clear = QPushButton("Clear")
        clear.clicked.connect(self.view.clear)
        buttons = QHBoxLayout()
        buttons.addStretch(1)
        buttons.addWidget(clear)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addWidget(self.view, 1)
        layout.addLayout(buttons)

    def add(self, source: str, lines: Sequence[str], when: datetime | None = None) -> None:
        """Log ``lines`` about the file ``source``; a line that names the file already (the Mitsuba reader's
        ``scene.xml:12: <bsdf ...>: ...``) is not given its name twice."""
        stamp = (when or datetime.now()).strftime("%H:%M:%S")
        for line in lines:
            text = line if source in line else f"{source}: {line}"
            self.view.appendPlainText(f"{stamp}  {one_line(text)}")

    def lines(self) -> list[str]:
        return self.view.toPlainText().splitlines()


def install_log_dock(window: QMainWindow, panel: LogPanel) -> QDockWidget:
    """``panel`` in a dock at the bottom of ``window``, hidden; its toggle is the dock's own (View > Log)."""
    dock = QDockWidget("Log", window)
    dock.setObjectName("logDock")  # restoreState finds it by this name
    dock.setWidget(panel)
    dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable | QDockWidget.DockWidgetClosable)
    window.addDockWidget(Qt.BottomDockWidgetArea, dock)
    dock.hide()
    return dock


def show_dock(dock: QDockWidget) -> None:
    dock.show()
    dock.raise_()


__all__ = ["LogPanel", "install_log_dock", "show_dock", "MAX_LINES"]
