"""How soon the studio itself shows an edit: the real main window, its render thread, its signals and its
viewport, at the size it opens at, with the denoiser on as it starts (docs/studio.md, "A clean picture after
every edit"). benchmarks/edit_to_clean.py times the render loop alone and judges each picture against a
converged one; this times what a photographer waits for in the window, Qt and all.

Each edit is made as the camera panel makes it (an undo step on the document); the clock runs from the edit to
the moment the window has taken each picture of it (the viewport's picture set, the tags and status updated;
the paint follows in the same turn of the event loop). Printed per edit: the first picture of it (and whether
it was the denoised quarter-resolution preview), the first full-resolution denoised picture, and how many raw
(not denoised) pictures of it were shown, which must be none.

Run with a display or Qt's offscreen platform:
    QT_QPA_PLATFORM=offscreen python benchmarks/studio_edit_latency.py [--scene cornell_box] [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time

from PySide6.QtCore import QEventLoop, QSettings

from lenslab.gui.app import create_application
from lenslab.gui.main_window import MainWindow
from lenslab.scene.io.loader import open_scene

EDITS = {
    "f-number x2": lambda c: {"f_number": c.f_number * 2},
    "focus -20%": lambda c: {"focus_distance_m": round(c.focus_distance_m * 0.8, 4)},
    "focal length +20%": lambda c: {"focal_length_mm": c.focal_length_mm * 1.2},
}


def run_until(app, done, seconds: float) -> bool:
    """Turn the event loop until ``done()`` or ``seconds`` pass; whether it was done."""
    end = time.perf_counter() + seconds
    while not done():
        if time.perf_counter() > end:
            return False
        app.processEvents(QEventLoop.AllEvents, 5)
    return True


def time_one_edit(app, window, seen: list, edit, seconds: float) -> tuple[float, str, float, int]:
    """Make ``edit()`` and wait for its first full-resolution denoised picture: the seconds to its first picture,
    which kind that was, the seconds to the full-resolution one, and how many raw pictures of it were shown."""
    seen.clear()
    edited = time.perf_counter()
    edit()
    generation = window.controller.generation

    def pictures() -> list:
        return [(t, f) for t, f in seen if f.generation >= generation]

    if not run_until(app, lambda: any(not f.preview and f.denoised for _, f in pictures()), seconds):
        raise SystemExit(f"no full-resolution picture within {seconds:g} s of an edit")
    shown = pictures()
    t, first = shown[0]
    kind = "denoised preview" if first.preview and first.denoised else "denoised" if first.denoised else "raw"
    full = next(t for t, f in shown if not f.preview and f.denoised)
    return t - edited, kind, full - edited, sum(1 for _, f in shown if not f.denoised)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="cornell_box")
    parser.add_argument("--repeat", type=int, default=3, help="times each edit is made (and undone)")
    parser.add_argument("--seconds", type=float, default=15.0, help="the longest wait for a picture")
    args = parser.parse_args()

    app = create_application()
    settings = QSettings(tempfile.NamedTemporaryFile(suffix=".ini", delete=False).name, QSettings.IniFormat)
    settings.setValue("viewport/denoise", True)
    window = MainWindow(open_scene(args.scene), settings=settings, restore_layout=False)
    window.show()
    controller = window.controller
    seen: list[tuple[float, object]] = []
    controller.frame_ready.connect(lambda frame: seen.append((time.perf_counter(), frame)))

    def settled() -> bool:  # every kernel compiled, the denoiser loaded, the picture whole
        frame = controller.last_frame
        return (frame is not None and frame.generation >= controller.generation and not frame.preview
                and frame.denoised and frame.samples_per_pixel >= 2)

    start = time.perf_counter()
    if not run_until(app, settled, 600):
        raise SystemExit("the studio did not settle within 10 minutes")
    w, h = controller.size
    device = (controller.device or {}).get("renderer", "?")
    print(f"{args.scene}: the window at {window.width()} x {window.height()}, the viewport's picture {w} x {h}; "
          f"{device}; settled {time.perf_counter() - start:.1f} s after opening")
    print("| edit | first picture (median) | which | full resolution, denoised (median) | raw pictures shown |")
    print("|---|---:|---|---:|---:|")
    for name, change in EDITS.items():
        firsts, fulls, kinds, raw = [], [], set(), 0
        for _ in range(args.repeat):
            # The edit, then its undo: both are edits the photographer waits for.
            for edit in (lambda: window.doc.set_camera(**change(window.doc.scene.camera)), window.doc.undo_stack.undo):
                first, kind, full, raw_shown = time_one_edit(app, window, seen, edit, args.seconds)
                firsts.append(first)
                kinds.add(kind)
                fulls.append(full)
                raw += raw_shown
                run_until(app, lambda: False, 0.5)  # let it sample on a moment, as between two edits
        print(f"  {name}: first pictures at " + ", ".join(f"{t:.2f}" for t in firsts) + " s", file=sys.stderr)
        print(f"| {name} | {statistics.median(firsts):.2f} s ({min(firsts):.2f} to {max(firsts):.2f}) | "
              f"{', '.join(sorted(kinds))} | {statistics.median(fulls):.2f} s ({min(fulls):.2f} to {max(fulls):.2f}) "
              f"| {raw} |", flush=True)
    window.doc.undo_stack.setClean()
    window.close()


if __name__ == "__main__":
    main()
