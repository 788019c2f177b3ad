"""Lens presets: primes and zooms with their aperture range and iris, one file each.

A lens preset limits what the camera panel offers (focal length, f-number)
and tells the renderer the shape of the aperture: ``aperture_blades`` straight
(or rounded) blades make polygonal bokeh, 0 means a circular stop.

Two kinds share the lens list. A thin-lens preset (a JSON file of the keys below) sets the thin-lens camera's
controls. A real lens (a prescription: our TOML or JSON with ``surfaces``, or pbrt's ``.dat``; see
optics/prescription.py) is traced through its glass, and its focal length and widest aperture come from the glass
(docs/lenses.md).
"""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path
from dataclasses import KW_ONLY, dataclass, field
from typing import TYPE_CHECKING, Iterable, Sequence

from .presetfiles import FieldError, PresetError, build_preset, merge_by_name, preset_dirs, read_json
from .stops import MAX_F_NUMBER, MIN_F_NUMBER, Scale, exact_f_number, is_offered_f_number
# A lens preset is a control (the studio mounts it): it marks stops and focal lengths within the controls' ranges,
# not everything a scene may hold (stops.F_NUMBER_RANGE, thinlens.FOCAL_LENGTH_RANGE_MM).
from .thinlens import FOCAL_LENGTH_CONTROL_RANGE_MM

if TYPE_CHECKING:  # prescription.py takes the iris's limits from here
    from .prescription import LensPrescription

__all__ = ["LensPreset", "LENSES_DIR", "MAX_APERTURE_BLADES", "find_lens", "load_lens_presets"]

#: Folder of lens files inside a presets folder.
LENSES_DIR = "lenses"

#: More blades than this is indistinguishable from a circle; use 0 instead.
MAX_APERTURE_BLADES = 32



@dataclass(frozen=True)
class LensPreset:
    """A lens: a prime (``focal_length_mm``) or a zoom (``focal_range_mm``), never both.

    Fields after ``name`` are keyword-only, since exactly one of the two focal
    fields is given.
    """

    name: str
    _: KW_ONLY
    #: Focal length of a prime, mm.
    focal_length_mm: float | None = None
    #: (shortest, longest) focal length of a zoom, mm.
    focal_range_mm: tuple[float, float] | None = None
    #: Largest aperture, e.g. 1.4 (constant over the zoom range).
    widest_f_number: float
    #: Smallest aperture, e.g. 22.
    narrowest_f_number: float = 22.0
    #: Number of iris blades; 0 = circular aperture, else 3..32.
    aperture_blades: int = 0
    #: Rotation of the blade polygon about the optical axis, degrees,
    #: counter-clockwise seen from behind the camera; 0 puts a vertex on +x.
    blade_rotation_deg: float = 0.0
    #: 0 = straight blades (sharp polygon) .. 1 = fully rounded (a circle).
    #: Modern lenses with "rounded blades" sit around 0.5 to 0.8.
    blade_roundness: float = 0.0
    #: Minimum focus distance as marked on the lens (from the sensor plane), m.
    min_focus_distance_m: float | None = None
    #: Free text shown as a tooltip.
    description: str = field(default="", compare=False)
    #: A real lens's glass, traced by the renderer (None: a thin-lens preset).
    prescription: LensPrescription | None = None
    #: A real lens read from a file named by its path (not found by name in a presets folder): that path, which a
    #: camera mounting it records as its ``real_lens``.
    source_file: str = field(default="", compare=False)

    @property
    def is_real(self) -> bool:
        """Traced through its glass, rather than a thin lens with controls."""
        return self.prescription is not None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.strip():
            raise FieldError("name", "must be a non-empty string")
        self._check_focal()
        for key in ("widest_f_number", "narrowest_f_number"):
            value = getattr(self, key)
            if not is_offered_f_number(value):
                raise FieldError(
                    key, f"f-number must lie in [{MIN_F_NUMBER:g}, {MAX_F_NUMBER:g}], got {value!r}"
                )
            # A lens's marks stand for exact stops: an f/1.4 lens opens to 2^0.5, and stops down to 2^4.5 at f/22.
            object.__setattr__(self, key, exact_f_number(float(value)))
        if self.narrowest_f_number < self.widest_f_number:
            raise FieldError(
                "narrowest_f_number",
                f"f/{self.narrowest_f_number:g} is wider than widest_f_number f/{self.widest_f_number:g}",
            )
        blades = self.aperture_blades
        if isinstance(blades, bool) or not isinstance(blades, int) or not (
            blades == 0 or 3 <= blades <= MAX_APERTURE_BLADES
        ):
            raise FieldError(
                "aperture_blades", f"must be 0 (circular) or 3..{MAX_APERTURE_BLADES}, got {blades!r}"
            )
        if not math.isfinite(self.blade_rotation_deg):
            raise FieldError("blade_rotation_deg", "must be finite")
        object.__setattr__(self, "blade_rotation_deg", float(self.blade_rotation_deg))
        if not 0.0 <= self.blade_roundness <= 1.0:
            raise FieldError("blade_roundness", f"must lie in [0, 1], got {self.blade_roundness!r}")
        object.__setattr__(self, "blade_roundness", float(self.blade_roundness))
        mfd = self.min_focus_distance_m
        if mfd is not None:
            if not (0.0 < mfd < math.inf):
                raise FieldError("min_focus_distance_m", f"must be positive, got {mfd!r}")
            object.__setattr__(self, "min_focus_distance_m", float(mfd))

    def _check_focal(self):
        def check_mm(key, value):
            low, high = FOCAL_LENGTH_CONTROL_RANGE_MM
            if not (low <= value <= high):
                raise FieldError(key, f"must lie in [{low:g}, {high:g}] mm, got {value!r}")
            return float(value)

        prime, zoom = self.focal_length_mm, self.focal_range_mm
        if (prime is None) == (zoom is None):
            raise FieldError(
                "focal_length_mm", "give exactly one of focal_length_mm (prime) and focal_range_mm (zoom)"
            )
        if prime is not None:
            object.__setattr__(self, "focal_length_mm", check_mm("focal_length_mm", prime))
            return
        zoom = tuple(zoom)
        if len(zoom) != 2:
            raise FieldError("focal_range_mm", "must be [shortest, longest]")
        short, long_ = (check_mm("focal_range_mm", v) for v in zoom)
        if not short < long_:
            raise FieldError(
                "focal_range_mm",
                f"shortest {short:g} mm must be below longest {long_:g} mm (a prime uses focal_length_mm)",
            )
        object.__setattr__(self, "focal_range_mm", (short, long_))

    @property
    def is_zoom(self) -> bool:
        return self.focal_range_mm is not None

    @property
    def min_focal_length_mm(self) -> float:
        return self.focal_range_mm[0] if self.is_zoom else self.focal_length_mm

    @property
    def max_focal_length_mm(self) -> float:
        return self.focal_range_mm[1] if self.is_zoom else self.focal_length_mm

    def clamp_focal_length(self, mm: float) -> float:
        """``mm`` limited to what the lens covers (a prime always returns its focal length)."""
        mm = float(mm)
        if math.isnan(mm):
            raise ValueError("focal length is NaN")
        return min(max(mm, self.min_focal_length_mm), self.max_focal_length_mm)

    def clamp_f_number(self, n: float) -> float:
        """``n`` limited to [widest_f_number, narrowest_f_number]."""
        n = float(n)
        if math.isnan(n):
            raise ValueError("f-number is NaN")
        return min(max(n, self.widest_f_number), self.narrowest_f_number)

    def available_stops(self, scale: Scale = "third") -> tuple[float, ...]:
        """The stops of ``scale`` (a name from stops.STOP_SCALES or a StopScale: its exact values; or a sequence
        of f-numbers) this lens can set, plus its own end stops.

        f/1.2 .. f/16 in thirds gives the exact (1.26, 1.41, 1.59, ..., 16).  The lens's own widest
        and narrowest f-numbers are always included, even when they are not
        marks (an f/1.8 lens on a full-stop scale starts at 1.8).  Pass the result as ``scale`` to
        ``stops.step_stop`` to step within the lens.
        """
        from .stops import scale_values

        scale = scale_values(scale)
        rel = 1e-3  # same tolerance as stops.py: 5.6 and 5.600001 are one mark
        inside = [
            float(s) for s in scale
            if self.widest_f_number * (1 - rel) <= s <= self.narrowest_f_number * (1 + rel)
        ]
        if not inside or not math.isclose(inside[0], self.widest_f_number, rel_tol=rel):
            inside.insert(0, self.widest_f_number)
        if not math.isclose(inside[-1], self.narrowest_f_number, rel_tol=rel):
            inside.append(self.narrowest_f_number)
        return tuple(inside)

    def mount(self, focal_length_mm: float, f_number: float) -> dict[str, object]:
        """The camera settings this lens gives a camera set to ``focal_length_mm`` and ``f_number``: the focal
        length and aperture kept within what the lens can do, and the lens's iris (as ThinLensCamera's fields).
        A real lens also names itself as the camera's ``real_lens`` and sets aside the thin lens's stand-ins for
        what its glass does (squeeze, barrel clipping, an aperture image); a thin-lens preset takes a real lens
        off."""
        settings = {"focal_length_mm": self.clamp_focal_length(focal_length_mm),
                    "f_number": self.clamp_f_number(f_number),
                    "aperture_blades": self.aperture_blades,
                    "blade_rotation_deg": self.blade_rotation_deg,
                    "blade_curvature": self.blade_roundness,
                    "real_lens": (self.source_file or self.name) if self.is_real else ""}
        if self.is_real:
            settings.update(anamorphic_squeeze=1.0, barrel_clipping=0.0, aperture_image="", pinhole=False)
        return settings


_KINDS = {
    "name": "string",
    "focal_length_mm": "number or null",
    "focal_range_mm": "number pair or null",
    "widest_f_number": "number",
    "narrowest_f_number": "number",
    "aperture_blades": "integer",
    "blade_rotation_deg": "number",
    "blade_roundness": "number",
    "min_focus_distance_m": "number or null",
    "description": "string",
}


def read_lens_file(path) -> LensPreset:
    """One lens from one file: a thin-lens preset's JSON, or a real lens's prescription (PresetError naming file
    and key on any problem)."""
    from .prescription import is_prescription_file, read_prescription_file

    if is_prescription_file(path):
        prescription = read_prescription_file(path)  # a PresetError naming the file, the line or the key
        try:
            return real_lens_preset(prescription)
        except ValueError as exc:  # read, but no lens (afocal glass, say)
            raise PresetError(path, None, str(exc)) from None
    return build_preset(LensPreset, read_json(path), _KINDS, path)


def real_lens_preset(prescription: LensPrescription) -> LensPreset:
    """The lens-list entry of a real lens: its focal length and widest aperture from its glass (as marked: an f/2
    lens is sold and set as f/2 even where paraxial optics says f/2.03; its stop cannot open further than the
    glass allows; LensSystem.marked_f_number)."""
    from .real_lenses import system_for

    system = system_for(prescription)
    widest = system.marked_f_number
    return LensPreset(prescription.name, focal_length_mm=system.efl, widest_f_number=widest,
                      narrowest_f_number=max(widest, prescription.narrowest_f_number),
                      aperture_blades=prescription.aperture_blades,
                      blade_rotation_deg=prescription.blade_rotation_deg,
                      blade_roundness=prescription.blade_roundness,
                      min_focus_distance_m=prescription.min_focus_distance_m,
                      description=prescription.description or prescription.source, prescription=prescription)


def _read_lens_dir(folder) -> list[LensPreset]:
    lenses: list[LensPreset] = []
    seen: dict[str, object] = {}
    # Sorted so that the result does not depend on the file system; dot files
    # are editor backups and lock files, not presets.
    from .prescription import PRESCRIPTION_SUFFIXES  # a thin-lens preset is JSON; a real lens, any of these

    files = [path for suffix in {".json", *PRESCRIPTION_SUFFIXES} for path in folder.glob(f"*{suffix}")]
    for path in sorted(files):
        if path.name.startswith("."):
            continue
        lens = read_lens_file(path)
        if lens.name in seen:
            raise PresetError(path, "name", f"{lens.name!r} is also the name in {seen[lens.name]}")
        seen[lens.name] = path.name
        lenses.append(lens)
    return lenses


def load_lens_presets(
    extra_dirs: Iterable[os.PathLike | str] = (),
    *,
    include_shipped: bool = True,
    include_user: bool = True,
) -> list[LensPreset]:
    """All lens presets from ``<folder>/lenses/*.json``: shipped, user's, then ``extra_dirs``.

    A lens whose name was already defined in an earlier folder replaces it.
    Sorted by focal length (shortest end first), primes before zooms that
    start at the same length.  Raises PresetError on any broken file.
    """
    groups = []
    for folder in preset_dirs(extra_dirs, include_shipped=include_shipped, include_user=include_user):
        lens_dir = folder / LENSES_DIR
        if lens_dir.is_dir():
            groups.append(_read_lens_dir(lens_dir))
    lenses = merge_by_name(groups)
    return sorted(lenses, key=lambda l: (l.min_focal_length_mm, l.max_focal_length_mm, l.name))


def _lens_key(name: str) -> str:
    """How a lens is named loosely: "85 mm f/1.4", "85mm-f1.4" (its file's name) and "85MM F1.4" are one lens."""
    return "".join(ch for ch in name.lower() if ch.isalnum() or ch == ".")


def find_lens(name: str, lenses: Sequence[LensPreset] | None = None) -> LensPreset:
    """The lens preset called ``name`` (its name, or its file's name without .json; case, spaces, dashes and
    slashes do not matter), or else the one lens whose name begins so: "85mm" is the 85 mm f/1.4 while only one
    85 mm lens is installed. A ValueError that lists the lenses there are when none is called that, or the
    candidates when the beginning fits several."""
    from .real_lenses import names_a_file

    if names_a_file(name) and lenses is None:  # a prescription file named on the command line or in a scene
        path = Path(name).expanduser()
        return dataclasses.replace(read_lens_file(path), source_file=str(path.resolve()))
    lenses = load_lens_presets() if lenses is None else lenses
    wanted = _lens_key(name)
    keyed = [(_lens_key(lens.name), lens) for lens in lenses]
    for key, lens in keyed:
        if key == wanted:
            return lens
    beginning_so = [lens for key, lens in keyed if wanted and key.startswith(wanted)]
    if len(beginning_so) == 1:
        return beginning_so[0]
    if beginning_so:
        raise ValueError(f"'{name}' could be any of {', '.join(lens.name for lens in beginning_so)}: name one whole")
    raise ValueError(f"no lens preset called '{name}' (there are: {', '.join(lens.name for lens in lenses)})")
