"""A contact sheet: every shot of a batch on one page, its settings printed under it, as a photographer lays
out a bracket to compare. Drawn with OpenImageIO (resizing, and text in the Droid fonts its wheel ships)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from lenslab.colour_management.view import METADATA, ViewTransform
from lenslab.optics import format_camera_settings
from lenslab.render import film

BACKGROUND = (0.11, 0.11, 0.12)  # display values: a dark neutral that neither glows nor flattens the shots
TITLE_COLOUR = (0.93, 0.93, 0.93)
CAPTION_COLOUR = (0.68, 0.68, 0.70)
MISSING_COLOUR = (0.20, 0.20, 0.21)
TITLE_FONT, CAPTION_FONT = "DroidSans-Bold", "DroidSans"
TITLE_SIZE, CAPTION_SIZE = 15, 13
MARGIN = 16  # pixels around and between cells
SHEET_ASPECT = 1.5  # the grid is chosen to make the page about 3:2


@dataclass(frozen=True)
class Frame:
    """One cell of the sheet: an image (None: it was not rendered) and the two lines under it."""

    image: Path | None
    title: str
    caption: str
    view: ViewTransform = ViewTransform()  # how an EXR (scene-linear) is shown; a picture is shown as it is


def shot_caption(camera, lens_name: str | None = None) -> str:
    """50 mm · f/2.8 · focus 1.50 m (· the lens): the settings a photographer compares, as the studio shows them."""
    settings = format_camera_settings(camera.focal_length_mm, camera.f_number, camera.focus_distance_m)
    return f"{settings} \u00b7 {lens_name}" if lens_name else settings


def write_contact_sheet(path: str | Path, frames: list[Frame], *, thumbnail_width: int = 320) -> Path:
    """Lay ``frames`` out in a grid of thumbnails ``thumbnail_width`` pixels wide and write a PNG, whole or not
    at all. A frame whose image is missing or unreadable is drawn as an empty box with its title."""
    import OpenImageIO as oiio

    if not frames:
        raise ValueError("a contact sheet needs at least one frame")
    thumbnails = [_thumbnail(frame, thumbnail_width) for frame in frames]
    cell_w = thumbnail_width
    image_h = max((t.shape[0] for t in thumbnails if t is not None), default=round(thumbnail_width * 2 / 3))
    cell_h = image_h + 8 + TITLE_SIZE + 6 + CAPTION_SIZE + 4
    columns = _columns(len(frames), cell_w + MARGIN, cell_h + MARGIN)
    rows = math.ceil(len(frames) / columns)
    width, height = MARGIN + columns * (cell_w + MARGIN), MARGIN + rows * (cell_h + MARGIN)
    sheet = np.empty((height, width, 3), np.float32)
    sheet[:] = BACKGROUND
    origins = []
    for index, thumbnail in enumerate(thumbnails):
        row, column = divmod(index, columns)
        x, y = MARGIN + column * (cell_w + MARGIN), MARGIN + row * (cell_h + MARGIN)
        origins.append((x, y))
        if thumbnail is None:
            sheet[y:y + image_h, x:x + cell_w] = MISSING_COLOUR
        else:  # centred in its cell where it is narrower or shorter than the others
            h, w = thumbnail.shape[:2]
            top, left = y + (image_h - h) // 2, x + (cell_w - w) // 2
            sheet[top:top + h, left:left + w] = thumbnail
    buffer = oiio.ImageBuf(np.ascontiguousarray(sheet))
    for frame, (x, y), thumbnail in zip(frames, origins, thumbnails):
        if thumbnail is None:
            _text(buffer, x + cell_w // 2, y + image_h // 2, "not rendered", CAPTION_SIZE, CAPTION_FONT,
                  CAPTION_COLOUR, cell_w, centred=True)
        baseline = y + image_h + 8 + TITLE_SIZE
        _text(buffer, x, baseline, frame.title, TITLE_SIZE, TITLE_FONT, TITLE_COLOUR, cell_w)
        _text(buffer, x, baseline + 6 + CAPTION_SIZE, frame.caption, CAPTION_SIZE, CAPTION_FONT, CAPTION_COLOUR,
              cell_w)
    pixels = film.to_8bit(buffer.get_pixels(oiio.FLOAT))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    spec = oiio.ImageSpec(width, height, 3, oiio.UINT8)
    spec.attribute("oiio:ColorSpace", "sRGB")
    return film.write_pixels(path, pixels, spec)


def _columns(count: int, cell_w: int, cell_h: int) -> int:
    """The number of columns that makes the page's shape nearest SHEET_ASPECT (ties: fewer rows)."""
    def misfit(columns: int) -> float:
        rows = math.ceil(count / columns)
        return abs(math.log((columns * cell_w) / (rows * cell_h) / SHEET_ASPECT))

    return min(range(1, count + 1), key=lambda c: (misfit(c), -c))


def _thumbnail(frame: Frame, width: int) -> np.ndarray | None:
    """The frame's image as display values (H, W, 3), ``width`` wide; None if it cannot be read."""
    import OpenImageIO as oiio

    if frame.image is None or not frame.image.exists():
        return None
    try:
        pixels, metadata = film.read_image(frame.image)
    except film.ExportError:
        return None
    pixels = pixels[..., :3] if pixels.shape[2] >= 3 else np.repeat(pixels[..., :1], 3, axis=2)
    height = max(1, round(pixels.shape[0] * width / pixels.shape[1]))
    source = oiio.ImageBuf(np.ascontiguousarray(pixels, dtype=np.float32))
    resized = oiio.ImageBufAlgo.resize(source, roi=oiio.ROI(0, width, 0, height, 0, 1, 0, 3))
    small = resized.get_pixels(oiio.FLOAT).reshape(height, width, 3)
    if frame.image.suffix.lower() == ".exr":  # scene-linear (resized as light adds up): through the view transform
        space = str(metadata.get(METADATA["working_space"], frame.view.working_space))
        return film.display_pixels(small, replace(frame.view, working_space=space))
    return np.clip(small, 0.0, 1.0)


def _text(buffer, x: int, y: int, text: str, size: int, font: str, colour, max_width: int,
          centred: bool = False) -> None:
    """Draw one line, shortened with an ellipsis to fit ``max_width``."""
    import OpenImageIO as oiio

    def width_of(s: str) -> int:
        roi = oiio.ImageBufAlgo.text_size(s, size, font)
        return roi.width if roi.defined else len(s) * size // 2

    if width_of(text) > max_width:
        while len(text) > 1 and width_of(text + "...") > max_width:
            text = text[:-1]
        text += "..."
    oiio.ImageBufAlgo.render_text(buffer, x, y, text, size, font, colour, "center" if centred else "left")
