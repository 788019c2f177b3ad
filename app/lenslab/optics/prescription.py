"""Real-lens prescriptions: the table of surfaces a lens designer publishes, and strict readers for it.

A thin lens is two numbers (focal length, f-number).  A real lens is a table, one row per surface,
front element first, the way every lens-design book and patent prints it::

    radius   thickness   n_d     V_d    clear aperture
    29.475   3.76        1.670   47.1   25.2     <- front of the first element: glass (n 1.67) behind it
    84.83    0.12        1                25.2     <- its back: air behind it
    ...
    0        4.5         1                17.1     <- the aperture stop, a plane (radius 0)

Each row describes one surface *and the medium behind it* (toward the sensor): its thickness is the
distance to the next vertex and its index is that of the glass (or air) in between.  This is the
convention of Kolb, Mitchell and Hanrahan (1995, "A realistic camera model for computer graphics") and of
pbrt's RealisticCamera, whose lens files this module reads as they are.  Tracing a ray through the table,
from the sensor out or from the scene in, is the business of the optics built on these types; this module
only makes sure the table describes a lens that can exist before anyone traces through it.

Two formats:

* pbrt's ``.dat`` files (pbrt-v3/v4, e.g. ``lenses/dgauss.50mm.dat`` of pbrt-v4-scenes): ``#`` comment
  lines, then rows of four numbers ``radius thickness ior aperture_diameter`` in millimetres.  A radius of
  0 is the stop and an index of 0 means air.  No dispersion: pbrt traces every wavelength alike.
* LensLab's own ``.toml`` / ``.json``: the same columns with names, an Abbe number per glass (so that the
  renderer can show chromatic aberration), and the lens's published data and iris (see presets/lenses).

Every problem is a :class:`PrescriptionError`, one line naming the file, and where the file allows it the
line, the surface (counted from 1 at the front, as the books number them) or the key.
"""

from __future__ import annotations

import codecs
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from lenslab.image_files import open_file
from lenslab.limits import number_problem

from .presetfiles import KINDS, PresetError, _describe
from .stops import MAX_F_NUMBER, MIN_F_NUMBER

__all__ = [
    "LensSurface",
    "LensPrescription",
    "PrescriptionError",
    "MAX_SURFACES",
    "PRESCRIPTION_SUFFIXES",
    "read_pbrt_lens",
    "read_prescription_file",
    "prescription_from_mapping",
    "is_prescription_file",
]

#: The GPU keeps a lens in a fixed-size array of surfaces; a table longer than this cannot be traced there.
#: 32 holds every photographic design in the usual books (a modern zoom has about 30 surfaces).
MAX_SURFACES = 32

#: The refractive index a surface may have behind it.  Air is 1; the densest optical glasses reach about
#: 2.0 and crystals such as rutile 2.9: past 3 a number is a typing mistake, not a glass.
IOR_RANGE = (1.0, 3.0)

#: Abbe numbers of real media lie between about 15 (the densest flints) and 95 (fluorite, FK glasses);
#: 150 leaves room for exotic ones while refusing V_d written in the wrong column.
MAX_ABBE = 150.0

#: A lens file is a page of numbers.  Reading stops here, so that a file named by mistake (a video, a
#: disk image) is refused without being read into memory.
MAX_FILE_BYTES = 1 << 20

#: The file name endings the readers know, by reader.
PRESCRIPTION_SUFFIXES = (".dat", ".toml", ".json")


#: Our surface keys by the names of the columns of pbrt's lens files, for errors said of a row of one.
_PBRT_COLUMNS = {"radius_mm": "radius", "thickness_mm": "thickness", "aperture_mm": "aperture"}


class PrescriptionError(PresetError):
    """A prescription that cannot be used.  ``str()`` is one line: the file (when there is one), where in it,
    and the problem, e.g. ``dgauss.dat: line 9 (surface 4): ior must lie in [1, 3], got 3.5`` or
    ``50mm.toml: 'surfaces[4].ior': must lie in [1, 3], got 3.5``.

    A PresetError, so that a preset loader that reports broken presets reports these too.  The parts are
    kept for callers that re-word or re-locate the error: ``path`` (None for a prescription built in
    memory), ``surface`` (1-based, from the front), ``line`` (1-based, in the file), ``field`` (the
    LensSurface or LensPrescription field at fault), ``key`` (the key in a TOML/JSON file) and ``problem``.
    """

    def __init__(
        self,
        path: os.PathLike | str | None,
        problem: str,
        *,
        surface: int | None = None,
        field: str | None = None,
        line: int | None = None,
        key: str | None = None,
    ):
        # PresetError.__init__ insists on a path; a prescription built in memory has none, so the parts are
        # set here and the message built the same way (file first, then where, then what).
        self.path = Path(path) if path is not None else None
        self.surface = surface
        self.field = field
        self.line = line
        self.key = key
        self.problem = " ".join(str(problem).split())  # keep the promise of one line
        if key:
            where = f"'{key}'"  # a key says which field: the problem need not
            what = self.problem
        else:
            if line is not None:
                where = f"line {line}" + (f" (surface {surface})" if surface is not None else "")
            else:
                where = f"surface {surface}" if surface is not None else ""
            # A row of a pbrt file names its columns as pbrt's comment line does, not as our keys.
            name = _PBRT_COLUMNS.get(field, field) if line is not None else field
            what = f"{name} {self.problem}" if field else self.problem
        parts = [str(p) for p in (self.path, where) if p]
        ValueError.__init__(self, ": ".join(parts + [what]))

    def __reduce__(self):
        # Exceptions pickle as their class called with ``args`` (here the message alone), which this __init__
        # does not take; a batch worker's error must cross to the scheduler whole.
        return (_rebuild_error, (self.path, self.problem, self.surface, self.field, self.line, self.key))

    def relocated(self, path, *, line: int | None = None, key: str | None = None) -> PrescriptionError:
        """The same problem, said of ``path`` (and of a line or a key there): a reader knows where a surface
        came from, the dataclass that found the problem does not."""
        return PrescriptionError(path, self.problem, surface=self.surface, field=self.field, line=line, key=key)


def _rebuild_error(path, problem, surface, field, line, key) -> PrescriptionError:
    return PrescriptionError(path, problem, surface=surface, field=field, line=line, key=key)


def _number(value: Any, name: str, path: Path | None = None) -> float:
    """``value`` as a float, or PrescriptionError: bools are not numbers, and nan, inf and 1e300 measure
    nothing (limits.number_problem, the bound every reader applies)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise PrescriptionError(path, f"must be a number, got {_describe(value)}", field=name)
    problem = number_problem(value)
    if problem:
        raise PrescriptionError(path, f"must be a finite number: {problem}", field=name)
    return float(value)


@dataclass(frozen=True)
class LensSurface:
    """One row of a prescription: a spherical surface (or the stop) and the medium behind it.

    Signs follow the optical convention: light travels from the scene (front, left) toward the sensor
    (right); a radius is positive when the centre of curvature lies to the right of the vertex.  So the
    front of a biconvex element has R > 0 and its back R < 0.
    """

    #: Signed radius of curvature, mm; + when the centre lies behind the vertex (toward the sensor).
    #: 0 marks the aperture stop, a plane; a flat refracting surface is written with a very large radius.
    radius_mm: float
    #: Axial distance from this vertex to the next one (toward the sensor), mm.  On the last surface it is
    #: the distance to the sensor at infinity focus (pbrt: the film distance, which pbrt sets by focusing).
    thickness_mm: float
    #: Refractive index at the d line (587.56 nm) of the medium behind this surface; 1.0 for air.
    ior: float
    #: Abbe number V_d = (n_d - 1) / (n_F - n_C) of that medium; None: no dispersion (air, or not known).
    abbe: float | None
    #: Clear aperture: the DIAMETER of the surface that light may pass, mm.  On the stop, the stop wide open.
    aperture_mm: float
    #: Free text: the catalogue glass the index (and Abbe number) stand for, e.g. "Schott N-BK7".
    glass: str = field(default="", compare=False)

    def __post_init__(self):
        # Numbers first, so that every later check compares floats.
        for name in ("radius_mm", "thickness_mm", "ior", "aperture_mm"):
            object.__setattr__(self, name, _number(getattr(self, name), name))
        if self.abbe is not None:
            object.__setattr__(self, "abbe", _number(self.abbe, "abbe"))
        if not isinstance(self.glass, str):
            raise PrescriptionError(None, f"must be a string, got {_describe(self.glass)}", field="glass")

        low, high = IOR_RANGE
        if not low <= self.ior <= high:
            raise PrescriptionError(None, f"must lie in [{low:g}, {high:g}] (1 is air), got {self.ior:g}",
                                    field="ior")
        if self.abbe is not None:
            if not 0.0 < self.abbe <= MAX_ABBE:
                raise PrescriptionError(None, f"must lie in (0, {MAX_ABBE:g}], got {self.abbe:g}", field="abbe")
            if self.ior == 1.0:
                # The Abbe number belongs to the glass row, the one whose ior is the glass's; on an air row it
                # is almost always a value written one row too low.
                raise PrescriptionError(
                    None, f"{self.abbe:g} given for air (ior 1): the Abbe number goes on the row of the glass",
                    field="abbe")
        if not self.aperture_mm > 0.0:
            raise PrescriptionError(None, f"must be > 0 (a diameter), got {self.aperture_mm:g}",
                                    field="aperture_mm")
        if self.thickness_mm < 0.0:
            raise PrescriptionError(None, f"must be >= 0, got {self.thickness_mm:g}", field="thickness_mm")
        if self.is_stop:
            if self.ior != 1.0:
                # The stop is an iris in air; a "stop" with glass behind it is a flat glass surface, which a
                # prescription writes with a very large radius instead.
                raise PrescriptionError(
                    None, f"must be 1 on the stop (radius 0), an iris in air; got {self.ior:g}", field="ior")
        elif abs(self.radius_mm) < self.aperture_mm / 2.0:
            # A sphere of radius R has no cap wider than 2R: the clear aperture cannot be cut from it.
            raise PrescriptionError(
                None,
                f"{abs(self.radius_mm):g} mm is smaller than the semi-aperture {self.aperture_mm / 2:g} mm "
                f"(clear aperture {self.aperture_mm:g} mm): no sphere that small is that wide",
                field="radius_mm")

    @property
    def is_stop(self) -> bool:
        """Whether this row is the aperture stop (radius 0)."""
        return self.radius_mm == 0.0


@dataclass(frozen=True)
class LensPrescription:
    """A real lens: its surfaces front to back, where the numbers came from, and what the lens does as a
    product (published focal length and aperture, iris, closest focus)."""

    name: str
    #: Front element (scene side) first, the rear surface last.  The medium in front of the first surface
    #: is air, and so is the one behind the last (the sensor sits in air).
    surfaces: tuple[LensSurface, ...]
    #: Where the numbers came from: patent, book and page, scaling.
    source: str = ""
    description: str = ""
    #: The effective focal length the source states, mm (a check on the transcription: a paraxial trace of
    #: the surfaces should give it).
    published_focal_length_mm: float | None = None
    #: The maximum aperture the source states.
    published_f_number: float | None = None
    #: The back focal distance (rear vertex to focus) the source states, mm.
    published_back_focal_mm: float | None = None
    #: The smallest aperture the iris closes to.
    narrowest_f_number: float = 22.0
    #: Iris: as LensPreset (optics/lenses.py): 0 a round stop, else 3..32 blades ...
    aperture_blades: int = 0
    #: ... turned this far about the axis, degrees, counter-clockwise seen from behind the camera ...
    blade_rotation_deg: float = 0.0
    #: ... and this rounded: 0 straight blades .. 1 a circle.
    blade_roundness: float = 0.0
    #: Closest focus as marked on the lens, measured from the sensor plane, m.
    min_focus_distance_m: float | None = None
    #: The file the prescription was read from (None when built in memory); named in every error.
    path: Path | None = field(default=None, compare=False)

    def __post_init__(self):
        if self.path is not None and not isinstance(self.path, Path):
            object.__setattr__(self, "path", Path(self.path))
        path = self.path

        def fail(problem, **where):
            raise PrescriptionError(path, problem, **where)

        for name in ("name", "source", "description"):
            if not isinstance(getattr(self, name), str):
                fail(f"must be a string, got {_describe(getattr(self, name))}", field=name)
        if not self.name.strip():
            fail("must be a non-empty string", field="name")
        self._check_surfaces(fail)
        self._check_product(fail)

    def _check_surfaces(self, fail):
        surfaces = self.surfaces
        if isinstance(surfaces, (str, bytes)) or not hasattr(surfaces, "__iter__"):
            fail(f"must be a sequence of LensSurface, got {_describe(surfaces)}", field="surfaces")
        surfaces = tuple(surfaces)
        object.__setattr__(self, "surfaces", surfaces)
        for number, surface in enumerate(surfaces, 1):
            if not isinstance(surface, LensSurface):
                fail(f"must be a LensSurface, got {type(surface).__name__}", surface=number)
        if len(surfaces) > MAX_SURFACES:
            fail(f"{len(surfaces)} surfaces: the renderer holds at most {MAX_SURFACES}")

        stops = [number for number, surface in enumerate(surfaces, 1) if surface.is_stop]
        if not stops:
            fail("no aperture stop: one row must have radius 0 (the iris)")
        if len(stops) > 1:
            fail(f"a second aperture stop (radius 0; surface {stops[0]} is the first): a lens has one iris",
                 surface=stops[1])
        if not any(surface.ior > 1.0 for surface in surfaces):
            fail("no glass: at least one surface besides the stop must have glass behind it (ior > 1)")
        if surfaces[-1].ior != 1.0:
            # The sensor sits in air.  Glass behind the last row almost always means its closing row (the
            # back of the rear element) was left out.
            fail(f"must be 1 on the last surface, for the sensor sits in air; got {surfaces[-1].ior:g} "
                 "(is the back of the rear element missing?)", surface=len(surfaces), field="ior")

    def _check_product(self, fail):
        def positive_or_none(name):
            value = getattr(self, name)
            if value is None:
                return
            value = _number(value, name, self.path)
            if not value > 0.0:
                fail(f"must be > 0, got {value:g}", field=name)
            object.__setattr__(self, name, value)

        for name in ("published_focal_length_mm", "published_f_number", "published_back_focal_mm",
                     "min_focus_distance_m"):
            positive_or_none(name)
        for name in ("narrowest_f_number", "blade_rotation_deg", "blade_roundness"):
            object.__setattr__(self, name, _number(getattr(self, name), name, self.path))
        if not MIN_F_NUMBER <= self.narrowest_f_number <= MAX_F_NUMBER:
            fail(f"must lie in [{MIN_F_NUMBER:g}, {MAX_F_NUMBER:g}], got {self.narrowest_f_number:g}",
                 field="narrowest_f_number")
        widest = self.published_f_number
        if widest is not None and self.narrowest_f_number < widest:
            fail(f"f/{self.narrowest_f_number:g} is wider than published_f_number f/{widest:g}",
                 field="narrowest_f_number")
        # lenses.py reads prescriptions (it imports this module), so its constant is fetched when used.
        from .lenses import MAX_APERTURE_BLADES

        blades = self.aperture_blades
        if isinstance(blades, bool) or not isinstance(blades, int) or not (
            blades == 0 or 3 <= blades <= MAX_APERTURE_BLADES
        ):
            fail(f"must be 0 (round) or 3..{MAX_APERTURE_BLADES}, got {blades!r}", field="aperture_blades")
        if not 0.0 <= self.blade_roundness <= 1.0:
            fail(f"must lie in [0, 1], got {self.blade_roundness:g}", field="blade_roundness")

    @property
    def stop_index(self) -> int:
        """Index (0-based, into ``surfaces``) of the aperture stop; there is exactly one."""
        return next(index for index, surface in enumerate(self.surfaces) if surface.is_stop)

    @property
    def dispersive(self) -> bool:
        """Whether any medium has an Abbe number, i.e. whether colours part on the way through."""
        return any(surface.abbe is not None for surface in self.surfaces)


# --- reading files ---------------------------------------------------------------------------------------

def _read_text(path: Path) -> str:
    """The text of the regular file at ``path``, or a PrescriptionError naming it.  open_file refuses a
    folder, a device or a named pipe (which would block a reader for ever) before reading a byte."""
    try:
        with open_file(path) as file:
            data = file.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise PrescriptionError(path, f"cannot read: {exc.strerror or exc}") from None
    if len(data) > MAX_FILE_BYTES:
        raise PrescriptionError(path, f"more than {MAX_FILE_BYTES >> 20} MiB: not a lens file")
    if data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8):]  # an editor's byte order mark is not part of the first line
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        pass
    # pbrt's files were typed on many systems, and a comment may hold a byte of some old code page (a degree
    # sign).  Numbers are ASCII in every one, so Latin-1, which reads any byte, loses nothing that matters.
    return data.decode("latin-1")


def read_pbrt_lens(path: os.PathLike | str) -> LensPrescription:
    """A lens from a pbrt-v3/v4 lens file (``.dat``), read as pbrt reads it, but strictly.

    The format: lines starting with ``#`` are comments (anything may follow, and the published files have
    stray quotes and tabs there); every other non-blank line is one surface, four numbers separated by
    spaces or tabs: ``radius thickness ior aperture_diameter``, all mm, front element first.  A radius of
    0 is the aperture stop, an ior of 0 means air (stored as 1.0).  A ``#`` after the numbers starts a
    comment too, as in pbrt.  pbrt reads the last row's thickness as the film distance and then sets it by
    focusing; it is kept here as read.

    The name is the file's stem ("dgauss.50mm"); the full-line comments, joined, are the description.
    Where pbrt warns and reads on (text that is not a number, a row of three), this refuses, naming the
    file and the line.
    """
    path = Path(path)
    text = _read_text(path)
    comments: list[str] = []
    surfaces: list[LensSurface] = []
    lines: list[int] = []  # the line of each surface, for errors found once the table is whole
    for line_number, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            comment = " ".join(line.lstrip("#").split())
            if comment.count('"') % 2:
                # The published files end some comments in a lone quote (a spreadsheet's export, by the
                # tabs around it): noise, not part of the text.
                comment = comment.rstrip('"').rstrip()
            if comment:
                comments.append(comment)
            continue
        fields = line.split("#", 1)[0].split()
        if len(fields) != 4:
            raise PrescriptionError(
                path, f"expected four numbers (radius thickness ior aperture_diameter), got {len(fields)}",
                line=line_number, surface=len(surfaces) + 1)
        values = []
        for name, word in zip(("radius", "thickness", "ior", "aperture_diameter"), fields):
            try:
                value = float(word)
            except ValueError:
                raise PrescriptionError(path, f"{name} {word!r} is not a number",
                                        line=line_number, surface=len(surfaces) + 1) from None
            values.append(value)
        radius, thickness, ior, aperture = values
        try:
            surfaces.append(LensSurface(radius_mm=radius, thickness_mm=thickness,
                                        ior=1.0 if ior == 0.0 else ior,  # pbrt: 0 is air
                                        abbe=None, aperture_mm=aperture))
        except PrescriptionError as exc:
            raise PrescriptionError(path, exc.problem, surface=len(surfaces) + 1, field=exc.field,
                                    line=line_number) from None
        lines.append(line_number)
        if len(surfaces) > MAX_SURFACES:
            break  # the dataclass says why; no need to read a long file to the end
    if not surfaces:
        raise PrescriptionError(path, "no surfaces: expected rows of four numbers after the # comments")
    try:
        return LensPrescription(name=path.stem, surfaces=tuple(surfaces), source=f"pbrt lens file {path.name}",
                                description=" / ".join(comments), path=path)
    except PrescriptionError as exc:
        line = lines[exc.surface - 1] if exc.surface is not None else None
        raise exc.relocated(path, line=line) from None


# The keys of LensLab's own format and their kinds (presetfiles.KINDS).  "or null": JSON may write null;
# TOML, which has no null, leaves the key out.
_TOP_KINDS = {
    "name": "string",
    "description": "string",
    "source": "string",
    "published_focal_length_mm": "number or null",
    "published_f_number": "number or null",
    "published_back_focal_mm": "number or null",
    "narrowest_f_number": "number",
    "aperture_blades": "integer",
    "blade_rotation_deg": "number",
    "blade_roundness": "number",
    "min_focus_distance_m": "number or null",
}
_REQUIRED_TOP = ("name", "surfaces")
_SURFACE_KINDS = {
    "radius_mm": "number",
    "thickness_mm": "number",
    "ior": "number",
    "abbe": "number or null",
    "aperture_mm": "number",
    "glass": "string",
}
_REQUIRED_SURFACE = ("radius_mm", "thickness_mm", "ior", "aperture_mm")


def _take(table: Mapping, kinds: Mapping[str, str], required, path: Path, prefix: str, extra=()) -> dict:
    """The values of ``table`` checked against ``kinds``: an unknown key, a missing required one or a value
    of the wrong kind is a PrescriptionError naming ``prefix + key``."""
    known = list(kinds) + list(extra)
    for key in table:
        if key not in known:
            raise PrescriptionError(path, f"unknown key (known keys: {', '.join(known)})", key=prefix + str(key))
    for key in required:
        if key not in table:
            raise PrescriptionError(path, "required key is missing", key=prefix + key)
    values = {}
    for key, kind in kinds.items():
        if key not in table:
            continue
        value = table[key]
        nullable = kind.endswith(" or null")
        check, wanted = KINDS[kind.removesuffix(" or null")]
        if value is None and nullable:
            values[key] = None
        elif check(value):
            values[key] = value
        else:
            raise PrescriptionError(path, f"expected {wanted}, got {_describe(value)}", key=prefix + key)
    return values


def prescription_from_mapping(data: Any, path: os.PathLike | str | None) -> LensPrescription:
    """A lens from LensLab's own format, parsed from TOML or JSON into ``data``, strictly.

    Top-level keys are LensPrescription's fields (but ``path``), ``name`` and ``surfaces`` required;
    ``surfaces`` is a list of tables with LensSurface's fields, ``abbe`` and ``glass`` optional.  Every
    problem names the file and the key; a surface's key is written ``surfaces[3].radius_mm``, where 3 is
    the surface number counted from 1 at the front, as the ``[[surfaces]]`` tables of a TOML file are
    counted by eye and as lens tables number their rows.
    """
    path = Path(path) if path is not None else None
    if not isinstance(data, dict):
        raise PrescriptionError(path, f"expected a table of keys at the top, got {_describe(data)}")
    top = _take(data, _TOP_KINDS, _REQUIRED_TOP, path, "", extra=("surfaces",))
    rows = data["surfaces"]
    if not isinstance(rows, list) or not rows:
        raise PrescriptionError(path, f"expected a non-empty list of surface tables, got {_describe(rows)}",
                                key="surfaces")
    if len(rows) > MAX_SURFACES:
        raise PrescriptionError(path, f"{len(rows)} surfaces: the renderer holds at most {MAX_SURFACES}",
                                key="surfaces")
    surfaces = []
    for number, row in enumerate(rows, 1):
        key = f"surfaces[{number}]"
        if not isinstance(row, dict):
            raise PrescriptionError(path, f"expected a table, got {_describe(row)}", key=key)
        values = _take(row, _SURFACE_KINDS, _REQUIRED_SURFACE, path, key + ".")
        values.setdefault("abbe", None)
        try:
            surfaces.append(LensSurface(**values))
        except PrescriptionError as exc:
            raise exc.relocated(path, key=f"{key}.{exc.field}" if exc.field else key) from None
    try:
        return LensPrescription(surfaces=tuple(surfaces), path=path, **top)
    except PrescriptionError as exc:
        if exc.surface is not None:
            key = f"surfaces[{exc.surface}]" + (f".{exc.field}" if exc.field else "")
        else:
            key = exc.field or "surfaces"  # no field, no surface: a problem of the table as a whole
        raise exc.relocated(path, key=key) from None


def _parse_toml(text: str, path: Path) -> Any:
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10: the tomli package, a dependency there (pyproject.toml)
        import tomli as tomllib
    try:
        return tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError) as exc:
        raise PrescriptionError(path, f"invalid TOML: {exc}") from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise PrescriptionError(path, f"a number too long to read ({str(exc).split(';')[0]})") from None


def _parse_json(text: str, path: Path) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise PrescriptionError(path, f"invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}") from None
    except RecursionError:
        raise PrescriptionError(path, "invalid JSON: nested too deeply") from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise PrescriptionError(path, f"a number too long to read ({str(exc).split(';')[0]})") from None


def read_prescription_file(path: os.PathLike | str) -> LensPrescription:
    """A lens from a file of any format this module knows, by its ending: ``.dat`` pbrt's, ``.toml`` and
    ``.json`` LensLab's.  A missing file, a folder, an unknown ending: one-line PrescriptionError."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".dat":
        return read_pbrt_lens(path)
    text = _read_text(path)  # before the ending, so that a folder or a missing file is called what it is
    if suffix == ".toml":
        return prescription_from_mapping(_parse_toml(text, path), path)
    if suffix == ".json":
        data = _parse_json(text, path)
        if isinstance(data, dict) and "surfaces" not in data and "focal_length_mm" in data:
            raise PrescriptionError(path, "a thin-lens preset (no 'surfaces'): read it with optics/lenses.py",
                                    key="surfaces")
        return prescription_from_mapping(data, path)
    raise PrescriptionError(
        path, f"unknown lens file type '{path.suffix}' (use {', '.join(PRESCRIPTION_SUFFIXES)})")


def is_prescription_file(path: os.PathLike | str) -> bool:
    """Whether ``path`` is a real-lens file (read it with :func:`read_prescription_file`) rather than one
    of the thin-lens JSON presets of optics/lenses.py.

    ``.dat`` and ``.toml`` always are; a ``.json`` file is when it holds an object with a ``surfaces`` key,
    which no thin-lens preset has.  A JSON file that cannot be read or parsed answers False, so that the
    thin-lens reader, which reports such files, gets it.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".dat", ".toml"):
        return True
    if suffix != ".json":
        return False
    try:
        data = _parse_json(_read_text(path), path)
    except PrescriptionError:
        return False
    return isinstance(data, dict) and "surfaces" in data
