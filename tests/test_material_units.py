"""A material kind is one unit (docs/architecture.md, "Adding a material kind"): one module under
lenslab/scene/materials/ (its dataclass, its packing, its KIND) and one glsl/material_<name>.glsl, registered
once in scene/materials/registry.py, from which the type codes, packing, kernel features and the shaders'
dispatch are made. No GL here: these check the registry against what it feeds."""

from __future__ import annotations

import importlib
import re

import numpy as np
import pytest

from lenslab.render import buffers, features, gpu_layout
from lenslab.render.gl import load_shader_source
from lenslab.resources import glsl_dir
from lenslab.scene import materials
from lenslab.scene.io import mitsuba_bsdfs
from lenslab.scene.io.mitsuba_xml import load_mitsuba_string
from lenslab.scene.materials import registry
from lenslab.scene.textures import Checkerboard

KINDS = registry.KINDS
IDS = [kind.name for kind in KINDS]


def test_codes_are_the_registration_order():
    assert [kind.code for kind in KINDS] == list(range(len(KINDS)))
    assert len({kind.name for kind in KINDS}) == len({kind.constant for kind in KINDS}) == len(KINDS)


@pytest.mark.parametrize("kind", KINDS, ids=IDS)
def test_gpu_layout_re_exports_the_registry_codes(kind):
    assert getattr(gpu_layout, kind.constant) == kind.code
    assert gpu_layout.glsl_defines()[kind.constant] == kind.code
    assert buffers.MATERIAL_CODES[kind.cls] == kind.code


def test_record_numbers_live_with_the_materials():
    from lenslab.scene.materials import base
    for name in ("MATERIAL_ROWS", "MATERIAL_NESTING", "MICROFACET_GGX", "MICROFACET_BECKMANN"):
        assert getattr(gpu_layout, name) == getattr(base, name)


@pytest.mark.parametrize("kind", KINDS, ids=IDS)
def test_every_kind_is_a_whole_unit(kind):
    # data: its dataclass, under its scene-file name, exported by lenslab.scene.materials
    assert materials.MATERIAL_TYPES[kind.name] is kind.cls
    assert getattr(materials, kind.cls.__name__) is kind.cls
    assert kind.cls.__module__ == f"lenslab.scene.materials.{kind.name}"
    # packing and feature bit
    assert callable(kind.pack)
    assert kind.feature_bit == 1 << kind.code
    # GLSL: its own include, with the functions the dispatch calls
    assert kind.glsl == f"material_{kind.name}.glsl"
    source = (glsl_dir() / kind.glsl).read_text(encoding="utf-8")
    for part, present in (("eval", kind.glsl_eval), ("sample", kind.glsl_sample)):
        if kind.glsl_prefix and present:
            assert re.search(rf"\b{kind.glsl_prefix}_{part}\(", source), f"{kind.glsl} lacks {kind.glsl_prefix}_{part}"


@pytest.mark.parametrize("kind", KINDS, ids=IDS)
def test_every_kind_appears_in_the_generated_dispatch(kind):
    dispatch = registry.glsl_dispatch()
    assert f'#include "{kind.glsl}"' in dispatch
    if kind.glsl_prefix:
        if kind.glsl_eval:
            assert f"if (is_type(b, {kind.constant})) return {kind.glsl_prefix}_eval(" in dispatch
        if kind.glsl_sample:
            assert f"if (is_type(b, {kind.constant})) return {kind.glsl_prefix}_sample(" in dispatch
    # ... and reaches the trace kernel's source, through glsl/bsdf.glsl
    source = load_shader_source("trace.comp", {"LOCAL_SIZE_X": 32})
    assert f"// {kind.cls.__name__} (scene/materials/{kind.name}.py)" in source


def test_the_general_kernel_has_every_kinds_feature_bit():
    assert features.GENERAL.defines()["MATERIAL_TYPES"] == sum(kind.feature_bit for kind in KINDS)
    assert set(buffers.WRAPPER_CODES) == {kind.code for kind in KINDS if kind.wrapper}
    assert set(buffers.HOLDING_CODES) == {kind.code for kind in KINDS if kind.holds is not None}


class _Context:
    """A texture table stand-in: textures get records 0, 1, ... in the order asked for."""

    class fresnel:  # noqa: N801 - stands for the module
        internal_diffuse_reflectance = staticmethod(lambda ior: 0.25)
        rough_internal_reflectance = staticmethod(lambda ior, alpha, distribution: 0.5)
        rough_reflectance_table = staticmethod(lambda ior, alpha, distribution: np.full(4, 0.25))
        rough_transmittance_table = staticmethod(lambda ior, alpha, distribution: np.full(4, 0.5))

    def __init__(self):
        self.textures, self.floats = [], []

    def index_of(self, texture, data=False):
        if texture is None:
            return -1
        self.textures.append(texture)
        return len(self.textures) - 1

    def add_floats(self, values):
        self.floats.append(values)
        return 100 * len(self.floats)


def test_packing_is_plain_numpy_and_keeps_the_record_layout():
    t = Checkerboard()
    ctx = _Context()
    cases = [
        (materials.Diffuse((0.1, 0.2, 0.3), albedo_texture=t), {(0, 0): 0.1, (3, 3): 0, (4, 3): -1, (2, 3): 0.0}),
        (materials.Emissive((4.0, 5.0, 6.0), two_sided=True), {(1, 0): 4.0, (1, 3): 1.0, (2, 0): 7, (2, 1): -1}),
        (materials.Conductor(metal="gold", roughness=0.5, roughness_texture=t), {
            (2, 0): 0.143, (3, 0): 3.983, (4, 3): 1, (2, 3): 0.25}),
        (materials.Plastic(roughness=0.5, distribution="beckmann"), {
            (2, 0): 1.49, (2, 1): 0.5, (2, 2): np.int32(100).view(np.float32), (5, 3): 1}),
        (materials.Dielectric(ior=1.33, tint=(0.5, 0.5, 0.5)), {(2, 0): 1.33, (4, 0): 0.5, (5, 0): 0.0}),
        (materials.ThinDielectric(ior=1.2), {(2, 0): 1.2, (4, 0): 1.0}),
        (materials.Blend(weight=0.25), {(0, 0): 0.25, (0, 1): -1, (0, 2): 0.0, (2, 0): 7, (2, 1): -1, (2, 3): 0.0}),
        (materials.Mask(opacity=0.75, opacity_texture=t), {(0, 0): 0.75, (0, 1): 2}),
        (materials.BumpMap(texture=t, scale=2.0), {(0, 0): 2.0, (0, 1): 3, (0, 2): 1.0}),
        (materials.NormalMap(texture=t, shadowing=False), {(0, 0): 0.0, (0, 1): 4, (0, 2): 0.0}),
    ]
    assert {type(m) for m, _ in cases} == {kind.cls for kind in KINDS}
    for material, expected in cases:
        record = registry.pack_record(material, ctx, inner=[7] if registry.kind_of(material).holds else [])
        assert record.shape == (gpu_layout.MATERIAL_ROWS, 4) and record.dtype == np.float32
        assert record[0, 3] == buffers.MATERIAL_CODES[type(material)]
        for (row, col), value in expected.items():
            assert record[row, col] == np.float32(value), (type(material).__name__, row, col)


def test_inner_materials_come_from_the_kinds():
    first, second = materials.Diffuse(), materials.Plastic()
    assert materials.inner_materials(materials.Blend(first, second)) == [first, second]
    assert materials.inner_materials(materials.BumpMap(material=first)) == [first]
    assert materials.inner_materials(materials.Emissive()) == []
    assert materials.inner_materials(materials.Emissive(surface=second)) == [second]
    blend = materials.Blend(first, second)
    assert list(materials.walk_materials(materials.Mask(material=blend)))[1:] == [blend, first, second]


# -- Mitsuba ---------------------------------------------------------------------------------------------------
# Every Mitsuba BSDF plugin name and the class it mapped onto when mitsuba_bsdfs.BSDF_MAPPINGS was one table
# (twosided: None, it is unwrapped to the BSDF it holds). The reference the kinds' own mappings keep to.
MITSUBA_REFERENCE: dict[str, type | None] = {
    "diffuse": materials.Diffuse,
    "roughdiffuse": materials.Diffuse,
    "conductor": materials.Conductor,
    "roughconductor": materials.Conductor,
    "plastic": materials.Plastic,
    "roughplastic": materials.Plastic,
    "dielectric": materials.Dielectric,
    "roughdielectric": materials.Dielectric,
    "thindielectric": materials.ThinDielectric,
    "principled": materials.Diffuse,
    "principledthin": materials.Diffuse,
    "twosided": None,
    "mask": materials.Mask,
    "bumpmap": materials.BumpMap,
    "normalmap": materials.NormalMap,
    "blendbsdf": materials.Blend,
}
# What a plugin needs inside to load (the wrappers' BSDFs, the maps' textures).
_MITSUBA_INSIDE = {
    "twosided": '<bsdf type="roughplastic"/>',
    "mask": '<bsdf type="diffuse"/>',
    "bumpmap": '<texture type="checkerboard"/><bsdf type="diffuse"/>',
    "normalmap": '<texture type="checkerboard" name="normalmap"/><bsdf type="diffuse"/>',
    "blendbsdf": '<bsdf type="diffuse"/><bsdf type="conductor"/>',
}


def test_the_mitsuba_table_has_every_plugin_it_had():
    assert set(mitsuba_bsdfs.BSDF_MAPPINGS) == set(MITSUBA_REFERENCE)


@pytest.mark.parametrize("plugin", list(MITSUBA_REFERENCE))
def test_every_mitsuba_plugin_maps_onto_the_kind_it_did(plugin):
    expected = MITSUBA_REFERENCE[plugin]
    kinds = [kind for kind in KINDS if plugin in kind.mitsuba_plugins]
    if kinds:  # mapped by its kind's module
        assert [kind.cls for kind in kinds] == [expected]
        assert mitsuba_bsdfs.BSDF_MAPPINGS[plugin] is kinds[0].from_mitsuba
    else:  # onto no one kind: kept in mitsuba_bsdfs
        assert plugin in mitsuba_bsdfs.UNWRAPPED_OR_APPROXIMATED
        assert mitsuba_bsdfs.BSDF_MAPPINGS[plugin].__module__ == mitsuba_bsdfs.__name__
    # ... and an imported scene gets that class (a twosided: the class of the BSDF it holds)
    xml = (f'<scene version="3.0.0"><bsdf type="{plugin}" id="m">{_MITSUBA_INSIDE.get(plugin, "")}</bsdf>'
           '<shape type="sphere"><ref id="m"/></shape></scene>')
    scene = load_mitsuba_string(xml, warn=lambda message: None)
    assert type(scene.materials[scene.nodes[0].material]) is (expected or materials.Plastic)


@pytest.mark.parametrize("kind", KINDS, ids=IDS)
def test_every_kind_holds_its_own_mitsuba_mappings(kind):
    module = importlib.import_module(kind.cls.__module__)
    if kind.from_mitsuba is None:  # no Mitsuba BSDF maps onto it (an emitter is not a BSDF)
        assert kind.mitsuba_plugins == () and not hasattr(module, "from_mitsuba")
        return
    assert kind.from_mitsuba is module.from_mitsuba
    assert kind.mitsuba_plugins == tuple(p for p, cls in MITSUBA_REFERENCE.items() if cls is kind.cls
                                         and p not in mitsuba_bsdfs.UNWRAPPED_OR_APPROXIMATED)
