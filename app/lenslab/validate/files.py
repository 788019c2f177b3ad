"""``lenslab validate --files``: any Mitsuba 3 scene files, rendered by LensLab and by Mitsuba 3, against one
goal: the scene opens with nothing dropped, and LensLab's image is within 2% of Mitsuba's in the median
16 x 16 block and in its total light (docs/validation.md, "Mitsuba's own scenes").

Per file, at a width of ``width`` pixels (the film scaled, its aspect kept: both renderers get the same size):

* the **reference**: Mitsuba 3 at ``reference_spp`` (seeds from 1000, as the built-in set's), cached;
* Mitsuba at ``spp`` (seeds from 500): how far noise alone takes the figures, the *noise* column; cached;
* LensLab at ``spp`` (seed 1), opened exactly as ``lenslab scene.xml --headless -D spp=N --width W`` opens it.

Mitsuba reads the file with its own parser (``mi.parser``, what ``mi.load_file`` runs), the film's width and
height set and a crop window removed before the objects are made; it runs in a child process of its own, as
in :mod:`lenslab.validate.runner`. Each file gets ``-D spp=N``, as Mitsuba's script for its documentation's
images passes it (a file that does not use it is not warned about it). A file that either renderer cannot
open or render is a result with a one-line ``error``, never an exception.
"""

from __future__ import annotations

import hashlib
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from lenslab.messages import one_line
from lenslab.resources import user_cache_dir
from lenslab.validate import findings, metrics
from lenslab.validate.runner import Render, in_child_process, mitsuba_image, render_scene

GOAL_MEDIAN = 0.02  # the median block error at most 2%
GOAL_TOTAL_LIGHT = 0.02  # and the total light within 2%
REFERENCE_SEED, NOISE_SEED, LENSLAB_SEED = 1000, 500, 1
CACHE_VERSION = 1  # bump when what a cached reference means changes
CROP_KEYS = ("crop_offset_x", "crop_offset_y", "crop_width", "crop_height")
AUTO_DEFINES = ("spp",)


def default_cache_dir() -> Path:
    return user_cache_dir("validate")


@dataclass
class FileResult:
    name: str
    path: Path
    warnings: list[str] = field(default_factory=list)  # LensLab's, one line each
    resolution: tuple[int, int] | None = None
    reference: Render | None = None
    mitsuba: Render | None = None  # Mitsuba at LensLab's sample count: the noise floor
    lenslab: Render | None = None
    lenslab_bias: metrics.BiasSummary | None = None
    mitsuba_bias: metrics.BiasSummary | None = None
    total_light: float = float("nan")  # LensLab's sum over the reference's, less one
    error: str | None = None  # why the two images could not be compared

    @property
    def drops(self) -> list[findings.Finding]:
        return findings.drops(self.warnings)

    @property
    def verdict(self) -> str:
        if self.error is not None:
            return "ERROR"
        return "FAIL" if self.reasons() else "PASS"

    def reasons(self) -> list[str]:
        """Why the goal is missed: [] when it is met (or the images could not be compared: see ``error``)."""
        if self.error is not None or self.lenslab_bias is None:
            return []
        why = []
        n = len(self.drops)
        if n:
            why.append(f"drops content ({n})")
        median = self.lenslab_bias.median_abs
        if not median <= GOAL_MEDIAN:  # NaN (no block bright enough) is no pass either
            why.append(f"median block {100 * median:.1f}%" if median == median else "no block bright enough")
        if not abs(self.total_light) <= GOAL_TOTAL_LIGHT:
            why.append(f"total light {100 * self.total_light:+.1f}%")
        return why


def display_names(paths: list[Path]) -> list[str]:
    """Each file's name in the table: its path below the folder all of them share, without ``.xml``."""
    resolved = [Path(os.path.abspath(p)) for p in paths]
    if len(resolved) == 1:
        return [resolved[0].stem]
    root = Path(os.path.commonpath([str(p.parent) for p in resolved]))
    return [str(p.relative_to(root).with_suffix("")) for p in resolved]


def _reason(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return one_line(text)


def validate_file(path: Path, *, name: str, spp: int, reference_spp: int, width: int, renderer,
                  cache_dir: Path | None, defines: dict[str, str] | None = None,
                  log: Callable[[str], None] = lambda _: None) -> FileResult:
    """Render one scene file with Mitsuba and with LensLab and compare them (see the module's doc)."""
    from lenslab.scene.overrides import SceneOverrides

    path = Path(path)
    result = FileResult(name=name, path=path)
    user = dict(defines or {})
    all_defines = {**{k: str(spp) for k in AUTO_DEFINES}, **user}
    errors = []

    log(f"{name}: Mitsuba at {reference_spp} spp (the reference) and {spp} spp")
    size = None
    try:
        size, renders = in_child_process(_render_mitsuba_scaled, Path(os.path.abspath(path)), all_defines, width,
                                         [(reference_spp, REFERENCE_SEED), (spp, NOISE_SEED)],
                                         None if cache_dir is None else Path(cache_dir))
        result.reference, result.mitsuba = renders
    except Exception as exc:  # noqa: BLE001 - whatever Mitsuba says is this file's row
        errors.append(f"Mitsuba: {_reason(exc)}")

    def warn(message: str) -> None:
        if any(f"-D {k}={all_defines[k]} is not used" in message for k in AUTO_DEFINES if k not in user):
            return  # the validator's own -D spp, which this file does not use
        if message not in result.warnings:
            result.warnings.append(message)

    log(f"{name}: LensLab at {spp} spp")
    try:
        start = time.perf_counter()
        overrides = SceneOverrides(spp=spp, seed=LENSLAB_SEED, width=width, height=size[1] if size else None,
                                   defines=all_defines)
        scene = overrides.open(path, warn=warn)
        if not errors:
            result.lenslab = render_scene(scene, spp, renderer, warn, start)
    except Exception as exc:  # noqa: BLE001 - a scene LensLab cannot open or render is a row, not a crash
        errors.append(f"LensLab: {_reason(exc)}")
    if errors:
        result.error = one_line("; ".join(errors))
        return result

    ref, image = result.reference.image, result.lenslab.image
    if image.shape != ref.shape:
        result.error = f"the images differ in size: LensLab {image.shape[1]}x{image.shape[0]}, Mitsuba " \
                       f"{ref.shape[1]}x{ref.shape[0]}"
        return result
    result.resolution = (ref.shape[1], ref.shape[0])
    try:
        result.lenslab_bias = metrics.summarize_bias(metrics.block_bias(image, ref))
        result.mitsuba_bias = metrics.summarize_bias(metrics.block_bias(result.mitsuba.image, ref))
        result.total_light = metrics.total_light(image, ref)
    except ValueError as exc:  # an image too small for one block
        result.error = _reason(exc)
    return result


# ---------------------------------------------------------------------------------------------------------
# In Mitsuba's child process
# ---------------------------------------------------------------------------------------------------------
def _render_mitsuba_scaled(path: Path, defines: dict[str, str], width: int, renders: list[tuple[int, int]],
                           cache_dir: Path | None) -> tuple[tuple[int, int], list[Render]]:
    """The file's film scaled to ``width`` (aspect kept), rendered at each (spp, seed): (size, [Render ...]).
    A render found in ``cache_dir`` is read, not made again (``seconds`` is then 0)."""
    from lenslab.validate.mitsuba_env import VARIANT, prepare_environment

    prepare_environment()  # the parent has checked (mitsuba_env.load_mitsuba) that this variant renders here
    import mitsuba as mi

    mi.set_variant(VARIANT)
    mi.set_log_level(mi.LogLevel.Error)  # its notes (a sampler's count rounded) would land in the table's output
    config = mi.parser.ParserConfig(VARIANT)
    config.unused_parameters = mi.LogLevel.Debug  # the -D spp given to every file, used or not
    resolver = mi.FileResolver(mi.file_resolver())  # as mi.load_file: files resolve against the scene's folder,
    resolver.prepend(str(path.parent))  # for the parser and for the objects it makes (on other threads too)
    mi.set_file_resolver(resolver)
    state = mi.parser.parse_file(config, str(path), **defines)
    mi.parser.transform_all(config, state)
    film = _first_film(mi, state)
    w = int(film.props["width"]) if "width" in film.props else 768  # hdrfilm's defaults
    h = int(film.props["height"]) if "height" in film.props else 576
    size = (width, max(1, round(width * h / w)))  # as SceneOverrides keeps an aspect
    film.props["width"], film.props["height"] = size
    for key in CROP_KEYS:
        if key in film.props:
            film.props.remove_property(key)
    if film.props.plugin_name() == "hdrfilm":
        film.props["pixel_format"] = "rgb"
    key = _cache_key(mi, state, defines, size) if cache_dir is not None else None
    scene, out = None, []
    for spp, seed in renders:
        cached = cache_dir / f"{key}-{spp}-{seed}.npy" if key else None
        if cached is not None and cached.is_file():
            out.append(Render(np.load(cached), spp, 0.0))
            continue
        start = time.perf_counter()
        if scene is None:
            scene = mi.parser.instantiate(config, state)
        image = mitsuba_image(mi, scene, spp, seed)
        out.append(Render(image, spp, time.perf_counter() - start))
        if cached is not None:
            cached.parent.mkdir(parents=True, exist_ok=True)
            partial = cached.with_name(f"{cached.stem}.{os.getpid()}.partial.npy")
            np.save(partial, image)
            os.replace(partial, cached)  # whole or not at all
    return size, out


def _first_film(mi, state):
    sensors = [n for n in state.nodes if n.type == mi.ObjectType.Sensor]
    if not sensors:
        raise ValueError("the scene has no <sensor> whose film could be scaled")
    for key in sensors[0].props.keys():
        value = sensors[0].props[key]
        if isinstance(value, mi.Properties.ResolvedReference) and state.nodes[value.index()].type == mi.ObjectType.Film:
            return state.nodes[value.index()]
    raise ValueError("the sensor has no <film> that could be scaled")


def _cache_key(mi, state, defines: dict[str, str], size: tuple[int, int]) -> str:
    """What the reference depends on: the bytes of the XML files and of the files they name (not where they are,
    nor when they were written: a copied or re-exported scene keeps its references), the defines, the image size,
    Mitsuba's version and variant."""
    from lenslab.validate.mitsuba_env import VARIANT

    digest = hashlib.sha256(repr((CACHE_VERSION, mi.__version__, VARIANT, sorted(defines.items()), size)).encode())
    for name in state.files:
        digest.update(hashlib.sha256(Path(str(name)).read_bytes()).digest())
    resolver = mi.file_resolver()
    for node in state.nodes:
        if "filename" in node.props and isinstance(node.props["filename"], str):
            asset = Path(str(resolver.resolve(node.props["filename"])))
            content = hashlib.sha256(asset.read_bytes()).digest() if asset.is_file() else b"absent"
            digest.update(node.props["filename"].encode() + b"\0" + content)
    return digest.hexdigest()[:32]
