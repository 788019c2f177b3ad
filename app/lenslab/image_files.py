"""Reading the files a user names, and the pixels of an image file a scene names: a texture, an environment map,
an aperture image, an image inside a mesh file. One reader, so that every one of them refuses the same broken
files alike.

Every reader of a file a user named (a scene, an include, a mesh, an MTL library, a glTF buffer, a batch file,
an image) opens it through :func:`open_file` or :func:`read_file_bytes`, or, where a library opens it by name
(OpenImageIO, trimesh), asks :func:`check_regular_file` first: a named pipe blocks a reader until something
writes to it (for ever), a device such as /dev/zero never ends and a folder has no bytes, so anything but a
regular file is refused up front with :class:`NotARegularFile`, naming it and saying what it is.

OpenImageIO reads the file; what it does not do by itself is refuse. Its header is read first, and a file that
claims more pixels than can be decoded (a few-kilobyte PNG of 60000 x 60000, a decompression bomb) is refused
before it is decoded; and a file cut short reads in part, saying so only in an error text that, unless it is
fetched, OpenImageIO prints from C++ when the buffer is destroyed.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import sys
import tempfile
import threading

import numpy as np

from lenslab.limits import image_too_large

FLOAT_FORMATS = ("half", "float", "double")


class NotARegularFile(OSError):
    """A path given to a reader that names a named pipe, a device, a socket or a folder, not a regular file.
    ``filename`` is the path and ``strerror`` what it is ("a named pipe (FIFO), not a regular file"), so the
    readers' ``f"{path}: cannot read ({exc.strerror})"`` and messages.describe_os_error say it in one line."""

    def __init__(self, path: str | os.PathLike, kind: str):
        super().__init__(errno.EINVAL, f"{kind}, not a regular file", os.fspath(path))

    def __str__(self) -> str:
        return f"{self.filename}: {self.strerror}"


_NOT_REGULAR = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a named pipe (FIFO)"),
                (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _kind(mode: int) -> str:
    return next((kind for test, kind in _NOT_REGULAR if test(mode)), "not a file")


def _other_kind_at(path: str | os.PathLike) -> str | None:
    """What is at ``path`` ("a named pipe (FIFO)") when it exists and is anything but a regular file (links
    followed); None for a regular file, or a path that does not exist or cannot be asked after (missing, no
    access, a name too long, a NUL in it): the reader's own error says so, as it always has."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None
    return None if stat.S_ISREG(mode) else _kind(mode)


def check_regular_file(path: str | os.PathLike) -> None:
    """Raise NotARegularFile where ``path`` exists and is anything but a regular file, before a library opens it
    by name."""
    kind = _other_kind_at(path)
    if kind is not None:
        raise NotARegularFile(path, kind)


def not_a_file(path: str | os.PathLike) -> str | None:
    """What is at ``path`` when it is something other than a regular file ("a named pipe (FIFO), not a regular
    file"); None where it is a regular file or nothing at all."""
    kind = _other_kind_at(path)
    return None if kind is None else f"{kind}, not a regular file"


def not_found(what: str, path: str | os.PathLike) -> str:
    """What to say of a file a reader was given that is not a regular file: "<what> not found: <path>", or where
    something else is at the path, "<what> <path> is a named pipe (FIFO), not a regular file"."""
    other = not_a_file(path)
    return f"{what} not found: {path}" if other is None else f"{what} {path} is {other}"


def open_file(path: str | os.PathLike):
    """The regular file at ``path`` open for reading in binary; NotARegularFile for anything else, found without
    waiting (a named pipe is opened without blocking, and asked what it is before a byte is read); other
    OSErrors as ``open`` raises them."""
    check_regular_file(path)  # a device is refused before it is even opened
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    try:
        mode = os.fstat(fd).st_mode  # what was opened: it may have been replaced since it was asked after
        if not stat.S_ISREG(mode):
            raise NotARegularFile(path, _kind(mode))
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_file_bytes(path: str | os.PathLike) -> bytes:
    """The whole of the regular file at ``path`` (see :func:`open_file`)."""
    with open_file(path) as file:
        return file.read()


def read_pixels(path: str | os.PathLike) -> tuple[np.ndarray, bool]:
    """(pixels as float32 (H, W, C), row 0 at the top, values as stored: 0..1 for 8 and 16-bit files;
    whether the file holds floating-point values). Raises OSError naming the file and why it cannot be read."""
    import OpenImageIO as oiio  # imported here: scenes without images never pay for it

    try:
        check_regular_file(path)  # OpenImageIO would wait for ever on a named pipe
    except NotARegularFile as exc:
        raise OSError(f"{path}: cannot read the image ({exc.strerror})") from None
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


def holds_floats(path: str | os.PathLike) -> bool | None:
    """Whether the image file holds floating-point values (EXR, HDR) rather than 8 or 16-bit integers, from its
    header alone; None when it cannot be read."""
    import OpenImageIO as oiio

    try:
        check_regular_file(path)
    except NotARegularFile:
        return None
    with _decoders_quiet():
        image = oiio.ImageInput.open(str(path))
        if image is None:
            oiio.geterror()  # cleared, so that it is not reported with a later, unrelated error
            return None
        try:
            return str(image.spec().format) in FLOAT_FORMATS
        finally:
            image.close()


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
