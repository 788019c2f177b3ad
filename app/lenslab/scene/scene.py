"""The scene as data: a tree of named nodes, a material library, a camera, an environment and render settings.

Nothing here knows about OpenGL or Qt. The renderer asks for :meth:`Scene.flatten`, which resolves the node
tree into world-space arrays of triangles and spheres; the GUI edits the dataclasses and says so through
:class:`SceneEvents` listeners.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, ClassVar, Iterator

import numpy as np

from lenslab.colour_management.working_space import DEFAULT_WORKING_SPACE, WORKING_SPACES

from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.lights import Light
from lenslab.scene.materials import Diffuse, Material
from lenslab.scene.shapes import Shape
from lenslab.scene.transform import Transform

RGB = tuple[float, float, float]


class SceneError(ValueError):
    """A scene that cannot be loaded or rendered; the message is one line naming the file and the key."""

    @classmethod
    def in_file(cls, path: object, problem: object) -> "SceneError":
        """The error for ``problem`` found in the scene file ``path``: the file named once, at the start,
        whether or not whoever raised ``problem`` had named it already."""
        text = str(problem)
        return cls(text if text.startswith(f"{path}: ") else f"{path}: {text}")


@dataclass
class Node:
    name: str = field(default="node", metadata={"required": True})
    transform: Transform = field(default_factory=Transform)
    shape: Shape | None = None
    material: str = field(default="", metadata={"doc": "name of an entry in the scene's materials"})
    # Unquoted: under ``from __future__ import annotations`` this whole annotation is already a string, and a name
    # quoted inside it stays a string after typing.get_type_hints on Python 3.10 (3.11 resolves it), which the
    # scene reader (io/native.py) cannot read.
    children: list[Node] = field(default_factory=list)

    def walk(self, parent_matrix: np.ndarray | None = None) -> Iterator[tuple["Node", np.ndarray]]:
        """Yield (node, local-to-world matrix) depth first."""
        matrix = self.transform.matrix() if parent_matrix is None else parent_matrix @ self.transform.matrix()
        yield self, matrix
        for child in self.children:
            yield from child.walk(matrix)


@dataclass
class Environment:
    """Light arriving from infinitely far away, seen where a ray leaves the scene."""

    type_name: ClassVar[str] = ""


@dataclass
class ConstantEnvironment(Environment):
    """Light arriving from every direction with the same radiance (the sky of a white furnace): in nits (cd/m^2,
    the default), or with ``unit`` "ev" the sky's colour scaled so that its luminance is an EV100, the sky's
    luminance then being (12.5 / 100) 2^EV cd/m^2 (scene/light_units.py)."""

    type_name: ClassVar[str] = "constant"
    radiance: RGB = field(default=(0.0, 0.0, 0.0), metadata={"range": (0.0, 1e6),
                                                             "doc": "cd/m^2 (nits) per channel, or an EV: see unit"})
    unit: str = field(default="nits", metadata={
        "choices": ("nits", "ev"),
        "doc": "what radiance's luminance gives: nits (cd/m^2), or an EV100 (luminance 0.125 x 2^EV cd/m^2)"})


@dataclass
class EnvironmentMap(Environment):
    """An HDR panorama in latitude-longitude layout (EXR, HDR, ...) wrapped around the scene.

    In its own frame the image's centre column looks down -Z and its top row straight up (+Y). ``rotation_deg``
    turns the panorama about that vertical axis (clockwise seen from above: the centre column moves towards +X),
    then ``zenith`` tilts it, by the shortest turn that takes +Y to ``zenith``: any orientation is one pair of
    the two (:meth:`world_from_map`, :func:`environment_orientation`).

    ``strength`` sets the radiance as ``unit`` says (scene/light_units.py): ``scale``, the default, multiplies
    the image's values (nits: a scene in arbitrary units, a Mitsuba import); ``nits`` is the map's mean luminance
    over the sphere in cd/m^2, the image scaled to have it; ``ev`` the same as an EV100, (12.5 / 100) 2^EV
    cd/m^2. Only an EV may be negative.
    """

    type_name: ClassVar[str] = "map"
    file: str = field(default="", metadata={"required": True, "doc": "lat-long image, relative to the scene"})
    # An EV may be negative (a night sky is EV -3): the range holds it, and a negative scale or nits are refused
    # by unit (light_units.check_environment_map). EV -64 is far darker than starlight (EV -6).
    strength: float = field(default=1.0, metadata={
        "range": (-64.0, 1e6),
        "doc": "multiplies the image (unit scale), its mean luminance in cd/m^2 (nits), or that as an EV100 (ev)"})
    unit: str = field(default="scale", metadata={
        "choices": ("scale", "nits", "ev"),
        "doc": "what strength gives: a scale of the image's values, the map's mean luminance over the sphere in "
               "nits (cd/m^2), or that luminance as an EV100"})
    rotation_deg: float = field(default=0.0, metadata={"range": (-360.0, 360.0)})
    rows: str = field(default="centred", metadata={
        "choices": ("centred", "pole_to_pole"),
        "doc": "how the image's rows meet the sphere: 'centred' (H rows of equal height, row i centred at polar "
               "angle pi (i + 1/2) / H: the usual layout) or 'pole_to_pole' (row i at pi i / (H - 1), the first "
               "and last rows on the poles: Mitsuba's envmap, which its importer sets)"})
    zenith: tuple[float, float, float] = field(default=(0.0, 1.0, 0.0), metadata={
        "nonzero_vector": True,
        "doc": "where the image's top row (its north pole) points; (0, 1, 0) is straight up"})

    def world_from_map(self) -> np.ndarray:
        """The 3x3 rotation taking a direction in the panorama's own frame to the world: the turn of
        ``rotation_deg`` about +Y, then the tilt that takes +Y to ``zenith``."""
        return _tilt_from_y(self.zenith) @ _turn_about_y(-self.rotation_deg)


def environment_orientation(world_from_map: np.ndarray) -> tuple[tuple[float, float, float], float]:
    """(zenith, rotation_deg) of an :class:`EnvironmentMap` whose panorama frame turns to the world by the
    rotation ``world_from_map`` (3x3, orthonormal, determinant +1): the inverse of ``world_from_map()``."""
    rotation = np.asarray(world_from_map, float)
    zenith = rotation[:, 1]
    about_y = _tilt_from_y(zenith).T @ rotation  # what is left once the tilt is undone fixes +Y
    angle = -math.degrees(math.atan2(about_y[0, 2], about_y[0, 0]))
    angle = (angle + 180.0) % 360.0 - 180.0
    return tuple(float(v) for v in zenith), (180.0 if angle == -180.0 else angle + 0.0)  # type: ignore[return-value]


def _turn_about_y(degrees: float) -> np.ndarray:
    """The right-handed rotation by ``degrees`` about +Y (counter-clockwise seen from above)."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _tilt_from_y(zenith) -> np.ndarray:
    """The shortest rotation taking +Y to the direction ``zenith`` (Rodrigues' formula about +Y x zenith);
    half a turn about +X for a zenith straight down, where every axis in the horizontal plane is as short."""
    z = np.asarray(zenith, float)
    norm = float(np.linalg.norm(z))
    if not norm > 0 or not math.isfinite(norm):
        raise ValueError("environment zenith must be a nonzero vector")
    z = z / norm
    axis = np.array([z[2], 0.0, -z[0]])  # +Y x zenith: its length is the sine of the angle
    sine = float(np.linalg.norm(axis))
    if sine < 1e-12:
        return np.eye(3) if z[1] > 0 else np.diag([1.0, -1.0, -1.0])
    k = axis / sine
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + sine * cross + (1.0 - z[1]) * (cross @ cross)


ENVIRONMENT_TYPES = {cls.type_name: cls for cls in (ConstantEnvironment, EnvironmentMap)}


@dataclass
class RenderSettings:
    spp: int = field(default=64, metadata={"range": (1, 1 << 24), "doc": "samples per pixel"})
    max_depth: int = field(
        default=8, metadata={"range": (1, 1024), "doc": "longest path in segments; 1 = emitters only, 2 = direct light"}
    )
    rr_depth: int = field(default=5, metadata={"range": (1, 1024), "doc": "path length at which Russian roulette starts"})
    seed: int = field(default=0, metadata={"range": (0, 2**31 - 1)})
    sampler: str = field(default="sobol", metadata={"choices": ("sobol", "independent")})
    pixel_filter: str = field(default="box", metadata={"choices": ("box", "gaussian"),
                                                      "doc": "how samples are spread over a pixel"})
    # What the film draws (a scene may hold it): past 1/1024 px a gaussian is narrower than the 1/4096-px buckets
    # trace.comp stores each sample's place in its pixel in; up to 32 px one smallest splat dispatch (LOCAL_SIZE_X
    # pixels, 32 x (2 ceil(4 sigma + 0.5) + 1)^2 terms a sample) stays within SPLAT_GATHER_TERMS (render/tracer.py).
    # The studio's field offers 0.05 to 4.
    filter_stddev: float = field(default=0.5, metadata={"range": (1.0 / 1024.0, 32.0), "controls": (0.05, 4.0),
                                                        "doc": "gaussian: standard deviation in pixels"})
    filter_weights: str = field(default="expected", metadata={
        "choices": ("expected", "sampled"),
        "doc": "gaussian: divide each pixel's weighted sum by the weight it expects (unbiased), or by the weights "
               "its samples drew (as Mitsuba: a little less noise, biased by O(1/spp))"})
    clamp: float = field(default=0.0, metadata={"range": (0.0, 1e9), "doc": "0 = off (unbiased); else the most "
                                                 "radiance one sample may add, to tame fireflies (biased)"})
    working_space: str = field(default=DEFAULT_WORKING_SPACE, metadata={
        "choices": tuple(WORKING_SPACES),
        "doc": "the RGB the scene's colours are in and the renderer computes in: linear Rec.709 (sRGB primaries), "
               "or ACEScg (docs/colour.md)"})


@dataclass
class Scene:
    camera: ThinLensCamera = field(default_factory=ThinLensCamera)
    environment: Environment = field(default_factory=ConstantEnvironment)
    render: RenderSettings = field(default_factory=RenderSettings)
    materials: dict[str, Material] = field(default_factory=dict)
    nodes: list[Node] = field(default_factory=list)
    lights: list[Light] = field(default_factory=list)
    # Where the scene came from: relative mesh paths resolve against its folder. Not saved.
    source_path: Path | None = field(default=None, compare=False, repr=False)

    def walk(self) -> Iterator[tuple[Node, np.ndarray]]:
        for root in self.nodes:
            yield from root.walk()

    def base_dir(self) -> Path:
        return self.source_path.parent if self.source_path else Path.cwd()

    def flatten(self, mesh_loader: Callable[[Path, bool, int], object] | None = None) -> "FlatScene":
        from lenslab.scene.flatten import flatten_scene

        return flatten_scene(self, mesh_loader)


DEFAULT_MATERIAL = Diffuse(albedo=(0.8, 0.8, 0.8))
