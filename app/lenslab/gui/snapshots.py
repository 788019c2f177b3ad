"""Snapshots: renders kept to compare with the live one (A/B), and the comparison's state. No Qt here.

A :class:`Snapshot` keeps the picture as it was shown (RGBA8, with the view transform it was made through and the
camera's exposure on its radiance), the linear radiance behind it (so that a new view transform makes it again
exactly as the viewport does the live picture, and the readout still reads it), a copy of the camera and of the
mounted lens, the sample count, the time, and a name the user may give it. A :class:`SnapshotStore` holds the last :data:`MAX_SNAPSHOTS` of them within
:data:`MAX_BYTES`, oldest evicted first, which one is the A side, and how A meets the live picture (B): not at all,
a split wipe with a divider, or side by side. Observers (the snapshot dock, the viewport's comparison) connect to
``store.events`` and are told which part changed: ``"snapshots"``, ``"a"``, ``"mode"`` or ``"divider"``.

Snapshots live for the session: they are not saved with the scene.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from lenslab.optics import format_distance, format_f_number, format_focal_length
from lenslab.optics.exposure import format_shutter
from lenslab.colour_management.view import EXPOSURE_RANGE, ViewTransform
from lenslab.render.film import display_pixels, to_8bit
from lenslab.scene.events import EventEmitter

#: How a snapshot (A) meets the live picture (B) in the viewport.
COMPARE_MODES = ("off", "wipe", "side")
COMPARE_LABELS = {"off": "Off", "wipe": "Split Wipe", "side": "Side by Side"}
#: The store keeps at most this many snapshots ...
MAX_SNAPSHOTS = 12
#: ... and at most this many bytes of pictures (RGBA8 + float32 RGB: 16 bytes a pixel, about 6.8 MB for the
#: viewport's usual 800 x 533, 33 MB at 1920 x 1080); the oldest go first.
MAX_BYTES = 512 * 2**20


def camera_label(camera, samples_per_pixel: int | None = None) -> str:
    """What a photographer reads off a snapshot: ``"50 mm f/1.4, focus 2.10 m, 256 spp"`` (with the shutter and ISO
    in the physical exposure mode)."""
    aperture = "pinhole" if camera.pinhole else format_f_number(camera.f_number)
    parts = [f"{format_focal_length(camera.focal_length_mm)} {aperture}",
             f"focus {format_distance(camera.focus_distance_m)}"]
    if camera.exposure_mode == "physical":
        parts.append(f"{format_shutter(camera.shutter_s)} ISO {camera.iso:g}")
    elif camera.exposure_mode == "auto":
        parts.append(f"auto ISO {camera.iso:g}")
    if samples_per_pixel is not None:
        parts.append(f"{samples_per_pixel} spp")
    return ", ".join(parts)


def _settings(camera) -> list[tuple[str, str]]:
    """The settings that tell two pictures of a scene apart, each as (key, text), in the order a label lists them."""
    out = [("focal", format_focal_length(camera.focal_length_mm)),
           ("aperture", "pinhole" if camera.pinhole else format_f_number(camera.f_number)),
           ("focus", f"focus {format_distance(camera.focus_distance_m)}")]
    if camera.exposure_mode == "physical":
        out += [("shutter", format_shutter(camera.shutter_s)), ("iso", f"ISO {camera.iso:g}")]
    return out


def compare_tags(snapshot: Snapshot, live_camera) -> tuple[str, str]:
    """The tags of a comparison, naming what differs: ``("A: f/1.4", "B: live f/4")``. The aperture is named
    when nothing else tells them apart; a snapshot the user named is called by its name."""
    a, b = dict(_settings(snapshot.camera)), dict(_settings(live_camera))
    keys = [k for k, _text in _settings(live_camera) if a.get(k) != b.get(k)] or ["aperture"]
    a_text = snapshot.name or " ".join(a[k] for k in keys if k in a)
    b_text = " ".join(b[k] for k in keys if k in b)
    return f"A: {a_text}", f"B: live {b_text}"


@dataclass(eq=False)
class Snapshot:
    id: int
    display: np.ndarray  # (H, W, 4) uint8: the picture as it was shown
    view: ViewTransform  # the viewport's view transform ``display`` was made through
    linear: np.ndarray | None  # (H, W, 3) float32 radiance behind it; None: only the picture was there to keep
    camera: object  # a copy of the scene's camera when it was taken
    lens: object = None  # the lens preset mounted then (None: free)
    samples_per_pixel: int = 0
    taken: float = field(default_factory=time.time)  # seconds since the epoch
    name: str = ""  # the user's name for it; empty: the settings speak for it
    exposure_scale: float = 1.0  # the camera's exposure on ``linear`` when it was shown (physical, auto)
    _look: tuple = field(default=(), repr=False)  # (view, RGBA8) of the last other view asked for

    @property
    def size(self) -> tuple[int, int]:
        return self.display.shape[1], self.display.shape[0]

    @property
    def auto_label(self) -> str:
        return camera_label(self.camera, self.samples_per_pixel)

    @property
    def label(self) -> str:
        return self.name or self.auto_label

    @property
    def nbytes(self) -> int:
        return self.display.nbytes + (self.linear.nbytes if self.linear is not None else 0)

    def picture(self, view: ViewTransform) -> np.ndarray:
        """The snapshot as RGBA8 through the view transform ``view``: made again from its radiance, with its own
        camera exposure, as the viewport does the live picture (``lenslab.render.film.display_pixels``); the
        picture as taken when the view is its own or no radiance was kept."""
        if self.linear is None or view == self.view:
            return self.display
        if self._look and self._look[0] == view:
            return self._look[1]
        stops = view.exposure_stops + math.log2(max(self.exposure_scale, 1e-30))
        made = dataclasses.replace(view, exposure_stops=min(max(stops, EXPOSURE_RANGE[0]), EXPOSURE_RANGE[1]))
        rgba = np.empty(self.display.shape, np.uint8)
        rgba[..., :3] = to_8bit(display_pixels(self.linear, made))
        rgba[..., 3] = 255
        self._look = (view, rgba)
        return rgba


class SnapshotStore:
    """The session's snapshots, oldest first; which one is A; how A is compared with the live picture."""

    def __init__(self, max_count: int = MAX_SNAPSHOTS, max_bytes: int = MAX_BYTES):
        self.max_count = max_count
        self.max_bytes = max_bytes
        self.snapshots: list[Snapshot] = []
        self.events = EventEmitter()
        self.a_id: int | None = None
        self.mode = "off"
        self.divider = 0.5  # the split wipe's divider: a fraction of the picture's width, A to its left
        self.show_a = False  # the quick A/B toggle: A alone in place of the live picture
        self._ids = itertools.count(1)

    # -- the snapshots -----------------------------------------------------------------------------------------
    def take(self, display: np.ndarray, view: ViewTransform, linear: np.ndarray | None, camera,
             lens=None, samples_per_pixel: int = 0, name: str = "", exposure_scale: float = 1.0) -> Snapshot:
        """Keep a copy of a picture and what made it (``view``, and the camera's ``exposure_scale`` on its
        radiance), as the new A side; the oldest go beyond the cap."""
        if linear is not None and linear.shape[:2] != display.shape[:2]:
            linear = None  # radiance of another frame: the picture alone is true to what was shown
        snapshot = Snapshot(next(self._ids), np.array(display, np.uint8, copy=True), view,
                            None if linear is None else np.array(linear, np.float32, copy=True),
                            copy.deepcopy(camera), lens, int(samples_per_pixel), name=name,
                            exposure_scale=float(exposure_scale))
        self.snapshots.append(snapshot)
        self._evict(keep=snapshot)
        self.a_id = snapshot.id
        self.events.emit("snapshots")
        self.events.emit("a")
        return snapshot

    def _evict(self, keep: Snapshot) -> None:
        while len(self.snapshots) > 1 and (len(self.snapshots) > self.max_count or self.nbytes > self.max_bytes):
            oldest = next(s for s in self.snapshots if s is not keep)
            self.snapshots.remove(oldest)

    @property
    def nbytes(self) -> int:
        return sum(s.nbytes for s in self.snapshots)

    def get(self, snapshot_id: int | None) -> Snapshot | None:
        return next((s for s in self.snapshots if s.id == snapshot_id), None)

    def remove(self, snapshot_id: int) -> None:
        """Delete a snapshot; deleting A makes the newest remaining one A."""
        snapshot = self.get(snapshot_id)
        if snapshot is None:
            return
        self.snapshots.remove(snapshot)
        self.events.emit("snapshots")
        if self.a_id == snapshot_id:
            self.a_id = self.snapshots[-1].id if self.snapshots else None
            if self.a_id is None:
                self.show_a = False
            self.events.emit("a")

    def rename(self, snapshot_id: int, name: str) -> None:
        """Name a snapshot; an empty name (or its automatic label) gives it back its automatic label."""
        snapshot = self.get(snapshot_id)
        name = name.strip()
        if snapshot is None:
            return
        if name == snapshot.auto_label:
            name = ""
        if name != snapshot.name:
            snapshot.name = name
            self.events.emit("snapshots")
            if snapshot_id == self.a_id:
                self.events.emit("a")

    # -- the comparison ----------------------------------------------------------------------------------------
    @property
    def a(self) -> Snapshot | None:
        return self.get(self.a_id)

    def select(self, snapshot_id: int | None) -> None:
        """Make a snapshot the A side."""
        if snapshot_id != self.a_id and (snapshot_id is None or self.get(snapshot_id) is not None):
            self.a_id = snapshot_id
            if snapshot_id is None:
                self.show_a = False
            self.events.emit("a")

    def set_mode(self, mode: str) -> None:
        """Choose how A meets the live picture; choosing a mode ends the quick A/B toggle."""
        if mode not in COMPARE_MODES:
            raise ValueError(f"unknown compare mode {mode!r} (expected one of {', '.join(COMPARE_MODES)})")
        if mode != self.mode or self.show_a:
            self.mode = mode
            self.show_a = False
            self.events.emit("mode")

    def cycle_mode(self) -> None:
        self.set_mode(COMPARE_MODES[(COMPARE_MODES.index(self.mode) + 1) % len(COMPARE_MODES)])

    def toggle_a(self, on: bool | None = None) -> None:
        """Show A alone in place of the live picture, or the live picture (with the chosen mode) again."""
        on = (not self.show_a) if on is None else bool(on)
        on = on and self.a is not None
        if on != self.show_a:
            self.show_a = on
            self.events.emit("mode")

    def set_divider(self, fraction: float) -> None:
        fraction = min(1.0, max(0.0, float(fraction)))
        if fraction != self.divider:
            self.divider = fraction
            self.events.emit("divider")

    @property
    def view(self) -> str:
        """What the viewport shows: ``"off"`` (the live picture), ``"wipe"``, ``"side"``, or ``"a"`` (A alone)."""
        if self.a is None:
            return "off"
        return "a" if self.show_a else self.mode


__all__ = ["COMPARE_LABELS", "COMPARE_MODES", "MAX_BYTES", "MAX_SNAPSHOTS", "Snapshot", "SnapshotStore",
           "camera_label", "compare_tags"]
