"""From accumulated samples to pictures: the linear image, its display through OpenColorIO, and export.

EXR holds the linear radiance as float32 RGB in the working space with the camera's settings as metadata
(standard Exif names where they exist). PNG (8-bit), TIFF (16-bit) and JPEG (8-bit) hold a display-referred
picture, made through OpenColorIO's view transform (lenslab.colour_management.view), one code path for all three;
each carries its display colour space (an ICC profile, and PNG's cICP chunk: lenslab.colour_management.icc) and
the view that made it. Files are written to a temporary name beside the target, checked, and renamed into place
(lenslab.atomic), so an export is whole or absent, never half-written.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from lenslab.atomic import atomic_path, write_failure_reason
from lenslab.colour_management.display_spaces import DisplaySpace, known_display_space
from lenslab.colour_management.icc import display_profile
from lenslab.colour_management.view import ViewTransform
from lenslab.colour_management.working_space import working_space
from lenslab.limits import image_too_large

#: What write_image writes: the scene-linear EXR, and the pictures (display code values).
PICTURE_SUFFIXES = (".png", ".tif", ".tiff", ".jpg", ".jpeg")
EXPORT_SUFFIXES = (".exr", *PICTURE_SUFFIXES)
#: The suffixes as an error message lists them.
EXPORT_SUFFIXES_TEXT = ", ".join(EXPORT_SUFFIXES[:-1]) + " or " + EXPORT_SUFFIXES[-1]
JPEG_SUFFIXES = (".jpg", ".jpeg")
JPEG_QUALITY = 95


class ExportError(RuntimeError):
    pass


def resolve(accumulation: np.ndarray) -> np.ndarray:
    """Radiance per pixel from (weighted sum rgb, weight); pixels with no samples yet are black. The weight is
    the sample count, or with a splatted gaussian filter the expected sum of filter weights (render/tracer.py)."""
    return (accumulation[..., :3] * _reciprocal(accumulation[..., 3:4])).astype(np.float32, copy=False)


def _reciprocal(weight: np.ndarray) -> np.ndarray:
    """1 / weight, and 0 where the weight is 0 (a pixel with no sample): one division per pixel, not per channel
    (a third of the time of dividing the channels, measured at 1920 x 1080)."""
    return np.divide(np.float32(1.0), weight, out=np.zeros(weight.shape, np.float32), where=weight > 0)


def resolve_features(features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(albedo, normal), each (H, W, 3) float32, from the denoiser's guide sums (H, W, 2, 4): (albedo sum, sample
    count) and (normal sum, 0), as glsl/trace.comp accumulates them; pixels with no samples yet are zero."""
    per_sample = _reciprocal(features[:, :, 0, 3:4])
    albedo = features[:, :, 0, :3] * per_sample
    normal = features[:, :, 1, :3] * per_sample
    # Means of values in [0, 1] and of unit vectors stay in range but for float rounding: OIDN expects them in it.
    return np.clip(albedo, 0.0, 1.0, out=albedo), np.clip(normal, -1.0, 1.0, out=normal)


def merge(*accumulations: np.ndarray) -> np.ndarray:
    """Combine partial renders of the same view (different seeds, or disjoint sample ranges of one seed: the
    parts of a shot split across workers, lenslab.batch.parts): sums and counts add."""
    return np.sum(accumulations, axis=0)


def display_pixels(linear: np.ndarray, view: ViewTransform = ViewTransform()) -> np.ndarray:
    """Display code values in [0, 1] of the linear image (H, W, 3) through the view transform ``view`` (OCIO's CPU
    processor): the steps of glsl/display.comp, which the studio runs on the GPU with OCIO's GLSL, in the same
    order (no negative radiance goes in)."""
    return view.apply(np.maximum(linear[..., :3], np.float32(0.0)))


def to_8bit(display: np.ndarray) -> np.ndarray:
    return np.clip(np.round(display * 255.0), 0, 255).astype(np.uint8)


def to_16bit(display: np.ndarray) -> np.ndarray:
    return np.clip(np.round(display * 65535.0), 0, 65535).astype(np.uint16)


#: Metadata that OpenImageIO must be told is a 4 x 4 matrix (OpenEXR's worldToCamera and worldToNDC).
MATRIX_ATTRIBUTES = ("worldtocamera", "worldtoNDC")


@dataclass(frozen=True)
class Layer:
    """An image an EXR carries beside its main RGB, as OpenEXR's layers are named: channel ``name.R`` and so on
    (how OpenImageIO, Nuke and Blender group channels into layers). A picture (PNG, TIFF, JPEG) has no room for
    layers."""

    name: str  # "noisy", "albedo", "normal"
    pixels: np.ndarray  # (H, W, len(channels)), the main image's size
    channels: tuple[str, ...] = ("R", "G", "B")  # a normal's are X, Y, Z, as Blender's Normal pass
    radiance: bool = True  # scaled by the camera's exposure as the main image is (albedo and normal are not)


#: Bytes per channel of what write_image writes: EXR float32, TIFF 16-bit, PNG and JPEG 8-bit.
BYTES_PER_CHANNEL = {".exr": 4, ".png": 1, ".tif": 2, ".tiff": 2, ".jpg": 1, ".jpeg": 1}
#: Room for a file's header and metadata beside its pixels.
HEADER_ALLOWANCE_BYTES = 64 << 10


def estimated_file_bytes(path: str | os.PathLike, width: int, height: int, layer_channels: int = 0) -> int:
    """What write_image will need on disk for a ``width`` x ``height`` image at ``path`` (its suffix names the
    format), with ``layer_channels`` more channels of EXR layers. The pixels as stored, uncompressed: EXR's zip,
    PNG's and TIFF's deflate gain little on a noisy render (nor does JPEG at quality 95 on one), and a check of
    free space should not pass a file that then does not fit."""
    suffix = Path(path).suffix.lower()
    channels = 3 + (layer_channels if suffix == ".exr" else 0)  # a picture has no room for layers
    return width * height * channels * BYTES_PER_CHANNEL.get(suffix, 4) + HEADER_ALLOWANCE_BYTES


def write_image(path: str | os.PathLike, linear: np.ndarray, metadata: dict[str, object] | None = None,
                *, sensor_exposure: float = 1.0, view: ViewTransform = ViewTransform(),
                before_rename: Callable[[], None] | None = None, layers: Sequence[Layer] = ()) -> Path:
    """Write ``linear`` (H, W, 3) to an .exr (linear float) or a picture (.png, .tif, .jpg: through the view
    transform), whole or not at all.

    ``sensor_exposure`` multiplies the radiance first, in both: the camera's physical exposure, part of the
    capture. ``view`` (OCIO's display, view, looks, exposure and contrast) makes a picture's pixels from it, and
    names the working space the EXR's chromaticities describe. An EXR carries the chromaticities and the camera
    matrices, and ``layers`` after its R, G, B (a picture leaves them out); a picture carries its display colour
    space (see :func:`_describe_colour`), Exif, and LensLab's own values (PNG: as text chunks; TIFF and JPEG, whose
    writers keep no metadata of other names: as lines of the ImageDescription). ``before_rename``: see
    lenslab.atomic.atomic_path."""
    import OpenImageIO as oiio  # imported here: only exporting needs it

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in EXPORT_SUFFIXES:
        raise ExportError(f"{path}: unsupported output type '{path.suffix}' (use {EXPORT_SUFFIXES_TEXT})")
    if not path.parent.is_dir():
        raise ExportError(f"{path}: folder {path.parent} does not exist")
    height, width = linear.shape[:2]
    linear = linear[..., :3] * np.float32(sensor_exposure) if sensor_exposure != 1.0 else linear[..., :3]
    metadata = dict(metadata or {})
    if suffix == ".exr":
        planes, names = [linear], ["R", "G", "B"]
        for layer in layers:
            if layer.pixels.shape != (height, width, len(layer.channels)):
                raise ValueError(f"layer {layer.name} is {layer.pixels.shape}, not ({height}, {width}, "
                                 f"{len(layer.channels)})")
            exposed = layer.radiance and sensor_exposure != 1.0
            planes.append(layer.pixels * np.float32(sensor_exposure) if exposed else layer.pixels)
            names += [f"{layer.name}.{channel}" for channel in layer.channels]
        pixels = np.ascontiguousarray(np.concatenate(planes, axis=2) if layers else linear, dtype=np.float32)
        spec = oiio.ImageSpec(width, height, len(names), oiio.FLOAT)
        spec.channelnames = tuple(names)
        spec.attribute("compression", "zip")
        spec.attribute("chromaticities", oiio.TypeDesc("float[8]"), working_space(view.working_space).chromaticities)
    else:
        display = display_pixels(linear, view)
        sixteen_bit = BYTES_PER_CHANNEL[suffix] == 2
        pixels = to_16bit(display) if sixteen_bit else to_8bit(display)
        spec = oiio.ImageSpec(width, height, 3, oiio.UINT16 if sixteen_bit else oiio.UINT8)
        if suffix in JPEG_SUFFIXES:
            spec.attribute("compression", f"jpeg:{JPEG_QUALITY}")
            spec.attribute("jpeg:subsampling", "4:4:4")  # full-resolution colour: a render's edges are sharp
        metadata.update(view.metadata())
        metadata.update(_describe_colour(spec, view, suffix))
        # A picture keeps Exif's own tags in its Exif block and only text besides: LensLab's values become text.
        metadata = {key: (_as_text(value) if key.startswith("lenslab:") else value) for key, value in metadata.items()
                    if key not in MATRIX_ATTRIBUTES}
        if suffix != ".png":
            metadata = _lenslab_values_in_description(metadata)
    for key, value in metadata.items():
        if key in MATRIX_ATTRIBUTES:
            spec.attribute(key, oiio.TypeDesc("matrix"), tuple(float(v) for v in np.asarray(value).reshape(-1)))
        else:
            spec.attribute(key, value if not isinstance(value, bool) else int(value))

    return write_pixels(path, pixels, spec, before_rename=before_rename)


#: Exif's ColorSpace: sRGB, or "uncalibrated" (any other, which the ICC profile then describes).
EXIF_SRGB, EXIF_UNCALIBRATED = 1, 0xFFFF


def _describe_colour(spec, view: ViewTransform, suffix: str) -> dict[str, object]:
    """Put in the picture's ``spec`` what says its display colour space, and return the metadata that names it.

    A space LensLab knows (colour_management/display_spaces.py) gets its ICC profile, in every picture format,
    and in a PNG its cICP chunk, which a PNG reader ranks above the profile. A space it does not know gets neither,
    since neither could be right. Every space's name is OpenImageIO's colour-space hint, from which it writes
    what older readers understand where it knows the name (PNG's sRGB or gAMA chunk, Exif's sRGB) and nothing
    where it does not (left without a hint, it would call the picture sRGB); lenslab:DisplayColourSpace keeps the
    name in the file, as OpenImageIO writes none of its ``oiio:`` hints."""
    import OpenImageIO as oiio

    name = view.display_colour_space()
    spec.attribute("oiio:ColorSpace", name)
    space: DisplaySpace | None = known_display_space(name, view.config)
    if space is not None and space.has_icc_profile:
        profile = display_profile(space)
        spec.attribute("ICCProfile", oiio.TypeDesc(f"uint8[{len(profile)}]"), profile)
    described: dict[str, object] = {"lenslab:DisplayColourSpace": name}
    if suffix == ".png":
        if space is not None and space.cicp is not None:
            spec.attribute("CICP", oiio.TypeDesc("int[4]"), space.cicp)
    else:  # a PNG says it in its own chunks (and OpenImageIO, reading Exif's sRGB there, ignores the cICP chunk)
        srgb = space is not None and space.interop_id == "srgb_rec709_display"
        # Also needed: OpenImageIO's TIFF writer fails on an Exif block left empty, as one without this would be.
        described["Exif:ColorSpace"] = EXIF_SRGB if srgb else EXIF_UNCALIBRATED
    return described


#: How a TIFF's or JPEG's ImageDescription holds LensLab's values: under this heading, a line each,
#: ``View : ACES 2.0 - SDR 100 nits (Rec.709)`` for lenslab:View.
DESCRIPTION_HEADING = "LensLab"
DESCRIPTION_LINE = re.compile(r"(\w+) : (.*)")


def _lenslab_values_in_description(metadata: dict[str, object]) -> dict[str, object]:
    """``metadata`` with LensLab's own values moved into the ImageDescription, before any description given:
    OpenImageIO's TIFF and JPEG writers drop metadata of names they do not know. The colons are spaced because
    OpenImageIO reads a JPEG comment as a ``key:value`` attribute unless the text before its first colon ends in
    white space, and would make one attribute of the whole text."""
    ours = {key: value for key, value in metadata.items() if key.startswith("lenslab:")}
    rest = {key: value for key, value in metadata.items() if key not in ours}
    lines = [f"{key.removeprefix('lenslab:')} : {' '.join(str(value).splitlines())}" for key, value in ours.items()]
    given = str(rest.get("ImageDescription", ""))
    rest["ImageDescription"] = "\n".join([DESCRIPTION_HEADING, *lines] + (["", given] if given else []))
    return rest


def _lenslab_values_from_description(description: str) -> dict[str, str]:
    """What _lenslab_values_in_description put in ``description`` (nothing if it is not there)."""
    lines = description.replace("\x00", "").splitlines()  # a JPEG comment may keep its C string's end
    if DESCRIPTION_HEADING not in lines:
        return {}
    values = {}
    for line in lines[lines.index(DESCRIPTION_HEADING) + 1:]:
        match = DESCRIPTION_LINE.fullmatch(line)
        if match is None:
            break
        values[f"lenslab:{match[1]}"] = match[2]
    return values


def write_pixels(path: str | os.PathLike, pixels: np.ndarray, spec, *,
                 before_rename: Callable[[], None] | None = None) -> Path:
    """Write ``pixels`` as the OpenImageIO ``spec`` describes them to ``path`` (its suffix names the format),
    whole or not at all: every failure the library reports is an ExportError naming ``path`` with the system's
    reason, and so is a file that was not written whole although no failure was reported."""
    path = Path(path)
    with atomic_path(path, before_rename=before_rename) as tmp:
        if path.suffix.lower() in JPEG_SUFFIXES:
            _make_room(tmp, path, pixels.nbytes + HEADER_ALLOWANCE_BYTES)
        _encode(tmp, path, pixels, spec)
        _check_whole(tmp, path, spec)
    return path


def _make_room(tmp: Path, path: Path, nbytes: int) -> None:
    """Take ``nbytes`` of disk for ``tmp`` before a writer that cannot report a failed write is let at it: libjpeg,
    as OpenImageIO sets it up, ends the whole process on one (its default error handler calls exit). The writer
    truncates the file and so gives the room back to itself; a disk that another process fills in between is
    not caught. ``nbytes``: the pixels as stored, more than a JPEG of them needs."""
    fd = os.open(tmp, os.O_WRONLY)
    try:
        if hasattr(os, "posix_fallocate"):  # not on macOS or Windows
            os.posix_fallocate(fd, 0, nbytes)
        else:
            chunk, written = bytes(1 << 16), 0
            while written < nbytes:
                written += os.write(fd, chunk)  # a short write is followed by one that fails, with the reason
    except OSError as exc:
        raise ExportError(f"{path}: cannot write the image ({exc.strerror or exc})") from None
    finally:
        os.close(fd)


def _encode(tmp: Path, path: Path, pixels: np.ndarray, spec) -> None:
    import OpenImageIO as oiio

    out = oiio.ImageOutput.create(str(tmp))
    if out is None:
        raise ExportError(f"{path}: cannot write ({oiio.geterror()})")
    if not out.open(str(tmp), spec):
        raise ExportError(f"{path}: cannot open for writing ({_reason(tmp, out.geterror())})")
    try:
        written = out.write_image(pixels)
    finally:
        closed = out.close()  # also when interrupted: the temporary file is removed next, and must be closed
    # A write that fails part-way may still return True, saying so only in the error text (PNG on a full disk).
    errors = out.geterror()
    if not (written and closed) or errors:
        raise ExportError(f"{path}: cannot write the image ({_reason(tmp, errors)})")


#: A PNG ends with its IEND chunk: no data, its type, and that type's CRC.
PNG_END = b"\x00\x00\x00\x00IEND\xaeB`\x82"
#: A JPEG ends with its EOI (end of image) marker.
JPEG_END = b"\xff\xd9"
#: The formats whose last bytes show them whole; the others are read back (see _incompleteness).
FILE_ENDS = {".png": PNG_END, ".jpg": JPEG_END, ".jpeg": JPEG_END}


def _check_whole(tmp: Path, path: Path, spec) -> None:
    """Read back what shows a file whole, where that is cheap: a library that buffers its last writes can lose
    them as the file closes and report nothing (a full disk left a small image at 0 bytes)."""
    problem = _incompleteness(tmp, spec)
    if problem is not None:
        raise ExportError(f"{path}: cannot write the image ({write_failure_reason(tmp) or problem})")


def _incompleteness(tmp: Path, spec) -> str | None:
    """Why the image file ``tmp`` is not whole, or None: its end is where the format puts it (a PNG's last chunk,
    a JPEG's end marker; an EXR's or a TIFF's last scanline, which OpenImageIO finds through the offsets the
    file keeps, and reads back, with a TIFF's profile)."""
    import OpenImageIO as oiio

    size = tmp.stat().st_size
    if size == 0:
        return "nothing reached the disk"
    end = FILE_ENDS.get(tmp.suffix.lower())
    if end is not None:
        with open(tmp, "rb") as file:
            file.seek(max(0, size - len(end)))
            return None if file.read() == end else "the file ends early"
    image = oiio.ImageInput.open(str(tmp))
    if image is None:
        return f"cannot read it back: {oiio.geterror()}"
    try:
        last = image.read_scanline(spec.y + spec.height - 1, 0, oiio.FLOAT)
        errors = image.geterror()
        profile = image.spec().getattribute("ICCProfile")
    finally:
        image.close()
    # A TIFF keeps its tags' data after its pixels, the ICC profile last: cut there, it reads without an error,
    # and without its profile.
    written = spec.getattribute("ICCProfile")
    profile_lost = written is not None and (profile is None or bytes(profile) != bytes(written))
    return None if last is not None and not errors and not profile_lost else "the file ends early"


def _reason(tmp: Path, library_errors: str) -> str:
    """The system's reason a write failed if it can say, else the library's first line."""
    lines = library_errors.strip().splitlines()
    return write_failure_reason(tmp) or (lines[0] if lines else "no reason given")


def _as_text(value: object) -> str:
    return f"{value:.9g}" if isinstance(value, float) else str(value)


def read_image(path: str | os.PathLike) -> tuple[np.ndarray, dict[str, object]]:
    """(pixels as float32 (H, W, C), metadata) of an image file; for tests and for resuming renders."""
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise ExportError(f"{path}: cannot read ({oiio.geterror()})")
    try:
        spec = image.spec()
        too_large = image_too_large(spec.width, spec.height, spec.nchannels)
        if too_large:
            raise ExportError(f"{path}: cannot read ({too_large})")
        pixels = image.read_image(format=oiio.FLOAT)
        errors = image.geterror()
        metadata = {attr.name: attr.value for attr in spec.extra_attribs}
    finally:
        image.close()
    # A TIFF's or JPEG's LensLab values, from its ImageDescription (see _lenslab_values_in_description).
    for key, value in _lenslab_values_from_description(str(metadata.get("ImageDescription", ""))).items():
        metadata.setdefault(key, value)
    if pixels is None or errors:  # a file cut short reads in part, and says so only in the error text
        raise ExportError(f"{path}: cannot read ({(errors.strip().splitlines() or ['no pixels'])[0]})")
    return np.asarray(pixels, dtype=np.float32), metadata
