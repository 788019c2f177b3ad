"""Mesh files bring their own materials: OBJ+MTL and glTF 2.0 mapped onto ours, with what cannot be mapped said
once per material, by name. Test files are written by hand here (text OBJ/MTL, glTF JSON with its buffers)."""

from __future__ import annotations

import base64
import json
import math
import struct

import numpy as np
import pytest

from lenslab.scene.camera import ThinLensCamera
from lenslab.scene.io.mesh_materials import load_parts, roughness_from_phong, srgb_to_linear
from lenslab.scene.io.meshes import load_mesh_parts
from lenslab.scene.materials import Conductor, Dielectric, Diffuse, Emissive, Plastic
from lenslab.scene.scene import ConstantEnvironment, Node, Scene
from lenslab.scene.shapes import MeshFile
from lenslab.scene.textures import ImageTexture, InlineImageTexture
from lenslab.scene.transform import Transform


def write_png(path, pixels) -> bytes:
    import OpenImageIO as oiio

    pixels = np.ascontiguousarray(pixels, dtype=np.uint8)
    height, width, channels = pixels.shape
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(width, height, channels, oiio.UINT8))
    out.write_image(pixels)
    out.close()
    return path.read_bytes()


def fresnel_f0(eta, k):
    """Reflectance of a conductor at normal incidence."""
    eta, k = np.asarray(eta), np.asarray(k)
    return ((eta - 1) ** 2 + k**2) / ((eta + 1) ** 2 + k**2)


def by_name(loaded):
    return {part.name: part for part in loaded.parts}


def warnings_about(loaded, name):
    return [w for w in loaded.warnings if f"material '{name}'" in w]


# ---------------------------------------------------------------------------------------------------------
# OBJ + MTL
# ---------------------------------------------------------------------------------------------------------
def write_obj(folder, materials: list[str], mtl: str, name="model.obj", mtllib="model.mtl"):
    """One unit quad per material, side by side along x, with uvs (0,0) bottom-left to (1,1) top-right."""
    lines = [f"mtllib {mtllib}"]
    for i, material in enumerate(materials):
        x = 2.0 * i
        lines += [f"v {x - 1} -1 0", f"v {x + 1} -1 0", f"v {x + 1} 1 0", f"v {x - 1} 1 0"]
    lines += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
    for i, material in enumerate(materials):
        a = 4 * i
        lines += [f"usemtl {material}", f"f {a + 1}/1 {a + 2}/2 {a + 3}/3", f"f {a + 1}/1 {a + 3}/3 {a + 4}/4"]
    (folder / name).write_text("\n".join(lines) + "\n")
    if mtl is not None:
        (folder / mtllib).write_text(mtl)
    return folder / name


MTL = """\
# a diffuse, a plastic, a glass, a lamp and two metals
newmtl Chalk
Ka 1 1 1
Kd 0.7 0.6 0.5
Ks 0 0 0
illum 1

newmtl Lacquer
Kd 0.1 0.2 0.6
Ks 0.5 0.5 0.5
Ns 100
Ni 1.4

newmtl Glass
Kd 0.8 0.8 0.8
Ni 1.52
d 0
Tf 0.9 1 0.95

newmtl Lamp
Kd 0.8 0.8 0.8
Ke 5 4 3

newmtl Brass
Kd 0 0 0
Ks 0.9 0.7 0.3
Ns 1000

newmtl Steel
Kd 0.6 0.6 0.62
Pm 1
Pr 0.25
"""


def test_obj_materials_map_onto_ours(tmp_path):
    path = write_obj(tmp_path, ["Chalk", "Lacquer", "Glass", "Lamp", "Brass", "Steel"], MTL)
    loaded = load_parts(path)
    parts = by_name(loaded)
    assert set(parts) == {"Chalk", "Lacquer", "Glass", "Lamp", "Brass", "Steel"}
    assert loaded.warnings == ()

    chalk = parts["Chalk"].material
    assert type(chalk) is Diffuse and chalk.albedo == pytest.approx((0.7, 0.6, 0.5)) and chalk.albedo_texture is None

    lacquer = parts["Lacquer"].material
    assert type(lacquer) is Plastic and lacquer.albedo == pytest.approx((0.1, 0.2, 0.6)) and lacquer.ior == 1.4
    # Ns 100 -> Beckmann alpha sqrt(2/102) = 0.140 -> perceptual roughness sqrt(alpha) = 0.374
    assert lacquer.roughness == pytest.approx(math.sqrt(math.sqrt(2 / 102)))

    glass = parts["Glass"].material
    assert type(glass) is Dielectric and glass.ior == 1.52 and glass.roughness == 0.0
    assert glass.tint == pytest.approx((0.9, 1.0, 0.95))

    lamp = parts["Lamp"].material
    assert type(lamp) is Emissive and lamp.radiance == (5.0, 4.0, 3.0)
    # Its Kd is its diffuser's colour: the lamp reflects as well as glows.
    assert type(lamp.surface) is Diffuse and lamp.surface.albedo == pytest.approx((0.8, 0.8, 0.8))

    brass = parts["Brass"].material  # the classic MTL metal: black Kd, coloured Ks
    assert type(brass) is Conductor and brass.metal == "custom"
    assert fresnel_f0(brass.eta, brass.k) == pytest.approx((0.9, 0.7, 0.3), abs=1e-6)
    assert brass.roughness == pytest.approx(roughness_from_phong(1000))

    steel = parts["Steel"].material  # Blender's PBR extension: Pm, Pr; F0 is Kd
    assert type(steel) is Conductor and steel.roughness == 0.25
    assert fresnel_f0(steel.eta, steel.k) == pytest.approx((0.6, 0.6, 0.62), abs=1e-6)

    # Geometry and uvs per part: the Lacquer quad is the second one, at x = 2.
    lacquer_mesh = parts["Lacquer"].mesh
    assert lacquer_mesh.triangle_count == 2
    assert lacquer_mesh.vertices[:, 0].min() == pytest.approx(1.0) and lacquer_mesh.vertices[:, 0].max() == pytest.approx(3.0)
    corner = np.argmin(lacquer_mesh.vertices[:, 0] + lacquer_mesh.vertices[:, 1])
    assert lacquer_mesh.uvs[corner] == pytest.approx((0.0, 0.0))


def test_phong_exponent_to_roughness_is_monotonic_and_bounded():
    values = [roughness_from_phong(ns) for ns in (0, 1, 10, 100, 1000, 1e6)]
    assert values[0] == 1.0 and all(a > b for a, b in zip(values, values[1:])) and values[-1] > 0.0


def test_obj_texture_is_the_file_beside_the_mtl(tmp_path):
    (tmp_path / "maps").mkdir()
    write_png(tmp_path / "maps" / "wood grain.png", np.full((4, 4, 3), 128))
    path = write_obj(tmp_path, ["Wood"], "newmtl Wood\nKd 0.8 0.8 0.8\nmap_Kd -s 2 3 1 maps\\wood grain.png\n")
    loaded = load_parts(path)
    material = loaded.parts[0].material
    assert loaded.warnings == ()
    assert type(material) is Diffuse and isinstance(material.albedo_texture, ImageTexture)
    assert material.albedo_texture.file == str((tmp_path / "maps" / "wood grain.png").resolve())
    assert material.albedo_texture.tiles == (2.0, 3.0)


def test_missing_obj_texture_warns_naming_material_and_file_and_keeps_the_material(tmp_path):
    from lenslab.render.textures import TextureTable

    path = write_obj(tmp_path, ["Wood", "Wood2"], "newmtl Wood\nKd 0.5 0.4 0.3\nmap_Kd textures/oak.jpg\n"
                                                   "newmtl Wood2\nKd 0.5 0.4 0.3\n")
    loaded = load_parts(path)
    (warning,) = loaded.warnings
    assert warning.startswith("model.obj: material 'Wood': map_Kd texture file 'textures/oak.jpg' not found")
    assert str(tmp_path / "textures" / "oak.jpg") in warning
    material = by_name(loaded)["Wood"].material
    assert type(material) is Diffuse and material.albedo_texture.file == str(tmp_path / "textures" / "oak.jpg")
    # ...which the renderer turns into its magenta placeholder, with a warning of its own
    table = TextureTable(tmp_path)
    assert table.index_of(material.albedo_texture) == 0 and "not found" in table.warnings[0]


def test_unmappable_mtl_statements_are_reported_once_per_material(tmp_path):
    mtl = ("newmtl Rock\nKd 0.5 0.5 0.5\nKs 0.2 0.2 0.2\nNs 10\nmap_Bump rock_n.png\ndisp rock_h.png\n"
           "map_Kd -o 0.5 0 0 rock.png\nnewmtl Clean\nKd 0.5 0.5 0.5\n")
    write_png(tmp_path / "rock.png", np.full((2, 2, 3), 200))
    # Rock is used by two separate objects: still one warning.
    path = write_obj(tmp_path, ["Rock", "Clean", "Rock"], mtl)
    loaded = load_parts(path)
    assert warnings_about(loaded, "Clean") == []
    (rock,) = warnings_about(loaded, "Rock")
    assert "map_Bump ignored" in rock and "disp ignored" in rock and "option -o 0.5 0 0 ignored" in rock
    assert len(loaded.warnings) == 1
    rock_part = by_name(loaded)["Rock"]
    assert type(rock_part.material) is Plastic and rock_part.mesh.triangle_count == 4  # both objects, one part


def test_partly_transparent_obj_becomes_glass_with_a_warning(tmp_path):
    path = write_obj(tmp_path, ["Veil"], "newmtl Veil\nKd 1 1 1\nd 0.4\n")
    loaded = load_parts(path)
    assert type(loaded.parts[0].material) is Dielectric and loaded.parts[0].material.ior == 1.5
    assert loaded.warnings == ("model.obj: material 'Veil': dissolve 0.4 (partly transparent) rendered as clear glass",)


def test_obj_without_materials_and_with_a_missing_library(tmp_path):
    plain = write_obj(tmp_path, ["A"], None, name="plain.obj", mtllib="absent.mtl")
    loaded = load_parts(plain)
    assert [p.material for p in loaded.parts] == [None]
    assert len(loaded.warnings) == 1 and "material library 'absent.mtl' not found" in loaded.warnings[0]


# ---------------------------------------------------------------------------------------------------------
# glTF 2.0
# ---------------------------------------------------------------------------------------------------------
QUAD_POSITIONS = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
# glTF's uv origin is the image's top-left corner: the quad's bottom-left corner shows the image's bottom-left.
QUAD_UVS = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
QUAD_INDICES = np.array([0, 1, 2, 0, 2, 3], np.uint16)
QUAD_COLOURS = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 1, 1]], np.float32)


def write_gltf(path, materials=(), primitives=(0,), images=(), textures=(), samplers=(), nodes=None,
               colours=False):
    """A glTF (or GLB, by suffix) with one quad mesh per entry of ``primitives`` (a material index or None).

    ``images``: {"png": bytes} to embed (a bufferView in a GLB, a data URI in a .gltf) or {"uri": "file.png"}.
    ``nodes``: glTF nodes; by default one per mesh, each moved 3 m further along x.
    """
    blob = bytearray()
    views, accessors = [], []

    def add_view(data: bytes) -> int:
        blob.extend(b"\0" * (-len(blob) % 4))
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        return len(views) - 1

    def add_accessor(array, kind, component):
        accessor = {"bufferView": add_view(array.tobytes()), "componentType": component, "count": len(array),
                    "type": kind}
        if kind == "VEC3":
            accessor.update(min=array.min(axis=0).tolist(), max=array.max(axis=0).tolist())
        accessors.append(accessor)
        return len(accessors) - 1

    position = add_accessor(QUAD_POSITIONS, "VEC3", 5126)
    uv = add_accessor(QUAD_UVS, "VEC2", 5126)
    index = add_accessor(QUAD_INDICES, "SCALAR", 5123)
    colour = add_accessor(QUAD_COLOURS, "VEC4", 5126)
    meshes = []
    for material in primitives:
        attributes = {"POSITION": position, "TEXCOORD_0": uv}
        if colours:
            attributes["COLOR_0"] = colour
        primitive = {"attributes": attributes, "indices": index}
        if material is not None:
            primitive["material"] = material
        meshes.append({"name": f"quad{len(meshes)}", "primitives": [primitive]})
    binary = path.suffix == ".glb"
    gltf_images = []
    for image in images:
        if "png" in image and binary:
            gltf_images.append({"bufferView": add_view(image["png"]), "mimeType": "image/png"})
        elif "png" in image:
            gltf_images.append({"uri": "data:image/png;base64," + base64.b64encode(image["png"]).decode()})
        else:
            gltf_images.append({"uri": image["uri"]})
    if nodes is None:
        nodes = [{"mesh": i, "translation": [3.0 * i, 0, 0]} for i in range(len(meshes))]
    header = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
        "meshes": meshes, "materials": list(materials), "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
    }
    for key, value in (("images", gltf_images), ("textures", list(textures)), ("samplers", list(samplers))):
        if value:
            header[key] = value
    if binary:
        text = json.dumps(header).encode()
        text += b" " * (-len(text) % 4)
        data = bytes(blob) + b"\0" * (-len(blob) % 4)
        body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(data), 0x004E4942) + data
        path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
    else:
        header["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()
        path.write_text(json.dumps(header))
    return path


PBR_MATERIALS = [
    {"name": "Paint", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1], "metallicFactor": 0.0,
                                               "roughnessFactor": 0.4},
     "extensions": {"KHR_materials_ior": {"ior": 1.6}}},
    {"name": "Gold", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.77, 0.34, 1], "metallicFactor": 1.0,
                                              "roughnessFactor": 0.2}},
    {"name": "Bottle", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 1.0, 0.9, 1], "metallicFactor": 0.0,
                                                "roughnessFactor": 0.05},
     "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                    "KHR_materials_ior": {"ior": 1.33},
                    "KHR_materials_volume": {"thicknessFactor": 0.01, "attenuationColor": [0.5, 0.8, 1.0],
                                             "attenuationDistance": 0.2}}},
    {"name": "Panel", "emissiveFactor": [1.0, 0.5, 0.25], "doubleSided": True,
     "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}},
]


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_gltf_metallic_roughness_and_khr_extensions_map_onto_ours(tmp_path, suffix):
    path = write_gltf(tmp_path / f"props{suffix}", PBR_MATERIALS, primitives=(0, 1, 2, 3))
    loaded = load_parts(path)
    parts = by_name(loaded)
    assert list(parts) == ["Paint", "Gold", "Bottle", "Panel"]

    paint = parts["Paint"].material
    assert type(paint) is Plastic and paint.albedo == pytest.approx((0.8, 0.1, 0.1))
    assert paint.roughness == pytest.approx(0.4) and paint.ior == pytest.approx(1.6)

    gold = parts["Gold"].material
    assert type(gold) is Conductor and gold.roughness == pytest.approx(0.2) and gold.tint == (1.0, 1.0, 1.0)
    assert fresnel_f0(gold.eta, gold.k) == pytest.approx((1.0, 0.77, 0.34), abs=1e-3)  # base colour is F0

    bottle = parts["Bottle"].material
    assert type(bottle) is Dielectric and bottle.ior == pytest.approx(1.33) and bottle.roughness == pytest.approx(0.05)
    assert bottle.tint == pytest.approx((0.9, 1.0, 0.9))
    assert bottle.absorption_color == pytest.approx((0.5, 0.8, 1.0)) and bottle.absorption_distance_m == pytest.approx(0.2)

    panel = parts["Panel"].material
    assert type(panel) is Emissive and panel.radiance == pytest.approx((4.0, 2.0, 1.0)) and panel.two_sided
    # glTF's emission adds to the surface's own reflection: here the default white, fully rough metal.
    assert type(panel.surface) is Conductor and panel.surface.roughness == pytest.approx(1.0)

    # The node transforms of the graph are applied: the fourth quad sits 9 m along x.
    assert parts["Panel"].mesh.vertices[:, 0].mean() == pytest.approx(9.0)
    assert loaded.warnings == ()


def test_unmappable_gltf_features_are_reported_once_per_material_by_name(tmp_path):
    materials = [
        {"name": "Coat", "pbrMetallicRoughness": {"metallicFactor": 0.3, "roughnessFactor": 0.5},
         "normalTexture": {"index": 0}, "occlusionTexture": {"index": 0}, "alphaMode": "BLEND",
         "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0}}},
        {"name": "Plain", "pbrMetallicRoughness": {"metallicFactor": 0.0}},
        {"name": "Haze", "pbrMetallicRoughness": {"metallicFactor": 0.0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5}}},
    ]
    png = write_png(tmp_path / "n.png", np.full((2, 2, 3), 128))
    # Coat is used twice (two primitives, and the mesh instanced twice): still one line.
    nodes = [{"mesh": 0}, {"mesh": 1, "translation": [3, 0, 0]}, {"mesh": 0, "translation": [0, 3, 0]},
             {"mesh": 2, "translation": [6, 0, 0]}, {"mesh": 3, "translation": [9, 0, 0]}]
    path = write_gltf(tmp_path / "mesh.glb", materials, primitives=(0, 0, 1, 2), images=[{"png": png}],
                      textures=[{"source": 0}], nodes=nodes, colours=True)
    loaded = load_parts(path)
    parts = by_name(loaded)
    assert type(parts["Coat"].material) is Plastic and type(parts["Haze"].material) is Dielectric
    assert parts["Coat"].mesh.triangle_count == 6  # both primitives and the instance: one part for the material
    (coat,) = warnings_about(loaded, "Coat")
    assert coat.startswith("mesh.glb: material 'Coat': ")
    for dropped in ("KHR_materials_clearcoat ignored", "alpha mode BLEND ignored", "normal map ignored",
                    "occlusion map ignored", "metallic 0.30 rendered as plastic", "vertex colours ignored"):
        assert dropped in coat
    assert warnings_about(loaded, "Plain") == ["mesh.glb: material 'Plain': vertex colours ignored"]
    (haze,) = warnings_about(loaded, "Haze")
    assert "transmission 0.50 rendered as fully transmissive glass" in haze
    assert len(loaded.warnings) == 3


def test_embedded_base_colour_texture_keeps_its_pixels_and_orientation(tmp_path):
    # 4 x 2 image, row 0 on top: the top-left texel is red, the bottom-left one blue.
    image = np.zeros((2, 4, 3), np.uint8)
    image[0, 0] = (255, 0, 0)
    image[1, 0] = (0, 0, 255)
    image[1, 3] = (255, 255, 255)
    image[0, 1:3] = (128, 64, 32)
    png = write_png(tmp_path / "albedo.png", image)
    materials = [{"name": "Label", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0,
                                                            "baseColorFactor": [1.0, 0.5, 1.0, 1.0]}}]
    path = write_gltf(tmp_path / "label.glb", materials, images=[{"png": png}], textures=[{"source": 0}])
    loaded = load_parts(path)
    assert loaded.warnings == ()
    part = loaded.parts[0]
    texture = part.material.albedo_texture
    assert isinstance(texture, InlineImageTexture) and texture.pixels.shape == (2, 4, 3)
    # linearised sRGB, times the base colour factor
    expected = srgb_to_linear(image / 255.0) * (1.0, 0.5, 1.0)
    assert np.allclose(texture.pixels, expected, atol=1e-6)
    assert texture.pixels[0, 1] == pytest.approx((0.2158605, 0.0512695 * 0.5, 0.0144438), abs=1e-4)

    # Our uv convention (glsl/textures.glsl): u right, v up, image row 0 at v = 1. The quad's bottom-left
    # corner must show the image's bottom-left texel, the top-left corner its top-left one.
    def texel_at(uv):
        h, w = texture.pixels.shape[:2]
        x = min(int(uv[0] * w), w - 1)
        y = min(int((1.0 - uv[1]) * h), h - 1)
        return texture.pixels[y, x]

    mesh = part.mesh
    bottom_left = np.argmin(mesh.vertices[:, 0] + mesh.vertices[:, 1])
    top_left = np.argmin(mesh.vertices[:, 0] - mesh.vertices[:, 1])
    bottom_right = np.argmax(mesh.vertices[:, 0] - mesh.vertices[:, 1])
    assert mesh.uvs[bottom_left] == pytest.approx((0.0, 0.0))
    assert texel_at(mesh.uvs[bottom_left]) == pytest.approx(expected[1, 0])  # blue
    assert texel_at(mesh.uvs[top_left]) == pytest.approx(expected[0, 0])  # red
    assert texel_at(mesh.uvs[bottom_right] - 1e-6) == pytest.approx(expected[1, 3])  # white, times the factor


def test_external_texture_is_the_file_and_a_missing_one_warns(tmp_path):
    write_png(tmp_path / "here.png", np.full((2, 2, 3), 90))
    materials = [
        {"name": "Found", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}},
        {"name": "Lost", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}, "metallicFactor": 0}},
    ]
    path = write_gltf(tmp_path / "scene.gltf", materials, primitives=(0, 1), images=[{"uri": "here.png"},
                      {"uri": "maps/gone%20away.png"}], textures=[{"source": 0}, {"source": 1}])
    loaded = load_parts(path)
    parts = by_name(loaded)
    found = parts["Found"].material.albedo_texture
    assert isinstance(found, ImageTexture) and found.file == str(tmp_path / "here.png") and found.color_space == "srgb"
    lost = parts["Lost"].material
    assert type(lost) is Plastic and lost.albedo_texture.file == str(tmp_path / "maps" / "gone away.png")
    (warning,) = loaded.warnings
    assert warning.startswith("scene.gltf: material 'Lost': base colour texture file 'maps/gone%20away.png' not found")
    assert "magenta" in warning


def test_metallic_roughness_texture_gives_a_roughness_texture_from_green(tmp_path):
    mr = np.zeros((2, 2, 3), np.uint8)
    mr[..., 1] = [[0, 255], [128, 64]]  # roughness varies
    mr[..., 2] = 0  # metalness: none anywhere
    varied = mr.copy()
    varied[..., 2] = [[0, 255], [0, 0]]  # metalness varies: mean 0.25 -> plastic, with a warning
    materials = [
        {"name": "Rubber", "pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0},
                                                    "roughnessFactor": 0.5, "metallicFactor": 1.0}},
        {"name": "Mixed", "pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 1}}},
    ]
    images = [{"png": write_png(tmp_path / "mr.png", mr)}, {"png": write_png(tmp_path / "mixed.png", varied)}]
    path = write_gltf(tmp_path / "mr.gltf", materials, primitives=(0, 1), images=images,
                      textures=[{"source": 0}, {"source": 1}])
    loaded = load_parts(path)
    rubber = by_name(loaded)["Rubber"].material
    assert type(rubber) is Plastic  # metallicFactor 1 times a metalness channel of 0
    texture = rubber.roughness_texture
    assert isinstance(texture, InlineImageTexture)
    # the renderer reads roughness from the red channel, linear: G times roughnessFactor, replicated
    assert np.allclose(texture.pixels[..., 0], mr[..., 1] / 255.0 * 0.5, atol=1e-6)
    assert np.allclose(texture.pixels[..., 0], texture.pixels[..., 2])
    assert warnings_about(loaded, "Rubber") == []
    (mixed,) = warnings_about(loaded, "Mixed")
    assert "metalness texture ignored (mean metallic 0.25 -> plastic)" in mixed
    assert type(by_name(loaded)["Mixed"].material) is Plastic


def test_gltf_without_materials_gives_a_part_per_geometry(tmp_path):
    path = write_gltf(tmp_path / "bare.glb", [], primitives=(None, None))
    loaded = load_parts(path)
    assert len(loaded.parts) == 2 and all(p.material is None for p in loaded.parts) and loaded.warnings == ()
    assert sorted(p.mesh.vertices[:, 0].mean() for p in loaded.parts) == pytest.approx([0.0, 3.0])


# ---------------------------------------------------------------------------------------------------------
# PLY
# ---------------------------------------------------------------------------------------------------------
def test_ply_vertex_colours_warn_once_and_plain_ply_is_one_bare_part(tmp_path):
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=1)
    ball.export(tmp_path / "plain.ply")
    plain = load_parts(tmp_path / "plain.ply")
    assert len(plain.parts) == 1 and plain.parts[0].material is None and plain.warnings == ()
    assert plain.parts[0].mesh.triangle_count == len(ball.faces)

    ball.visual.vertex_colors = np.tile([255, 0, 0, 255], (len(ball.vertices), 1))
    ball.export(tmp_path / "red.ply")
    red = load_parts(tmp_path / "red.ply")
    assert [p.material for p in red.parts] == [None]
    assert red.warnings == ("red.ply: vertex colours ignored (LensLab takes colour from materials and textures only)",)


# ---------------------------------------------------------------------------------------------------------
# Through the scene
# ---------------------------------------------------------------------------------------------------------
def test_a_scene_flattens_with_the_files_materials(tmp_path):
    path = write_gltf(tmp_path / "props.glb", PBR_MATERIALS, primitives=(0, 1))
    obj = write_obj(tmp_path, ["Lacquer"], MTL)
    scene = Scene(
        materials={"white": Diffuse((0.9, 0.9, 0.9))},
        nodes=[Node("props", Transform(translate=(0, 1, 0)), MeshFile("props.glb")),
               Node("override", shape=MeshFile("props.glb"), material="white"),
               Node("obj", shape=MeshFile(obj.name))],
        source_path=tmp_path / "scene.json",
    )
    assert load_mesh_parts(path) is load_mesh_parts(path)  # cached
    flat = scene.flatten()
    names = flat.material_names
    assert "props: Paint" in names and "props: Gold" in names and "obj: Lacquer" in names
    assert type(flat.materials[names.index("props: Gold")]) is Conductor
    node_of = np.asarray([flat.nodes[i].name for i in flat.prim_node])
    override = flat.triangle_material[node_of == "override"]
    assert set(override) == {names.index("white")}
    assert flat.warnings == ()
    props = flat.triangles[node_of == "props"].reshape(-1, 3)
    assert props[:, 1].mean() == pytest.approx(1.0)


@pytest.mark.gl
def test_a_textured_gltf_renders_its_texture(renderer, tmp_path):
    from lenslab.render.tracer import RenderSession
    from tests.helpers import render_to_spp

    # 8 x 8 image in four colour blocks: red top-left, green top-right, blue bottom-left, white bottom-right.
    image = np.zeros((8, 8, 3), np.uint8)
    image[:4, :4] = (255, 0, 0)
    image[:4, 4:] = (0, 255, 0)
    image[4:, :4] = (0, 0, 255)
    image[4:, 4:] = (255, 255, 255)
    png = write_png(tmp_path / "blocks.png", image)
    materials = [{"name": "Chart", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                            "metallicFactor": 0.0, "roughnessFactor": 1.0}}]
    write_gltf(tmp_path / "chart.glb", materials, images=[{"png": png}], textures=[{"source": 0}])
    scene = Scene(
        camera=ThinLensCamera(position=(0, 0, 3), look_at=(0, 0, 0), focal_length_mm=70, f_number=16,
                              focus_distance_m=3, resolution=(16, 16)),
        environment=ConstantEnvironment((1.0, 1.0, 1.0)),
        nodes=[Node("chart", shape=MeshFile("chart.glb"))],
        source_path=tmp_path / "scene.json",
    )
    session = RenderSession(renderer, scene, width=16, height=16)
    try:
        picture = render_to_spp(session, 1).image()
    finally:
        session.release()
    quadrant = {"top-left": picture[2:6, 2:6], "top-right": picture[2:6, 10:14],
                "bottom-left": picture[10:14, 2:6], "bottom-right": picture[10:14, 10:14]}
    mean = {k: v.reshape(-1, 3).mean(axis=0) for k, v in quadrant.items()}
    r, g, b = mean["top-left"]
    assert r > 3 * g and r > 3 * b, mean
    r, g, b = mean["top-right"]
    assert g > 3 * r and g > 3 * b, mean
    r, g, b = mean["bottom-left"]
    assert b > 3 * r and b > 3 * g, mean
    assert min(mean["bottom-right"]) > 0.5 and np.ptp(mean["bottom-right"]) < 0.2, mean


def test_statements_that_change_nothing_are_not_reported(tmp_path):
    # What Blender writes with its PBR extensions on: zero sheen, clearcoat and anisotropy change nothing.
    mtl = ("newmtl Blender\nNs 250\nKa 1 1 1\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nKe 0 0 0\nNi 1.45\nd 1\nillum 2\n"
           "Pr 0.5\nPm 0\nPs 0\nPc 0\nPcr 0.03\naniso 0\nanisor 0\n"
           "newmtl Coated\nKd 0.8 0.8 0.8\nPc 1\nPcr 0.1\n")
    path = write_obj(tmp_path, ["Blender", "Coated"], mtl)
    loaded = load_parts(path)
    material = by_name(loaded)["Blender"].material
    assert type(material) is Plastic and material.roughness == 0.5 and material.ior == 1.45
    assert loaded.warnings == ("model.obj: material 'Coated': Pc ignored; Pcr ignored",)

    materials = [{"name": "Quiet", "pbrMetallicRoughness": {"metallicFactor": 0},
                  "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.0},
                                 "KHR_materials_specular": {"specularFactor": 1.0}}},
                 {"name": "Sheen", "pbrMetallicRoughness": {"metallicFactor": 0},
                  "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5]}}}]
    loaded = load_parts(write_gltf(tmp_path / "quiet.gltf", materials, primitives=(0, 1)))
    assert loaded.warnings == ("quiet.gltf: material 'Sheen': KHR_materials_sheen ignored",)
