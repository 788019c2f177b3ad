"""Malformed input meets one clear line: the file named, what is wrong, a non-zero exit; never a traceback.

The seeded run goes through hundreds of broken scenes made by ``tests/malformed_inputs.py``; the cases
below it are the minimal ones of each class that once ended in a traceback or slipped through.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest

from lenslab.cli import main
from lenslab.messages import LONGEST_LINE, one_line
from tests import malformed_inputs

pytestmark = pytest.mark.gl
CORNELL = Path(__file__).resolve().parent.parent / "scenes" / "cornell_box" / "scene.json"


def _seeded_run(count: int, seed: int, folder: Path) -> None:
    """``count`` cases of the generator, each in this process; a hang is found from the work a case does (the
    harness's watcher), never from the clock, so a machine busy with other work makes the run slower, not red."""
    failures = []
    try:
        for index, case in enumerate(malformed_inputs.generate(count, seed=seed)):
            outcome = malformed_inputs.run_in_process(case, folder / "case")
            if outcome.problem:
                failures.append(f"[{index}] {case.what[:100]!r}: {outcome.problem}: "
                                f"{outcome.stderr.strip()[-300:]!r}")
    finally:
        malformed_inputs.close_watcher()
    assert not failures, f"{len(failures)} of {count} cases broke the contract:\n" + "\n".join(failures)


@pytest.mark.slow  # its scenes compile dozens of kernel variants: minutes on llvmpipe with a cold shader cache
def test_a_seeded_run_of_malformed_inputs_meets_the_contract(tmp_path):
    _seeded_run(300, 2026, tmp_path)


@pytest.mark.slow
def test_a_long_seeded_run_of_malformed_inputs_meets_the_contract(tmp_path):
    _seeded_run(3000, 11, tmp_path)


def test_the_seeded_run_covers_every_class_of_input():
    """The default run meets each kind of case at least a few times: batch values (TOML dates among them),
    truncated .serialized meshes, glTF fields of the wrong type, named pipes read and written."""
    whats = [case.what for case in malformed_inputs.generate(300, seed=2026)]
    for prefix in ("batch: ", "serialized: ", "glTF: ", "FIFO: "):
        assert sum(what.startswith(prefix) for what in whats) >= 5, prefix
    assert any(what.startswith("batch: ") and re.search(r"\d{4}-\d\d-\d\d|\d\d:\d\d:\d\d", what) for what in whats)
    assert any(what.startswith("serialized: mesh 0's stream ended") for what in whats)


def _run(*args: str) -> tuple[int, str]:
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        status = main([*map(str, args)])
    return status, stderr.getvalue()


def _render(scene: Path, tmp_path: Path, *extra: str) -> tuple[int, str]:
    return _run(scene, "--headless", "-o", tmp_path / "out.png", "--spp", "1", "--width", "8", "--height", "8",
                *extra)


def _cornell(tmp_path: Path, edit) -> Path:
    doc = json.loads(CORNELL.read_text())
    edit(doc)
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(doc))
    return path


def _one_error(status: int, stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert status == 1 and len(lines) == 1 and lines[0].startswith("lenslab: error: "), stderr
    assert "Traceback" not in stderr
    return lines[0]


def _add_node(doc: dict, shape: dict) -> None:
    doc["nodes"].append({"name": "extra", "shape": shape, "children": []})


@pytest.mark.parametrize("mesh_name, text, expected", [
    ("m.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 99\n",
     "1 face index points outside the 3 vertices"),
    ("m.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
    ("m.obj", "v 3.4e38 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "beyond the 1e+30"),
    ("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n",
     "node 'extra': 1 triangle has normals that are not finite numbers"),
])
def test_a_broken_mesh_is_named(tmp_path, mesh_name, text, expected):
    (tmp_path / mesh_name).write_text(text)
    scene = _cornell(tmp_path, lambda doc: _add_node(doc, {"type": "mesh", "file": mesh_name}))
    line = _one_error(*_render(scene, tmp_path))
    assert (mesh_name in line or "node 'extra'" in line) and expected in line and str(scene) in line
    assert line.count(f"{scene}: ") == 1, "the scene file is named once"


def test_an_mtl_emission_that_is_not_a_number_is_refused(tmp_path):
    (tmp_path / "m.obj").write_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glow\nf 1 2 3\n")
    (tmp_path / "m.mtl").write_text("newmtl glow\nKe nan inf 1\n")
    scene = _cornell(tmp_path, lambda doc: _add_node(doc, {"type": "mesh", "file": "m.obj"}))
    line = _one_error(*_render(scene, tmp_path))
    assert "m.mtl: material 'glow': Ke nan inf 1: not a finite number" in line


@pytest.mark.parametrize("edit, expected", [
    (lambda doc: doc["render"].update(spp=int("9" * 400)), "render.spp: a 400-digit number is too large"),
    (lambda doc: doc.update(environment={"type": []}), "environment.type: unknown type []"),
    (lambda doc: doc["camera"].update(focus_distance_m=float("nan")), "camera.focus_distance_m: nan is not a finite"),
    (lambda doc: doc["nodes"][0]["transform"].update(translate=[3.4e38, 0, 0]), "is too large"),
    (lambda doc: doc["materials"]["white"].update(albedo=[float("inf"), 0, 0]), "inf is not a finite number"),
])
def test_a_native_value_that_cannot_be_is_named_with_its_key(tmp_path, edit, expected):
    scene = _cornell(tmp_path, edit)
    line = _one_error(*_render(scene, tmp_path))
    assert str(scene) in line and expected in line


def test_a_node_tree_deeper_than_the_format_allows_is_refused(tmp_path):
    node = {"name": "leaf", "shape": {"type": "sphere", "radius": 0.1}}
    for _ in range(250):
        node = {"name": "level", "children": [node]}
    scene = _cornell(tmp_path, lambda doc: doc.update(nodes=[node]))
    line = _one_error(*_render(scene, tmp_path))
    assert "nodes: nested more than 100 deep" in line


@pytest.mark.parametrize("text, expected", [
    ("[" * 100_000 + "]" * 100_000, "nested too deeply to read"),
    ('{"lenslab_scene": 2, "render": {"spp": ' + "9" * 5000 + "}}", "a number too long to read"),
])
def test_a_json_file_python_cannot_parse_is_named(tmp_path, text, expected):
    scene = tmp_path / "scene.json"
    scene.write_text(text)
    line = _one_error(*_render(scene, tmp_path))
    assert str(scene) in line and expected in line


@pytest.mark.parametrize("xml, expected", [
    ('<scene version="3.0.0"><sensor type="perspective"><float name="fov"/></sensor></scene>',
     'line 1: <float name="fov">: missing attribute "value"'),
    ('<?xml version="1.0" encoding="bogus"?>\n<scene version="3.0.0"/>', "unknown encoding: bogus"),
    ('<?xml version="1.0" encoding="utf-32"?>\n<scene version="3.0.0"/>', "cannot read the file's encoding"),
    ('<scene version="3.0.0"><shape type="sphere"><bsdf type="dielectric"><float name="ext_ior" value="0"/>'
     '</bsdf></shape></scene>', "an index of refraction must be positive"),
    ('<scene version="3.0.0"><shape type="sphere"><bsdf type="roughconductor"><float name="alpha_u" value="-1"/>'
     '<float name="alpha_v" value="0.1"/></bsdf></shape></scene>', "alpha_u must not be negative"),
    ('<scene version="3.0.0"><shape type="sphere"><transform name="to_world"><translate x="nan"/></transform>'
     '</shape></scene>', "could not parse a number"),
    ('<scene version="3.0.0">' + '<shape type="sphere">' * 1000 + "</shape>" * 1000 + "</scene>",
     "elements nested more than 100 deep"),
    ('<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="inf"/></sensor></scene>',
     'could not parse "inf" as a finite floating point value'),
    ('<scene version="3.0.0"><shape type="shapegroup" id="g"><shape type="instance"><ref id="g"/></shape></shape>'
     '<shape type="instance"><ref id="g"/></shape></scene>', '<shape type="shapegroup" id="g"> instances itself'),
    ('<scene version="3.0.0"><shape type="shapegroup" id="g0"><shape type="sphere"/></shape>'
     + "".join(f'<shape type="shapegroup" id="g{i}">' + f'<shape type="instance"><ref id="g{i - 1}"/></shape>' * 30
               + "</shape>" for i in range(1, 5)) + '<shape type="instance"><ref id="g4"/></shape></scene>',
     "instances of shapegroups make more than 250,000 nodes"),
])
def test_a_broken_mitsuba_file_is_named_with_its_line(tmp_path, xml, expected):
    scene = tmp_path / "scene.xml"
    scene.write_text(xml)
    line = _one_error(*_render(scene, tmp_path))
    assert line.count(f"{scene}: ") == 1 and expected in line


def test_a_file_name_too_long_for_the_file_system_is_named(tmp_path):
    scene = _cornell(tmp_path, lambda doc: _add_node(doc, {"type": "mesh", "file": "n" * 300 + ".obj"}))
    line = _one_error(*_render(scene, tmp_path))
    assert str(scene) in line and "Errno" not in line and (".obj" in line)


def test_error_lines_escape_what_a_terminal_would_obey(tmp_path):
    scene = _cornell(tmp_path, lambda doc: doc["materials"].update({"\x1b[2J": {"type": "nonsense"}}))
    line = _one_error(*_render(scene, tmp_path))
    assert "\x1b" not in line and "\\x1b[2J" in line


def test_one_line_escapes_controls_and_shortens_what_is_endless():
    assert one_line("a\nb\x1b[31m\u202e") == "a\\nb\\x1b[31m\\u202e"
    long = one_line("value '" + "x" * 100_000 + "' is wrong")
    assert len(long) <= LONGEST_LINE and long.endswith("' is wrong") and "…" in long
    many = one_line(", ".join(f"'s{i}'" for i in range(5000)), prefix="lenslab: error: ")  # short words, many
    assert len(many) == LONGEST_LINE and many.startswith("lenslab: error: 's0', ") and many.endswith("'s4999'")
    path = "/home/me/" + "/".join(["folder"] * 20) + "/scene.json"
    assert one_line(f"{path}: bad") == f"{path}: bad", "a real path stays whole"


def test_a_python_warning_is_one_warning_line(capsys):
    import warnings

    from lenslab import cli

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        cli._report_library_warnings()
        warnings.warn("overflow encountered in multiply", RuntimeWarning)
    err = capsys.readouterr().err
    assert err == "lenslab: warning: RuntimeWarning: overflow encountered in multiply\n"


def test_an_image_cut_short_is_named_and_nothing_else_reaches_stderr(tmp_path):
    """OpenImageIO reads a truncated EXR in part and, unless its error is fetched, prints it from C++ as the
    buffer is destroyed: the environment map's warning must be the only word about it."""
    import shutil
    import subprocess
    import sys

    for source in (CORNELL.parent.parent / "product_shot").iterdir():
        shutil.copy(source, tmp_path)
    studio = tmp_path / "studio.exr"
    studio.write_bytes(studio.read_bytes()[: studio.stat().st_size * 2 // 3])
    from lenslab.render.textures import read_texture_image

    with pytest.raises(OSError, match="studio.exr: cannot read the image"):
        read_texture_image(studio)
    done = subprocess.run([sys.executable, "-m", "lenslab", tmp_path / "scene.json", "--headless", "-o",
                           tmp_path / "out.png", "--spp", "1", "--width", "8", "--height", "8"],
                          capture_output=True, text=True, timeout=120)
    lines = done.stderr.splitlines()
    assert done.returncode == 0 and all(line.startswith(("lenslab: ", "wrote ")) for line in lines), done.stderr
    assert any(f"{studio}: cannot read the image" in line and "magenta sky" in line for line in lines)


def test_an_image_that_claims_too_many_pixels_is_refused_from_its_header(tmp_path, monkeypatch):
    """A PNG of a few kilobytes may claim 60000 x 60000 pixels and decode into gigabytes: read its header only."""
    import OpenImageIO as oiio

    from lenslab import image_files

    bomb = tmp_path / "bomb.png"
    out = oiio.ImageOutput.create(str(bomb))
    out.open(str(bomb), oiio.ImageSpec(4000, 3000, 1, oiio.UINT8))
    out.write_image(np.zeros((3000, 4000, 1), np.uint8))
    out.close()
    monkeypatch.setattr("lenslab.limits.MAX_SOURCE_PIXELS", 1000 * 1000)  # small enough to test with a small file

    def never(*args):
        raise AssertionError("the pixels were decoded")

    monkeypatch.setattr(oiio.ImageBuf, "get_pixels", never)
    with pytest.raises(OSError, match=r"bomb.png: cannot read the image \(4000 x 3000 pixels, more than the "
                                      r"1,000,000 LensLab reads\)"):
        image_files.read_pixels(bomb)


def _png_claiming(width: int, height: int) -> bytes:
    """A one-pixel grey PNG whose header claims another size (zero, or a decompression bomb's)."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(b"\x00\x80"))
            + chunk(b"IEND", b""))


def test_what_an_image_library_prints_from_c_stays_off_stderr(tmp_path):
    """libpng prints "libpng error: Invalid IHDR data" itself; OpenImageIO says the same in its error text."""
    import subprocess
    import sys

    image = tmp_path / "zero.png"
    image.write_bytes(_png_claiming(0, 0))
    done = subprocess.run([sys.executable, "-m", "lenslab", "cornell_box", "--headless", "-o", tmp_path / "out.png",
                           "--aperture-image", image, "--spp", "1", "--width", "8", "--height", "8"],
                          capture_output=True, text=True, timeout=120)
    # A usage error: the option named a file that is no image (it is read as the option is parsed).
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(f"lenslab: error: argument --aperture-image: {image}: cannot read the image")


def test_a_batch_s_names_reach_the_terminal_escaped(tmp_path, capsys):
    (tmp_path / "b.json").write_text('{"shots": [{"name": "\\u001b[2Jwiped \\ud800", "scene": "cornell_box", '
                                     '"output": "{index}.png"}]}')  # a lone surrogate: JSON allows it
    assert main(["batch", str(tmp_path / "b.json"), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\\x1b[2Jwiped \\ud800: " in out
    (tmp_path / "b.toml").write_text('[[shots]]\nscene = "cornell_box"\noutput = "\\u001b[31m{index}.png"\n')
    assert main(["batch", str(tmp_path / "b.toml"), "--dry-run"]) == 1
    assert "output: a file name holds no control characters ('\\x1b[31m{index}.png')" in capsys.readouterr().err


def test_a_texture_reduced_in_size_has_no_negative_texels(tmp_path):
    """OpenImageIO's resize filter rings below zero beside a sharp edge: an environment map of 4097 x 1 once lit
    a pixel with negative radiance."""
    import OpenImageIO as oiio

    from lenslab.render.textures import MAX_SIDE, read_texture_image

    stripes = np.zeros((1, MAX_SIDE + 1, 3), np.float32)
    stripes[:, ::2] = 1.0
    stripes[:, 2000:2100] = 100.0
    path = tmp_path / "stripes.exr"
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(MAX_SIDE + 1, 1, 3, oiio.FLOAT))
    out.write_image(stripes)
    out.close()
    texels = read_texture_image(path, "linear")
    assert texels.shape == (1, MAX_SIDE, 3) and texels.min() >= 0.0


def test_a_texel_brighter_than_any_light_or_negative_is_clamped_with_a_warning(tmp_path, caplog):
    import OpenImageIO as oiio

    from lenslab.render.textures import BRIGHTEST, read_texture_image

    pixels = np.ones((4, 8, 3), np.float32)
    pixels[1, 2] = 3e38  # finite in float32, but the map's power and sampling table overflow with it
    pixels[3, 7] = -5.0  # and no light is negative
    path = tmp_path / "sky.exr"
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(8, 4, 3, oiio.FLOAT))
    out.write_image(pixels)
    out.close()
    texels = read_texture_image(path, "linear")
    assert texels.max() == np.float32(BRIGHTEST) and texels.min() == 0.0 and texels[0, 0, 0] == 1.0
    assert "sky.exr: 1 texel is brighter than 1e+10, beyond any light: clamped" in caplog.text
    assert "sky.exr: 1 texel is negative: read as 0" in caplog.text


def test_includes_of_includes_are_counted(tmp_path, monkeypatch):
    """No cycle, only fan-out: ten includes of ten includes, twelve deep, would be 10^12 files to read."""
    from lenslab.scene.io import mitsuba_xml

    monkeypatch.setattr(mitsuba_xml, "MAX_INCLUDES", 500)  # the same refusal, sooner
    (tmp_path / "l0.xml").write_text('<scene version="3.0.0"><shape type="sphere"/></scene>')
    for level in range(1, 13):
        (tmp_path / f"l{level}.xml").write_text('<scene version="3.0.0">'
                                                + f'<include filename="l{level - 1}.xml"/>' * 10 + "</scene>")
    line = _one_error(*_render(tmp_path / "l12.xml", tmp_path))
    assert "<include>: more than 500 includes in all (includes of includes multiply)" in line


@pytest.mark.slow
def test_a_scheduler_that_never_answers_is_given_up_on(tmp_path, capsys):
    """A server that accepts the connection and says nothing: Dask's handshake has no deadline of its own."""
    import socket
    import threading

    import dask

    server = socket.create_server(("127.0.0.1", 0))
    held = []
    threading.Thread(target=lambda: held.append(server.accept()), daemon=True).start()
    (tmp_path / "z.toml").write_text('[[shots]]\nscene = "cornell_box"\noutput = "z.png"\n')
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        status = main(["batch", str(tmp_path / "z.toml"), "--scheduler", address])
    server.close()
    err = capsys.readouterr().err
    assert status == 1 and err.count("\n") == 1, err
    assert f"cannot reach a Dask scheduler at {address} (no answer as a Dask scheduler within 1 s)" in err


# -- the minimal cases of the classes the fuzzer found running the real command --------------------------------
def _gltf_scene(tmp_path: Path, edit) -> Path:
    header = malformed_inputs._gltf_quad()
    edit(header)
    (tmp_path / "quad.gltf").write_text(json.dumps(header))
    (tmp_path / "label.png").write_bytes((CORNELL.parent.parent.parent / "app/lenslab/validate/scenes/label.png")
                                         .read_bytes())
    return _cornell(tmp_path, lambda doc: _add_node(doc, {"type": "mesh", "file": "quad.gltf"}))


@pytest.mark.parametrize("edit, expected", [
    (lambda h: h["materials"][0]["pbrMetallicRoughness"].update(baseColorFactor=0.5),
     "materials[0].pbrMetallicRoughness.baseColorFactor: expected a list of 4 numbers, not 0.5"),
    (lambda h: h["materials"][0]["pbrMetallicRoughness"].update(metallicFactor=None),
     "materials[0].pbrMetallicRoughness.metallicFactor: expected a number, not null"),
    (lambda h: h.update(images={"0": {"uri": "label.png"}}),
     'images: expected a list, not {"0": {"uri": "label.png"}}'),
    (lambda h: h["materials"][0].update(emissiveFactor=[1, 2e30, 0]),
     "materials[0].emissiveFactor: 2e+30 is too large (the most any value may be is 1e+30)"),
    (lambda h: h["textures"][0].update(sampler=3), "textures[0].sampler: 3 points past the file's 1 samplers"),
    (lambda h: h["images"][0].update(uri=7), "images[0].uri: expected a string, not 7"),
])
def test_a_gltf_field_of_the_wrong_type_is_named(tmp_path, edit, expected):
    """Each of these once reached the material mapping and ended as "internal error"."""
    scene = _gltf_scene(tmp_path, edit)
    line = _one_error(*_render(scene, tmp_path))
    assert f"{tmp_path / 'quad.gltf'}: {expected}" in line and "internal error" not in line


def test_a_well_formed_gltf_quad_renders(tmp_path):
    status, stderr = _render(_gltf_scene(tmp_path, lambda header: None), tmp_path)
    assert status == 0 and "error" not in stderr, stderr


@pytest.mark.parametrize("statement, expected", [
    ("map_Kd -s nan nan t.png", "map_Kd -s nan nan t.png: not a finite number"),  # once rendered black, silently
    ("map_Kd -o 1e31 0 t.png", "map_Kd -o 1e31 0 t.png: 1e+31 is too large (the most any value may be is 1e+30)"),
    ("Kd 2e30 0.5 0.5", "Kd 2e30 0.5 0.5: 2e+30 is too large (the most any value may be is 1e+30)"),
])
def test_an_mtl_number_that_is_not_finite_or_too_large_is_refused(tmp_path, statement, expected):
    (tmp_path / "m.obj").write_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\n"
                                    "f 1/1 2/2 3/3\n")
    (tmp_path / "m.mtl").write_text(f"newmtl a\n{statement}\n")
    (tmp_path / "t.png").write_bytes(_png_claiming(1, 1))
    scene = _cornell(tmp_path, lambda doc: _add_node(doc, {"type": "mesh", "file": "m.obj"}))
    line = _one_error(*_render(scene, tmp_path))
    assert f"m.mtl: material 'a': {expected}" in line


def test_every_format_refuses_a_number_past_the_same_bound(tmp_path):
    """Native JSON, Mitsuba XML, MTL and glTF all stop at limits.LARGEST_NUMBER (1e30), in the same words: a
    Mitsuba radiance of 1e308 once put infinities in the light tables, and an MTL or glTF one was taken too."""
    folders = [tmp_path / name for name in "abcd"]
    for folder in folders:
        folder.mkdir()
    scenes = [_cornell(folders[0], lambda doc: doc["nodes"][0]["transform"].update(translate=[1.5e30, 0, 0]))]
    (folders[1] / "scene.xml").write_text('<scene version="3.0.0"><shape type="sphere"><emitter type="area">'
                                          '<rgb name="radiance" value="1.5e30"/></emitter></shape></scene>')
    scenes.append(folders[1] / "scene.xml")
    (folders[2] / "m.obj").write_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n")
    (folders[2] / "m.mtl").write_text("newmtl a\nKe 1.5e30 1 1\n")
    scenes.append(_cornell(folders[2], lambda doc: _add_node(doc, {"type": "mesh", "file": "m.obj"})))
    scenes.append(_gltf_scene(folders[3], lambda h: h["materials"][0].update(emissiveFactor=[1.5e30, 0, 0])))
    lines = [_one_error(*_render(scene, folder)) for scene, folder in zip(scenes, folders)]
    assert all(re.search(r"1\.5e\+?30'? is too large \(the most any value may be is 1e\+30\)", line)
               for line in lines), lines


@pytest.mark.parametrize("kind", ["an image texture", "a glTF buffer", "a glTF image", "an aperture image",
                                  "an environment map", "a mesh file pipe.obj", "the scene file", "the batch file"])
def test_a_named_pipe_is_refused_at_once_wherever_a_file_is_read(tmp_path, kind):
    """A FIFO where a texture or a glTF's buffer belongs once blocked the render for ever. The case runs under the
    harness's watcher, which would stop it (and say so) were it still waiting on the pipe."""
    rng = __import__("random").Random(0)
    case = next(c for c in iter(lambda: malformed_inputs.fifo_case(rng), None) if c.what == f"FIFO: {kind}")
    try:
        outcome = malformed_inputs.run_in_process(case, tmp_path / "case")
    finally:
        malformed_inputs.close_watcher()
    assert not outcome.problem, f"{outcome.problem}: {outcome.stderr}"
    assert "a named pipe (FIFO), not a regular file" in outcome.stderr


def test_the_one_reader_of_user_files_refuses_what_is_not_a_regular_file(tmp_path):
    from lenslab.image_files import NotARegularFile, check_regular_file, open_file, read_file_bytes

    (tmp_path / "plain.txt").write_bytes(b"bytes")
    assert read_file_bytes(tmp_path / "plain.txt") == b"bytes"
    with open_file(tmp_path / "plain.txt") as file:
        assert file.read(2) == b"by"
    check_regular_file(tmp_path / "absent")  # what is not there is for the reader to say
    with malformed_inputs.fifo_read_as_empty(tmp_path / "pipe") as pipe:
        for read in (read_file_bytes, open_file, check_regular_file):
            with pytest.raises(NotARegularFile) as caught:
                read(pipe)
            assert str(caught.value) == f"{pipe}: a named pipe (FIFO), not a regular file"
            assert caught.value.filename == str(pipe)
            assert caught.value.strerror == "a named pipe (FIFO), not a regular file"
    for path, what in ((tmp_path, "a folder"), (Path("/dev/zero"), "a character device")):  # /dev/zero never ends
        with pytest.raises(NotARegularFile, match=f"^{re.escape(str(path))}: {what}, not a regular file$"):
            read_file_bytes(path)


def test_a_toml_date_in_a_batch_file_is_one_line_from_the_command(tmp_path, capsys):
    (tmp_path / "b.toml").write_text('[[shots]]\nscene = "cornell_box"\noutput = "a.png"\nspp = 1979-05-27\n')
    assert main(["batch", str(tmp_path / "b.toml"), "--dry-run"]) == 1
    err = capsys.readouterr().err
    assert err == (f"lenslab batch: error: {tmp_path / 'b.toml'}, shot 1: spp: expected a whole number, not a date "
                   "(1979-05-27)\n")
