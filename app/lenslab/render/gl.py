"""OpenGL context and shader loading.

LensLab renders in compute shaders through a standalone (window-less) moderngl context created through EGL:
Mesa's llvmpipe on machines without a GPU, the vendor's driver (NVIDIA) where there is one. The context
belongs to the thread that creates it; the GUI gives its render worker a context of its own.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from lenslab.render.gpu_layout import glsl_defines, glsl_generated_includes
from lenslab.resources import glsl_dir

REQUIRED_GL = 430  # compute shaders and shader storage buffers

# One line a user can act on, for the commonest way this fails on a fresh Linux machine.
INSTALL_HINT = (
    "install an EGL-capable OpenGL driver: on Debian/Ubuntu `apt-get install libegl1 libgl1 libopengl0 "
    "libegl-mesa0 libgl1-mesa-dri` (Mesa llvmpipe works without a GPU), or the NVIDIA driver on a GPU machine"
)
#: The Debian/Ubuntu package of each library moderngl loads by name (glvnd's dispatch libraries).
LIBRARY_PACKAGES = {"libEGL": "libegl1", "libGL": "libgl1", "libOpenGL": "libopengl0"}


def _missing_library(text: str) -> str | None:
    """'libEGL.so not loaded' (moderngl's words for a library it cannot open): which package brings it."""
    for library, package in LIBRARY_PACKAGES.items():
        if re.search(rf"\b{library}\.so[.\d]*(:? not loaded|: cannot open)", text):
            return f"{library}.so is missing: on Debian/Ubuntu `apt-get install {package}`"
    return None


class GLUnavailable(RuntimeError):
    """No usable OpenGL 4.3 context; the message says what is missing and how to get it."""


@dataclass(frozen=True)
class DeviceLimits:
    max_storage_block_bytes: int
    max_compute_storage_blocks: int
    max_work_group_invocations: int
    max_work_group_count: tuple[int, int, int]


def create_context(device_index: int | None = None):
    """A standalone GL >= 4.3 core context through EGL on device ``device_index`` (None: the default)."""
    try:
        import moderngl
    except ImportError as exc:  # pragma: no cover - a broken install
        raise GLUnavailable(f"the Python package moderngl is missing ({exc}); reinstall LensLab") from None
    kwargs = {"standalone": True, "backend": "egl", "require": REQUIRED_GL}
    if device_index is not None:
        kwargs["device_index"] = int(device_index)
    try:
        return moderngl.create_context(**kwargs)
    except Exception as exc:  # moderngl/glcontext raise plain Exceptions with the EGL error in the text
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        if "device index" in text:
            raise GLUnavailable(f"no such GPU: {text}") from None
        missing = _missing_library(text)
        if missing:
            raise GLUnavailable(f"no OpenGL through EGL ({missing}); {INSTALL_HINT}") from None
        if "libEGL" in text or "eglGetProcAddress" in text or "cannot open" in text.lower():
            raise GLUnavailable(f"no EGL library ({text}); {INSTALL_HINT}") from None
        raise GLUnavailable(f"cannot create an OpenGL {REQUIRED_GL // 100}.{REQUIRED_GL % 100 // 10} context "
                            f"through EGL ({text}); {INSTALL_HINT}") from None


def make_current(ctx) -> None:
    """Make ``ctx`` the current context of this thread, and leave it so. A standalone context is current in the
    thread that made it only until another is made there (a second Renderer: the CLI, a test); GL calls would
    then go to that one, or nowhere once it is released, and images would silently stay black. moderngl's
    ``with ctx:`` is no help: on leaving, it restores what was current on entering, which with EGL is often
    no context at all."""
    ctx.__enter__()


def device_limits(ctx) -> DeviceLimits:
    info = ctx.info
    return DeviceLimits(
        max_storage_block_bytes=int(info["GL_MAX_SHADER_STORAGE_BLOCK_SIZE"]),
        max_compute_storage_blocks=int(info["GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS"]),
        max_work_group_invocations=int(info["GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS"]),
        max_work_group_count=tuple(int(v) for v in info["GL_MAX_COMPUTE_WORK_GROUP_COUNT"]),
    )


# llvmpipe from Mesa before 24 runs the trace kernels 1.3 to 2 times slower (docs/performance.md).
FAST_LLVMPIPE_MESA = 24
_MESA_VERSION = re.compile(r"Mesa (\d+)\.")


def slow_driver_note(renderer: str, version: str) -> str | None:
    """Advice for a CPU renderer that a newer Mesa would make faster; None when there is nothing to say."""
    match = _MESA_VERSION.search(version)
    if "llvmpipe" not in renderer or match is None or int(match.group(1)) >= FAST_LLVMPIPE_MESA:
        return None
    return (f"Mesa {match.group(1)}'s llvmpipe renders 1.3 to 2 times slower than Mesa {FAST_LLVMPIPE_MESA} or later "
            "(on Debian 12: apt-get install -t bookworm-backports libgl1-mesa-dri libegl-mesa0)")


def describe_device(ctx) -> dict[str, str]:
    """What `lenslab --info` prints: renderer, version and the limits the tracer works within."""
    info = ctx.info
    limits = device_limits(ctx)
    note = slow_driver_note(info["GL_RENDERER"], info["GL_VERSION"])
    return {
        "renderer": info["GL_RENDERER"],
        "vendor": info["GL_VENDOR"],
        "version": info["GL_VERSION"],
        "max storage block": f"{limits.max_storage_block_bytes / 2**20:.0f} MiB",
        "storage blocks per compute shader": str(limits.max_compute_storage_blocks),
        "max work-group invocations": str(limits.max_work_group_invocations),
        "max work-group count": " x ".join(str(v) for v in limits.max_work_group_count),
        **({"note": note} if note else {}),
    }


_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


@lru_cache(maxsize=None)
def _read(path: Path) -> str:
    return path.read_text(encoding="utf-8")


def load_shader_source(name: str, defines: dict[str, object] | None = None, directory: Path | None = None,
                       includes: dict[str, str] | None = None) -> str:
    """Read ``glsl/<name>``, expand ``#include "file"`` (each file once) and put ``#define``s after #version:
    the buffer layout every shader shares (gpu_layout.glsl_defines), then the caller's ``defines``. An include
    named in gpu_layout.glsl_generated_includes (the material kinds' dispatch) or in the caller's ``includes``
    (OpenColorIO's view transform) is that generated text, not a file."""
    layout = glsl_defines()
    clash = sorted(layout.keys() & (defines or {}).keys())
    if clash:
        raise ValueError(f"{', '.join(clash)}: part of the shared buffer layout (render/gpu_layout.py), "
                         "not a per-kernel define")
    defines = {**layout, **(defines or {})}
    directory = directory or glsl_dir()
    seen: set[str] = set()
    generated = {**glsl_generated_includes(), **(includes or {})}

    def expand(file_name: str) -> str:
        if file_name in seen:
            return ""
        seen.add(file_name)
        if file_name in generated:
            return _INCLUDE.sub(lambda m: expand(m.group(1)), generated[file_name])
        path = directory / file_name
        if not path.is_file():
            raise FileNotFoundError(f"shader {path} not found")
        body = _read(path)
        return _INCLUDE.sub(lambda m: expand(m.group(1)), body)

    source = expand(name)
    lines = source.splitlines()
    version_at = next(i for i, line in enumerate(lines) if line.startswith("#version"))
    define_lines = [f"#define {key} {value}" for key, value in defines.items()]
    return "\n".join(lines[: version_at + 1] + define_lines + lines[version_at + 1 :]) + "\n"


# A plain uniform's declaration: `uniform <type> <name>;` (with an optional array size). Uniform blocks
# (`uniform Name {`) are bound by number, not set by name, and do not match.
_UNIFORM = re.compile(r"^\s*uniform\s+\w+\s+(\w+)\s*(?:\[[^\]]*\])?\s*;", re.MULTILINE)


def declared_uniforms(source: str) -> frozenset[str]:
    """The names of the plain uniforms ``source`` declares, whether or not the compiled program keeps them."""
    return frozenset(_UNIFORM.findall(source))
