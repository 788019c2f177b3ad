"""The layers of docs/architecture.md hold: import-linter checks every contract in pyproject.toml's
[tool.importlinter] against the package's imports, lazy imports inside functions included.

One test per contract, so a failure names the contract that broke and prints the linter's report: the import
chains that break it, with their line numbers. The same check from a shell: `lint-imports` in the repository.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib  # a dependency of lenslab below Python 3.11

REPO = Path(__file__).resolve().parents[1]
PYPROJECT = REPO / "pyproject.toml"


def _contracts() -> list[dict]:
    with PYPROJECT.open("rb") as f:
        return tomllib.load(f)["tool"]["importlinter"]["contracts"]


def _lint_imports() -> str:
    """The linter's console script, from the environment that runs the tests (the dev extras install it)."""
    script = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    if script is None:
        pytest.fail("lint-imports is not installed: pip install -e '.[dev]' installs import-linter")
    return script


def test_every_contract_has_an_id():
    """The tests below select contracts by id; an id-less contract would go unchecked here."""
    contracts = _contracts()
    assert contracts, "pyproject.toml has no [[tool.importlinter.contracts]]"
    ids = [contract.get("id") for contract in contracts]
    assert all(ids), f"every contract needs an id: {[c['name'] for c in contracts if not c.get('id')]}"
    assert len(set(ids)) == len(ids), f"contract ids repeat: {ids}"


@pytest.mark.parametrize("contract", _contracts(), ids=lambda contract: contract.get("id", "?"))
def test_contract_is_kept(contract):
    result = subprocess.run(
        # In the repository the linter reads pyproject.toml (--config is deprecated in recent import-linter, and
        # what replaces it is missing from 2.1); no cache written into the checkout.
        [_lint_imports(), "--contract", contract["id"], "--no-cache"],
        cwd=REPO,
        env={**os.environ, "COLUMNS": "160"},  # the report's lines unwrapped
        capture_output=True,
        text=True,
        timeout=300,
    )
    report = result.stdout + result.stderr
    assert result.returncode == 0, f"import-linter: contract {contract['name']!r} is broken:\n{report}"
    assert "KEPT" in report, f"import-linter checked nothing:\n{report}"
