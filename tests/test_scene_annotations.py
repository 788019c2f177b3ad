"""The scene's dataclasses are read and written by reflection (scene/io/native.py, gui/properties.py): every field's
annotation must resolve with typing.get_type_hints to real types on every Python the project supports.

A name quoted inside an annotation of a module with ``from __future__ import annotations`` (``list["Node"]``)
resolves on Python 3.11 and later but stays the string 'Node' on 3.10, where the reader then fails with
``no reader for 'Node'``; the first test catches such an annotation on any version."""

from __future__ import annotations

import dataclasses
import typing

from lenslab.scene.io import native
from lenslab.scene.scene import Scene


def _reflected_dataclasses() -> list[type]:
    """Scene and every dataclass the reader can reach from it: field types and the tagged registries."""
    pending = [Scene] + [cls for registry in native._TAGGED.values() for cls in registry.values()]
    seen: list[type] = []
    while pending:
        cls = pending.pop()
        if cls in seen:
            continue
        seen.append(cls)
        for hint in typing.get_type_hints(cls).values():
            stack = [hint]
            while stack:
                t = stack.pop()
                stack.extend(typing.get_args(t))
                if isinstance(t, type) and dataclasses.is_dataclass(t):
                    pending.append(t)
    return seen


def _leftover_names(hint: typing.Any) -> list[typing.Any]:
    """Parts of a resolved annotation that are still names (str or ForwardRef), not types."""
    if isinstance(hint, (str, typing.ForwardRef)):
        return [hint]
    return [part for arg in typing.get_args(hint) for part in _leftover_names(arg)]


def test_no_name_is_quoted_inside_a_field_annotation():
    classes = _reflected_dataclasses()
    assert Scene in classes and len(classes) > 10
    quoted = [f"{cls.__module__}.{cls.__qualname__}.{f.name}: {f.type}"
              for cls in classes for f in dataclasses.fields(cls)
              if isinstance(f.type, str) and ('"' in f.type or "'" in f.type)]
    assert not quoted, "quoted names inside annotations do not resolve on Python 3.10: " + "; ".join(quoted)


def test_every_field_annotation_resolves_to_types():
    unresolved = [f"{cls.__qualname__}.{name}: {hint!r}"
                  for cls in _reflected_dataclasses()
                  for name, hint in typing.get_type_hints(cls).items() if _leftover_names(hint)]
    assert not unresolved
