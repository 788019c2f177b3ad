"""The viewport's work banner: whenever the picture on screen does not show the latest edit yet, a line over it
says so, what is under way (a scene's load step by step, a kernel compiling, the preview, the first pass) and
how far along, so that a new label over an old picture never passes for the truth.

The render worker reports its work as WorkNotes (gui/render_loop.py); whether the picture is current is the
controller's to say (``RenderController.picture_is_current``). The banner looks at both a few times a second and
stays away during the first BANNER_DELAY_SECONDS of an edit, so a drag, whose pictures follow within a fraction
of a second, does not flicker with it. A scene still loading dims the last scene's picture: it is another scene.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from PySide6.QtCore import QObject, QRectF, Qt, QTimer
from PySide6.QtGui import QColor, QPainter

from lenslab.gui import theme
from lenslab.gui.corner_tags import BANNER

BANNER_DELAY_SECONDS = 0.25
POLL_MS = 100
STARTING_TEXT = "Starting the renderer…"


@dataclass(frozen=True)
class BannerState:
    """What the banner needs to know, gathered from the controller (plain values, for tests)."""

    current: bool  # the picture shows the latest edit
    stale_seconds: float  # how long since that edit, while the picture does not show it
    has_picture: bool
    preview: bool  # the picture is the low-resolution preview of the latest edit
    new_scene: bool  # a whole other scene is on its way (its picture would be another scene's)
    paused: bool
    note: object = None  # the latest WorkNote for an edit the picture does not show, or None
    snapshot_alone: bool = False  # a snapshot is shown in place of the live picture (A of the A/B): its tags say so


def banner_text(state: BannerState) -> str | None:
    """The banner's line, or None for no banner."""
    if (state.current and not state.preview) or state.snapshot_alone:
        return None
    if state.has_picture and not state.preview and state.stale_seconds < BANNER_DELAY_SECONDS:
        return None
    if state.paused:
        return "Paused: the picture shows the settings before the last edit"
    note = state.note
    what = ""
    if note is not None:
        what = note.stage
        if note.steps:
            what += f" (step {note.step} of {note.steps})"
        if note.fraction is not None:
            what += f" {100 * note.fraction:.0f}%"
    if state.preview:
        head = "Preview at ¼ resolution"
        what = what if what and note.stage == "first pass" else "full resolution under way"
    elif state.new_scene:
        head = "Opening the scene"
    else:
        head = "Updating the picture"
    line = f"{head}: {what}" if what else f"{head}…"
    if state.stale_seconds >= 1.0:
        line += f" · {state.stale_seconds:.0f} s"
    return line


class WorkBanner(QObject):
    """A viewport layer (``viewport.layers``) drawing ``banner_text`` at the top of the picture, with a bar for
    the fraction done where it is known; before the first picture, the viewport's waiting text."""

    visible = True

    def __init__(self, viewport, controller, parent: QObject | None = None):
        super().__init__(parent)
        self.viewport = viewport
        self.controller = controller
        self.text: str | None = None
        self.fraction: float | None = None
        self.dim = False
        self._stale_since: float | None = None  # when the latest edit the picture does not show was made
        self._stale_generation: int | None = None  # that edit's generation
        self._timer = QTimer(self)
        self._timer.setInterval(POLL_MS)
        self._timer.timeout.connect(self.refresh)
        self._timer.start()
        controller.frame_ready.connect(lambda _frame: self.refresh())
        controller.working.connect(lambda _note: self.refresh())
        viewport.layers.append(self)

    def state(self) -> BannerState:
        c = self.controller
        frame = c.last_frame
        current = c.picture_is_current
        now = time.perf_counter()
        if current:
            self._stale_since = self._stale_generation = None
        elif self._stale_generation != c.generation:  # the seconds count from the newest edit, not an older one
            self._stale_since, self._stale_generation = now, c.generation
        stale = 0.0 if self._stale_since is None else now - self._stale_since
        note = c.work_note
        if note is not None and frame is not None and note.generation <= frame.generation and not frame.preview:
            note = None  # about a picture already shown
        if note is not None and note.generation < c.scene_generation:
            note = None  # about the scene before the one opening
        return BannerState(
            current=current, stale_seconds=stale, has_picture=frame is not None,
            preview=frame is not None and frame.preview and frame.generation >= c.generation,
            new_scene=frame is None or c.scene_generation > frame.generation,
            paused=c.paused and not current, note=note,
            snapshot_alone=self.viewport.compare is not None and self.viewport.compare.shows_a_alone())

    def refresh(self) -> None:
        state = self.state()
        text = banner_text(state)
        note = state.note
        fraction = note.fraction if note is not None else None
        if note is not None and note.steps and fraction is None:
            fraction = (note.step - 1) / note.steps
        dim = text is not None and state.new_scene and state.has_picture
        if (text, fraction, dim) != (self.text, self.fraction, self.dim):
            self.text, self.fraction, self.dim = text, fraction, dim
            self.viewport.idle_text = text or STARTING_TEXT
            self.viewport.update()

    def paint(self, p: QPainter, viewport, image_rect: QRectF) -> None:
        if self.text is None:
            return
        if self.dim:
            p.fillRect(image_rect, QColor(0, 0, 0, 110))
        metrics = p.fontMetrics()
        width = min(metrics.horizontalAdvance(self.text) + 24, max(120.0, viewport.width() - 16.0))
        height = metrics.height() + 12
        top = max(4.0, image_rect.top() + 36)
        box = QRectF(viewport.width() / 2 - width / 2, top, width, height)
        viewport.tags.reserve(box, BANNER)  # the less important tags give way (a sensor's size, a focus plane's)
        p.setPen(Qt.NoPen)
        p.setBrush(QColor(20, 20, 22, 215))
        p.drawRoundedRect(box, 4, 4)
        if self.fraction is not None:
            p.setBrush(QColor(theme.ACCENT))
            p.drawRect(QRectF(box.left() + 4, box.bottom() - 4, (box.width() - 8) * min(1.0, self.fraction), 2))
        p.setPen(QColor("#f0f0f0"))
        text = metrics.elidedText(self.text, Qt.ElideRight, int(box.width() - 16))
        p.drawText(box.adjusted(8, 0, -8, -2), Qt.AlignCenter, text)
