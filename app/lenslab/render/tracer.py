"""The progressive render session: accumulate samples into a float32 image in bounded GPU dispatches.

A :class:`Renderer` owns a GL context and the compiled trace kernels. A :class:`RenderSession` holds one
scene on the GPU and its accumulation buffer: each call to :meth:`RenderSession.step` runs dispatches for
about a given time and returns, so a caller can show, save or stop the image between any two dispatches.
Every dispatch is sized from the measured cost of the last one to stay near a target duration, well under
any GPU watchdog.

Each pixel's running sum is kept with its own weight (alpha channel: the sample count, or with a splatted
gaussian filter the expected sum of filter weights): the image is the sum divided by the weight, partial
renders can be merged by adding, and the same seed gives the same image however the work was split.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass
from typing import Callable

import moderngl
import numpy as np

from lenslab.optics.aperture import APERTURE_KINDS, Aperture
from lenslab.render import film, gl, kdtree_cache
from lenslab.render.buffers import GpuScene, pack_scene
from lenslab.render.instancing import INSTANCE_MIN_TRIANGLES, GroupCache
from lenslab.render.denoise import MAX_MEMORY_MB
from lenslab.render.features import GENERAL, KernelFeatures, scene_features
from lenslab.render.gpu_layout import (ACCUMULATION_BINDING, APERTURE_TABLE_UNIT, DISPLAY_BINDING, FEATURE_ROWS,
                                      FEATURES_BINDING, MAX_LENS_SURFACES, SHADING_ROWS,
                                      SPLAT_IMAGE_BINDING)
from lenslab.colour_management.view import ViewTransform
from lenslab.limits import SceneTooLarge, available_memory_bytes, format_bytes
from lenslab.render.sobol import glsl_array_literal
from lenslab.scene.camera import CameraFrame, ThinLensCamera
from lenslab.scene.flatten import flatten_scene, made_triangles
from lenslab.scene.scene import RenderSettings, Scene

LOCAL_SIZE_X = 32  # GPU-NOTES: 32x1 work groups traversed the kd-tree fastest on llvmpipe
DISPLAY_GROUP_X = 64  # display.comp's work groups: 64 pixels of a row
# display.comp includes OCIO's generated view transform under this name; its lookup tables take texture units from
# DISPLAY_FIRST_TEXTURE_UNIT on, clear of the trace kernel's (APERTURE_TABLE_UNIT).
OCIO_DISPLAY_INCLUDE = "ocio_display.glsl"
DISPLAY_FIRST_TEXTURE_UNIT = 4
DEFAULT_DISPATCH_SECONDS = 0.1
# A splatted gaussian keeps one pass of samples (16 bytes each) until splat.comp has spread them. One sample
# per pixel may take up to SPLAT_MEMORY_BYTES (a 3840 x 2160 image: 127 MiB; never more than one storage
# block); passes of several samples per pixel, which pay off on small images, stay within SPLAT_LAYERS_BYTES.
SPLAT_MEMORY_BYTES = 128 << 20
SPLAT_LAYERS_BYTES = 32 << 20
SPLAT_MAX_LAYERS = 64  # samples per pixel in one splatted pass
SPLAT_GATHER_TERMS = 1 << 22  # neighbour terms per splat.comp dispatch, to keep it short on any device
SAMPLE_INDEX_LIMIT = 1 << 32  # the kernel's sample index is a 32-bit unsigned integer
# The image's memory. Each pixel's running sum and weight take ACCUMULATION_BYTES_PER_PIXEL in one storage
# buffer; reading the finished image back and writing it takes HOST_BYTES_PER_PIXEL of the machine's memory
# at its peak (measured: 90 bytes a pixel writing a 2048 x 2048 PNG on llvmpipe, whose buffers are host
# memory too; 39 for an EXR), rounded up.
ACCUMULATION_BYTES_PER_PIXEL = 16
HOST_BYTES_PER_PIXEL = 96
# With the denoiser's feature buffers, their sums take FEATURE_BYTES_PER_PIXEL in a storage buffer of their own
# (the largest one then), and reading them back, denoising and writing an EXR with its extra layers takes
# HOST_FEATURE_BYTES_PER_PIXEL more of the machine's memory at the peak, and OIDN's scratch memory up to
# DENOISER_SCRATCH_BYTES besides (measured, a denoised EXR of the Cornell box: 0.87 GB more at 1024 x 1024,
# 1.21 GB at 2048 x 2048, about 0.76 GB and 108 bytes a pixel; rounded up).
FEATURE_BYTES_PER_PIXEL = 16 * FEATURE_ROWS
HOST_FEATURE_BYTES_PER_PIXEL = 192
DENOISER_SCRATCH_BYTES = MAX_MEMORY_MB << 20
# The storage buffers the trace kernel binds: the scene's six, image data, the accumulation, and the features.
TRACE_STORAGE_BLOCKS_WITH_FEATURES = 9
#: A triangle's bytes in the largest of the scene's storage buffers (buffers.py's shading rows).
GPU_BYTES_PER_TRIANGLE = SHADING_ROWS * 16
#: And in this machine's memory while the scene is flattened, packed and its kd-tree built: the float64 and
#: float32 copies of corners, normals and uvs, the packed rows, and about four kd-tree references at up to
#: 256 bytes each at the build's peak (render/bsp.py): rounded up from marbles_on_sand's million triangles.
HOST_BYTES_PER_TRIANGLE = 1536
# Mesa's llvmpipe advertises storage blocks of 128 MiB but binds any buffer it can make whole, and a Gallium
# buffer's size is a 32-bit number: 4 GiB less 16 bytes work, 4 GiB fails with "cannot map the buffer".
LLVMPIPE_BUFFER_BYTES = (1 << 32) - 1


def in_context(method):
    """Run a method with its object's GL context current (see gl.make_current)."""

    @functools.wraps(method)
    def with_context(self, *args, **kwargs):
        gl.make_current(self.ctx)
        return method(self, *args, **kwargs)

    return with_context


class Renderer:
    """A GL context and the trace kernels compiled for it (one per set of compile-time defines)."""

    def __init__(self, device_index: int | None = None, ctx=None):
        self.ctx = ctx if ctx is not None else gl.create_context(device_index)
        self.limits = gl.device_limits(self.ctx)
        self.largest_buffer_bytes = largest_storage_buffer(self.ctx.info["GL_RENDERER"], self.limits)
        self._programs: dict[tuple, object] = {}
        self._declared: dict[int, tuple[str, frozenset[str]]] = {}  # id(program): (shader, uniforms declared)
        self._luts: dict[str, list] = {}  # OCIO's lookup tables as textures, by the GLSL that samples them
        # Told the shader's name before a kernel is compiled (seconds on llvmpipe): the studio says so on screen.
        self.on_compile: Callable[[str], None] | None = None

    @in_context
    def program(self, shader: str, includes: dict[str, str] | None = None, **defines):
        """The compute shader glsl/<shader> compiled with these #defines, besides the buffer layout that
        gl.load_shader_source gives every shader, and with generated ``includes`` (compiled once, then cached)."""
        key = (shader, tuple(sorted(defines.items())), tuple(sorted((includes or {}).items())))
        if key not in self._programs:
            if self.on_compile is not None:
                self.on_compile(shader)
            source = gl.load_shader_source(shader, defines, includes=includes)
            program = self.ctx.compute_shader(source)
            self._programs[key] = program
            self._declared[id(program)] = (shader, gl.declared_uniforms(source))
        return self._programs[key]

    @in_context
    def set_uniforms(self, program, values: dict[str, object]) -> None:
        """Set uniforms of a program from :meth:`program` by name. The GLSL compiler drops the uniforms a
        kernel never reads, as a kernel specialised to a scene does for every feature it leaves out: such a
        name is skipped. A name the shader's source does not declare at all is misspelt or stale: it raises."""
        shader, declared = self._declared[id(program)]
        for name, value in values.items():
            if name in program:
                program[name].value = value
            elif name not in declared:
                raise KeyError(f"{shader} declares no uniform {name!r}")

    def trace_program(self, sampler: str, features: KernelFeatures = GENERAL, feature_buffers: bool = False):
        """The trace kernel for this sampler and these scene features; ``feature_buffers`` compiles in the
        denoiser's albedo and normal buffers (glsl/feature_buffers.glsl), a variant of its own."""
        defines = {"LOCAL_SIZE_X": LOCAL_SIZE_X, "SOBOL_DIRECTIONS": glsl_array_literal(),
                   **features.defines()}
        if feature_buffers:
            if self.limits.max_compute_storage_blocks < TRACE_STORAGE_BLOCKS_WITH_FEATURES:
                raise RuntimeError(f"this GL device lets a kernel bind {self.limits.max_compute_storage_blocks} storage "
                                   f"buffers; the denoiser's feature buffers need {TRACE_STORAGE_BLOCKS_WITH_FEATURES}")
            defines["HAS_FEATURE_BUFFERS"] = 1
        if sampler == "independent":
            defines["SAMPLER_INDEPENDENT"] = 1
        return self.program("trace.comp", **defines)

    def splat_program(self):
        return self.program("splat.comp", LOCAL_SIZE_X=LOCAL_SIZE_X)

    def display_program(self, view: ViewTransform):
        """display.comp with OCIO's GLSL for ``view``, its lookup tables bound to their texture units (made once
        per transform and kept), and the uniforms of its exposure and contrast set."""
        shader = view.gpu_shader()
        program = self.program("display.comp", includes={OCIO_DISPLAY_INCLUDE: shader.source},
                               LOCAL_SIZE_X=DISPLAY_GROUP_X)
        for unit, texture in enumerate(self._lookup_textures(shader), start=DISPLAY_FIRST_TEXTURE_UNIT):
            texture.use(unit)
            if texture.extra in program:
                program[texture.extra].value = unit
        self.set_uniforms(program, view.gpu_uniforms())
        return program

    def _lookup_textures(self, shader) -> list:
        """GL textures of OCIO's lookup tables for ``shader``: uploaded as OCIO's own GL code uploads them (its
        values in its order, float32), kept for as long as the renderer."""
        key = shader.source
        if key not in self._luts:
            textures = []
            for table in shader.textures:
                data = np.ascontiguousarray(table.values, np.float32)
                if data.ndim == 4:  # a 3D LUT: edge x edge x edge x 3
                    texture = self.ctx.texture3d(data.shape[2::-1], 3, data.tobytes(), dtype="f4")
                else:
                    texture = self.ctx.texture((data.shape[1], data.shape[0]), data.shape[2], data.tobytes(),
                                               dtype="f4")
                interpolation = moderngl.LINEAR if table.linear else moderngl.NEAREST
                texture.filter = (interpolation, interpolation)
                texture.repeat_x = texture.repeat_y = False
                if data.ndim == 4:
                    texture.repeat_z = False
                texture.extra = table.sampler
                textures.append(texture)
            self._luts[key] = textures
        return self._luts[key]

    def describe(self) -> dict[str, str]:
        return gl.describe_device(self.ctx)

    def release(self) -> None:
        gl.make_current(self.ctx)
        for program in self._programs.values():
            program.release()
        self._programs.clear()
        for textures in self._luts.values():
            for texture in textures:
                texture.release()
        self._luts.clear()
        self._declared.clear()
        self.ctx.release()


def largest_storage_buffer(renderer_name: str, limits: gl.DeviceLimits) -> int:
    """The largest storage buffer a kernel can bind whole on this device: the GL limit on one storage block,
    which llvmpipe does not hold to (see LLVMPIPE_BUFFER_BYTES)."""
    if "llvmpipe" in renderer_name:
        return max(limits.max_storage_block_bytes, LLVMPIPE_BUFFER_BYTES)
    return limits.max_storage_block_bytes


def check_image_size(width: int, height: int, largest_buffer_bytes: int, memory_bytes: int | None,
                     feature_buffers: bool = False) -> None:
    """Refuse, in one line, an image whose accumulation buffer (or feature buffer) the device cannot bind or whose
    read-back the machine's memory (``memory_bytes`` available, None: unknown) cannot hold, saying the largest
    image of the same shape that fits."""
    pixels = width * height
    buffer_bytes, what = ((FEATURE_BYTES_PER_PIXEL, "feature buffer") if feature_buffers
                          else (ACCUMULATION_BYTES_PER_PIXEL, "accumulation buffer"))
    host_bytes = HOST_BYTES_PER_PIXEL + (HOST_FEATURE_BYTES_PER_PIXEL if feature_buffers else 0)
    scratch = DENOISER_SCRATCH_BYTES if feature_buffers else 0
    most_pixels = largest_buffer_bytes // buffer_bytes
    needs = f"needs {buffer_bytes * pixels:,} bytes of {what}"
    holder, holds = "this device", f"the largest storage buffer it binds is {largest_buffer_bytes:,} bytes"
    if memory_bytes is not None and max(0, memory_bytes - scratch) // host_bytes < most_pixels:
        most_pixels = max(0, memory_bytes - scratch) // host_bytes
        needs = f"needs {format_bytes(host_bytes * pixels + scratch)} of memory ({host_bytes} bytes a pixel" + (
            f" and {format_bytes(scratch)} for the denoiser)" if scratch else ")")
        holder, holds = "this machine", f"{format_bytes(memory_bytes)} of memory is available"
    if pixels <= most_pixels:
        return
    fit_width, fit_height = largest_image_within(width, height, most_pixels)
    raise SceneTooLarge(f"a {width} x {height} image {needs}; {holder} holds at most {fit_width} x {fit_height} "
                        f"({holds})")


def check_triangle_count(count: int, what: str, largest_block_bytes: int, memory_bytes: int | None) -> None:
    """Refuse, in one line, more triangles than the device's largest storage buffer holds (GpuScene's limit)
    or than this machine's memory (``memory_bytes`` available, None: unknown) can flatten and build a tree for."""
    limits = [(largest_block_bytes // GPU_BYTES_PER_TRIANGLE,
               f"the GL device's largest storage buffer ({format_bytes(largest_block_bytes)}) holds")]
    if memory_bytes is not None:
        limits.append((memory_bytes // HOST_BYTES_PER_TRIANGLE,
                       f"this machine's {format_bytes(memory_bytes)} of available memory can build"))
    most, holder = min(limits)
    if count > most:
        raise SceneTooLarge(f"{what} {count:,} triangles; {holder} at most {most:,}")


def largest_image_within(width: int, height: int, most_pixels: int) -> tuple[int, int]:
    """The largest image of (about) the shape width : height with at most ``most_pixels`` pixels."""
    scale = math.sqrt(most_pixels / (width * height))
    # At least a pixel each way: a strip too thin to scale down keeps its one row (or column) and gets shorter.
    fit_width, fit_height = max(1, int(width * scale)), max(1, int(height * scale))
    while fit_width * fit_height > most_pixels:  # rounding or that one pixel made it too large: trim the longer side
        if fit_width >= fit_height:
            fit_width -= 1
        else:
            fit_height -= 1
    return fit_width, fit_height


def camera_uniforms(frame: CameraFrame) -> dict[str, object]:
    """glsl/camera.glsl's uniforms: the camera's frame for an image, as the host computes it. The aperture's tables
    go to the GPU apart (:class:`ApertureTable`)."""
    aperture = frame.aperture
    arc_centre, arc_radius, area = aperture.blade_geometry if aperture.blades >= 3 else (0.0, 0.0, math.pi)
    (gain_x, gain_y), barrel_radius = frame.barrel_opening
    rows, cols = aperture.image.shape if aperture.image is not None else (0, 0)
    return {
        "cam_position": tuple(float(v) for v in frame.position),
        "cam_to_world": tuple(float(v) for v in frame.to_world.T.reshape(-1)),  # column-major: right, up, back
        "cam_tan_half_fov": tuple(float(t) for t in frame.tan_half_fov),
        "cam_lens_radius": float(frame.lens_radius),
        "cam_focus_distance": float(frame.focus_distance),
        "cam_aperture_kind": APERTURE_KINDS[aperture.kind],
        "cam_blades": int(aperture.blades),
        "cam_blade_rotation": float(aperture.rotation_rad),
        "cam_blade_arc": (float(arc_centre), float(min(arc_radius, 1e30))),
        "cam_blade_wedge_area": float(area / max(aperture.blades, 1)),
        "cam_aperture_axes": tuple(float(a) for a in aperture.axes),
        "cam_barrel_gain": (float(gain_x), float(gain_y)),
        "cam_barrel_radius": float(barrel_radius) if frame.barrel_clipping > 0.0 else 0.0,
        "cam_aperture_image_size": (int(cols), int(rows)),
        "aperture_table": APERTURE_TABLE_UNIT,
        "image_size": (frame.width, frame.height),
        **real_lens_uniforms(frame),
    }


def real_lens_uniforms(frame: CameraFrame) -> dict[str, object]:
    """glsl/real_lens.glsl's uniforms: the lens's surfaces where they stand at this focus, their indices at each
    channel's wavelength, the stop and the exit pupil's table (lens_surface_count 0: the thin lens)."""
    setting = frame.real_lens
    if setting is None:
        return {"lens_surface_count": 0}
    system = setting.system
    count = len(system.radius)
    vertex_z = system.vertex_z(setting.shift)
    surfaces = [(float(system.radius[k]), float(vertex_z[k]), float(system.aperture_radius[k]), 0.0)
                for k in range(count)] + [(0.0, 0.0, 0.0, 0.0)] * (MAX_LENS_SURFACES - count)
    iors = [tuple(float(n) for n in row) for row in setting.channel_iors] + [(1.0, 1.0, 1.0)] * (
        MAX_LENS_SURFACES - count)
    return {
        "lens_surface_count": count,
        "lens_surfaces": surfaces,
        "lens_iors": iors,
        "lens_dispersive": int(setting.dispersive),
        "lens_stop_radius": float(setting.stop_radius),
        "lens_sensor_z": float(setting.sensor_z),
        "lens_rear_z": float(setting.rear_z),
        "lens_film_half": (float(frame.film_mm[0] / 2.0), float(frame.film_mm[1] / 2.0)),
        "lens_film_radius": float(setting.film_radius_mm),
        "lens_weight_scale": float(setting.weight_scale),
        "lens_pupil": [tuple(float(v) for v in box) for box in setting.pupil_bounds],
        "lens_pupil_disk": [tuple(float(v) for v in disk) for disk in setting.pupil_disks],
    }


class ApertureTable:
    """The aperture's cumulative tables (``Aperture.table``) as a float texture that glsl/camera.glsl reads
    with texelFetch; uploaded again only when the table changes."""

    def __init__(self, ctx):
        self.ctx = ctx
        self._texture = None
        self._key = None

    def bind(self, aperture: Aperture) -> None:
        table = aperture.table
        key = (table.shape, table.tobytes())
        if key != self._key:
            self.release()
            rows, cols = table.shape
            self._texture = self.ctx.texture((cols, rows), 1, np.ascontiguousarray(table).tobytes(), dtype="f4")
            self._texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self._key = key
        self._texture.use(APERTURE_TABLE_UNIT)

    def release(self) -> None:
        if self._texture is not None:
            self._texture.release()
            self._texture = None
            self._key = None


@dataclass(frozen=True)
class Pick:
    point: np.ndarray  # world position of the hit
    depth: float  # distance along the view axis: what focus_distance_m must be for this point to be sharp
    prim: int
    node: object  # the scene Node that owns the primitive
    node_index: int  # that node's index in the flattened scene's nodes (depth first)


class _TimedMeshReads:
    """flatten_scene's mesh loader (scene/io/meshes.load_mesh_parts), adding up the seconds spent in it."""

    def __init__(self):
        self.seconds = 0.0

    def __call__(self, path, smooth: bool, shape_index: int):
        from lenslab.scene.io.meshes import load_mesh_parts

        start = time.perf_counter()
        try:
            return load_mesh_parts(path, smooth, shape_index)
        finally:
            self.seconds += time.perf_counter() - start


@dataclass(frozen=True)
class SceneLoad:
    """Where the time of the last set_scene went, in seconds, and what it made (the CLI's load line, the
    benchmarks). ``read``: reading mesh files (nothing when they were read before and are unchanged);
    ``place``: placing every primitive (scene/flatten.py); ``trees``: building or reading back the kd-trees; ``pack``: the rest of the packing (materials, lights, textures, joining the
    layers); ``upload``: the buffers to the device; ``kernel``: choosing (and, the first time, compiling) it."""

    read: float
    place: float
    trees: float
    pack: float
    upload: float
    kernel: float
    trees_built: int  # kd-trees built or read back (the world's, and the mesh groups' not kept from before)
    trees_from_cache: int  # of those, read back from the on-disk cache
    mesh_trees_built: int  # of those, mesh groups' (render/instancing.py): 0 after an edit that kept every mesh
    uploaded_bytes: int  # sent to the device (buffers kept from before the edit are not: buffers.GpuScene)

    @property
    def total(self) -> float:
        return self.read + self.place + self.trees + self.pack + self.upload + self.kernel

    def describe_steps(self) -> str:
        """Every step but the trees' (which the CLI's load line names with the trees)."""
        return (f"mesh files read in {self.read:.2f} s, placed in {self.place:.2f} s, packed in {self.pack:.2f} s, "
                f"uploaded in {self.upload:.2f} s, kernel ready in {self.kernel:.2f} s")


@dataclass(frozen=True)
class Progress:
    samples_per_pixel: int  # every pixel has at least this many
    target_spp: int | None
    elapsed_seconds: float
    samples_per_second: float


#: The steps of RenderSession.set_scene, in order, as on_stage is told them.
SCENE_STAGES = ("reading and placing", "building the kd-tree", "packing", "uploading", "preparing the kernel")


class RenderSession:
    """One scene on the GPU, one image accumulating. Not thread-safe: use it from the context's thread."""

    def __init__(self, renderer: Renderer, scene: Scene, *, width: int | None = None, height: int | None = None,
                 settings: RenderSettings | None = None, dispatch_seconds: float = DEFAULT_DISPATCH_SECONDS,
                 environment_importance: bool = True, specialise: bool = True, first_sample: int = 0,
                 feature_buffers: bool = False, on_stage: Callable[[str], None] | None = None):
        if not 0 <= first_sample < SAMPLE_INDEX_LIMIT:
            raise ValueError(f"first sample index {first_sample} is out of range [0, {SAMPLE_INDEX_LIMIT})")
        self.renderer = renderer
        # Sample indices start here: renders of disjoint index ranges of one seed add up to one render of them
        # all (render/job.py; lenslab.batch splits a shot across workers this way).
        self.first_sample = first_sample
        self.specialise = specialise  # False: the general kernel, whatever the scene uses (for comparisons)
        self.environment_importance = environment_importance
        self.ctx = renderer.ctx
        self.dispatch_seconds = dispatch_seconds
        self._gpu_scene: GpuScene | None = None
        self._accumulation = None
        self._splat_samples = None  # one pass of radiance samples, while a gaussian filter is splatted
        self._display_pixels = None  # display.comp's 8-bit picture
        self._display_source = None  # display_image's linear image, on its way to display.comp
        # The denoiser's guides: first-hit albedo and normal sums beside the image (set_feature_buffers).
        self.feature_buffers = bool(feature_buffers)
        self._features = None
        self._aperture_table = ApertureTable(self.ctx)
        self._groups = GroupCache()  # the mesh groups' trees and rows, kept across edits
        # How the camera frames the image: None, as the export does (camera.frame); a margin, as the studio's
        # viewport does, showing the export's frame and some of the scene around it (camera.view_frame).
        self.view_margin: float | None = None
        self.region: tuple[int, int, int, int] | None = None  # (x, y, width, height): render only these pixels
        # Told each step of set_scene as it begins (one of SCENE_STAGES): the studio shows how far a load is.
        self.on_stage = on_stage
        self.set_scene(scene, width=width, height=height, settings=settings)

    # -- scene and camera ---------------------------------------------------------------------------------
    @in_context
    def set_scene(self, scene: Scene, *, width: int | None = None, height: int | None = None,
                  settings: RenderSettings | None = None) -> None:
        """Upload a (new or edited) scene and restart accumulation."""
        width = int(width or scene.camera.resolution[0])
        height = int(height or scene.camera.resolution[1])
        self._check_image_size(width, height)  # before the kd-tree build: an image too large is refused at once
        # Triangles made in code (a relief of 8192 x 8192 vertices is 134 M) are counted before they are made,
        # and those of mesh files once read, before the kd-tree build: a scene too large is refused at once.
        made, largest = made_triangles(scene)
        self._check_triangle_count(made, f"the shapes made in code (node '{largest}' the most) make")
        start = time.perf_counter()
        self._stage("reading and placing")
        # Large meshes stay in their own space with trees of their own, kept from one edit to the next
        # (render/instancing.py): an edit that leaves a mesh as it was never rebuilds its tree.
        reading = _TimedMeshReads()
        flat_scene = flatten_scene(scene, mesh_loader=reading, instance_min_triangles=INSTANCE_MIN_TRIANGLES,
                                   known_groups=self._groups.known_groups())
        self._check_triangle_count(flat_scene.stored_triangle_count, "the scene has")
        placed = time.perf_counter()
        self.scene = scene
        self.settings = settings or scene.render
        self.flat_scene = flat_scene
        if (width, height) != (getattr(self, "width", None), getattr(self, "height", None)):
            self.region = None  # its pixels were another image's
        self._stage("building the kd-tree")
        world_tree = kdtree_cache.kdtree(flat_scene.prim_bounds(), triangles=flat_scene.triangles)
        packed_groups = self._groups.packed_groups(flat_scene)
        trees = time.perf_counter()
        self._stage("packing")
        packed = pack_scene(self.flat_scene, scene.environment, kdtree=world_tree, base_dir=scene.base_dir(),
                            lights=scene.lights, environment_importance=self.environment_importance,
                            packed_groups=packed_groups, group_cache=self._groups,
                            working_space=scene.render.working_space)
        packing = time.perf_counter()
        # What the render survives but the user should hear about: unmapped mesh materials, missing textures.
        self.warnings = [*self.flat_scene.warnings, *packed.warnings]
        self._stage("uploading")
        gpu_scene = GpuScene(self.ctx, packed, self.renderer.limits.max_storage_block_bytes, previous=self._gpu_scene)
        if self._gpu_scene is not None:
            self._gpu_scene.release()
        self._gpu_scene = gpu_scene
        uploaded = time.perf_counter()
        self.width, self.height = width, height
        self.features = scene_features(packed) if self.specialise else GENERAL
        self._stage("preparing the kernel")
        self.program = self._trace_program(self.settings.sampler)
        self.set_camera(scene.camera)
        built = [world_tree, *self._groups.new_trees]
        self.load = SceneLoad(read=reading.seconds, place=placed - start - reading.seconds, trees=trees - placed, pack=packing - trees, upload=uploaded - packing,
                              kernel=time.perf_counter() - uploaded, trees_built=len(built),
                              trees_from_cache=sum(tree.from_cache for tree in built),
                              mesh_trees_built=self._groups.built, uploaded_bytes=gpu_scene.uploaded_bytes)

    def _stage(self, name: str) -> None:
        if self.on_stage is not None:
            self.on_stage(name)

    @in_context
    def set_camera(self, camera: ThinLensCamera) -> None:
        """A camera-only edit: no re-upload of geometry, just restart accumulation."""
        camera.validate()
        self.camera = camera
        self._frame_camera()
        self.reset()

    def _frame_camera(self) -> None:
        if self.view_margin is None:
            self.frame = self.camera.frame(self.width, self.height, base_dir=self.scene.base_dir())
        else:
            self.frame = self.camera.view_frame(self.width, self.height, self.view_margin,
                                                base_dir=self.scene.base_dir())

    @in_context
    def set_view(self, width: int, height: int, margin: float | None = None) -> None:
        """A new image size, and how the camera frames it (see view_margin); restarts accumulation and drops
        any render region."""
        self._check_image_size(int(width), int(height))
        self.width, self.height = int(width), int(height)
        self.view_margin = margin
        self.region = None
        self._frame_camera()
        self.reset()

    @in_context
    def set_region(self, region: tuple[int, int, int, int] | None) -> None:
        """Render only the pixels of ``region`` (x, y, width, height; clipped to the image) from now on, or the
        whole image (None). Restarts accumulation: pixels outside the region stay without samples."""
        if region is not None:
            x, y, w, h = (int(round(v)) for v in region)
            x0, y0 = min(max(x, 0), self.width), min(max(y, 0), self.height)
            x1, y1 = min(max(x + w, 0), self.width), min(max(y + h, 0), self.height)
            region = (x0, y0, x1 - x0, y1 - y0) if x1 > x0 and y1 > y0 else None
        self.region = region
        self.reset()

    @property
    def region_pixels(self) -> tuple[int, int, int, int]:
        """The pixels each pass renders: the render region, or the whole image."""
        return self.region if self.region is not None else (0, 0, self.width, self.height)

    @in_context
    def set_settings(self, settings: RenderSettings) -> None:
        if settings.sampler != self.settings.sampler:
            self.program = self._trace_program(settings.sampler)
        self.settings = settings
        self.reset()

    def _check_triangle_count(self, count: int, what: str) -> None:
        check_triangle_count(count, what, self.renderer.limits.max_storage_block_bytes, available_memory_bytes())

    def _check_image_size(self, width: int, height: int) -> None:
        """Refuse an image this device or machine cannot hold (check_image_size), before allocating for it."""
        check_image_size(width, height, self.renderer.largest_buffer_bytes, available_memory_bytes(),
                         self.feature_buffers)

    @in_context
    def set_feature_buffers(self, on: bool) -> None:
        """Accumulate the denoiser's guides (first-hit albedo and normal, :meth:`features_image`) beside the image,
        or stop. The kernel with them is a variant of its own (compiled once, then cached); restarts accumulation.
        Without them the kernel is exactly the one before (HAS_FEATURE_BUFFERS 0), and the image is the same."""
        on = bool(on)
        if on == self.feature_buffers:
            return
        previous = self.feature_buffers
        self.feature_buffers = on
        try:
            self._check_image_size(self.width, self.height)
            self.program = self._trace_program(self.settings.sampler)
        except Exception:
            self.feature_buffers = previous
            raise
        self.reset()

    @property
    def splat_layers(self) -> int:
        """Samples per pixel one pass may take while splatting a gaussian filter; 0: samples are not splatted
        (a box filter, or a gaussian by filter importance sampling where a pass would not fit in memory or only
        a render region is rendered: splat.comp spreads whole images)."""
        if self.settings.pixel_filter != "gaussian" or self.region is not None:
            return 0
        layer_bytes = 16 * self.width * self.height
        if layer_bytes > min(SPLAT_MEMORY_BYTES, self.renderer.limits.max_storage_block_bytes):
            return 0
        return max(1, min(SPLAT_MAX_LAYERS, SPLAT_LAYERS_BYTES // layer_bytes))

    @property
    def gpu_scene(self) -> GpuScene:
        """The scene's buffers on the GPU, for ray queries that share them (lenslab.render.raycast)."""
        return self._gpu_scene

    @property
    def kdtree(self):
        """The scene's kd-tree as built for the GPU (its size and build time, for progress reports)."""
        return self._gpu_scene.packed.kdtree

    def _trace_program(self, sampler: str):
        return self.renderer.trace_program(sampler, self.features, self.feature_buffers)

    @in_context
    def reset(self) -> None:
        """Discard the accumulated samples (after any edit)."""
        pixels = self.width * self.height
        if self._accumulation is None or self._accumulation.size != pixels * ACCUMULATION_BYTES_PER_PIXEL:
            self._check_image_size(self.width, self.height)  # the studio resizes the image through here
            if self._accumulation is not None:
                self._accumulation.release()
            self._accumulation = self.ctx.buffer(reserve=pixels * ACCUMULATION_BYTES_PER_PIXEL)
        self._accumulation.clear()
        layers = self.splat_layers
        if layers and (self._splat_samples is None or self._splat_samples.size != 16 * pixels * layers):
            self._release_splat_samples()
            self._splat_samples = self.ctx.buffer(reserve=16 * pixels * layers)
        elif not layers:
            self._release_splat_samples()
        if not self.feature_buffers:
            self._release_features()
        elif self._features is None or self._features.size != pixels * FEATURE_BYTES_PER_PIXEL:
            self._release_features()
            self._features = self.ctx.buffer(reserve=pixels * FEATURE_BYTES_PER_PIXEL)
        if self._features is not None:
            self._features.clear()
        if self.settings.pixel_filter == "gaussian" and not layers and self.region is None:
            warning = (f"a {self.width}x{self.height} image is too large to splat its gaussian pixel filter on this "
                       "device: it is sampled by importance instead (the same image, more noise)")
            if warning not in self.warnings:
                self.warnings.append(warning)
        self._pixels_done = 0  # pixels of the current pass that have their samples
        self.samples_per_pixel = 0  # completed passes, in samples
        self._pass_samples = 1
        self._seconds_per_pixel_sample = None
        self.elapsed_seconds = 0.0
        self._samples_traced = 0

    # -- rendering ----------------------------------------------------------------------------------------
    def trace_uniforms(self) -> dict[str, object]:
        """The uniforms the trace kernel is given by name before each step: the scene's, the camera's and the
        settings' (each dispatch then sets its own tile and samples). The general kernel reads every one."""
        values = dict(self._gpu_scene.packed.uniforms)
        if self.features.flat_primitives:  # only a kernel that loops over the world's primitives reads where they start
            values["first_world_prim"] = self._gpu_scene.packed.first_world_prim
        values.update(camera_uniforms(self.frame))
        splat_pixels = self.width * self.height if self._splat_samples is not None else 0
        values.update(max_depth=self.settings.max_depth, rr_depth=self.settings.rr_depth, seed=self.settings.seed,
                      clamp_max=self.settings.clamp, splat_pixels=splat_pixels,
                      filter_stddev=self.settings.filter_stddev if self.settings.pixel_filter == "gaussian" else 0.0)
        return values

    def _set_uniforms(self) -> None:
        self.renderer.set_uniforms(self.program, self.trace_uniforms())

    def _plan_dispatch(self, target_spp: int | None) -> tuple[int, int]:
        """(pixels, samples) for the next dispatch, aiming at dispatch_seconds of GPU time."""
        pixels_total = self.region_pixels[2] * self.region_pixels[3]
        remaining_pixels = pixels_total - self._pixels_done
        if self._seconds_per_pixel_sample is None:
            return min(remaining_pixels, 16384), 1  # a small first dispatch to measure the cost
        budget = self.dispatch_seconds / self._seconds_per_pixel_sample  # pixel-samples that fit
        # A device runs at most so many work groups in one dispatch (65535 on some: 2 M pixels).
        most_pixels = self.renderer.limits.max_work_group_count[0] * LOCAL_SIZE_X
        if self._pixels_done == 0 and budget >= 2 * pixels_total and pixels_total <= most_pixels:
            # The whole image fits more than twice: take several samples per pixel in one dispatch.
            samples = max(1, int(budget // pixels_total))
            if target_spp is not None:
                samples = min(samples, target_spp - self.samples_per_pixel)
            if self._splat_samples is not None:
                samples = min(samples, self.splat_layers)
            self._pass_samples = samples
            return pixels_total, samples
        if self._pixels_done == 0:
            self._pass_samples = 1
        pixels = int(max(LOCAL_SIZE_X, budget // self._pass_samples))
        pixels = min(remaining_pixels, most_pixels, (pixels + LOCAL_SIZE_X - 1) // LOCAL_SIZE_X * LOCAL_SIZE_X)
        return pixels, self._pass_samples

    def _dispatch(self, pixels: int, samples: int) -> None:
        program = self.program
        program["region"].value = self.region_pixels
        program["tile_start"].value = self._pixels_done
        program["tile_pixels"].value = pixels
        program["sample_start"].value = self.first_sample + self.samples_per_pixel
        program["sample_count"].value = samples
        groups = (pixels + LOCAL_SIZE_X - 1) // LOCAL_SIZE_X
        start = time.perf_counter()
        program.run(groups, 1, 1)
        self.ctx.finish()  # bound the work in flight: the caller may read or stop right after
        seconds = time.perf_counter() - start
        self.elapsed_seconds += seconds
        self._samples_traced += pixels * samples
        measured = seconds / (pixels * samples)
        previous = self._seconds_per_pixel_sample
        self._seconds_per_pixel_sample = measured if previous is None else 0.5 * (previous + measured)
        self._pixels_done += pixels
        if self._pixels_done >= self.region_pixels[2] * self.region_pixels[3]:
            if self._splat_samples is not None:
                self._splat_pass(samples)
            self._pixels_done = 0
            self.samples_per_pixel += samples

    def _splat_pass(self, samples: int) -> None:
        """Spread a finished pass of samples over the pixels their gaussian filter reaches (splat.comp)."""
        program = self.renderer.splat_program()
        reach = int(np.ceil(4.0 * self.settings.filter_stddev + 0.5))
        terms_per_pixel = samples * (2 * reach + 1) ** 2
        pixels_total = self.width * self.height
        chunk = max(LOCAL_SIZE_X, SPLAT_GATHER_TERMS // terms_per_pixel // LOCAL_SIZE_X * LOCAL_SIZE_X)
        self._accumulation.bind_to_storage_buffer(SPLAT_IMAGE_BINDING)
        for name, value in (("image_size", (self.width, self.height)), ("sample_count", samples),
                            ("filter_stddev", self.settings.filter_stddev),
                            ("sampled_weights", self.settings.filter_weights == "sampled")):
            program[name].value = value
        start = time.perf_counter()
        for first in range(0, pixels_total, chunk):
            count = min(chunk, pixels_total - first)
            program["tile_start"].value = first
            program["tile_pixels"].value = count
            program.run((count + LOCAL_SIZE_X - 1) // LOCAL_SIZE_X, 1, 1)
            self.ctx.finish()
        self.elapsed_seconds += time.perf_counter() - start
        self._bind_trace_buffers()  # binding 0 is the kd-tree's again

    @in_context
    def step(self, seconds: float, target_spp: int | None = None) -> Progress:
        """Render for at most about ``seconds`` (but at least one dispatch) or until ``target_spp`` is reached.

        A dispatch is not started when the time it is expected to take would run past the deadline: the
        studio asks for a frame's worth of work and must get its picture within that frame, not one dispatch
        late."""
        self._bind_trace_buffers()
        self._set_uniforms()
        deadline = time.perf_counter() + seconds
        first = True
        while target_spp is None or self.samples_per_pixel < target_spp:
            pixels, samples = self._plan_dispatch(target_spp)
            if not first and time.perf_counter() + self._expected_seconds(pixels, samples) > deadline:
                break
            self._dispatch(pixels, samples)
            first = False
        return self.progress(target_spp)

    def _expected_seconds(self, pixels: int, samples: int) -> float:
        """How long a dispatch of ``pixels`` x ``samples`` should take, from the cost measured so far."""
        return pixels * samples * (self._seconds_per_pixel_sample or 0.0)

    def _bind_trace_buffers(self) -> None:
        self._gpu_scene.bind()
        self._aperture_table.bind(self.frame.aperture)
        target = self._splat_samples if self._splat_samples is not None else self._accumulation
        target.bind_to_storage_buffer(ACCUMULATION_BINDING)
        if self._features is not None:
            self._features.bind_to_storage_buffer(FEATURES_BINDING)

    @property
    def pass_fraction(self) -> float:
        """How much of the pass under way has its samples, 0 to 1 (0 between passes)."""
        _x, _y, w, h = self.region_pixels
        return self._pixels_done / max(1, w * h)

    def done(self, target_spp: int) -> bool:
        return self.samples_per_pixel >= target_spp

    def progress(self, target_spp: int | None = None) -> Progress:
        rate = self._samples_traced / self.elapsed_seconds if self.elapsed_seconds > 0 else 0.0
        return Progress(self.samples_per_pixel, target_spp, self.elapsed_seconds, rate)

    # -- ray queries --------------------------------------------------------------------------------------
    @in_context
    def pick(self, x: float, y: float) -> "Pick | None":
        """The surface seen through the lens centre at image position (x, y) in pixels, (0, 0) top left."""
        from lenslab.render.raycast import cast_rays

        frame = self.frame
        origins, directions, looks_out = frame.rays([(x, y)], with_weights=True)
        if not np.max(looks_out) > 0.0:  # beyond a fisheye's image circle: no ray from there leaves the lens
            return None
        hits = cast_rays(self.renderer, self._gpu_scene, origins, directions)
        prim = int(hits.prim[0])
        if prim < 0:
            return None
        point = origins[0] + float(hits.t[0]) * directions[0]
        node_index = int(self.hit_nodes(hits)[0])
        return Pick(point=point, depth=frame.depth_of(point), prim=prim, node=self.flat_scene.nodes[node_index],
                    node_index=node_index)

    def hit_nodes(self, hits) -> np.ndarray:
        """The index (into flat_scene.nodes) of the node each of cast_rays' hits landed on, -1 for none."""
        return hits.nodes(self.flat_scene, self._gpu_scene.packed.first_world_prim)

    # -- reading the image --------------------------------------------------------------------------------
    @in_context
    def accumulation(self) -> np.ndarray:
        """(H, W, 4) float32: radiance sums and sample counts; rows top to bottom."""
        return self._read_accumulation().copy()

    @in_context
    def _read_accumulation(self) -> np.ndarray:
        """The accumulation as read back: a read-only view of the bytes, for callers that only read it."""
        data = np.frombuffer(self._accumulation.read(), dtype=np.float32)
        return data.reshape(self.height, self.width, 4)

    def image(self) -> np.ndarray:
        """(H, W, 3) float32 linear radiance: the mean of the samples so far."""
        return film.resolve(self._read_accumulation())

    @in_context
    def feature_accumulation(self) -> np.ndarray:
        """(H, W, FEATURE_ROWS, 4) float32: the denoiser's guide sums (albedo and sample count, normal and 0)."""
        if self._features is None:
            raise RuntimeError("this render session has no feature buffers (set_feature_buffers(True) first)")
        data = np.frombuffer(self._features.read(), dtype=np.float32)
        return data.reshape(self.height, self.width, FEATURE_ROWS, 4)  # read-only: resolve_features copies

    def features_image(self) -> tuple[np.ndarray, np.ndarray]:
        """(albedo, normal), each (H, W, 3) float32: the mean first-hit albedo in [0, 1] and world-space shading
        normal in [-1, 1] (not unit length) over each pixel's samples so far (glsl/feature_buffers.glsl);
        zero where a pixel has none. The guides OIDN takes beside the image (render/denoise.py)."""
        return film.resolve_features(self.feature_accumulation())

    @in_context
    def display(self, view: ViewTransform = ViewTransform()) -> np.ndarray:
        """(H, W, 4) uint8 RGBA: the image as a screen shows it through ``view``, made on the GPU (display.comp:
        the steps of film.display_pixels, with OCIO's GLSL); alpha 0 where a pixel has no sample yet. A quarter of
        the bytes of :meth:`accumulation` cross to the CPU, and no per-pixel work is left for it."""
        return self._display_from(self._accumulation, view)

    @in_context
    def display_image(self, image: np.ndarray, view: ViewTransform = ViewTransform()) -> np.ndarray:
        """:meth:`display` of another linear image (H, W, 3) of this session's size, such as the denoiser's: it
        goes up to the GPU once and comes back as RGBA8, instead of going through OCIO's CPU processor (at
        1920 x 1080, a few milliseconds against a tenth of a second)."""
        if image.shape[:2] != (self.height, self.width):
            raise ValueError(f"an image of {image.shape[1]} x {image.shape[0]} pixels is not this session's "
                             f"{self.width} x {self.height}")
        rgba = np.ones((self.height, self.width, 4), np.float32)  # weight 1: display.comp's resolve is a no-op
        rgba[..., :3] = image
        if self._display_source is None or self._display_source.size != rgba.nbytes:
            self._release_display_source()
            self._display_source = self.ctx.buffer(reserve=rgba.nbytes)
        self._display_source.write(rgba)
        return self._display_from(self._display_source, view)

    def _display_from(self, source, view: ViewTransform) -> np.ndarray:
        pixels = self.width * self.height
        if self._display_pixels is None or self._display_pixels.size != 4 * pixels:
            self._release_display_pixels()
            self._display_pixels = self.ctx.buffer(reserve=4 * pixels)
        program = self.renderer.display_program(view)
        program["image_size"].value = (self.width, self.height)
        source.bind_to_storage_buffer(ACCUMULATION_BINDING)
        self._display_pixels.bind_to_storage_buffer(DISPLAY_BINDING)
        program.run((self.width + DISPLAY_GROUP_X - 1) // DISPLAY_GROUP_X, self.height, 1)
        self.ctx.memory_barrier()  # the shader's writes must be visible to the read that follows
        data = np.frombuffer(self._display_pixels.read(), dtype=np.uint8)
        return data.reshape(self.height, self.width, 4).copy()

    def _release_display_pixels(self) -> None:
        if self._display_pixels is not None:
            self._display_pixels.release()
            self._display_pixels = None

    def _release_display_source(self) -> None:
        if self._display_source is not None:
            self._display_source.release()
            self._display_source = None

    def _release_splat_samples(self) -> None:
        if self._splat_samples is not None:
            self._splat_samples.release()
            self._splat_samples = None

    def _release_features(self) -> None:
        if self._features is not None:
            self._features.release()
            self._features = None

    @in_context
    def release(self) -> None:
        self._aperture_table.release()
        self._release_splat_samples()
        self._release_features()
        self._release_display_pixels()
        self._release_display_source()
        if self._gpu_scene is not None:
            self._gpu_scene.release()
            self._gpu_scene = None
        if self._accumulation is not None:
            self._accumulation.release()
            self._accumulation = None
