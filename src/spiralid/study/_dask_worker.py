"""Loaded by every worker of a study's local Dask cluster (Dask's
``preload``): Ctrl-C is the parent's to handle.

Ctrl-C sends SIGINT to the whole process group; a worker that acted on it
would print a traceback and die before the client closes the cluster.
"""

import signal


def dask_setup(worker) -> None:
    """Ignore SIGINT in this worker process (Dask calls it at start)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
