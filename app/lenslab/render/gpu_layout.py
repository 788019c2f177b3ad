"""What the host and the shaders must agree on, declared once: record sizes, type codes and binding points.

Python packs the scene's buffers with these values (render/buffers.py, render/textures.py, render/bsp.py)
and gl.load_shader_source hands every one of them to every compute shader as a #define of the same name
(:func:`glsl_defines`). No GLSL file types these numbers itself, so a shader compiled without them fails to
compile instead of reading the buffers askew.
"""


from __future__ import annotations

import math

from lenslab.optics.aperture import APERTURE_KINDS, ROUNDED_BLADE_BINS as _ROUNDED_BLADE_BINS
from lenslab.optics.lens_system import PUPIL_BINS as _PUPIL_BINS
from lenslab.optics.prescription import MAX_SURFACES as _MAX_LENS_SURFACES

# -- Materials: MATERIAL_ROWS vec4 rows per material (scene/materials/base.py describes them; packed through
# buffers.pack_material, read by glsl/bsdf.glsl), its type code in row 0, w. The numbers belong to the material
# kinds (lenslab.scene.materials): each kind's MATERIAL_<KIND> code is its place in the registry
# (scene/materials/registry.py), re-exported here under the same names, as the rest of the layout.
# MATERIAL_NESTING: how deep materials may hold one another (glsl/bsdf.glsl's resolve loop runs at most this
# many steps). A microfacet material's distribution is row 5, w: MICROFACET_*.
from lenslab.scene.materials.base import (MATERIAL_NESTING, MATERIAL_ROWS,  # noqa: E402
                                          MICROFACET_BECKMANN, MICROFACET_GGX)
from lenslab.scene.materials.registry import GLSL_DISPATCH_INCLUDE, MATERIAL_CODES, glsl_dispatch  # noqa: E402

globals().update(MATERIAL_CODES)  # MATERIAL_DIFFUSE = 0, MATERIAL_EMISSIVE = 1, ... (registration order)

# Entries of a rough plastic coating's reflectance table (render/fresnel.py), over cos theta in [0, 1].
ROUGH_TABLE_SIZE = 64

# -- Textures: TEXTURE_ROWS vec4 rows per texture record (render/textures.py, glsl/textures.glsl): row 0 its
# type, rows 1-2 its uv transform, rows 3-4 what its type needs.
TEXTURE_IMAGE = 0
TEXTURE_CHECKER = 1
TEXTURE_ROWS = 5
TEXELS_HALF = 0  # how an image's texels are packed (record row 3, x): two half-float uints a texel
TEXELS_FLOAT = 1  # three 32-bit float uints a texel, for values beyond the half-float range
TEXTURE_WRAP_REPEAT = 0  # an image beyond [0, 1]^2 (record row 3, y), as scene/textures.WRAP_MODES
TEXTURE_WRAP_MIRROR = 1
TEXTURE_WRAP_CLAMP = 2
TEXTURE_FILTER_BILINEAR = 0  # record row 3, z, as scene/textures.FILTERS
TEXTURE_FILTER_NEAREST = 1

# -- Geometry: vec4 rows per primitive in the geometry buffer, per triangle in the shading buffer.
GEOMETRY_ROWS = 3
SHADING_ROWS = 4

# kd-tree nodes (render/bsp.py): the low two bits of a node's second word are its split axis, or this.
KD_LEAF = 3
# -- Instances of mesh groups (render/instancing.py, glsl/common.glsl): vec4 rows per instance.
INSTANCE_ROWS = 8
# A scene of many instances finds them through a kd-tree over their world boxes, built no deeper than this (the
# stack glsl/bsp.glsl's walk_instance_tree keeps).
INSTANCE_TREE_DEPTH = 16

# -- Lights: LIGHT_ROWS vec4 rows per light in the light table (buffers.pack_scene, glsl/lights.glsl), its
# kind in row 0, x.
LIGHT_AREA = 0
LIGHT_POINT = 1
LIGHT_SUN = 2
LIGHT_ENVIRONMENT = 3
LIGHT_SPOT = 4
LIGHT_ROWS = 3
# A spot's parameters beyond its three rows, in image_data at the offset its row 0 holds (buffers.py's
# _spot_light_entry, glsl/lights.glsl's spot_intensity): axis, right, top (3 each), cutoff angle, the ramp's
# slope 1 / (cutoff - beam), 1 / (2 tan cutoff), texture record (-1: none).
SPOT_PARAMS = 13
# The lights the LightPlaces uniform block holds: next-event estimation chooses among at most this many by
# what each brings to the shading point.
LIGHT_PLACES = 32

# The uniform env_type: a constant colour (env_radiance) or a lat-long map.
ENV_CONSTANT = 0
ENV_MAP = 1

# -- Binding points of the storage buffers (and of the one uniform block) the kernels read and write.
KD_NODES_BINDING = 0
PRIM_REFS_BINDING = 1
GEOMETRY_BINDING = 2
SHADING_BINDING = 3
MATERIALS_BINDING = 4
LIGHTS_BINDING = 5
ACCUMULATION_BINDING = 6  # trace.comp's output: the image's running sums, or one pass of splatted samples
IMAGE_DATA_BINDING = 7
LIGHT_CHOICE_BINDING = 0  # a uniform block: uniform-block bindings are numbered apart from storage buffers
# splat.comp reads the samples trace.comp left at ACCUMULATION_BINDING and gathers them into the image here.
SPLAT_IMAGE_BINDING = 0
# display.comp reads the image's sums at ACCUMULATION_BINDING and writes 8-bit display pixels here.
DISPLAY_BINDING = 8
# trace.comp's denoiser guides (glsl/feature_buffers.glsl), when a session has feature buffers: FEATURE_ROWS
# vec4 per pixel, (albedo sum, sample count) and (normal sum, 0).
FEATURES_BINDING = 9
FEATURE_ROWS = 2
INSTANCES_BINDING = 10  # the instance table (render/instancing.py)
# raycast.comp's rays in and hits out; bsdf_probe.comp's items in and results out.
RAYS_BINDING = 6
HITS_BINDING = 7
PROBE_IN_BINDING = 6
PROBE_OUT_BINDING = 8
# glsl/camera.glsl: the aperture's shape (lenslab.optics.aperture), and the texture unit of its tables.
APERTURE_ROUND = APERTURE_KINDS["round"]
APERTURE_BLADES = APERTURE_KINDS["blades"]
APERTURE_ROUNDED_BLADES = APERTURE_KINDS["rounded_blades"]
APERTURE_IMAGE = APERTURE_KINDS["image"]
APERTURE_TABLE_UNIT = 0
ROUNDED_BLADE_BINS = _ROUNDED_BLADE_BINS
# A real lens (glsl/real_lens.glsl): at most MAX_LENS_SURFACES surfaces (optics/prescription.py refuses more), and
# the exit pupil's table in PUPIL_BINS radial bins (optics/lens_system.py).
MAX_LENS_SURFACES = _MAX_LENS_SURFACES
PUPIL_BINS = _PUPIL_BINS


def glsl_defines() -> dict[str, int | str]:
    """Every constant above by its own name: the #defines each compute shader is compiled with. An int is
    itself; a float is its text as GLSL reads it (:func:`glsl_float`)."""
    return {name: glsl_float(value) if type(value) is float else value for name, value in globals().items()
            if name.isupper() and not name.startswith("_") and type(value) in (int, float)}


def glsl_generated_includes() -> dict[str, str]:
    """GLSL made from Python rather than read from glsl/, by the name shaders #include it under: the material
    kinds' includes and dispatch (scene/materials/registry.py's glsl_dispatch), included by glsl/bsdf.glsl."""
    return {GLSL_DISPATCH_INCLUDE: _MATERIAL_DISPATCH}


_MATERIAL_DISPATCH = glsl_dispatch()


def glsl_float(value: float) -> str:
    """``value`` as a GLSL float literal: Python's repr, the shortest text that reads back as this very number
    (so GLSL's float32 is the one the same number typed in the shader gave), with a decimal point always."""
    if not math.isfinite(value) or abs(value) > 3.4028234663852886e38:  # float32's largest
        raise ValueError(f"{value!r}: GLSL's float has no literal for it")
    text = repr(float(value))
    if "." not in text:  # 1e-05, 3e+38: GLSL reads these too, but they must not be mistaken for an int
        mantissa, _, exponent = text.partition("e")
        text = f"{mantissa}.0" + (f"e{exponent}" if exponent else "")
    return f"({text})" if text.startswith("-") else text
