"""Running the `spiralid` console script as a user would (a subprocess)."""

import os
import signal
import subprocess
import sys
from pathlib import Path

from patience import allowance, slowness

SCRIPT = Path(sys.executable).parent / "spiralid"


def cli_env(**extra) -> dict:
    return {**os.environ, "MPLBACKEND": "Agg", **extra}


def run(*args, cwd, env=None, timeout=600):
    """Run ``spiralid ARGS`` in `cwd`; return the CompletedProcess.

    `timeout` only stops a hang: seconds on an unloaded machine, scaled by
    the machine's measured slowness (see patience.py)."""
    timeout = allowance(timeout)
    return subprocess.run(
        [str(SCRIPT), *map(str, args)],
        cwd=cwd,
        env=env or cli_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def _as_from_a_terminal() -> None:
    # A shell starts background jobs with SIGINT ignored, and the command
    # keeps an ignored SIGINT (as every Unix program should): reset it, so
    # that these tests see what a user at a terminal sees however pytest
    # itself was started.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(*args, cwd, env=None, new_group=False) -> subprocess.Popen:
    """Start ``spiralid ARGS`` in `cwd` without waiting; with `new_group`,
    in a process group of its own (as a shell's job: Ctrl-C signals the
    whole group, workers included)."""
    slowness()  # measured now, before the run competes with the measurement
    return subprocess.Popen(
        [str(SCRIPT), *map(str, args)],
        cwd=cwd,
        env=env or cli_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_as_from_a_terminal,
        process_group=0 if new_group else None,
    )
