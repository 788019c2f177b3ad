"""Desktop integration metadata: the .desktop entry, AppStream metainfo and icon agree on one id."""

import configparser
import shutil
import struct
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

PACKAGING = Path(__file__).resolve().parents[1] / "packaging"
APP_ID = "io.github.lenslab.LensLab"
DESKTOP = PACKAGING / "lenslab.desktop"
METAINFO = PACKAGING / f"{APP_ID}.metainfo.xml"
ICON_SVG = PACKAGING / "icons" / "lenslab.svg"
ICON_PNG = PACKAGING / "icons" / "lenslab-256.png"


@pytest.fixture(scope="module")
def entry():
    parser = configparser.ConfigParser(interpolation=None, strict=True)
    parser.optionxform = str  # desktop keys are case-sensitive
    parser.read(DESKTOP, encoding="utf-8")
    assert parser.has_section("Desktop Entry"), "missing [Desktop Entry] group"
    return parser["Desktop Entry"]


def test_desktop_entry_required_keys(entry):
    assert entry["Type"] == "Application"
    assert entry["Name"] == "LensLab"
    assert entry["Exec"] == "lenslab %f"
    assert entry["Icon"] == APP_ID
    assert entry.get("Terminal") == "false"
    assert entry["Comment"]


def test_desktop_entry_categories(entry):
    categories = entry["Categories"]
    assert categories.endswith(";")
    assert {"Graphics", "3DGraphics", "Photography"} <= set(filter(None, categories.split(";")))


@pytest.mark.skipif(shutil.which("desktop-file-validate") is None,
                    reason="desktop-file-validate not installed (Debian package desktop-file-utils)")
def test_desktop_file_validate():
    result = subprocess.run(["desktop-file-validate", str(DESKTOP)], capture_output=True, text=True)
    assert result.returncode == 0 and not result.stdout.strip(), result.stdout + result.stderr


@pytest.fixture(scope="module")
def component():
    return ET.parse(METAINFO).getroot()


def test_metainfo_ids_agree_with_desktop_entry(component, entry):
    assert component.get("type") == "desktop-application"
    assert component.findtext("id") == APP_ID
    launchable = component.find("launchable")
    assert launchable.get("type") == "desktop-id" and launchable.text == f"{APP_ID}.desktop"
    assert component.findtext("icon") == entry["Icon"]
    assert component.findtext("name") == entry["Name"]
    assert component.findtext("provides/binary") == entry["Exec"].split()[0]


def test_metainfo_required_fields(component):
    assert component.findtext("metadata_license") == "CC0-1.0"
    assert component.findtext("project_license") == "MIT"
    assert component.findtext("summary")
    assert component.find("description/p") is not None
    assert component.find("content_rating").get("type").startswith("oars-")
    homepage = component.find("url[@type='homepage']")
    assert homepage is not None and homepage.text.startswith("https://")
    release = component.find("releases/release")
    assert (release.get("version"), release.get("date")) == ("0.1.0", "2026-11-22")


@pytest.mark.skipif(shutil.which("appstreamcli") is None,
                    reason="appstreamcli not installed (Debian package appstream)")
def test_appstreamcli_validate():
    result = subprocess.run(
        ["appstreamcli", "validate", "--no-net", str(METAINFO)], capture_output=True, text=True
    )
    assert result.returncode == 0, result.stdout + result.stderr


def test_icon_svg_is_square_svg():
    root = ET.parse(ICON_SVG).getroot()
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    assert root.get("viewBox") == "0 0 256 256"


def test_icon_png_is_256_square():
    header = ICON_PNG.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n" and header[12:16] == b"IHDR"
    assert struct.unpack(">II", header[16:24]) == (256, 256)
