"""Textures placed by (u, v) as Mitsuba 3 places them: the uv transform, wrap modes and filters, the checkerboard's
squares, the importer's bitmap, checkerboard and cylinder, each shape's uvs, and a render against Mitsuba.

GPU lookups run through glsl/texture_probe.comp. References are Mitsuba's rules written out in numpy from its
source (Dr.Jit's texture_impl.h, src/textures/checkerboard.cpp), numbers marked "Mitsuba 3.9.1" (measured once
with mitsuba==3.9.1, llvm_ad_rgb, and written down, so those tests need no Mitsuba), and, in the tests that take
the ``mitsuba`` fixture, a live Mitsuba (skipped where it is not installed).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from lenslab.render.gl import make_current
from lenslab.render.gpu_layout import IMAGE_DATA_BINDING, MATERIALS_BINDING, PROBE_IN_BINDING, PROBE_OUT_BINDING
from lenslab.render.textures import TextureTable
from lenslab.scene.flatten import flatten_scene
from lenslab.scene.io import mitsuba_textures as mt
from lenslab.scene.io.mitsuba_xml import load_mitsuba_string
from lenslab.scene.io.native import scene_from_dict, scene_to_dict
from lenslab.scene.materials import Diffuse, Plastic
from lenslab.scene.scene import Node, Scene, SceneError
from lenslab.scene.shapes import Box, Cylinder
from lenslab.scene.textures import Checkerboard, ImageTexture, uv_fields

LOCAL_SIZE_X = 64
# A camera for the documents below: without one the importer frames the scene by reading its meshes with
# lenslab.scene.io.meshes.load_mesh, which (through trimesh) needs PIL for a mesh with uvs.
SENSOR = ('<sensor type="perspective"><transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" '
          'up="0, 1, 0"/></transform></sensor>')
SCENES = Path(__file__).resolve().parents[1] / "app" / "lenslab" / "validate" / "scenes"


# ---------------------------------------------------------------------------------------------------------
# Helpers
# ---------------------------------------------------------------------------------------------------------
def write_image(path: Path, pixels: np.ndarray) -> Path:
    import OpenImageIO as oiio

    kind = oiio.UINT8 if pixels.dtype == np.uint8 else oiio.FLOAT
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], kind))
    out.write_image(np.ascontiguousarray(pixels))
    out.close()
    return path


def probe(renderer, textures: list, uv: np.ndarray, which: np.ndarray, base_dir: Path) -> np.ndarray:
    """texture_rgb(textures[which[i]], uv[i]) on the GPU, (N, 3)."""
    ctx = renderer.ctx
    make_current(ctx)
    table = TextureTable(base_dir)
    records = np.array([table.index_of(t) for t in textures])
    assert table.warnings == []
    items = np.zeros((len(uv), 4), np.float32)
    items[:, :2], items[:, 2] = uv, records[which]
    texels = table.texels()
    buffers = [ctx.buffer(table.records().astype(np.float32).tobytes()),
               ctx.buffer(texels.tobytes() if texels.size else np.zeros(4, np.uint32).tobytes()),
               ctx.buffer(items.tobytes()), ctx.buffer(reserve=len(uv) * 16)]
    for buffer, binding in zip(buffers, (MATERIALS_BINDING, IMAGE_DATA_BINDING, PROBE_IN_BINDING, PROBE_OUT_BINDING)):
        buffer.bind_to_storage_buffer(binding)
    program = renderer.program("texture_probe.comp", LOCAL_SIZE_X=LOCAL_SIZE_X)
    program["texture_base"].value = 0
    program["item_count"].value = len(uv)
    program.run((len(uv) + LOCAL_SIZE_X - 1) // LOCAL_SIZE_X, 1, 1)
    out = np.frombuffer(buffers[3].read(), np.float32).reshape(-1, 4)[:, :3].copy()
    for buffer in buffers:
        buffer.release()
    return out


def mitsuba_bitmap_lookup(pixels: np.ndarray, st: np.ndarray, wrap: str, filter_type: str) -> np.ndarray:
    """Mitsuba's bitmap at texture coordinates st = to_uv(si.uv): Dr.Jit's tex_eval (texture_impl.h), texel
    row = t H, centres at half-integers, tex_wrap's repeat, mirror and clamp."""
    h, w = pixels.shape[:2]

    def wrapped(i, n):
        if wrap == "clamp":
            return np.clip(i, 0, n - 1)
        if wrap == "repeat":
            return np.mod(i, n)
        m = np.mod(i, 2 * n)
        return np.where(m < n, m, 2 * n - 1 - m)

    x, y = st[:, 0] * w, st[:, 1] * h
    if filter_type == "nearest":
        return pixels[wrapped(np.floor(y).astype(int), h), wrapped(np.floor(x).astype(int), w)]
    x, y = x - 0.5, y - 0.5
    ix, iy = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - ix)[:, None], (y - iy)[:, None]

    def at(dx, dy):
        return pixels[wrapped(iy + dy, h), wrapped(ix + dx, w)]

    return (1 - fy) * ((1 - fx) * at(0, 0) + fx * at(1, 0)) + fy * ((1 - fx) * at(0, 1) + fx * at(1, 1))


def apply(matrix: np.ndarray, uv: np.ndarray) -> np.ndarray:
    return uv @ np.asarray(matrix)[:2, :2].T + np.asarray(matrix)[:2, 2]


def flip_v(uv: np.ndarray) -> np.ndarray:
    return np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1)


def import_texture(xml_texture: str, base_dir: Path, warn=None):
    """A texture element imported as a diffuse reflectance on an OBJ-like (mesh-frame) shape: the texture
    texture_of gives, unfitted."""
    from lenslab.scene.io.mitsuba_xml import MitsubaImporter, _parse_xml, _Expander

    expander = _Expander({})
    root = expander.expand(_parse_xml(f'<scene version="3.0.0">{xml_texture}</scene>'.encode(), "<t>", base_dir), 0)[0]
    importer = MitsubaImporter(root, expander.ids, base_dir, warn or (lambda message: None))
    return importer, root.children[0]


# ---------------------------------------------------------------------------------------------------------
# The scene model's uv transform
# ---------------------------------------------------------------------------------------------------------
def test_any_invertible_affine_uv_map_has_exactly_one_set_of_fields():
    rng = np.random.default_rng(3)
    for _ in range(500):
        matrix = rng.normal(size=(2, 3)) * rng.choice([0.01, 1.0, 50.0])
        fields = uv_fields(matrix)
        assert fields["tiles"][0] > 0 and -180 < fields["rotation_deg"] <= 180
        np.testing.assert_allclose(Checkerboard(**fields).uv_matrix(), matrix, atol=2e-9 * abs(matrix).max())
    # A mirror in v is a negative v tile; a quarter turn a rotation; nice numbers stay nice.
    assert uv_fields([[1, 0, 0], [0, -1, 1]]) == {"tiles": (1.0, -1.0), "shear": 0.0, "rotation_deg": 0.0,
                                                  "offset": (0.0, 1.0)}
    assert uv_fields([[0, -2, 0.2], [2, 0, 0]])["rotation_deg"] == 90.0
    with pytest.raises(ValueError, match="onto a line"):
        uv_fields([[1, 2, 0], [2, 4, 0]])


def test_old_texture_records_keep_their_meaning_and_new_fields_round_trip():
    old = {"lenslab_scene": 2, "materials": {"m": {"type": "diffuse", "albedo_texture": {
        "type": "checker", "tiles": [4, 2]}}}}
    texture = scene_from_dict(old).materials["m"].albedo_texture
    np.testing.assert_array_equal(texture.uv_matrix(), [[4, 0, 0], [0, 2, 0]])  # tiles alone, as before
    image = ImageTexture(file="a.png", tiles=(2.0, -1.0), shear=0.5, rotation_deg=30.0, offset=(0.25, 1.0),
                         wrap="mirror", filter="nearest")
    scene = Scene(materials={"m": Diffuse(albedo_texture=image)})
    assert scene_from_dict(scene_to_dict(scene)).materials["m"].albedo_texture == image
    for bad, message in (({"tiles": [0, 1]}, "must not be zero"), ({"wrap": "tile"}, "not one of")):
        data = {**old, "materials": {"m": {"type": "diffuse", "albedo_texture": {"type": "image", "file": "a.png",
                                                                                 **bad}}}}
        with pytest.raises(Exception, match=message):
            scene_from_dict(data)


# ---------------------------------------------------------------------------------------------------------
# GPU lookups against Mitsuba's rules
# ---------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("wrap", ["repeat", "mirror", "clamp"])
@pytest.mark.parametrize("filter_type", ["bilinear", "nearest"])
def test_image_lookups_follow_drjits_filters_and_wrap_modes(renderer, tmp_path, wrap, filter_type):
    rng = np.random.default_rng(7)
    pixels = rng.uniform(0.0, 1.0, (3, 5, 3)).astype(np.float16).astype(np.float32)  # as the GPU holds them
    path = write_image(tmp_path / "t.exr", pixels)
    texture = ImageTexture(file=str(path), color_space="linear", tiles=(1.7, -2.3), shear=0.3, rotation_deg=25.0,
                           offset=(0.4, -1.2), wrap=wrap, filter=filter_type)
    uv = rng.uniform(-1.5, 2.5, (4000, 2))
    st = apply(texture.uv_matrix(), uv)
    if filter_type == "nearest":  # away from texel edges, where float32 may round to either texel
        texel = st * (5, 3)
        uv = uv[np.all(np.abs(texel - np.round(texel)) > 1e-3, axis=1)]
        st = apply(texture.uv_matrix(), uv)
    got = probe(renderer, [texture], uv.astype(np.float32), np.zeros(len(uv), int), tmp_path)
    # Ours puts the image's top row at t = 1, Mitsuba's at t = 0: the importer composes that flip (below).
    want = mitsuba_bitmap_lookup(pixels, flip_v(st), wrap, filter_type)
    np.testing.assert_allclose(got, want, atol=2e-4)


def mitsuba_checker(color0, color1, to_uv: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """src/textures/checkerboard.cpp's eval: color0 where frac(s) > 1/2 equals frac(t) > 1/2."""
    st = apply(to_uv, uv)
    upper = (st - np.floor(st)) > 0.5
    return np.where((upper[:, 0] == upper[:, 1])[:, None], color0, color1)


def test_imported_checkerboard_has_mitsubas_squares_and_colours(renderer, tmp_path):
    importer, node = import_texture(
        '<texture type="checkerboard" id="c"><rgb name="color0" value="0.9, 0.2, 0.1"/><float name="color1" value="0.3"/>'
        '<transform name="to_uv"><scale x="3" y="1.5"/><rotate z="1" angle="40"/><translate x="0.3" y="-0.7"/>'
        '<matrix value="1 0.4 0 0  0 1 0 0  0 0 1 0  0 0 0 1"/></transform></texture>', tmp_path)
    texture = importer.texture_of(node)
    # to_uv by hand: scale, then rotate, then translate, then shear u by 0.4 v (each applied after the last).
    c, s = math.cos(math.radians(40)), math.sin(math.radians(40))
    to_uv = np.array([[1, 0.4, 0], [0, 1, 0], [0, 0, 1]]) @ np.array([[c, -s, 0.3], [s, c, -0.7], [0, 0, 1]]) @ np.diag(
        [3, 1.5, 1])
    rng = np.random.default_rng(11)
    w = rng.uniform(-2, 2, (3000, 2))  # a mesh's own uvs
    si_uv = flip_v(w)  # what Mitsuba's OBJ reader makes of them
    st = apply(to_uv, si_uv)
    frac = st - np.floor(st)
    keep = np.all(np.minimum(np.abs(frac - 0.5), np.minimum(frac, 1 - frac)) > 1e-4, axis=1)  # off the edges
    got = probe(renderer, [texture], w[keep].astype(np.float32), np.zeros(keep.sum(), int), tmp_path)
    np.testing.assert_allclose(got, mitsuba_checker((0.9, 0.2, 0.1), (0.3, 0.3, 0.3), to_uv, si_uv[keep]), atol=1e-6)


def test_imported_textures_look_up_what_mitsuba_looks_up(renderer, tmp_path, mitsuba):
    mi = mitsuba
    rng = np.random.default_rng(5)
    srgb = rng.integers(0, 256, (6, 4, 3), dtype=np.uint8)
    write_image(tmp_path / "srgb.png", srgb)
    write_image(tmp_path / "grey.png", srgb[..., :1].copy())
    write_image(tmp_path / "hdr.exr", rng.uniform(0, 4, (5, 7, 3)).astype(np.float32))
    to_uv = ('<transform name="to_uv"><scale x="1.3" y="0.8"/><rotate z="1" angle="-20"/><translate x="0.1"/>'
             '</transform>')
    elements = [
        f'<texture type="bitmap"><string name="filename" value="{tmp_path}/srgb.png"/>{to_uv}</texture>',
        f'<texture type="bitmap"><string name="filename" value="{tmp_path}/srgb.png"/><boolean name="raw" value="true"/>'
        '<string name="wrap_mode" value="mirror"/><string name="filter_type" value="nearest"/></texture>',
        f'<texture type="bitmap"><string name="filename" value="{tmp_path}/grey.png"/>'
        f'<string name="wrap_mode" value="clamp"/>{to_uv}</texture>',
        f'<texture type="bitmap"><string name="filename" value="{tmp_path}/hdr.exr"/><string name="wrap_mode" '
        'value="mirror"/><transform name="to_uv"><matrix value="2 0.5 0 0.3  -0.4 1.5 0 0  0 0 1 0  0 0 0 1"/>'
        '</transform></texture>',
        '<texture type="checkerboard"><rgb name="color0" value="0.8, 0.5, 0.1"/><rgb name="color1" '
        f'value="0.1, 0.3, 0.6"/>{to_uv}</texture>',
    ]
    w = rng.uniform(-1.2, 2.2, (2000, 2))
    si = mi.SurfaceInteraction3f()
    si.uv = mi.Point2f(*flip_v(w).T.astype(np.float32))
    for element in elements:
        importer, node = import_texture(element, tmp_path)
        texture = importer.texture_of(node)
        theirs = mi.load_string(element.replace("<texture ", '<texture version="3.0.0" ', 1))
        want = np.array(theirs.eval(si)).T
        got = probe(renderer, [texture], w.astype(np.float32), np.zeros(len(w), int), tmp_path)
        close = np.isclose(got, want, rtol=2e-3, atol=2e-3).all(axis=1)
        # Nearest texels and checker squares may differ at their very edges, where float rounding decides.
        assert close.mean() > 0.995, (element, got[~close][:3], want[~close][:3])
        if texture.type_name == "checker":  # Mitsuba's eval_1 swaps the colours, each its channels' mean
            scalar = importer.texture_of(node, scalar=True)
            grey = probe(renderer, [scalar], w.astype(np.float32), np.zeros(len(w), int), tmp_path)[:, 0]
            want_1 = np.array(theirs.eval_1(si))
            assert np.isclose(grey, want_1, atol=1e-6).mean() > 0.995


# ---------------------------------------------------------------------------------------------------------
# The importer
# ---------------------------------------------------------------------------------------------------------
def test_textured_reflectances_become_textures_shared_by_every_material_that_refers_to_them(tmp_path):
    write_image(tmp_path / "wood.png", np.zeros((2, 2, 3), np.uint8))
    warnings: list[str] = []
    scene = load_mitsuba_string('''<scene version="3.0.0">
        <texture type="bitmap" id="wood"><string name="filename" value="wood.png"/></texture>
        <shape type="obj" id="a"><string name="filename" value="quad.obj"/>
            <bsdf type="diffuse"><ref name="reflectance" id="wood"/></bsdf></shape>
        <shape type="obj" id="b"><string name="filename" value="quad.obj"/>
            <bsdf type="roughplastic"><ref name="diffuse_reflectance" id="wood"/></bsdf></shape>
        <shape type="obj" id="c"><string name="filename" value="quad.obj"/>
            <bsdf type="plastic"><texture type="checkerboard" name="diffuse_reflectance"/></bsdf></shape>
        <shape type="obj" id="d"><string name="filename" value="quad.obj"/>
            <bsdf type="roughconductor"><ref name="specular_reflectance" id="wood"/></bsdf></shape>
    ''' + SENSOR + '</scene>', base_dir=write_quad_obj(tmp_path), warn=warnings.append)
    a, b, c, d = (scene.materials[f"{n}.bsdf"] for n in "abcd")
    assert isinstance(a, Diffuse) and isinstance(b, Plastic) and a.albedo_texture is b.albedo_texture
    # a mesh's uvs take Mitsuba's identity to_uv as is; an 8-bit file without raw is sRGB, as Mitsuba reads it
    assert a.albedo_texture == ImageTexture(file="wood.png", color_space="srgb")
    assert c.albedo_texture == Checkerboard(color_a=(0.4,) * 3, color_b=(0.2,) * 3, tiles=(2.0, -2.0),
                                            offset=(0.0, 2.0))  # Mitsuba's defaults, two squares per unit
    # A conductor's tint cannot vary over the surface: the texture's mean, with a warning naming the line.
    assert d.tint == (0.0, 0.0, 0.0)
    assert len(warnings) == 1 and "<string>:2:" in warnings[0] and "mean colour (0, 0, 0)" in warnings[0]


def write_quad_obj(folder: Path) -> Path:
    (folder / "quad.obj").write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0.1 0.2\nvt 0.9 0.2\nvt 0.9 0.7\n"
                                     "vt 0.1 0.7\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")
    (folder / "quad.ply").write_text("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                     "property float z\nproperty float u\nproperty float v\nelement face 2\n"
                                     "property list uchar int vertex_indices\nend_header\n-1 -1 0 0.1 0.2\n"
                                     "1 -1 0 0.9 0.2\n1 1 0 0.9 0.7\n-1 1 0 0.1 0.7\n3 0 1 2\n3 0 2 3\n")
    from tests.test_mitsuba_serialized import write_serialized

    write_serialized(folder / "quad.serialized", [{"vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],
                                                   "faces": [[0, 1, 2], [0, 2, 3]],
                                                   "uvs": [[0.1, 0.2], [0.9, 0.2], [0.9, 0.7], [0.1, 0.7]]}])
    return folder


def test_bitmap_properties_missing_files_and_bad_values(tmp_path):
    warnings: list[str] = []
    scene = load_mitsuba_string('''<scene version="3.0.0">
        <shape type="obj"><string name="filename" value="quad.obj"/><bsdf type="diffuse">
            <texture type="bitmap" name="reflectance"><string name="filename" value="gone.exr"/>
                <boolean name="raw" value="true"/><string name="filter_type" value="nearest"/>
                <string name="wrap_mode" value="clamp"/><string name="format" value="float16"/></texture>
        </bsdf></shape>''' + SENSOR + '</scene>', base_dir=write_quad_obj(tmp_path), warn=warnings.append, name="gone.xml")
    texture = next(iter(scene.materials.values())).albedo_texture
    assert (texture.file, texture.color_space, texture.filter, texture.wrap) == ("gone.exr", "raw", "nearest", "clamp")
    assert warnings == [f'gone.xml:3: <texture type="bitmap" name="reflectance">: texture file not found: '
                        f"{tmp_path / 'gone.exr'}; LensLab shows a magenta checkerboard in its place"]
    for body, message in (('<string name="wrap_mode" value="wrap"/>', 'line 2: .*invalid wrap_mode "wrap"'),
                          ('<string name="filter_type" value="cubic"/>', 'invalid filter_type "cubic"'),
                          ('', 'a bitmap needs a "filename"')):
        filename = '' if not body else '<string name="filename" value="x.png"/>'
        with pytest.raises(SceneError, match=message):
            load_mitsuba_string(f'''<scene version="3.0.0"><shape type="obj"><string name="filename" value="quad.obj"/>
                <bsdf type="diffuse"><texture type="bitmap" name="reflectance">{filename}{body}</texture></bsdf>
                </shape>{SENSOR}</scene>''', base_dir=tmp_path, warn=lambda m: None)


def test_a_texture_lands_on_each_shape_as_mitsuba_391_puts_it(tmp_path):
    """Mitsuba 3.9.1's si.uv at chosen points (measured with scene.ray_intersect), against the (u, v) our
    shapes have there, through the material the importer gives each shape."""
    def fitted(kind: str, extra: str = ""):
        scene = load_mitsuba_string(f'''<scene version="3.0.0"><shape type="{kind}">{extra}<bsdf type="diffuse">
            <texture type="checkerboard" name="reflectance"/></bsdf></shape></scene>''', base_dir=tmp_path,
                                    warn=lambda m: None)
        node = scene.nodes[0]
        return node, scene.materials[node.material].albedo_texture.uv_matrix() / 2  # Mitsuba's si.uv

    # The rectangle (and flipped): at world (x, y, 0) Mitsuba has ((x + 1) / 2, (y + 1) / 2) either way.
    for extra in ("", '<boolean name="flip_normals" value="true"/>'):
        node, to_si_uv = fitted("rectangle", extra)
        for x, y in ((-0.5, -0.5), (0.5, 0.25)):
            local = np.linalg.inv(node.transform.matrix()) @ (x, y, 0, 1)
            ours = (local[0] + 1) / 2, (local[1] + 1) / 2  # Rectangle(2, 2)'s uvs
            np.testing.assert_allclose(apply(to_si_uv, np.array([ours])), [[(x + 1) / 2, (y + 1) / 2]], atol=1e-12)
    # The cube: one point on each face (Mitsuba 3.9.1), against our Box's uvs there.
    node, to_si_uv = fitted("cube")
    mesh = Box((2, 2, 2)).mesh()
    measured = {(1, .6, -.2): (.8, .6), (-1, .6, -.2): (.8, .4), (.3, 1, -.2): (.35, .6), (.3, -1, -.2): (.4, .65),
                (.3, .6, 1): (.8, .65), (.3, .6, -1): (.2, .65)}
    for point, si_uv in measured.items():
        axis = int(np.argmax(np.abs(point)))
        face = next(f for f in range(6) if np.all(mesh.vertices[4 * f:4 * f + 4, axis] == point[axis]))
        corners, uvs = mesh.vertices[4 * face:4 * face + 4], mesh.uvs[4 * face:4 * face + 4]
        ours = uv_at_point_on_quad(corners, uvs, np.array(point, float))
        np.testing.assert_allclose(apply(to_si_uv, ours[None]), [si_uv], atol=1e-6)
    # The sphere with its poles on the world's Y axis and its seam on -X: exact (Mitsuba 3.9.1 at the
    # unrotated sphere: (1, 0, 0) -> (0, 1/2), (0, 1, 0) -> (1/4, 1/2), (0, 0, 1) -> v = 0).
    node, to_si_uv = fitted("sphere", '<transform name="to_world"><rotate x="1" angle="-90"/>'
                                      '<rotate y="1" angle="180"/></transform>')
    turn = node.transform.matrix()[:3, :3]
    for local, si_uv in (((1, 0, 0), (0, .5)), ((0, 1, 0), (.25, .5)), ((0, 0.6, 0.8), (.25, math.acos(.8) / math.pi))):
        n = turn @ local
        ours = np.array([[math.atan2(n[2], n[0]) / (2 * math.pi) + 0.5, math.acos(n[1]) / math.pi]])
        np.testing.assert_allclose(np.mod(apply(to_si_uv, ours), 1.0), [si_uv], atol=1e-9)


def uv_at_point_on_quad(corners: np.ndarray, uvs: np.ndarray, point: np.ndarray) -> np.ndarray:
    """The uv our quad (two triangles, a parallelogram) has at ``point``: affine in the position."""
    e1, e2 = corners[1] - corners[0], corners[3] - corners[0]
    a, b = np.linalg.lstsq(np.stack([e1, e2], 1), point - corners[0], rcond=None)[0]
    return uvs[0] + a * (uvs[1] - uvs[0]) + b * (uvs[3] - uvs[0])


def test_shapes_whose_uvs_cannot_follow_mitsubas_warn(tmp_path):
    write_image(tmp_path / "a.png", np.zeros((2, 2, 3), np.uint8))
    turned = '<transform name="to_world"><rotate x="1" angle="-90"/><rotate y="1" angle="{}"/></transform>'
    warnings: list[str] = []
    load_mitsuba_string(f'''<scene version="3.0.0">
        <bsdf type="diffuse" id="m"><texture type="checkerboard" name="reflectance"/></bsdf>
        <bsdf type="diffuse" id="clamped"><texture type="bitmap" name="reflectance">
            <string name="filename" value="a.png"/><string name="wrap_mode" value="clamp"/></texture></bsdf>
        <shape type="disk"><ref id="m"/></shape>
        <shape type="sphere"><ref id="m"/></shape>
        <shape type="sphere"><bsdf type="diffuse"/></shape>
        <shape type="sphere"><ref id="m"/>{turned.format(30)}</shape>
        <shape type="sphere"><ref id="clamped"/>{turned.format(180)}</shape>
        <shape type="sphere"><ref id="clamped"/>{turned.format(30)}</shape>
    ''' + SENSOR + "</scene>", base_dir=tmp_path, warn=warnings.append)
    # The disk, the upright sphere, and a clamped image on a sphere whose seam is turned away from ours.
    assert [w.split(": ")[0] for w in warnings] == ["<string>:5", "<string>:6", "<string>:10"]
    assert "polar uvs" in warnings[0] and "poles on the world's Y axis" in warnings[1] and "seam" in warnings[2]


# ---------------------------------------------------------------------------------------------------------
# Each shape's uvs against a live Mitsuba
# ---------------------------------------------------------------------------------------------------------
SHAPES = {
    "rectangle": '<shape type="rectangle"><transform name="to_world"><scale x="1.5"/><rotate x="1" angle="-60"/>'
                 '<translate y="0.2"/></transform>{bsdf}</shape>',
    "flipped rectangle": '<shape type="rectangle"><boolean name="flip_normals" value="true"/>'
                         '<transform name="to_world"><rotate y="1" angle="30"/></transform>{bsdf}</shape>',
    "cube": '<shape type="cube"><transform name="to_world"><scale value="0.7"/><rotate x="1" angle="30"/><rotate y="1" angle="25"/>'
            '</transform>{bsdf}</shape>',
    "sphere": '<shape type="sphere"><transform name="to_world"><rotate x="1" angle="-90"/><rotate y="1" angle="180"/>'
              '<scale value="0.8"/><translate x="0.2"/></transform>{bsdf}</shape>',
    "sphere turned about its poles": '<shape type="sphere"><transform name="to_world"><rotate x="1" angle="90"/>'
                                     '<rotate y="1" angle="37"/></transform>{bsdf}</shape>',
    "cylinder": '<shape type="cylinder"><point name="p0" x="0.2" y="-0.6" z="0.1"/><point name="p1" x="-0.3" y="0.7"'
                ' z="0.4"/><float name="radius" value="0.4"/>{bsdf}</shape>',
    "cylinder by to_world": '<shape type="cylinder"><transform name="to_world"><scale x="0.5" y="0.5" z="1.5"/>'
                            '<rotate x="1" angle="50"/><rotate y="1" angle="20"/><translate z="-0.5"/></transform>'
                            '{bsdf}</shape>',
    "obj": '<shape type="obj"><string name="filename" value="quad.obj"/>{bsdf}</shape>',
    "obj unflipped": '<shape type="obj"><string name="filename" value="quad.obj"/>'
                     '<boolean name="flip_tex_coords" value="false"/>{bsdf}</shape>',
    "ply": '<shape type="ply"><string name="filename" value="quad.ply"/>{bsdf}</shape>',
    "ply flipped": '<shape type="ply"><string name="filename" value="quad.ply"/>'
                   '<boolean name="flip_tex_coords" value="true"/>{bsdf}</shape>',
    "serialized": '<shape type="serialized"><string name="filename" value="quad.serialized"/>{bsdf}</shape>',
}


def lenslab_uv(flat, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(hit, uv, texture coordinates / 2) of each ray on the flattened scene, by brute force (Moller-Trumbore
    on every triangle, the sphere in closed form, uvs as glsl/texcoords.glsl has them)."""
    n = len(origins)
    best, uv, which = np.full(n, np.inf), np.zeros((n, 2)), np.full(n, -1)
    tri = flat.triangles.astype(np.float64)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    for i in range(n):
        o, d = origins[i], directions[i]
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = o - tri[:, 0]
            b1 = np.einsum("ij,ij->i", s, p) * inv
            q = np.cross(s, e1)
            b2 = (q @ d) * inv
            t = np.einsum("ij,ij->i", e2, q) * inv
        ok = (np.abs(det) > 1e-12) & (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1) & (t > 1e-6)
        if ok.any():
            k = np.flatnonzero(ok)[np.argmin(t[ok])]
            best[i], which[i] = t[k], k
            c = flat.triangle_uvs[k].astype(np.float64)
            uv[i] = (1 - b1[k] - b2[k]) * c[0] + b1[k] * c[1] + b2[k] * c[2]
        for s_index, sphere in enumerate(flat.spheres.astype(np.float64)):
            oc = o - sphere[:3]
            b, c = oc @ d, oc @ oc - sphere[3] ** 2
            disc = b * b - c
            if disc > 0 and -b - math.sqrt(disc) > 1e-6 and -b - math.sqrt(disc) < best[i]:
                best[i] = -b - math.sqrt(disc)
                nrm = (oc + best[i] * d) / sphere[3]
                uv[i] = (math.atan2(nrm[2], nrm[0]) / (2 * math.pi) + 0.5, math.acos(np.clip(nrm[1], -1, 1)) / math.pi)
                which[i] = len(flat.triangles) + s_index
    materials = np.concatenate([flat.triangle_material, flat.sphere_material])
    st = np.zeros((n, 2))
    for i in np.flatnonzero(which >= 0):
        texture = flat.materials[materials[which[i]]].albedo_texture
        st[i] = apply(texture.uv_matrix(), uv[i][None])[0] / 2
    return origins + best[:, None] * directions, uv, st


@pytest.mark.parametrize("shape", list(SHAPES))
def test_each_shapes_texture_coordinates_are_mitsubas(tmp_path, mitsuba, shape):
    mi = mitsuba
    write_quad_obj(tmp_path)
    bsdf = '<bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf>'
    xml = f'<scene version="3.0.0">{SHAPES[shape].format(bsdf=bsdf)}{SENSOR}</scene>'
    warnings: list[str] = []
    flat = flatten_scene(load_mitsuba_string(xml, base_dir=tmp_path, warn=warnings.append))
    assert warnings == []
    rng = np.random.default_rng(sum(map(ord, shape)))
    directions = rng.normal(size=(300, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    aim = rng.uniform(-0.3, 0.3, (300, 3))
    origins = aim - 4 * directions
    mscene = mi.load_string(xml.replace('value="quad.', f'value="{tmp_path}/quad.'))
    si = mscene.ray_intersect(mi.Ray3f(mi.Point3f(*origins.T.astype(np.float32)),
                                       mi.Vector3f(*directions.T.astype(np.float32))))
    valid = np.array(si.is_valid())
    m_p, m_uv = np.array(si.p).T, np.array(si.uv).T
    cosine = np.abs(np.einsum("ij,ij->i", np.array(si.n).T, directions))
    hit, _, st = lenslab_uv(flat, origins, directions)
    # The same point of the same surface (a polygonal tube meets the ray within a hair of the round one),
    # not grazing, where the (u, v) compare fairly.
    same = valid & np.isfinite(hit).all(axis=1) & (np.linalg.norm(hit - m_p, axis=1) < 2e-3) & (cosine > 0.2)
    assert same.sum() > 60
    diff = st[same] - m_uv[same]
    if "sphere" in shape or "cylinder" in shape:  # u goes round: compare on the circle
        diff[:, 0] = (diff[:, 0] + 0.5) % 1.0 - 0.5
    tolerance = 2e-3 if "cylinder" in shape else 2e-5  # the polygon's u is linear along each side
    assert np.abs(diff).max() < tolerance


# ---------------------------------------------------------------------------------------------------------
# The cylinder
# ---------------------------------------------------------------------------------------------------------
def test_the_tessellated_cylinder_keeps_the_area_and_stays_within_a_thousandth_of_the_radius():
    shape = Cylinder(radius=0.3, height=2.0, segments=128)
    mesh = shape.mesh()
    corners = mesh.vertices[mesh.faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    assert shape.triangle_count == len(mesh.faces) == 256
    assert np.linalg.norm(normals, axis=1).sum() / 2 == pytest.approx(2 * math.pi * 0.3 * 2.0, rel=1e-12)
    # The silhouette: the prism's corners lie outside the circle, its sides' middles inside, both within 0.1%.
    corner_r = np.linalg.norm(mesh.vertices[:, :2], axis=1)
    middle_r = corner_r.max() * math.cos(math.pi / 128)
    assert 0 < corner_r.max() / 0.3 - 1 < 1e-3 and 0 < 1 - middle_r / 0.3 < 1e-3
    centres = corners.mean(axis=1)
    assert (np.einsum("ij,ij->i", normals[:, :2], centres[:, :2]) > 0).all()  # wound outwards
    assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1) and np.allclose(mesh.normals[:, 2], 0)
    assert mesh.uvs[:, 1].min() == 0 and mesh.uvs[:, 1].max() == 1 and mesh.vertices[:, 2].min() == -1.0
    inward = dataclasses.replace(shape, flip_normals=True).mesh()
    inner = np.cross(*(inward.vertices[inward.faces][:, k] - inward.vertices[inward.faces][:, 0] for k in (1, 2)))
    assert (np.einsum("ij,ij->i", inner[:, :2], centres[:, :2]) < 0).all() and np.allclose(inward.normals, -mesh.normals)
    scene = Scene(nodes=[Node("tube", shape=shape)])
    assert scene_from_dict(scene_to_dict(scene)).nodes[0].shape == shape


def test_a_mitsuba_cylinder_imports_with_its_ends_radius_and_frame():
    warnings: list[str] = []
    scene = load_mitsuba_string('''<scene version="3.0.0"><shape type="cylinder">
        <point name="p0" x="1" y="2" z="3"/><point name="p1" x="1" y="2" z="0"/><float name="radius" value="0.25"/>
        <boolean name="flip_normals" value="true"/>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>''' + SENSOR + "</scene>",
                                warn=warnings.append)
    node = scene.nodes[0]
    assert warnings == [] and node.shape == Cylinder(radius=0.25, height=3.0, segments=128, flip_normals=True)
    matrix = node.transform.matrix()
    np.testing.assert_allclose(matrix[:3, 3], (1, 2, 1.5), atol=1e-12)  # the middle of p0 p1
    # Frame3f(0, 0, -1) (Mitsuba's coordinate_system): s = (1, 0, 0), t = (0, -1, 0): u = 0 towards +X.
    np.testing.assert_allclose(matrix[:3, :3], np.diag([1, -1, -1]), atol=1e-12)
    assert np.allclose(mt.coordinate_system(np.array([0.3, 0.4, -math.sqrt(0.75)]))[0],
                       (0.951768, -0.0643087, 0.3), atol=1e-6)  # Mitsuba 3.9.1's Frame3f


# ---------------------------------------------------------------------------------------------------------
# A render against Mitsuba
# ---------------------------------------------------------------------------------------------------------
def test_the_textured_validation_scene_renders_as_mitsubas(renderer, mitsuba):
    from lenslab.validate import metrics, runner

    path = SCENES / "textured.xml"
    warnings: list[str] = []
    ours = runner.render_lenslab(path, 128, 1, 64, renderer, warnings.append).image
    reference = runner.render_mitsuba(path, 256, 1000, 64).image
    assert warnings == []
    bias = metrics.summarize_bias(metrics.block_bias(ours, reference))
    # 16 blocks of 16 x 16 pixels; noise alone moves one by up to about 1.3% at these sample counts (measured:
    # median 0.2%, largest 1.3%, total light 0.03%); the bitmaps read upside down move one by 3.9%.
    assert bias.median_abs < 0.01 and bias.max_abs < 0.03
    assert abs(metrics.total_light(ours, reference)) < 0.01


def test_the_studio_adds_a_standing_cylinder_at_the_point_of_focus():
    from lenslab.scene import editing
    from lenslab.scene.editable import EditableScene

    model = EditableScene(Scene())
    node = editing.new_primitive(model, "cylinder").node
    frame = model.scene.camera.frame()
    size = round(editing.object_size(frame), 3)
    assert node.shape == Cylinder(radius=size / 2, height=size)
    assert node.transform.translate == pytest.approx(frame.focus_point(), abs=1e-4)
    np.testing.assert_allclose(node.transform.matrix()[:3, :3] @ (0, 0, 1), (0, 1, 0), atol=1e-12)  # axis up
