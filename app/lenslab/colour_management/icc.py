"""ICC v4 display profiles of the known display colour spaces (colour_management/display_spaces.py), built byte by
byte from ICC.1:2022 (profile version 4.4): what a picture embeds so that any colour-managed viewer shows it as
the display it was made for.

A matrix/TRC display profile: the 128-byte header, the tag table, and the tags a v4 display profile requires:

- ``desc`` and ``cprt``: text, as multiLocalizedUnicodeType (``mluc``), one English record;
- ``wtpt``: the media white, which for a display profile is the PCS white, D50;
- ``chad``: the Bradford adaptation from the display's white (D65) to D50, an s15Fixed16 3 x 3 matrix (``sf32``);
- ``rXYZ``, ``gXYZ``, ``bXYZ``: the primaries' XYZ, adapted to D50 by that matrix (the columns of RGB -> PCS XYZ);
- ``rTRC``, ``gTRC``, ``bTRC``: one parametricCurveType (``para``) shared by the three channels: function type 3 for
  sRGB's piecewise curve, type 0 (a pure power) for a gamma.

Numbers are big-endian; every tag starts on a 4-byte boundary and the profile's size counts the padding after the
last. The profile ID is the MD5 of the profile with its flags, rendering intent and ID fields zeroed. The header's
date is fixed, so one display always makes the same bytes (and an export the same file).
"""

from __future__ import annotations

import hashlib
import struct
from functools import lru_cache

import numpy as np

from lenslab.colour_management.display_spaces import SRGB_CURVE, DisplaySpace

#: The PCS illuminant, D50, as ICC.1 gives it in nCIEXYZ (the header's and wtpt's value).
PCS_D50 = (0.9642, 1.0, 0.8249)
#: Bradford's cone response matrix (Lam 1985), XYZ -> sharpened LMS, as ICC.1 Annex E uses it.
BRADFORD = np.array([[0.8951, 0.2664, -0.1614],
                     [-0.7502, 1.7135, 0.0367],
                     [0.0389, -0.0685, 1.0296]])
#: IEC 61966-2-1's decoding, as parametric function type 3's g, a, b, c, d:
#: Y = (aX + b)^g for X >= d, else Y = cX.
SRGB_PARAMETERS = (2.4, 1 / 1.055, 0.055 / 1.055, 1 / 12.92, 0.04045)

PROFILE_VERSION = bytes((4, 0x40, 0, 0))  # 4.4.0.0: ICC.1:2022
PROFILE_DATE = (2026, 1, 1, 0, 0, 0)  # fixed: see the module's docstring
HEADER_BYTES = 128
TAG_ENTRY_BYTES = 12  # signature, offset, size
COPYRIGHT = "No copyright, use freely"


def s15fixed16(value: float) -> bytes:
    """ICC's s15Fixed16Number: a signed 32-bit integer, 1.0 = 0x00010000."""
    return struct.pack(">i", int(round(value * 65536.0)))


def xyz_from_xy(x: float, y: float) -> np.ndarray:
    """XYZ with Y = 1 of chromaticity (x, y)."""
    return np.array([x / y, 1.0, (1.0 - x - y) / y])


def rgb_to_xyz(primaries: tuple[float, ...], white: tuple[float, float]) -> np.ndarray:
    """The 3 x 3 matrix from linear RGB of these primaries to XYZ, RGB (1, 1, 1) mapping to the white at Y = 1."""
    columns = np.stack([xyz_from_xy(primaries[2 * i], primaries[2 * i + 1]) for i in range(3)], axis=1)
    return columns * np.linalg.solve(columns, xyz_from_xy(*white))


def bradford_adaptation(source_white: np.ndarray, target_white: np.ndarray) -> np.ndarray:
    """The 3 x 3 matrix that adapts XYZ seen under ``source_white`` to ``target_white`` (both XYZ)."""
    gains = (BRADFORD @ target_white) / (BRADFORD @ source_white)
    return np.linalg.inv(BRADFORD) @ np.diag(gains) @ BRADFORD


# -- tag types (ICC.1:2022 clause 10) ---------------------------------------------------------------------------
def _type_header(signature: bytes) -> bytes:
    return signature + bytes(4)  # the type's signature and four reserved bytes


def mluc(text: str) -> bytes:
    """multiLocalizedUnicodeType with one record, en-US: count, record size 12, then language, country, the
    string's length in bytes and its offset from the tag's start; the string in UTF-16BE, unterminated."""
    encoded = text.encode("utf-16-be")
    records_start = 16
    string_offset = records_start + 12
    return (_type_header(b"mluc") + struct.pack(">II", 1, 12) + b"en" + b"US"
            + struct.pack(">II", len(encoded), string_offset) + encoded)


def xyz_type(xyz) -> bytes:
    return _type_header(b"XYZ ") + b"".join(s15fixed16(v) for v in xyz)


def sf32(values) -> bytes:
    return _type_header(b"sf32") + b"".join(s15fixed16(v) for v in values)


def para(curve: str | float) -> bytes:
    """parametricCurveType: the function type (uInt16), two reserved bytes, its parameters."""
    function_type, parameters = (3, SRGB_PARAMETERS) if curve == SRGB_CURVE else (0, (float(curve),))
    return (_type_header(b"para") + struct.pack(">HH", function_type, 0)
            + b"".join(s15fixed16(p) for p in parameters))


# -- the profile -------------------------------------------------------------------------------------------------
@lru_cache(maxsize=16)
def display_profile(space: DisplaySpace) -> bytes:
    """The ICC v4 display profile of ``space`` (one with a curve: ``space.has_icc_profile``)."""
    if not space.has_icc_profile:
        raise ValueError(f"{space.description} has no ICC matrix/TRC profile (its curve is no power function)")
    d50 = np.array(PCS_D50)
    white = xyz_from_xy(*space.white)
    chad = bradford_adaptation(white, d50)
    colorants = chad @ rgb_to_xyz(space.primaries, space.white)  # columns: red, green, blue in the PCS
    curve = para(space.curve)
    tags = [(b"desc", mluc(space.description)), (b"cprt", mluc(COPYRIGHT)), (b"wtpt", xyz_type(d50)),
            (b"chad", sf32(chad.reshape(-1))),
            (b"rXYZ", xyz_type(colorants[:, 0])), (b"gXYZ", xyz_type(colorants[:, 1])),
            (b"bXYZ", xyz_type(colorants[:, 2])),
            (b"rTRC", curve), (b"gTRC", curve), (b"bTRC", curve)]
    return _assemble(tags)


def _assemble(tags: list[tuple[bytes, bytes]]) -> bytes:
    """Header, tag table and tag data; a tag whose data is another's (the three TRCs) points at the same bytes,
    as ICC.1 allows."""
    table_end = HEADER_BYTES + 4 + TAG_ENTRY_BYTES * len(tags)
    data = bytearray()
    placed: dict[bytes, int] = {}  # tag data -> its offset in the profile
    entries = []
    for signature, payload in tags:
        if payload not in placed:
            placed[payload] = table_end + len(data)
            data += payload + bytes(-len(payload) % 4)  # the next tag starts on a 4-byte boundary
        entries.append(struct.pack(">4sII", signature, placed[payload], len(payload)))
    table = struct.pack(">I", len(tags)) + b"".join(entries)
    size = table_end + len(data)
    profile = bytearray(_header(size) + table + data)
    profile[84:100] = hashlib.md5(_with_id_fields_zeroed(bytes(profile))).digest()
    return bytes(profile)


def _header(size: int) -> bytes:
    header = (struct.pack(">I", size) + bytes(4)  # size; no preferred CMM
              + PROFILE_VERSION + b"mntr" + b"RGB " + b"XYZ "  # a display profile, RGB device, XYZ PCS
              + struct.pack(">6H", *PROFILE_DATE) + b"acsp"
              + bytes(4)  # primary platform: none
              + bytes(4)  # flags: not embedded-only, usable independently
              + bytes(4) + bytes(4) + bytes(8)  # device manufacturer, model, attributes: none
              + struct.pack(">I", 0)  # rendering intent: perceptual
              + b"".join(s15fixed16(v) for v in PCS_D50)
              + bytes(4)  # creator: none
              + bytes(16)  # profile ID: filled in from the MD5 once the profile is whole
              + bytes(28))  # reserved
    assert len(header) == HEADER_BYTES
    return header


def _with_id_fields_zeroed(profile: bytes) -> bytes:
    """What ICC.1 computes the profile ID over: the profile with its flags (bytes 44-47), rendering intent
    (64-67) and profile ID (84-99) zeroed."""
    data = bytearray(profile)
    for start, end in ((44, 48), (64, 68), (84, 100)):
        data[start:end] = bytes(end - start)
    return bytes(data)
