"""A panel that scrolls up and down, never sideways: the docks' tall contents (the camera panel, the property editor,
the snapshots) in a window of any height.

A panel scrolled sideways hides the end of every row (the Z of a position, the second field of a pair), so the
scroll area is made as wide as its contents need beside the scroll bar: the dock cannot be narrowed below that, and
its rows are always seen whole. Its height asks for little, so a short window still gives every dock room and the
contents scroll instead of being squeezed."""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, QSize, Qt
from PySide6.QtWidgets import QFrame, QScrollArea, QWidget

#: The least height a scrolling panel asks for: a few rows, enough to scroll through.
MIN_PANEL_HEIGHT = 80


class PanelScroll(QScrollArea):
    def __init__(self, contents: QWidget | None = None, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
        self.setVerticalScrollBarPolicy(Qt.ScrollBarAsNeeded)
        self.setFrameShape(QFrame.NoFrame)
        if contents is not None:
            self.setWidget(contents)

    def setWidget(self, widget: QWidget) -> None:
        old = self.widget()
        if old is not None:
            old.removeEventFilter(self)
        super().setWidget(widget)
        widget.installEventFilter(self)
        self.updateGeometry()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        # The contents' layout changed (a section folded, another form built): so may the width they need.
        if watched is self.widget() and event.type() == QEvent.LayoutRequest:
            self.updateGeometry()
        return super().eventFilter(watched, event)

    def minimumSizeHint(self) -> QSize:
        contents = self.widget()
        if contents is None:
            return super().minimumSizeHint()
        inner = contents.minimumSizeHint().expandedTo(contents.minimumSize())
        bar = self.verticalScrollBar().sizeHint().width()
        frame = 2 * self.frameWidth()
        return QSize(inner.width() + bar + frame, min(inner.height(), MIN_PANEL_HEIGHT) + frame)

    def sizeHint(self) -> QSize:
        contents = self.widget()
        if contents is None:
            return super().sizeHint()
        hint = contents.sizeHint().expandedTo(contents.minimumSizeHint())
        bar = self.verticalScrollBar().sizeHint().width()
        frame = 2 * self.frameWidth()
        return QSize(hint.width() + bar + frame, hint.height() + frame)


__all__ = ["PanelScroll", "MIN_PANEL_HEIGHT"]
