"""The photographic model: thin-lens math, depth of field, f-stops, lens and sensor presets.

Pure Python + numpy; knows nothing of GL or Qt.  Units: focal lengths and
sensor sizes in millimetres, scene distances in metres.

Modules, one job each:

* :mod:`.thinlens` - field of view, lens radius, defocus blur (the renderer's camera model)
* :mod:`.dof`      - circle of confusion, hyperfocal distance, near/far limits
* :mod:`.stops`    - full, half and third-stop scales (marks shown, exact values rendered), stepping,
  ``"f/2.8"`` text in and out
* :mod:`.sensors`, :mod:`.lenses` - presets loaded from editable JSON files
* :mod:`.presetfiles` - where those files live, strict parsing, :class:`PresetError`
"""

from .dof import (
    COC_DIAGONAL_DIVISOR,
    DepthOfField,
    circle_of_confusion_mm,
    depth_of_field,
    hyperfocal_distance_m,
)
from .lenses import LensPreset, load_lens_presets
from .presetfiles import PresetError, shipped_presets_dir, user_presets_dir
from .sensors import DEFAULT_SENSOR_NAME, FULL_FRAME, SensorPreset, load_sensor_presets
from .stops import (
    DEFAULT_STOP_SCALE,
    STOP_SCALES,
    StopScale,
    exact_f_number,
    marked_f_number,
    stop_scale,
    MAX_F_NUMBER,
    MIN_F_NUMBER,
    THIRD_STOPS,
    EXTENDED_THIRD_STOPS,
    format_f_number,
    is_valid_f_number,
    nearest_stop,
    parse_f_number,
    step_stop,
    stops_between,
)
from .thinlens import (
    blur_diameter_mm,
    field_of_view_x,
    focal_length_for_fov,
    format_camera_settings,
    format_distance,
    format_focal_length,
    lens_radius_m,
    textbook_blur_diameter_mm,
)

__all__ = [
    "COC_DIAGONAL_DIVISOR", "DepthOfField", "circle_of_confusion_mm", "depth_of_field",
    "hyperfocal_distance_m",
    "LensPreset", "load_lens_presets",
    "PresetError", "shipped_presets_dir", "user_presets_dir",
    "DEFAULT_SENSOR_NAME", "FULL_FRAME", "SensorPreset", "load_sensor_presets",
    "MAX_F_NUMBER", "MIN_F_NUMBER", "THIRD_STOPS", "EXTENDED_THIRD_STOPS", "format_f_number", "is_valid_f_number",
    "nearest_stop", "parse_f_number", "step_stop", "stops_between",
    "DEFAULT_STOP_SCALE", "STOP_SCALES", "StopScale", "exact_f_number", "marked_f_number", "stop_scale",
    "blur_diameter_mm", "field_of_view_x", "focal_length_for_fov", "format_camera_settings", "format_distance",
    "format_focal_length", "lens_radius_m",
    "textbook_blur_diameter_mm",
]
