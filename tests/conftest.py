"""Shared fixtures. GL tests run on whatever EGL gives (Mesa llvmpipe on CI); one context per test session."""

from __future__ import annotations

import atexit
import builtins
import os
import shutil
import tempfile

import pytest

if not os.environ.get("QT_QPA_PLATFORM"):  # unset or empty (an empty value makes Qt abort)
    os.environ["QT_QPA_PLATFORM"] = "offscreen"

# Large scenes' kd-trees are kept on disk between runs (render/kdtree_cache.py): the tests keep theirs apart from
# the user's, for this session only.
if "LENSLAB_KDTREE_CACHE" not in os.environ:
    _trees = tempfile.mkdtemp(prefix="lenslab-test-kdtrees-")
    os.environ["LENSLAB_KDTREE_CACHE"] = _trees
    atexit.register(shutil.rmtree, _trees, True)


@pytest.fixture(scope="session")
def renderer():
    from lenslab.render.gl import GLUnavailable
    from lenslab.render.tracer import Renderer

    try:
        r = Renderer()
    except GLUnavailable as exc:  # CI installs Mesa; a developer without it gets a reason, not a failure
        pytest.skip(f"no OpenGL 4.3 context: {exc}")
    yield r
    r.release()


@pytest.hookimpl(tryfirst=True)  # before -m deselects: the marks must be on the items by then
def pytest_collection_modifyitems(config, items):
    """Every comparison with Mitsuba 3 is in the slow tier (the full validation, docs/testing.md), whichever file
    it is in: a test that asks for the ``mitsuba`` fixture is marked slow here."""
    for item in items:
        if "mitsuba" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="session")
def mitsuba():
    """Mitsuba 3's Python module with its comparison variant set, or a skip saying why it cannot render here."""
    pytest.importorskip("mitsuba", reason="Mitsuba 3 is not installed (pip install 'lenslab[validate]')")
    from lenslab.validate import mitsuba_env

    works, why = mitsuba_env.mitsuba_works()
    if not works:
        pytest.skip(why)
    return mitsuba_env.load_mitsuba()


@pytest.fixture
def hide_package(monkeypatch):
    """A function that makes a package (and its modules) fail to import for the rest of the test, as on a machine
    without it. Modules already imported stay in sys.modules; a test that needs them gone removes them itself."""
    real_import = builtins.__import__
    hidden: set[str] = set()

    def importing(name, *args, **kwargs):
        if name.split(".")[0] in hidden:
            raise ImportError(f"No module named '{name}'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", importing)
    return hidden.add
