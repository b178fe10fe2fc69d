"""Running the `spiralid` console script as a user would (a subprocess)."""

import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(sys.executable).parent / "spiralid"


def cli_env(**extra) -> dict:
    return {**os.environ, "MPLBACKEND": "Agg", **extra}


def run(*args, cwd, env=None, timeout=600):
    """Run ``spiralid ARGS`` in `cwd`; return the CompletedProcess."""
    return subprocess.run(
        [str(SCRIPT), *map(str, args)],
        cwd=cwd,
        env=env or cli_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def start(*args, cwd, env=None) -> subprocess.Popen:
    """Start ``spiralid ARGS`` in `cwd` without waiting."""
    return subprocess.Popen(
        [str(SCRIPT), *map(str, args)],
        cwd=cwd,
        env=env or cli_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
