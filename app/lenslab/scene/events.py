"""Observing a scene while it is edited: a small event emitter with no GUI toolkit in it.

The scene classes are plain dataclasses; the scene open for editing (:class:`~lenslab.scene.editable.EditableScene`)
owns a :class:`SceneEvents` and says what each edit changed by emitting a :class:`SceneChange` on it. Observers
(the viewport, the outliner, the render worker's feeder, a script) connect callables to it directly and decide
for themselves what to refresh, as napari's widgets listen to its layers' event groups. Nothing here imports
Qt, so a headless tool observes a scene the same way the studio does.

    events = SceneEvents()
    events.changed.connect(lambda change: print(change.kind, change.field))
    events.changed.emit(SceneChange("camera", ("camera",), ("f_number",)))
"""

from __future__ import annotations

import sys
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Callable, Iterator

#: What a change touched, from cheapest to dearest to re-render:
#: ``camera`` (restart only), ``render`` (sampler settings), ``material`` (re-pack materials),
#: ``environment``, ``light`` (a point light's or a sun's fields), ``node`` (a node's fields: transform,
#: shape, material), ``structure`` (nodes, materials or lights added, removed, renamed or moved) and
#: ``scene`` (the whole scene replaced).
CHANGE_KINDS = ("camera", "render", "material", "environment", "light", "node", "structure", "scene")


@dataclass(frozen=True)
class SceneChange:
    kind: str
    target: tuple = ()  # what was edited: ("camera",), ("node", path), ("material", name), ...
    field: tuple[str, ...] = ()  # which field of it, as an attribute path: ("transform", "translate")

    def __post_init__(self):
        if self.kind not in CHANGE_KINDS:
            raise ValueError(f"unknown change kind {self.kind!r} (expected one of {', '.join(CHANGE_KINDS)})")

    @property
    def geometry(self) -> bool:
        """True when what the camera sees may have moved (so picking and selection buffers are stale)."""
        if self.kind in ("node", "structure", "scene"):
            return self.field[:1] != ("material",) and self.field[:1] != ("name",)
        if self.kind == "camera":
            return self.field[:1] not in (("f_number",), ("focus_distance_m",), ("aperture_blades",),
                                          ("blade_rotation_deg",))
        return False


class EventEmitter:
    """Callables connected to one kind of event; ``emit`` calls them in the order they were connected.

    A callback that raises does not stop the others, nor unwind the edit that is announcing itself half way
    through: its error goes to ``sys.excepthook`` (which prints it, or fails the test under pytest-qt) and the
    next callback runs, as with a Qt signal's slots."""

    def __init__(self) -> None:
        self._callbacks: list[Callable[[Any], None]] = []
        self._blocked = 0

    def connect(self, callback: Callable[[Any], None]) -> Callable[[Any], None]:
        if callback not in self._callbacks:
            self._callbacks.append(callback)
        return callback  # usable as a decorator

    def disconnect(self, callback: Callable[[Any], None] | None = None) -> None:
        """Disconnect one callback, or all of them when none is given."""
        if callback is None:
            self._callbacks.clear()
        elif callback in self._callbacks:
            self._callbacks.remove(callback)

    def emit(self, event: Any = None) -> None:
        if self._blocked:
            return
        for callback in list(self._callbacks):  # a callback may disconnect itself
            try:
                callback(event)
            except Exception:  # noqa: BLE001 (reported, not swallowed: see the class's docstring)
                sys.excepthook(*sys.exc_info())

    @contextmanager
    def blocked(self) -> Iterator[None]:
        """Emit nothing inside the block (for a batch of edits announced once at the end)."""
        self._blocked += 1
        try:
            yield
        finally:
            self._blocked -= 1

    def __len__(self) -> int:
        return len(self._callbacks)


class SceneEvents:
    """The events of one edited scene: ``changed`` carries a :class:`SceneChange` after each edit."""

    def __init__(self) -> None:
        self.changed = EventEmitter()
