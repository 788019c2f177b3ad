"""The ``lenslab`` command: open the studio, or render a scene to a file without a window.

``--headless`` never imports Qt. Every failure a user can cause (a bad argument, a broken scene, no GPU
driver, an unwritable output) ends with a non-zero exit status and one line on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import threading
import time
import warnings
from pathlib import Path

from lenslab import __version__
from lenslab.command_line import (EXIT_ERROR, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE, CliError, CommandParser,
                                  add_option, number_argument, parse_defines)
from lenslab.messages import describe_os_error, one_line

#: With stderr not a terminal (a log), a line of progress this often, so that a long render shows it is alive.
PROGRESS_LINE_SECONDS = 10.0


def build_parser() -> argparse.ArgumentParser:
    from lenslab.scene.io.loader import shipped_scene_names

    p = CommandParser(
        prog="lenslab",
        description="LensLab: a photographic studio on a physically based path tracer. Without --headless it "
        "opens the studio window; with --headless it renders SCENE to a file and exits.",
        epilog="Examples:\n"
        "  lenslab cornell_box --headless -o cornell.png --spp 64\n"
        "  lenslab dof_chart --headless -o dof.exr --spp 16 --denoise\n"
        "  lenslab my_scene.json --headless -o shot.exr --f-number 1.4 --focus-distance 2.5 --time-limit 60\n"
        "  lenslab product_shot --headless -o p.exr --lens '85mm f/1.4' --f-number 2 --iso 400 --shutter 1/60\n"
        "The camera settings override the scene's camera for this render only. A marked stop (--f-number 11) is\n"
        "the exact stop (2^3.5); focus is measured from the sensor plane unless the scene says otherwise, and a\n"
        "mounted lens focuses no nearer than its minimum. In the default compensated exposure brightness does not\n"
        "change with the f-number; with --iso or --shutter each stop is a stop of light.\n"
        "Lenses and sensors: --list-lenses, --list-sensors.\n"
        "Shipped scenes: " + ", ".join(shipped_scene_names()) + ".\n"
        "Render many shots (brackets, focus stacks, a farm): lenslab batch --help.\n"
        "Compare with Mitsuba 3: lenslab validate --help.\n",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scene", nargs="?", help="a scene file (.json), a folder holding scene.json, or a shipped scene name")
    p.add_argument("--headless", action="store_true", help="render to a file without opening a window")
    p.add_argument("-o", "--output", metavar="FILE",
                   help="with --headless: where to write the image: .exr (scene-linear float), or a picture through "
                        "the view transform: .png, .tif/.tiff (16-bit), .jpg/.jpeg")
    for name in ("spp", "time_limit", "width", "height", "f_number", "focal_length", "focus_distance"):
        add_option(p, name)
    camera = p.add_argument_group("camera and lens")
    for name in ("lens", "dispersion", "sensor", "sensor_fit", "focus_from", "focus_breathing", "circle_of_confusion",
                 "aperture_blades", "blade_curvature", "anamorphic_squeeze", "barrel_clipping", "aperture_image"):
        add_option(camera, name)
    camera.add_argument("--list-lenses", action="store_true", help="print the lens presets and exit")
    camera.add_argument("--list-sensors", action="store_true", help="print the sensor presets and exit")
    for name in ("exposure_mode", "iso", "shutter", "metering"):
        add_option(camera, name)
    for name in ("seed", "max_depth", "sampler", "clamp", "working_space"):
        add_option(p, name)
    colour = p.add_argument_group("pictures (PNG, TIFF, JPEG): OpenColorIO's view transform (docs/colour.md)")
    for name in ("display", "view", "look", "ocio_config"):
        add_option(colour, name)
    add_option(colour, "exposure", default=0.0)
    add_option(colour, "contrast", default=1.0)
    p.add_argument("--denoise", action="store_true",
                   help="write the image denoised (Intel Open Image Denoise, guided by the first-hit albedo and normal "
                        "rendered beside it); an EXR also keeps the noisy image and the guides as layers")
    p.add_argument("-D", dest="defines", action="append", default=[], metavar="NAME=VALUE",
                   help="Mitsuba XML scenes: set the parameter $NAME, as mitsuba -D does (repeatable)")
    p.add_argument("--device", type=number_argument(int, 0, 64), metavar="N", help="which GPU to use (EGL device index)")
    p.add_argument("--info", action="store_true", help="print the OpenGL device and the limits in use, then exit")
    p.add_argument("--version", action="version", version=f"lenslab {__version__}")
    return p


# ---------------------------------------------------------------------------------------------------------
def _print_info(device: int | None) -> int:
    from lenslab.render.tracer import Renderer

    renderer = Renderer(device)
    width = max(len(k) for k in renderer.describe())
    for key, value in renderer.describe().items():
        print(f"{key:<{width}}  {value}")
    renderer.release()
    return EXIT_OK


def _check_output(path_text: str | None) -> Path:
    from lenslab.atomic import check_output_folder
    from lenslab.render.film import EXPORT_SUFFIXES, EXPORT_SUFFIXES_TEXT

    if not path_text:
        raise CliError("--headless needs an output file: -o OUT.exr, OUT.png, OUT.tif or OUT.jpg", EXIT_USAGE)
    path = Path(path_text)
    if path.is_dir():
        raise CliError(f"{path} is a folder: name the image file, e.g. {path / 'render.exr'}", EXIT_USAGE)
    if path.suffix.lower() not in EXPORT_SUFFIXES:
        raise CliError(f"{path}: unsupported output type '{path.suffix}' (use {EXPORT_SUFFIXES_TEXT})", EXIT_USAGE)
    folder = path.parent if str(path.parent) else Path(".")
    if folder.exists() and not folder.is_dir():
        raise CliError(f"{path}: '{folder}' is a file, not a folder")
    if not folder.is_dir():
        raise CliError(f"{path}: folder '{folder}' does not exist")
    if not os.access(folder, os.W_OK):
        raise CliError(f"{path}: folder '{folder}' is not writable")
    try:  # permissions say nothing for root: the folder asked as the writer will ask it, before the render
        check_output_folder(path)
    except OSError as exc:
        raise CliError(str(exc)) from None
    return path


def _warn(message: str) -> None:
    print(one_line(message, prefix="lenslab: warning: "), file=sys.stderr)


def _error(message: object) -> None:
    print(one_line(message, prefix="lenslab: error: "), file=sys.stderr)


def scene_overrides(args):
    """The command line's settings for this render, on top of the scene's own (headless and studio alike)."""
    from lenslab.optics.presetfiles import PresetError
    from lenslab.scene.options import SCENE_OPTIONS
    from lenslab.scene.overrides import SceneOverrides

    try:
        return SceneOverrides(**{option.name: getattr(args, option.name) for option in SCENE_OPTIONS},
                              defines=parse_defines(args.defines))
    except PresetError:
        raise
    except ValueError as exc:  # settings that do not go together (f/1.2 on an f/1.4 lens): a usage error
        raise CliError(f"{exc} (see lenslab --help)", EXIT_USAGE) from None


def _progress_display():
    """A rich progress bar on a terminal; nothing when stderr is a file or pipe."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    console = Console(stderr=True)
    return Progress(
        TextColumn("[bold]rendering"), BarColumn(), TextColumn("{task.fields[status]}"),
        TimeElapsedColumn(), TimeRemainingColumn(), console=console, disable=not console.is_terminal, transient=False,
    )


def _terminal_console():
    """A rich console on stderr when it is a terminal (None otherwise: logs and pipes get no spinners)."""
    from rich.console import Console

    console = Console(stderr=True)
    return console if console.is_terminal else None


def _loading_status(console, text: str):
    """A spinner while a scene loads or its tree builds: a million triangles take seconds before any sample."""
    return console.status(text) if console is not None else contextlib.nullcontext()


def _progress_lines(every_seconds: float):
    """``on_progress`` for a render without a progress bar (stderr is a log, not a terminal): a line every
    ``every_seconds`` of rendering, with the samples, the time and the speed, so a long render shows it is alive."""
    next_line_at = every_seconds

    def report(progress) -> None:
        nonlocal next_line_at
        if progress.elapsed_seconds < next_line_at:
            return
        next_line_at = progress.elapsed_seconds + every_seconds
        samples = (f"{progress.samples_per_pixel} of {progress.target_spp} spp" if progress.target_spp else
                   f"{progress.samples_per_pixel} spp")
        limit = f" of {progress.time_limit:g} s" if progress.time_limit else " s"
        print(f"lenslab: rendering: {samples} after {progress.elapsed_seconds:.0f}{limit} "
              f"({progress.samples_per_second / 1e6:.2f} M samples/s)", file=sys.stderr, flush=True)

    return report


def _load_line(session, ready_after: float) -> str:
    """What opening the scene made and where the time went: triangles and spheres (and meshes placed more than
    once), the kd-trees (built or read from the cache), each step's seconds (render/tracer.SceneLoad)."""
    flat, packed, load = session.flat_scene, session.gpu_scene.packed, session.load
    placed, stored = flat.placed_triangle_count, flat.stored_triangle_count
    triangles = f"{placed:,} triangles" + (f" ({stored:,} stored)" if stored != placed else "")
    trees = packed.trees
    made = ("read from the cache" if load.trees_from_cache == load.trees_built else
            "built" if not load.trees_from_cache else f"built or read from the cache ({load.trees_from_cache})")
    what = f"kd-tree of {len(trees[0].nodes):,} nodes" if len(trees) == 1 else \
        f"{len(trees)} kd-trees of {sum(len(t.nodes) for t in trees):,} nodes"
    return (f"{triangles}, {flat.sphere_count:,} spheres; {what} {made} in {load.trees:.1f} s; "
            f"{load.describe_steps()}; ready to sample after {ready_after:.1f} s")


def render_headless(args) -> int:
    from lenslab.render.job import OFFLINE_DISPATCH_SECONDS, RenderJob
    from lenslab.limits import SceneTooLarge
    from lenslab.render.tracer import Renderer
    from lenslab.scene.scene import SceneError

    output = _check_output(args.output)
    if output.suffix.lower() == ".exr":
        given = {"display": args.display is not None, "view": args.view is not None, "look": args.look is not None,
                 "exposure": args.exposure != 0.0, "contrast": args.contrast != 1.0}
        for name in (name for name, yes in given.items() if yes):
            _warn(f"--{name} applies to pictures only: an EXR keeps the scene-linear values")
    from lenslab.colour_management.config import use_config

    use_config(args.ocio_config or "")  # the config of the whole render, textures and picture ("": $OCIO's)
    overrides = scene_overrides(args)
    if args.denoise:  # a denoiser that cannot run says so now, not after the render
        from lenslab.render.denoise import DenoiseError, describe

        try:
            describe()
        except DenoiseError as exc:
            raise CliError(f"--denoise: {exc}") from None
    console = _terminal_console()
    loading_start = time.perf_counter()
    with _loading_status(console, f"loading {args.scene}"):
        scene = overrides.open(args.scene, warn=_warn)
    view = _view_transform(args, scene.render.working_space)
    renderer = Renderer(args.device)
    try:
        with _loading_status(console, "building the kd-tree and compiling the kernel"):
            job = RenderJob(renderer, scene, spp=args.spp, time_limit=args.time_limit,
                            dispatch_seconds=OFFLINE_DISPATCH_SECONDS, feature_buffers=args.denoise)
    except (SceneError, SceneTooLarge, ValueError) as exc:  # found only when the scene is packed: name its file
        raise SceneError.in_file(scene.source_path or args.scene, exc) from None
    session = job.session
    ready_after = time.perf_counter() - loading_start
    loaded = _load_line(session, ready_after)
    if console is not None:
        console.print(loaded, highlight=False)
    elif ready_after >= PROGRESS_LINE_SECONDS:  # a log that was silent this long says what took the time
        print(f"lenslab: loaded: {loaded}", file=sys.stderr)
    for warning in session.warnings:
        _warn(warning)
    log_progress = _progress_lines(PROGRESS_LINE_SECONDS) if console is None else None
    first_pass_late = _first_pass_notice(session.width * session.height)
    with _progress_display() as bar:
        task = bar.add_task("render", total=job.target_spp or job.time_limit, status="")

        def show(progress) -> None:
            first_pass_late(progress)
            done = progress.samples_per_pixel if job.target_spp else min(progress.elapsed_seconds, job.time_limit)
            bar.update(task, completed=done, status=f"{progress.samples_per_pixel} spp, "
                                                    f"{progress.samples_per_second / 1e6:.2f} M samples/s")
            if log_progress is not None:
                log_progress(progress)

        job.run(on_progress=show)
    if job.overran_time_limit > 0:
        _warn(f"the time limit ended before every pixel had a sample: the first pass was finished "
              f"{job.overran_time_limit:.1f} s later")
    # Once the image is whole and about to take its name, a stop signal could only misreport it.
    job.write(output, view=view, before_rename=_ignore_stop_signals, denoise=args.denoise)
    print(one_line(f"wrote {output} ({session.width}x{session.height}, {job.samples_per_pixel} spp, "
                   f"{job.elapsed_seconds:.1f} s{', denoised' if args.denoise else ''})"), file=sys.stderr)
    job.release()
    renderer.release()
    return EXIT_OK


def _view_transform(args, working_space: str):
    """The view transform the command line asks for, checked against its OCIO config before anything renders."""
    from lenslab.colour_management.config import ColourConfigError
    from lenslab.scene.options import view_transform

    try:
        return view_transform(vars(args), working_space).resolved()
    except ColourConfigError as exc:
        raise CliError(str(exc)) from None


def _first_pass_notice(pixels: int):
    """A function of each JobProgress that warns, once, when the time limit is up before every pixel has a
    sample: the job finishes that first pass (render/job.py), and the user hears at once why it goes on rather
    than a wait that looks like a hang (the speed of the first slices is no guide to how long it will be)."""
    warned = False

    def notice(progress) -> None:
        nonlocal warned
        if warned or not progress.time_limit or progress.elapsed_seconds < progress.time_limit:
            return
        if progress.samples_per_pixel >= 1:
            warned = True
            return
        warned = True
        _warn(f"the time limit ({progress.time_limit:g} s) is up before every pixel has a sample: finishing the "
              f"first pass ({pixels:,} samples) before stopping")

    return notice


def _print_presets(kind: str) -> int:
    """--list-lenses / --list-sensors: the presets as a table, shipped and the user's own."""
    from lenslab.optics import format_f_number, format_focal_length, load_lens_presets, load_sensor_presets
    from lenslab.optics.thinlens import format_distance

    if kind == "lenses":
        header = ("lens", "focal length", "stops", "blades", "closest focus", "model")
        rows = [(lens.name,
                 format_focal_length(lens.min_focal_length_mm) if not lens.is_zoom else
                 f"{lens.min_focal_length_mm:g}-{format_focal_length(lens.max_focal_length_mm)}",
                 f"{format_f_number(lens.widest_f_number)} to {format_f_number(lens.narrowest_f_number)}",
                 "round" if not lens.aperture_blades else
                 f"{lens.aperture_blades}" + (f", curvature {lens.blade_roundness:g}" if lens.blade_roundness else ""),
                 format_distance(lens.min_focus_distance_m) if lens.min_focus_distance_m else "",
                 f"glass, {len(lens.prescription.surfaces)} surfaces" if lens.is_real else "thin lens")
                for lens in load_lens_presets()]
    else:
        header = ("sensor", "size", "crop", "circle of confusion")
        rows = [(sensor.name, f"{sensor.width_mm:g} x {sensor.height_mm:g} mm", f"{sensor.crop_factor:.2f}x",
                 f"{sensor.coc_mm * 1000:.0f} µm") for sensor in load_sensor_presets()]
    widths = [max(len(str(row[i])) for row in [header, *rows]) for i in range(len(header))]
    for row in [header, *rows]:
        print("  ".join(str(cell).ljust(width) for cell, width in zip(row, widths)).rstrip())
    return EXIT_OK


def run(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.list_lenses or args.list_sensors:
        return _print_presets("lenses" if args.list_lenses else "sensors")
    if args.info:
        if args.headless or args.output:
            raise CliError("--info prints the device and exits without rendering: leave out --headless and -o, "
                           "or --info", EXIT_USAGE)
        return _print_info(args.device)
    if args.output and not args.headless:
        # -o means a file, not a window: say how to get one rather than open the studio and ignore it.
        raise CliError(f"-o writes an image without the studio: add --headless (lenslab {args.scene or 'SCENE'} "
                       f"--headless -o {args.output})", EXIT_USAGE)
    if args.headless:
        if not args.scene:
            raise CliError("--headless needs a scene to render", EXIT_USAGE)
        if argv is None:  # the process's own command
            _stop_on_sigterm_as_on_ctrl_c()
        return render_headless(args)
    problem = display_problem()
    if problem:
        raise CliError(problem)
    from lenslab.gui.app import run_studio  # only the studio imports Qt

    return run_studio(args.scene, scene_overrides(args), device_index=args.device)


#: Qt platforms that draw on a display server; any other (offscreen, minimal, eglfs, vnc ...) needs none.
DISPLAY_PLATFORMS = ("xcb", "wayland", "wayland-egl")


def display_problem(environ=None, platform: str | None = None) -> str | None:
    """Why the studio cannot open its window here, in a line that says what to do instead; None when it can.
    On Linux and the BSDs a window needs an X or Wayland display: without one Qt aborts with a hint about
    libxcb-cursor that leads nowhere. Windows and macOS always have their own."""
    environ = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    if platform.startswith(("win", "darwin", "cygwin")):
        return None
    wanted = [name.split(":")[0].strip() for name in environ.get("QT_QPA_PLATFORM", "").split(";") if name.strip()]
    if any(name not in DISPLAY_PLATFORMS for name in wanted):
        return None  # a platform of Qt's that needs no display server (QT_QPA_PLATFORM=offscreen)
    if environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY"):
        return None
    return ("the studio needs a display, and there is none here (DISPLAY and WAYLAND_DISPLAY are not set): to "
            "render without a window add --headless -o OUT.png (lenslab --help); for the studio, run it on the "
            "desktop or over ssh -X")


class _WarningLine(logging.Handler):
    """Prints a logged warning as the CLI's own warning line, to whatever stderr is at the time."""

    def emit(self, record: logging.LogRecord) -> None:
        _warn(record.getMessage())


def _report_library_warnings() -> None:
    """Warnings LensLab's modules log (a texture reduced in size, NaN texels) read as the CLI's own lines,
    instead of Python's bare last-resort output."""
    logger = logging.getLogger("lenslab")
    if not any(isinstance(h, _WarningLine) for h in logger.handlers):
        logger.addHandler(_WarningLine(logging.WARNING))
    warnings.showwarning = _show_python_warning


def _show_python_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A Python warning (numpy's "overflow encountered in multiply") as one warning line: not Python's two,
    whose second is a line of some library's source, meaningless to whoever is rendering."""
    _warn(f"{category.__name__}: {message}")


def _stop_on_sigterm_as_on_ctrl_c() -> None:
    """SIGTERM (``kill``, a service manager, a render farm's time-out) stops a command that writes files as Ctrl-C
    does: it raises KeyboardInterrupt, so the temporary file is removed and the exit is "interrupted; nothing was
    written", status 130 for either signal. Only for the process's own command (main() without argv: a caller's
    signals are its own), and not for the studio, which Qt's event loop would keep from hearing it. A SIGTERM the
    process was started ignoring stays ignored."""
    if threading.current_thread() is threading.main_thread() and \
            signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
        signal.signal(signal.SIGTERM, signal.default_int_handler)


def _ignore_stop_signals() -> None:
    """Ignore SIGINT and SIGTERM for the rest of the command, where it has made SIGTERM Ctrl-C's: called as the
    image takes its name, after which a stop could only misreport a written file (as "nothing was written", or as
    a traceback from the process's exit)."""
    if threading.current_thread() is threading.main_thread() and \
            signal.getsignal(signal.SIGTERM) is signal.default_int_handler:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)


#: The exit status when whoever reads the output stops reading (``lenslab --list-lenses | head -3``): a C program
#: dies of SIGPIPE there, which a shell reports as 128 + 13; nothing is printed, since there is no one to tell.
EXIT_READER_GONE = 141


def main(argv: list[str] | None = None) -> int:
    try:
        return _main(argv)
    except BrokenPipeError:
        _stop_writing_to_stdout()
        return EXIT_READER_GONE


def _stop_writing_to_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's last flush at exit finds no closed pipe to complain of."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # no stdout to redirect (a caller's StringIO): nothing will be flushed to a pipe
        pass


def _main(argv: list[str] | None) -> int:
    args_list = sys.argv[1:] if argv is None else list(argv)
    _report_library_warnings()
    if argv is None and args_list[:1] in (["validate"], ["batch"]):  # the process's own command
        _stop_on_sigterm_as_on_ctrl_c()
    if args_list[:1] == ["validate"]:
        from lenslab.validate.cli import main as validate_main

        return validate_main(args_list[1:])
    if args_list[:1] == ["batch"]:
        from lenslab.batch.cli import main as batch_main

        return batch_main(args_list[1:])
    from lenslab.optics.presetfiles import PresetError
    from lenslab.render.buffers import SceneTooLarge
    from lenslab.render.film import ExportError
    from lenslab.render.gl import GLUnavailable
    from lenslab.scene.scene import SceneError

    try:
        return run(argv)
    except CliError as exc:
        _error(exc)
        return exc.status
    except (SceneError, GLUnavailable, SceneTooLarge, ExportError, PresetError, ValueError) as exc:
        _error(exc)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("lenslab: interrupted; nothing was written", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        raise  # the reader went away: main says nothing
    except OSError as exc:
        _error(describe_os_error(exc))
        return EXIT_ERROR
    except Exception as exc:  # a bug of ours: one line for the user, the traceback on request
        if os.environ.get("LENSLAB_DEBUG"):
            raise
        _error(f"internal error: {type(exc).__name__}: {exc} (please report it; LENSLAB_DEBUG=1 shows where)")
        return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
