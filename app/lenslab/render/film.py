"""From accumulated samples to pictures: the linear image, display tone mapping, and export.

EXR holds the linear radiance as float32 RGB with the camera's settings as metadata (standard Exif names
where they exist); PNG holds a display-referred 8-bit sRGB picture. Files are written to a temporary name
beside the target and renamed into place, so an export is whole or absent, never half-written.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from lenslab.atomic import atomic_path
from lenslab.color import linear_to_srgb

EXPORT_SUFFIXES = (".exr", ".png")
TONE_MAPS = ("clamp", "reinhard", "filmic")


class ExportError(RuntimeError):
    pass


def check_tone_map(operator: str) -> str:
    """``operator`` if it is one of TONE_MAPS; otherwise a ValueError that names it and the choices."""
    if operator not in TONE_MAPS:
        raise ValueError(f"unknown tone map '{operator}' (choose from {', '.join(TONE_MAPS)})")
    return operator


def resolve(accumulation: np.ndarray) -> np.ndarray:
    """Radiance per pixel from (weighted sum rgb, weight); pixels with no samples yet are black. The weight is
    the sample count, or with a splatted gaussian filter the expected sum of filter weights (render/tracer.py)."""
    weight = accumulation[..., 3:4]
    image = np.zeros(accumulation.shape[:-1] + (3,), np.float32)
    np.divide(accumulation[..., :3], weight, out=image, where=weight > 0)
    return image


def merge(*accumulations: np.ndarray) -> np.ndarray:
    """Combine partial renders of the same view (different seeds, or disjoint sample ranges of one seed: the
    parts of a shot split across workers, lenslab.batch.parts): sums and counts add."""
    return np.sum(accumulations, axis=0)


def _filmic(x: np.ndarray) -> np.ndarray:
    # Narkowicz's fit of the ACES reference rendering transform: a gentle shoulder that keeps highlights.
    a, b, c, d, e = 2.51, 0.03, 2.43, 0.59, 0.14
    return np.clip((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0)


def tone_map(linear: np.ndarray, exposure_stops: float = 0.0, operator: str = "clamp") -> np.ndarray:
    """Display-referred sRGB in [0, 1] from linear radiance. ``exposure_stops`` scales by 2**stops first."""
    check_tone_map(operator)
    x = np.maximum(linear, 0.0) * np.float32(2.0**exposure_stops)
    if operator == "reinhard":
        x = x / (1.0 + x)
    elif operator == "filmic":
        x = _filmic(x)
    return linear_to_srgb(x).astype(np.float32)


def to_8bit(display: np.ndarray) -> np.ndarray:
    return np.clip(np.round(display * 255.0), 0, 255).astype(np.uint8)


#: The primaries and white point of LensLab's linear RGB (Rec. 709 / sRGB, D65), as OpenEXR's chromaticities.
REC709_CHROMATICITIES = (0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290)
#: Metadata that OpenImageIO must be told is a 4 x 4 matrix (OpenEXR's worldToCamera and worldToNDC).
MATRIX_ATTRIBUTES = ("worldtocamera", "worldtoNDC")


def write_image(path: str | os.PathLike, linear: np.ndarray, metadata: dict[str, object] | None = None,
                *, sensor_exposure: float = 1.0, exposure_stops: float = 0.0, tone_map_operator: str = "clamp") -> Path:
    """Write ``linear`` (H, W, 3) to an .exr (linear float) or .png (sRGB, tone mapped), atomically.

    ``sensor_exposure`` multiplies the radiance first, in both: the camera's physical exposure, part of the
    capture. ``exposure_stops`` and the tone map are the PNG's display look. An EXR carries Rec. 709
    chromaticities and the camera matrices; a PNG carries Exif (its eXIf chunk: f-number, exposure time, ISO,
    focal length) and LensLab's own values as text chunks."""
    import OpenImageIO as oiio  # imported here: only exporting needs it

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in EXPORT_SUFFIXES:
        raise ExportError(f"{path}: unsupported output type '{path.suffix}' (use .exr or .png)")
    if not path.parent.is_dir():
        raise ExportError(f"{path}: folder {path.parent} does not exist")
    height, width = linear.shape[:2]
    linear = linear[..., :3] * np.float32(sensor_exposure) if sensor_exposure != 1.0 else linear[..., :3]
    metadata = dict(metadata or {})
    if suffix == ".exr":
        pixels = np.ascontiguousarray(linear, dtype=np.float32)
        spec = oiio.ImageSpec(width, height, 3, oiio.FLOAT)
        spec.attribute("compression", "zip")
        spec.attribute("chromaticities", oiio.TypeDesc("float[8]"), REC709_CHROMATICITIES)
    else:
        pixels = to_8bit(tone_map(linear, exposure_stops, tone_map_operator))
        spec = oiio.ImageSpec(width, height, 3, oiio.UINT8)
        spec.attribute("oiio:ColorSpace", "sRGB")
        metadata.update({"lenslab:DisplayExposureStops": float(exposure_stops), "lenslab:ToneMap": tone_map_operator})
        # PNG keeps Exif's own tags in its eXIf chunk and only text besides: LensLab's values become text.
        metadata = {key: (_as_text(value) if key.startswith("lenslab:") else value) for key, value in metadata.items()
                    if key not in MATRIX_ATTRIBUTES}
    for key, value in metadata.items():
        if key in MATRIX_ATTRIBUTES:
            spec.attribute(key, oiio.TypeDesc("matrix"), tuple(float(v) for v in np.asarray(value).reshape(-1)))
        else:
            spec.attribute(key, value if not isinstance(value, bool) else int(value))

    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None or not out.open(str(tmp), spec):
            raise ExportError(f"{path}: cannot open for writing ({oiio.geterror() or (out and out.geterror())})")
        ok = out.write_image(pixels)
        error = out.geterror()
        out.close()
        if not ok:
            raise ExportError(f"{path}: write failed ({error})")
    return path


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
        pixels = image.read_image(format=oiio.FLOAT)
        metadata = {attr.name: attr.value for attr in spec.extra_attribs}
    finally:
        image.close()
    return np.asarray(pixels, dtype=np.float32), metadata
