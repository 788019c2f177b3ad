"""Sensor fit: which part of the sensor an image of a given shape shows (docs/architecture.md, "The camera").

A sensor and an image rarely share an aspect ratio (a 36 x 24 mm sensor, a square or portrait render), so a
camera must say which of the sensor's sides the image spans. The choices are Blender's and Unity's:

* ``auto`` (Blender's Auto, the default): the sensor's long side spans the image's long side, as a camera is
  turned for a portrait; the other side follows the image's shape.
* ``horizontal``: the sensor's width spans the image's width (Mitsuba's and pbrt's ``fov_axis = x``).
* ``vertical``: the sensor's height spans the image's height.
* ``fill``: the image lies inside the sensor and fills it one way: the image is a crop of the sensor.
* ``overscan``: the sensor lies inside the image and fills it one way: the image shows more than the sensor.

The result is the *imaged area*: the width and height in millimetres of the film the image covers. The field of
view, the circle of confusion (its diagonal / 1500) and the metadata's focal-plane resolution all follow from it.
"""

from __future__ import annotations

SENSOR_FITS = ("auto", "horizontal", "vertical", "fill", "overscan")


def imaged_area_mm(sensor_width_mm: float, sensor_height_mm: float, width: int, height: int,
                   fit: str = "auto") -> tuple[float, float]:
    """Width and height (mm) of the film that an image of ``width`` x ``height`` pixels shows (square pixels)."""
    if fit not in SENSOR_FITS:
        raise ValueError(f"unknown sensor fit '{fit}' (choose from {', '.join(SENSOR_FITS)})")
    aspect = width / height
    if fit == "auto":
        long_side = max(sensor_width_mm, sensor_height_mm)
        return (long_side, long_side / aspect) if width >= height else (long_side * aspect, long_side)
    if fit == "horizontal":
        return sensor_width_mm, sensor_width_mm / aspect
    if fit == "vertical":
        return sensor_height_mm * aspect, sensor_height_mm
    by_width = (sensor_width_mm, sensor_width_mm / aspect)
    by_height = (sensor_height_mm * aspect, sensor_height_mm)
    # Fill keeps the smaller of the two fits (inside the sensor), overscan the larger (around it).
    smaller = by_width if by_width[0] <= by_height[0] else by_height
    larger = by_height if smaller is by_width else by_width
    return smaller if fit == "fill" else larger
