"""The buffer layout reaches every shader from render/gpu_layout.py, and every uniform the host sets exists."""

from __future__ import annotations

import dataclasses
import re

import moderngl
import pytest

from lenslab.colour_management.view import ViewTransform
from lenslab.render.gl import declared_uniforms, load_shader_source
from lenslab.render.gpu_layout import glsl_defines
from lenslab.render.sobol import glsl_array_literal
from lenslab.render.tracer import OCIO_DISPLAY_INCLUDE, RenderSession
from lenslab.resources import glsl_dir
from lenslab.scene.io.loader import open_scene

LAYOUT = glsl_defines()
KERNELS = sorted(path.name for path in glsl_dir().glob("*.comp"))
# What the host passes besides the layout; a kernel that does not read one ignores it.
KERNEL_DEFINES = {"LOCAL_SIZE_X": 32, "SOBOL_DIRECTIONS": glsl_array_literal()}
# And the code it generates: display.comp includes OpenColorIO's view transform (the default one here).
KERNEL_INCLUDES = {OCIO_DISPLAY_INCLUDE: ViewTransform().gpu_shader().source}


@pytest.mark.parametrize("kernel", KERNELS)
def test_every_kernel_is_compiled_with_every_layout_constant(kernel):
    lines = set(load_shader_source(kernel, KERNEL_DEFINES, includes=KERNEL_INCLUDES).splitlines())
    assert {f"#define {name} {value}" for name, value in LAYOUT.items()} <= lines


@pytest.mark.parametrize("path", sorted(glsl_dir().iterdir()), ids=lambda path: path.name)
def test_no_shader_types_a_layout_constant_of_its_own(path):
    source = path.read_text(encoding="utf-8")
    for name in LAYOUT:
        assert not re.search(rf"(\bconst\s+\w+\s+|#define\s+){name}\b", source), f"{path.name} declares {name}"


def test_a_kernel_cannot_redefine_the_layout():
    with pytest.raises(ValueError, match="MATERIAL_ROWS"):
        load_shader_source("splat.comp", {"LOCAL_SIZE_X": 32, "MATERIAL_ROWS": 9})


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_kernel_without_the_layout_does_not_compile(renderer, kernel):
    source = load_shader_source(kernel, KERNEL_DEFINES, includes=KERNEL_INCLUDES)
    without = "\n".join(line for line in source.splitlines()
                        if not (line.startswith("#define ") and line.split()[1] in LAYOUT))
    with pytest.raises(moderngl.Error):
        renderer.ctx.compute_shader(without)


def test_declared_uniforms_are_the_plain_uniforms_of_the_source():
    source = ("uniform int light_count;  // entries\nuniform vec4 weights[4];\n"
              "layout(std140, binding = 0) uniform LightPlaces {\n    vec4 light_place[32];\n};\n")
    assert declared_uniforms(source) == {"light_count", "weights"}


def session_for(renderer, **settings):
    scene = open_scene("cornell_box")
    scene = dataclasses.replace(scene, render=dataclasses.replace(scene.render, **settings))
    return RenderSession(renderer, scene, width=16, height=16, specialise=False)


@pytest.mark.parametrize("sampler", ["sobol", "independent"])
def test_the_general_kernel_reads_every_uniform_the_session_sets(renderer, sampler):
    # A specialised kernel may lack some of them (the compiler drops what it never reads); the general one
    # must have every one, or the name is misspelt or the shader stopped reading it.
    session = session_for(renderer, sampler=sampler)
    try:
        missing = sorted(name for name in session.trace_uniforms() if name not in session.program)
        assert not missing
    finally:
        session.release()


def test_a_uniform_no_shader_declares_is_refused_by_name(renderer):
    session = session_for(renderer)
    try:
        with pytest.raises(KeyError, match="scene_mni"):
            renderer.set_uniforms(session.program, {"scene_mni": (0.0, 0.0, 0.0)})
    finally:
        session.release()


def test_a_specialised_kernel_skips_the_uniforms_it_dropped(renderer):
    scene = open_scene("cornell_box")  # no environment map: its kernel never reads env_strength
    session = RenderSession(renderer, scene, width=16, height=16)
    try:
        dropped = "env_strength" not in session.program  # Mesa drops it; NVIDIA's compiler keeps it, unread
        renderer.set_uniforms(session.program, {"env_strength": 1.0})  # declared: accepted either way
        if not dropped:
            assert session.program["env_strength"].value == pytest.approx(1.0)
    finally:
        session.release()
