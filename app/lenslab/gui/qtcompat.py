"""Work-arounds for bugs in particular Qt for Python releases, each detected at run time, not by version number.

PySide6 6.12.0 (seen with Python 3.11 on Linux) releases references it never took: every call of a C++ method
that returns ``void`` (``QPainter.setPen``, ``QWidget.repaint``, ...) drops one reference to ``None``, and every
``Signal.emit()`` from Python drops one to ``True``. On Python 3.11 these singletons have ordinary reference
counts; a studio that paints and signals several times a second runs them down to zero within minutes and the
interpreter aborts ("none_dealloc: deallocating None", "bool_dealloc: deallocating True or False"). PySide6
6.11.3 does not do this, and Python 3.12 made the singletons immortal, which hides it.

:func:`guard_singletons` measures whether this Qt binding leaks and, only if it does, keeps the reference counts
of ``None``, ``True`` and ``False`` far from zero: it adds a large reserve once and tops it up from a timer.
Extra references to these objects are harmless (they are never freed); missing ones are fatal. The real fix is
a PySide6 without the bug: ``pyproject.toml`` should exclude 6.12.0.
"""

from __future__ import annotations

import ctypes
import sys

RESERVE = 1 << 40  # references added at a time: far more than any session can leak
_PROTECTED = (None, True, False)
_state: dict = {"leaks": None, "timer": None, "floor": {}}


def measure_leaks() -> dict[str, int]:
    """References lost per call: {"void call": n to None, "emit": n to True} (zeros for a sound binding)."""
    from PySide6.QtCore import QObject, Signal

    class _Probe(QObject):
        ping = Signal()

    probe = _Probe()
    calls = 64
    none_before = sys.getrefcount(None)
    for _ in range(calls):
        probe.blockSignals(False)  # returns bool
        probe.setObjectName("probe")  # returns void
    void_leak = max(0, round((none_before - sys.getrefcount(None)) / calls))
    true_before = sys.getrefcount(True)
    for _ in range(calls):
        probe.ping.emit()
    emit_leak = max(0, round((true_before - sys.getrefcount(True)) / calls))
    return {"void call": void_leak, "emit": emit_leak}


def binding_leaks() -> bool:
    if _state["leaks"] is None:
        _state["leaks"] = measure_leaks()
    return any(_state["leaks"].values())


def _add_references(obj, count: int) -> None:
    # CPython before 3.12: ob_refcnt is the first field of every object (3.12 and later never get here).
    ctypes.c_ssize_t.from_address(id(obj)).value += count


def _top_up() -> None:
    for obj in _PROTECTED:
        if sys.getrefcount(obj) < _state["floor"][obj]:
            _add_references(obj, RESERVE)


def guard_singletons(parent=None) -> bool:
    """Install the guard if this PySide6 needs it; returns whether it is active. Safe to call repeatedly."""
    if sys.version_info >= (3, 12) or sys.implementation.name != "cpython" or not binding_leaks():
        return False
    if _state["timer"] is None:
        from PySide6.QtCore import QTimer

        for obj in _PROTECTED:
            _add_references(obj, RESERVE)
            _state["floor"][obj] = sys.getrefcount(obj) - RESERVE // 2
        timer = QTimer(parent)
        timer.setInterval(10_000)
        timer.timeout.connect(_top_up)  # emitted by C++: does not leak
        timer.start()
        _state["timer"] = timer
    return True


def guard_active() -> bool:
    return _state["timer"] is not None


# The name the first version of this module used.
guard_true_refcount = guard_singletons
