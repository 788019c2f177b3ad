"""``lenslab batch shots.toml``: render every shot of a batch file, on this machine or a Dask cluster.

One progress bar for the batch and one per shot being rendered on a terminal; one line per finished, skipped
or failed shot otherwise. Exit status 0 when every shot is written (now or by an earlier run), 1 when any
failed (the others are still rendered), 2 for a usage error, 130 when interrupted (nothing half-written).
"""

from __future__ import annotations

import argparse
import sys
import threading
import time

from lenslab.batch.spec import Batch, BatchError, read_batch
from lenslab.command_line import EXIT_ERROR, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE, CliError, CommandParser, number_argument
from lenslab.messages import one_line

MAX_LOCAL_WORKERS = 256


def _devices(text: str) -> tuple[int, ...]:
    try:
        devices = tuple(int(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected device numbers such as 0,1, not '{text}'") from None
    if not devices or any(not 0 <= d <= 64 for d in devices):
        raise argparse.ArgumentTypeError(f"device numbers lie in [0, 64], not '{text}'")
    return devices


def build_parser() -> argparse.ArgumentParser:
    p = CommandParser(
        prog="lenslab batch",
        description="Render the shots of a batch file (TOML or JSON: docs/batch.md) on worker processes of this "
                    "machine, or on a Dask cluster. Shots whose output exists are skipped, so a batch that was "
                    "interrupted resumes where it stopped.",
        epilog="Examples:\n"
               "  lenslab batch shots.toml                       # one worker on this machine\n"
               "  lenslab batch shots.toml --workers 4 --devices 0,1,2,3   # a worker per GPU\n"
               "  lenslab batch shots.toml --scheduler tcp://farm:8786      # a running Dask cluster\n",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("batch_file", metavar="BATCH", help="the batch file (.toml or .json)")
    p.add_argument("--workers", type=number_argument(int, 1, MAX_LOCAL_WORKERS), default=None, metavar="N",
                   help="worker processes on this machine (default: one per --devices entry, else 1)")
    p.add_argument("--devices", type=_devices, default=(), metavar="0,1",
                   help="GPUs (EGL device numbers) for this machine's workers, one worker each unless --workers")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="use a running Dask cluster, e.g. tcp://farm:8786; its workers must reach the scene files "
                        "at the same paths (docs/batch.md)")
    p.add_argument("--force", action="store_true", help="render every shot, even those whose output exists")
    p.add_argument("--contact-sheet", metavar="FILE.png", help="also write a contact sheet here (besides any the "
                   "batch file names)")
    p.add_argument("--dry-run", action="store_true", help="list the shots and their outputs, render nothing")
    return p


def main(argv: list[str]) -> int:
    """``lenslab batch ...`` (lenslab.cli.main has set up the warning lines)."""
    try:
        return run(argv)
    except CliError as exc:
        print(one_line(exc, prefix="lenslab batch: error: "), file=sys.stderr)
        return exc.status
    except BatchError as exc:
        print(one_line(exc, prefix="lenslab batch: error: "), file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("lenslab batch: interrupted; every shot reported done is written, and running the batch again "
              "renders the rest", file=sys.stderr)
        return EXIT_INTERRUPTED
    except OSError as exc:  # the scheduler cannot be reached, a worker cannot start
        print(one_line(' '.join(str(exc).split()), prefix="lenslab batch: error: "), file=sys.stderr)
        return EXIT_ERROR


def run(argv: list[str]) -> int:
    from lenslab.render.film import ExportError

    args = build_parser().parse_args(argv)
    if args.scheduler and (args.workers or args.devices):
        raise CliError("--scheduler uses the cluster's own workers: leave out --workers and --devices (pin a "
                       "worker to a GPU with LENSLAB_DEVICE=N in its environment)", EXIT_USAGE)
    batch = read_batch(args.batch_file)
    contact_sheets = [p for p in (batch.contact_sheet, args.contact_sheet) if p]
    if args.contact_sheet and not str(args.contact_sheet).lower().endswith(".png"):
        raise CliError(f"--contact-sheet {args.contact_sheet}: a contact sheet is a .png", EXIT_USAGE)
    if args.dry_run:
        _print_plan(batch, args.force)
        return EXIT_OK
    summary = _render(batch, args)
    if contact_sheets:
        from lenslab.batch.contact_sheet import write_contact_sheet

        frames = _contact_sheet_frames(batch, summary)
        for sheet in contact_sheets:
            try:
                written = write_contact_sheet(sheet, frames)
            except (ExportError, OSError) as exc:  # the shots are written: say what is missing, not a traceback
                print(one_line(f"contact sheet {sheet}: {' '.join(str(exc).split())}",
                               prefix="lenslab batch: error: "), file=sys.stderr)
                return EXIT_ERROR
            print(one_line(f"wrote contact sheet {written} ({len(frames)} shots)"), file=sys.stderr)
    if summary.failed:
        print(f"lenslab batch: {len(summary.failed)} of {len(batch.shots)} shots failed:", file=sys.stderr)
        for shot, message in summary.failed:
            print(one_line(f"{shot.name}: {message}", prefix="  "), file=sys.stderr)
        return EXIT_ERROR
    return EXIT_OK


def _print_plan(batch: Batch, force: bool) -> None:
    for shot in batch.shots:
        state = "exists, skipped" if shot.output.exists() and not force else "to render"
        parts = f", in {shot.split} parts" if shot.split > 1 else ""
        print(one_line(f"{shot.name}: {shot.output} ({state}{parts})"))


def _cluster_client(args):
    from distributed import Client

    from lenslab.batch.farm import local_cluster

    if args.scheduler:
        _check_scheduler_address(args.scheduler)
        # How long to try is Dask's own setting (distributed.comm.timeouts.connect, e.g. the environment's
        # DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT=5s).
        try:
            return None, _connect(Client, args.scheduler)
        except (OSError, ValueError, MemoryError) as exc:  # OSError includes TimeoutError; ValueError: no port;
            # MemoryError: a server that is not Dask's answered, and its first bytes were read as a frame's length
            raise OSError(f"cannot reach a Dask scheduler at {args.scheduler} ({exc}): is `dask scheduler` "
                          "running there, and is the address its own?") from None
        except Exception as exc:  # noqa: BLE001 - a comm library failing in its own way: still one line
            raise OSError(f"cannot reach a Dask scheduler at {args.scheduler} ({type(exc).__name__}: {exc})") from None
    workers = args.workers or max(1, len(args.devices))
    cluster = local_cluster(workers)
    return cluster, Client(cluster)


def _check_scheduler_address(address: str) -> None:
    """Refuse, as a usage error, an address whose protocol this installation of Dask cannot connect over: one it
    does not know (``foo://``), or one it knows and cannot use (``ucx://`` without UCX-Py, whose connector Dask
    cannot even make)."""
    from distributed.comm import registry
    from distributed.comm.addressing import parse_address

    try:
        scheme, _ = parse_address(address, strict=False)
        registry.get_backend(scheme).get_connector()
    except Exception as exc:  # noqa: BLE001 - each comm backend fails in its own way; one line says which
        usable = []
        for name, backend in registry.backends.items():
            try:
                backend.get_connector()
            except Exception:  # noqa: BLE001
                continue
            if name != "inproc":  # within one process: no farm
                usable.append(f"{name}://")
        reason = str(exc).splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise CliError(f"--scheduler {address}: this installation of Dask cannot connect over that protocol "
                       f"({reason}); it can over {', '.join(usable)}", EXIT_USAGE) from None


def _connect(client_class, address: str):
    """A Dask client of the scheduler at ``address``, or TimeoutError when none has answered within Dask's own
    connect time-out (distributed.comm.timeouts.connect): a server that accepts the connection and then says
    nothing (not a scheduler) would otherwise hold the batch for ever, since the handshake has no deadline."""
    import dask
    from dask.utils import parse_timedelta

    seconds = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), default="s")
    outcome: dict = {}

    def connect() -> None:
        try:
            outcome["client"] = client_class(address, timeout=seconds)
        except BaseException as exc:  # handed to the waiting thread, which raises it
            outcome["error"] = exc

    attempt = threading.Thread(target=connect, name="lenslab-connect", daemon=True)
    attempt.start()
    attempt.join(seconds + 5)
    if attempt.is_alive():
        raise TimeoutError(f"no answer as a Dask scheduler within {seconds:g} s")
    if "error" in outcome:
        raise outcome["error"]
    return outcome["client"]


def _render(batch: Batch, args):
    from lenslab.batch.farm import run_batch

    display = _Display(len(batch.shots))
    cluster, client = _cluster_client(args)
    try:
        with display:
            summary = run_batch(batch.shots, client, force=args.force, devices=args.devices, on_event=display.show)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    display.summary(summary)
    return summary


class _Display:
    """Rich progress bars on a terminal (the batch, and each shot being rendered); plain lines otherwise."""

    def __init__(self, shots: int):
        from rich.console import Console
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        self.console = Console(stderr=True)
        self.bars = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[status]}"),
                             TimeElapsedColumn(), console=self.console, disable=not self.console.is_terminal)
        self.overall = self.bars.add_task("[bold]batch", total=shots, status=f"0/{shots} shots")
        self._shots: dict[str, int] = {}
        self._start = time.perf_counter()
        self._finished = 0
        self._total = shots

    def __enter__(self):
        self.bars.__enter__()
        return self

    def __exit__(self, *exc):
        return self.bars.__exit__(*exc)

    def _line(self, text: str) -> None:
        self.console.print(one_line(text), highlight=False, markup=False, soft_wrap=True)  # names come from files

    def _finish(self, shot, text: str) -> None:
        self._finished += 1
        task = self._shots.pop(str(shot.output), None)
        if task is not None:
            self.bars.remove_task(task)
        self.bars.update(self.overall, completed=self._finished, status=f"{self._finished}/{self._total} shots")
        self._line(text)

    def show(self, event) -> None:
        from lenslab.batch.farm import PartRetried, ShotDone, ShotFailed, ShotProgress, ShotSkipped

        shot = event.shot
        if isinstance(event, ShotSkipped):
            self._finish(shot, f"skipped {shot.name}: {shot.output} exists (--force renders it again)")
        elif isinstance(event, ShotDone):
            for warning in event.warnings:
                self._line(f"lenslab batch: warning: {shot.name}: {warning}")
            self._finish(shot, f"wrote {shot.output} ({shot.name}, {event.samples_per_pixel} spp, "
                               f"{event.seconds:.1f} s of sampling)")
        elif isinstance(event, ShotFailed):
            self._finish(shot, f"failed {shot.name}: {event.message}")
        elif isinstance(event, PartRetried):
            self._line(f"{shot.name}: a worker was lost; part {event.part + 1} of {shot.split} starts again on "
                       f"{event.worker}")
        elif isinstance(event, ShotProgress):
            key = str(shot.output)
            if key not in self._shots:
                from rich.markup import escape  # a shot's name is text, not rich's markup

                self._shots[key] = self.bars.add_task(escape(one_line(shot.name)), total=1.0, status="")
            workers = f" on {len(event.workers)} workers" if len(event.workers) > 1 else ""
            self.bars.update(self._shots[key], completed=event.fraction,
                             status=f"{event.samples_per_pixel} spp, "
                                    f"{event.samples_per_second / 1e6:.2f} M samples/s{workers}")

    def summary(self, summary) -> None:
        seconds = time.perf_counter() - self._start
        self._line(f"{len(summary.done)} rendered, {len(summary.skipped)} skipped, {len(summary.failed)} failed "
                   f"in {seconds:.1f} s")


def _contact_sheet_frames(batch: Batch, summary) -> list:
    """A frame per shot, captioned with its camera as set (or why it failed). Each scene file is read once,
    however many shots of a bracket it has."""
    from lenslab.batch.contact_sheet import Frame, shot_caption
    from lenslab.scene.io.loader import open_scene
    from lenslab.scene.scene import SceneError

    failed = {str(shot.output): message for shot, message in summary.failed}
    scenes: dict[tuple, object] = {}

    def caption(shot) -> str:
        if str(shot.output) in failed:
            return f"failed: {failed[str(shot.output)]}"
        defines = shot.overrides.defines
        key = (shot.scene, tuple(sorted(defines.items())))
        try:
            if key not in scenes:
                scenes[key] = open_scene(shot.scene, defines=dict(defines))
            return shot_caption(shot.overrides.apply(scenes[key]).camera, lens_name=shot.overrides.lens)
        except (SceneError, ValueError, OSError) as exc:
            return " ".join(str(exc).split())

    return [Frame(shot.output if shot.output.exists() else None, shot.name, caption(shot), view=shot.view)
            for shot in batch.shots]
