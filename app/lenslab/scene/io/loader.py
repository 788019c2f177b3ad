"""Open a scene from whatever the user typed: a scene file, a folder holding ``scene.json``, or the name of
a scene that ships with LensLab (``cornell_box``)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

from lenslab.image_files import not_a_file
from lenslab.messages import describe_os_error
from lenslab.resources import scenes_dir
from lenslab.scene.io.native import SCENE_SUFFIX, load_scene
from lenslab.scene.scene import Scene, SceneError

SCENE_FILE_NAME = "scene.json"
MITSUBA_SUFFIX = ".xml"
#: The formats open_scene reads: what a file dialog calls each, and its suffixes.
SCENE_FORMATS = (("LensLab scenes", (SCENE_SUFFIX,)), ("Mitsuba 3 scenes", (MITSUBA_SUFFIX,)))
SCENE_SUFFIXES = tuple(suffix for _name, suffixes in SCENE_FORMATS for suffix in suffixes)


def shipped_scene_names() -> list[str]:
    return sorted(p.name for p in scenes_dir().iterdir() if (p / SCENE_FILE_NAME).is_file())


#: Words a scene's name spells in lower case that a title writes otherwise (acronyms).
TITLE_WORDS = {"dof": "DOF", "hdr": "HDR", "hdri": "HDRI", "ibl": "IBL", "pbr": "PBR", "3d": "3D", "uv": "UV"}
#: Words a title leaves in lower case unless they begin it.
SMALL_WORDS = {"a", "an", "and", "at", "by", "for", "in", "of", "on", "or", "the", "to", "with"}


def scene_title(name: str) -> str:
    """A scene's name (its folder's or its file's: ``dof_chart``) as a title: "DOF Chart", "Marbles on Sand".
    The native format holds no title of its own, so the name is all there is; a word its author capitalised
    stays as written."""
    words = name.replace("_", " ").replace("-", " ").split()
    out = []
    for i, word in enumerate(words):
        low = word.lower()
        if low in TITLE_WORDS:
            out.append(TITLE_WORDS[low])
        elif word != low:
            out.append(word)
        elif i and low in SMALL_WORDS:
            out.append(low)
        else:
            out.append(word[:1].upper() + word[1:])
    return " ".join(out)


def resolve_scene_path(text: str | os.PathLike) -> Path:
    path = Path(text)
    if os.path.isfile(path / SCENE_FILE_NAME):
        return path / SCENE_FILE_NAME
    if os.path.isfile(path):
        return path
    shipped = scenes_dir() / str(text) / SCENE_FILE_NAME
    if os.path.isfile(shipped):
        return shipped
    other = None if os.path.isdir(path) else not_a_file(path)
    if other:  # a named pipe, a device: refused, not waited on
        raise SceneError(f"{path}: {other}")
    if os.path.isdir(path):
        raise SceneError(f"{path}: a folder with no {SCENE_FILE_NAME} in it (name the scene file itself, or a "
                         f"scene's folder)")
    names = ", ".join(shipped_scene_names())
    raise SceneError(f"{text}: no such scene file (or a shipped scene: {names})")


def open_scene(text: str | os.PathLike, defines: dict[str, str] | None = None,
               warn: Callable[[str], None] | None = None) -> Scene:
    """Load a native (.json) or Mitsuba 3 (.xml) scene. ``defines`` are Mitsuba's ``-D name=value``
    parameters; ``warn`` receives one line per thing an importer approximates or leaves out."""
    path = resolve_scene_path(text)
    try:
        return _open(path, defines, warn)
    except SceneError:
        raise
    except OSError as exc:  # a file the scene names that the system will not open (a name too long, no access)
        raise SceneError.in_file(path, describe_os_error(exc)) from None
    except RecursionError:
        raise SceneError(f"{path}: nested too deeply to read") from None
    except MemoryError:
        raise SceneError(f"{path}: too large to read into memory") from None
    except Exception as exc:  # a case the readers missed: still one line naming the file, and a bug to fix
        raise SceneError(f"{path}: cannot be read ({type(exc).__name__}: {exc}; an internal error, please "
                         f"report it)") from exc


def _open(path: Path, defines: dict[str, str] | None, warn: Callable[[str], None] | None) -> Scene:
    suffix = path.suffix.lower()
    if suffix == MITSUBA_SUFFIX:
        from lenslab.scene.io.mitsuba_xml import load_mitsuba_scene  # only Mitsuba users pay for the importer

        return load_mitsuba_scene(path, defines=defines, warn=warn)
    if suffix != SCENE_SUFFIX:
        raise SceneError(f"{path}: unknown scene type '{path.suffix}' (expected {SCENE_SUFFIX} or {MITSUBA_SUFFIX})")
    if defines:
        raise SceneError(f"{path}: -D parameters apply to Mitsuba XML scenes only")
    return load_scene(path)
