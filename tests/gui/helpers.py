"""Helpers for the studio tests: waiting (never sleeps: each waits on a condition with a timeout) and the pointer.

The pointer's events are sent to the widget itself. ``qtbot.mouseMove`` moves the platform cursor instead, and on
the offscreen platform that move goes to whichever top-level window is under the global point (a window of an
earlier test not yet deleted will do), and a move to where the cursor already is sends nothing: hover tests that
used it failed now and then on a loaded machine."""

from __future__ import annotations

from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication


def send_mouse(widget, kind, pos, button=Qt.NoButton, buttons=Qt.NoButton, modifiers=Qt.NoModifier) -> None:
    """One mouse event of ``kind`` at widget position ``pos`` (a QPoint, QPointF or (x, y)), handled at once."""
    if not isinstance(pos, (QPointF,)):
        pos = QPointF(pos) if hasattr(pos, "x") else QPointF(*pos)
    event = QMouseEvent(kind, pos, widget.mapToGlobal(pos), button, buttons, modifiers)
    QApplication.sendEvent(widget, event)


def hover(widget, pos) -> None:
    """The pointer moved to ``pos`` over ``widget`` with no button held."""
    send_mouse(widget, QEvent.MouseMove, pos)


def press_drag_release(widget, start, end, button=Qt.LeftButton, modifiers=Qt.NoModifier) -> None:
    """A press at ``start``, one move to ``end`` with the button held, and the release there."""
    send_mouse(widget, QEvent.MouseButtonPress, start, button, button, modifiers)
    send_mouse(widget, QEvent.MouseMove, end, Qt.NoButton, button, modifiers)
    send_mouse(widget, QEvent.MouseButtonRelease, end, button, Qt.NoButton, modifiers)


def wait_for_frame(qtbot, window, min_spp: int = 1, generation: int | None = None, timeout: int = 20000):
    """Wait until the viewport shows a frame with at least ``min_spp`` samples (of ``generation`` if given)."""

    def ready():
        frame = window.controller.last_frame
        assert frame is not None and not frame.preview
        assert frame.samples_per_pixel >= min_spp
        if generation is not None:
            assert frame.generation >= generation

    qtbot.waitUntil(ready, timeout=timeout)
    return window.controller.last_frame


def wait_for_gbuffer(qtbot, window, timeout: int = 20000):
    def ready():
        g = window.viewport.gbuffer
        assert g is not None and g.generation >= window.tools.structure_generation

    qtbot.waitUntil(ready, timeout=timeout)
    return window.viewport.gbuffer


def cpu_depth(scene, u: float, v: float) -> tuple[float, int]:
    """Ground truth for click-to-focus, independent of the GPU: the pinhole ray through image point (u, v)
    intersected with every triangle and sphere in numpy. Returns (depth along the view axis, node index)."""
    import numpy as np

    flat = scene.flatten()
    cam = scene.camera
    # The pinhole ray written out here, not asked of the camera under test: tan(fov_x / 2) = w / 2f, the
    # image's height a cut of the sensor's width.
    right, up, back = cam.basis()
    tan_x = cam.sensor_mm[0] / (2 * cam.focal_length_mm)
    tan_y = tan_x * cam.resolution[1] / cam.resolution[0]
    d = (2 * u - 1) * tan_x * right + (1 - 2 * v) * tan_y * up - back
    d /= np.linalg.norm(d)
    o = np.asarray(cam.position, float)
    best_t, best_prim = np.inf, -1
    tri = flat.triangles.astype(float)
    if len(tri):
        e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = o - tri[:, 0]
        bu = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        bv = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (bu >= 0) & (bv >= 0) & (bu + bv <= 1) & (t > 1e-6)
        if hit.any():
            i = int(np.argmin(np.where(hit, t, np.inf)))
            best_t, best_prim = float(t[i]), i
    for j, (cx, cy, cz, r) in enumerate(flat.spheres.astype(float)):
        oc = o - (cx, cy, cz)
        b = float(oc @ d)
        disc = b * b - (float(oc @ oc) - r * r)
        if disc >= 0:
            for t in (-b - disc**0.5, -b + disc**0.5):
                if 1e-6 < t < best_t:
                    best_t, best_prim = t, len(tri) + j
                    break
    if best_prim < 0:
        return np.inf, -1
    forward = -cam.basis()[2]
    return best_t * float(d @ forward), int(flat.prim_node[best_prim])
