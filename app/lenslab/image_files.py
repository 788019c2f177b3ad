"""Reading the pixels of an image file a scene names: a texture, an environment map, an aperture image, an
image inside a mesh file. One reader, so that every one of them refuses the same broken files alike.

OpenImageIO reads the file; what it does not do by itself is refuse. Its header is read first, and a file that
claims more pixels than can be decoded (a few-kilobyte PNG of 60000 x 60000, a decompression bomb) is refused
before it is decoded; and a file cut short reads in part, saying so only in an error text that, unless it is
fetched, OpenImageIO prints from C++ when the buffer is destroyed.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import threading

import numpy as np

from lenslab.limits import image_too_large

FLOAT_FORMATS = ("half", "float", "double")


def read_pixels(path: str | os.PathLike) -> tuple[np.ndarray, bool]:
    """(pixels as float32 (H, W, C), row 0 at the top, values as stored: 0..1 for 8 and 16-bit files;
    whether the file holds floating-point values). Raises OSError naming the file and why it cannot be read."""
    import OpenImageIO as oiio  # imported here: scenes without images never pay for it

    with _decoders_quiet():
        image = oiio.ImageBuf(str(path))
        if image.has_error or image.spec().width == 0:
            raise OSError(f"{path}: cannot read the image ({_first_line(image.geterror()) or 'unknown format'})")
        spec = image.spec()
        too_large = image_too_large(spec.width, spec.height, spec.nchannels)
        if too_large:
            raise OSError(f"{path}: cannot read the image ({too_large})")
        pixels = image.get_pixels(oiio.FLOAT)
        if image.has_error or pixels is None:
            raise OSError(f"{path}: cannot read the image ({_first_line(image.geterror()) or 'no pixels'})")
    pixels = np.asarray(pixels, dtype=np.float32)
    return (pixels[..., None] if pixels.ndim == 2 else pixels), str(spec.format) in FLOAT_FORMATS


_quiet_lock = threading.Lock()


@contextlib.contextmanager
def _decoders_quiet():
    """Keep what the format libraries print from C onto the process's stderr ("libpng error: Invalid IHDR
    data") off it: OpenImageIO reports the same problem in its error text, which the caller puts into one line.
    File descriptor 2 is the process's, so threads take turns; a terminal's spinner misses a frame at most."""
    with _quiet_lock, tempfile.TemporaryFile() as swallowed, c_stderr_into(swallowed):
        yield


@contextlib.contextmanager
def c_stderr_into(file):
    """File descriptor 2, where C and C++ libraries print, written into ``file`` (an open file) for the block."""
    if sys.stderr is not None:
        sys.stderr.flush()
    saved = os.dup(2)
    os.dup2(file.fileno(), 2)
    try:
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _first_line(text: str) -> str:
    lines = text.strip().splitlines()
    return lines[0] if lines else ""
