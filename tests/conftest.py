"""Shared fixtures. GL tests run on whatever EGL gives (Mesa llvmpipe on CI); one context per test session."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


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


@pytest.fixture(scope="session")
def mitsuba():
    """Mitsuba 3's Python module with its comparison variant set, or a skip saying why it cannot render here."""
    pytest.importorskip("mitsuba", reason="Mitsuba 3 is not installed (pip install 'lenslab[validate]')")
    from lenslab.validate import mitsuba_env

    works, why = mitsuba_env.mitsuba_works()
    if not works:
        pytest.skip(why)
    return mitsuba_env.load_mitsuba()
