"""``lenslab validate``: compare LensLab's images with Mitsuba 3's (see lenslab.validate.runner)."""

from __future__ import annotations

import sys
from pathlib import Path

from lenslab.command_line import EXIT_ERROR, EXIT_OK, EXIT_USAGE, CliError, CommandParser, number_argument
from lenslab.messages import one_line
from lenslab.validate.mitsuba_env import MitsubaUnavailable, load_mitsuba
from lenslab.validate.runner import SCENE_NAMES

_positive = number_argument(int, 1, 1 << 20)  # a sample count or a resolution


def default_docs_dir() -> Path:
    from lenslab import resources

    checkout = resources.checkout_dir()
    return checkout / "docs" if checkout is not None and (checkout / "docs").is_dir() else Path.cwd() / "docs"


def build_parser() -> CommandParser:
    p = CommandParser(prog="lenslab validate",
                description="Render the validation scenes with LensLab and with Mitsuba 3 (pip install "
                "'lenslab[validate]') and print, per scene, the bias of 16x16 block means against a converged "
                "Mitsuba reference, each renderer's relative MSE at equal samples, and their times. With --files, "
                "any Mitsuba scene files instead: per file, LensLab's warnings, the median and 95th-percentile "
                "16x16 block error against a converged Mitsuba reference, the total light, and PASS when nothing "
                "is dropped and both figures are within 2% (docs/validation.md).")
    p.add_argument("--spp", type=_positive, default=None, metavar="N", help="samples per pixel for the equal-sample comparison (64); with --files, of LensLab's image (256)")
    p.add_argument("--reference-spp", type=_positive, default=None, metavar="M", help="samples per pixel of the Mitsuba reference (4096; with --files 1024)")
    p.add_argument("--bias-spp", type=_positive, default=None, metavar="B", help="samples per pixel of the renders whose bias is measured (1024)")
    p.add_argument("--resolution", type=_positive, default=None, metavar="PX", help="image width and height (128); with --files, the width, the film's aspect kept (128)")
    p.add_argument("--scenes", default=None, metavar="a,b", help=f"which scenes ({','.join(SCENE_NAMES)})")
    p.add_argument("--files", nargs="+", type=Path, default=None, metavar="XML", help="Mitsuba 3 scene files to validate instead of the built-in scenes")
    p.add_argument("-D", dest="defines", action="append", default=[], metavar="NAME=VALUE", help="with --files: set the parameter $NAME in every file, as mitsuba -D does (spp is set to --spp)")
    p.add_argument("--cache-dir", type=Path, default=None, metavar="DIR", help="with --files: where Mitsuba's images are kept for the next run (~/.cache/lenslab/validate)")
    p.add_argument("--no-cache", action="store_true", help="with --files: render Mitsuba's images again, and keep none")
    p.add_argument("--markdown", type=Path, default=None, metavar="FILE", help="with --files: also write the table, the warnings and the missing features as Markdown")
    p.add_argument("--write-docs", action="store_true", help="write docs/validation.md and its images")
    p.add_argument("--docs-dir", type=Path, default=None, metavar="DIR", help="where docs/validation.md goes (the checkout's docs/)")
    p.add_argument("--device", type=int, default=None, metavar="N", help="which GPU LensLab uses (EGL device index)")
    return p


def run(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    if args.files is not None:
        return run_files(args)
    for option, value in (("-D", args.defines), ("--cache-dir", args.cache_dir), ("--no-cache", args.no_cache),
                          ("--markdown", args.markdown)):
        if value:
            raise CliError(f"{option} goes with --files", EXIT_USAGE)
    args.spp, args.reference_spp = args.spp or 64, args.reference_spp or 4096
    args.bias_spp, args.resolution = args.bias_spp or 1024, args.resolution or 128
    names = [n.strip() for n in (args.scenes or ",".join(SCENE_NAMES)).split(",") if n.strip()]
    unknown = [n for n in names if n not in SCENE_NAMES]
    if unknown or not names:
        raise CliError(f"unknown scene '{','.join(unknown)}' (choose from {', '.join(SCENE_NAMES)})", EXIT_USAGE)
    if args.resolution < 16:
        raise CliError("--resolution must be at least 16 (one 16x16 block)", EXIT_USAGE)
    load_mitsuba()  # fail early, with one line, when Mitsuba cannot run here

    from lenslab.render.tracer import Renderer
    from lenslab.validate import report
    from lenslab.validate.runner import validate_scene

    renderer = Renderer(args.device)
    results = []
    try:
        for name in names:
            results.append(validate_scene(name, spp=args.spp, reference_spp=args.reference_spp, bias_spp=args.bias_spp,
                                          res=args.resolution, renderer=renderer,
                                          log=lambda m: print(f"lenslab validate: {m}", file=sys.stderr)))
        print(report.format_table([report.row(r) for r in results]))
        print("M = Mitsuba 3, L = LensLab; bias at %d spp against Mitsuba at %d spp; relMSE and time at %d spp"
              % (args.bias_spp, args.reference_spp, args.spp))
        if args.write_docs:
            path = report.write_docs(results, args.docs_dir or default_docs_dir(), spp=args.spp,
                                     reference_spp=args.reference_spp, bias_spp=args.bias_spp, renderer=renderer)
            print(f"wrote {path}", file=sys.stderr)
    finally:
        renderer.release()
    return EXIT_OK if all(r.meets_goal for r in results) else EXIT_ERROR


def run_files(args) -> int:
    """``--files``: each file rendered by both renderers and judged against the agreement goal of validate/files.py."""
    from lenslab.command_line import parse_defines

    for option, value in (("--scenes", args.scenes), ("--bias-spp", args.bias_spp), ("--write-docs", args.write_docs),
                          ("--docs-dir", args.docs_dir)):
        if value:
            raise CliError(f"{option} is for the built-in scenes, not --files", EXIT_USAGE)
    spp, reference_spp, width = args.spp or 256, args.reference_spp or 1024, args.resolution or 128
    if width < 16:
        raise CliError("--resolution must be at least 16 (one 16x16 block)", EXIT_USAGE)
    defines = parse_defines(args.defines)
    load_mitsuba()  # fail early, with one line, when Mitsuba cannot run here

    from lenslab.render.tracer import Renderer
    from lenslab.validate import report
    from lenslab.validate.files import default_cache_dir, display_names, validate_file

    cache_dir = None if args.no_cache else (args.cache_dir or default_cache_dir())

    def log(message: str) -> None:
        print(f"lenslab validate: {message}", file=sys.stderr)

    renderer = Renderer(args.device)
    results = []
    try:
        for path, name in zip(args.files, display_names(args.files)):
            result = validate_file(path, name=name, spp=spp, reference_spp=reference_spp, width=width,
                                   renderer=renderer, cache_dir=cache_dir, defines=defines, log=log)
            results.append(result)
            why = result.error if result.error is not None else ", ".join(result.reasons())
            log(f"{name}: {result.verdict}" + (f" ({why})" if why else ""))
    finally:
        renderer.release()
    print(report.format_files_report(results, spp=spp, reference_spp=reference_spp))
    if args.markdown:
        args.markdown.write_text(report.markdown_files_report(results, spp=spp, reference_spp=reference_spp),
                                 encoding="utf-8")
        print(f"wrote {args.markdown}", file=sys.stderr)
    return EXIT_OK if all(r.verdict == "PASS" for r in results) else EXIT_ERROR


def main(argv: list[str] | None = None) -> int:
    from lenslab.render.gl import GLUnavailable
    from lenslab.scene.scene import SceneError

    try:
        return run(list(sys.argv[1:] if argv is None else argv))
    except CliError as exc:
        print(one_line(exc, prefix="lenslab validate: error: "), file=sys.stderr)
        return exc.status
    except MitsubaUnavailable as exc:
        print(one_line(exc, prefix="lenslab validate: "), file=sys.stderr)
        return EXIT_ERROR
    except (SceneError, GLUnavailable, OSError, ValueError) as exc:
        print(one_line(exc, prefix="lenslab validate: error: "), file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("lenslab validate: interrupted", file=sys.stderr)
        return 130
