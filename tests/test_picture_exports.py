"""Pictures (PNG, 16-bit TIFF, JPEG): the display's code values, their colour space, and the view that made them.

Each format holds what render/film.display_pixels makes of the render; each carries an ICC v4 display profile of a
known display colour space, which a reader written here from ICC.1:2022 takes apart (not the module that built
it); a PNG carries its cICP chunk, found by walking the PNG's chunks; every picture names the view, also a display
LensLab does not know. A file cut short is caught, and a full disk is an error, not the end of the process.
"""

from __future__ import annotations

import hashlib
import shutil
import struct
import zlib

import numpy as np
import pytest

from lenslab.colour_management.display_spaces import known_display_space
from lenslab.colour_management.icc import display_profile
from lenslab.colour_management.view import ViewTransform
from lenslab.render import film
from lenslab.render.film import ExportError, read_image, write_image

PICTURES = (".png", ".tif", ".tiff", ".jpg", ".jpeg")
D50 = (0.9642, 1.0, 0.8249)
#: The D50-adapted colorants of published sRGB v4 profiles (ICC's sRGB_v4_ICC_preference.icc, rXYZ gXYZ bXYZ).
SRGB_COLORANTS = ((0.4361, 0.2225, 0.0139), (0.3851, 0.7169, 0.0971), (0.1431, 0.0606, 0.7141))
#: Apple's Display P3 profile's colorants.
DISPLAY_P3_COLORANTS = ((0.5151, 0.2412, -0.0011), (0.2920, 0.6922, 0.0419), (0.1571, 0.0666, 0.7841))
REQUIRED_DISPLAY_TAGS = {"desc", "cprt", "wtpt", "chad", "rXYZ", "gXYZ", "bXYZ", "rTRC", "gTRC", "bTRC"}


def render_like(width=64, height=48, seed=0) -> np.ndarray:
    """Smooth ramps past white with a little noise: every code value range, and edges a JPEG keeps."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    ramps = np.stack([x / width * 2.0, y / height * 1.5, 0.2 + 0.8 * (x + y) / (width + height)], axis=-1)
    return ramps + np.random.default_rng(seed).normal(0.0, 0.01, ramps.shape).astype(np.float32)


# -- an ICC profile, read as ICC.1:2022 lays it out -------------------------------------------------------------
def s15(data: bytes, at: int) -> float:
    return struct.unpack_from(">i", data, at)[0] / 65536.0


def parse_icc(profile: bytes) -> dict[str, bytes]:
    """The profile's tags by signature, after checking its header and tag table."""
    assert len(profile) % 4 == 0 and struct.unpack_from(">I", profile, 0)[0] == len(profile)
    assert profile[36:40] == b"acsp" and profile[8] == 4  # version 4
    assert profile[12:24] == b"mntrRGB XYZ "  # a display profile of an RGB device, XYZ PCS
    assert [s15(profile, 68 + 4 * i) for i in range(3)] == pytest.approx(D50, abs=1e-4)
    zeroed = bytearray(profile)
    for start, end in ((44, 48), (64, 68), (84, 100)):
        zeroed[start:end] = bytes(end - start)
    assert profile[84:100] == hashlib.md5(bytes(zeroed)).digest()  # the profile ID
    count = struct.unpack_from(">I", profile, 128)[0]
    table_end = 132 + 12 * count
    tags = {}
    for i in range(count):
        signature, offset, size = struct.unpack_from(">4sII", profile, 132 + 12 * i)
        assert offset % 4 == 0 and offset >= table_end and offset + size <= len(profile), signature
        tags[signature.decode("ascii")] = profile[offset:offset + size]
    return tags


def xyz_tag(tag: bytes) -> tuple[float, float, float]:
    assert tag[:4] == b"XYZ " and len(tag) == 20
    return tuple(s15(tag, 8 + 4 * i) for i in range(3))


def mluc_text(tag: bytes) -> str:
    assert tag[:4] == b"mluc"
    count, record_size = struct.unpack_from(">II", tag, 8)
    assert count >= 1 and record_size == 12
    length, offset = struct.unpack_from(">II", tag, 20)
    return tag[offset:offset + length].decode("utf-16-be")


def para_curve(tag: bytes) -> tuple[int, list[float]]:
    assert tag[:4] == b"para"
    function_type = struct.unpack_from(">H", tag, 8)[0]
    count = {0: 1, 1: 3, 2: 4, 3: 5, 4: 7}[function_type]
    assert len(tag) == 12 + 4 * count
    return function_type, [s15(tag, 12 + 4 * i) for i in range(count)]


def icc_of(metadata: dict) -> bytes:
    return bytes(np.asarray(metadata["ICCProfile"], dtype=np.uint8))


# -- a PNG's chunks ----------------------------------------------------------------------------------------------
def png_chunks(data: bytes) -> list[tuple[bytes, bytes]]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    chunks, at = [], 8
    while at < len(data):
        length, kind = struct.unpack_from(">I4s", data, at)
        payload = data[at + 8:at + 8 + length]
        assert struct.unpack_from(">I", data, at + 8 + length)[0] == zlib.crc32(kind + payload)
        chunks.append((kind, payload))
        at += 12 + length
    return chunks


# -- the pixels --------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", PICTURES)
def test_each_picture_holds_the_display_code_values_of_the_view(tmp_path, suffix):
    import OpenImageIO as oiio

    linear, view = render_like(), ViewTransform()
    display = film.display_pixels(linear, view)
    pixels, metadata = read_image(write_image(tmp_path / f"shot{suffix}", linear, view=view))
    stored = oiio.ImageInput.open(str(tmp_path / f"shot{suffix}"))
    stored_format = stored.spec().format
    stored.close()
    if suffix in (".tif", ".tiff"):
        assert stored_format == oiio.UINT16
        levels = np.round(pixels * 65535.0).astype(np.int64)
        assert np.abs(levels - np.round(display * 65535.0)).max() <= 1
    elif suffix == ".png":
        assert stored_format == oiio.UINT8
        np.testing.assert_array_equal(np.round(pixels * 255.0), film.to_8bit(display))
    else:  # JPEG: lossy, at quality 95 without chroma subsampling
        assert stored_format == oiio.UINT8 and metadata["jpeg:subsampling"] == "4:4:4"
        difference = np.abs(np.round(pixels * 255.0) - film.to_8bit(display).astype(np.float64))
        assert difference.mean() < 1.5 and difference.max() <= 16


def test_sixteen_bits_keep_what_eight_lose(tmp_path):
    """A dark ramp: many 16-bit levels inside one 8-bit level."""
    linear = np.repeat(np.linspace(0.0, 0.002, 256, dtype=np.float32)[None, :, None], 3, axis=2).repeat(4, axis=0)
    view = ViewTransform(view="Un-tone-mapped")
    tiff, _ = read_image(write_image(tmp_path / "dark.tif", linear, view=view))
    png, _ = read_image(write_image(tmp_path / "dark.png", linear, view=view))
    assert len(np.unique(tiff[0, :, 0])) > 4 * len(np.unique(png[0, :, 0]))


# -- the colour space: ICC profile and cICP -----------------------------------------------------------------------
@pytest.mark.parametrize("suffix", PICTURES)
def test_every_picture_of_a_known_display_carries_its_icc_profile(tmp_path, suffix):
    view = ViewTransform(display="Display P3 - Display")
    _, metadata = read_image(write_image(tmp_path / f"shot{suffix}", render_like(), view=view))
    profile = icc_of(metadata)
    assert profile == display_profile(known_display_space("Display P3 - Display"))
    tags = parse_icc(profile)
    assert mluc_text(tags["desc"]) == "Display P3"
    colorants = [xyz_tag(tags[name]) for name in ("rXYZ", "gXYZ", "bXYZ")]
    np.testing.assert_allclose(colorants, DISPLAY_P3_COLORANTS, atol=2e-3)
    if suffix != ".png":  # a PNG says it in its own chunks
        assert metadata["Exif:ColorSpace"] == 0xFFFF  # uncalibrated: the profile says what it is


def test_the_srgb_profile_is_a_v4_display_profile_with_srgbs_colorants_and_curve(tmp_path):
    _, metadata = read_image(write_image(tmp_path / "shot.tif", render_like()))  # the default display: sRGB
    tags = parse_icc(icc_of(metadata))
    assert REQUIRED_DISPLAY_TAGS <= set(tags)
    assert mluc_text(tags["desc"]) == "sRGB" and mluc_text(tags["cprt"])
    assert xyz_tag(tags["wtpt"]) == pytest.approx(D50, abs=1e-4)  # a display profile's white is the PCS's
    columns = np.array([xyz_tag(tags[name]) for name in ("rXYZ", "gXYZ", "bXYZ")])
    np.testing.assert_allclose(columns.sum(axis=0), D50, atol=1e-3)  # RGB white lands on D50
    np.testing.assert_allclose(columns, SRGB_COLORANTS, atol=2e-3)
    # chad: Bradford from D65 to D50, so it takes D65 to D50.
    assert tags["chad"][:4] == b"sf32" and len(tags["chad"]) == 8 + 9 * 4
    chad = np.array([s15(tags["chad"], 8 + 4 * i) for i in range(9)]).reshape(3, 3)
    np.testing.assert_allclose(chad @ np.array([0.3127 / 0.3290, 1.0, (1 - 0.3127 - 0.3290) / 0.3290]), D50,
                               atol=1e-3)
    function_type, parameters = para_curve(tags["rTRC"])
    assert function_type == 3
    assert parameters == pytest.approx([2.4, 1 / 1.055, 0.055 / 1.055, 1 / 12.92, 0.04045], abs=2e-5)
    assert tags["gTRC"] == tags["bTRC"] == tags["rTRC"]
    assert metadata["Exif:ColorSpace"] == 1


@pytest.mark.parametrize("display, gamma", [("Rec.1886 Rec.709 - Display", 2.4), ("Gamma 2.2 Rec.709 - Display", 2.2),
                                            ("P3-D65 - Display", 2.6)])
def test_a_gamma_display_has_a_pure_power_curve(display, gamma):
    tags = parse_icc(display_profile(known_display_space(display)))
    assert para_curve(tags["rTRC"]) == (0, [pytest.approx(gamma, abs=2e-5)])
    columns = np.array([xyz_tag(tags[name]) for name in ("rXYZ", "gXYZ", "bXYZ")])
    np.testing.assert_allclose(columns.sum(axis=0), D50, atol=1e-3)


@pytest.mark.parametrize("display, cicp", [("sRGB - Display", (1, 13, 0, 1)), ("Display P3 - Display", (12, 13, 0, 1)),
                                           ("Rec.1886 Rec.709 - Display", (1, 1, 0, 1)),
                                           ("Gamma 2.2 Rec.709 - Display", (1, 4, 0, 1)),
                                           ("Rec.2100-PQ - Display", (9, 16, 0, 1))])
def test_a_png_carries_its_cicp_chunk_and_profile_before_its_pixels(tmp_path, display, cicp):
    path = write_image(tmp_path / "shot.png", render_like(16, 8), view=ViewTransform(display=display))
    chunks = png_chunks(path.read_bytes())
    kinds = [kind for kind, _ in chunks]
    assert kinds.count(b"cICP") == 1 and kinds.index(b"cICP") < kinds.index(b"IDAT")
    assert dict(chunks)[b"cICP"] == bytes(cicp)
    _, metadata = read_image(path)
    assert tuple(metadata["CICP"]) == cicp
    space = known_display_space(display)
    if space.has_icc_profile:  # the profile is the chunk's name, a zero, the compression method, zlib's stream
        name_end = dict(chunks)[b"iCCP"].index(b"\x00")
        assert zlib.decompress(dict(chunks)[b"iCCP"][name_end + 2:]) == display_profile(space)
    else:  # PQ: no power curve, so no matrix/TRC profile
        assert b"iCCP" not in kinds
    # What older readers take instead agrees: the sRGB chunk for sRGB alone, a gAMA chunk for a gamma display.
    assert (b"sRGB" in kinds) == (display == "sRGB - Display")
    if isinstance(space.curve, float):
        assert struct.unpack(">I", dict(chunks)[b"gAMA"])[0] == round(100000 / space.curve)


# -- which view made it --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", PICTURES)
def test_every_picture_says_which_view_made_it(tmp_path, suffix):
    view = ViewTransform(display="Display P3 - Display", view="Un-tone-mapped", exposure_stops=-1.0)
    metadata = {"FNumber": 2.8, "ExposureTime": 1 / 60, "Software": "LensLab test", "lenslab:Seed": 7}
    _, back = read_image(write_image(tmp_path / f"shot{suffix}", render_like(), metadata, view=view))
    assert back["lenslab:View"] == "Un-tone-mapped" and back["lenslab:Display"] == "Display P3 - Display"
    assert back["lenslab:DisplayColourSpace"] == "Display P3 - Display"
    assert float(back["lenslab:DisplayExposureStops"]) == -1.0 and back["lenslab:Seed"] == "7"
    assert back["FNumber"] == pytest.approx(2.8) and back["Software"] == "LensLab test"  # Exif stays Exif
    # LensLab's values are each one attribute: nothing made of a comment's text (OpenImageIO reads a JPEG's so).
    assert all("\n" not in key for key in back)


def test_a_display_lenslab_does_not_know_gets_no_profile_but_its_name(tmp_path):
    """A studio's own config: no profile or cICP that might misdescribe its display, and the file names it."""
    config = tmp_path / "studio.ocio"
    config.write_text("""ocio_profile_version: 2
roles: {default: Linear Rec.709 (sRGB), scene_linear: Linear Rec.709 (sRGB)}
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  Studio Monitor:
    - !<View> {name: Plain, colorspace: Studio Display}
colorspaces:
  - !<ColorSpace> {name: Linear Rec.709 (sRGB), isdata: false}
  - !<ColorSpace>
    name: Studio Display
    from_scene_reference: !<ExponentTransform> {value: 2.2, direction: inverse}
""")
    view = ViewTransform(config=str(config))
    assert known_display_space(view.display_colour_space(), view.config) is None
    for suffix in (".png", ".tif", ".jpg"):
        path = write_image(tmp_path / f"shot{suffix}", render_like(), view=view)
        _, metadata = read_image(path)
        assert "ICCProfile" not in metadata and "CICP" not in metadata
        assert metadata["lenslab:DisplayColourSpace"] == "Studio Display" and metadata["lenslab:View"] == "Plain"
        assert metadata.get("Exif:ColorSpace", 0xFFFF) == 0xFFFF  # never "sRGB"
    assert b"cICP" not in [kind for kind, _ in png_chunks((tmp_path / "shot.png").read_bytes())]


# -- formats, sizes, refusals ---------------------------------------------------------------------------------------
def test_an_unknown_suffix_is_refused_naming_the_file_and_the_choices(tmp_path):
    target = tmp_path / "shot.bmp"
    with pytest.raises(ExportError) as refused:
        write_image(target, render_like())
    assert str(refused.value) == (f"{target}: unsupported output type '.bmp' "
                                  "(use .exr, .png, .tif, .tiff, .jpg or .jpeg)")
    assert list(tmp_path.iterdir()) == []


def test_layers_go_only_in_an_exr(tmp_path):
    layer = film.Layer("noisy", render_like())
    pixels, _ = read_image(write_image(tmp_path / "shot.tif", render_like(), layers=(layer,)))
    assert pixels.shape[2] == 3


@pytest.mark.parametrize("suffix, bytes_per_channel", [(".tif", 2), (".tiff", 2), (".jpg", 1), (".jpeg", 1)])
def test_the_space_a_picture_needs_is_its_pixels_as_stored(suffix, bytes_per_channel):
    needed = film.estimated_file_bytes(f"shot{suffix}", 100, 50, layer_channels=9)
    assert needed == 100 * 50 * 3 * bytes_per_channel + film.HEADER_ALLOWANCE_BYTES


# -- a file cut short, a full disk ------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".tif", ".jpg"])
def test_a_picture_cut_short_is_not_whole(tmp_path, suffix):
    import OpenImageIO as oiio

    whole = write_image(tmp_path / f"whole{suffix}", render_like(256, 128))
    spec = oiio.ImageSpec(256, 128, 3, oiio.UINT16 if suffix == ".tif" else oiio.UINT8)
    profile = display_profile(known_display_space("sRGB - Display"))  # as write_image's spec has it
    spec.attribute("ICCProfile", oiio.TypeDesc(f"uint8[{len(profile)}]"), profile)
    assert film._incompleteness(whole, spec) is None
    for keep in (len(whole.read_bytes()) // 2, len(whole.read_bytes()) - 1):
        cut = tmp_path / f"cut{suffix}"
        shutil.copyfile(whole, cut)
        with open(cut, "r+b") as file:
            file.truncate(keep)
        assert film._incompleteness(cut, spec) is not None
