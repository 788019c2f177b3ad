"""Finding a Mitsuba 3 that works: the package (the ``validate`` extra) and an LLVM its JIT accepts.

On Debian 12 the system's only libLLVM is Mesa's LLVM 15, on which Dr.Jit's JIT aborts; with
``apt-get install libllvm19`` and ``DRJIT_LIBLLVM_PATH`` pointing at it, the ``llvm_ad_rgb`` variant works.
We set that variable ourselves when it is unset and the library is there. On a machine with an NVIDIA GPU,
``LENSLAB_MITSUBA_VARIANT=cuda_ad_rgb`` compares against Mitsuba on the same GPU (benchmarks/vs_mitsuba.py).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

VARIANT = os.environ.get("LENSLAB_MITSUBA_VARIANT", "llvm_ad_rgb")
LLVM19 = Path("/lib/x86_64-linux-gnu/libLLVM.so.19.1")
MISSING_MITSUBA = "Mitsuba 3 is not installed: pip install 'lenslab[validate]'"
NO_LLVM = ("Mitsuba 3 found no usable LLVM for its JIT ({detail}): install LLVM 19 (apt-get install libllvm19) "
           "or set DRJIT_LIBLLVM_PATH to a libLLVM.so of version 11 or later")
NO_CUDA = ("Mitsuba 3's {variant} variant cannot render here ({detail}): it needs an NVIDIA GPU and its driver; "
           "unset LENSLAB_MITSUBA_VARIANT to compare against llvm_ad_rgb on the CPU")


def unavailable_message(detail: str, variant: str | None = None) -> str:
    """Why Mitsuba's chosen variant cannot render, and what to do about it."""
    variant = variant or VARIANT
    if variant.startswith("cuda"):
        return NO_CUDA.format(variant=variant, detail=detail)
    return NO_LLVM.format(detail=detail)


class MitsubaUnavailable(RuntimeError):
    """Mitsuba cannot render here; the message is one line saying how to fix it."""


def prepare_environment(environ=os.environ, llvm19: Path = LLVM19) -> None:
    """Point Dr.Jit at LLVM 19 when nobody chose a library and it is installed (must precede the import)."""
    if not environ.get("DRJIT_LIBLLVM_PATH") and llvm19.exists():
        environ["DRJIT_LIBLLVM_PATH"] = str(llvm19)


PROBE = (f"import mitsuba as mi; mi.set_variant('{VARIANT}'); " "mi.render(mi.load_dict({'type': 'scene', "
         "'integrator': {'type': 'path'}, 'light': {'type': 'constant'}, 'sensor': {'type': 'perspective', "
         "'film': {'type': 'hdrfilm', 'width': 4, 'height': 4}}}), spp=1)")

_mitsuba = None


def _probe_jit() -> str | None:
    """Render 4 x 4 pixels in a child process: with an LLVM it cannot use, Dr.Jit's JIT aborts the whole
    process (no exception to catch), so find that out before this process depends on it. None: it works."""
    try:
        result = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return str(exc)
    if result.returncode == 0:
        return None
    lines = [line for line in result.stderr.strip().splitlines() if line.strip()]
    return f"a test render failed with status {result.returncode}" + (f": {lines[-1][:160]}" if lines else "")


def load_mitsuba():
    """The ``mitsuba`` module with its RGB variant set (LLVM unless chosen otherwise), or :class:`MitsubaUnavailable`."""
    global _mitsuba
    if _mitsuba is not None:
        return _mitsuba
    prepare_environment()
    try:
        import mitsuba as mi
    except ImportError:
        raise MitsubaUnavailable(MISSING_MITSUBA) from None
    try:
        mi.set_variant(VARIANT)
    except Exception as exc:  # ImportError or Dr.Jit's RuntimeError when libLLVM cannot be loaded
        detail = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise MitsubaUnavailable(unavailable_message(detail)) from None
    problem = _probe_jit()
    if problem:
        raise MitsubaUnavailable(unavailable_message(problem))
    _mitsuba = mi
    return mi


def mitsuba_works() -> tuple[bool, str]:
    """(True, "") when a tiny Mitsuba render succeeds, else (False, why): what tests skip on."""
    try:
        mi = load_mitsuba()
        scene = mi.load_dict({"type": "scene", "integrator": {"type": "path"}, "light": {"type": "constant"},
                              "sensor": {"type": "perspective",
                                         "film": {"type": "hdrfilm", "width": 4, "height": 4}}})
        mi.render(scene, spp=1)
    except MitsubaUnavailable as exc:
        return False, str(exc)
    except Exception as exc:  # noqa: BLE001 - any failure means: cannot validate here
        return False, f"Mitsuba 3 cannot render here: {exc}"
    return True, ""
