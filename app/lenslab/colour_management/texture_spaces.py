"""What an image texture's ``color_space`` says, and how its texels reach the working space (docs/colour.md,
"Textures in their colour space").

A texture's colour space is one of four keywords, or the name or alias of any colour space of the OCIO config:

- ``auto``: 8- and 16-bit files are sRGB, float files (EXR, HDR) linear Rec.709, as files of each kind hold them
  by convention (and as Mitsuba reads a bitmap). In a data slot: ``raw``.
- ``srgb``: sRGB-encoded Rec.709. ``linear``: linear Rec.709. ``raw``: numbers, never converted.
- an OCIO name (``ACEScg``, ``sRGB Encoded P3-D65``, ``lin_ap1_scene`` ...): converted by OCIO's own processor.

A colour texture (an albedo, a projected slide, a sky) is converted into the scene's working space as it is read.
A data texture (roughness, a normal map, a bump map's heights, a mask's opacity, a blend's weight) holds numbers:
a change of primaries would mix a normal map's axes, so in a data slot ``auto``, ``raw`` and ``linear`` read the
values as stored, whatever the working space; ``srgb`` decodes the sRGB curve channel by channel and changes no
primaries (how Mitsuba reads a bitmap without ``raw`` in any slot: a mask painted in an 8-bit paint program); any
other colour space is read as stored too, with a warning (:func:`data_slot_note`), unless OCIO marks it data.

``srgb`` (and ``auto`` on an 8-bit file) is decoded by ``lenslab.color.srgb_to_linear``, not by OCIO: OCIO's
default CPU processor computes the curve with a fast approximation of pow that reads white as 1.000024 (2.4e-5 off,
measured with OpenColorIO 2.5/2.6), and the curve's one home is lenslab.color, which the display shares. The change
of primaries that follows, for a working space other than linear Rec.709, is OCIO's.
"""

from __future__ import annotations

import difflib

import numpy as np

from lenslab.color import srgb_to_linear
from lenslab.colour_management.config import DEFAULT_SOURCE, ColourConfigError, config_name, load_config
from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE, convert, ocio_space_of

#: What ``color_space`` may be besides a colour space of the OCIO config.
KEYWORDS = ("auto", "srgb", "linear", "raw")
#: The working space that linear Rec.709, and so ``srgb`` and ``linear``, need no OCIO to reach.
REC709_WORKING_SPACE = "lin_rec709"
#: OCIO names shown as examples in the error for a name the config lacks.
EXAMPLE_NAMES = ("ACEScg", "sRGB Encoded P3-D65", "lin_ap1_scene")


def is_keyword(color_space: str) -> bool:
    return color_space in KEYWORDS


def colour_space_problem(color_space: object, config_source: str = DEFAULT_SOURCE) -> str | None:
    """Why ``color_space`` is no texture colour space (neither a keyword nor a colour space of the config), in
    words that list the keywords; None when it is one. A keyword never loads OCIO."""
    if isinstance(color_space, str) and is_keyword(color_space):
        return None
    keywords = ", ".join(KEYWORDS)
    try:
        config = load_config(config_source)
    except ColourConfigError as exc:
        return f"'{color_space}' is not one of {keywords}, and no OCIO colour space can be checked ({exc})"
    if isinstance(color_space, str) and color_space.strip() and config.getColorSpace(color_space) is not None:
        return None
    examples = ", ".join(f"'{name}'" for name in EXAMPLE_NAMES)
    hint = _closest(str(color_space), config)
    return (f"'{color_space}' is not a colour space: give {keywords}, or the name or alias of any colour space of "
            f"the OCIO config {config_name(config_source)} (such as {examples})"
            + (f"; did you mean '{hint}'?" if hint else ""))


def _closest(name: str, config) -> str | None:
    names = list(KEYWORDS)
    for space in config.getColorSpaces():
        names += [space.getName(), *space.getAliases()]
    by_lower = {n.lower(): n for n in names}
    found = difflib.get_close_matches(name.lower(), list(by_lower), n=1, cutoff=0.75)
    return by_lower[found[0]] if found else None


def data_slot_note(color_space: str, config_source: str = DEFAULT_SOURCE) -> str | None:
    """What to tell the user of a texture in a data slot whose colour space cannot apply there: a colour space
    of the config other than a data one (a change of primaries would mix the data's channels); None when the
    slot reads it as asked (a keyword, or a space OCIO marks as data)."""
    if is_keyword(color_space):
        return None
    space = load_config(config_source).getColorSpace(color_space)
    if space is None or space.isData():
        return None
    return (f"color_space '{color_space}' is a colour space, but this texture holds data (roughness, normals, "
            "heights, an opacity or a weight): read as stored, as \"raw\" reads it (\"srgb\" would decode an 8-bit "
            "file's curve)")


def to_working_space(rgb: np.ndarray, color_space: str, is_float: bool, working_space: str = DEFAULT_WORKING_SPACE,
                     *, data: bool = False, config_source: str = DEFAULT_SOURCE) -> np.ndarray:
    """(..., 3) texels as stored in the file (0..1 for 8 and 16-bit files; ``is_float``: a float file) as the
    renderer reads them: a colour texture in ``working_space``, a data texture as the module's docstring says.
    Raises ColourConfigError for a name the config lacks, or a config without the working space."""
    if color_space == "auto":
        color_space = "raw" if data else ("linear" if is_float else "srgb")
    if color_space == "srgb":
        rgb = srgb_to_linear(np.clip(rgb, 0.0, 1.0))  # an sRGB file encodes only what a display shows
        return rgb if data else _from_rec709(rgb, working_space, config_source)
    if data or color_space == "raw":
        return rgb
    if color_space == "linear":
        return _from_rec709(rgb, working_space, config_source)
    config = load_config(config_source)
    return convert(rgb, color_space, ocio_space_of(working_space, config), config_source)


def _from_rec709(rgb: np.ndarray, working_space: str, config_source: str) -> np.ndarray:
    if working_space == REC709_WORKING_SPACE:
        return rgb  # no OCIO needed: a default scene never loads it for its textures
    config = load_config(config_source)
    return convert(rgb, ocio_space_of(REC709_WORKING_SPACE, config), ocio_space_of(working_space, config),
                   config_source)
