"""Aperture stops: full, half and third-stop scales (marks and exact values), snapping and stepping, text.

An f-number ``N`` is focal length over entrance-pupil diameter; each *stop*
halves the light, i.e. multiplies ``N`` by ``sqrt(2)``, a half stop by ``2 ** (1/4)`` and a third stop by
``2 ** (1/6)``.  Lenses and cameras *mark* rounded values (5.6 rather than 5.657, 11 rather than 11.31),
but an iris is calibrated to the exact ones: that is what makes each mark the same step of light. So
LensLab shows marks and renders exact values. Three scales (:data:`STOP_SCALES`): full, half and third
stops, each with its marks and the exact ``2 ** (k / 2)``, ``2 ** (k / 4)``, ``2 ** (k / 6)`` beside them.
Text a user types ("f/11", "11") means the marked stop's exact value (:func:`parse_f_number`); a number
read from a scene file is taken as written. Distances along a scale are measured in stops
(``log2 N^2``), not in N.
"""

from __future__ import annotations

import bisect
import math
import re
from dataclasses import dataclass
from functools import cached_property
from typing import Sequence, Union

__all__ = [
    "DEFAULT_STOP_SCALE",
    "STOP_SCALES",
    "StopScale",
    "stop_scale",
    "scale_values",
    "exact_f_number",
    "marked_f_number",
    "THIRD_STOPS",
    "EXTENDED_THIRD_STOPS",
    "HALF_STOPS",
    "FULL_STOPS",
    "MIN_F_NUMBER",
    "MAX_F_NUMBER",
    "F_NUMBER_RANGE",
    "F_NUMBER_CONTROL_RANGE",
    "is_valid_f_number",
    "is_offered_f_number",
    "stops_between",
    "nearest_stop",
    "step_stop",
    "format_f_number",
    "parse_f_number",
]

#: The third-stop scale as marked on lenses and camera displays, f/1.4 to f/22: *marked* values (the exact
#: ones are ``STOP_SCALES["third"].exact``), kept for callers that want the printed numbers.
THIRD_STOPS: tuple[float, ...] = (
    1.4, 1.6, 1.8, 2, 2.2, 2.5, 2.8, 3.2, 3.5, 4, 4.5, 5, 5.6,
    6.3, 7.1, 8, 9, 10, 11, 13, 14, 16, 18, 20, 22,
)

#: The same scale continued both ways over the controls' range, f/0.7 to
#: f/128 (marked values: 1.1 and 1.2 for 1.12 and 1.26, 25 and 29 for 25.4
#: and 28.5, ...): the marks of ``STOP_SCALES["third"]``.
EXTENDED_THIRD_STOPS: tuple[float, ...] = (
    (0.7, 0.8, 0.9, 1, 1.1, 1.2)
    + THIRD_STOPS
    + (25, 29, 32, 36, 40, 45, 51, 57, 64, 72, 81, 90, 102, 114, 128)
)

#: Full stops as marked, f/0.7 to f/128 (exact: 2 ** (k / 2)).
FULL_STOPS: tuple[float, ...] = (0.7, 1, 1.4, 2, 2.8, 4, 5.6, 8, 11, 16, 22, 32, 45, 64, 90, 128)
#: Half stops as marked, f/0.7 to f/128 (exact: 2 ** (k / 4)): 1.7 for 1.68, 9.5 for 9.51, 13 for 13.45.
HALF_STOPS: tuple[float, ...] = (0.7, 0.8, 1, 1.2, 1.4, 1.7, 2, 2.4, 2.8, 3.3, 4, 4.8, 5.6, 6.7, 8, 9.5, 11, 13,
                                 16, 19, 22, 27, 32, 38, 45, 54, 64, 76, 90, 108, 128)


@dataclass(frozen=True)
class StopScale:
    """A scale of apertures: ``marks`` as printed on lenses, ``exact`` the f-numbers they stand for,
    ``2 ** (k / (2 * steps_per_stop))`` with f/1 at k = 0.

    A mark is the exact value rounded the conventional way (two significant digits, with the traditional
    exceptions such as 11 for 11.31 and 13 for both 12.70 and 13.45), so marks alone are uneven steps; the iris
    is calibrated to the exact values, and those are what LensLab renders.
    """

    name: str
    #: Marks per stop of light: 1 (full), 2 (half) or 3 (third).
    steps_per_stop: int
    #: The marked f-numbers, ascending, one a step; they must include f/1.
    marks: tuple[float, ...]

    @cached_property
    def exact(self) -> tuple[float, ...]:
        """The exact f-numbers of the marks, in the same order (each mark's own stop of light)."""
        first = -self.marks.index(1)  # the mark f/1 is k = 0
        return tuple(2.0 ** ((first + i) / (2 * self.steps_per_stop)) for i in range(len(self.marks)))

    @property
    def step_in_stops(self) -> float:
        """One step of this scale in stops of light (1, 1/2, 1/3)."""
        return 1.0 / self.steps_per_stop


#: The scales a camera steps its aperture along, by name.
STOP_SCALES: dict[str, StopScale] = {
    "full": StopScale("full", 1, FULL_STOPS),
    "half": StopScale("half", 2, HALF_STOPS),
    "third": StopScale("third", 3, EXTENDED_THIRD_STOPS),
}
DEFAULT_STOP_SCALE = "third"

#: What functions taking a scale accept: a scale's name, a StopScale (its exact values), or the f-numbers
#: themselves, ascending.
Scale = Union[str, StopScale, Sequence[float]]


def stop_scale(scale: str | StopScale = DEFAULT_STOP_SCALE) -> StopScale:
    """The :class:`StopScale` named ``scale`` ("full", "half", "third"); a StopScale as it is.

    Raises ValueError listing the names for any other name.
    """
    if isinstance(scale, StopScale):
        return scale
    if scale not in STOP_SCALES:
        raise ValueError(f"unknown stop scale {scale!r} (choose from {', '.join(STOP_SCALES)})")
    return STOP_SCALES[scale]


def scale_values(scale: Scale) -> Sequence[float]:
    """The f-numbers a scale argument stands for: a name's or a StopScale's exact values, a sequence itself."""
    if isinstance(scale, (str, StopScale)):
        return stop_scale(scale).exact
    return scale


def exact_f_number(n: float, scale: str | StopScale = DEFAULT_STOP_SCALE) -> float:
    """The exact f-number of a marked stop of ``scale`` (11 -> 11.3137 on the third-stop scale, 13 -> 12.70 on
    thirds but 13.45 on halves); any other number as it is.

    Marks are rounded for printing; the iris is calibrated to the exact value, so that is what a typed or
    preset mark means. A number within 1e-3 (relative) of a mark counts as that mark.
    """
    stops = stop_scale(scale)
    for mark, exact in zip(stops.marks, stops.exact):
        if math.isclose(n, mark, rel_tol=_SAME_STOP_REL_TOL):
            return exact
    return float(n)


def marked_f_number(n: float, scale: str | StopScale | None = None) -> float:
    """The mark a lens prints for an exact stop (11.3137 -> 11); any other number as it is.

    Without ``scale``, the third-stop marks are tried, then the half-stop ones (every full stop is on both).
    A number within 1e-3 (relative) of an exact stop counts as that stop.
    """
    for name in ((scale,) if scale else ("third", "half")):
        stops = stop_scale(name)
        for mark, exact in zip(stops.marks, stops.exact):
            if math.isclose(n, exact, rel_tol=_SAME_STOP_REL_TOL):
                return mark
    return float(n)


#: Two ranges, not one. F_NUMBER_CONTROL_RANGE, [MIN_F_NUMBER, MAX_F_NUMBER], is what the studio's controls
#: offer and a lens preset may mark: 0.5 is the theoretical limit of an aplanatic lens in air (N = 1 / (2 NA),
#: NA < 1); f/128 is about the smallest aperture ever marked on a lens. It limits what the controls offer, never
#: what a scene holds.
MIN_F_NUMBER = 0.5
MAX_F_NUMBER = 128.0
F_NUMBER_CONTROL_RANGE = (MIN_F_NUMBER, MAX_F_NUMBER)
#: F_NUMBER_RANGE is what an f-number may *be*: what a scene file, an importer, the command line and a batch file
#: accept, and what the studio shows as it is. The thin lens itself takes any N > 0 (pbrt and Mitsuba take any
#: aperture radius: Mitsuba's own documentation scene sensor_thinlens is f/0.13). What bounds N is the GPU's
#: float32: the lens radius f / 2N and the focal length meet in the camera's float32 sums (the ray's origin on
#: the lens, its direction to the point of focus), and float32 resolves one beside the other only while they
#: differ by less than its 24-bit significand, 2^24 = 1.7e7. A million either way keeps 4 bits to spare, and the
#: exposure's N^2 stays within 1e+-12 (float32 reaches 3.4e38). Beyond f/1e6 the lens is a pinhole to float32;
#: below f/1e-6 the aperture is a million focal lengths wide.
F_NUMBER_RANGE = (1e-6, 1e6)

# Two values closer than this (relative) are the same marked stop.  Adjacent
# third stops differ by about 12 %, so this only absorbs float noise and
# rounding such as 5.6 vs 5.60001.
_SAME_STOP_REL_TOL = 1e-3


def is_valid_f_number(n: float) -> bool:
    """True when ``n`` is an f-number a scene may hold: a finite number in :data:`F_NUMBER_RANGE` (f/0.13 is one;
    the studio's controls offer :data:`F_NUMBER_CONTROL_RANGE`)."""
    return _number_within(n, F_NUMBER_RANGE)


def is_offered_f_number(n: float) -> bool:
    """True when ``n`` lies in what the controls offer and a lens may mark, :data:`F_NUMBER_CONTROL_RANGE`."""
    return _number_within(n, F_NUMBER_CONTROL_RANGE)


def _number_within(n, bounds: tuple[float, float]) -> bool:
    """Whether ``n`` is a number in [low, high] (NaN is in no range)."""
    try:
        n = float(n)
    except (TypeError, ValueError):
        return False
    return bounds[0] <= n <= bounds[1]


def _checked(n: float) -> float:
    if not is_valid_f_number(n):
        raise ValueError(f"f-number must be a number in [{F_NUMBER_RANGE[0]:g}, {F_NUMBER_RANGE[1]:g}], got {n!r}")
    return float(n)


def stops_between(n1: float, n2: float) -> float:
    """Exposure difference in stops going from f/n1 to f/n2: ``2 log2(n2 / n1)``.

    Positive when n2 lets in less light.  f/2.8 -> f/5.6 is 2.0 stops.
    """
    return 2.0 * math.log2(_checked(n2) / _checked(n1))


def nearest_stop(n: float, scale: Scale = DEFAULT_STOP_SCALE) -> float:
    """The value on ``scale`` closest to ``n`` in stops (log scale): an exact stop for a named scale.

    Values outside the scale snap to its end.  ``scale`` is a name from :data:`STOP_SCALES`, a
    :class:`StopScale` (both mean its exact values) or a sequence of f-numbers, ascending; pass
    ``lens.available_stops(name)`` to snap within what a lens can do.
    """
    n = _checked(n)
    return float(min(scale_values(scale), key=lambda stop: abs(math.log(stop / n))))


def _index_on_scale(n: float, values: Sequence[float], scale: Scale) -> int | None:
    """Where ``n`` sits on ``values``: as it is, else as the exact stop of a mark (5.6 on a scale of exact
    values is 5.657) or the mark of an exact stop (5.657 on a scale of marks is 5.6); None between stops."""
    names = [scale.name if isinstance(scale, StopScale) else scale] if isinstance(scale, (str, StopScale)) else []
    names += [name for name in ("third", "half", "full") if name not in names]
    candidates = [n] + [exact_f_number(n, name) for name in names] + [marked_f_number(n)]
    for candidate in candidates:
        for i, stop in enumerate(values):
            if math.isclose(candidate, stop, rel_tol=_SAME_STOP_REL_TOL):
                return i
    return None


def step_stop(n: float, steps: int, scale: Scale = DEFAULT_STOP_SCALE) -> float:
    """Move ``steps`` marks along ``scale`` from ``n`` (positive = smaller aperture, less light).

    ``scale`` as for :func:`nearest_stop`; a named scale steps between exact values, so from an exact stop one
    step is exactly one mark's worth of light: 1, 1/2 or 1/3 stop on the full, half or third scale (by mark
    alone, f/5.6 -> f/6.3 would look like 0.34 stop and f/10 -> f/11 like 0.28). A marked value counts as its
    exact stop (from 5.6, +1 gives 6.35 on thirds). From a value between marks, the first step lands on the
    next mark in that direction (so from f/3, +1 gives 3.17 and -1 gives 2.83 on thirds). The result is clamped
    to the ends of the scale, but never moves against the requested direction: from f/1.2 on a scale starting
    at f/1.4, -1 returns f/1.2 unchanged. ``steps == 0`` snaps to the nearest mark.
    """
    n = _checked(n)
    steps = int(steps)
    values = scale_values(scale)
    if steps == 0:
        return nearest_stop(n, values)
    last = len(values) - 1
    i = _index_on_scale(n, values, scale)
    if i is None:
        if steps > 0:
            i = bisect.bisect_right(values, n)  # first mark above n
            if i > last:
                return n  # already past the narrow end
            i += steps - 1
        else:
            i = bisect.bisect_left(values, n) - 1  # last mark below n
            if i < 0:
                return n  # already past the wide end
            i += steps + 1
    else:
        i += steps
    return float(values[min(max(i, 0), last)])


def format_f_number(n: float) -> str:
    """Text as photographers write it: ``"f/2.8"``, ``"f/2"``, ``"f/0.95"``, ``"f/22"``.

    An exact stop shows its mark (``"f/11"`` for 11.31). Otherwise one decimal (two below f/1, where 0.95
    vs 0.9 matters, and two significant digits below f/0.1: ``"f/0.013"``), trailing zeros dropped.
    """
    n = marked_f_number(_checked(n))
    if n < 0.1:
        return f"f/{n:.2g}"
    text = f"{n:.2f}" if n < 1.0 else f"{n:.1f}"
    return "f/" + text.rstrip("0").rstrip(".")


# "f/2.8", "F2.8", "ƒ/2.8", "1:2.8", "2.8", "2,8" (decimal comma); spaces allowed around parts.
_F_NUMBER_RE = re.compile(
    r"^\s*(?:[fƒ]\s*/?|1\s*:)?\s*(\d+(?:[.,]\d*)?|[.,]\d+)\s*$", re.IGNORECASE
)


def parse_f_number(text: str, scale: str | StopScale = DEFAULT_STOP_SCALE) -> float:
    """Parse ``"f/2.8"``, ``"2.8"``, ``"F2.8"``, ``"1:2.8"`` (and ``"2,8"``): a marked stop of ``scale`` gives
    its exact value (2.8 -> 2.8284), any other number itself ("3" is f/3). Someone typing "f/11" means the stop
    engraved 11, whose iris is 2^3.5 = 11.31; ``scale`` settles marks two scales read differently ("13" is
    12.70 on thirds, 13.45 on halves).

    Raises ValueError naming the text when it is not an f-number or is outside what an f-number may be,
    :data:`F_NUMBER_RANGE` (f/0 is none; f/0.2 is one, as a scene file may hold it, though the studio's stops
    begin at f/0.7).
    """
    match = _F_NUMBER_RE.match(text) if isinstance(text, str) else None
    if match is None:
        raise ValueError(f"not an f-number: {text!r} (expected e.g. 'f/2.8' or '2.8')")
    n = float(match.group(1).replace(",", "."))
    if not is_valid_f_number(n):
        raise ValueError(
            f"f-number out of range [{F_NUMBER_RANGE[0]:g}, {F_NUMBER_RANGE[1]:g}]: {text!r}"
        )
    return exact_f_number(n, scale)
