"""Settings given for one render on top of a scene's own: the command line's ``--f-stop 1.4 --spp 256 -D res=512``.

``lenslab SCENE --headless`` and ``lenslab SCENE`` (the studio) both open their scene through
:meth:`SceneOverrides.open`, so a setting given on the command line means the same in both. The scene file is
never changed: the overrides apply to the copy in memory.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Callable

from lenslab.optics.lenses import find_lens
from lenslab.scene.camera import MAX_IMAGE_SIDE, ThinLensCamera
from lenslab.scene.fields import declared_choices, declared_range
from lenslab.scene.scene import RenderSettings, Scene

# The overrides named as the camera's and the render settings' fields they set.
_CAMERA_FIELDS = ("f_number", "focal_length_mm", "focus_distance_m")
_RENDER_FIELDS = ("spp", "seed", "max_depth", "sampler", "clamp")


@dataclass(frozen=True)
class SceneOverrides:
    f_number: float | None = None
    focal_length_mm: float | None = None
    focus_distance_m: float | None = None
    width: int | None = None  # given alone, width or height keeps the scene's aspect ratio
    height: int | None = None
    spp: int | None = None
    seed: int | None = None
    max_depth: int | None = None
    sampler: str | None = None
    clamp: float | None = None
    lens: str | None = None  # a lens preset's name: its focal length (a zoom's nearest), aperture range and iris
    defines: dict[str, str] = field(default_factory=dict)  # Mitsuba XML parameters ($name), as mitsuba -D

    def __post_init__(self):
        for name in _CAMERA_FIELDS:
            _check_range(name, getattr(self, name), declared_range(ThinLensCamera, name))
        for name in ("width", "height"):
            _check_range(name, getattr(self, name), (1, MAX_IMAGE_SIDE))
        for name in _RENDER_FIELDS:
            value = getattr(self, name)
            if name == "sampler":
                if value is not None and value not in declared_choices(RenderSettings, name):
                    raise ValueError(f"sampler '{value}' is not one of "
                                     f"{', '.join(declared_choices(RenderSettings, name))}")
            else:
                _check_range(name, value, declared_range(RenderSettings, name))
        if self.lens is not None:
            self._check_lens()

    def _check_lens(self) -> None:
        """A focal length or f-number given with a lens must be one the lens has: f/1.2 on an f/1.4 lens is
        refused, not quietly changed."""
        lens = find_lens(self.lens)
        if self.focal_length_mm is not None and lens.clamp_focal_length(self.focal_length_mm) != self.focal_length_mm:
            raise ValueError(f"focal_length {self.focal_length_mm:g} mm is not on the lens '{lens.name}' "
                             f"({lens.min_focal_length_mm:g}-{lens.max_focal_length_mm:g} mm)")
        if self.f_number is not None and lens.clamp_f_number(self.f_number) != self.f_number:
            raise ValueError(f"f/{self.f_number:g} is not on the lens '{lens.name}' "
                             f"(f/{lens.widest_f_number:g} to f/{lens.narrowest_f_number:g})")

    def open(self, scene_ref: str | os.PathLike, warn: Callable[[str], None] | None = None) -> Scene:
        """Load a scene file (native or Mitsuba XML, with this object's defines) and apply the overrides."""
        from lenslab.scene.io.loader import open_scene

        return self.apply(open_scene(scene_ref, defines=dict(self.defines), warn=warn))

    def apply(self, scene: Scene) -> Scene:
        """A copy of ``scene`` with the overrides set; fields left at None keep the scene's value."""
        camera_changes = {name: getattr(self, name) for name in _CAMERA_FIELDS if getattr(self, name) is not None}
        if self.lens is not None:  # mounted first: the focal length and f-number given with it are on the lens
            camera = scene.camera
            mounted = find_lens(self.lens).mount(camera_changes.get("focal_length_mm", camera.focal_length_mm),
                                                 camera_changes.get("f_number", camera.f_number))
            camera_changes = {**mounted, **camera_changes}
        if self.width is not None or self.height is not None:
            camera_changes["resolution"] = self._resolution(scene.camera.resolution)
        render_changes = {name: getattr(self, name) for name in _RENDER_FIELDS if getattr(self, name) is not None}
        return dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, **camera_changes),
                                   render=dataclasses.replace(scene.render, **render_changes))

    def _resolution(self, scene_resolution: tuple[int, int]) -> tuple[int, int]:
        width, height = scene_resolution
        if self.width is not None and self.height is None:  # keep the scene's aspect ratio
            return self.width, min(MAX_IMAGE_SIDE, max(1, round(self.width * height / width)))
        if self.height is not None and self.width is None:
            return min(MAX_IMAGE_SIDE, max(1, round(self.height * width / height))), self.height
        return self.width, self.height


def _check_range(name: str, value, bounds: tuple) -> None:
    if value is None:
        return
    low, high = bounds
    if not low <= value <= high:  # also refuses NaN
        raise ValueError(f"{name} {value} is out of range [{low:g}, {high:g}]")
