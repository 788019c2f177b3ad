"""A wheel carries the shaders, scenes and presets, and renders from any working directory."""

from __future__ import annotations

import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    result = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(out), str(ROOT)],
        capture_output=True, text=True, timeout=300,
    )
    assert result.returncode == 0, result.stderr
    (path,) = out.glob("lenslab-*.whl")
    return path


def test_wheel_ships_shaders_scenes_and_presets(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    assert "lenslab/glsl/trace.comp" in names and "lenslab/glsl/bsp.glsl" in names
    assert "lenslab/scenes/cornell_box/scene.json" in names and "lenslab/scenes/dof_chart/scene.json" in names
    assert any(n.startswith("lenslab/presets/lenses/") for n in names)
    entry_points = next(n for n in names if n.endswith("entry_points.txt"))
    assert "lenslab = lenslab.cli:main" in zipfile.ZipFile(wheel).read(entry_points).decode()


@pytest.mark.slow
def test_wheel_in_a_fresh_virtualenv_renders_from_any_directory(renderer, wheel, tmp_path):
    venv = tmp_path / "fresh"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    python = venv / "bin" / "python"
    site = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    # The fresh environment borrows this one's third-party packages (numpy, moderngl, ...) but not LensLab:
    # a path listed in a .pth file is not itself scanned for .pth files, so the editable install stays out.
    (site / "borrowed_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(site), str(wheel)],
                   check=True, timeout=300, capture_output=True)
    elsewhere = tmp_path / "somewhere" / "else"
    elsewhere.mkdir(parents=True)
    code = (
        "import sys, lenslab; from pathlib import Path; "
        f"assert Path(lenslab.__file__).is_relative_to({str(site)!r}), lenslab.__file__; "
        "from lenslab.cli import main; "
        "sys.exit(main(['cornell_box', '--headless', '-o', 'out.png', '--spp', '1', '--width', '16', '--height', '16']))"
    )
    result = subprocess.run([str(python), "-c", code], cwd=elsewhere, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert (elsewhere / "out.png").is_file()


def _declared_closure() -> set[str]:
    """The distributions a plain ``pip install lenslab`` brings: pyproject's dependencies and, recursively,
    what each of them requires without extras."""
    import importlib.metadata as metadata
    import re

    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    def name(requirement: str) -> str:
        return re.split(r"[\s\[<>=!~;(]", requirement.strip(), maxsplit=1)[0].lower().replace("_", "-")

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    pending = [name(r) for r in project["dependencies"] if "python_version" not in r or sys.version_info < (3, 11)]
    closure: set[str] = set()
    while pending:
        dist = pending.pop()
        if dist in closure:
            continue
        closure.add(dist)
        try:
            requires = metadata.requires(dist) or []
        except metadata.PackageNotFoundError:
            continue
        pending += [name(r) for r in requires if "extra ==" not in r]
    return closure


@pytest.mark.slow
def test_a_plain_install_declares_every_package_a_render_imports(tmp_path):
    """What trimesh imports for smooth normals (scipy) is nowhere in its own requirements: without it in ours,
    a plain install printed 'unable to use sparse matrix' and a ModuleNotFoundError on product_shot."""
    code = (
        "import sys, json, importlib.metadata as md; from lenslab.cli import main; "
        "status = main(['product_shot', '--headless', '-o', 'p.png', '--spp', '1', '--width', '8', '--height', '8']); "
        "owners = md.packages_distributions(); "
        "print(json.dumps(sorted({d for m in list(sys.modules) for d in owners.get(m.split('.')[0], [])})))"
    )
    result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    import json

    imported = {d.lower().replace("_", "-") for d in json.loads(result.stdout.strip().splitlines()[-1])}
    undeclared = imported - _declared_closure() - {"lenslab", "pip", "setuptools", "pytest", "pytest-qt"}
    assert not undeclared, f"imported by a render but not brought by a plain install: {sorted(undeclared)}"
