"""Moving the camera from the viewport: the mouse gestures of lenslab.scene.navigation turned into undo steps.

A gesture (press, drag, release) is one step in the History, however many pictures it made on the way: each
move replaces the camera the gesture started from by a new one, and the commands of one gesture merge. The
gesture turns about the selection's centre when something is selected, else about the plane of focus on the view
axis. Frame Selection is a step of its own.
"""

from __future__ import annotations

import copy
import itertools

import numpy as np
from PySide6.QtCore import QObject

from lenslab.gui.commands import SetValuesCommand
from lenslab.scene import navigation
from lenslab.scene.editable import CAMERA

_GESTURE_ID = 1002
_GESTURE_NAMES = {"orbit": "Orbit camera", "pan": "Pan camera", "dolly": "Dolly camera"}
WHEEL_DOLLY_PIXELS = 30.0  # a wheel step dollies as far as this much vertical drag


class CameraGestureCommand(SetValuesCommand):
    """A camera move; the commands of one gesture merge into one step, whatever time passes between them."""

    def __init__(self, doc, changes: dict, text: str, gesture: int):
        super().__init__(doc, CAMERA, {(k,): v for k, v in changes.items()}, text, merge=True)
        self.gesture = gesture

    def id(self) -> int:
        return _GESTURE_ID

    def mergeWith(self, other) -> bool:
        if not isinstance(other, CameraGestureCommand) or other.gesture != self.gesture:
            return False
        self.new = other.new
        if self.new == self.old:
            self.setObsolete(True)
        return True


class CameraNavigator(QObject):
    """Connects a Viewport's navigation signals to the document's camera."""

    def __init__(self, doc, viewport, view_frame, parent=None):
        """``view_frame()`` gives the CameraFrame of the picture on screen (for how far a pixel pans)."""
        super().__init__(parent)
        self.doc = doc
        self.viewport = viewport
        self.view_frame = view_frame
        self._gestures = itertools.count(1)
        self._gesture: int | None = None
        self._start_camera = None
        self._pivot: np.ndarray | None = None
        self._wheel_gesture: int | None = None
        self._wheel_selection: np.ndarray | None = None  # the selection's centre, found once a run of notches
        viewport.navigation_started.connect(self.start)
        viewport.navigation_moved.connect(self.move)
        viewport.navigation_finished.connect(self.finish)
        viewport.dolly_wheel.connect(self.wheel)

    def start(self, kind: str, _pixel=None) -> None:
        self._gesture = next(self._gestures)
        # A copy, not the document's camera: each move of the gesture edits that one in place, and every move
        # must be worked out from the camera the gesture began with, or the moves would compound.
        self._start_camera = copy.deepcopy(self.doc.scene.camera)
        self._pivot = navigation.gesture_pivot(self._start_camera, self._selection_centre())
        self._wheel_gesture = None

    def move(self, kind: str, dx: float, dy: float) -> None:
        """The gesture has gone (dx, dy) widget pixels from where it started."""
        camera = self._start_camera
        if camera is None:
            return
        if kind == "orbit":
            changes = navigation.orbit(camera, dx, dy, self._pivot)
        elif kind == "dolly":
            changes = navigation.dolly(camera, dy, self._pivot)
        else:
            frame = self.view_frame()
            # Widget pixels to picture pixels, then to metres in the plane of the pivot.
            per_pixel = navigation.pan_metres_per_pixel(camera, frame.width, frame.tan_half_fov[0], self._pivot)
            per_pixel /= max(self.viewport.scale(), 1e-6)
            changes = navigation.pan(camera, dx * per_pixel, dy * per_pixel)
        self._push(changes, _GESTURE_NAMES[kind], self._gesture)

    def finish(self) -> None:
        self._gesture = None
        self._start_camera = None
        self._pivot = None

    def wheel(self, steps: float) -> None:
        """Ctrl + wheel: a dolly by a fixed share of the distance to the pivot a notch; the wheel steps that
        follow one another make one step in the History."""
        command = self.doc.undo_stack.command(self.doc.undo_stack.index() - 1)
        if not (isinstance(command, CameraGestureCommand) and command.gesture == self._wheel_gesture):
            self._wheel_gesture = next(self._gestures)
            self._wheel_selection = self._selection_centre()
        camera = self.doc.scene.camera
        centre = navigation.gesture_pivot(camera, self._wheel_selection)
        changes = navigation.dolly(camera, -steps * WHEEL_DOLLY_PIXELS, centre)
        self._push(changes, "Dolly camera", self._wheel_gesture)

    def selection_bounds(self, paths: list[tuple]) -> tuple[np.ndarray, np.ndarray] | None:
        """The world box (lower, upper) around the objects at ``paths`` and everything under them (everything
        when ``paths`` is empty); None when that holds nothing to see."""
        flat = self.doc.scene.flatten()
        if flat.prim_count == 0:
            return None
        boxes = flat.prim_bounds()
        if paths:
            indices = np.asarray([i for p in paths for i in self.doc.model.subtree_indices(p)], np.int32)
            boxes = boxes[np.isin(flat.prim_node, indices)]
            if len(boxes) == 0:
                return None
        return boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)

    def _selection_centre(self) -> np.ndarray | None:
        """The centre of the selected objects' box, or None when no object is selected."""
        paths = self.doc.selected_node_paths()
        bounds = self.selection_bounds(paths) if paths else None
        return None if bounds is None else (bounds[0] + bounds[1]) / 2.0

    def frame_selection(self, paths: list[tuple]) -> bool:
        """Point the camera at the selection (or everything), back off until it fills the frame and focus on it;
        False when there is nothing to frame."""
        bounds = self.selection_bounds(paths)
        if bounds is None:
            return False
        lower, upper = bounds
        camera = self.doc.scene.camera
        changes = navigation.frame_bounds(camera, lower, upper)
        # What is framed is also focused on: the focus lands on the box's centre.
        distance = float(np.linalg.norm(np.subtract(changes["look_at"], changes["position"])))
        try:
            setting = round(camera.focus_setting_for(distance), 4)
            if setting >= camera.closest_focus_with(self.doc.lens):  # the camera's own check, lens and all
                changes["focus_distance_m"] = setting
        except ValueError:
            pass
        self._push(changes, "Frame selection" if paths else "Frame all", next(self._gestures))
        return True

    def _push(self, changes: dict, text: str, gesture: int) -> None:
        camera = self.doc.scene.camera
        changes = {k: v for k, v in changes.items() if getattr(camera, k) != v}
        if changes:
            self.doc.push(CameraGestureCommand(self.doc, changes, text, gesture))
