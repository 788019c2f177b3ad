"""Set-up that runs in each of a local batch's Dask worker processes as it starts (a Dask preload).

Ctrl-C belongs to ``lenslab batch`` itself. A terminal sends its SIGINT to the whole foreground process group,
the worker processes of the batch's LocalCluster included. The batch's own process handles it: it reports
that every finished shot is written, exits with 130 and closes the cluster, which ends the workers. A worker
that took the SIGINT itself would stop its event loop and print a KeyboardInterrupt traceback of Dask's
internals over that message, or not, depending on which process got there first.
"""

from __future__ import annotations

import signal


def dask_setup(worker) -> None:
    """Called by Dask in the worker process's main thread, before the worker takes any task."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
