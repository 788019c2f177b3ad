"""Shots across Dask workers: submit each shot's parts, follow their progress, write each shot as it completes.

Dask's distributed scheduler does the farming (docs/batch.md, "Why Dask"): it places parts on idle workers,
moves the parts of a lost worker to another (up to ``distributed.scheduler.allowed-failures`` times, 3 by
default) and reaches SLURM, PBS or Kubernetes through dask-jobqueue and dask-kubernetes. LensLab adds what is
particular to rendering: splitting a shot into sample ranges, merging them, skipping shots already written,
and reporting progress per shot.

A shot that fails (a broken scene, a worker lost too often) is reported and the others go on. Images are written
here, by the machine that runs the batch, one whole file at a time: an interrupted batch loses no finished shot,
and the next run skips every shot whose file exists.
"""

from __future__ import annotations

import itertools
import logging
import os
import queue
import uuid
from dataclasses import dataclass
from typing import Callable, Iterable

from lenslab.batch.parts import PROGRESS_TOPIC, PartProgress, PartResult, ShotAssembly, run_part
from lenslab.batch.spec import Shot


# -- what a batch reports as it goes ---------------------------------------------------------------------------
@dataclass(frozen=True)
class ShotSkipped:
    shot: Shot  # its output exists already


@dataclass(frozen=True)
class ShotProgress:
    shot: Shot
    fraction: float  # 0 to 1 over all its parts
    samples_per_pixel: int  # in the parts so far
    samples_per_second: float  # all its parts together
    workers: tuple[str, ...]  # the addresses of the workers rendering it now


@dataclass(frozen=True)
class PartRetried:
    shot: Shot
    part: int
    worker: str  # where it runs again, after the worker it was on was lost


@dataclass(frozen=True)
class ShotDone:
    shot: Shot
    samples_per_pixel: int
    seconds: float  # sampling time summed over its parts
    warnings: tuple[str, ...]


@dataclass(frozen=True)
class ShotFailed:
    shot: Shot
    message: str


BatchEvent = ShotSkipped | ShotProgress | PartRetried | ShotDone | ShotFailed


@dataclass(frozen=True)
class BatchSummary:
    done: tuple[Shot, ...]
    skipped: tuple[Shot, ...]
    failed: tuple[tuple[Shot, str], ...]

    @property
    def ok(self) -> bool:
        return not self.failed


# -- the cluster -----------------------------------------------------------------------------------------------
WORKER_SETUP = "lenslab.batch.worker_setup"  # a module every local worker runs as it starts


def local_cluster(workers: int, *, dashboard_address: str = ":0"):
    """A Dask cluster of ``workers`` processes on this machine, one task at a time each (a worker renders on one
    GL context). llvmpipe is told to share the cores among them, unless LP_NUM_THREADS says otherwise. Dask's
    scheduler always serves HTTP; by default on a free port, so that it never takes a dashboard's usual 8787.
    The workers leave Ctrl-C to this process (lenslab.batch.worker_setup says why)."""
    from distributed import LocalCluster

    env = {}
    if "LP_NUM_THREADS" not in os.environ:
        env["LP_NUM_THREADS"] = str(max(1, (os.cpu_count() or 1) // workers))
    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=dashboard_address,
                        silence_logs=logging.CRITICAL, env=env, preload=[WORKER_SETUP])


# -- the run ---------------------------------------------------------------------------------------------------
class _ShotState:
    def __init__(self, shot: Shot, futures: list):
        self.shot = shot
        self.futures = futures
        self.assembly = ShotAssembly(shot)
        self.progress: dict[int, PartProgress] = {}  # part: what it reported last (and from which process)
        self.failed = False

    def fraction(self) -> float:
        done = {r.part for r in self.assembly.results.values()}
        per_part = [1.0 if part in done else (self.progress[part].progress.fraction if part in self.progress else 0.0)
                    for part in range(self.shot.split)]
        return sum(per_part) / len(per_part)


def run_batch(shots: Iterable[Shot], client, *, force: bool = False, devices: tuple[int, ...] = (),
              on_event: Callable[[BatchEvent], None] | None = None) -> BatchSummary:
    """Render ``shots`` on ``client``'s cluster; a shot whose output exists is skipped unless ``force``.
    ``on_event`` is called on this thread with each BatchEvent. Ctrl-C cancels what is left and re-raises."""
    emit = on_event or (lambda event: None)
    done: list[Shot] = []
    skipped: list[Shot] = []
    failed: list[tuple[Shot, str]] = []
    todo = []
    for shot in shots:
        if shot.output.exists() and not force:
            skipped.append(shot)
            emit(ShotSkipped(shot))
        else:
            todo.append(shot)
    if not todo:
        return BatchSummary(tuple(done), tuple(skipped), tuple(failed))

    inbox: queue.Queue = queue.Queue()  # progress messages and finished futures, from Dask's threads
    client.subscribe_topic(PROGRESS_TOPIC, lambda event: inbox.put(("progress", event[1])))
    run_id = uuid.uuid4().hex[:8]
    states: dict[str, _ShotState] = {}
    by_key: dict[str, tuple[_ShotState, int]] = {}
    try:
        for order, shot in enumerate(todo):
            futures = []
            for part in range(shot.split):
                future = client.submit(run_part, shot, part, shot.split, tuple(devices), pure=False,
                                       key=f"lenslab-{run_id}-shot{order}-part{part}",
                                       priority=-order)  # earlier shots first; a shot's parts side by side
                futures.append(future)
            state = _ShotState(shot, futures)
            states[str(shot.output)] = state
            for part, future in enumerate(futures):
                by_key[future.key] = (state, part)
                future.add_done_callback(lambda f: inbox.put(("finished", f)))
        open_shots = len(states)
        while open_shots:
            kind, payload = inbox.get()
            if kind == "progress":
                _on_progress(states, PartProgress.from_message(payload), emit)
                continue
            state, part = by_key[payload.key]
            if state.failed or part in state.assembly.results:
                continue
            message = _failure(payload)
            if message is not None:
                state.failed = True
                client.cancel([f for f in state.futures if not f.done()])
                failed.append((state.shot, message))
                emit(ShotFailed(state.shot, message))
                open_shots -= 1
                continue
            result: PartResult = payload.result()
            state.assembly.add(result)
            if state.assembly.complete:
                open_shots -= 1
                message = _write(state.assembly)
                if message is None:
                    done.append(state.shot)
                    warnings = tuple(dict.fromkeys(itertools.chain.from_iterable(
                        r.warnings for r in state.assembly.results.values())))
                    emit(ShotDone(state.shot, state.assembly.samples_per_pixel, state.assembly.seconds, warnings))
                else:
                    failed.append((state.shot, message))
                    emit(ShotFailed(state.shot, message))
    except BaseException:
        client.cancel([f for s in states.values() for f in s.futures if not f.done()])
        raise
    finally:
        client.unsubscribe_topic(PROGRESS_TOPIC)
    return BatchSummary(tuple(done), tuple(skipped), tuple(failed))


def _on_progress(states: dict[str, _ShotState], message: PartProgress, emit) -> None:
    state = states.get(message.output)
    if state is None or state.failed or message.part in state.assembly.results:
        return  # another batch's, or late news of a finished part
    previous = state.progress.get(message.part)
    if previous is not None and previous.pid != message.pid:
        emit(PartRetried(state.shot, message.part, message.worker))  # its worker was lost; it starts again
    state.progress[message.part] = message
    running = [p for part, p in state.progress.items() if part not in state.assembly.results]
    emit(ShotProgress(state.shot, state.fraction(),
                      sum(p.progress.samples_per_pixel for p in state.progress.values()),
                      sum(p.progress.samples_per_second for p in running), tuple(p.worker for p in running)))


def _failure(future) -> str | None:
    """Why a part failed, in one line; None when it did not."""
    from distributed.scheduler import KilledWorker

    if future.status == "finished":
        return None
    if future.status == "cancelled":
        return "cancelled"
    exc = future.exception()
    if isinstance(exc, KilledWorker):
        return ("every worker that took it was lost (killed, or out of memory: see the workers' logs); "
                "the scheduler gave up after distributed.scheduler.allowed-failures tries")
    return " ".join(str(exc).split()) or type(exc).__name__


def _write(assembly: ShotAssembly) -> str | None:
    """Write a finished shot; the reason in one line if it could not be."""
    from lenslab.render.film import ExportError

    try:
        assembly.write()
    except (ExportError, OSError) as exc:
        return " ".join(str(exc).split())
    return None

