"""Each render and camera option is declared once (scene/options.py): the command line, the batch file, the scene
overrides and the image metadata are made from the table, under one name each, older spellings still read."""

from __future__ import annotations

import dataclasses
import math
import textwrap

import pytest

from lenslab.batch.spec import parse_batch
from lenslab.cli import build_parser
from lenslab.render.job import image_metadata
from lenslab.scene.io.loader import open_scene
from lenslab.scene.options import OLD_NAMES, OPTIONS, SCENE_OPTIONS
from lenslab.scene.overrides import SceneOverrides


def a_value(option):
    """A value the option takes that differs from the shipped scenes' defaults where possible."""
    if option.kind is bool:
        return False
    if option.allowed is not None:
        return option.allowed[-1]
    if option.range is not None:
        low, high = option.range
        value = low + (min(high, low + 10) - low) * 0.37 if option.kind is float else min(high, low + 3)
        return option.check(value)
    return None  # a preset's or a file's name: tested on their own


def test_the_overrides_have_one_field_per_scene_option():
    fields = [field.name for field in dataclasses.fields(SceneOverrides)]
    assert fields == [option.name for option in SCENE_OPTIONS] + ["defines"]


def test_every_option_is_a_command_line_flag_of_its_name_and_its_older_ones():
    parser = build_parser()
    by_flag = {flag: action for action in parser._actions for flag in action.option_strings}
    for option in OPTIONS.values():
        assert option.flag in by_flag, option.name
        action = by_flag[option.flag]
        assert action.dest == option.name
        assert all(by_flag[old] is action for old in option.old_flags)
        assert option.help.split(" (")[0][:30] in (action.help or ""), option.name


@pytest.mark.parametrize("option", [o for o in OPTIONS.values() if o.scene and a_value(o) is not None],
                         ids=lambda o: o.name)
def test_a_value_reaches_the_scene_the_same_from_the_command_line_a_batch_file_and_python(option, tmp_path):
    value = a_value(option)
    scene = open_scene("cornell_box")
    if option.kind is bool:
        argv = [f"--no-{option.flag[2:]}"]
    else:
        argv = [option.flag, repr(value) if option.kind is float else str(value)]
    args = build_parser().parse_args(["cornell_box", *argv])
    from lenslab.cli import scene_overrides

    from_cli = scene_overrides(args)
    toml = f"[[shots]]\nscene = 'cornell_box'\noutput = 'a.png'\n{option.name} = " + (
        f"'{value}'" if isinstance(value, str) else str(value).lower())
    (shot,) = parse_batch(toml, tmp_path / "shots.toml").shots
    from_python = SceneOverrides(**{option.name: value})
    assert from_cli == shot.overrides == from_python
    changed = from_python.apply(scene)
    if option.sets:
        owner, name = option.sets.split(".")
        got = getattr(getattr(changed, owner), name)
        expected = from_python.f_number if option.name == "f_number" else value  # a marked stop is exact
        assert got == expected or (isinstance(got, float) and math.isclose(got, expected)), (option.name, got)


@pytest.mark.parametrize("old, name", sorted((old, name) for old, name in OLD_NAMES.items() if OPTIONS[name].scene))
def test_older_spellings_are_still_read(old, name, tmp_path):
    option = OPTIONS[name]
    value = a_value(option)
    args = build_parser().parse_args(["cornell_box", "--" + old.replace("_", "-"), str(value)])
    assert getattr(args, name) == option.from_text(str(value))
    toml = f"[[shots]]\nscene = 'cornell_box'\noutput = 'a_{{{old}}}.png'\n{old} = {value}\n"
    (shot,) = parse_batch(toml, tmp_path / "shots.toml").shots
    assert getattr(shot.overrides, name) == getattr(SceneOverrides(**{name: value}), name)
    assert shot.output.name != "a_.png"  # an output pattern may name the setting as it was written


def test_the_old_tone_map_is_read_as_the_view_everywhere(tmp_path):
    """tone_map was how a picture's display curve was named; its values clamp and filmic name views now."""
    args = build_parser().parse_args(["cornell_box", "--tone-map", "clamp"])
    assert args.view == "clamp"
    toml = "[[shots]]\nscene = 'cornell_box'\noutput = 'a_{tone_map}.png'\ntone_map = 'filmic'\n"
    (shot,) = parse_batch(toml, tmp_path / "shots.toml").shots
    assert shot.view.resolved().view == "ACES 2.0 - SDR 100 nits (Rec.709)"
    assert shot.output.name == "a_filmic.png"


def test_a_setting_given_twice_under_two_spellings_is_refused(tmp_path):
    toml = "[[shots]]\nscene = 'cornell_box'\noutput = 'a.png'\ncoc = 0.02\ncircle_of_confusion = 0.03\n"
    with pytest.raises(ValueError, match="'circle_of_confusion' are one setting"):
        parse_batch(toml, tmp_path / "shots.toml")


def test_text_a_photographer_writes_means_the_same_everywhere(tmp_path):
    args = build_parser().parse_args(["cornell_box", "--f-number", "f/11", "--shutter", "1/125"])
    toml = textwrap.dedent("""
        [[shots]]
        scene = 'cornell_box'
        output = 'a.png'
        f_number = "f/11"
        shutter = "1/125"
        """)
    (shot,) = parse_batch(toml, tmp_path / "shots.toml").shots
    assert (args.f_number, args.shutter) == (shot.overrides.f_number, shot.overrides.shutter) == (2 ** 3.5, 1 / 125)


def test_the_image_metadata_names_come_from_the_table():
    overrides = SceneOverrides(iso=400.0, shutter=1 / 60, aperture_blades=7)
    scene = overrides.apply(open_scene("cornell_box"))
    frame = scene.camera.frame(*scene.camera.resolution)
    metadata = image_metadata(scene, 16, frame)
    # An aperture image is named only when there is one; dispersion only through a real lens's glass
    # (tests/test_real_lens.py).
    named = {option.metadata for option in SCENE_OPTIONS
             if option.metadata and option.name not in ("aperture_image", "dispersion")}
    assert named <= metadata.keys()
    assert metadata[OPTIONS["spp"].metadata] == 16
    assert metadata[OPTIONS["aperture_blades"].metadata] == 7
    assert metadata[OPTIONS["shutter"].metadata] == pytest.approx(1 / 60)
