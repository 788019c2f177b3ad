"""Real-lens prescriptions: pbrt's lens files and LensLab's TOML/JSON read to the same surfaces, the shipped
lenses are the published designs, and every broken table is refused in one line naming the file and the row."""

from __future__ import annotations

import dataclasses
import json
import os
import sys
import threading
from pathlib import Path

import pytest

from lenslab.optics.prescription import (
    MAX_SURFACES,
    LensPrescription,
    LensSurface,
    PrescriptionError,
    is_prescription_file,
    prescription_from_mapping,
    read_pbrt_lens,
    read_prescription_file,
)
from lenslab.optics.presetfiles import PresetError

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10: the tomli package, a dependency there
    import tomli as tomllib

REPO = Path(__file__).resolve().parents[1]
SHIPPED = REPO / "presets" / "lenses"
DATA = Path(__file__).resolve().parent / "data" / "lenses"

#: Each shipped lens and the pbrt lens file (tests/data/lenses) with the same published numbers.
PAIRS = {
    "50mm-f2-double-gauss.toml": "dgauss.50mm.dat",
    "22mm-wide-angle.toml": "wide.22mm.dat",
    "250mm-telephoto.toml": "telephoto.250mm.dat",
    "10mm-fisheye.toml": "fisheye.10mm.dat",
}
SHIPPED_TOML = sorted(SHIPPED / name for name in PAIRS)
THIN_LENS_JSON = sorted(SHIPPED.glob("*.json"))

DGAUSS_ROWS = """\
29.475 3.76 1.67 25.2
84.83 0.12 1 25.2
19.275 4.025 1.67 23
40.77 3.275 1.699 23
12.75 5.705 1 18
0 4.5 0 17.1
-14.495 1.18 1.603 17
40.77 6.065 1.658 20
-20.385 0.19 1 20
437.065 3.22 1.717 20
-39.73 0 1 20
"""


def geometry(lens: LensPrescription) -> list[tuple[float, float, float, float]]:
    return [(s.radius_mm, s.thickness_mm, s.ior, s.aperture_mm) for s in lens.surfaces]


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def one_line_naming(exc: BaseException, *parts: str) -> str:
    """The error's text, after checking it is one line holding every one of ``parts``."""
    text = str(exc)
    assert "\n" not in text
    for part in parts:
        assert part in text, (part, text)
    return text


def paraxial_efl(lens: LensPrescription) -> float:
    """Effective focal length by a paraxial (y, nu) trace of a ray parallel to the axis: the shipped tables are
    checked against the focal length their source publishes without depending on the optics modules."""
    y, nu, n = 1.0, 0.0, 1.0
    for index, s in enumerate(lens.surfaces):
        curvature = 0.0 if s.is_stop else 1.0 / s.radius_mm
        nu -= y * (s.ior - n) * curvature
        n = s.ior
        if index < len(lens.surfaces) - 1:
            y += s.thickness_mm * nu / n
    return -1.0 / nu  # the last medium is air (n = 1)


def toml_text(path: Path) -> str:
    return path.read_text(encoding="utf-8")


# --- pbrt's lens files -------------------------------------------------------------------------------------

@pytest.mark.parametrize("toml_name", sorted(PAIRS))
def test_pbrt_file_reads_as_the_shipped_toml(toml_name):
    shipped = read_prescription_file(SHIPPED / toml_name)
    pbrt = read_prescription_file(DATA / PAIRS[toml_name])
    assert geometry(pbrt) == geometry(shipped)
    assert pbrt.stop_index == shipped.stop_index
    assert not pbrt.dispersive and shipped.dispersive  # pbrt's files have no Abbe numbers


def test_pbrt_file_as_published():
    lens = read_pbrt_lens(DATA / "dgauss.50mm.dat")
    assert lens.name == "dgauss.50mm"
    assert lens.path == DATA / "dgauss.50mm.dat"
    assert len(lens.surfaces) == 11
    assert lens.surfaces[0] == LensSurface(29.475, 3.76, 1.67, None, 25.2)
    assert lens.surfaces[-1].thickness_mm == 0.0  # pbrt's film distance, kept as read
    # The comment lines, with their tabs and stray quotes, become the description.
    assert "US patent 2,673,491 Tronnier" in lens.description
    assert '"' not in lens.description and "\t" not in lens.description


def test_pbrt_air_written_as_zero_is_one(tmp_path):
    lens = read_pbrt_lens(DATA / "dgauss.50mm.dat")
    assert lens.stop_index == 5
    assert lens.surfaces[5].ior == 1.0 and lens.surfaces[5].is_stop
    assert [s.is_stop for s in lens.surfaces].count(True) == 1
    # Every air row may be written 0, as pbrt allows.
    zeros = "".join(
        " ".join(row.split()[:2] + ["0" if row.split()[2] == "1" else row.split()[2], row.split()[3]]) + "\n"
        for row in DGAUSS_ROWS.splitlines())
    assert " 0 " in zeros.splitlines()[1]
    again = read_pbrt_lens(write(tmp_path / "zeros.dat", zeros))
    assert geometry(again) == geometry(lens)


def test_pbrt_file_with_bom_crlf_latin1_comment_and_inline_comment(tmp_path):
    rows = DGAUSS_ROWS.splitlines()
    rows[0] += "   # the front element"
    text = "# 22\xb0 half field\r\n" + "\r\n".join(rows) + "\r\n"
    path = tmp_path / "crlf.dat"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode("latin-1"))  # a BOM, then a byte that is not UTF-8
    lens = read_pbrt_lens(path)
    assert geometry(lens) == geometry(read_pbrt_lens(DATA / "dgauss.50mm.dat"))
    assert "half field" in lens.description


def _replace_row(number: int, row: str) -> str:
    rows = DGAUSS_ROWS.splitlines()
    rows[number - 1] = row
    return "\n".join(rows) + "\n"


# (what is wrong, the table, the surface the error must name (None: the table as a whole), words it must say)
PBRT_BROKEN = [
    ("three numbers", _replace_row(3, "19.275 4.025 1.67"), 3, "four numbers"),
    ("five numbers", _replace_row(3, "19.275 4.025 1.67 23 1"), 3, "four numbers"),
    ("a word", _replace_row(4, "40.77 3.275 glass 23"), 4, "'glass' is not a number"),
    ("nan", _replace_row(4, "40.77 nan 1.699 23"), 4, "finite"),
    ("infinity", _replace_row(2, "1e400 0.12 1 25.2"), 2, "finite"),
    ("ior too high", _replace_row(4, "40.77 3.275 3.5 23"), 4, "ior"),
    ("negative ior", _replace_row(4, "40.77 3.275 -1.5 23"), 4, "ior"),
    # A row of a pbrt file is told in pbrt's column names (thickness, aperture), not our keys.
    ("negative thickness", _replace_row(2, "84.83 -0.12 1 25.2"), 2, "thickness must be"),
    ("no aperture", _replace_row(7, "-14.495 1.18 1.603 0"), 7, "aperture must be"),
    ("sphere smaller than aperture", _replace_row(5, "8.75 5.705 1 18"), 5, "smaller than the semi-aperture"),
    ("glass behind the stop", _replace_row(6, "0 4.5 1.5 17.1"), 6, "stop"),
    ("a second stop", _replace_row(9, "0 0.19 1 20"), 9, "second aperture stop"),
    ("no stop", _replace_row(6, "1000 4.5 0 17.1"), None, "no aperture stop"),
    ("glass behind the last surface", _replace_row(11, "-39.73 0 1.5 20"), 11, "last surface"),
]


@pytest.mark.parametrize("what, text, surface, words", PBRT_BROKEN, ids=[case[0] for case in PBRT_BROKEN])
def test_pbrt_errors_name_file_line_and_surface(tmp_path, what, text, surface, words):
    path = write(tmp_path / "broken.dat", "# a comment line\n\n" + text)
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(path)
    parts = [str(path), words]
    if surface is not None:
        parts.append(f"line {surface + 2} (surface {surface})")  # a comment and a blank line come first
    one_line_naming(caught.value, *parts)
    assert caught.value.surface == surface
    assert isinstance(caught.value, ValueError) and isinstance(caught.value, PresetError)


def test_errors_survive_pickling(tmp_path):
    """A batch worker's error crosses to the scheduler pickled: it must arrive whole, not as a TypeError."""
    import pickle

    path = write(tmp_path / "broken.dat", _replace_row(4, "40.77 3.275 3.5 23"))
    with pytest.raises(PrescriptionError) as caught:
        read_pbrt_lens(path)
    again = pickle.loads(pickle.dumps(caught.value))
    assert str(again) == str(caught.value)
    assert (again.path, again.line, again.surface, again.field) == (path, 4, 4, "ior")


def test_pbrt_file_without_surfaces(tmp_path):
    path = write(tmp_path / "empty.dat", "# only comments\n# here\n")
    with pytest.raises(PrescriptionError) as caught:
        read_pbrt_lens(path)
    one_line_naming(caught.value, str(path), "no surfaces")


# --- LensLab's TOML and JSON -------------------------------------------------------------------------------

def test_json_equivalent_reads_the_same(tmp_path):
    toml_path = SHIPPED / "50mm-f2-double-gauss.toml"
    data = tomllib.loads(toml_text(toml_path))
    json_path = write(tmp_path / "dgauss.json", json.dumps(data, indent=2))
    from_toml = read_prescription_file(toml_path)
    from_json = read_prescription_file(json_path)
    assert from_json == from_toml
    assert [s.glass for s in from_json.surfaces] == [s.glass for s in from_toml.surfaces]  # compare=False
    assert from_json.path == json_path and from_toml.path == toml_path


def test_json_null_is_allowed_where_a_key_may_be_left_out(tmp_path):
    data = tomllib.loads(toml_text(SHIPPED / "50mm-f2-double-gauss.toml"))
    data["published_back_focal_mm"] = None
    data["surfaces"][1]["abbe"] = None
    lens = read_prescription_file(write(tmp_path / "nulls.json", json.dumps(data)))
    assert lens.published_back_focal_mm is None and lens.surfaces[1].abbe is None


def _dgauss_data() -> dict:
    return tomllib.loads(toml_text(SHIPPED / "50mm-f2-double-gauss.toml"))


def _set(data, key, value):
    """``data`` with ``key`` ("surfaces[3].ior", 1-based as the errors count) set, or removed for ...."""
    target = data
    if key.startswith("surfaces["):
        number, key = key[len("surfaces["):].split("].")
        target = data["surfaces"][int(number) - 1]
    if value is ...:
        del target[key]
    else:
        target[key] = value
    return data


# (the key changed, its new value (...: removed), the key the error must name, words it must say)
MAPPING_BROKEN = [
    ("focal_length_mm", 50, "focal_length_mm", "unknown key"),
    ("path", "/tmp/x", "path", "unknown key"),
    ("name", ..., "name", "missing"),
    ("name", "  ", "name", "non-empty"),
    ("name", 50, "name", "expected a string"),
    ("published_f_number", "2", "published_f_number", "expected a finite number"),
    ("published_f_number", 0, "published_f_number", "> 0"),
    ("narrowest_f_number", 1.4, "narrowest_f_number", "wider than"),
    ("aperture_blades", 2, "aperture_blades", "0 (round) or 3..32"),
    ("aperture_blades", 6.0, "aperture_blades", "expected an integer"),
    ("blade_roundness", 1.5, "blade_roundness", "[0, 1]"),
    ("min_focus_distance_m", -1, "min_focus_distance_m", "> 0"),
    ("surfaces[3].radius", 19.275, "surfaces[3].radius", "unknown key"),
    ("surfaces[2].ior", ..., "surfaces[2].ior", "missing"),
    ("surfaces[3].radius_mm", "19.275", "surfaces[3].radius_mm", "expected a finite number"),
    ("surfaces[3].radius_mm", True, "surfaces[3].radius_mm", "expected a finite number"),
    ("surfaces[4].ior", 3.5, "surfaces[4].ior", "[1, 3]"),
    ("surfaces[4].abbe", 0, "surfaces[4].abbe", "(0, 150]"),
    ("surfaces[2].abbe", 64.17, "surfaces[2].abbe", "air"),
    ("surfaces[4].glass", 7, "surfaces[4].glass", "expected a string"),
    ("surfaces[5].radius_mm", 8.0, "surfaces[5].radius_mm", "smaller than the semi-aperture"),
    ("surfaces[6].ior", 1.5, "surfaces[6].ior", "stop"),
    ("surfaces[9].radius_mm", 0, "surfaces[9]", "second aperture stop"),
    ("surfaces[6].radius_mm", 1000, "surfaces", "no aperture stop"),
    ("surfaces[11].ior", 1.5, "surfaces[11].ior", "last surface"),
]


@pytest.mark.parametrize("change, value, key, words", MAPPING_BROKEN,
                         ids=[f"{case[0]}={case[1]!r}" for case in MAPPING_BROKEN])
def test_mapping_errors_name_file_and_key(tmp_path, change, value, key, words):
    path = tmp_path / "broken.json"
    write(path, json.dumps(_set(_dgauss_data(), change, value)))
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(path)
    one_line_naming(caught.value, str(path), f"'{key}'", words)
    assert caught.value.key == key


def test_toml_errors_name_file_and_key(tmp_path):
    text = toml_text(SHIPPED / "50mm-f2-double-gauss.toml").replace("ior = 1.699", "ior = 4.699")
    path = write(tmp_path / "broken.toml", text)
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(path)
    one_line_naming(caught.value, str(path), "'surfaces[4].ior'", "[1, 3]")
    path = write(tmp_path / "syntax.toml", 'name = "x"\n[[surfaces]\n')
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(path)
    one_line_naming(caught.value, str(path), "invalid TOML")


@pytest.mark.parametrize("data, words", [
    ([], "expected a table"),
    ({"name": "x", "surfaces": []}, "non-empty list"),
    ({"name": "x", "surfaces": {"radius_mm": 1}}, "list"),
    ({"name": "x", "surfaces": [1, 2]}, "expected a table"),
])
def test_mapping_shapes(tmp_path, data, words):
    path = write(tmp_path / "shape.json", json.dumps(data))
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(path)
    one_line_naming(caught.value, str(path), words)


def test_a_thin_lens_preset_is_not_a_prescription():
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(SHIPPED / "50mm-f1.2.json")
    one_line_naming(caught.value, "50mm-f1.2.json", "thin-lens preset")


# --- the data model ----------------------------------------------------------------------------------------

def _surfaces(count: int) -> list[LensSurface]:
    """``count`` surfaces that make a valid table: glass and air in turn, the stop third."""
    rows = [LensSurface(100.0, 1.0, 1.5 if i % 2 == 0 else 1.0, 60.0 if i % 2 == 0 else None, 10.0)
            for i in range(count)]
    rows[2] = LensSurface(0.0, 1.0, 1.0, None, 8.0)
    if rows[-1].ior != 1.0:
        rows[-1] = LensSurface(-100.0, 0.0, 1.0, None, 10.0)
    return rows


def test_built_in_memory_errors_name_the_surface():
    surfaces = _surfaces(6)
    LensPrescription("ok", tuple(surfaces))
    surfaces[4] = LensSurface(0.0, 1.0, 1.0, None, 8.0)
    with pytest.raises(PrescriptionError) as caught:
        LensPrescription("two stops", tuple(surfaces))
    assert one_line_naming(caught.value, "surface 5", "second aperture stop").startswith("surface 5")
    with pytest.raises(PrescriptionError) as caught:
        LensSurface(4.0, 1.0, 1.5, None, 10.0)
    one_line_naming(caught.value, "radius_mm", "smaller than the semi-aperture")
    with pytest.raises(PrescriptionError) as caught:
        LensSurface(10.0, 1.0, 1.5, 200.0, 10.0)
    one_line_naming(caught.value, "abbe", "(0, 150]")
    with pytest.raises(PrescriptionError) as caught:
        LensPrescription("only air", (LensSurface(0.0, 1.0, 1.0, None, 8.0), LensSurface(50.0, 1.0, 1.0, None, 8.0)))
    one_line_naming(caught.value, "no glass")


def test_a_hemisphere_is_as_wide_as_a_sphere_gets():
    assert LensSurface(5.0, 1.0, 1.5, None, 10.0).radius_mm == 5.0  # |R| == half the aperture: allowed


def test_numbers_are_floats_and_tables_tuples():
    surface = LensSurface(10, 1, 1, None, 8)
    assert all(isinstance(v, float) for v in (surface.radius_mm, surface.thickness_mm, surface.ior,
                                                surface.aperture_mm))
    lens = LensPrescription("x", _surfaces(4), path="somewhere/x.toml")
    assert isinstance(lens.surfaces, tuple) and lens.path == Path("somewhere/x.toml")
    assert lens == dataclasses.replace(lens, path=None)  # where it was read from is not part of the lens


@pytest.mark.parametrize("count", [MAX_SURFACES, MAX_SURFACES + 1])
def test_at_most_32_surfaces(tmp_path, count):
    surfaces = _surfaces(count)
    rows = "".join(f"{s.radius_mm:g} {s.thickness_mm:g} {s.ior:g} {s.aperture_mm:g}\n" for s in surfaces)
    pbrt = write(tmp_path / "long.dat", rows)
    mapping = {"name": "long", "surfaces": [
        {"radius_mm": s.radius_mm, "thickness_mm": s.thickness_mm, "ior": s.ior, "aperture_mm": s.aperture_mm}
        for s in surfaces]}
    readers = [lambda: LensPrescription("long", tuple(surfaces)), lambda: read_pbrt_lens(pbrt),
               lambda: prescription_from_mapping(mapping, tmp_path / "long.json")]
    for read in readers:
        if count <= MAX_SURFACES:
            assert len(read().surfaces) == count
        else:
            with pytest.raises(PrescriptionError) as caught:
                read()
            one_line_naming(caught.value, f"at most {MAX_SURFACES}")


# --- files that are not lens files -------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["lens.toml", "lens.dat", "lens.json"])
def test_a_folder_or_missing_file_named_as_a_lens(tmp_path, name):
    folder = tmp_path / name
    folder.mkdir()
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(folder)
    one_line_naming(caught.value, str(folder), "folder")
    missing = tmp_path / "missing" / name
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(missing)
    one_line_naming(caught.value, str(missing), "cannot read")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are a POSIX thing")
def test_a_named_pipe_is_refused_not_waited_on(tmp_path):
    fifo = tmp_path / "lens.toml"
    os.mkfifo(fifo)
    outcome: list[BaseException | object] = []

    def read():
        try:
            outcome.append(read_prescription_file(fifo))
        except BaseException as exc:  # noqa: BLE001 - handed to the test's thread
            outcome.append(exc)

    # A reader that opens the pipe as a file blocks until something writes to it: in a thread, so that such a
    # reader fails this test instead of hanging the run; a writer then lets it go.
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(10)
    if reader.is_alive():
        with open(fifo, "wb"):
            pass
        reader.join(10)
        pytest.fail("the reader waited on a named pipe")
    (error,) = outcome
    assert isinstance(error, PrescriptionError), error
    one_line_naming(error, str(fifo), "named pipe")
    assert is_prescription_file(tmp_path / "x.json") is False  # missing: not a prescription, and no hang


def test_unknown_suffix(tmp_path):
    path = write(tmp_path / "lens.txt", DGAUSS_ROWS)
    with pytest.raises(PrescriptionError) as caught:
        read_prescription_file(path)
    one_line_naming(caught.value, str(path), "unknown lens file type '.txt'")


def test_is_prescription_file_tells_thin_lens_presets_apart(tmp_path):
    assert THIN_LENS_JSON, "the thin-lens presets are gone"
    assert (SHIPPED / "50mm-f1.2.json") in THIN_LENS_JSON
    for path in THIN_LENS_JSON:
        assert not is_prescription_file(path), path
    for path in SHIPPED_TOML:
        assert is_prescription_file(path)
    assert is_prescription_file(DATA / "dgauss.50mm.dat")
    real = write(tmp_path / "real.json", json.dumps(_dgauss_data()))
    assert is_prescription_file(real)
    assert not is_prescription_file(write(tmp_path / "broken.json", '{"surfaces": ['))
    assert not is_prescription_file(write(tmp_path / "list.json", '[{"surfaces": []}]'))
    assert not is_prescription_file(write(tmp_path / "lens.txt", DGAUSS_ROWS))


# --- the shipped lenses ------------------------------------------------------------------------------------

PUBLISHED = {  # file: (name, focal length and f-number the source states, surfaces, stop index)
    "50mm-f2-double-gauss.toml": ("50 mm f/2 double-Gauss", 50.0, 2.0, 11, 5),
    "22mm-wide-angle.toml": ("22 mm wide angle", 22.0, None, 13, 5),
    "250mm-telephoto.toml": ("250 mm f/5.6 telephoto", 254.0, 5.6, 7, 3),
    "10mm-fisheye.toml": ("10 mm f/4 fisheye", 10.0, 4.0, 12, 6),
}


@pytest.mark.parametrize("path", SHIPPED_TOML, ids=lambda p: p.name)
def test_shipped_lens(path):
    lens = read_prescription_file(path)
    name, efl, f_number, count, stop = PUBLISHED[path.name]
    assert (lens.name, lens.published_focal_length_mm, lens.published_f_number) == (name, efl, f_number)
    assert len(lens.surfaces) == count and lens.stop_index == stop
    assert [s.is_stop for s in lens.surfaces].count(True) == 1
    for number, surface in enumerate(lens.surfaces, 1):
        if surface.ior > 1.0:
            assert surface.abbe is not None and surface.glass, f"surface {number}: a glass without its Abbe number"
        else:
            assert surface.abbe is None and not surface.glass, f"surface {number}: air with a glass"
    assert lens.dispersive
    assert "Modern Lens Design" in lens.source and "Abbe numbers assigned by LensLab" in lens.source
    assert "achromat" in lens.source
    assert lens.narrowest_f_number >= (lens.published_f_number or 0) and lens.min_focus_distance_m


@pytest.mark.parametrize("path", SHIPPED_TOML, ids=lambda p: p.name)
def test_shipped_lens_focal_length_is_the_published_one(path):
    """A paraxial trace of the table gives the focal length the source states: a mistyped radius or index shows.
    Within 2 %: the telephoto's header states 254 mm for a table scaled to 250 mm (its trace gives 249.6)."""
    lens = read_prescription_file(path)
    assert paraxial_efl(lens) == pytest.approx(lens.published_focal_length_mm, rel=0.02)


def test_shipped_glasses_match_their_index():
    """Every glass named has a catalogue n_d within 0.005 of the table's index, and the Abbe number is that
    glass's, moved by at most 15% (to achromatise the lens), as the glass's note says."""
    for path in SHIPPED_TOML:
        for surface in read_prescription_file(path).surfaces:
            if surface.glass:
                catalogue_nd = float(surface.glass.split("n_d ")[1].split(",")[0])
                catalogue_vd = float(surface.glass.split("V_d ")[1].split(")")[0])
                assert abs(catalogue_nd - surface.ior) < 0.005, (path.name, surface.glass)
                assert abs(surface.abbe - catalogue_vd) <= 0.15 * catalogue_vd, (path.name, surface.glass)
                assert f"V_d moved to {surface.abbe:.1f}" in surface.glass or \
                    f"V_d {surface.abbe:.2f}" in surface.glass


def test_shipped_lenses_are_achromats():
    """Each design brings F and C light to one focus (paraxially, within 20 um), as a photographic lens is
    corrected: the colour left is what an achromat keeps (secondary spectrum, lateral colour)."""
    from lenslab.optics.lens_system import C_LINE_NM, F_LINE_NM, LensSystem

    for path in SHIPPED_TOML:
        system = LensSystem(read_prescription_file(path))
        back_focus = {}
        for line in (F_LINE_NM, C_LINE_NM):
            y, nu, _ = system.paraxial_trace(1.0, 0.0, system.ior(line))
            back_focus[line] = -y / nu
        assert abs(back_focus[F_LINE_NM] - back_focus[C_LINE_NM]) < 0.02, path.name


def test_shipped_names_are_distinct():
    names = [read_prescription_file(path).name for path in SHIPPED_TOML]
    assert len(set(names)) == len(names) == 4
