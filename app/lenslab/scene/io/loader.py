"""Open a scene from whatever the user typed: a scene file, a folder holding ``scene.json``, or the name of
a scene that ships with LensLab (``cornell_box``)."""

from __future__ import annotations

import os
from pathlib import Path

from lenslab.resources import scenes_dir
from lenslab.scene.io.native import SCENE_SUFFIX, load_scene
from lenslab.scene.scene import Scene, SceneError

SCENE_FILE_NAME = "scene.json"


def shipped_scene_names() -> list[str]:
    return sorted(p.name for p in scenes_dir().iterdir() if (p / SCENE_FILE_NAME).is_file())


def resolve_scene_path(text: str | os.PathLike) -> Path:
    path = Path(text)
    if path.is_dir():
        path = path / SCENE_FILE_NAME
    if path.exists():
        return path
    shipped = scenes_dir() / str(text) / SCENE_FILE_NAME
    if shipped.is_file():
        return shipped
    names = ", ".join(shipped_scene_names())
    raise SceneError(f"{text}: no such scene file (or a shipped scene: {names})")


def open_scene(text: str | os.PathLike) -> Scene:
    path = resolve_scene_path(text)
    suffix = path.suffix.lower()
    if suffix == SCENE_SUFFIX:
        return load_scene(path)
    if suffix == ".xml":
        try:
            from lenslab.scene.io.mitsuba_xml import load_mitsuba_scene
        except ImportError:
            raise SceneError(f"{path}: Mitsuba XML scenes are not supported by this version") from None
        return load_mitsuba_scene(path)
    raise SceneError(f"{path}: unknown scene type '{path.suffix}' (expected {SCENE_SUFFIX} or .xml)")
