"""Textures in their colour space (docs/colour.md, "Textures in their colour space"): each image texture's
``color_space`` (auto, srgb, linear, raw, or any colour space of the OCIO config), converted at load into the
scene's working space for colour slots and left as stored for data slots; Mitsuba's ``raw`` flag and glTF's and
OBJ's conventions; the error for a name that is no colour space. Plain numpy and OCIO: no GPU."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lenslab.color import srgb_to_linear
from lenslab.colour_management.config import load_config
from lenslab.image_files import read_pixels
from lenslab.render.buffers import MaterialTable, pack_material, pack_scene
from lenslab.render.gpu_layout import TEXELS_FLOAT, TEXELS_HALF, TEXTURE_ROWS
from lenslab.render.textures import TextureTable, read_texture_image
from lenslab.scene.io.mesh_materials import load_parts
from lenslab.scene.io.mitsuba_xml import load_mitsuba_string
from lenslab.scene.io.native import FORMAT_VERSION, load_scene, scene_from_dict, scene_to_dict
from lenslab.scene.materials import BumpMap, Blend, Conductor, Diffuse, Mask, NormalMap, Plastic
from lenslab.scene.scene import EnvironmentMap, Node, Scene, SceneError
from lenslab.scene.shapes import Sphere
from lenslab.scene.textures import ImageTexture, InlineImageTexture
from tests.test_mesh_materials import write_gltf, write_obj, write_png
from tests.test_textures_uv import SENSOR, write_image, write_quad_obj

PURE_RED_IN_ACESCG = (0.6131, 0.0702, 0.0206)  # linear Rec.709 (1, 0, 0) in AP1 (Bradford-adapted D65 -> ACES white)
HALF_TOLERANCE = 2e-3  # what half-float texels keep of a value near 1


@pytest.fixture
def swatch(tmp_path) -> tuple[Path, np.ndarray]:
    """An 8-bit PNG with every level of each channel somewhere, and its values as stored (0..1)."""
    levels = np.arange(256, dtype=np.uint8)
    pixels = np.stack([levels, levels[::-1], np.roll(levels, 85)], axis=-1).reshape(16, 16, 3)
    path = write_image(tmp_path / "swatch.png", pixels)
    return path, read_pixels(path)[0]


def ocio_says(pixels: np.ndarray, source: str, target: str) -> np.ndarray:
    """OCIO's own CPU processor from ``source`` to ``target``, called directly."""
    config = load_config()
    values = np.ascontiguousarray(pixels, np.float32).copy()
    config.getProcessor(source, target).getDefaultCPUProcessor().applyRGB(values.reshape(-1, 3))
    return values


def packed_texels(records: np.ndarray, texels: np.ndarray, index: int) -> np.ndarray:
    """Texture ``index``'s texels (H, W, 3) as the GPU gets them, from its record rows and the texel buffer."""
    record = records.reshape(-1, TEXTURE_ROWS, 4)[index]
    offset = int(np.float32(record[0, 1]).view(np.int32))
    width, height = int(record[0, 2]), int(record[0, 3])
    if record[3, 0] == TEXELS_HALF:
        return texels[offset: offset + 2 * width * height].view(np.float16).reshape(height, width, 4)[..., :3]
    assert record[3, 0] == TEXELS_FLOAT
    return texels[offset: offset + 3 * width * height].view(np.float32).reshape(height, width, 3)


def table_texels(table: TextureTable, index: int = 0) -> np.ndarray:
    return packed_texels(table.records(), table.texels(), index).astype(np.float32)


# ---------------------------------------------------------------------------------------------------------
# Colour textures: from their space into the working space
# ---------------------------------------------------------------------------------------------------------
def test_an_8_bit_file_reads_as_srgb_by_default_exactly_as_before(swatch):
    path, stored = swatch
    want = srgb_to_linear(np.clip(stored, 0.0, 1.0))  # lenslab.color's curve, as every earlier version read it
    for color_space in ("auto", "srgb"):
        np.testing.assert_array_equal(read_texture_image(path, color_space), want)
    # OCIO's own sRGB agrees within 1e-5 where it computes the curve exactly (its lossless processor); its default
    # processor's fast pow is 2.4e-5 off at white, which is why "srgb" keeps lenslab.color's curve.
    import PyOpenColorIO as ocio

    exact = np.ascontiguousarray(stored, np.float32).copy()
    processor = load_config().getProcessor("sRGB Encoded Rec.709 (sRGB)", "Linear Rec.709 (sRGB)")
    processor.getOptimizedCPUProcessor(ocio.OPTIMIZATION_LOSSLESS).applyRGB(exact.reshape(-1, 3))
    np.testing.assert_allclose(read_texture_image(path), exact, rtol=0, atol=1e-5)


def test_raw_leaves_the_values_as_stored_in_any_working_space(swatch):
    path, stored = swatch
    for working_space in ("lin_rec709", "acescg"):
        np.testing.assert_allclose(read_texture_image(path, "raw", working_space), stored, rtol=0, atol=1e-7)


def test_a_float_file_reads_as_linear_rec709_by_default(tmp_path):
    values = np.array([[[0.25, 2.0, 0.0], [4.0, 0.5, 0.125]]], np.float32)
    path = write_image(tmp_path / "linear.exr", values)
    np.testing.assert_array_equal(read_texture_image(path), values)
    np.testing.assert_allclose(read_texture_image(path, "auto", "acescg"),
                               ocio_says(values, "lin_rec709", "ACEScg"), rtol=0, atol=1e-6)


@pytest.mark.parametrize("name", ["sRGB Encoded P3-D65", "srgb_p3d65", "Linear Rec.2020", "ACEScg"])
@pytest.mark.parametrize("working_space, ocio_name", [("lin_rec709", "Linear Rec.709 (sRGB)"), ("acescg", "ACEScg")])
def test_a_space_named_in_the_ocio_config_converts_as_ocio_says(swatch, name, working_space, ocio_name):
    path, stored = swatch
    want = np.maximum(ocio_says(stored, name, ocio_name), 0.0)  # beyond the working space's gamut: read as 0
    np.testing.assert_allclose(read_texture_image(path, name, working_space), want, rtol=0, atol=1e-6)


def test_an_acescg_scene_reads_an_srgb_texture_in_ap1(tmp_path):
    red = write_image(tmp_path / "red.png", np.array([[[255, 0, 0]]], np.uint8))
    np.testing.assert_allclose(read_texture_image(red, "auto", "acescg")[0, 0], PURE_RED_IN_ACESCG, atol=1e-4)
    # ... and the default scene reads it as it always did
    np.testing.assert_array_equal(read_texture_image(red)[0, 0], (1.0, 0.0, 0.0))


def test_the_environment_map_is_read_into_the_working_space(tmp_path):
    sky = np.array([[[1.0, 0.0, 0.0], [0.0, 0.5, 0.0]], [[0.0, 0.0, 2.0], [1.0, 1.0, 1.0]]], np.float32)
    write_image(tmp_path / "sky.exr", sky)
    scene = Scene(nodes=[Node(name="ball", shape=Sphere())], environment=EnvironmentMap(file="sky.exr"))
    for working_space, want in (("lin_rec709", sky), ("acescg", ocio_says(sky, "lin_rec709", "ACEScg"))):
        packed = pack_scene(scene.flatten(), scene.environment, base_dir=tmp_path, working_space=working_space)
        records = packed.arrays["materials"][packed.uniforms["texture_base"]:]
        got = packed_texels(records, packed.arrays["image_data"], packed.uniforms["env_texture"])
        np.testing.assert_allclose(got, want, rtol=HALF_TOLERANCE, atol=1e-4)


# ---------------------------------------------------------------------------------------------------------
# Slots: colour or data
# ---------------------------------------------------------------------------------------------------------
DATA_SLOTS = [
    lambda t: Plastic(roughness_texture=t), lambda t: Conductor(roughness_texture=t), lambda t: Blend(weight_texture=t),
    lambda t: Mask(opacity_texture=t), lambda t: BumpMap(texture=t), lambda t: NormalMap(texture=t),
]
COLOUR_SLOTS = [lambda t: Diffuse(albedo_texture=t), lambda t: Plastic(albedo_texture=t)]


@pytest.mark.parametrize("slot", range(len(DATA_SLOTS)))
def test_data_slots_read_their_values_as_stored_under_acescg(swatch, slot):
    path, stored = swatch
    for color_space in ("auto", "raw", "linear"):
        table = TextureTable(path.parent, working_space="acescg")
        pack_material(DATA_SLOTS[slot](ImageTexture(file=path.name, color_space=color_space)), table)
        np.testing.assert_allclose(table_texels(table), stored, rtol=HALF_TOLERANCE, atol=1e-4)
        assert table.warnings == []


@pytest.mark.parametrize("slot", range(len(COLOUR_SLOTS)))
def test_colour_slots_are_converted_into_the_working_space(swatch, slot):
    path, stored = swatch
    table = TextureTable(path.parent, working_space="acescg")
    pack_material(COLOUR_SLOTS[slot](ImageTexture(file=path.name)), table)
    want = ocio_says(srgb_to_linear(stored.astype(np.float32)), "lin_rec709", "ACEScg")
    np.testing.assert_allclose(table_texels(table), want, rtol=HALF_TOLERANCE, atol=1e-4)


def test_one_texture_in_a_colour_slot_and_a_data_slot_is_read_both_ways(swatch):
    path, stored = swatch
    texture = ImageTexture(file=path.name)
    table = TextureTable(path.parent, working_space="acescg")
    pack_material(Plastic(albedo_texture=texture, roughness_texture=texture), table)
    assert len(table.records()) == 2 * TEXTURE_ROWS
    np.testing.assert_allclose(table_texels(table, 1), stored, rtol=HALF_TOLERANCE, atol=1e-4)
    assert not np.allclose(table_texels(table, 0), stored, atol=0.05)


def test_a_data_slot_decodes_srgb_when_asked_and_reads_a_colour_space_raw_with_one_warning(swatch):
    path, stored = swatch
    table = TextureTable(path.parent, working_space="acescg")
    pack_material(Mask(opacity_texture=ImageTexture(file=path.name, color_space="srgb")), table)
    # the sRGB curve decoded channel by channel, no change of primaries (Mitsuba's non-raw bitmap in any slot)
    np.testing.assert_allclose(table_texels(table), srgb_to_linear(stored), rtol=HALF_TOLERANCE, atol=1e-4)
    assert table.warnings == []
    texture = ImageTexture(file=path.name, color_space="ACEScg")
    table = TextureTable(path.parent, working_space="lin_rec709")
    MaterialTable([Blend(weight_texture=texture, first=Mask(opacity_texture=texture))], table)
    np.testing.assert_allclose(table_texels(table), stored, rtol=HALF_TOLERANCE, atol=1e-4)
    (warning,) = table.warnings  # once, though two slots read it
    assert str(path) in warning and "'ACEScg'" in warning and "holds data" in warning and "as stored" in warning


def test_inline_pixels_are_linear_rec709_unless_they_say_raw():
    pixels = np.array([[[1.0, 0.0, 0.0]]], np.float32)
    table = TextureTable(Path("."), working_space="acescg")
    colour = table.index_of(InlineImageTexture(pixels=pixels, name="glb: base colour"))
    already = table.index_of(InlineImageTexture(pixels=pixels, name="sky", color_space="raw"))
    np.testing.assert_allclose(table_texels(table, colour)[0, 0], PURE_RED_IN_ACESCG, atol=2e-4)
    np.testing.assert_array_equal(table_texels(table, already)[0, 0], (1.0, 0.0, 0.0))


def test_textures_made_for_one_call_each_get_their_own_record():
    """The sky's pixels are indexed as a texture made for the call (render/buffers.py): its id must not pass to
    the next one, which would find the first one's record."""
    table = TextureTable(Path("."))
    indices = [table.index_of(InlineImageTexture(pixels=np.full((1, 1, 3), level, np.float32), color_space="raw"))
               for level in range(8)]
    assert indices == list(range(8))
    assert [float(table_texels(table, i)[0, 0, 0]) for i in indices] == list(range(8))


# ---------------------------------------------------------------------------------------------------------
# The importers
# ---------------------------------------------------------------------------------------------------------
def test_mitsuba_raw_flag_round_trips_and_reads_as_mitsuba_does(tmp_path, swatch):
    path, stored = swatch
    write_image(tmp_path / "hdr.exr", np.full((2, 2, 3), 0.5, np.float32))
    bitmap = '<texture type="bitmap" name="{name}"><string name="filename" value="{file}"/>{raw}</texture>'
    raw = '<boolean name="raw" value="true"/>'
    shapes = [("a", "diffuse", "reflectance", path.name, ""), ("b", "diffuse", "reflectance", path.name, raw),
              ("c", "diffuse", "reflectance", "hdr.exr", ""), ("d", "mask", "opacity", path.name, ""),
              ("e", "mask", "opacity", path.name, raw)]
    body = "".join(f'<shape type="obj" id="{id_}"><string name="filename" value="quad.obj"/><bsdf type="{kind}">'
                   + bitmap.format(name=name, file=file, raw=flag)
                   + ('<bsdf type="diffuse"/>' if kind == "mask" else "") + "</bsdf></shape>"
                   for id_, kind, name, file, flag in shapes)
    scene = load_mitsuba_string(f'<scene version="3.0.0">{body}{SENSOR}</scene>', base_dir=write_quad_obj(tmp_path))
    textures = {id_: getattr(scene.materials[f"{id_}.bsdf"], "albedo_texture", None)
                or scene.materials[f"{id_}.bsdf"].opacity_texture for id_, *_ in shapes}
    assert {id_: t.color_space for id_, t in textures.items()} == {"a": "srgb", "b": "raw", "c": "linear",
                                                                   "d": "srgb", "e": "raw"}
    # Written to LensLab's format and read back, each keeps its colour space.
    again = scene_from_dict(json.loads(json.dumps(scene_to_dict(scene))), scene.source_path)
    assert again.materials == scene.materials
    # Mitsuba decodes a non-raw 8-bit bitmap's sRGB curve in every slot, a mask's opacity included.
    for id_, want in (("d", srgb_to_linear(stored)), ("e", stored), ("b", stored)):
        table = TextureTable(tmp_path)
        table.index_of(textures[id_], data=id_ in "de")
        np.testing.assert_allclose(table_texels(table), want, rtol=HALF_TOLERANCE, atol=1e-4)


def test_gltf_colour_textures_are_srgb_and_its_data_textures_raw(tmp_path):
    base = np.array([[[255, 0, 0], [128, 128, 128]]], np.uint8)
    mr = np.array([[[0, 64, 0], [0, 200, 0]]], np.uint8)  # green: roughness; blue: metalness (none)
    write_png(tmp_path / "base.png", base)
    materials = [
        {"name": "Painted", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0,
                                                     "metallicRoughnessTexture": {"index": 1}}},
        {"name": "Lost", "pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 2}}},
    ]
    images = [{"uri": "base.png"}, {"png": write_png(tmp_path / "mr.png", mr)}, {"uri": "gone.png"}]
    path = write_gltf(tmp_path / "painted.gltf", materials, primitives=(0, 1), images=images,
                      textures=[{"source": 0}, {"source": 1}, {"source": 2}])
    parts = {part.name: part.material for part in load_parts(path).parts}
    painted = parts["Painted"]
    assert painted.albedo_texture.color_space == "srgb"
    roughness = painted.roughness_texture
    assert isinstance(roughness, InlineImageTexture) and roughness.color_space == "raw"
    assert parts["Lost"].roughness_texture.color_space == "raw"  # the placeholder for a missing data file
    table = TextureTable(tmp_path, working_space="acescg")
    pack_material(painted, table)
    np.testing.assert_allclose(table_texels(table, 0)[0, 0], PURE_RED_IN_ACESCG, atol=2e-4)
    np.testing.assert_allclose(table_texels(table, 1)[0, :, 1], mr[0, :, 1] / 255.0, rtol=HALF_TOLERANCE)


def test_obj_map_kd_is_colour_and_map_pr_data(tmp_path):
    write_png(tmp_path / "kd.png", np.full((2, 2, 3), 128))
    write_png(tmp_path / "pr.png", np.full((2, 2, 3), 128))
    path = write_obj(tmp_path, ["Varnish"], "newmtl Varnish\nKd 0.5 0.5 0.5\nKs 0.2 0.2 0.2\nmap_Kd kd.png\n"
                                            "map_Pr pr.png\n")
    material = load_parts(path).parts[0].material
    assert isinstance(material, Plastic)
    assert (material.albedo_texture.color_space, material.roughness_texture.color_space) == ("auto", "raw")


# ---------------------------------------------------------------------------------------------------------
# Names that are no colour space
# ---------------------------------------------------------------------------------------------------------
def scene_file(folder: Path, color_space: str) -> Path:
    data = {"lenslab_scene": FORMAT_VERSION, "materials": {"wood": {"type": "diffuse", "albedo_texture": {
        "type": "image", "file": "wood.png", "color_space": color_space}}}}
    path = folder / "wood.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("name", ["auto", "srgb", "linear", "raw", "ACEScg", "lin_ap1_scene", "sRGB Encoded P3-D65",
                                  "acescg", "Utility - Raw"])
def test_a_scene_file_takes_the_keywords_and_any_ocio_name_or_alias(tmp_path, name):
    scene = load_scene(scene_file(tmp_path, name))
    assert scene.materials["wood"].albedo_texture.color_space == name


def test_a_scene_file_with_no_such_colour_space_is_refused_naming_file_key_and_value(tmp_path):
    path = scene_file(tmp_path, "ACEScgg")
    with pytest.raises(SceneError) as refused:
        load_scene(path)
    message = str(refused.value)
    assert message.startswith(f"{path}: materials.wood.albedo_texture.color_space: 'ACEScgg' is not a colour space")
    assert "give auto, srgb, linear, raw, or the name or alias of any colour space of the OCIO config" in message
    assert "did you mean 'ACEScg'?" in message


def test_a_texture_given_no_such_colour_space_in_memory_shows_the_placeholder_naming_file_and_value(swatch):
    path, _ = swatch
    table = TextureTable(path.parent)
    table.index_of(ImageTexture(file=path.name, color_space="Rec.709 please"))
    (warning,) = table.warnings
    assert warning.startswith(f"{path}: color_space 'Rec.709 please' is not a colour space: give auto, srgb")
    assert warning.endswith("showing a magenta checkerboard instead")


def test_keywords_never_load_ocio_for_a_default_scene(swatch, monkeypatch):
    """A default scene's textures (sRGB or linear into linear Rec.709) are read without OCIO at all."""
    import lenslab.colour_management.texture_spaces as spaces

    def no_ocio(*args, **kwargs):
        raise AssertionError("OCIO loaded")

    monkeypatch.setattr(spaces, "load_config", no_ocio)
    path, _ = swatch
    table = TextureTable(path.parent)
    for color_space in ("auto", "srgb", "linear", "raw"):
        table.index_of(ImageTexture(file=path.name, color_space=color_space))
    assert table.warnings == []  # and no OCIO: a read through it would have raised
