"""What this machine and its GL device can hold, and the one error for a scene or an image that does not fit.

A small file can ask for a great deal of work: ten coplanar disks of 4,096 segments once drove the
kd-tree build to 7.5 GB, and a 16384 x 16384 image asks for 4 GiB of accumulation buffer. The builders and
the render session work out what they need *before* allocating it and compare it with what is here, so the
user gets one line naming what is too big rather than a crash deep inside numpy or the GL driver.
"""

from __future__ import annotations

import math
import os
import resource


#: The largest magnitude any number of a scene may have (a coordinate, a colour, a setting): past it a number
#: measures nothing, and float32 on the GPU would make it infinite or swallow every smaller one.
LARGEST_NUMBER = 1e30


def number_problem(value: float) -> str | None:
    """Why a number read from a file cannot be a scene's, in the words every reader uses ("nan is not a finite
    number", "1e+308 is too large (the most any value may be is 1e+30)"); None where it can be. The one bound
    for every format: native JSON, Mitsuba XML, MTL and glTF values alike."""
    if isinstance(value, float) and not math.isfinite(value):
        return f"{value} is not a finite number"
    if abs(value) > LARGEST_NUMBER:  # exact for an integer of any length: no conversion to float can overflow
        shown = f"a {len(str(abs(value)))}-digit number" if isinstance(value, int) else f"{value:g}"
        return f"{shown} is too large (the most any value may be is {LARGEST_NUMBER:g})"
    return None


class SceneTooLarge(RuntimeError):
    """The scene or the image needs more than this machine or GL device can hold: a storage buffer beyond
    the device's limit, a kd-tree build beyond the memory available, accumulation buffers beyond either."""


def format_bytes(nbytes: float) -> str:
    """A size as a person reads it: KiB, MiB or GiB, one decimal from MiB up."""
    if nbytes >= 2**30:
        return f"{nbytes / 2**30:.1f} GiB"
    if nbytes >= 2**20:
        return f"{nbytes / 2**20:.1f} MiB"
    return f"{nbytes / 2**10:.0f} KiB"


def available_memory_bytes() -> int | None:
    """Bytes this process may still allocate, as far as the system says: the kernel's estimate of memory
    available without swapping, within a cgroup's limit and the address-space limit (``ulimit -v``) where
    those are set. None where none of them can be read (not Linux)."""
    known = [n for n in (_mem_available(), _cgroup_room(), _address_space_room()) if n is not None]
    return min(known) if known else None


def _mem_available() -> int | None:
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _cgroup_room() -> int | None:
    """What a cgroup v2 memory limit (a container's) leaves: memory.max less memory.current."""
    try:
        with open("/sys/fs/cgroup/memory.max", encoding="ascii") as limit_file:
            limit = limit_file.read().strip()
        if limit == "max":
            return None
        with open("/sys/fs/cgroup/memory.current", encoding="ascii") as current_file:
            return max(0, int(limit) - int(current_file.read()))
    except (OSError, ValueError):
        return None


def _address_space_room() -> int | None:
    """What ``ulimit -v`` leaves: the limit less the address space already mapped (/proc/self/status VmSize)."""
    soft, _hard = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY:
        return None
    try:
        with open(f"/proc/{os.getpid()}/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmSize:"):
                    return max(0, soft - int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    return None


#: The most pixels an image file may hold to be read at all (a 16K x 8K panorama): its header is read first,
#: so a PNG of a few kilobytes that claims 60000 x 60000 pixels (a decompression bomb) is refused before it
#: is decoded into gigabytes.
MAX_SOURCE_PIXELS = 16384 * 8192


def image_too_large(width: int, height: int, channels: int) -> str | None:
    """Why an image file of this size is not to be read (None: it may be), from its header alone: more pixels
    than MAX_SOURCE_PIXELS, or more than the memory available can decode (as float, with a copy to spare)."""
    if width * height > MAX_SOURCE_PIXELS:
        return f"{width} x {height} pixels, more than the {MAX_SOURCE_PIXELS:,} LensLab reads"
    needed = 2 * width * height * max(channels, 1) * 4
    memory = available_memory_bytes()
    if memory is not None and needed > memory:
        return f"{width} x {height} pixels need {format_bytes(needed)} to read, more than the {format_bytes(memory)} available"
    return None
