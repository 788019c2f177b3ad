"""Settings given for one render on top of a scene's own: the command line's ``--f-number 1.4 --spp 256 -D res=512``.

``lenslab SCENE --headless`` and ``lenslab SCENE`` (the studio) both open their scene through
:meth:`SceneOverrides.open`, so a setting given on the command line means the same in both. The scene file is
never changed: the overrides apply to the copy in memory.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from typing import Callable

from lenslab.optics.lenses import find_lens
from lenslab.optics.sensors import find_sensor
from lenslab.optics.stops import exact_f_number, format_f_number
from lenslab.scene.camera import MAX_IMAGE_SIDE, CameraValueError
from lenslab.scene.options import SCENE_OPTIONS
from lenslab.scene.scene import Scene


class _OverridesMethods:
    """What SceneOverrides does; its fields are made from the options table below the class."""

    def __post_init__(self):
        for option in SCENE_OPTIONS:
            value = getattr(self, option.name)
            if value is not None:
                object.__setattr__(self, option.name, option.check(value))
        if self.f_number is not None:  # a marked stop as typed means its exact value (f/11 is 11.31)
            object.__setattr__(self, "f_number", exact_f_number(self.f_number))
        if self.aperture_image:
            object.__setattr__(self, "aperture_image", str(Path(self.aperture_image).expanduser().resolve()))
        if self.exposure_mode is None and (self.iso is not None or self.shutter is not None):
            object.__setattr__(self, "exposure_mode", "physical")
        if self.sensor is not None:
            find_sensor(self.sensor)
        if self.lens is not None:
            self._check_lens()

    def _check_lens(self) -> None:
        """A focal length or f-number given with a lens must be one the lens has: f/1.2 on an f/1.4 lens is
        refused, not quietly changed."""
        lens = find_lens(self.lens)
        if self.focal_length is not None and not _on_the_lens(lens, self.focal_length):
            on_it = (f"{lens.min_focal_length_mm:g}-{lens.max_focal_length_mm:g} mm" if lens.is_zoom
                     else f"{lens.focal_length_mm:.4g} mm")
            raise ValueError(f"focal_length {self.focal_length:g} mm is not on the lens '{lens.name}' ({on_it})")
        if self.f_number is not None and lens.clamp_f_number(self.f_number) != self.f_number:
            raise ValueError(f"{format_f_number(self.f_number)} is not on the lens '{lens.name}' "
                             f"({format_f_number(lens.widest_f_number)} to {format_f_number(lens.narrowest_f_number)})")

    def open(self, scene_ref: str | os.PathLike, warn: Callable[[str], None] | None = None) -> Scene:
        """Load a scene file (native or Mitsuba XML, with this object's defines) and apply the overrides."""
        from lenslab.scene.io.loader import open_scene

        return self.apply(open_scene(scene_ref, defines=dict(self.defines), warn=warn))

    def apply(self, scene: Scene) -> Scene:
        """A copy of ``scene`` with the overrides set; fields left at None keep the scene's value."""
        camera_changes = self._changes("camera")
        if self.sensor is not None:
            sensor = find_sensor(self.sensor)
            camera_changes = {"sensor_mm": (sensor.width_mm, sensor.height_mm),
                              "circle_of_confusion_mm": sensor.circle_of_confusion_mm, **camera_changes}
        if self.lens is not None:  # mounted first: the focal length and f-number given with it are on the lens
            camera = scene.camera
            mounted = find_lens(self.lens).mount(camera_changes.get("focal_length_mm", camera.focal_length_mm),
                                                 camera_changes.get("f_number", camera.f_number))
            camera_changes = {**mounted, **camera_changes}
            if mounted.get("real_lens"):  # the glass's focal length, whatever the barrel's rounded mark said
                camera_changes["focal_length_mm"] = mounted["focal_length_mm"]
        if self.width is not None or self.height is not None:
            camera_changes["resolution"] = self._resolution(scene.camera.resolution)
        render_changes = self._changes("render")
        camera = dataclasses.replace(scene.camera, **camera_changes)
        try:  # the camera's own check, as every path makes it: the thin lens's limit and the lens's marked minimum
            camera.validate(find_lens(self.lens) if self.lens is not None else None)
        except CameraValueError as exc:
            raise ValueError(exc.worded(self._word_for(exc.field_name))) from None
        return dataclasses.replace(scene, camera=camera, render=dataclasses.replace(scene.render, **render_changes))

    def _word_for(self, field_name: str) -> str:
        """What the user calls a camera field: the option that set it (``--focus-distance``), or the scene's value."""
        for option in SCENE_OPTIONS:
            if option.sets == "camera." + field_name and getattr(self, option.name) is not None:
                return option.flag
        return f"the scene's {field_name.removesuffix('_m').removesuffix('_mm').replace('_', ' ')}"

    def _changes(self, owner: str) -> dict[str, object]:
        """The given options that set fields of the scene's ``owner`` ("camera" or "render"), by field name."""
        changes = {}
        for option in SCENE_OPTIONS:
            value = getattr(self, option.name)
            if value is not None and option.sets.startswith(owner + "."):
                changes[option.sets.split(".")[1]] = value
        return changes

    def _resolution(self, scene_resolution: tuple[int, int]) -> tuple[int, int]:
        width, height = scene_resolution
        if self.width is not None and self.height is None:  # keep the scene's aspect ratio
            return self.width, min(MAX_IMAGE_SIDE, max(1, round(self.width * height / width)))
        if self.height is not None and self.width is None:
            return min(MAX_IMAGE_SIDE, max(1, round(self.height * width / height))), self.height
        return self.width, self.height


SceneOverrides = dataclasses.make_dataclass(
    "SceneOverrides",
    [(option.name, option.kind | None, None) for option in SCENE_OPTIONS]
    # Mitsuba XML parameters ($name), as mitsuba -D
    + [("defines", dict[str, str], dataclasses.field(default_factory=dict))],
    bases=(_OverridesMethods,), frozen=True)
SceneOverrides.__module__ = __name__
SceneOverrides.__doc__ = """Settings for one render on top of the scene's: one field per option of scene/options.py,
None where the scene's own value stays, and the Mitsuba defines. Checked when made (a ValueError of one line);
``open`` reads a scene file with them, ``apply`` sets them on a scene already read."""


def _on_the_lens(lens, focal_length_mm: float) -> bool:
    """Whether a focal length is one the lens has: within a zoom's range, a prime's own, or for a real lens
    (whose glass fixes it: 50.36 mm for the 50 mm double-Gauss) what its barrel would say, within 2%."""
    if lens.is_real:
        marks = [lens.focal_length_mm, lens.prescription.published_focal_length_mm or lens.focal_length_mm]
        return any(abs(focal_length_mm / mark - 1.0) <= 0.02 for mark in marks)
    return lens.clamp_focal_length(focal_length_mm) == focal_length_mm
