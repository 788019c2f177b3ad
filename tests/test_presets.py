"""Lens and sensor presets: every shipped file loads, every broken file is reported by name and key."""

import json
import math
from pathlib import Path

import pytest

from lenslab.optics import presetfiles
from lenslab.optics.lenses import LensPreset, load_lens_presets, read_lens_file
from lenslab.optics.presetfiles import PresetError, shipped_presets_dir, user_presets_dir
from lenslab.optics.sensors import FULL_FRAME, SensorPreset, load_sensor_presets
from lenslab.optics.presetfiles import FieldError
from lenslab.optics.stops import STOP_SCALES, THIRD_STOPS, exact_f_number, step_stop

REPO = Path(__file__).resolve().parents[1]
SHIPPED_LENS_FILES = sorted((REPO / "presets" / "lenses").glob("*.json"))


@pytest.fixture(autouse=True)
def isolated_user_dir(tmp_path, monkeypatch):
    """Point the user presets folder at an empty temporary place, whatever the host has."""
    config = tmp_path / "config"
    config.mkdir()
    monkeypatch.setenv("XDG_CONFIG_HOME", str(config))
    return config / "lenslab" / "presets"


def write(path: Path, data) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(data if isinstance(data, str) else json.dumps(data), encoding="utf-8")
    return path


# --- shipped presets ------------------------------------------------------------------------

def test_shipped_folder_is_the_checkout_presets():
    assert shipped_presets_dir() == REPO / "presets"


def test_there_are_shipped_lens_files():
    assert len(SHIPPED_LENS_FILES) >= 9


@pytest.mark.parametrize("path", SHIPPED_LENS_FILES, ids=lambda p: p.name)
def test_every_shipped_lens_file_loads(path):
    lens = read_lens_file(path)
    assert lens.widest_f_number < lens.narrowest_f_number
    assert lens.aperture_blades >= 5, "shipped lenses have a real iris"
    assert lens.min_focus_distance_m is not None and lens.min_focus_distance_m > 0
    assert lens.description


def test_shipped_lenses_are_the_promised_set():
    lenses = {l.name: l for l in load_lens_presets(include_user=False)}
    expected = {
        "14 mm f/2.8": (14, 14, 2.8),
        "24 mm f/1.4": (24, 24, 1.4),
        "35 mm f/1.4": (35, 35, 1.4),
        "50 mm f/1.2": (50, 50, 1.2),
        "85 mm f/1.4": (85, 85, 1.4),
        "100 mm f/2.8 Macro": (100, 100, 2.8),
        "135 mm f/2": (135, 135, 2.0),
        "24-70 mm f/2.8": (24, 70, 2.8),
        "70-200 mm f/2.8": (70, 200, 2.8),
    }
    assert set(expected) <= set(lenses)
    for name, (short, long_, n) in expected.items():
        lens = lenses[name]
        assert (lens.min_focal_length_mm, lens.max_focal_length_mm, lens.widest_f_number) == (short, long_,
                                                                                              exact_f_number(n))
        assert lens.is_zoom == (short != long_)


def test_lenses_come_sorted_by_focal_length():
    lenses = load_lens_presets(include_user=False)
    keys = [(l.min_focal_length_mm, l.max_focal_length_mm) for l in lenses]
    assert keys == sorted(keys)


def test_shipped_sensors():
    sensors = {s.name: s for s in load_sensor_presets(include_user=False)}
    expected = {
        "Full frame": (36, 24),
        "APS-C": (23.5, 15.6),
        "APS-C (Canon)": (22.3, 14.9),
        "Micro Four Thirds": (17.3, 13),
        "Medium format 44x33": (44, 33),
    }
    for name, size in expected.items():
        assert (sensors[name].width_mm, sensors[name].height_mm) == size
    assert sensors["Full frame"] == FULL_FRAME
    assert len(sensors) >= 8


def test_sensor_properties():
    aps_c = SensorPreset("APS-C", 23.5, 15.6)
    # crop = 43.2666 / 28.2066 = 1.5339
    assert aps_c.crop_factor == pytest.approx(1.5339, abs=1e-4)
    assert FULL_FRAME.crop_factor == 1.0
    assert FULL_FRAME.aspect_ratio == 1.5
    assert FULL_FRAME.coc_mm == pytest.approx(0.028844, rel=1e-4)


def test_a_sensor_may_name_its_circle_of_confusion(tmp_path):
    write(tmp_path / "sensors.json", {"sensors": [
        {"name": "Super 35 (cine)", "width_mm": 24.89, "height_mm": 18.66, "circle_of_confusion_mm": 0.025},
        {"name": "Own default", "width_mm": 36, "height_mm": 24, "circle_of_confusion_mm": None},
        {"name": "Plain", "width_mm": 36, "height_mm": 24}]})
    cine, explicit_null, plain = load_sensor_presets([tmp_path], include_shipped=False)
    assert (cine.circle_of_confusion_mm, cine.coc_mm) == (0.025, 0.025)  # the file's value, not 31.1 mm / 1500
    assert explicit_null.circle_of_confusion_mm is None and plain.circle_of_confusion_mm is None
    assert explicit_null.coc_mm == plain.coc_mm == pytest.approx(math.hypot(36, 24) / 1500)
    assert plain == FULL_FRAME.__class__("Plain", 36, 24)
    assert isinstance(SensorPreset("x", 36, 24, circle_of_confusion_mm=1).circle_of_confusion_mm, float)


def test_shipped_sensors_use_the_diagonal_rule_unless_they_say():
    for sensor in load_sensor_presets(include_user=False):
        expected = sensor.circle_of_confusion_mm or math.hypot(sensor.width_mm, sensor.height_mm) / 1500
        assert sensor.coc_mm == pytest.approx(expected)


@pytest.mark.parametrize("coc", [0, -0.02, 1.5, math.nan, math.inf, "0.02", True])
def test_a_bad_circle_of_confusion_is_refused_naming_the_key(coc):
    with pytest.raises(FieldError) as info:
        SensorPreset("x", 36, 24, circle_of_confusion_mm=coc)
    assert info.value.key == "circle_of_confusion_mm"


def test_the_sensor_and_the_camera_accept_the_same_circles_of_confusion():
    from lenslab.optics.sensors import SENSOR_COC_RANGE_MM
    from lenslab.scene.camera import ThinLensCamera
    from lenslab.scene.fields import declared_range

    assert declared_range(ThinLensCamera, "circle_of_confusion_mm") == SENSOR_COC_RANGE_MM


# --- lens behaviour -------------------------------------------------------------------------

def test_prime_clamps():
    lens = LensPreset("50", focal_length_mm=50, widest_f_number=1.2, narrowest_f_number=16)
    assert lens.clamp_focal_length(24) == 50 and lens.clamp_focal_length(85) == 50
    # A lens's marks are its exact stops: f/1.2 opens to 2^(2/3), f/16 closes to 16.
    assert lens.clamp_f_number(0.95) == exact_f_number(1.2) == pytest.approx(1.26, abs=0.001)
    assert lens.clamp_f_number(22) == 16
    assert lens.clamp_f_number(5.6) == 5.6
    assert not lens.is_zoom


def test_zoom_clamps():
    lens = LensPreset("24-70", focal_range_mm=(24, 70), widest_f_number=2.8)
    assert lens.clamp_focal_length(10) == 24
    assert lens.clamp_focal_length(35) == 35
    assert lens.clamp_focal_length(200) == 70
    assert lens.clamp_f_number(1.4) == exact_f_number(2.8)
    assert lens.clamp_f_number(32) == exact_f_number(22)  # narrowest defaults to f/22
    assert lens.is_zoom


def test_available_stops_include_the_lens_ends():
    fast = LensPreset("50", focal_length_mm=50, widest_f_number=1.2, narrowest_f_number=16)
    stops = fast.available_stops()  # exact third stops
    assert stops[:3] == pytest.approx((2 ** (2 / 6), 2 ** (3 / 6), 2 ** (4 / 6))) and stops[-1] == 16
    assert step_stop(2 ** 0.5, -1, stops) == stops[0]
    assert fast.available_stops("full") == pytest.approx((2 ** (1 / 3), 2 ** 0.5, 2, 2 ** 1.5, 4, 2 ** 2.5, 8,
                                                          2 ** 3.5, 16))
    assert fast.available_stops(STOP_SCALES["full"]) == fast.available_stops("full")
    half = fast.available_stops("half")
    assert half[0] == exact_f_number(1.2) and half[-1] == 16
    assert all(n in STOP_SCALES["half"].exact for n in half[1:])  # f/1.2 (2^(1/3)) is no half stop: the lens's end
    # A lens marked f/1.4 to f/22 ends on exact stops, so every step within it is one mark of the scale.
    lens = LensPreset("85", focal_length_mm=85, widest_f_number=1.4, narrowest_f_number=22)
    assert (lens.widest_f_number, lens.narrowest_f_number) == (2 ** 0.5, 2 ** 4.5)
    for scale, fraction in (("full", 1), ("half", 1 / 2), ("third", 1 / 3)):
        stops = lens.available_stops(scale)
        assert (stops[0], stops[-1]) == (2 ** 0.5, 2 ** 4.5) and len(stops) == 8 * fraction ** -1 + 1
        assert [step_stop(n, 1, stops) for n in stops[:-1]] == list(stops[1:])
        assert all(2 * math.log2(b / a) == pytest.approx(fraction) for a, b in zip(stops, stops[1:]))
    odd = LensPreset("odd", focal_length_mm=40, widest_f_number=1.7, narrowest_f_number=21)
    stops = odd.available_stops(THIRD_STOPS)
    assert stops[0] == 1.7 and stops[1] == 1.8 and stops[-2:] == (20, 21)


@pytest.mark.parametrize(
    "kwargs,key",
    [
        (dict(widest_f_number=2), "focal_length_mm"),  # neither focal field
        (dict(focal_length_mm=50, focal_range_mm=(24, 70), widest_f_number=2), "focal_length_mm"),
        (dict(focal_length_mm=-50, widest_f_number=2), "focal_length_mm"),
        (dict(focal_range_mm=(70, 24), widest_f_number=2), "focal_range_mm"),
        (dict(focal_length_mm=50, widest_f_number=0), "widest_f_number"),
        (dict(focal_length_mm=50, widest_f_number=4, narrowest_f_number=2), "narrowest_f_number"),
        (dict(focal_length_mm=50, widest_f_number=2, aperture_blades=2), "aperture_blades"),
        (dict(focal_length_mm=50, widest_f_number=2, blade_roundness=1.5), "blade_roundness"),
        (dict(focal_length_mm=50, widest_f_number=2, min_focus_distance_m=0), "min_focus_distance_m"),
    ],
)
def test_direct_construction_validates(kwargs, key):
    with pytest.raises(ValueError, match=key):
        LensPreset("bad", **kwargs)


def test_presets_are_frozen():
    with pytest.raises(AttributeError):
        FULL_FRAME.width_mm = 24


# --- broken files ---------------------------------------------------------------------------

GOOD_LENS = {"name": "Test 40", "focal_length_mm": 40, "widest_f_number": 2}

BROKEN_LENSES = [
    # (file content, key that must be named; None where the file is not JSON at all)
    ('{"name": "x", "focal_length_mm": 40,, }', None),
    ("[1, 2]", None),
    ("", None),
    ({**GOOD_LENS, "focal_lenght_mm": 50}, "focal_lenght_mm"),
    ({k: v for k, v in GOOD_LENS.items() if k != "widest_f_number"}, "widest_f_number"),
    ({**GOOD_LENS, "focal_length_mm": "40"}, "focal_length_mm"),
    ({**GOOD_LENS, "focal_length_mm": -40}, "focal_length_mm"),
    ({**GOOD_LENS, "focal_length_mm": 0}, "focal_length_mm"),
    ({**GOOD_LENS, "widest_f_number": 0}, "widest_f_number"),
    ({**GOOD_LENS, "widest_f_number": 200}, "widest_f_number"),
    ({**GOOD_LENS, "narrowest_f_number": 1.4}, "narrowest_f_number"),
    ({**GOOD_LENS, "aperture_blades": 9.5}, "aperture_blades"),
    ({**GOOD_LENS, "aperture_blades": True}, "aperture_blades"),
    ({**GOOD_LENS, "aperture_blades": -9}, "aperture_blades"),
    ({**GOOD_LENS, "blade_roundness": -0.1}, "blade_roundness"),
    ({**GOOD_LENS, "blade_rotation_deg": None}, "blade_rotation_deg"),
    ({**GOOD_LENS, "min_focus_distance_m": -1}, "min_focus_distance_m"),
    ({**GOOD_LENS, "name": ""}, "name"),
    ({**GOOD_LENS, "name": 40}, "name"),
    ({**GOOD_LENS, "focal_range_mm": [24, 70]}, "focal_length_mm"),
    ({"name": "z", "focal_range_mm": [24], "widest_f_number": 2}, "focal_range_mm"),
    ({"name": "z", "focal_range_mm": [70, 24], "widest_f_number": 2}, "focal_range_mm"),
    ({"name": "z", "focal_range_mm": [50, 50], "widest_f_number": 2}, "focal_range_mm"),
]


@pytest.mark.parametrize("content,key", BROKEN_LENSES)
def test_broken_lens_file_raises_naming_file_and_key(tmp_path, content, key):
    path = write(tmp_path / "extra" / "lenses" / "broken-lens.json", content)
    write(tmp_path / "extra" / "lenses" / "good.json", GOOD_LENS | {"name": "Fine"})
    with pytest.raises(PresetError) as info:
        load_lens_presets([tmp_path / "extra"])
    message = str(info.value)
    assert "\n" not in message
    assert str(path) in message
    assert info.value.path == path
    if key is not None:
        assert f"'{key}'" in message
        assert info.value.key == key


def test_bad_json_names_the_line(tmp_path):
    write(tmp_path / "lenses" / "a.json", '{\n  "name": "x",\n  "focal_length_mm": 4 0\n}')
    with pytest.raises(PresetError, match=r"a\.json: invalid JSON at line 3"):
        load_lens_presets([tmp_path], include_shipped=False)


def test_non_utf8_file(tmp_path):
    path = tmp_path / "lenses" / "latin1.json"
    path.parent.mkdir(parents=True)
    path.write_bytes('{"name": "Objectif 50 mm \u00e9"}'.encode("latin-1"))
    with pytest.raises(PresetError, match="latin1.json: not UTF-8"):
        load_lens_presets([tmp_path], include_shipped=False)


def test_duplicate_lens_name_in_one_folder(tmp_path):
    write(tmp_path / "lenses" / "a.json", GOOD_LENS)
    second = write(tmp_path / "lenses" / "b.json", GOOD_LENS)
    with pytest.raises(PresetError) as info:
        load_lens_presets([tmp_path], include_shipped=False)
    assert str(second) in str(info.value) and info.value.key == "name"


GOOD_SENSOR = {"name": "Test", "width_mm": 30, "height_mm": 20}

BROKEN_SENSORS = [
    ("{not json", None),
    ([GOOD_SENSOR], None),  # a bare list, not {"sensors": [...]}
    ({"sensor": [GOOD_SENSOR]}, "sensor"),
    ({"sensors": GOOD_SENSOR}, "sensors"),
    ({"sensors": [GOOD_SENSOR, "APS-C"]}, "sensors[1]"),
    ({"sensors": [GOOD_SENSOR | {"width_mm": -36}]}, "sensors[0].width_mm"),
    ({"sensors": [GOOD_SENSOR | {"height_mm": 0}]}, "sensors[0].height_mm"),
    ({"sensors": [GOOD_SENSOR | {"height_mm": "24"}]}, "sensors[0].height_mm"),
    ({"sensors": [GOOD_SENSOR | {"width_mm": 36000}]}, "sensors[0].width_mm"),
    ({"sensors": [{"name": "x", "width_mm": 36}]}, "sensors[0].height_mm"),
    ({"sensors": [GOOD_SENSOR | {"crop": 1.5}]}, "sensors[0].crop"),
    ({"sensors": [GOOD_SENSOR, GOOD_SENSOR]}, "sensors[1].name"),
    ({"sensors": [GOOD_SENSOR | {"circle_of_confusion_mm": 0}]}, "sensors[0].circle_of_confusion_mm"),
    ({"sensors": [GOOD_SENSOR | {"circle_of_confusion_mm": -0.03}]}, "sensors[0].circle_of_confusion_mm"),
    ({"sensors": [GOOD_SENSOR | {"circle_of_confusion_mm": 30}]}, "sensors[0].circle_of_confusion_mm"),  # µm, not mm
    ({"sensors": [GOOD_SENSOR | {"circle_of_confusion_mm": "0.03"}]}, "sensors[0].circle_of_confusion_mm"),
    ({"sensors": [GOOD_SENSOR | {"circle_of_confusion_mm": True}]}, "sensors[0].circle_of_confusion_mm"),
    ('{"sensors": [{"name": "x", "width_mm": 36, "height_mm": 24, "circle_of_confusion_mm": NaN}]}',
     "sensors[0].circle_of_confusion_mm"),
    ('{"sensors": [{"name": "x", "width_mm": 36, "height_mm": 24, "circle_of_confusion_mm": Infinity}]}',
     "sensors[0].circle_of_confusion_mm"),
    ({"sensors": [GOOD_SENSOR | {"coc_mm": 0.03}]}, "sensors[0].coc_mm"),  # the file's key is the field's name
]


@pytest.mark.parametrize("content,key", BROKEN_SENSORS)
def test_broken_sensor_file_raises_naming_file_and_key(tmp_path, content, key):
    path = write(tmp_path / "sensors.json", content)
    with pytest.raises(PresetError) as info:
        load_sensor_presets([tmp_path])
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    if key is not None:
        assert f"'{key}'" in message


def test_broken_shipped_file_is_reported_too(tmp_path, monkeypatch):
    """The shipped folder gets no leniency: point it at a broken copy."""
    fake = tmp_path / "shipped"
    write(fake / "lenses" / "24mm.json", GOOD_LENS | {"widest_f_number": 0})
    monkeypatch.setattr(presetfiles, "shipped_presets_dir", lambda: fake)
    with pytest.raises(PresetError, match=r"24mm\.json: 'widest_f_number'"):
        load_lens_presets()


def test_missing_extra_dir_is_an_error(tmp_path):
    with pytest.raises(PresetError, match="does not exist"):
        load_lens_presets([tmp_path / "nowhere"])


# --- user presets and overriding ------------------------------------------------------------

def test_user_dir_follows_xdg(isolated_user_dir):
    assert user_presets_dir() == isolated_user_dir


def test_relative_xdg_is_ignored(monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_CONFIG_HOME", "relative/config")
    monkeypatch.setenv("HOME", str(tmp_path))
    assert user_presets_dir() == tmp_path / ".config" / "lenslab" / "presets"


def test_user_lens_is_added_and_can_replace_a_shipped_one(isolated_user_dir):
    write(isolated_user_dir / "lenses" / "mine.json", {"name": "40 mm f/2", "focal_length_mm": 40, "widest_f_number": 2})
    write(isolated_user_dir / "lenses" / "retuned.json",
          {"name": "85 mm f/1.4", "focal_length_mm": 85, "widest_f_number": 1.4, "aperture_blades": 6})
    write(isolated_user_dir / "lenses" / ".mine.json.swp", "editor junk")  # dot files are ignored
    lenses = {l.name: l for l in load_lens_presets()}
    assert lenses["40 mm f/2"].focal_length_mm == 40
    assert lenses["85 mm f/1.4"].aperture_blades == 6
    assert sum(1 for l in load_lens_presets() if l.name == "85 mm f/1.4") == 1


def test_user_sensor_replaces_in_place(isolated_user_dir):
    shipped = [s.name for s in load_sensor_presets()]
    write(isolated_user_dir / "sensors.json",
          {"sensors": [{"name": "APS-C", "width_mm": 23.6, "height_mm": 15.7}, {"name": "Mine", "width_mm": 10, "height_mm": 10}]})
    sensors = load_sensor_presets()
    assert [s.name for s in sensors] == shipped + ["Mine"]
    assert next(s for s in sensors if s.name == "APS-C").width_mm == 23.6


def test_extra_dirs_win_over_user(isolated_user_dir, tmp_path):
    write(isolated_user_dir / "lenses" / "a.json", GOOD_LENS | {"aperture_blades": 5})
    write(tmp_path / "extra" / "lenses" / "a.json", GOOD_LENS | {"aperture_blades": 7})
    lens = next(l for l in load_lens_presets([tmp_path / "extra"]) if l.name == GOOD_LENS["name"])
    assert lens.aperture_blades == 7


def test_broken_user_file_is_reported(isolated_user_dir):
    path = write(isolated_user_dir / "lenses" / "oops.json", GOOD_LENS | {"focal_length_mm": -1})
    with pytest.raises(PresetError) as info:
        load_lens_presets()
    assert str(path) in str(info.value) and "'focal_length_mm'" in str(info.value)


# --- locating the shipped folder ------------------------------------------------------------

def test_installed_package_location_wins_over_checkout(tmp_path, monkeypatch):
    """In a wheel, presets sit in lenslab/presets next to the optics package."""
    site = tmp_path / "checkout" / "app"
    module = site / "lenslab" / "optics" / "presetfiles.py"
    module.parent.mkdir(parents=True)
    module.touch()
    monkeypatch.setattr(presetfiles, "__file__", str(module))
    (tmp_path / "checkout" / "presets").mkdir()
    assert presetfiles.shipped_presets_dir() == tmp_path / "checkout" / "presets"
    (site / "lenslab" / "presets").mkdir()
    assert presetfiles.shipped_presets_dir() == site / "lenslab" / "presets"


def test_missing_shipped_folder_is_a_preset_error(tmp_path, monkeypatch):
    module = tmp_path / "a" / "b" / "lenslab" / "optics" / "presetfiles.py"
    module.parent.mkdir(parents=True)
    monkeypatch.setattr(presetfiles, "__file__", str(module))
    with pytest.raises(PresetError, match="shipped presets folder not found"):
        presetfiles.shipped_presets_dir()


def test_readme_documents_every_key():
    readme = (REPO / "presets" / "README.md").read_text(encoding="utf-8")
    from dataclasses import fields
    for cls in (LensPreset, SensorPreset):
        for f in fields(cls):
            if f.init and f.name != "_":
                assert f"`{f.name}`" in readme, f.name


def test_a_named_pipe_among_the_users_lenses_is_refused_not_waited_on(isolated_user_dir):
    from tests.malformed_inputs import fifo_read_as_empty

    (isolated_user_dir / "lenses").mkdir(parents=True)
    with fifo_read_as_empty(isolated_user_dir / "lenses" / "pipe.json") as pipe:
        with pytest.raises(PresetError, match=r"pipe\.json.*named pipe"):
            load_lens_presets()
    assert pipe.name == "pipe.json"


def test_an_option_given_an_integer_past_the_float_range_is_refused_in_one_line():
    from lenslab.scene.options import OPTIONS

    blades = OPTIONS["aperture_blades"]
    with pytest.raises(ValueError, match=r"^aperture_blades 999999\.\.\. \(400 digits\) is out of range \[0, "):
        blades.check(int("9" * 400))
