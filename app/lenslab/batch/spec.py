"""A batch file: the shots to render, with brackets and sweeps written compactly (docs/batch.md).

::

    contact_sheet = "renders/sheet.png"

    [defaults]
    scene = "dof_chart"
    width = 480
    spp = 64

    [[shots]]
    name = "aperture bracket"
    output = "renders/chart_f{f_number}.png"
    f_number = [1.4, 2, 2.8, 4]

A list is a sweep and a ``{from, to, steps}`` table a range; a shot with several of them is rendered for every
combination. Every problem is reported as one line naming the file, the shot and the key, before anything
renders: a batch that would fail at its fortieth shot fails at once.
"""

from __future__ import annotations

import datetime
import difflib
import itertools
import json
import math
import os
import re
import string
from dataclasses import dataclass, field
from pathlib import Path

from lenslab.atomic import check_output_file
from lenslab.image_files import read_file_bytes
from lenslab.limits import LARGEST_NUMBER
from lenslab.render.film import EXPORT_SUFFIXES, EXPORT_SUFFIXES_TEXT
from lenslab.colour_management.view import ViewTransform
from lenslab.scene.options import OLD_NAMES, OPTIONS, SCENE_OPTIONS, VIEW_OPTIONS, view_transform
from lenslab.scene.overrides import SceneOverrides

#: Parts one shot may be split into (one per worker).
MAX_SPLIT = 256


class BatchError(ValueError):
    """A batch file that cannot be used; the message is one line naming the file (and the shot and key)."""


# The keys a shot may have: every option of scene/options.py by its name (or an older spelling), and the shot's
# own. What kind of value each takes.
_SHOT_KEYS = {"name": str, "scene": str, "output": str, "split": int, "defines": dict}
_KINDS = {**{name: option.kind for name, option in OPTIONS.items()}, **_SHOT_KEYS}
_NOT_SWEPT = ("name", "output", "defines")  # one value per shot
_TOP_LEVEL = ("defaults", "shots", "contact_sheet")


@dataclass(frozen=True)
class Shot:
    """One image to render: a scene, what to change in it, and where the image goes."""

    name: str  # the shot's name and its swept settings ("bracket f/2.8"), or its file's name
    scene: str  # a scene file (absolute path) or a shipped scene's name
    output: Path
    overrides: SceneOverrides = field(default_factory=SceneOverrides)
    time_limit: float | None = None
    view: ViewTransform = field(default_factory=ViewTransform)  # pictures only, as on the command line
    split: int = 1  # render in this many sample ranges, on as many workers, and merge
    where: str = ""  # "shots.toml, shot 2 ('bracket'), f/2.8" for messages
    number: int = 0  # which [[shots]] entry of the file it came from (1 for the first)

    def open_scene(self, warn=None):
        """The scene with this shot's overrides applied (a SceneError names the scene's file)."""
        return self.overrides.open(self.scene, warn=warn)


@dataclass(frozen=True)
class Batch:
    path: Path
    shots: tuple[Shot, ...]
    contact_sheet: Path | None = None


def read_batch(path: str | Path) -> Batch:
    """Read and check a batch file (.toml or .json); BatchError on any problem."""
    path = Path(path)
    try:
        text = read_file_bytes(path).decode("utf-8")  # a named pipe or a device is refused, not waited on
    except FileNotFoundError:
        raise BatchError(f"{path}: no such batch file") from None
    except OSError as exc:
        raise BatchError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise BatchError(f"{path}: cannot read ({exc})") from None
    return parse_batch(text, path)


def parse_batch(text: str, path: Path) -> Batch:
    """The batch in ``text``, read as the file ``path`` (its suffix picks TOML or JSON; relative scene and
    output paths are relative to its folder)."""
    document = _decode(text, path)
    unknown = [key for key in document if key not in _TOP_LEVEL]
    if unknown:
        raise BatchError(f"{path}: unknown key '{unknown[0]}'{_did_you_mean(unknown[0], _TOP_LEVEL)} "
                         f"(a batch file has {', '.join(_TOP_LEVEL)})")
    defaults = document.get("defaults", {})
    if not isinstance(defaults, dict):
        raise BatchError(f"{path}: 'defaults' must be a table of shot settings")
    defaults = _check_keys(defaults, f"{path}, defaults")
    entries = document.get("shots")
    if not isinstance(entries, list) or not entries or not all(isinstance(e, dict) for e in entries):
        raise BatchError(f"{path}: no shots: give at least one [[shots]] table (TOML) or a \"shots\" list (JSON)")
    folder = path.parent.resolve()
    shots: list[Shot] = []
    for number, entry in enumerate(entries, start=1):
        where = f"{path}, shot {number}" + (f" ('{entry['name']}')" if isinstance(entry.get("name"), str) else "")
        shots.extend(_expand(number, {**defaults, **_check_keys(entry, where)}, folder, where))
    _check_outputs(shots, path)
    contact_sheet = document.get("contact_sheet")
    if contact_sheet is not None:
        if not isinstance(contact_sheet, str) or not contact_sheet.strip():
            raise BatchError(f"{path}: contact_sheet: expected a file name, not {contact_sheet!r}")
        contact_sheet = folder / contact_sheet
        if contact_sheet.suffix.lower() != ".png":
            raise BatchError(f"{path}: contact_sheet: {contact_sheet.name} must be a .png")
    return Batch(path, tuple(shots), contact_sheet)


def _decode(text: str, path: Path) -> dict:
    suffix = path.suffix.lower()
    if suffix == ".json":
        try:
            document = json.loads(text)
        except (json.JSONDecodeError, RecursionError) as exc:
            raise BatchError(f"{path}: not valid JSON ({exc})") from None
        except ValueError as exc:  # an integer of more digits than Python converts
            raise BatchError(f"{path}: a number too long to read ({str(exc).split(';')[0]})") from None
    elif suffix == ".toml":
        try:
            import tomllib
        except ModuleNotFoundError:  # Python 3.10
            import tomli as tomllib
        try:
            document = tomllib.loads(text)
        except (tomllib.TOMLDecodeError, RecursionError) as exc:
            raise BatchError(f"{path}: not valid TOML ({exc})") from None
        except ValueError as exc:  # an integer of more digits than Python converts
            raise BatchError(f"{path}: a number too long to read ({str(exc).split(';')[0]})") from None
    else:
        raise BatchError(f"{path}: unknown batch file type '{path.suffix}' (use .toml or .json)")
    if not isinstance(document, dict):
        raise BatchError(f"{path}: expected a table of settings and shots at the top")
    return document


def _did_you_mean(word: str, choices) -> str:
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""


def _check_keys(table: dict, where: str) -> dict:
    """``table`` with every key known, older spellings of an option under its name ("coc" -> circle_of_confusion)."""
    named = {}
    for key, value in table.items():
        name = OLD_NAMES.get(key, key)
        if name not in _KINDS:
            raise BatchError(f"{where}: unknown key '{key}'{_did_you_mean(key, _KINDS)}")
        if name in named:
            raise BatchError(f"{where}: '{key}' and '{name}' are one setting: give it once")
        named[name] = value
    return named


# -- sweeps --------------------------------------------------------------------------------------------------
def _values(key: str, raw, where: str) -> list:
    """The values a key takes: one, a list (a sweep) or a {from, to, steps} range; each checked for kind."""
    kind = _KINDS[key]
    if isinstance(raw, list) and kind is not dict:
        if key in _NOT_SWEPT:
            raise BatchError(f"{where}: {key}: takes one value, not a list")
        if not raw:
            raise BatchError(f"{where}: {key}: an empty list sweeps over nothing")
        return [_scalar(key, value, where) for value in raw]
    if isinstance(raw, dict) and kind is not dict:
        if key in _NOT_SWEPT or kind in (str, bool):
            raise BatchError(f"{where}: {key}: expected {_kind_name(kind)}, not a table")
        return _range(key, raw, where)
    return [_scalar(key, raw, where)]


def _kind_name(kind) -> str:
    return {str: "a string", float: "a number", int: "a whole number", dict: "a table", bool: "true or false"}[kind]


def _scalar(key: str, value, where: str):
    kind = _KINDS[key]
    option = OPTIONS.get(key)
    if isinstance(value, str) and kind is not str and option is not None and option.parse_text is not None:
        try:  # a number written as a camera shows it: "1/125" s, "f/2.8"
            return option.from_text(value)
        except ValueError as exc:
            raise BatchError(f"{where}: {key}: {str(exc).removeprefix(key + ' ')}") from None
    ok = (isinstance(value, str) if kind is str else
          isinstance(value, dict) if kind is dict else
          isinstance(value, bool) if kind is bool else
          isinstance(value, int) and not isinstance(value, bool) if kind is int else
          isinstance(value, (int, float)) and not isinstance(value, bool))
    if not ok:
        raise BatchError(f"{where}: {key}: expected {_kind_name(kind)}, not {_shown(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        raise BatchError(f"{where}: {key}: {value} is not a finite number")
    if kind in (int, float) and abs(value) > LARGEST_NUMBER:  # exact for an integer of any length: no overflow
        shown = f"a {len(str(abs(value)))}-digit number" if isinstance(value, int) else f"{value:g}"
        raise BatchError(f"{where}: {key}: {shown} is too large")
    if kind is float:
        value = float(value)
    return value


def _shown(value) -> str:
    if isinstance(value, (datetime.date, datetime.time)):  # TOML's own kinds of value, which JSON has no text for
        kind = ("a date and time" if isinstance(value, datetime.datetime) else
                "a date" if isinstance(value, datetime.date) else "a time")
        return f"{kind} ({value.isoformat()})"  # short: said whole
    text = json.dumps(value, default=str) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


_RANGE_KEYS = ("from", "to", "steps", "spacing")


def _range(key: str, table: dict, where: str) -> list:
    """``{from = 1, to = 8, steps = 4}`` -> [1, 3.33, 5.67, 8]; ``spacing = "geometric"`` spaces by equal ratios
    (a focus stack, or f-numbers a stop apart: {from = 1.4, to = 16, steps = 8, spacing = "geometric"})."""
    unknown = [k for k in table if k not in _RANGE_KEYS]
    if unknown:
        raise BatchError(f"{where}: {key}: a range has from, to, steps and optionally spacing, not '{unknown[0]}'")
    for name in ("from", "to", "steps"):
        if name not in table:
            raise BatchError(f"{where}: {key}: a range needs '{name}'")
    low, high = (_scalar(key, table[name], f"{where}: {key}.{name}") for name in ("from", "to"))
    steps = table["steps"]
    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= 10_000:
        raise BatchError(f"{where}: {key}.steps: expected a whole number from 1 to 10000, not {_shown(steps)}")
    spacing = table.get("spacing", "linear")
    if spacing not in ("linear", "geometric"):
        raise BatchError(f"{where}: {key}.spacing: '{spacing}' is not linear or geometric")
    if spacing == "geometric" and not (low > 0 and high > 0):
        raise BatchError(f"{where}: {key}: a geometric range needs positive ends, not {low:g} to {high:g}")
    if steps == 1:
        return [low]
    fractions = [i / (steps - 1) for i in range(steps)]
    if spacing == "geometric":
        values = [low * (high / low) ** t for t in fractions]
    else:
        values = [low + (high - low) * t for t in fractions]
    values[-1] = high  # exactly the end the user wrote
    return [round(v) for v in values] if _KINDS[key] is int else [round(v, 6) for v in values]


#: More shots than a render farm gets through in a week of short renders: a sweep of sweeps gone wrong.
MAX_SHOTS = 10_000


def _expand(number: int, settings: dict, folder: Path, where: str) -> list[Shot]:
    """One Shot per combination of the swept keys' values, in the order the file gives them."""
    for required in ("scene", "output"):
        if required not in settings:
            raise BatchError(f"{where}: no '{required}' (give it in the shot or in [defaults])")
    choices = {key: _values(key, raw, where) for key, raw in settings.items()}
    swept = [key for key, values in choices.items() if len(values) > 1]
    count = math.prod(len(values) for values in choices.values())
    if count > MAX_SHOTS:  # sweeps multiply: say so before making a million of them
        sizes = " x ".join(f"{len(choices[key])} {key}" for key in swept)
        raise BatchError(f"{where}: {sizes} make {count:,} shots; a batch holds at most {MAX_SHOTS:,}")
    shots = []
    for index, combination in enumerate(itertools.product(*choices.values()), start=1):
        values = dict(zip(choices, combination))
        shot_where = where + (f", {_describe(values, swept)}" if swept else "")
        shots.append(_shot(number, index, values, swept, folder, shot_where))
    return shots


def _describe(values: dict, keys) -> str:
    """How a photographer writes the settings that tell the shots of a sweep apart: f/2.8, 50 mm, 1.5 m."""
    words = []
    for key in keys:
        value = values[key]
        if isinstance(value, str):
            words.append(value if key in ("lens", "scene", "sensor") else f"{key} {value}")
        elif isinstance(value, bool):
            words.append(f"{key} {str(value).lower()}")
        elif key == "shutter":
            from lenslab.optics.exposure import format_shutter

            words.append(format_shutter(value))
        else:
            units = {"f_number": "f/{:g}", "focal_length": "{:g} mm", "focus_distance": "{:g} m", "iso": "ISO {:g}"}
            words.append(units.get(key, key + " {:g}").format(value))
    return ", ".join(words)


def _shot(number: int, index: int, values: dict, swept: list[str], folder: Path, where: str) -> Shot:
    output = folder / _output_name(values, index, where)
    if output.suffix.lower() not in EXPORT_SUFFIXES:
        raise BatchError(f"{where}: output: {output.name} must be one of {EXPORT_SUFFIXES_TEXT}")
    try:
        check_output_file(output)  # a named pipe or a device node there: never "exists, skipped", never replaced
    except OSError as exc:
        raise BatchError(f"{where}: output: {exc}") from None
    # Named by the user (with the swept settings added), or else by its file, which is unique.
    name = values["name"] + (f" {_describe(values, swept)}" if swept else "") if "name" in values else output.stem
    if "aperture_image" in values:  # relative to the batch file, as the outputs are
        values = {**values, "aperture_image": str(folder / Path(values["aperture_image"]).expanduser())}
    try:
        overrides = SceneOverrides(**{option.name: values[option.name] for option in SCENE_OPTIONS
                                      if option.name in values},
                                   defines={str(k): str(v) for k, v in values.get("defines", {}).items()})
        time_limit = values.get("time_limit")
        if time_limit is not None:
            OPTIONS["time_limit"].check(time_limit)
        view = _view_transform(values)
    except ValueError as exc:  # ColourConfigError among them
        raise BatchError(f"{where}: {exc}") from None
    split = values.get("split", 1)
    if not 1 <= split <= MAX_SPLIT:
        raise BatchError(f"{where}: split: {split} is out of range [1, {MAX_SPLIT}]")
    scene = values["scene"]
    if os.path.exists(folder / scene):  # a file beside the batch file; otherwise a shipped scene's name
        scene = str((folder / scene).resolve())
    return Shot(name=name, scene=scene, output=output, overrides=overrides, time_limit=time_limit,
                view=view, split=split, where=where, number=number)


def _view_transform(values: dict) -> ViewTransform:
    """The view transform a shot's pictures are made with, checked against its OCIO config (its working space is
    the scene's, set when the image is written)."""
    view = view_transform({name: OPTIONS[name].check(values[name]) for name in VIEW_OPTIONS if name in values})
    view.resolved()
    return view


#: File systems take names of at most 255 bytes.
MAX_FIELD_WIDTH = 255


class _OutputFormatter(string.Formatter):
    """str.format for file names: 2.0 is written 2 and 1.4 stays 1.4 unless a format is given; text such as a
    lens's name "85 mm f/1.4" becomes 85_mm_f_1.4, safe in a file name."""

    def get_field(self, field_name, args, kwargs):
        if not field_name.isidentifier():  # {index[0]}, {index.__class__}: a name is made of values, not their parts
            raise ValueError(f"{{{field_name}}} is not a field's name")
        return super().get_field(field_name, args, kwargs)

    def format_field(self, value, format_spec):
        widest = max((int(digits) for digits in re.findall(r"\d+", format_spec)), default=0)  # width, precision
        if widest > MAX_FIELD_WIDTH:  # {index:>2000000000} would fill memory, not make a name
            raise ValueError(f"a field {widest} characters wide: a file name holds at most {MAX_FIELD_WIDTH}")
        if isinstance(value, _ShutterTime) and not format_spec:  # 1/125 s is 1_125, 0.5 s is 0.5
            from lenslab.optics.exposure import format_shutter

            value = format_shutter(value).removesuffix(" s")
        if isinstance(value, float) and not format_spec:
            text = f"{value:g}"
        elif isinstance(value, str):
            text = re.sub(r"[^A-Za-z0-9.+-]+", "_", value).strip("_")
        else:
            text = super().format_field(value, format_spec)
        # A value makes part of one name: never a character a name cannot show ({index:c} of 1 is "\x01"), a
        # separator that would put the file in another folder ({index:c} of 47 is "/"), or a name of a folder.
        if not text.isprintable() or any(sep in text for sep in ("/", "\\")) or text in (".", ".."):
            raise _FieldMakesNoName(f"a field makes {ascii(text)}, which is no part of a file name (it must be "
                                    "printable, without / or \\, and not . or ..)")
        return text


class _FieldMakesNoName(ValueError):
    """A field of an output pattern whose value, formatted, cannot be part of a file's name."""


class _ShutterTime(float):
    """A shutter time in an output's name: written as the camera shows it (1_125 for 1/125 s)."""


def _output_name(values: dict, index: int, where: str) -> str:
    template = values["output"]
    fields = {key: value for key, value in values.items() if key not in ("output", "defines")}
    fields["index"] = index
    for old_name, name in OLD_NAMES.items():  # a pattern written with an option's older name still works
        if name in fields:
            fields.setdefault(old_name, fields[name])
    if "shutter" in fields:
        fields["shutter"] = _ShutterTime(fields["shutter"])
    if any(ord(char) < 32 or ord(char) == 127 for char in template):
        raise BatchError(f"{where}: output: a file name holds no control characters ({template!r})")
    try:
        template.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate ("\ud800" in JSON): no file system can hold it
        raise BatchError(f"{where}: output: {template!r} is not text a file name can hold") from None
    try:
        name = _OutputFormatter().format(template, **fields)
    except KeyError as exc:
        name = exc.args[0]
        problem = (f"this shot sets no {name}" if name in _KINDS else
                   f"unknown field {{{name}}}{_did_you_mean(str(name), [*_KINDS, 'index'])}")
        raise BatchError(f"{where}: output: '{template}' names {{{name}}}, but {problem}") from None
    except _FieldMakesNoName as exc:
        raise BatchError(f"{where}: output: '{template}': {exc}") from None
    except (ValueError, IndexError, TypeError, AttributeError) as exc:  # {index[0]}, {f_number.real.x}
        raise BatchError(f"{where}: output: '{template}' is not a valid name pattern ({exc})") from None
    if not name.isprintable():  # a format character (U+202E turns the name's text around): no name shows it
        raise BatchError(f"{where}: output: {ascii(name)} is not a name a terminal or a folder shows as it is "
                         "(it holds characters that are not printable)")
    return name


def _check_outputs(shots: list[Shot], path: Path) -> None:
    """Two shots writing one file would lose a render: say which, and how to tell them apart."""
    seen: dict[Path, Shot] = {}
    for shot in shots:
        first = seen.setdefault(shot.output, shot)
        if first is not shot:
            hint = ("put the swept setting in the output's name, e.g. {f_number} or {index}"
                    if first.number == shot.number else "give each shot its own output")
            raise BatchError(f"{path}: {first.where.removeprefix(f'{path}, ')} and "
                             f"{shot.where.removeprefix(f'{path}, ')} both write {shot.output.name}: {hint}")
