"""Depth-of-field readout: acceptable circle of confusion, hyperfocal distance, near/far limits.

Two models, which differ only in where the sensor sits (see :mod:`.thinlens`):

``model="thin_lens"`` (default)
    The textbook thin lens focused by moving the sensor to the image distance
    ``v = f s / (s - f)``.  Formulas as in the usual DoF tables and
    calculators (e.g. S. F. Ray, *Applied Photographic Optics*; DOFMaster)::

        H    = f^2 / (N c) + f
        near = s (H - f) / (H + s - 2 f)
        far  = s (H - f) / (H - s)          for s < H, else infinity

    These are the exact solutions of ``textbook_blur_diameter_mm(..., d) == c``.

``model="planar"``
    What the renderer actually draws (docs/architecture.md, "The camera": sensor fixed at ``f``, planar
    focus).  Solving ``blur_diameter_mm(..., d) == c`` gives::

        H0   = f^2 / (N c)
        near = s H0 / (H0 + s)
        far  = s H0 / (H0 - s)              for s < H0, else infinity

    i.e. the same formulas with the ``+ f`` / ``- f`` corrections dropped.

How far apart they are: the hyperfocal distances differ by exactly one focal
length (``H0 = H - f``) and the near limits by less than ``f / s`` (relative),
so at ordinary distances (a metre or more with normal lenses) the readouts
match to the precision anyone reads off a slider.  The far limits differ more,
because they run off to infinity at H0 and H respectively: focused between the
two, "planar" says infinity while "thin_lens" gives a large finite number.  In
macro (s of a few f) the models part ways; the GUI should show the ``planar``
numbers if it wants to describe the picture on screen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .thinlens import MM_PER_M, require_positive

__all__ = [
    "COC_DIAGONAL_DIVISOR",
    "DOF_MODELS",
    "DepthOfField",
    "circle_of_confusion_mm",
    "hyperfocal_distance_m",
    "depth_of_field",
]

#: The acceptable circle of confusion is the sensor diagonal divided by this.
#: 1500 is the long-standing convention (Kodak, Canon and most DoF calculators):
#: a print of the whole frame viewed at its own diagonal by an eye resolving
#: about 1/1500 of it.  Full frame (43.3 mm diagonal) -> 0.029 mm.  Zeiss used
#: 1730 (0.025 mm); pass your own ``coc_mm`` for a stricter criterion.
COC_DIAGONAL_DIVISOR = 1500.0

#: The accepted values of ``depth_of_field(model=...)``.
DOF_MODELS = ("thin_lens", "planar")


@dataclass(frozen=True)
class DepthOfField:
    """Near and far limits of acceptable sharpness, in metres.

    ``far_m`` and ``total_m`` are ``math.inf`` when focused at or beyond the
    hyperfocal distance.
    """

    near_m: float
    far_m: float
    hyperfocal_m: float
    total_m: float


def circle_of_confusion_mm(sensor_width_mm: float, sensor_height_mm: float) -> float:
    """Acceptable circle of confusion (mm): sensor diagonal / 1500.

    36 x 24 mm -> 0.0288 mm (the familiar "0.029" / "0.03"); APS-C 23.5 x 15.6
    -> 0.0188 mm.  See :data:`COC_DIAGONAL_DIVISOR` for why 1500.
    """
    w = require_positive("sensor_width_mm", sensor_width_mm)
    h = require_positive("sensor_height_mm", sensor_height_mm)
    return math.hypot(w, h) / COC_DIAGONAL_DIVISOR


def hyperfocal_distance_m(focal_length_mm: float, f_number: float, coc_mm: float) -> float:
    """Hyperfocal distance in metres: ``H = f^2 / (N c) + f`` (textbook thin lens).

    Focused at H, everything from H/2 to infinity is acceptably sharp.
    Example: 50 mm, f/8, c = 0.029 mm -> 10.83 m.  The renderer's planar model
    has ``H0 = H - f`` (use ``depth_of_field(..., model="planar").hyperfocal_m``).
    """
    f = require_positive("focal_length_mm", focal_length_mm)
    n = require_positive("f_number", f_number)
    c = require_positive("coc_mm", coc_mm)
    return (f * f / (n * c) + f) / MM_PER_M


def depth_of_field(
    focal_length_mm: float,
    f_number: float,
    focus_distance_m: float,
    coc_mm: float,
    *,
    model: str = "thin_lens",
) -> DepthOfField:
    """Near/far limits of sharpness when focused at ``focus_distance_m``.

    See the module docstring for the formulas of the two models.  All the
    arithmetic is in millimetres; results are returned in metres.
    ``model="thin_lens"`` needs ``focus_distance_m`` beyond the focal length
    (nearer than that a real lens forms no image).
    """
    f = require_positive("focal_length_mm", focal_length_mm)
    n = require_positive("f_number", f_number)
    s = require_positive("focus_distance_m", focus_distance_m) * MM_PER_M
    c = require_positive("coc_mm", coc_mm)
    if model == "thin_lens":
        if s <= f:
            raise ValueError(
                f"focus distance {s / MM_PER_M} m is not beyond the focal length {f} mm"
            )
        # Both models share "f^2/(N c)"; the thin lens shifts it by one focal length.
        shift = f
    elif model == "planar":
        shift = 0.0
    else:
        raise ValueError(f"unknown depth-of-field model {model!r}; expected one of {DOF_MODELS}")

    h0 = f * f / (n * c)  # = H - f in the textbook notation
    hyperfocal = h0 + shift
    near = s * h0 / (h0 + s - shift)
    # Written with h0 so that both models read the same: far = s (H - f) / (H - s).
    far = s * h0 / (hyperfocal - s) if s < hyperfocal else math.inf
    return DepthOfField(
        near_m=near / MM_PER_M,
        far_m=far / MM_PER_M,
        hyperfocal_m=hyperfocal / MM_PER_M,
        total_m=(far - near) / MM_PER_M,
    )
