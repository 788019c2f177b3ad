"""Exposure as a camera makes it: aperture, shutter speed and ISO (docs/architecture.md, "Exposure").

Two modes, a camera's ``exposure_mode``:

* ``compensated`` (the default): the picture's brightness does not depend on the camera's settings, as if an
  automatic exposure made up for every change of aperture, so that a photographer can judge depth of field at
  f/1.4 and f/16 side by side. The render holds the scene's radiance.
* ``physical``: each stop of aperture, shutter or ISO is a stop of light. Radiance L (in cd/m^2) is scaled to
  L / L_max, where L_max is the luminance that saturates the sensor at this exposure (the saturation-based
  ISO speed of ISO 12232, with the 78 / 0.65 constant that Frostbite and Unity HDRP use)::

      EV100 = log2(N^2 / t) - log2(S / 100)
      L_max = 1.2 * 2^EV100        so the scale is  t S / (120 N^2)

  An aperture that passes less light than the round f/N stop (an aperture image) counts with its real area.
  ISO 100, 1/125 s, f/8: EV100 12.97, a sunny-day exposure; a room lit to 1 cd/m^2 wants EV100 near 3.
"""

from __future__ import annotations

import math

from .thinlens import require_positive

EXPOSURE_MODES = ("compensated", "physical")

#: The ISO speeds LensLab accepts, and the shutter times, seconds.
ISO_RANGE = (1.0, 1_000_000.0)
SHUTTER_RANGE_S = (1e-6, 3600.0)

# L_max = 78 / (q S) * N^2 / t with lens transmission and vignetting q = 0.65 (ISO 12232 saturation speed).
_SATURATION_CONSTANT = 78.0 / 0.65


def ev100(f_number: float, shutter_s: float, iso: float) -> float:
    """Exposure value at ISO 100 of these settings: ``log2(N^2 / t) - log2(S / 100)``. f/8, 1/125 s, ISO 100:
    12.97."""
    n = require_positive("f_number", f_number)
    t = require_positive("shutter_s", shutter_s)
    s = require_positive("iso", iso)
    return math.log2(n * n / t) - math.log2(s / 100.0)


def exposure_scale(f_number: float, shutter_s: float, iso: float, light_fraction: float = 1.0) -> float:
    """What radiance is multiplied by for a physical exposure: ``t S / (120 N^2)`` times the fraction of the
    round stop's light the aperture passes."""
    n = require_positive("f_number", f_number)
    t = require_positive("shutter_s", shutter_s)
    s = require_positive("iso", iso)
    return t * s * light_fraction / (_SATURATION_CONSTANT * n * n)


def format_shutter(seconds: float) -> str:
    """A shutter time as a camera shows it: ``"1/125 s"``, ``"1/4 s"``, ``"0.8 s"``, ``"2 s"``, ``"30 s"``."""
    t = require_positive("shutter_s", seconds)
    if t < 0.4:
        return f"1/{1.0 / t:.0f} s" if 1.0 / t >= 10 else f"1/{1.0 / t:.3g} s"
    return f"{t:.2g} s" if t < 10 else f"{t:.0f} s"


def parse_shutter(text: str) -> float:
    """``"1/125"``, ``"1/125 s"``, ``"0.5"``, ``"2s"``, ``"30"`` to seconds; a ValueError naming the text."""
    cleaned = str(text).strip().lower().removesuffix("s").strip()
    try:
        if "/" in cleaned:
            numerator, denominator = cleaned.split("/", 1)
            value = float(numerator) / float(denominator)
        else:
            value = float(cleaned)
    except (ValueError, ZeroDivisionError):
        raise ValueError(f"not a shutter time: '{text}' (expected e.g. '1/125' or '2')") from None
    low, high = SHUTTER_RANGE_S
    if not low <= value <= high:
        raise ValueError(f"shutter time '{text}' is out of range [1/{1 / low:.0f} s, {high:g} s]")
    return value
