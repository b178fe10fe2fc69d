"""The gallery's examples (examples/plot_*.py) run to the end as plain scripts.

Each runs in a subprocess with matplotlib's Agg backend, from a scratch
folder, and must exit with status 0. They are marked slow (a few seconds to
half a minute each): the documentation build executes them too.

BLAS is pinned to one thread, as the benchmarks pin it: on a shared 2-core
machine a threaded OpenBLAS makes the small least-squares problems that
output error and the polishes solve many times slower, and a run that is
merely slow is not what this test is about.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from patience import allowance

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SCRIPTS = sorted(EXAMPLES.glob("plot_*.py"))


def test_there_are_examples():
    assert len(SCRIPTS) >= 8, SCRIPTS


@pytest.mark.slow
@pytest.mark.parametrize("script", SCRIPTS, ids=[s.stem for s in SCRIPTS])
def test_example_runs(script, tmp_path):
    env = {
        **os.environ,
        "MPLBACKEND": "Agg",
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
    }
    proc = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        # Only stops a hang: seconds on an unloaded machine, scaled by the
        # machine's measured slowness (see patience.py).
        timeout=allowance(300),
    )
    assert proc.returncode == 0, (
        f"{script.name} exited with {proc.returncode}\n"
        f"--- stdout ---\n{proc.stdout[-3000:]}\n--- stderr ---\n{proc.stderr[-3000:]}"
    )
    assert proc.stdout.strip(), f"{script.name} printed nothing"
