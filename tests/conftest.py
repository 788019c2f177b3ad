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
