"""Exposure as a camera makes it: aperture, shutter speed and ISO, and the light meter that suggests them
(docs/colour.md, "Exposure").

A camera's ``exposure_mode`` is one of:

* ``compensated`` (the default for scenes in arbitrary units): the picture's brightness does not depend on the
  camera's settings, as if an automatic exposure made up for every change of aperture, so that a photographer can
  judge depth of field at f/1.4 and f/16 side by side. The render holds the scene's values as they are.
* ``physical`` (manual): each stop of aperture, shutter or ISO is a stop of light, on a scene lit in photometric
  units (scene-linear 1 is a luminance of 1 cd/m^2: scene/light_units.py).
* ``auto``: aperture priority. The meter reads the render and picks the shutter time that puts its reading at
  middle grey; the f-number and ISO stay as set.

The calibration is a reflected-light meter's, ISO 2720's, as Lagarde and de Rousiers ("Moving Frostbite to PBR",
2014, section 5.1) apply it in Frostbite and Unity's HDRP::

    EV100 = log2(N^2 / t) - log2(S / 100)                      (the camera's settings)
    EV100 = log2(L S / K)  at S = 100, K = 12.5 cd s / m^2      (what a meter reading luminance L suggests)

A camera set to what the meter suggests maps the metered luminance to middle grey, scene-linear 0.18 (the ACES
and OCIO convention, an 18% grey card under a unit white), so the scale from luminance to the picture is::

    scale = 0.18 / L_metered = 0.18 * 100 / (K 2^EV100) = 0.18 t S / (K N^2)

(Frostbite's own exposure, 1 / (1.2 * 2^EV100), is ISO 12232's saturation-based one: it puts the meter's reading at
0.104, 0.79 stops under middle grey.) An aperture that passes less light than the round f/N stop (an aperture
image) counts with its real area. Sunny 16 (f/16, 1/ISO s) is EV100 14.6: a sunlit 18% card, about 3,200 cd/m^2
under 56,000 lux, lands at middle grey.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .thinlens import require_positive

EXPOSURE_MODES = ("compensated", "physical", "auto")

#: The ISO speeds LensLab accepts, and the shutter times, seconds.
ISO_RANGE = (1.0, 1_000_000.0)
SHUTTER_RANGE_S = (1e-6, 3600.0)

#: ISO 2720's calibration constant of a reflected-light meter, cd s / m^2 (12.5: Canon, Nikon, Sekonic).
REFLECTED_METER_K = 12.5
#: Where a meter's reading lands: scene-linear middle grey.
MIDDLE_GREY = 0.18
#: The two ways the meter reads the picture: the mean over the frame's luminance weighted to its centre, or the
#: spot (SPOT_FRACTION of the frame's diagonal, at its centre or a chosen point).
METER_MODES = ("average", "spot")
SPOT_FRACTION = 0.05
#: The average's weighting: a gaussian this fraction of the frame's width and height wide (one standard deviation).
CENTRE_WEIGHT_SIGMA = 1.0 / 3.0


def ev100(f_number: float, shutter_s: float, iso: float) -> float:
    """Exposure value at ISO 100 of these settings: ``log2(N^2 / t) - log2(S / 100)``. f/8, 1/125 s, ISO 100:
    12.97."""
    n = require_positive("f_number", f_number)
    t = require_positive("shutter_s", shutter_s)
    s = require_positive("iso", iso)
    return math.log2(n * n / t) - math.log2(s / 100.0)


def exposure_scale(f_number: float, shutter_s: float, iso: float, light_fraction: float = 1.0) -> float:
    """What scene-linear luminance (cd/m^2) is multiplied by for a physical exposure: ``0.18 t S / (K N^2)``
    times the fraction of the round stop's light the aperture passes."""
    n = require_positive("f_number", f_number)
    t = require_positive("shutter_s", shutter_s)
    s = require_positive("iso", iso)
    return MIDDLE_GREY * t * s * light_fraction / (REFLECTED_METER_K * n * n)


def metered_ev100(luminance_cd_m2: float, light_fraction: float = 1.0) -> float:
    """The EV100 a reflected-light meter suggests for a reading of ``luminance_cd_m2``: ``log2(L 100 / K)``. A
    meter behind an aperture that passes ``light_fraction`` of the round stop's light sees that much less: the EV
    is lower by log2 of it, and the shutter it asks for longer."""
    return (math.log2(require_positive("metered luminance", luminance_cd_m2) * 100.0 / REFLECTED_METER_K)
            + math.log2(require_positive("light_fraction", light_fraction)))


def ev100_to_luminance(ev: float) -> float:
    """The luminance (cd/m^2) a reflected-light meter reads as ``ev`` at ISO 100, the inverse of metered_ev100:
    (K / 100) 2^EV. EV 0: 0.125 cd/m^2."""
    return REFLECTED_METER_K / 100.0 * 2.0 ** ev


def shutter_for(ev: float, f_number: float, iso: float) -> float:
    """The shutter time (s) that gives exposure value ``ev`` (at ISO 100) at ``f_number`` and ``iso``:
    ``N^2 100 / (S 2^EV)``."""
    n = require_positive("f_number", f_number)
    s = require_positive("iso", iso)
    return n * n * 100.0 / (s * 2.0 ** ev)


def nearest_third_stop_shutter(seconds: float) -> float:
    """The camera shutter time in third stops (1/125, 1/100, 1/80, ...) nearest ``seconds`` in stops."""
    t = require_positive("shutter_s", seconds)
    thirds = round(3 * math.log2(t))
    return 2.0 ** (thirds / 3)


def meter_luminance(luminance: np.ndarray, mode: str = "average", spot: tuple[float, float] = (0.5, 0.5)) -> float:
    """A meter's reading (cd/m^2 on a photometric scene) of the image's luminance (H, W): ``average``, the mean
    weighted towards the frame's centre (a gaussian CENTRE_WEIGHT_SIGMA of the frame wide, as a camera's
    centre-weighted average), or ``spot``, the mean over a disk of SPOT_FRACTION of the diagonal at ``spot`` (x, y
    as fractions of the width and height from the top left). Pixels with no value (NaN) do not count; 0 for an
    image with none."""
    if mode not in METER_MODES:
        raise ValueError(f"unknown meter mode '{mode}' (choose from {', '.join(METER_MODES)})")
    lum = np.asarray(luminance, np.float64)
    height, width = lum.shape
    y, x = np.mgrid[0:height, 0:width]
    px, py = (x + 0.5) / width - spot[0], (y + 0.5) / height - spot[1]
    if mode == "spot":
        radius = SPOT_FRACTION * math.hypot(width, height) / 2
        weights = ((px * width) ** 2 + (py * height) ** 2 <= max(radius, 0.75) ** 2).astype(np.float64)
    else:
        cx, cy = (x + 0.5) / width - 0.5, (y + 0.5) / height - 0.5
        weights = np.exp(-(cx * cx + cy * cy) / (2 * CENTRE_WEIGHT_SIGMA ** 2))
    weights = np.where(np.isfinite(lum), weights, 0.0)
    total = weights.sum()
    return float((np.where(np.isfinite(lum), lum, 0.0) * weights).sum() / total) if total > 0 else 0.0


@dataclass(frozen=True)
class Exposure:
    """A picture's exposure as a camera made it: the ``scale`` from scene-linear values to the picture's, the
    ``shutter_s`` it was made with (auto: the one the meter chose), its ``ev100`` (None: compensated, no camera
    settings apply) and the meter's reading (auto only)."""

    scale: float
    shutter_s: float
    ev100: float | None = None
    metered_cd_m2: float | None = None


def camera_exposure(mode: str, f_number: float, shutter_s: float, iso: float, light_fraction: float = 1.0,
                    luminance: np.ndarray | None = None, meter_mode: str = "average",
                    spot: tuple[float, float] = (0.5, 0.5), reading: float | None = None) -> Exposure:
    """The exposure of a camera in ``mode`` (EXPOSURE_MODES). ``auto`` reads ``luminance`` (H, W: the render's
    scene-linear luminance) with the meter, or takes the meter's ``reading`` (cd/m^2) made already, and sets the
    shutter so that it lands at middle grey, the f-number and ISO as given (aperture priority). The aperture's
    ``light_fraction`` counts in both physical modes, as the light a camera's through-the-lens meter sees."""
    if mode not in EXPOSURE_MODES:
        raise ValueError(f"unknown exposure mode '{mode}' (choose from {', '.join(EXPOSURE_MODES)})")
    if mode == "compensated":
        return Exposure(1.0, shutter_s)
    if mode == "physical":
        return Exposure(exposure_scale(f_number, shutter_s, iso, light_fraction), shutter_s,
                        ev100(f_number, shutter_s, iso))
    if reading is None:
        if luminance is None:
            raise ValueError("auto exposure needs the image to meter, or a reading")
        reading = meter_luminance(luminance, meter_mode, spot)
    if not reading > 0.0:  # a black frame: nothing to meter, the camera's own shutter stays
        return Exposure(exposure_scale(f_number, shutter_s, iso, light_fraction), shutter_s,
                        ev100(f_number, shutter_s, iso), 0.0)
    ev = metered_ev100(reading, light_fraction)
    chosen = min(max(shutter_for(ev, f_number, iso), SHUTTER_RANGE_S[0]), SHUTTER_RANGE_S[1])
    return Exposure(exposure_scale(f_number, chosen, iso, light_fraction), chosen, ev100(f_number, chosen, iso),
                    reading)


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
