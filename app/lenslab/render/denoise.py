"""Denoising with Intel Open Image Denoise (OIDN), through PyPI ``pyoidn``, whose wheels carry the library.

:func:`denoise` takes linear HDR radiance (H, W, 3) and, when given, the first-hit albedo and shading normal the
tracer accumulates beside it (``RenderSession(feature_buffers=True)``, glsl/feature_buffers.glsl), and runs
OIDN's "RT" filter on them. Two ways, as OIDN's documentation advises:

* **preview** (``prefilter=False``): the guides as they are. They come from the same few samples as the image and
  are noisy too, so ``cleanAux`` stays off: OIDN then tolerates their noise. For the studio's viewport.
* **final frame** (``prefilter=True``): the albedo and normal are denoised first, each by a filter of its own,
  and the image then with ``cleanAux`` on, as OIDN advises for final frames: seven to eight times the work (three
  networks, each made for the one call). For exports.

Making an OIDN device loads its library and kernels, so one device serves every call, and a preview's filter and
buffers are kept for the next call of the same size and options: the viewport, which denoises the same size again
and again, only copies pixels in and out and runs the network. A final frame frees its filters as it goes (their
scratch memory is large: see MAX_MEMORY_MB). Calls are serialised (the shared :class:`Denoiser`'s lock). A
thread that must denoise beside the others, not after them, keeps a Denoiser of its own: its own device, buffers
and lock.

The device is OIDN's default: a GPU that OIDN supports and whose driver it finds (CUDA, HIP, SYCL), else the
CPU. ``LENSLAB_DENOISE_DEVICE`` (cpu, cuda, hip, sycl, metal) forces one.
"""

from __future__ import annotations

import atexit
import os
import threading
import weakref

import numpy as np

from lenslab.messages import one_line

QUALITIES = ("high", "balanced", "fast")  # OIDN's filter qualities: balanced and fast trade quality for speed
# OIDN's scratch memory per filter (its maxMemoryMB). Left to itself its CPU device takes about 620 bytes a pixel
# up to about 2.5 GB (measured: 1.1 GB at 1920 x 1080, 2.5 GB at 3840 x 2160); held to 1 GiB it works in tiles:
# 1920 x 1080 took 10% longer (2.87 s against 2.61 s on two cores), a frame of up to 1.7 Mpx no longer at all.
MAX_MEMORY_MB = 1024
DEVICE_ENV = "LENSLAB_DENOISE_DEVICE"
_DEVICE_TYPES = {"default": 0, "cpu": 1, "sycl": 2, "cuda": 3, "hip": 4, "metal": 5}  # OIDNDeviceType
_DEVICE_NAMES = {value: name.upper() for name, value in _DEVICE_TYPES.items()}
_FLOAT3 = 3  # OIDN_FORMAT_FLOAT3


class DenoiseError(RuntimeError):
    """Denoising cannot run here (no pyoidn, no device) or OIDN reported a failure: a one-line reason."""


def denoise(color: np.ndarray, albedo: np.ndarray | None = None, normal: np.ndarray | None = None, *,
            prefilter: bool = False, quality: str = "high") -> np.ndarray:
    """The denoised image, (H, W, 3) float32 linear radiance, from ``color`` (H, W, 3) linear radiance and the
    optional guides: ``albedo`` in [0, 1] and ``normal`` in [-1, 1] (world or view space, any length), each
    (H, W, 3). A normal needs an albedo (OIDN has no filter for a normal alone). ``prefilter``: denoise the
    guides first and trust them (OIDN's cleanAux), for final frames. Raises ValueError for input it cannot take
    and DenoiseError where denoising cannot run."""
    return _SHARED.denoise(color, albedo, normal, prefilter=prefilter, quality=quality)


class Denoiser:
    """A denoiser: an OIDN device, its buffers and its filter, made on first use. Calls on one Denoiser are
    serialised; calls on two run at once. :func:`denoise` uses the one the process shares; a thread that denoises
    beside the others (the studio's full-resolution pictures, off the render thread that denoises its previews)
    keeps one of its own. Its owner releases it; one still held at exit is released then."""

    def __init__(self):
        self._lock = threading.Lock()
        self._impl: _Denoiser | None = None
        _DENOISERS.add(self)

    def denoise(self, color: np.ndarray, albedo: np.ndarray | None = None, normal: np.ndarray | None = None, *,
                prefilter: bool = False, quality: str = "high") -> np.ndarray:
        """As :func:`denoise`, on this denoiser's device."""
        images = _checked_images(color, albedo, normal, quality)
        with self._lock:
            return self._device().run(images, prefilter, quality)

    @property
    def description(self) -> str:
        with self._lock:
            return self._device().description

    def release(self) -> None:
        with self._lock:
            if self._impl is not None:
                self._impl.release()
                self._impl = None

    def _device(self) -> _Denoiser:
        if self._impl is None:
            self._impl = _Denoiser(os.environ.get(DEVICE_ENV, "default").strip().lower() or "default")
        return self._impl


def describe() -> str:
    """The library and the device that denoises, e.g. "Intel Open Image Denoise 2.5.1 on CPU (2 threads)"."""
    return _SHARED.description


def _checked_images(color, albedo, normal, quality: str) -> dict[str, np.ndarray]:
    if quality not in QUALITIES:
        raise ValueError(f"unknown denoise quality '{quality}' (choose from {', '.join(QUALITIES)})")
    if normal is not None and albedo is None:
        raise ValueError("a normal guide needs an albedo guide beside it (OIDN denoises with color, color + albedo "
                         "or color + albedo + normal)")
    images = {}
    for name, image in (("color", color), ("albedo", albedo), ("normal", normal)):
        if image is None:
            continue
        image = np.asarray(image)
        if image.ndim != 3 or image.shape[2] != 3 or 0 in image.shape:
            raise ValueError(f"the {name} image to denoise must be (height, width, 3), not {image.shape}")
        if image.shape != np.shape(color):
            raise ValueError(f"the {name} image is {image.shape[1]}x{image.shape[0]}, the color image "
                             f"{np.shape(color)[1]}x{np.shape(color)[0]}: they must be the same size")
        images[name] = np.ascontiguousarray(image, dtype=np.float32)
    if not np.isfinite(images["color"]).all():  # OIDN would spread a NaN over its neighbourhood
        raise ValueError("the color image to denoise has NaN or infinite pixels")
    return images


class _Denoiser:
    """One OIDN device, the buffers for the last image size and options, and the preview's filter for them."""

    def __init__(self, device_kind: str):
        try:
            import pyoidn
        except ImportError as exc:  # pyoidn is a dependency; a broken install says so in one line
            raise DenoiseError(f"denoising needs Intel Open Image Denoise: pip install pyoidn ({exc})") from None
        if device_kind not in _DEVICE_TYPES:
            raise DenoiseError(f"{DEVICE_ENV}={device_kind}: choose one of {', '.join(_DEVICE_TYPES)}")
        self.pyoidn = pyoidn
        self.device = pyoidn.Device(_DEVICE_TYPES[device_kind])
        self._check(f"making a {device_kind} device")
        self.device.commit()
        self._check(f"starting the {device_kind} device")
        kind = _DEVICE_NAMES.get(self.device.get_int("type"), "unknown device")
        version = self.device.get_int("version")  # e.g. 20501
        threads = f" ({self.device.get_int('numThreads')} threads)" if kind == "CPU" else ""
        self.description = (f"Intel Open Image Denoise {version // 10000}.{version // 100 % 100}.{version % 100} "
                            f"on {kind}{threads}")
        self._key = None  # the images, size and quality the buffers (and the preview's filter) are for
        self._buffers: dict[str, object] = {}
        self._filter = None  # the preview's filter, kept for the next call

    def _check(self, doing: str) -> None:
        message = self.device.get_error()
        if message:
            raise DenoiseError(one_line(f"Open Image Denoise failed {doing}: {message}"))

    def run(self, images: dict[str, np.ndarray], prefilter: bool, quality: str) -> np.ndarray:
        """A preview keeps its buffers and its filter for the next call of the same size and options. A final
        frame is a single call: each of its filters is made, run and released in turn, so that no more than one
        filter's scratch memory is held at a time, and nothing once it is done."""
        height, width = images["color"].shape[:2]
        key = (tuple(images), width, height, quality)
        if key != self._key or prefilter:  # a final frame also frees the preview's filter while it runs
            self._release_filters()
            for name in (*images, "output"):
                self._buffers[name] = self.pyoidn.Buffer(self.device, width * height * 12)
                self._check(f"allocating a {width}x{height} {name} image")
            self._key = key
        size = width * height * 12
        for name, pixels in images.items():
            self._buffers[name].write(0, size, pixels)
        guides = [name for name in ("albedo", "normal") if name in images]
        image_slots = {name: name for name in images} | {"output": "output"}
        try:
            if not prefilter:
                if self._filter is None:
                    self._filter = self._new_filter(image_slots, width, height, quality, hdr=True)
                self._execute(self._filter)
            else:
                # Each guide alone, denoised in place (OIDN's "denoising with prefiltering"), then the image,
                # trusting them (cleanAux).
                for slots, flags in [*[({guide: guide, "output": guide}, {}) for guide in guides],
                                     (image_slots, {"hdr": True, "cleanAux": bool(guides)})]:
                    flt = self._new_filter(slots, width, height, quality, **flags)
                    try:
                        self._execute(flt)
                    finally:
                        flt.release()
            output = np.empty((height, width, 3), np.float32)
            self._buffers["output"].read(0, size, output)
        finally:
            if prefilter:
                self._release_filters()
        return output

    def _new_filter(self, slots: dict[str, str], width: int, height: int, quality: str, **flags: bool):
        """An "RT" filter reading and writing ``slots`` (OIDN's image name: buffer name), set up and committed."""
        oidn = self.pyoidn
        flt = oidn.Filter(self.device, oidn.OIDN_FILTER_TYPE_RT)
        try:
            for slot, buffer in slots.items():
                flt.set_image(slot, self._buffers[buffer], _FLOAT3, width, height)
            for flag, value in flags.items():
                flt.set_bool(flag, value)
            flt.set_int("maxMemoryMB", MAX_MEMORY_MB)
            flt.set_quality({"high": oidn.OIDN_QUALITY_HIGH, "balanced": oidn.OIDN_QUALITY_BALANCED,
                             "fast": oidn.OIDN_QUALITY_FAST}[quality])
            flt.commit()
            self._check("setting up a filter")
        except BaseException:
            flt.release()
            raise
        return flt

    def _execute(self, flt) -> None:
        flt.execute()
        self._check("denoising")

    def _release_filters(self) -> None:
        if self._filter is not None:
            self._filter.release()
            self._filter = None
        for buffer in self._buffers.values():
            buffer.release()
        self._buffers = {}
        self._key = None

    def release(self) -> None:
        self._release_filters()
        self.device.release()


_DENOISERS: weakref.WeakSet = weakref.WeakSet()  # every Denoiser not yet collected
_SHARED = Denoiser()  # denoise()'s


@atexit.register
def _release_at_exit() -> None:
    """Release the devices before the interpreter unloads the library under them."""
    for denoiser in list(_DENOISERS):
        denoiser.release()
