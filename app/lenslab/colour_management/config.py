"""Which OpenColorIO config colour decisions come from.

By default the one in ``$OCIO`` when that is set (what every OCIO application does, so that a studio's config
rules Nuke, Blender and LensLab alike), else OCIO's built-in ACES computer-graphics config, pinned to one
version so that a picture does not change when the package is upgraded. A scene or a command line may name a
config file, or a built-in one by its ``ocio://`` URI.
"""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

#: OCIO's built-in config for computer graphics, ACES 2.0 output transforms (OpenColorIO 2.5 and later).
BUILTIN_CONFIG = "ocio://cg-config-v4.0.0_aces-v2.0_ocio-v2.5"
#: What a scene, option or setting names to mean "$OCIO if set, else the built-in config".
DEFAULT_SOURCE = ""


class ColourConfigError(ValueError):
    """A config that cannot be read, or a name (display, view, look, colour space) a config does not have."""


_chosen_for_this_process = ""


def use_config(source: str | os.PathLike) -> None:
    """Make ``source`` the config of everything this process does that names none (the command line's
    ``--ocio-config``: its textures and its pictures alike), before $OCIO."""
    global _chosen_for_this_process
    _chosen_for_this_process = str(source or "").strip()


def config_source(source: str | os.PathLike | None = DEFAULT_SOURCE) -> str:
    """The config ``source`` stands for: itself when given, else the one :func:`use_config` chose, else ``$OCIO``
    when set, else BUILTIN_CONFIG. A file is made absolute, so that the cache holds one entry for it however it was
    named."""
    text = (str(source or "").strip() or _chosen_for_this_process or os.environ.get("OCIO", "").strip()
            or BUILTIN_CONFIG)
    if text.startswith("ocio://"):
        return text
    return str(Path(text).expanduser().resolve())


def load_config(source: str | os.PathLike | None = DEFAULT_SOURCE):
    """The OCIO config ``source`` names (see :func:`config_source`); a ColourConfigError naming the file (or
    ``$OCIO``) and OCIO's reason when it cannot be used. Read once per file and modification time."""
    resolved = config_source(source)
    if resolved.startswith("ocio://"):
        return _load(resolved, None)
    path = Path(resolved)
    where = f"{path} (from $OCIO)" if resolved == _from_environment() else str(path)
    if not path.is_file():
        raise ColourConfigError(f"{where}: no such OCIO config file")
    try:
        stamp = path.stat().st_mtime_ns
    except OSError as exc:
        raise ColourConfigError(f"{where}: cannot read the OCIO config ({exc.strerror})") from None
    try:
        return _load(resolved, stamp)
    except ColourConfigError as exc:
        raise ColourConfigError(f"{where}: {exc}") from None


def _from_environment() -> str:
    text = os.environ.get("OCIO", "").strip()
    return str(Path(text).expanduser().resolve()) if text and not text.startswith("ocio://") else text


@lru_cache(maxsize=8)
def _load(resolved: str, stamp: int | None):
    import PyOpenColorIO as ocio  # imported here: a plain scene load or a test of the optics needs none of it

    try:
        config = ocio.Config.CreateFromFile(resolved)  # a file, or a built-in config's ocio:// URI
        config.validate()
    except Exception as exc:  # OCIO raises its own Exception type for every problem
        raise ColourConfigError(f"not a usable OCIO config: {_first_line(exc)}") from None
    return config


def _first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else type(exc).__name__


def config_name(source: str | os.PathLike | None = DEFAULT_SOURCE) -> str:
    """A short name for the config, as metadata and the studio show it: the built-in config's name, or the
    file's path."""
    resolved = config_source(source)
    return resolved.removeprefix("ocio://")
