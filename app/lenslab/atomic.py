"""Writing files whole or not at all: write beside the target under a temporary name, then rename.

A rename within one folder is atomic on POSIX and Windows, so a crash, a full disk or Ctrl-C mid-write
leaves either the old file or the new one, never half of one. Three things make that hold in practice:

- **Nothing is renamed that was not written whole.** The writer checks its own writes (an image writer must
  check what its library reports, see render/film.py); the temporary file is then flushed to the disk
  (``fsync``), which is where a disk that filled under delayed allocation, or a network file system, reports
  the failure of writes that seemed to succeed. Only then is it renamed into place.
- **A temporary file is short-named and recognisably ours**: ``.lenslab-<pid>-<host>-<random>.tmp<suffix>``,
  whatever the target is called (a 254-byte name stays a legal name), ending in the target's own suffix,
  since image libraries choose the format by it.
- **What a killed writer leaves is swept up.** SIGKILL and power cuts run no clean-up, so each write first
  removes our own temporaries in its folder whose writer is gone: a process of this machine that no longer
  exists (or this process's number, reused, as a container's processes reuse theirs, for a file this process is
  not writing), or anything older than STALE_AFTER_SECONDS (a writer on another machine of a shared folder,
  whose process we cannot ask after). Nothing that is not named as ours is ever touched.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import shutil
import socket
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator

from lenslab.image_files import not_a_file
from lenslab.limits import format_bytes

TEMPORARY_PREFIX = ".lenslab-"
#: A temporary file older than this has lost its writer, wherever that ran: no image or scene takes hours to write.
STALE_AFTER_SECONDS = 6 * 3600
#: The target's suffix is kept on the temporary name up to this length (a format is named in a few letters).
LONGEST_KEPT_SUFFIX = 16
#: ``.lenslab-<pid>-<host>-<random>.tmp<suffix>``: the random part is tempfile.mkstemp's.
TEMPORARY_NAME = re.compile(r"\.lenslab-(?P<pid>[0-9]+)-(?P<host>[0-9a-f]{6})-[a-z0-9_]+\.tmp(\.[A-Za-z0-9]{1,%d})?"
                            % LONGEST_KEPT_SUFFIX)

_writing: set[str] = set()  # the temporary files this process is writing now (in any thread)


class WriteFailed(OSError):
    """A file that could not be written, named as the user asked for it (never our temporary name), with the
    system's reason; ``errno`` is kept for callers that tell a full disk from a locked folder."""

    def __init__(self, path: str | os.PathLike, reason: str, errno: int | None = None):
        super().__init__(f"{path}: {reason}")
        self.errno = errno


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _host_tag() -> str:
    """Six hex digits for this machine: a shared folder's temporaries tell whose process table to ask."""
    return hashlib.blake2b(socket.gethostname().encode(), digest_size=3).hexdigest()


def _kept_suffix(path: Path) -> str:
    suffix = path.suffix
    return suffix if 1 < len(suffix) <= LONGEST_KEPT_SUFFIX + 1 and suffix[1:].isalnum() and suffix.isascii() else ""


def _create_temporary(path: Path) -> Path:
    try:
        fd, name = tempfile.mkstemp(prefix=f"{TEMPORARY_PREFIX}{os.getpid()}-{_host_tag()}-",
                                    suffix=f".tmp{_kept_suffix(path)}", dir=path.parent)
    except OSError as exc:  # name the file the user asked for, not our temporary one
        raise WriteFailed(path, f"cannot write in {path.parent} ({exc.strerror or exc})", exc.errno) from None
    os.close(fd)
    return Path(name)


def check_output_file(path: str | os.PathLike) -> None:
    """Raise WriteFailed, naming ``path``, where something other than a regular file is there (links followed):
    a named pipe, a device node, a socket, a folder. The rename that puts a finished file in place would replace
    it (a FIFO a reader waits on, /dev/null ...): a write goes where nothing is, or over a regular file only."""
    other = not_a_file(path)
    if other is not None:
        raise WriteFailed(path, f"{other}: LensLab writes only where no file is or over a regular file "
                                "(name another output)")


def check_output_folder(path: str | os.PathLike, estimated_bytes: int = 0) -> None:
    """Raise WriteFailed, naming ``path`` and the problem in one line, if ``path`` cannot be written now: its folder
    is missing or a file, refuses a new file, or has less free space than ``estimated_bytes``; or something other
    than a regular file is at ``path`` (check_output_file: a named pipe, a device node). For a caller about
    to spend minutes making the file (a render), so that it fails before the work, not after.

    The folder is asked by doing what the writer will do: a temporary file of ours is made there and removed
    (permission bits say nothing for root, nor for a read-only mount, an ACL or a full inode table)."""
    path = Path(path)
    check_output_file(path)
    folder = path.parent
    if folder.exists() and not folder.is_dir():
        raise WriteFailed(path, f"{folder} is a file, not a folder")
    if not folder.is_dir():
        raise WriteFailed(path, f"the folder {folder} does not exist")
    _discard(_create_temporary(path))
    if estimated_bytes > 0:
        try:
            free = shutil.disk_usage(folder).free
        except OSError:  # a file system that will not say: the write itself will tell
            return
        if free < estimated_bytes:
            raise WriteFailed(path, f"not enough space in {folder}: the file needs about "
                                    f"{format_bytes(estimated_bytes)}, {format_bytes(free)} is free")


def _process_alive(pid: int) -> bool:
    """Whether process ``pid`` of this machine exists (when in doubt: yes, and the file waits for its age)."""
    if os.name == "nt" or pid <= 0:  # Windows' os.kill would end the process, not ask after it
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # EPERM: it exists, as another user's
        return True
    return True


def _is_stale(name: str, modified: float, now: float) -> bool:
    match = TEMPORARY_NAME.fullmatch(name)
    if match is None:
        return False  # not ours
    if now - modified > STALE_AFTER_SECONDS:
        return True
    if match["host"] != _host_tag():
        return False
    pid = int(match["pid"])
    if pid == os.getpid():
        return name not in _writing
    return not _process_alive(pid)


def remove_stale_temporaries(folder: str | os.PathLike) -> list[Path]:
    """Remove the temporary files of our writers that were killed mid-write in ``folder`` (not below it);
    the paths removed. Best effort: a folder we may not list or a file we may not remove is left as it is."""
    removed = []
    now = time.time()
    try:
        with os.scandir(folder) as entries:
            candidates = [entry for entry in entries if entry.name.startswith(TEMPORARY_PREFIX)]
    except OSError:
        return removed
    for entry in candidates:
        try:
            if not entry.is_file(follow_symlinks=False):
                continue
            if _is_stale(entry.name, entry.stat(follow_symlinks=False).st_mtime, now):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:  # gone meanwhile (another writer swept it), or not ours to remove
            continue
    return removed


def _flush_to_disk(path: Path) -> None:
    """fsync: the disk's last word on writes it accepted into memory (a full disk, a lost NFS server)."""
    fd = os.open(path, os.O_RDWR)  # Windows' fsync needs a handle open for writing
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _flush_folder(folder: Path) -> None:
    """Make the rename itself durable; not every system can open a folder (Windows) or sync one, and the file is
    already in place, so a refusal here is not a failure."""
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def write_failure_reason(path: str | os.PathLike, probe_bytes: int = 1 << 20) -> str | None:
    """The system's reason that writing to ``path`` fails now ("No space left on device", "Disk quota exceeded",
    "File too large"), or None if a write of ``probe_bytes`` succeeds.

    Found by appending to the file, so only for a file about to be discarded (a temporary one that failed): an
    image library reports a failed write without the system's reason, or, when only its last buffered write
    fails as the file closes, not at all."""
    chunk = bytes(min(probe_bytes, 1 << 16))
    try:
        fd = os.open(path, os.O_WRONLY | os.O_APPEND)
    except OSError:  # no file to ask with: the reason is unknown, not this
        return None
    try:
        written = 0
        while written < probe_bytes:
            written += os.write(fd, chunk)  # a short write is followed by one that fails, with the reason
    except OSError as exc:
        return exc.strerror or str(exc)
    finally:
        os.close(fd)
    return None


def _discard(tmp: Path) -> None:
    with contextlib.suppress(OSError):  # the failure to report is the write's, not this
        tmp.unlink(missing_ok=True)


def _naming_target(exc: OSError, path: Path) -> OSError:
    """``exc`` as a failure to write ``path``: the system's reason, and the user's file name in place of ours."""
    if isinstance(exc, WriteFailed) or str(path) in str(exc):
        return exc
    return WriteFailed(path, f"cannot write ({exc.strerror or exc})", exc.errno)


@contextmanager
def atomic_path(path: str | os.PathLike, *, before_rename: Callable[[], None] | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` for the caller to write and close; on success the temporary file is
    flushed to the disk and replaces ``path``, with the permissions a newly created file would have. On any
    failure or interrupt the temporary file is removed and ``path`` is left as it was; an OSError names ``path``.

    ``before_rename()`` is called once the file is whole and flushed, just before the rename: from there nothing
    can stop the write but the rename failing. The command line ignores its stop signals there, so a Ctrl-C that
    comes as the file appears cannot be reported as "nothing was written"."""
    path = Path(path)
    check_output_file(path)  # never renamed over a named pipe or a device node
    remove_stale_temporaries(path.parent)
    tmp = _create_temporary(path)
    _writing.add(tmp.name)
    try:
        yield tmp
        _flush_to_disk(tmp)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; a saved scene or image is for sharing
        if before_rename is not None:
            before_rename()
        os.replace(tmp, path)
    except OSError as exc:
        _discard(tmp)
        raise _naming_target(exc, path) from None
    except BaseException:
        _discard(tmp)
        raise
    finally:
        _writing.discard(tmp.name)
    _flush_folder(path.parent)
