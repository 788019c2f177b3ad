"""Where preset files live, and strict reading of them.

Presets are JSON files a user may edit, so a mistake in one must be reported,
not skipped: every problem raises :class:`PresetError` with one line naming
the file and the key.  The layout of a presets folder (see presets/README.md)::

    <presets>/sensors.json        {"sensors": [{...}, ...]}
    <presets>/lenses/<any>.json   one lens per file

Folders are read in this order, a later preset replacing an earlier one of
the same name (so users can retune a shipped lens without editing the install):

1. the shipped folder: ``lenslab/presets`` inside an installed package, else
   ``presets/`` at the root of a source checkout;
2. the user folder, ``$XDG_CONFIG_HOME/lenslab/presets`` (default
   ``~/.config/lenslab/presets``; ``%APPDATA%\\lenslab\\presets`` on Windows
   when XDG_CONFIG_HOME is unset), if it exists;
3. any folders the caller passes as ``extra_dirs``, which must exist.
"""

from __future__ import annotations

import json
import math
import os
import sys
from dataclasses import MISSING, fields
from pathlib import Path
from typing import Any, Iterable, Mapping

from lenslab.image_files import read_file_bytes

__all__ = [
    "PresetError",
    "FieldError",
    "shipped_presets_dir",
    "user_presets_dir",
    "preset_dirs",
    "read_json",
    "build_preset",
    "merge_by_name",
]


class PresetError(ValueError):
    """A preset file could not be used.  ``str()`` is one line: ``<file>: <key>: <problem>``."""

    def __init__(self, path: os.PathLike | str, key: str | None, problem: str):
        self.path = Path(path)
        self.key = key
        self.problem = " ".join(str(problem).split())  # keep the promise of one line
        where = f"{self.path}: '{key}'" if key else str(self.path)
        super().__init__(f"{where}: {self.problem}")


class FieldError(ValueError):
    """A preset value is out of range; raised by the dataclasses, mapped to PresetError by loaders."""

    def __init__(self, key: str, problem: str):
        self.key = key
        self.problem = problem
        super().__init__(f"{key}: {problem}")


def shipped_presets_dir() -> Path:
    """The presets folder that ships with LensLab.

    Looks first where an installed package keeps it (``lenslab/presets``, next
    to this package's parent) and then at the root of a source checkout
    (``app/lenslab/optics`` -> ``presets``).
    """
    here = Path(__file__).resolve()
    candidates = [here.parents[1] / "presets"]  # site-packages/lenslab/presets
    if len(here.parents) > 3:
        candidates.append(here.parents[3] / "presets")  # <checkout>/presets
    for candidate in candidates:
        if candidate.is_dir():
            return candidate
    raise PresetError(
        candidates[0], None,
        "shipped presets folder not found (also looked in "
        + ", ".join(str(c) for c in candidates[1:]) + ")",
    )


def user_presets_dir() -> Path:
    """The per-user presets folder (may not exist)."""
    xdg = os.environ.get("XDG_CONFIG_HOME", "")
    # The XDG spec says relative values are invalid and must be ignored.
    if xdg and os.path.isabs(xdg):
        base = Path(xdg)
    elif sys.platform == "win32" and os.environ.get("APPDATA"):
        base = Path(os.environ["APPDATA"])
    else:
        base = Path.home() / ".config"
    return base / "lenslab" / "presets"


def preset_dirs(
    extra_dirs: Iterable[os.PathLike | str] = (),
    *,
    include_shipped: bool = True,
    include_user: bool = True,
) -> list[Path]:
    """The presets folders to read, lowest priority first (see module docstring)."""
    dirs: list[Path] = []
    if include_shipped:
        dirs.append(shipped_presets_dir())
    if include_user:
        user = user_presets_dir()
        if user.is_dir():
            dirs.append(user)
    for extra in extra_dirs:
        extra = Path(extra)
        if not extra.is_dir():
            raise PresetError(extra, None, "presets folder does not exist")
        dirs.append(extra)
    return dirs


def read_json(path: Path) -> Any:
    """Parse one JSON file; any failure becomes a PresetError naming the file."""
    try:
        text = read_file_bytes(path).decode("utf-8")  # a named pipe refused, not waited on
    except UnicodeDecodeError as exc:
        raise PresetError(path, None, f"not UTF-8 text ({exc.reason})") from exc
    except OSError as exc:
        raise PresetError(path, None, f"cannot read: {exc.strerror or exc}") from exc
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise PresetError(
            path, None, f"invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
        ) from exc


# JSON type checks.  bool is a subclass of int in Python but never a number here.
def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _is_integer(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number_pair(v: Any) -> bool:
    return isinstance(v, list) and len(v) == 2 and all(_is_number(x) for x in v)


#: JSON kinds a preset field may declare, with a check and a name for messages.
KINDS = {
    "string": (lambda v: isinstance(v, str), "a string"),
    "number": (_is_number, "a finite number"),
    "integer": (_is_integer, "an integer"),
    "number pair": (_is_number_pair, "a list of two numbers [min, max]"),
}


def _describe(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    return {str: "a string", list: "a list", dict: "an object"}.get(type(value), repr(value))


def build_preset(
    cls: type,
    data: Any,
    kinds: Mapping[str, str],
    path: Path,
    key_prefix: str = "",
):
    """Construct dataclass ``cls`` from a JSON object, strictly.

    ``kinds`` maps each field name to a kind in :data:`KINDS`; a trailing
    ``" or null"`` allows null.  Unknown keys, missing required keys, wrong
    types and out-of-range values (FieldError from ``cls``) all raise
    PresetError naming ``path`` and ``key_prefix + key``.
    """
    if not isinstance(data, dict):
        raise PresetError(path, key_prefix.rstrip(".") or None,
                          f"expected a JSON object, got {_describe(data)}")
    known = {f.name: f for f in fields(cls) if f.init}
    for key in data:
        if key not in known:
            raise PresetError(path, key_prefix + key,
                              f"unknown key (known keys: {', '.join(known)})")
    values = {}
    for name, field in known.items():
        key = key_prefix + name
        if name not in data:
            if field.default is MISSING and field.default_factory is MISSING:
                raise PresetError(path, key, "required key is missing")
            continue
        value = data[name]
        kind = kinds[name]
        nullable = kind.endswith(" or null")
        check, wanted = KINDS[kind.removesuffix(" or null")]
        if value is None and nullable:
            values[name] = None
            continue
        if not check(value):
            raise PresetError(path, key, f"expected {wanted}, got {_describe(value)}")
        values[name] = tuple(value) if isinstance(value, list) else value
    try:
        return cls(**values)
    except FieldError as exc:
        raise PresetError(path, key_prefix + exc.key, exc.problem) from exc


def merge_by_name(groups: Iterable[list]) -> list:
    """Concatenate preset lists, a later preset replacing an earlier one of the same name.

    A replaced preset keeps its position; new names are appended.
    """
    merged: dict[str, Any] = {}
    for group in groups:
        for preset in group:
            merged[preset.name] = preset
    return list(merged.values())
