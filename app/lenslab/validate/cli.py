"""``lenslab validate``: compare LensLab's images with Mitsuba 3's (see lenslab.validate.runner)."""

from __future__ import annotations

import sys
from pathlib import Path

from lenslab.cli import EXIT_ERROR, EXIT_OK, EXIT_USAGE, CliError, CommandParser, number_argument
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
                "Mitsuba reference, each renderer's relative MSE at equal samples, and their times.")
    p.add_argument("--spp", type=_positive, default=64, metavar="N", help="samples per pixel for the equal-sample comparison (64)")
    p.add_argument("--reference-spp", type=_positive, default=4096, metavar="M", help="samples per pixel of the Mitsuba reference (4096)")
    p.add_argument("--bias-spp", type=_positive, default=1024, metavar="B", help="samples per pixel of the renders whose bias is measured (1024)")
    p.add_argument("--resolution", type=_positive, default=128, metavar="PX", help="image width and height (128)")
    p.add_argument("--scenes", default=",".join(SCENE_NAMES), metavar="a,b", help=f"which scenes ({','.join(SCENE_NAMES)})")
    p.add_argument("--write-docs", action="store_true", help="write docs/validation.md and its images")
    p.add_argument("--docs-dir", type=Path, default=None, metavar="DIR", help="where docs/validation.md goes (the checkout's docs/)")
    p.add_argument("--device", type=int, default=None, metavar="N", help="which GPU LensLab uses (EGL device index)")
    return p


def run(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    names = [n.strip() for n in args.scenes.split(",") if n.strip()]
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
