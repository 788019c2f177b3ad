"""What the pointer does over the viewport: the tool in use, the readout under the cursor (pixel, radiance,
luminance, depth, object), click to select, click to focus (and the held preview of the plane of focus), the
render region drawn, focus on the selection, and the zone of sharpness drawn on the picture."""

from __future__ import annotations

import dataclasses
import math

from PySide6.QtCore import QObject, Qt
from PySide6.QtWidgets import QLabel, QMainWindow

from lenslab.colour_management.working_space import luminance
from lenslab.optics import format_distance
from lenslab.scene import editing


class ViewportTools(QObject):
    """The viewport's tools for the window (its document, viewport, controller and camera panel; its status bar
    the messages'), and the readout below the picture (``readout``).

    ``structure_generation`` is the render generation of the last edit of the scene's tree: a depth buffer older
    than it numbers the nodes as they were, so clicks and focus do not trust its node numbers."""

    def __init__(self, window: QMainWindow):
        super().__init__(window)
        self.window = window
        self.structure_generation = 0
        # Where the spot meter reads: the point last clicked with the focus tool, as fractions of the frame (the
        # sensor's gate), as a camera's spot meter follows its focus point; the frame's centre until then.
        self.meter_spot = (0.5, 0.5)
        self._hover: tuple[int, int] | None = None
        self.readout = QLabel(" ")
        self.readout.setObjectName("readout")
        self.readout.setContentsMargins(8, 2, 8, 2)
        self.readout.setTextFormat(Qt.RichText)

    def _status(self, text: str, ms: int) -> None:
        self.window.statusBar().showMessage(text, ms)

    def set_tool(self, tool: str) -> None:
        self.window.actions["tool_" + tool].setChecked(True)
        self.window.viewport.set_tool(tool)
        hints = {"select": "Select: click an object in the picture; Shift adds to the selection.",
                 "focus": "Focus: click a point to focus there; hold the button to preview the plane of focus.",
                 "pan": "Pan: drag the picture; the wheel zooms.",
                 "region": "Render region: drag a rectangle to refine only it; Alt+R renders everything again."}
        self._status(hints[tool], 4000)

    # -- the readout -----------------------------------------------------------------------------------------------
    def show_readout(self, xy) -> None:
        """The readout for image pixel ``xy`` under the cursor (None: off the picture)."""
        self._hover = xy
        viewport, model = self.window.viewport, self.window.doc.model
        image = viewport.linear
        if xy is None or image is None:
            self.readout.setText(" ")
            return
        x, y = xy
        h, w = image.shape[:2]
        if not (0 <= x < w and 0 <= y < h):
            self.readout.setText(" ")
            return
        r, g, b = (float(c) for c in image[y, x])
        lum = luminance((r, g, b), self.window.doc.scene.render.working_space)
        parts = [f"x {x}  y {y}",
                 f"<span style='color:#e06c6c'>R</span> {r:.4f}  <span style='color:#7fc56b'>G</span> {g:.4f}  "
                 f"<span style='color:#6b9be0'>B</span> {b:.4f}",
                 f"L {lum:.4f} ({math.log2(lum / 0.18):+.1f} EV from mid grey)" if lum > 0 else "L 0"]
        depth = viewport.depth_at(x, y)
        if math.isfinite(depth):
            parts.append(f"depth {format_distance(depth)}")
        index = viewport.node_at(x, y)
        paths = model.node_paths()
        if 0 <= index < len(paths):
            parts.append(model.node(paths[index]).name)
        self.readout.setText("   ·   ".join(parts))

    def refresh_readout(self, _frame=None) -> None:
        """A new picture: the readout reads it where the cursor still is."""
        if self._hover is not None:
            self.show_readout(self._hover)

    # -- click to select -------------------------------------------------------------------------------------------
    def node_clicked(self, index: int, add: bool) -> None:
        doc = self.window.doc
        g = self.window.viewport.gbuffer
        paths = doc.model.node_paths()
        if g is not None and g.generation < self.structure_generation:
            return  # the picture's node numbers predate an edit of the tree
        target = [("node", paths[index])] if 0 <= index < len(paths) else []
        if add:
            current = list(doc.selection)
            for t in target:
                if t in current:
                    current.remove(t)
                else:
                    current.append(t)
            doc.set_selection(current)
        else:
            doc.set_selection(target)

    # -- the render region -----------------------------------------------------------------------------------------
    def region_drawn(self, region) -> None:
        self.window.controller.set_region(region)
        self._status("Refining the render region; Alt+R renders the whole picture again.", 5000)

    # -- focus -----------------------------------------------------------------------------------------------------
    def focus_clicked(self, u: float, v: float) -> None:
        self.window.controller.pick(u, v, self._focus_answered)
        self.set_meter_spot(*self.frame_fraction(u, v))

    def frame_fraction(self, u: float, v: float) -> tuple[float, float]:
        """Image point (u, v) of the viewport's picture as fractions of the frame (the sensor's gate) it shows."""
        viewport = self.window.viewport
        w, h = viewport.image_size()
        gate = viewport.gate_rect
        if gate is None or w <= 0 or h <= 0 or gate.width() <= 0 or gate.height() <= 0:
            return min(max(u, 0.0), 1.0), min(max(v, 0.0), 1.0)
        x = (u * w - gate.x()) / gate.width()
        y = (v * h - gate.y()) / gate.height()
        return min(max(x, 0.0), 1.0), min(max(y, 0.0), 1.0)

    def set_meter_spot(self, x: float, y: float) -> None:
        """The spot meter reads at (x, y), fractions of the frame from its top left."""
        self.meter_spot = (float(x), float(y))
        self.window.controller.set_meter_spot(*self.meter_spot)

    def _focus_answered(self, result) -> None:
        self.window.viewport.focus_pending = False
        if not result.hit:
            self.window.viewport.hide_focus_overlay()
            self._status("Nothing there to focus on: that is the background.", 4000)
            return
        model = self.window.doc.model
        paths = model.node_paths()
        name = model.node(paths[result.node_index]).name if 0 <= result.node_index < len(paths) else "surface"
        camera = self.window.doc.scene.camera
        # The pick's depth is from the lens; the camera's focus reading may be from the sensor.
        if camera.focus_from == "sensor" and result.depth <= camera.focal_length_mm / 1000:
            self._status(f"{name} is nearer than any lens focuses", 4000)
            return
        setting = round(camera.focus_setting_for(float(result.depth)), 4)
        if self.window.camera_panel.set_focus(setting, text=f"Focus on {name} ({format_distance(setting)})"):
            self._status(f"Focused on {name} at {format_distance(setting)}", 4000)

    def focus_preview(self, depth: float) -> None:
        self.show_focus_overlay(depth, hold=True)

    def focus_on_selection(self) -> None:
        doc = self.window.doc
        paths = doc.selected_node_paths()
        if not paths:
            return
        g = self.window.viewport.gbuffer
        fresh = g is not None and g.generation >= self.structure_generation  # its node numbers are today's
        distance = editing.focus_distance_for(doc.model, paths, g if fresh else None)
        if distance is None:
            self._status("The selection is behind the camera, or nearer than the lens focuses", 4000)
            return
        name = doc.model.node(paths[0]).name
        self.window.camera_panel.set_focus(distance, text=f"Focus on {name}")

    def show_focus_overlay(self, depth: float, hold: bool = False) -> None:
        """The zone of sharpness on the picture, were the plane of focus ``depth`` ahead of the lens (the depth
        buffer's distances)."""
        cam = self.window.doc.scene.camera
        if cam.focus_from == "sensor" and depth <= cam.focal_length_mm / 1000 * 1.0001:
            return
        try:
            trial = dataclasses.replace(cam, focus_distance_m=cam.focus_setting_for(max(depth, 1e-3)))
            dof = trial.depth_of_field(*cam.resolution, self.window.camera_panel.light_fraction(), reference="lens")
        except ValueError:  # nearer than the lens can focus: no zone to show
            return
        self.window.viewport.show_focus_overlay(depth, dof.near_m, dof.far_m, hold)

    def refresh_focus_overlay(self, _gbuffer=None) -> None:
        """A new depth buffer: the zone of sharpness, while it shows, is drawn from it."""
        if self.window.viewport.overlay_visible():
            self.show_focus_overlay(self.window.doc.scene.camera.plane_of_focus_m)

    # -- the picture's size on screen ----------------------------------------------------------------------------
    def frame_height_on_screen(self) -> float:
        """The export frame's height as the viewport draws it, in screen pixels (0 before the first picture):
        what the camera's frame spans at an object's depth is spread over this many pixels."""
        viewport = self.window.viewport
        gate = viewport.gate_rect
        height = gate.height() if gate is not None else viewport.image_size()[1]
        return height * viewport.scale()


__all__ = ["ViewportTools"]
