"""Where the data that ships with LensLab lives (shaders, ready scenes and presets), and where it keeps what it
saves between runs (user_cache_dir).

In an installed wheel these folders sit inside the package (``lenslab/glsl`` ...); in a source checkout
they sit at the top of the repository. We look in the package first so that an installed copy never
picks up a stray checkout.
"""

from __future__ import annotations

import os
from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent
_CHECKOUT_DIR = _PACKAGE_DIR.parents[1]


def resource_dir(name: str) -> Path:
    """Return the folder holding the shipped resource ``name`` ("glsl", "scenes" or "presets")."""
    for candidate in (_PACKAGE_DIR / name, _CHECKOUT_DIR / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"LensLab's '{name}' folder is missing from {_PACKAGE_DIR} (broken install?)")


def user_cache_dir(name: str) -> Path:
    """``$XDG_CACHE_HOME/lenslab/<name>``, by default ``~/.cache/lenslab/<name>``: work kept between runs to be
    done once (Mitsuba's references, built kd-trees), safe to delete."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "lenslab" / name


def checkout_dir() -> Path | None:
    """The top of the source checkout LensLab runs from (where docs/ and benchmarks/ are), or None when it
    runs from an installed wheel, which ships no such folders."""
    return _CHECKOUT_DIR if (_CHECKOUT_DIR / "pyproject.toml").is_file() else None


def glsl_dir() -> Path:
    return resource_dir("glsl")


def scenes_dir() -> Path:
    return resource_dir("scenes")


def presets_dir() -> Path:
    return resource_dir("presets")
