"""What "nothing clipped, nothing out of reach" means for the studio's tests (tests/gui/test_layout_holds.py).

A widget in a dock is reachable when each of its ancestors up to the dock shows all of it, or is a scroll area
that can scroll down to it. Not sideways: a panel scrolled sideways cuts every one of its rows at the edge (the Z
of a position, the second of two fields), so a panel's rows must fit its width. (A list's or a tree's items are
the view's own business.) It is clipped when
it is given less room than it needs to show itself: less than its minimum size (a button's text, a label's line),
a number field narrower than its number, a wrapped label shorter than its lines. Each check returns what it found
as readable lines, so that a failing test says which widget and why.
"""

from __future__ import annotations

from PySide6.QtCore import QRect, Qt
from PySide6.QtWidgets import (QAbstractButton, QAbstractScrollArea, QAbstractSpinBox, QComboBox, QDockWidget,
                               QLabel, QLineEdit, QScrollBar, QSizePolicy, QTabBar, QToolBar, QWidget)

# Parts that belong to another widget, which sizes them itself (a spin box's field, a combo's view, scroll bars).
_COMPOSITE = (QAbstractSpinBox, QComboBox, QScrollBar, QTabBar)


def describe(widget: QWidget) -> str:
    text = ""
    for getter in ("text", "currentText", "title"):
        value = getattr(widget, getter, None)
        if callable(value):
            try:
                text = str(value())
            except TypeError:
                continue
            break
    name = widget.objectName()
    return f"{type(widget).__name__}{'#' + name if name else ''}{' ' + repr(text[:40]) if text else ''}"


def _is_scroll_viewport(widget: QWidget) -> QAbstractScrollArea | None:
    parent = widget.parentWidget()
    if isinstance(parent, QAbstractScrollArea) and parent.viewport() is widget:
        return parent
    return None


def _scrolls_down(area: QAbstractScrollArea) -> bool:
    return area.verticalScrollBarPolicy() != Qt.ScrollBarAlwaysOff and area.verticalScrollBar().maximum() > 0


def _inside_composite(widget: QWidget, root: QWidget) -> bool:
    parent = widget.parentWidget()
    while parent is not None and parent is not root:
        if isinstance(parent, _COMPOSITE) or (isinstance(parent, QAbstractScrollArea)
                                              and not hasattr(parent, "widget")):
            return True  # a list's or a tree's items are its own business (it scrolls them)
        parent = parent.parentWidget()
    return False


def out_of_reach(widget: QWidget, root: QWidget) -> str | None:
    """Why ``widget`` cannot be seen whole by scrolling within ``root``, or None when it can."""
    rect = QRect(widget.rect())
    child = widget
    while child is not root:
        parent = child.parentWidget()
        if parent is None:
            return "not inside the dock"
        rect = rect.translated(child.pos())
        area = _is_scroll_viewport(parent)
        if area is not None:
            # The scroll area's contents: reachable below by scrolling down, cut past its right edge.
            view = parent.rect()
            if rect.right() > view.right():
                return f"past the right edge of a scrolling panel ({rect} in {view})"
            if rect.bottom() > view.bottom() and not _scrolls_down(area):
                return f"below a scroll area that does not scroll down ({rect} in {view})"
            rect = QRect(area.rect())  # from here up, the scroll area's own frame must be seen
            child = area
            continue
        if not parent.rect().contains(rect):
            return f"{rect} outside {describe(parent)} {parent.rect()}"
        child = parent
    return None


def squeezed(widget: QWidget) -> str | None:
    """Why ``widget`` is drawn with less room than it needs, or None."""
    # A field's text (a spin box's number, in the line edit it is edited in) must fit it.
    field = widget.lineEdit() if isinstance(widget, QAbstractSpinBox) else widget
    if isinstance(field, QLineEdit) and field.text() and not field.echoMode():
        need = field.fontMetrics().horizontalAdvance(field.text()) + 4
        margins = field.textMargins()
        have = field.contentsRect().width() - margins.left() - margins.right()
        if need > have:
            return f"its text {field.text()!r} needs {need} px, has {have}"
    if isinstance(widget, QLabel) and widget.wordWrap() and widget.text():
        need = widget.heightForWidth(widget.width())
        if need > widget.height():
            return f"its wrapped text needs {need} px of height, has {widget.height()}"
        return None
    if isinstance(widget, QLineEdit) and isinstance(widget.parentWidget(), _COMPOSITE):
        return None  # its spin box or combo sizes it
    policy = widget.sizePolicy()
    least = widget.minimumSizeHint()
    if not least.isValid():
        return None
    for extent, have, minimum, maximum, flags in (
            ("width", widget.width(), widget.minimumWidth(), widget.maximumWidth(), policy.horizontalPolicy()),
            ("height", widget.height(), widget.minimumHeight(), widget.maximumHeight(), policy.verticalPolicy())):
        if flags == QSizePolicy.Ignored:
            continue
        need = min(minimum or getattr(least, extent)(), maximum)
        if have < need:
            return f"{have} px of {extent}, needs {need}"
    return None


def dock_problems(dock: QDockWidget) -> list[str]:
    """Every widget of the dock's contents that cannot be reached or is clipped, shown as it is now."""
    root = dock.widget()
    found = []
    for widget in [root] + root.findChildren(QWidget):
        if not widget.isVisibleTo(root) or _inside_composite(widget, root):
            continue
        if isinstance(widget, (QScrollBar,)) or _is_scroll_viewport(widget) is not None:
            continue
        if widget is not root:
            reason = out_of_reach(widget, root)
            if reason is not None:
                found.append(f"{dock.objectName()}: {describe(widget)} out of reach: {reason}")
                continue
        reason = squeezed(widget)
        if reason is not None:
            found.append(f"{dock.objectName()}: {describe(widget)} clipped: {reason}")
    if root.width() > dock.width() or root.height() > dock.height():
        found.append(f"{dock.objectName()}: its contents {root.size()} are larger than the dock {dock.size()}")
    return found


def toolbar_problems(bar: QToolBar) -> list[str]:
    """Controls of the toolbar that are neither shown nor in its overflow, or shown clipped.

    An item the bar has no room for is reachable only through the bar's extension button: it must be shown, and
    pressing it must show the items."""
    found = []
    hidden = []
    for action in bar.actions():
        if action.isSeparator() or not action.isVisible():
            continue
        widget = bar.widgetForAction(action)
        if widget is None:
            continue
        if not widget.isVisible():
            hidden.append((action, widget))
            continue
        if not bar.rect().contains(widget.geometry()):
            found.append(f"{describe(widget)} cut by the toolbar's edge: {widget.geometry()} in {bar.rect()}")
        reason = squeezed(widget)
        if reason is not None and not isinstance(widget, QAbstractButton):
            found.append(f"{describe(widget)} clipped: {reason}")
    if hidden:
        extension = bar.findChild(QAbstractButton, "qt_toolbar_ext_button")
        if extension is None or not extension.isVisible():
            found.append(f"{len(hidden)} controls hidden without an overflow button: "
                         + ", ".join(describe(w) for _a, w in hidden))
    return found


__all__ = ["dock_problems", "toolbar_problems", "out_of_reach", "squeezed", "describe"]
