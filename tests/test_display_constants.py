"""display.comp's tone curves are film.py's: the shader types none of their numbers, it is compiled with the
Python constants as #defines (render/gpu_layout.py), and a ramp through both paths gives the same pixels."""

from __future__ import annotations

import re

import numpy as np
import pytest

from lenslab import color
from lenslab.render import film
from lenslab.render.gl import load_shader_source
from lenslab.render.gpu_layout import glsl_defines, glsl_float
from lenslab.resources import glsl_dir

SRGB_ENCODING = ("SRGB_SCALE", "SRGB_OFFSET", "SRGB_EXPONENT", "SRGB_LINEAR_SLOPE", "SRGB_LINEAR_CUTOFF")
FILMIC = ("FILMIC_A", "FILMIC_B", "FILMIC_C", "FILMIC_D", "FILMIC_E")
OWNER = {**{name: color for name in SRGB_ENCODING}, **{name: film for name in FILMIC}}
# A GLSL float literal outside comments: 1.055, .5, 2., 1.0e-05 (an int such as 255u is no curve number).
FLOAT_LITERAL = re.compile(r"(?<![\w.])(?:\d+\.\d*|\.\d+)(?:[eE][+-]?\d+)?")


def shader_code(name: str) -> str:
    """glsl/<name> without its comments."""
    source = (glsl_dir() / name).read_text(encoding="utf-8")
    return re.sub(r"//[^\n]*", "", re.sub(r"/\*.*?\*/", "", source, flags=re.DOTALL))


def test_display_comp_types_none_of_the_curve_numbers():
    code = shader_code("display.comp")
    numbers = {float(text) for text in FLOAT_LITERAL.findall(code)}
    python = {getattr(OWNER[name], name) for name in OWNER} | {color.SRGB_ENCODED_CUTOFF}
    assert not numbers & python, f"display.comp types {sorted(numbers & python)} itself"
    assert not re.search(r"\bconst\s+float\b", code)  # the old `const float a = 2.51, ...` is gone
    for name in OWNER:  # and it reads every one of them by name
        assert re.search(rf"\b{name}\b", code), f"display.comp does not use {name}"


def test_display_comp_is_compiled_with_the_python_constants():
    lines = load_shader_source("display.comp", {"LOCAL_SIZE_X": 64}).splitlines()
    for name, module in OWNER.items():
        value = getattr(module, name)
        assert glsl_defines()[name] == glsl_float(value)
        assert f"#define {name} {glsl_float(value)}" in lines
        # The text reads back as the very number, so GLSL's float32 is the one this literal typed in it gave.
        assert float(glsl_float(value)) == value and np.float32(glsl_float(value)) == np.float32(value)


def test_these_are_the_numbers_of_the_curves():
    # IEC 61966-2-1 and Narkowicz 2015: the refactoring moved them, it did not change them.
    assert (color.SRGB_SCALE, color.SRGB_OFFSET, color.SRGB_EXPONENT, color.SRGB_LINEAR_SLOPE,
            color.SRGB_LINEAR_CUTOFF, color.SRGB_ENCODED_CUTOFF) == (1.055, 0.055, 2.4, 12.92, 0.0031308, 0.04045)
    assert (film.FILMIC_A, film.FILMIC_B, film.FILMIC_C, film.FILMIC_D, film.FILMIC_E) == (2.51, 0.03, 2.43, 0.59,
                                                                                         0.14)


@pytest.mark.parametrize("value, text", [(2.51, "2.51"), (0.0031308, "0.0031308"), (1 / 2.4, "0.4166666666666667"),
                                         (3.0, "3.0"), (1e-05, "1.0e-05"), (2.5e-07, "2.5e-07"), (1e20, "1.0e+20"),
                                         (-0.5, "(-0.5)")])
def test_a_float_define_is_the_shortest_exact_text_with_a_decimal_point(value, text):
    assert glsl_float(value) == text
    assert float(text.strip("()")) == value


@pytest.mark.parametrize("value", [float("inf"), float("nan"), 1e39])
def test_a_float_glsl_cannot_write_is_refused(value):
    with pytest.raises(ValueError):
        glsl_float(value)


# -- The same ramp of linear values through display.comp (RenderSession.display_image) and through film.py.

WIDTH, HEIGHT = 512, 256
# Most allowed: pow() may round the last bit differently on a GPU, which moves a rare pixel by one level.
MOST_DIFFERING = 1e-3


def ramp() -> np.ndarray:
    """(HEIGHT, WIDTH, 3) linear values: even steps over [0, 1], even ratios up to 64 (where the tone maps
    bend), and the sRGB curve's straight part, densely."""
    third = WIDTH * HEIGHT
    values = np.concatenate([np.linspace(0.0, 1.0, third), np.geomspace(1e-6, 64.0, third),
                             np.linspace(0.0, 0.0032, third)]).astype(np.float32)
    return values.reshape(3, HEIGHT, WIDTH).transpose(1, 2, 0).copy()


@pytest.fixture(scope="module")
def gpu_pictures(renderer):
    """The ramp and display.comp's 8-bit picture of it for every tone map."""
    from lenslab.render.tracer import RenderSession
    from lenslab.scene.io.loader import open_scene

    image = ramp()
    session = RenderSession(renderer, open_scene("cornell_box"), width=WIDTH, height=HEIGHT)
    try:
        pictures = {operator: session.display_image(image, 0.0, operator) for operator in film.TONE_MAPS}
    finally:
        session.release()
    return image, pictures


def differences(picture: np.ndarray, image: np.ndarray, operator: str) -> tuple[int, float]:
    """(largest difference in levels, fraction of channels that differ) of the GPU picture from film.py's."""
    expected = film.to_8bit(film.tone_map(image, 0.0, operator)).astype(int)
    difference = np.abs(picture[..., :3].astype(int) - expected)
    return int(difference.max()), float((difference > 0).mean())


@pytest.mark.gl
@pytest.mark.parametrize("operator", film.TONE_MAPS)
def test_a_ramp_is_displayed_by_the_gpu_as_film_py_displays_it(gpu_pictures, operator):
    image, pictures = gpu_pictures
    largest, differing = differences(pictures[operator], image, operator)
    assert largest <= 1 and differing <= MOST_DIFFERING, (largest, differing)
    assert (pictures[operator][..., 3] == 255).all()
    assert len(np.unique(pictures[operator][..., :3])) > 250  # nearly every level: the ramp spans the curve


@pytest.mark.gl
@pytest.mark.parametrize("name", [name for name in OWNER if name != "SRGB_LINEAR_CUTOFF"])
def test_the_ramp_sees_a_curve_number_the_shader_does_not_share(gpu_pictures, monkeypatch, name):
    """The comparison above has teeth: a number 1% off on the Python side only (as if the shader typed its own)
    fails it. The sRGB cut-off is left out: the curve is continuous there, so moving it changes no 8-bit level;
    the #define tests above hold it to the Python one."""
    image, pictures = gpu_pictures
    monkeypatch.setattr(OWNER[name], name, getattr(OWNER[name], name) * 1.01)
    operator = "filmic" if OWNER[name] is film else "clamp"
    largest, differing = differences(pictures[operator], image, operator)
    assert differing > MOST_DIFFERING, (largest, differing)
