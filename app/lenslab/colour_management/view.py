"""The view transform: scene-linear light in the working space to a display's code values, as OpenColorIO makes
it, on the CPU for files and on the GPU for the screen (docs/colour.md, "From scene to screen").

OCIO's viewing pipeline, in its order: the exposure and contrast adjustment in scene-linear light (contrast about
middle grey, 0.18), then the looks, then the display's view (the tone mapping and the display's encoding). The
adjustment is dynamic: the studio moves it with a uniform, without generating or compiling a new shader.

The names of LensLab's hand-written tone curves stay as aliases where a view of the config does their job:
``filmic`` is the display's default view (ACES 2.0 SDR in the built-in config), ``clamp`` its
``Un-tone-mapped`` view (sRGB's curve on the unchanged values, clipped by the display). ``reinhard`` has no
counterpart in an ACES config and is refused with the views there are.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from lenslab.colour_management.config import DEFAULT_SOURCE, ColourConfigError, config_name, config_source, load_config
from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE, ocio_space_of

#: Old tone-curve names, as scene files, batch files and settings of earlier versions wrote them: the view they
#: become ("" is the display's default view).
VIEW_ALIASES = {"filmic": "", "clamp": "Un-tone-mapped"}
#: Contrast about middle grey, as OCIO's ExposureContrastTransform pivots it.
CONTRAST_PIVOT = 0.18
EXPOSURE_RANGE = (-30.0, 30.0)
#: The name a picture's metadata gives each part of the transform (the options that set them record the same:
#: scene/options.py reads them here).
METADATA = {"config": "lenslab:OCIOConfig", "display": "lenslab:Display", "view": "lenslab:View",
            "looks": "lenslab:Looks", "exposure_stops": "lenslab:DisplayExposureStops", "contrast": "lenslab:Contrast",
            "working_space": "lenslab:WorkingSpace"}
CONTRAST_RANGE = (0.1, 10.0)


@dataclass(frozen=True)
class ViewTransform:
    """How scene-linear pixels become a display's: ``display`` and ``view`` of the config (empty: its default
    display, and that display's default view), ``looks`` (OCIO's look syntax: names, comma separated, ``-`` for an
    inverse), an ``exposure_stops`` and ``contrast`` adjustment, from ``working_space`` pixels, in config
    ``config`` (empty: $OCIO, else the built-in ACES config)."""

    display: str = ""
    view: str = ""
    looks: str = ""
    exposure_stops: float = 0.0
    contrast: float = 1.0
    working_space: str = DEFAULT_WORKING_SPACE
    config: str = DEFAULT_SOURCE
    _resolved: bool = field(default=False, repr=False, compare=False)

    def resolved(self) -> "ViewTransform":
        """This transform with its display and view named as the config names them (defaults filled in, an alias
        turned into its view), checked: a ColourConfigError naming what the config lacks, and what it has."""
        if self._resolved:
            return self
        _check_range("exposure", self.exposure_stops, EXPOSURE_RANGE)
        _check_range("contrast", self.contrast, CONTRAST_RANGE)
        config = load_config(self.config)
        display = self.display or config.getDefaultDisplay()
        displays = list(config.getDisplays())
        if display not in displays:
            raise ColourConfigError(f"display '{display}' is not in the OCIO config {config_name(self.config)} "
                                    f"(it has: {', '.join(displays)})")
        views = list(config.getViews(display))
        view = VIEW_ALIASES.get(self.view, self.view) or config.getDefaultView(display)
        if view not in views:
            hint = (" ('reinhard' was a tone curve of earlier versions: choose a view)" if self.view == "reinhard"
                    else "")
            raise ColourConfigError(f"view '{self.view}' is not one of display '{display}''s views{hint} "
                                    f"(it has: {', '.join(views)})")
        for look in _look_names(self.looks):
            if config.getLook(look) is None:
                have = [look.getName() for look in config.getLooks()]
                raise ColourConfigError(f"look '{look}' is not in the OCIO config "
                                        f"(it has: {', '.join(have) or 'none'})")
        ocio_space_of(self.working_space, config)  # raises for a config without the working space
        return replace(self, display=display, view=view, looks=",".join(_look_names(self.looks)), _resolved=True)

    # -- what it is, in words and for files -------------------------------------------------------------------
    def describe(self) -> str:
        """``"sRGB - Display / ACES 2.0 - SDR 100 nits (Rec.709)"``, with the looks after a ``+``."""
        done = self.resolved()
        return f"{done.display} / {done.view}" + (f" + {done.looks}" if done.looks else "")

    def display_colour_space(self) -> str:
        """The colour space the transform's output is encoded in (what a file's ICC profile or cICP describes)."""
        done = self.resolved()
        config = load_config(done.config)
        name = config.getDisplayViewColorSpaceName(done.display, done.view)
        return done.display if name == "<USE_DISPLAY_NAME>" else name

    def metadata(self) -> dict[str, object]:
        """What an exported picture says about how it was made from the render."""
        done = self.resolved()
        values = {"config": config_name(done.config), "display": done.display, "view": done.view,
                  "looks": done.looks, "exposure_stops": float(done.exposure_stops), "contrast": float(done.contrast),
                  "working_space": done.working_space}
        return {METADATA[part]: value for part, value in values.items()}

    # -- the transform -------------------------------------------------------------------------------------------
    def apply(self, linear: np.ndarray) -> np.ndarray:
        """Display code values in [0, 1], (H, W, 3) float32, of the scene-linear ``linear`` (H, W, 3) working-space
        pixels: OCIO's CPU processor (the GPU's shader, :meth:`gpu_shader`, is the same transform)."""
        done = self.resolved()
        pixels = np.ascontiguousarray(linear[..., :3], dtype=np.float32).copy()
        processor = _processor(*done._key()).getDefaultCPUProcessor()
        _set_dynamic(processor, done)
        processor.applyRGB(pixels.reshape(-1, 3))
        np.nan_to_num(pixels, copy=False, nan=0.0)
        return np.clip(pixels, 0.0, 1.0, out=pixels)

    def gpu_shader(self) -> "GpuShader":
        """The GLSL 4.0 function ``vec4 ocio_display(vec4)`` and the lookup tables it samples, as OCIO generates
        them for this transform (the same for every exposure and contrast: see :meth:`gpu_uniforms`)."""
        return _gpu_shader(*self.resolved()._key())

    def gpu_uniforms(self) -> dict[str, float]:
        """The values of the shader's uniforms for this transform's exposure and contrast."""
        done = self.resolved()
        shader = _gpu_shader(*done._key())
        return shader.uniforms(done.exposure_stops, done.contrast)

    def _key(self) -> tuple[str, str, str, str, str]:
        return config_source(self.config), self.working_space, self.display, self.view, self.looks


@dataclass(frozen=True)
class LookupTexture:
    """A table OCIO's shader samples: ``sampler`` is its uniform's name; ``values`` (height, width, channels)
    float32; ``linear`` interpolation, else nearest."""

    sampler: str
    values: np.ndarray
    linear: bool


@dataclass(frozen=True)
class GpuShader:
    source: str  # defines vec4 ocio_display(vec4)
    textures: tuple[LookupTexture, ...]
    _description: object = field(repr=False, compare=False)

    def uniforms(self, exposure_stops: float, contrast: float) -> dict[str, float]:
        import PyOpenColorIO as ocio

        desc = self._description
        if desc.hasDynamicProperty(ocio.DYNAMIC_PROPERTY_EXPOSURE):
            desc.getDynamicProperty(ocio.DYNAMIC_PROPERTY_EXPOSURE).setDouble(float(exposure_stops))
        if desc.hasDynamicProperty(ocio.DYNAMIC_PROPERTY_CONTRAST):
            desc.getDynamicProperty(ocio.DYNAMIC_PROPERTY_CONTRAST).setDouble(float(contrast))
        return {name: float(data.getDouble()) for name, data in desc.getUniforms()}


def _look_names(looks: str) -> list[str]:
    return [name.strip() for name in str(looks).split(",") if name.strip()]


def _check_range(what: str, value: float, bounds: tuple[float, float]) -> None:
    if not bounds[0] <= float(value) <= bounds[1]:  # also refuses NaN
        raise ValueError(f"display {what} {value:g} is out of range [{bounds[0]:g}, {bounds[1]:g}]")


@lru_cache(maxsize=32)
def _processor(source: str, working_space: str, display: str, view: str, looks: str):
    """OCIO's processor for one resolved transform, its exposure and contrast left dynamic."""
    import PyOpenColorIO as ocio

    config = load_config(source)
    adjustment = ocio.ExposureContrastTransform(style=ocio.EXPOSURE_CONTRAST_LINEAR, exposure=0.0, contrast=1.0,
                                                pivot=CONTRAST_PIVOT)
    adjustment.makeExposureDynamic()
    adjustment.makeContrastDynamic()
    pipeline = ocio.LegacyViewingPipeline()
    pipeline.setLinearCC(adjustment)
    pipeline.setLooksOverrideEnabled(bool(looks))
    pipeline.setLooksOverride(looks)
    pipeline.setDisplayViewTransform(ocio.DisplayViewTransform(src=ocio_space_of(working_space, config),
                                                               display=display, view=view))
    try:
        return pipeline.getProcessor(config)
    except Exception as exc:  # OCIO's own Exception: a look or view whose files are missing, say
        raise ColourConfigError(f"OCIO cannot make the view {display} / {view}: {str(exc).strip()}") from None


def _set_dynamic(processor, transform: ViewTransform) -> None:
    import PyOpenColorIO as ocio

    for kind, value in ((ocio.DYNAMIC_PROPERTY_EXPOSURE, transform.exposure_stops),
                        (ocio.DYNAMIC_PROPERTY_CONTRAST, transform.contrast)):
        if processor.hasDynamicProperty(kind):
            processor.getDynamicProperty(kind).setDouble(float(value))


@lru_cache(maxsize=32)
def _gpu_shader(source: str, working_space: str, display: str, view: str, looks: str) -> GpuShader:
    import PyOpenColorIO as ocio

    gpu = _processor(source, working_space, display, view, looks).getDefaultGPUProcessor()
    desc = ocio.GpuShaderDesc.CreateShaderDesc(language=ocio.GPU_LANGUAGE_GLSL_4_0, functionName="ocio_display",
                                               resourcePrefix="ocio_")
    desc.setAllowTexture1D(False)  # 2D tables one row high: the renderer's GL wrapper has no 1D textures
    gpu.extractGpuShaderInfo(desc)
    textures = []
    for texture in desc.getTextures():
        channels = 1 if texture.channel == ocio.GpuShaderDesc.TEXTURE_RED_CHANNEL else 3
        values = np.asarray(texture.getValues(), np.float32).reshape(texture.height, texture.width, channels)
        textures.append(LookupTexture(texture.samplerName, values, texture.interpolation != ocio.INTERP_NEAREST))
    for texture in desc.get3DTextures():
        edge = texture.edgeLen
        values = np.asarray(texture.getValues(), np.float32).reshape(edge, edge, edge, 3)
        textures.append(LookupTexture(texture.samplerName, values, texture.interpolation != ocio.INTERP_NEAREST))
    return GpuShader(desc.getShaderText(), tuple(textures), desc)
