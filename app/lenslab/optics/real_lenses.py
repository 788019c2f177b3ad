"""Real lenses by name or by file: what a camera's ``real_lens`` names, made ready to trace once and kept.

A camera names its real lens as a lens preset does (``"50mm f/2 double-Gauss"``: a prescription file in a presets
folder's ``lenses/``) or by a file's path (our TOML or JSON, or pbrt's ``.dat``). Building a :class:`LensSystem`
and, above all, a :class:`LensSetting` (its focus found by tracing, its exit-pupil table) costs tenths of a second,
and the studio asks for the camera's frame at every edit and redraw: both are kept, keyed by what they are made
from.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from .aperture import Aperture
from .lens_system import LensSetting, LensSystem
from .prescription import PRESCRIPTION_SUFFIXES, LensPrescription, read_prescription_file

__all__ = ["lens_setting", "names_a_file", "real_lens_system", "system_for"]

def names_a_file(text: str) -> bool:
    """Whether a ``real_lens`` value is a path (it ends in a prescription file's suffix) rather than a preset's
    name (names hold slashes: "50 mm f/2")."""
    return Path(text).suffix.lower() in PRESCRIPTION_SUFFIXES


@lru_cache(maxsize=64)
def system_for(prescription: LensPrescription) -> LensSystem:
    """The traceable lens of a prescription (kept: prescriptions are immutable and compare by value)."""
    return LensSystem(prescription)


@lru_cache(maxsize=16)
def _system_from_file(path: str, modified_ns: int) -> LensSystem:
    return system_for(read_prescription_file(path))


def real_lens_system(text: str) -> LensSystem:
    """The lens a camera's ``real_lens`` names: a file (read again when it changes), or a lens preset that has a
    prescription. A ValueError in one line when there is no such lens, or the preset is a thin lens."""
    if names_a_file(text):
        path = Path(text).expanduser()
        try:
            modified = path.stat().st_mtime_ns
        except OSError:
            raise ValueError(f"{text}: no such lens file") from None
        return _system_from_file(str(path.resolve()), modified)
    preset = _preset_named(text, _lens_folders_state())
    if preset.prescription is None:
        raise ValueError(f"'{preset.name}' is a thin-lens preset, not a lens traced through its glass "
                         "(mount it as the lens, not as real_lens)")
    return system_for(preset.prescription)


def _lens_folders_state() -> tuple:
    """What the lens presets' folders hold, by name and modification time: a lookup by name is kept until a file
    is added, removed or edited (reading every preset file again costs tens of milliseconds, and the studio looks
    its camera's lens up at every refresh)."""
    from .lenses import LENSES_DIR
    from .presetfiles import preset_dirs

    state = []
    for folder in preset_dirs():
        lenses = folder / LENSES_DIR
        if lenses.is_dir():
            state.extend((str(path), path.stat().st_mtime_ns) for path in sorted(lenses.iterdir()))
    return tuple(state)


@lru_cache(maxsize=32)
def _preset_named(text: str, folders_state: tuple):
    from .lenses import find_lens

    return find_lens(text)


@lru_cache(maxsize=32)
def _setting(system: LensSystem, f_number: float, focus_distance_mm: float, film_mm: tuple[float, float],
             film_radius_mm: float, iris: tuple[int, float, float], dispersion: bool) -> LensSetting:
    blades, rotation_rad, curvature = iris
    return system.setting(f_number, focus_distance_mm, film_mm, film_radius_mm=film_radius_mm,
                          aperture=Aperture(blades=blades, rotation_rad=rotation_rad, curvature=curvature),
                          dispersion=dispersion)


def lens_setting(system: LensSystem, f_number: float, focus_distance_mm: float, film_mm: tuple[float, float],
                 film_radius_mm: float, aperture: Aperture, dispersion: bool = True) -> LensSetting:
    """The lens at ``f_number``, focused ``focus_distance_mm`` from the sensor, making an image of ``film_mm``
    whose pupil table reaches ``film_radius_mm``, its glass dispersing or not (kept for the next frame of the
    same camera)."""
    iris = (int(aperture.blades), float(aperture.rotation_rad), float(aperture.curvature))
    return _setting(system, float(f_number), float(focus_distance_mm), (float(film_mm[0]), float(film_mm[1])),
                    float(film_radius_mm), iris, bool(dispersion))
