"""Work-arounds for bugs in particular Qt for Python releases, each detected at run time, not by version number.

PySide6 6.12.0: every ``Signal.emit()`` called from Python drops one reference to ``True`` that it never took
(6.11.3 does not). On Python 3.11, where ``True`` is an ordinary object with a reference count, a studio that
emits a few signals per rendered frame runs the count down to zero within minutes and the interpreter aborts
("bool_dealloc: deallocating True or False"). Python 3.12 made ``True`` immortal, which hides the bug.

:func:`guard_true_refcount` measures whether this Qt binding has the leak and, only if it has, keeps ``True``'s
reference count far from zero: it adds a large reserve once and tops it up from a timer. Extra references to
``True`` are harmless (it is never freed); missing ones are fatal. The real fix is a PySide6 without the bug:
``pyproject.toml`` should exclude 6.12.0.
"""

from __future__ import annotations

import ctypes
import sys

RESERVE = 1_000_000  # references added at a time: hours of signals at the worst rates seen
_state = {"checked": False, "leak": 0, "floor": 0, "timer": None}


def _emit_leak_per_call() -> int:
    from PySide6.QtCore import QObject, Signal

    class _Probe(QObject):
        ping = Signal()

    probe = _Probe()
    calls = 64
    before = sys.getrefcount(True)
    for _ in range(calls):
        probe.ping.emit()
    after = sys.getrefcount(True)
    return max(0, round((before - after) / calls))


def _add_true_references(count: int) -> None:
    # CPython < 3.12: ob_refcnt is the first field of every object. (3.12 and later never get here.)
    ctypes.c_ssize_t.from_address(id(True)).value += count


def signal_emit_leaks_true() -> bool:
    if not _state["checked"]:
        _state["leak"] = _emit_leak_per_call()
        _state["checked"] = True
    return _state["leak"] > 0


def _top_up() -> None:
    if sys.getrefcount(True) < _state["floor"]:
        _add_true_references(RESERVE)


def guard_true_refcount(parent=None) -> bool:
    """Install the guard if this PySide6 needs it; returns whether it is active. Safe to call repeatedly."""
    if sys.version_info >= (3, 12) or not signal_emit_leaks_true():
        return False
    if _state["timer"] is None:
        from PySide6.QtCore import QTimer

        _add_true_references(RESERVE)
        _state["floor"] = sys.getrefcount(True) - RESERVE // 2
        timer = QTimer(parent)
        timer.setInterval(5000)
        timer.timeout.connect(_top_up)  # a C++ signal: emitting it does not leak
        timer.start()
        _state["timer"] = timer
    return True


def guard_active() -> bool:
    return _state["timer"] is not None
