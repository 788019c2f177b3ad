"""The settings a user gives one render on top of the scene's own, each declared once.

One row per option: its one name (the ``SceneOverrides`` field and the batch file's key; the command line's flag is
the same words with dashes: ``focal_length``, ``--focal-length``), the kind of value, its range or choices (read
from the scene field it sets, where it sets one: scene/fields.py), its unit, its help, the names it was known by
before (still accepted: ``--f-stop``, ``coc``, ``blades``, ``anamorphic``), and the name an image's metadata
gives it. ``cli.build_parser``, ``batch/spec.py``, ``SceneOverrides`` and ``render/job.image_metadata`` are made
from this table; a new option is a new row.

Values arrive three ways, all checked here: as text (the command line: ``"f/2.8"``, ``"1/125"``), as a batch
file's number or string, or from Python. Problems are ValueErrors of one line naming the option.
"""

from __future__ import annotations

import math

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping

from lenslab.colour_management.view import CONTRAST_RANGE, EXPOSURE_RANGE, METADATA as VIEW_METADATA, ViewTransform
from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE
from lenslab.scene.camera import MAX_IMAGE_SIDE, ThinLensCamera
from lenslab.scene.fields import declared_choices, declared_range
from lenslab.scene.scene import RenderSettings


@dataclass(frozen=True)
class Option:
    name: str
    kind: type  # float, int, str or bool
    help: str
    sets: str = ""  # "camera.<field>" or "render.<field>" it overrides; "" where the overrides apply it by hand
    unit: str = ""  # what the number is in, for help and messages
    metavar: str = "VALUE"
    bounds: tuple | None = None  # (low, high) where the option sets no declared field
    choices: tuple[str, ...] | None = None  # for text options that set no declared field
    parse_text: Callable[[str], object] | None = None  # text as a user writes it -> value (e.g. "1/125" -> 0.008)
    old_names: tuple[str, ...] = ()  # spellings still accepted on the command line and in batch files
    metadata: str = ""  # the image metadata key holding the value the render used ("" for none)
    scene: bool = True  # False: how the image is made or written (time limit, display), not the scene
    refuse: Callable[[object], str] | None = None  # a further rule: the reason a value in range is refused, or ""

    @property
    def flag(self) -> str:
        return "--" + self.name.replace("_", "-")

    @property
    def old_flags(self) -> tuple[str, ...]:
        return tuple("--" + name.replace("_", "-") for name in self.old_names)

    @property
    def scene_field(self) -> tuple[type, str] | None:
        """(scene class, field name) this option sets, or None."""
        if not self.sets:
            return None
        owner, name = self.sets.split(".")
        return {"camera": ThinLensCamera, "render": RenderSettings}[owner], name

    @property
    def range(self) -> tuple | None:
        if self.bounds is not None:
            return self.bounds
        if self.scene_field is None or self.kind not in (int, float):
            return None
        return declared_range(*self.scene_field)

    @property
    def allowed(self) -> tuple[str, ...] | None:
        """The values a text option takes (None: any text, such as a preset's or a file's name)."""
        if self.choices is not None:
            return self.choices
        if self.scene_field is None or self.kind is not str:
            return None
        try:
            return declared_choices(*self.scene_field)
        except KeyError:
            return None

    def from_text(self, text: str):
        """The value a user's text means: a ValueError of one line where it means none."""
        if self.parse_text is not None:
            return self.check(self.parse_text(text))
        if self.kind is str:
            return self.check(text)
        try:
            value = self.kind(text)
        except ValueError:
            raise ValueError(f"expected {'a whole number' if self.kind is int else 'a number'}, not '{text}'") \
                from None
        return self.check(value)

    def check(self, value):
        """``value`` if this option takes it (a whole-number float is taken as an int); else a ValueError."""
        if self.kind is str:
            if not isinstance(value, str):
                raise ValueError(f"{self.name}: expected text, not {value!r}")
            if self.allowed is not None and value not in self.allowed:
                raise ValueError(f"{self.name} '{value}' is not one of {', '.join(self.allowed)}")
            return value
        if self.kind is bool:
            if not isinstance(value, bool):
                raise ValueError(f"{self.name}: expected true or false, not {value!r}")
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"{self.name}: expected a number, not {value!r}")
        if self.kind is int:
            if isinstance(value, float) and (not math.isfinite(value) or value != int(value)):
                raise ValueError(f"{self.name}: expected a whole number, not {value!r}")
            value = int(value)
        else:
            try:
                value = float(value)
            except OverflowError:  # an integer past the float range: out of every range
                pass
        low, high = self.range
        if not low <= value <= high:  # also refuses NaN
            raise ValueError(f"{self.name} {_shown(value)} is out of range [{format_bound(low)}, {format_bound(high)}]")
        reason = self.refuse(value) if self.refuse is not None else ""
        if reason:
            raise ValueError(f"{self.name} {_shown(value)}: {reason}")
        return value


def _shown(value: float) -> str:
    """A number as a message shows it; an integer of any size (past the float range, ``{:g}`` overflows) cut short."""
    if isinstance(value, int):
        digits = str(value)
        return digits if len(digits) <= 16 else f"{digits[:6]}... ({len(digits.lstrip('-'))} digits)"
    return f"{value:g}"


def format_bound(value: float) -> str:
    """A range's end as a message shows it: 1, not 1.0; 0.25 as it is."""
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


# -- text as users write it ---------------------------------------------------------------------------------------
def _f_number(text: str) -> float:
    from lenslab.optics.stops import parse_f_number

    return parse_f_number(text)


def _shutter(text: str) -> float:
    from lenslab.optics.exposure import parse_shutter

    return parse_shutter(text)


def _blades_that_make_a_stop(blades) -> str:
    return "a stop has 0 blades (round) or at least 3" if blades in (1, 2) else ""


def _lens_name(text: str) -> str:
    """The name of a lens preset there is, or a lens file that reads, as given (the overrides look it up again
    when they mount it). A broken lens file named here is the option's error, as an unreadable aperture image
    is; a broken preset folder is an error of its own (command_line.option_argument)."""
    from lenslab.optics.lenses import find_lens
    from lenslab.optics.presetfiles import PresetError
    from lenslab.optics.real_lenses import names_a_file

    try:
        find_lens(text)
    except PresetError as exc:
        if names_a_file(text):
            raise ValueError(str(exc)) from None
        raise
    return text


def _sensor_name(text: str) -> str:
    from lenslab.optics.sensors import find_sensor

    find_sensor(text)
    return text


def _existing_file(text: str) -> str:
    """A file named relative to the current folder, made absolute (a scene reads its own relative to its folder)."""
    path = Path(text).expanduser()
    if not path.is_file():
        raise ValueError(f"no such file: {text}")
    return str(path.resolve())


def _ocio_config(text: str) -> str:
    """An OCIO config file named relative to the current folder (made absolute), or a built-in config by its URI
    (``ocio://cg-config-latest``); read now, so that a broken one is the option's error."""
    from lenslab.colour_management.config import load_config

    source = text.strip() if text.strip().startswith("ocio://") else _existing_file(text)
    load_config(source)  # ColourConfigError, a ValueError, names the file and OCIO's reason
    return source


def _aperture_image_file(text: str) -> str:
    """An aperture image named on the command line or in a batch file: read now, so that a file that is missing,
    unreadable or black is blamed on the option that named it, not on the scene it is rendered with."""
    from lenslab.scene.aperture_images import read_aperture_image

    path = _existing_file(text)
    read_aperture_image(path)
    return path


_ROWS = (
    Option("f_number", float, "aperture as an f-number, e.g. 2.8 or f/2.8 (1.4 is wide open and blurry, 16 is deep "
           "focus); a marked stop is its exact value (f/11 is 2^3.5)", "camera.f_number", metavar="N",
           parse_text=_f_number, old_names=("f_stop",), metadata="FNumber"),
    Option("focal_length", float, "lens focal length in millimetres (sets the field of view with the sensor width)",
           "camera.focal_length_mm", unit="mm", metavar="MM", metadata="Exif:FocalLength"),
    Option("focus_distance", float, "distance to the plane of focus, in metres", "camera.focus_distance_m", unit="m",
           metavar="M", metadata="lenslab:FocusDistanceM"),
    Option("width", int, "image width in pixels (alone, the scene's aspect ratio is kept)", metavar="W",
           bounds=(1, MAX_IMAGE_SIDE)),
    Option("height", int, "image height in pixels (alone, the scene's aspect ratio is kept)", metavar="H",
           bounds=(1, MAX_IMAGE_SIDE)),
    Option("spp", int, "samples per pixel (default: the scene's; with a time limit alone, as many as fit)",
           "render.spp", metavar="N", metadata="lenslab:SamplesPerPixel"),
    Option("seed", int, "random seed: the same seed gives the same image", "render.seed", metavar="S",
           metadata="lenslab:Seed"),
    Option("max_depth", int, "longest light path in segments (2 = direct light only)", "render.max_depth",
           metavar="D", metadata="lenslab:MaxDepth"),
    Option("sampler", str, "sample pattern (default: the scene's)", "render.sampler", metadata="lenslab:Sampler"),
    Option("clamp", float, "tame fireflies: cap the radiance one sample may add (biased; 0 = off, the default)",
           "render.clamp", metavar="L", metadata="lenslab:Clamp"),
    Option("lens", str, "mount a lens preset: its focal lengths, stops, iris and minimum focus (see --list-lenses; "
           "the name's beginning will do where only one lens has it: 85mm), or a real lens's file (.toml, .json or "
           "pbrt's .dat; docs/lenses.md), traced through its glass", metavar="NAME", parse_text=_lens_name),
    Option("dispersion", bool, "a real lens's glass disperses: each sample at one colour's wavelength (colour "
           "fringes, and colour noise until it converges); off: achromatic, for a clean preview",
           "camera.dispersion", metadata="lenslab:Dispersion"),
    Option("sensor", str, "a sensor preset: its size and circle of confusion (see --list-sensors)", metavar="NAME",
           parse_text=_sensor_name),
    Option("sensor_fit", str, "which part of the sensor the image shows (auto: the long sides together)",
           "camera.sensor_fit", metadata="lenslab:SensorFit"),
    Option("focus_from", str, "what the focus distance is measured from (default: the scene's; new scenes: sensor)",
           "camera.focus_from", metadata="lenslab:FocusFrom"),
    Option("focus_breathing", bool, "off, the framing holds at every focus: the sensor one focal length behind "
           "the lens", "camera.focus_breathing", metadata="lenslab:FocusBreathing"),
    Option("circle_of_confusion", float, "circle of confusion for the depth-of-field readout and metadata",
           "camera.circle_of_confusion_mm", unit="mm", metavar="MM", old_names=("coc",),
           metadata="lenslab:CircleOfConfusionMM"),
    Option("aperture_blades", int, "aperture blades: 0 round, or 3 to 32", "camera.aperture_blades", metavar="N",
           refuse=_blades_that_make_a_stop, old_names=("blades",), metadata="lenslab:ApertureBlades"),
    Option("blade_curvature", float, "0 straight blades (polygonal bokeh) to 1 round", "camera.blade_curvature",
           metavar="C", metadata="lenslab:BladeCurvature"),
    Option("anamorphic_squeeze", float, "anamorphic squeeze: bokeh height over width (e.g. 1.33, 2)",
           "camera.anamorphic_squeeze", metavar="SQUEEZE", old_names=("anamorphic",),
           metadata="lenslab:AnamorphicSqueeze"),
    Option("barrel_clipping", float, "cat's-eye bokeh toward the frame's corners, 0 to 1", "camera.barrel_clipping",
           metavar="C", metadata="lenslab:BarrelClipping"),
    Option("aperture_image", str, "a grayscale image of the stop (custom bokeh), relative to the current folder",
           "camera.aperture_image", metavar="FILE", parse_text=_aperture_image_file, metadata="lenslab:ApertureImage"),
    Option("exposure_mode", str, "compensated (brightness kept, for scenes in arbitrary units), physical (manual: "
           "each stop a stop of light) or auto (aperture priority: the meter picks the shutter)",
           "camera.exposure_mode", metadata="lenslab:ExposureMode"),
    Option("iso", float, "sensor speed; implies the physical exposure mode", "camera.iso", metavar="S",
           metadata="Exif:PhotographicSensitivity"),
    Option("shutter", float, "exposure time, e.g. 1/125 or 2s; implies the physical exposure mode",
           "camera.shutter_s", unit="s", metavar="T", parse_text=_shutter, metadata="ExposureTime"),
    Option("metering", str, "how the auto exposure meters: average (centre-weighted) or spot (the frame's centre)",
           "camera.metering", metadata="lenslab:Metering"),
    Option("working_space", str, "the RGB the scene's colours are in and the renderer computes in",
           "render.working_space", metadata=VIEW_METADATA["working_space"]),
    # How the image is made and written, not the scene: the render job's and the output's.
    Option("time_limit", float, "stop after this many seconds, keeping what has been rendered (at least one "
           "sample in every pixel)", unit="s", metavar="SECONDS", bounds=(0.001, 1e7), scene=False),
    # The view transform of a picture (PNG, TIFF, JPEG; an EXR stays scene-linear): OpenColorIO's, from $OCIO or
    # the built-in ACES config (lenslab.colour_management.view). Names are checked against the config when the
    # transform is made, where the config is known.
    Option("display", str, "the display a picture is made for (default: the OCIO config's first, sRGB)",
           metavar="NAME", metadata=VIEW_METADATA["display"], scene=False),
    Option("view", str, "the display's view (default: its first, ACES 2.0 SDR in the built-in config; 'filmic' and "
           "'clamp' name that and 'Un-tone-mapped')", metavar="NAME", old_names=("tone_map",),
           metadata=VIEW_METADATA["view"], scene=False),
    Option("look", str, "OCIO looks applied before the view, comma separated", metavar="NAMES",
           metadata=VIEW_METADATA["looks"], scene=False),
    Option("exposure", float, "pictures only: brighten (+) or darken (-) by this many stops, in the view transform",
           unit="stops", metavar="STOPS", bounds=EXPOSURE_RANGE, metadata=VIEW_METADATA["exposure_stops"],
           scene=False),
    Option("contrast", float, "pictures only: contrast about middle grey (1 = as the view makes it)",
           metavar="C", bounds=CONTRAST_RANGE, metadata=VIEW_METADATA["contrast"], scene=False),
    Option("ocio_config", str, "an OpenColorIO config file, or a built-in one by its ocio:// URI (default: $OCIO, "
           "else the built-in ACES config)", metavar="FILE", parse_text=_ocio_config, metadata=VIEW_METADATA["config"],
           scene=False),
)

#: Every option by its name.
OPTIONS: dict[str, Option] = {option.name: option for option in _ROWS}

#: The options that override the scene (the fields of SceneOverrides), in the table's order.
SCENE_OPTIONS: tuple[Option, ...] = tuple(option for option in _ROWS if option.scene)

#: Older spellings -> the option's name.
OLD_NAMES: dict[str, str] = {old: option.name for option in _ROWS for old in option.old_names}


def option_named(name: str) -> Option:
    """The option called ``name`` or by an older spelling of it; KeyError for neither."""
    return OPTIONS[OLD_NAMES.get(name, name)]


#: The options that make a picture's view transform, and the ViewTransform field each sets.
VIEW_OPTIONS = {"display": "display", "view": "view", "look": "looks", "exposure": "exposure_stops",
                "contrast": "contrast", "ocio_config": "config"}


def view_transform(values: Mapping[str, object], working_space: str = DEFAULT_WORKING_SPACE) -> ViewTransform:
    """The view transform the picture options among ``values`` (by option name; missing or None: the default)
    describe, over ``working_space``: the command line's and a batch shot's alike. Not yet checked against its
    config (``resolved()`` does that)."""
    given = {field: values[name] for name, field in VIEW_OPTIONS.items() if values.get(name) is not None}
    return ViewTransform(working_space=working_space, **given)
