"""The command line on the way to the studio: ``-o`` without ``--headless`` says to add it, and a studio started
where there is no display says so (not Qt's hint about libxcb-cursor). Run through ``lenslab.cli.main`` with the
environment set by each test, and once as a real process."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from lenslab.cli import EXIT_ERROR, EXIT_USAGE, main

NO_DISPLAY = {"DISPLAY": None, "WAYLAND_DISPLAY": None, "QT_QPA_PLATFORM": None}


@pytest.fixture
def studio_calls(monkeypatch):
    """run_studio replaced by a recorder: a test learns whether the studio would have opened, and no window does."""
    from lenslab.gui import app

    calls = []
    monkeypatch.setattr(app, "run_studio", lambda *args, **kwargs: calls.append(args) or 0)
    return calls


def environment(monkeypatch, **values):
    for name, value in values.items():
        if value is None:
            monkeypatch.delenv(name, raising=False)
        else:
            monkeypatch.setenv(name, value)


def test_an_output_file_without_headless_says_to_add_it(tmp_path, capsys, monkeypatch, studio_calls):
    environment(monkeypatch, DISPLAY=":0")
    out = tmp_path / "out.png"
    status = main(["cornell_box", "-o", str(out), "--spp", "4"])
    err = capsys.readouterr().err
    assert status == EXIT_USAGE and studio_calls == [] and not out.exists()
    assert err.count("\n") == 1 and err.startswith("lenslab: error: ")
    assert "--headless" in err and f"lenslab cornell_box --headless -o {out}" in err


@pytest.mark.parametrize("platform", [None, "xcb", "wayland"])
def test_the_studio_without_a_display_says_it_needs_one(capsys, monkeypatch, studio_calls, platform):
    environment(monkeypatch, **{**NO_DISPLAY, "QT_QPA_PLATFORM": platform})
    status = main(["cornell_box"])
    err = capsys.readouterr().err
    assert status == EXIT_ERROR and studio_calls == []
    assert err.count("\n") == 1 and err.startswith("lenslab: error: the studio needs a display")
    assert "--headless" in err and "xcb" not in err


@pytest.mark.parametrize("values", [{"DISPLAY": ":1"}, {"WAYLAND_DISPLAY": "wayland-0"},
                                    {"QT_QPA_PLATFORM": "offscreen"}, {"QT_QPA_PLATFORM": "minimal"},
                                    {"QT_QPA_PLATFORM": "wayland;offscreen"}])
def test_a_display_or_a_platform_that_needs_none_opens_the_studio(capsys, monkeypatch, studio_calls, values):
    environment(monkeypatch, **{**NO_DISPLAY, **values})
    assert main(["cornell_box"]) == 0
    assert len(studio_calls) == 1 and capsys.readouterr().err == ""


def test_windows_and_macos_always_have_a_display():
    from lenslab.cli import display_problem

    assert display_problem({}, "win32") is None and display_problem({}, "darwin") is None
    assert display_problem({}, "linux") and display_problem({}, "freebsd14")


def test_a_real_process_without_a_display_says_so_and_never_imports_qt():
    env = {k: v for k, v in os.environ.items() if k not in NO_DISPLAY}
    code = ("import sys; from lenslab.cli import main; status = main(['cornell_box']); "
            "assert 'PySide6' not in sys.modules, 'Qt was imported'; sys.exit(status)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)
    assert result.returncode == EXIT_ERROR, result.stderr
    assert result.stderr.startswith("lenslab: error: the studio needs a display") and result.stderr.count("\n") == 1
    assert "libxcb" not in result.stderr and "Traceback" not in result.stderr
