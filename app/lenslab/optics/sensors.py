"""Sensor (film-back) presets: named sensor sizes, loaded from ``presets/sensors.json``.

The sensor size fixes the field of view for a focal length (``thinlens``) and
the acceptable circle of confusion (``dof``).  Sizes are the active image
area in millimetres, landscape (width >= height is usual but not required).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Iterable

from .dof import circle_of_confusion_mm
from .presetfiles import FieldError, PresetError, build_preset, merge_by_name, preset_dirs, read_json

__all__ = [
    "SensorPreset",
    "FULL_FRAME",
    "SENSOR_SIDE_RANGE_MM",
    "SENSOR_COC_RANGE_MM",
    "crop_factor",
    "DEFAULT_SENSOR_NAME",
    "SENSORS_FILE",
    "find_sensor",
    "load_sensor_presets",
]

#: File name of the sensor list inside a presets folder.
SENSORS_FILE = "sensors.json"

#: Diagonal of the 36 x 24 mm format, the reference for crop factors.
_FULL_FRAME_DIAGONAL_MM = math.hypot(36.0, 24.0)

#: The sensor sides LensLab accepts, mm, in scene files, presets and the studio: from a 1 mm phone sensor
#: side to beyond 8x10 inch sheet film (254 mm); much more is a typo (metres entered as millimetres, say).
SENSOR_SIDE_RANGE_MM = (1.0, 500.0)

#: The circles of confusion a sensor preset may name, mm (as the camera's ``circle_of_confusion_mm`` accepts).
SENSOR_COC_RANGE_MM = (0.0005, 1.0)


def crop_factor(width_mm: float, height_mm: float) -> float:
    """Full-frame diagonal over this sensor's diagonal (1.53 for APS-C 23.5 x 15.6): what a focal length is
    multiplied by to give its 35 mm equivalent."""
    return _FULL_FRAME_DIAGONAL_MM / math.hypot(width_mm, height_mm)


@dataclass(frozen=True)
class SensorPreset:
    """A named sensor size in millimetres."""

    name: str
    width_mm: float
    height_mm: float
    description: str = field(default="", compare=False)
    #: This format's own circle of confusion, mm (a cinema or a print standard, a stricter criterion for large
    #: prints); None: the diagonal / 1500. Read it through :attr:`coc_mm`, which applies that default.
    circle_of_confusion_mm: float | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.strip():
            raise FieldError("name", "must be a non-empty string")
        for key in ("width_mm", "height_mm"):
            value = float(getattr(self, key))
            low, high = SENSOR_SIDE_RANGE_MM
            if not (low <= value <= high):
                raise FieldError(key, f"must lie in [{low:g}, {high:g}] mm, got {value:g}")
            object.__setattr__(self, key, value)  # store ints from JSON as floats
        coc = self.circle_of_confusion_mm
        if coc is not None:
            low, high = SENSOR_COC_RANGE_MM
            if isinstance(coc, bool) or not isinstance(coc, (int, float)) or not (low <= coc <= high):
                raise FieldError("circle_of_confusion_mm", f"must lie in [{low:g}, {high:g}] mm, got {coc!r}")
            object.__setattr__(self, "circle_of_confusion_mm", float(coc))

    @property
    def diagonal_mm(self) -> float:
        return math.hypot(self.width_mm, self.height_mm)

    @property
    def aspect_ratio(self) -> float:
        """Width over height (1.5 for 36 x 24)."""
        return self.width_mm / self.height_mm

    @property
    def crop_factor(self) -> float:
        """Full-frame diagonal over this diagonal (1.53 for APS-C 23.5 x 15.6)."""
        return crop_factor(self.width_mm, self.height_mm)

    @property
    def coc_mm(self) -> float:
        """Acceptable circle of confusion: the format's own, or its diagonal / 1500 (see ``dof``)."""
        if self.circle_of_confusion_mm is not None:
            return self.circle_of_confusion_mm
        return circle_of_confusion_mm(self.width_mm, self.height_mm)


#: Name of the default sensor in the shipped list (docs/architecture.md, "The camera": full frame 36 x 24 mm).
DEFAULT_SENSOR_NAME = "Full frame"

#: The default sensor, available without reading any file.
FULL_FRAME = SensorPreset(DEFAULT_SENSOR_NAME, 36.0, 24.0, "35 mm still format")

_KINDS = {"name": "string", "width_mm": "number", "height_mm": "number", "description": "string",
          "circle_of_confusion_mm": "number or null"}


def _read_sensors_file(path) -> list[SensorPreset]:
    data = read_json(path)
    if not isinstance(data, dict):
        raise PresetError(path, None, 'expected a JSON object {"sensors": [...]}')
    for key in data:
        if key != "sensors":
            raise PresetError(path, key, "unknown key (known keys: sensors)")
    entries = data.get("sensors")
    if not isinstance(entries, list):
        raise PresetError(path, "sensors", "expected a list of sensor objects")
    sensors: list[SensorPreset] = []
    seen: set[str] = set()
    for i, entry in enumerate(entries):
        sensor = build_preset(SensorPreset, entry, _KINDS, path, key_prefix=f"sensors[{i}].")
        if sensor.name in seen:
            raise PresetError(path, f"sensors[{i}].name", f"duplicate sensor name {sensor.name!r}")
        seen.add(sensor.name)
        sensors.append(sensor)
    return sensors


def load_sensor_presets(
    extra_dirs: Iterable[os.PathLike | str] = (),
    *,
    include_shipped: bool = True,
    include_user: bool = True,
) -> list[SensorPreset]:
    """All sensor presets: shipped, then the user's, then ``extra_dirs``.

    Each folder may hold a ``sensors.json``; a sensor whose name was already
    defined replaces the earlier one in place, new names are appended.
    Raises PresetError (file and key named) on any broken file.
    """
    groups = []
    for folder in preset_dirs(extra_dirs, include_shipped=include_shipped, include_user=include_user):
        path = folder / SENSORS_FILE
        if path.exists():
            groups.append(_read_sensors_file(path))
    return merge_by_name(groups)


def find_sensor(name: str, sensors: Iterable[SensorPreset] | None = None) -> SensorPreset:
    """The sensor preset called ``name`` (case, spaces and dashes do not matter: "aps-c", "Full Frame"). A
    ValueError listing the sensors there are when none is called that."""
    sensors = list(load_sensor_presets() if sensors is None else sensors)

    def key(text: str) -> str:
        return "".join(ch for ch in text.lower() if ch.isalnum() or ch in "./()")

    for sensor in sensors:
        if key(sensor.name) == key(name):
            return sensor
    raise ValueError(f"no sensor preset called '{name}' (there are: {', '.join(s.name for s in sensors)})")
