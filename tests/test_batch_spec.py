"""Batch files: sweeps and ranges expand into shots, output names are filled in, and every mistake is one line
naming the file, the shot and the key, before anything renders."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from lenslab.batch.parts import PART_INDEX_STRIDE, sample_range
from lenslab.batch.spec import BatchError, parse_batch, read_batch
from lenslab.scene.io.loader import open_scene


def batch(tmp_path: Path, text: str, name: str = "shots.toml"):
    path = tmp_path / name
    path.write_text(text)
    return read_batch(path)


def error(tmp_path: Path, text: str, name: str = "shots.toml") -> str:
    with pytest.raises(BatchError) as caught:
        batch(tmp_path, text, name)
    message = str(caught.value)
    assert "\n" not in message and message.startswith(str(tmp_path / name))
    return message


def test_a_list_is_a_sweep_and_defaults_apply_to_every_shot(tmp_path):
    shots = batch(tmp_path, """
        [defaults]
        scene = "cornell_box"
        width = 64
        spp = 16
        [[shots]]
        name = "bracket"
        output = "out/c_f{f_number}.png"
        f_number = [1.4, 2, 2.8]
        [[shots]]
        output = "out/single.exr"
        spp = 4
    """).shots
    assert [s.name for s in shots] == ["bracket f/1.4", "bracket f/2", "bracket f/2.8", "single"]
    assert [s.output for s in shots] == [tmp_path / "out/c_f1.4.png", tmp_path / "out/c_f2.png",
                                         tmp_path / "out/c_f2.8.png", tmp_path / "out/single.exr"]
    assert [s.overrides.f_number for s in shots] == [2 ** 0.5, 2.0, 2 ** 1.5, None]  # marked stops, exact
    assert [s.overrides.spp for s in shots] == [16, 16, 16, 4]  # a shot's own value wins over the default
    assert all(s.overrides.width == 64 and s.scene == "cornell_box" for s in shots)


def test_ranges_linear_and_geometric_and_the_product_of_two_sweeps(tmp_path):
    shots = batch(tmp_path, """
        [[shots]]
        scene = "dof_chart"
        output = "stack_{index:02d}_f{f_number}.exr"
        focus_distance = {from = 1, to = 4, steps = 4}
        f_number = {from = 2, to = 8, steps = 3, spacing = "geometric"}
    """).shots
    pairs = [(s.overrides.focus_distance, s.overrides.f_number) for s in shots]
    assert pairs == [(d, n) for d in (1.0, 2.0, 3.0, 4.0) for n in (2.0, 4.0, 8.0)]
    assert shots[0].output.name == "stack_01_f2.exr" and shots[-1].output.name == "stack_12_f8.exr"
    assert shots[4].name == "stack_05_f4"  # no name given: its file's


def test_lens_names_become_safe_file_names_and_the_lens_is_mounted(tmp_path):
    shots = batch(tmp_path, """
        [[shots]]
        scene = "cornell_box"
        output = "lens_{lens}.png"
        lens = ["35 mm f/1.4", "85mm-f1.4"]
    """).shots
    assert [s.output.name for s in shots] == ["lens_35_mm_f_1.4.png", "lens_85mm-f1.4.png"]
    camera = shots[1].open_scene().camera
    assert (camera.focal_length_mm, camera.aperture_blades) == (85.0, 11)


def test_json_batch_files_and_scene_paths_beside_the_batch_file(tmp_path):
    (tmp_path / "my_scene.json").write_text("{}")
    shots = batch(tmp_path, json.dumps({"shots": [{"scene": "my_scene.json", "output": "a_{seed}.exr",
                                                   "seed": [1, 2], "defines": {"spp": 8}}]}), "shots.json").shots
    assert [s.scene for s in shots] == [str(tmp_path / "my_scene.json")] * 2
    assert [s.output.name for s in shots] == ["a_1.exr", "a_2.exr"]
    assert shots[0].overrides.defines == {"spp": "8"}  # as -D spp=8


@pytest.mark.parametrize("text, expected", [
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nf_numbr=2", "shot 1: unknown key 'f_numbr' (did you mean 'f_number'?)"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nspp='many'", "shot 1: spp: expected a whole number, not 'many'"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nspp=2.5", "shot 1: spp: expected a whole number, not 2.5"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nf_number=0", "shot 1: f_number 0 is out of range"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nf_number=[]", "f_number: an empty list sweeps over nothing"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nfocus_distance={from=1, to=2}", "focus_distance: a range needs 'steps'"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nfocus_distance={from=0, to=2, steps=3, spacing='geometric'}",
     "a geometric range needs positive ends"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nlens='300mm'", "no lens preset called '300mm' (there are: "),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nlens='85mm f/1.4'\nf_number=1.2",
     "f/1.2 is not on the lens '85 mm f/1.4' (f/1.4 to f/16)"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.bmp'",
     "output: a.bmp must be one of .exr, .png, .tif, .tiff, .jpg or .jpeg"),
    ("[[shots]]\noutput='a.png'", "shot 1: no 'scene' (give it in the shot or in [defaults])"),
    ("[[shots]]\nscene='cornell_box'\noutput='a_{aperture}.png'", "names {aperture}, but unknown field {aperture}"),
    ("[[shots]]\nscene='cornell_box'\noutput='a_{seed}.png'", "names {seed}, but this shot sets no seed"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nf_number=[2, 4]",
     "shot 1, f/2 and shot 1, f/4 both write a.png: put the swept setting in the output's name"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\n[[shots]]\nscene='dof_chart'\noutput='a.png'",
     "give each shot its own output"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nsplit=0", "split: 0 is out of range [1, 256]"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\ntime_limit=-1", "time_limit -1 is out of range"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\nname=['a', 'b']", "name: takes one value, not a list"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\ntone_map='aces'", "view 'aces' is not one of display 'sRGB"),
    ("[[shots]]\nscene='cornell_box'\noutput='a.png'\ndisplay='CRT'", "display 'CRT' is not in the OCIO config"),
    ("shots = 3", "no shots: give at least one [[shots]] table"),
    ("[[shot]]\nscene='cornell_box'", "unknown key 'shot' (did you mean 'shots'?)"),
    ("[[shots]\nscene=", "not valid TOML ("),
    ("contact_sheet = 'sheet.jpg'\n[[shots]]\nscene='cornell_box'\noutput='a.png'", "contact_sheet: sheet.jpg must be a .png"),
])
def test_every_mistake_is_one_line_naming_file_shot_and_key(tmp_path, text, expected):
    assert expected in error(tmp_path, text)


def test_files_that_are_not_batch_files(tmp_path):
    assert "no such batch file" in str(pytest.raises(BatchError, read_batch, tmp_path / "none.toml").value)
    assert "unknown batch file type '.yaml'" in error(tmp_path, "a: 1", "shots.yaml")
    assert "not valid JSON" in error(tmp_path, "{", "shots.json")
    assert "not valid JSON" in error(tmp_path, "[" * 100_000, "shots.json")
    with pytest.raises(BatchError, match="expected a table"):
        parse_batch("[1, 2]", tmp_path / "shots.json")


def test_sample_ranges_cover_the_samples_once():
    for total, parts in ((256, 4), (10, 3), (3, 8), (1, 1)):
        ranges = [sample_range(total, part, parts) for part in range(parts)]
        covered = [index for first, count in ranges for index in range(first, first + count)]
        assert covered == list(range(total))
    assert [sample_range(None, part, 3) for part in range(3)] == [(0, None), (PART_INDEX_STRIDE, None),
                                                                  (2 * PART_INDEX_STRIDE, None)]
    with pytest.raises(ValueError):
        sample_range(8, 2, 2)


def test_a_worker_takes_its_gpu_from_its_environment_or_its_number(monkeypatch):
    from lenslab.batch.parts import DEVICE_ENVIRONMENT, PartFailed, _worker_device

    monkeypatch.delenv(DEVICE_ENVIRONMENT, raising=False)
    assert _worker_device(0, ()) is None  # the default device
    assert [_worker_device(n, (2, 3)) for n in (0, 1, 2)] == [2, 3, 2]  # a local cluster's workers are numbered
    assert _worker_device("tcp://farm-node-7:40000", (2, 3)) == 2
    monkeypatch.setenv(DEVICE_ENVIRONMENT, "1")
    assert _worker_device(0, (2, 3)) == 1  # pinned where the worker was started
    monkeypatch.setenv(DEVICE_ENVIRONMENT, "gpu1")
    with pytest.raises(PartFailed, match="LENSLAB_DEVICE='gpu1'"):
        _worker_device(0, ())


def test_the_documented_batch_files_read(tmp_path):
    docs = Path(__file__).resolve().parents[1] / "docs"
    assert len(read_batch(docs / "batch-example.toml").shots) == 12
    text = (docs / "batch.md").read_text()
    block = text.split("```toml\n", 1)[1].split("```", 1)[0]  # docs/batch.md's annotated example
    names = [shot.name for shot in batch(tmp_path, block).shots]
    assert len(names) == 6 + 8 + 4 and names[0] == "aperture bracket f/1.4" and names[-1] == "lenses 135 mm f/2"


def test_a_shutter_bracket_and_the_camera_controls_of_a_shot(tmp_path):
    shots = batch(tmp_path, """
        [[shots]]
        name = "bracket"
        scene = "cornell_box"
        output = "b_{index}.exr"
        shutter = ["1/250", "1/125", 0.5]
        iso = 400
        sensor = "aps-c"
        blades = 7
        blade_curvature = 0.4
        anamorphic = 1.5
        """).shots
    assert [s.overrides.shutter for s in shots] == pytest.approx([1 / 250, 1 / 125, 0.5])
    assert [s.name for s in shots] == ["bracket 1/250 s", "bracket 1/125 s", "bracket 0.5 s"]
    overrides = shots[0].overrides
    assert overrides.exposure_mode == "physical" and overrides.iso == 400 and overrides.sensor == "aps-c"
    assert (overrides.aperture_blades, overrides.blade_curvature, overrides.anamorphic_squeeze) == (7, 0.4, 1.5)
    camera = overrides.apply(open_scene("cornell_box")).camera
    assert camera.sensor_mm == (23.5, 15.6) and camera.exposure_mode == "physical"


@pytest.mark.parametrize("entry, message", [
    ('shutter = "forever"', "shutter: not a shutter time: 'forever'"),
    ("blades = 2", "shot 1: aperture_blades 2: a stop has 0 blades (round) or at least 3"),
    ("blades = 2.5", "shot 1: aperture_blades: expected a whole number, not 2.5"),
    ("anamorphic = 9.0", "shot 1: anamorphic_squeeze 9 is out of range [0.25, 4]"),
    ("coc = 0", "shot 1: circle_of_confusion 0 is out of range [0.0005, 1]"),
    ("blade_curvature = [0.5, 2]", "shot 1, blade_curvature 2: blade_curvature 2 is out of range [0, 1]"),
    ("barrel_clipping = -1", "shot 1: barrel_clipping -1 is out of range [0, 1]"),
    ("iso = 0", "shot 1: iso 0 is out of range"),
    ('shutter = "1/0"', "shot 1: shutter: not a shutter time: '1/0'"),
    ("shutter = 5000", "shot 1: shutter 5000 is out of range"),
    ('sensor = "super 8"', "shot 1: no sensor preset called 'super 8'"),
    ('sensor_fit = "stretch"', "shot 1: sensor_fit 'stretch' is not one of auto, horizontal"),
    ('focus_from = "film"', "shot 1: focus_from 'film' is not one of sensor, lens"),
    ('exposure_mode = "manual"', "shot 1: exposure_mode 'manual' is not one of compensated, physical, auto"),
    ('focus_breathing = "no"', "shot 1: focus_breathing: expected true or false, not 'no'"),
    ("focus_breathing = {from = 0, to = 1, steps = 2}", "shot 1: focus_breathing: expected true or false, not a table"),
    ('sensor = {from = 1, to = 2, steps = 2}', "shot 1: sensor: expected a string, not a table"),
])
def test_bad_camera_controls_in_a_batch_name_the_shot(tmp_path, entry, message):
    assert message in error(tmp_path, f"""
        [[shots]]
        scene = "cornell_box"
        output = "a.png"
        {entry}
        """)


def test_sweeps_over_the_camera_controls_name_and_file_each_shot(tmp_path):
    shots = batch(tmp_path, """
        [[shots]]
        name = "bracket"
        scene = "cornell_box"
        output = "s_{shutter}_{sensor}.exr"
        shutter = {from = "1/500", to = "1/125", steps = 3, spacing = "geometric"}
        sensor = ["Full frame", "APS-C"]
        [[shots]]
        name = "stops"
        scene = "cornell_box"
        output = "b_{blades}_{anamorphic}_{index}.png"
        blades = [0, 6]
        anamorphic = [1, 2]
        focus_breathing = [true, false]
        exposure_mode = "physical"
        """).shots
    bracket, stops = shots[:6], shots[6:]
    assert [s.output.name for s in bracket] == ["s_1_500_Full_frame.exr", "s_1_500_APS-C.exr", "s_1_250_Full_frame.exr",
                                                "s_1_250_APS-C.exr", "s_1_125_Full_frame.exr", "s_1_125_APS-C.exr"]
    assert [s.overrides.shutter for s in bracket[::2]] == pytest.approx([1 / 500, 1 / 250, 1 / 125])
    assert bracket[1].name == "bracket 1/500 s, APS-C"
    assert all(s.overrides.exposure_mode == "physical" for s in bracket)  # a shutter alone means it
    assert len(stops) == 8 and stops[0].name == "stops aperture_blades 0, anamorphic_squeeze 1, focus_breathing true"
    assert [(s.overrides.aperture_blades, s.overrides.anamorphic_squeeze, s.overrides.focus_breathing)
            for s in stops[:2]] == [(0, 1.0, True), (0, 1.0, False)]
    assert stops[-1].output.name == "b_6_2_8.png" and stops[-1].overrides.exposure_mode == "physical"


def test_an_aperture_image_is_read_beside_the_batch_file(tmp_path):
    (shot,) = batch(tmp_path, """
        [[shots]]
        scene = "cornell_box"
        output = "a.exr"
        aperture_image = "stops/star.png"
        sensor_fit = "overscan"
        focus_from = "lens"
        coc = 0.02
        barrel_clipping = 0.5
        """).shots
    overrides = shot.overrides
    assert overrides.aperture_image == str(tmp_path / "stops" / "star.png")
    assert (overrides.sensor_fit, overrides.focus_from, overrides.circle_of_confusion) == ("overscan", "lens", 0.02)
    camera = overrides.apply(open_scene("cornell_box")).camera
    assert (camera.aperture_image, camera.barrel_clipping) == (str(tmp_path / "stops" / "star.png"), 0.5)


def test_a_shot_focused_nearer_than_its_lens_fails_when_its_scene_is_opened(tmp_path):
    (shot,) = batch(tmp_path, """
        [[shots]]
        scene = "cornell_box"
        output = "a.exr"
        lens = "85mm f/1.4"
        focus_distance = 0.5
        """).shots
    with pytest.raises(ValueError, match=r"^--focus-distance 0.5 m from the sensor is nearer than the 85 mm f/1.4 lens's minimum focus of 0.8 m"):
        shot.open_scene()


@pytest.mark.parametrize("value, expected", [
    ("9" * 400, "f_number: a 400-digit number is too large"),
    ("1e400", "f_number: inf is not a finite number"),
    ("nan", "f_number: nan is not a finite number"),
    ("9" * 5000, "a number too long to read"),
])
def test_a_number_no_camera_has_is_one_error_line(tmp_path, value, expected):
    with pytest.raises(BatchError, match=expected):
        batch(tmp_path, f'[[shots]]\nscene = "cornell_box"\noutput = "a.png"\nf_number = {value}\n')


def test_an_output_field_wider_than_a_file_name_is_refused(tmp_path):
    with pytest.raises(BatchError, match=r"output: '\{index:>2000000000\}.png' is not a valid name pattern \(a field "
                                         r"2000000000 characters wide"):
        batch(tmp_path, '[[shots]]\nscene = "cornell_box"\noutput = "{index:>2000000000}.png"\n')
    assert batch(tmp_path, '[[shots]]\nscene = "cornell_box"\noutput = "{index:03d}.png"\n').shots[0].output.name == "001.png"


@pytest.mark.parametrize("shot, expected", [
    ('f_number = { from = 1.4, to = 16, steps = 1000 }\nfocus_distance = { from = 1, to = 9, steps = 1000 }\n',
     "1000 f_number x 1000 focus_distance make 1,000,000 shots; a batch holds at most 10,000"),
    ('output = "{index[0]}.png"\n', "is not a valid name pattern"),
    ('output = "out\\u0000{index}.png"\n', "a file name holds no control characters"),
    ('output = "{index.__class__}.png"\n', "{index.__class__} is not a field's name"),
])
def test_a_batch_that_cannot_be_is_refused_before_anything_runs(tmp_path, shot, expected):
    text = '[[shots]]\nscene = "cornell_box"\n' + shot + ('' if "output" in shot else 'output = "{index}.png"\n')
    with pytest.raises(BatchError, match=re.escape(expected)):
        batch(tmp_path, text)


def test_an_output_name_no_file_system_can_hold_is_refused(tmp_path):
    with pytest.raises(BatchError, match=r"output: '\\ud800.png' is not text a file name can hold"):
        batch(tmp_path, '{"shots": [{"scene": "cornell_box", "output": "\\ud800.png"}]}', name="shots.json")


def test_a_scene_name_too_long_for_the_file_system_is_a_scene_not_found(tmp_path):
    shots = batch(tmp_path, f'[[shots]]\nscene = "{"x" * 300}"\noutput = "a.png"\n')  # no Errno 36 while reading
    assert shots.shots[0].scene == "x" * 300


@pytest.mark.parametrize("value, expected", [
    ("1979-05-27", "shot 1: spp: expected a whole number, not a date (1979-05-27)"),
    ("07:32:00", "shot 1: spp: expected a whole number, not a time (07:32:00)"),
    ("1979-05-27T07:32:00Z", "shot 1: spp: expected a whole number, not a date and time (1979-05-27T07:32:00+00:00)"),
    ("[1, 1979-05-27]", "shot 1: spp: expected a whole number, not a date (1979-05-27)"),
    ("{from = 1, to = 8, steps = 07:32:00}", "shot 1: spp.steps: expected a whole number from 1 to 10000, not a time"),
])
def test_a_toml_date_or_time_as_a_value_is_one_line(tmp_path, value, expected):
    """TOML has dates and times of its own, which JSON (the messages' way of showing a value) has no text for."""
    assert expected in error(tmp_path, f'[[shots]]\nscene = "cornell_box"\noutput = "a.png"\nspp = {value}\n')


@pytest.mark.parametrize("shot, expected", [
    ('output = "{index:c}.png"\n', r"output: '{index:c}.png': a field makes '\x01', which is no part of a file name"),
    ('output = "{spp:c}.png"\nspp = [48, 47]\n', r"a field makes '/', which is no part of a file name"),
    ('output = "{name}/{index}.png"\nname = ".."\n', "a field makes '..', which is no part of a file name"),
    ('output = "\\u202e{index}.png"\n', r"output: '\u202e1.png' is not a name a terminal or a folder shows as it is"),
])
def test_an_output_pattern_that_makes_no_file_name_is_refused(tmp_path, shot, expected):
    """{index:c} once wrote a file named "\\x01.png"; a value's "/" or ".." would put the image in another folder."""
    message = error(tmp_path, '[[shots]]\nscene = "cornell_box"\n' + shot)
    assert expected in message
    assert list(tmp_path.iterdir()) == [tmp_path / "shots.toml"]


def test_output_patterns_that_make_names_still_do(tmp_path):
    shots = batch(tmp_path, '[[shots]]\nscene = "cornell_box"\noutput = "renders/{index:03d}_{name}.png"\n'
                            'name = "a/b"\nspp = [1, 2]\n')
    assert [shot.output.relative_to(tmp_path).as_posix() for shot in shots.shots] == [
        "renders/001_a_b.png", "renders/002_a_b.png"]


def test_a_batch_file_that_is_a_named_pipe_is_refused_not_waited_on(tmp_path):
    from tests.malformed_inputs import fifo_read_as_empty

    with fifo_read_as_empty(tmp_path / "shots.toml") as pipe, pytest.raises(BatchError) as caught:
        read_batch(pipe)
    assert str(caught.value) == f"{pipe}: cannot read (a named pipe (FIFO), not a regular file)"


def test_an_output_that_is_a_named_pipe_is_refused_not_skipped_or_replaced(tmp_path):
    import os
    import stat

    os.mkfifo(tmp_path / "a.png")
    message = error(tmp_path, '[[shots]]\nscene = "cornell_box"\noutput = "a.png"\n')
    assert f"shot 1: output: {tmp_path / 'a.png'}: a named pipe (FIFO), not a regular file" in message
    assert stat.S_ISFIFO(os.lstat(tmp_path / "a.png").st_mode)
