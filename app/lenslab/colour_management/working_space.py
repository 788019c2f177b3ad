"""The working space: the RGB the renderer computes in, and what a scene's colours mean.

Linear Rec.709 (sRGB primaries, D65) by default, as Mitsuba and pbrt: a scene written for them renders alike here.
ACEScg (the AP1 primaries, the ACES white) is available for scenes that want a wider gamut. A scene's typed
colours, its emitters and its reflectances are in its working space; image textures are converted into it as they
are read (render/textures.py). The luminance rows below make a meter and a histogram read the same light in
either space.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lenslab.colour_management.config import DEFAULT_SOURCE, ColourConfigError, load_config


@dataclass(frozen=True)
class WorkingSpace:
    name: str  # as a scene file writes it
    label: str  # as the studio shows it
    ocio_names: tuple[str, ...]  # the colour space's names and aliases in the ACES configs, the first preferred
    luminance: tuple[float, float, float]  # Y of linear R, G, B (the middle row of RGB -> XYZ)
    chromaticities: tuple[float, ...]  # OpenEXR's: red x y, green x y, blue x y, white x y


WORKING_SPACES: dict[str, WorkingSpace] = {space.name: space for space in (
    WorkingSpace("lin_rec709", "Linear Rec.709 (sRGB)",
                 ("Linear Rec.709 (sRGB)", "lin_rec709_srgb", "lin_rec709", "Utility - Linear - sRGB"),
                 (0.2126, 0.7152, 0.0722),  # ITU-R BT.709
                 (0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290)),
    WorkingSpace("acescg", "ACEScg",
                 ("ACEScg", "lin_ap1_scene", "lin_ap1", "ACES - ACEScg"),
                 (0.2722287168, 0.6740817658, 0.0536895174),  # SMPTE ST 2065-1's AP1 -> XYZ, middle row
                 (0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767)),
)}
DEFAULT_WORKING_SPACE = "lin_rec709"


def working_space(name: str) -> WorkingSpace:
    """The working space called ``name``; a ValueError naming the choices for any other."""
    try:
        return WORKING_SPACES[name]
    except KeyError:
        raise ValueError(f"unknown working space '{name}' (choose from {', '.join(WORKING_SPACES)})") from None


def ocio_space_of(name: str, config) -> str:
    """The colour space of ``config`` that is the working space ``name``: found by its name or an alias (every ACES
    config has them); a ColourConfigError when the config has none."""
    space = working_space(name)
    for candidate in space.ocio_names:
        found = config.getColorSpace(candidate)
        if found is not None:
            return found.getName()
    raise ColourConfigError(f"the OCIO config has no colour space for the working space {space.label} (looked for "
                            f"{', '.join(repr(n) for n in space.ocio_names)}): add one of those names as an alias")


def luminance(rgb, space: str = DEFAULT_WORKING_SPACE):
    """Luminance (the CIE Y that a meter reads) of linear colours in working space ``space``: (..., 3) values."""
    weights = working_space(space).luminance
    rgb = np.asarray(rgb)
    y = rgb[..., 0] * weights[0] + rgb[..., 1] * weights[1] + rgb[..., 2] * weights[2]
    return y if y.ndim else float(y)


def convert(pixels: np.ndarray, source: str, target: str, config_source: str = DEFAULT_SOURCE) -> np.ndarray:
    """``pixels`` (..., 3) from OCIO colour space ``source`` to ``target`` (names or aliases in the config) as
    float32, through OCIO's CPU processor; the pixels as they are when the two are one space."""
    config = load_config(config_source)
    names = []
    for name in (source, target):
        found = config.getColorSpace(name)
        if found is None:
            raise ColourConfigError(f"the OCIO config has no colour space '{name}'")
        names.append(found.getName())
    rgb = np.ascontiguousarray(pixels, dtype=np.float32)
    if names[0] == names[1]:
        return rgb
    rgb = rgb.copy() if rgb is pixels else rgb
    processor = config.getProcessor(names[0], names[1]).getDefaultCPUProcessor()
    processor.applyRGB(rgb.reshape(-1, 3))
    return rgb
