"""Helpers the test modules share (fixtures are in conftest.py): running the command line in-process, and rendering
a session to a number of samples per pixel."""

from __future__ import annotations

from lenslab.cli import main
from lenslab.render.job import RenderJob
from lenslab.render.tracer import RenderSession


class CliRun(tuple):
    """What :func:`run_cli` saw: unpacks (and indexes) as ``(status, err)``, the exit status and stderr, which is
    what most tests look at; stdout is ``.out``."""

    def __new__(cls, status: int, err: str, out: str):
        run = super().__new__(cls, (status, err))
        run.out = out
        return run

    @property
    def status(self) -> int:
        return self[0]

    @property
    def err(self) -> str:
        return self[1]


def run_cli(capsys, *argv) -> CliRun:
    """Run ``lenslab`` with ``argv`` (each turned to a string: paths are welcome) in this process."""
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return CliRun(status, captured.err, captured.out)


def render_to_spp(session: RenderSession, spp: int) -> RenderSession:
    """Render ``session`` until every pixel has ``spp`` samples, as a :class:`~lenslab.render.job.RenderJob` does
    (``RenderJob.of_session``: a session the test made itself, with another size, kernel, view or region than a
    job makes from the scene, or one it has edited); the session, for its image. How the work is split into
    dispatches does not change the image (tests/test_integrator.py checks that)."""
    RenderJob.of_session(session, spp=spp).render()  # the caller reads back what it needs
    return session
