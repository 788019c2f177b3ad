"""The studio: LensLab's PySide6 desktop application. The only layer of LensLab that imports Qt.

Modules, one job each:

* :mod:`.app`          - ``run_studio``: the QApplication, theme, and the window from the command line
* :mod:`.main_window`  - the window's assembly: the viewport, docks, menus and status bar, wired together
* :mod:`.actions`      - every action and the menus, declared as data (text, shortcut, handler, enabled-when)
* :mod:`.file_controller` - new, open, save, recent files, mesh import, drag and drop
* :mod:`.export_flow`  - the export dialog, progress, cancel and the result
* :mod:`.edit_controller` - the edits of the Edit menu: add, duplicate, delete, rename
* :mod:`.viewport_toolbar` - the viewport's toolbar: tools, zoom, display exposure and tone map, resolution, limit
* :mod:`.viewport_tools` - the pointer over the picture: readout, click to select, click to focus, render region
* :mod:`.render_status` - frames into the viewport, the status bar's progress, device, corner tag, pause, errors
* :mod:`.document`     - the open scene, its undo stack, selection and lens; targets that address its parts
* :mod:`.commands`     - every edit as a QUndoCommand
* :mod:`.render_loop`  - the progressive render loop (preview, full passes, denoise, picks, exports), Qt-free
* :mod:`.worker`       - the thread that carries the loop, with its own GL context; :mod:`.controller` feeds it
* :mod:`.viewport`     - the converging picture, display transform, selection outline, plane-of-focus overlay
* :mod:`.scene_tree`   - the outliner (a Qt item model over the scene)
* :mod:`.properties`   - the property editor, generic over the scene's dataclass fields
* :mod:`.camera_panel` - lens, aperture, focal length, focus, sensor, iris and depth-of-field readout, one
                         widget per section
* :mod:`.export_dialog`, :mod:`.widgets`, :mod:`.theme`, :mod:`.defaults`
"""
