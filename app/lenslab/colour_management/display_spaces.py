"""The display colour spaces LensLab can describe in a picture file: their primaries, white and transfer curve (for
an ICC profile, colour_management/icc.py) and their ITU-T H.273 code points (for PNG's cICP chunk).

A display colour space of an OCIO config is recognised by its Color Interop Forum ID (OCIO 2.5 configs give one:
``srgb_rec709_display``), else by the names and aliases the ACES configs give it. One no table row names (a
studio's own display) is unknown: its pictures carry its name, and no profile that might misdescribe it.
"""

from __future__ import annotations

from dataclasses import dataclass

from lenslab.colour_management.config import DEFAULT_SOURCE, load_config

#: Chromaticities x, y of red, green and blue.
REC709_PRIMARIES = (0.640, 0.330, 0.300, 0.600, 0.150, 0.060)  # ITU-R BT.709, sRGB
P3_PRIMARIES = (0.680, 0.320, 0.265, 0.690, 0.150, 0.060)  # SMPTE EG 432-1 (P3 with a D65 white)
REC2020_PRIMARIES = (0.708, 0.292, 0.170, 0.797, 0.131, 0.046)  # ITU-R BT.2020
D65_WHITE = (0.3127, 0.3290)

#: The transfer curve of IEC 61966-2-1 (sRGB): piecewise, linear near black. A number is a pure power (a gamma).
SRGB_CURVE = "sRGB"

# ITU-T H.273's code points, as PNG's cICP chunk carries them: colour primaries, transfer characteristics, matrix
# coefficients (0: RGB, no matrix) and video full range (1: code values 0 to 2^n - 1).
H273_BT709_PRIMARIES, H273_BT2020_PRIMARIES, H273_P3D65_PRIMARIES = 1, 9, 12
H273_BT709_TRANSFER = 1  # H.273 names BT.1886 (gamma 2.4) as this curve's display counterpart
H273_GAMMA22_TRANSFER = 4  # "assumed display gamma 2.2" (BT.470 System M)
H273_SRGB_TRANSFER, H273_PQ_TRANSFER, H273_HLG_TRANSFER = 13, 16, 18


def _cicp(primaries: int, transfer: int) -> tuple[int, int, int, int]:
    return primaries, transfer, 0, 1


@dataclass(frozen=True)
class DisplaySpace:
    interop_id: str  # the Color Interop Forum's name
    description: str  # as an ICC profile's description
    primaries: tuple[float, ...]  # red x y, green x y, blue x y
    white: tuple[float, float]
    curve: str | float | None  # SRGB_CURVE, a gamma, or None: no ICC matrix/TRC profile can say it (PQ, HLG)
    cicp: tuple[int, int, int, int] | None  # None: H.273 has no code point for the curve (a pure 2.6)
    names: tuple[str, ...] = ()  # the ACES configs' names and aliases of it

    @property
    def has_icc_profile(self) -> bool:
        return self.curve is not None


DISPLAY_SPACES: tuple[DisplaySpace, ...] = (
    DisplaySpace("srgb_rec709_display", "sRGB", REC709_PRIMARIES, D65_WHITE, SRGB_CURVE,
                 _cicp(H273_BT709_PRIMARIES, H273_SRGB_TRANSFER), ("sRGB - Display", "srgb_display")),
    DisplaySpace("srgb_p3d65_display", "Display P3", P3_PRIMARIES, D65_WHITE, SRGB_CURVE,
                 _cicp(H273_P3D65_PRIMARIES, H273_SRGB_TRANSFER), ("Display P3 - Display", "displayp3_display")),
    # BT.1886's EOTF with a black of 0 is a pure 2.4 power.
    DisplaySpace("g24_rec709_display", "Rec.709, BT.1886 (gamma 2.4)", REC709_PRIMARIES, D65_WHITE, 2.4,
                 _cicp(H273_BT709_PRIMARIES, H273_BT709_TRANSFER),
                 ("Rec.1886 Rec.709 - Display", "rec1886_rec709_display")),
    DisplaySpace("g22_rec709_display", "Rec.709, gamma 2.2", REC709_PRIMARIES, D65_WHITE, 2.2,
                 _cicp(H273_BT709_PRIMARIES, H273_GAMMA22_TRANSFER), ("Gamma 2.2 Rec.709 - Display",)),
    DisplaySpace("g26_p3d65_display", "P3-D65, gamma 2.6", P3_PRIMARIES, D65_WHITE, 2.6, None,
                 ("P3-D65 - Display", "p3d65_display")),
    # HDR: PQ and HLG are no power curve, so no matrix/TRC profile; cICP is how a PNG says them.
    DisplaySpace("pq_rec2020_display", "Rec.2100 PQ", REC2020_PRIMARIES, D65_WHITE, None,
                 _cicp(H273_BT2020_PRIMARIES, H273_PQ_TRANSFER), ("Rec.2100-PQ - Display", "rec2100_pq_display")),
    DisplaySpace("pq_p3d65_display", "P3-D65 PQ", P3_PRIMARIES, D65_WHITE, None,
                 _cicp(H273_P3D65_PRIMARIES, H273_PQ_TRANSFER), ("ST2084-P3-D65 - Display", "st2084_p3d65_display")),
    DisplaySpace("hlg_rec2020_display", "Rec.2100 HLG", REC2020_PRIMARIES, D65_WHITE, None,
                 _cicp(H273_BT2020_PRIMARIES, H273_HLG_TRANSFER), ("Rec.2100-HLG - Display", "rec2100_hlg_display")),
)
_BY_NAME = {name: space for space in DISPLAY_SPACES for name in (space.interop_id, *space.names)}


def known_display_space(name: str, config: str = DEFAULT_SOURCE) -> DisplaySpace | None:
    """The display colour space that the colour space ``name`` of OCIO config ``config`` is, or None when it is
    none LensLab knows: looked up by its interop ID, then its name, then its aliases."""
    candidates = [name]
    space = load_config(config).getColorSpace(name)
    if space is not None:
        interop_id = space.getInteropID() if hasattr(space, "getInteropID") else ""  # OCIO 2.5 and later
        candidates = [interop_id, space.getName(), *space.getAliases()]
    return next((_BY_NAME[candidate] for candidate in candidates if candidate in _BY_NAME), None)
