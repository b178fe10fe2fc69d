"""Waiting in tests: for an event, with a safety net scaled to the machine.

A test that runs the command in a subprocess waits for something to happen
(a file appears, a process group empties, a row is stored), never for a
fixed time: on a shared CI machine (load 5-15 on 2 cores) a run takes ten
times as long as here, and a fixed sleep or timeout then either misses the
moment or gives up on a run that was merely slow.

A deadline is still needed as a safety net, so that a run that hangs fails
the test instead of the CI job's own timeout; it is never what the test
measures. Each deadline is given in seconds as generous for an unloaded
machine (several times the time the wait takes here) and multiplied by
:func:`slowness`: how much longer than on an unloaded machine a fixed small
workload took, measured once per session in a subprocess (process start,
NumPy and SciPy imports, the small QR factorisations and the plain Python
loop the command spends its time in; a threaded BLAS on a loaded machine
slows down far more than a plain loop does, and so does the command). The
load can rise after that measurement, so a wait that reaches its deadline
measures again and extends the deadline if the machine has become slower.
"""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Callable

import pytest

_WORKLOAD = """
import numpy as np
from scipy.linalg import qr
a = np.random.default_rng(0).standard_normal((1000, 16))
for _ in range(40):
    qr(a, mode="economic", check_finite=False)
x = 0
for i in range(200_000):
    x += i % 7
"""

# What `_WORKLOAD` takes on an unloaded 2-core machine (0.35-0.5 s here).
REFERENCE_SECONDS = 0.5


def _measure() -> float:
    start = time.monotonic()
    subprocess.run([sys.executable, "-c", _WORKLOAD], check=True)
    return max(1.0, (time.monotonic() - start) / REFERENCE_SECONDS)


_factor: float | None = None


def slowness(again: bool = False) -> float:
    """How many times slower than an unloaded machine this one is now (at
    least 1): measured on first use (a fraction of a second unloaded), and
    measured `again` on request, keeping the larger factor."""
    global _factor
    if _factor is None or again:
        _factor = max(_factor or 1.0, _measure())
    return _factor


def allowance(seconds: float) -> float:
    """`seconds` (a safety net sized for an unloaded machine) scaled by
    :func:`slowness`: for a ``timeout=`` that only stops a hang."""
    return seconds * slowness()


def until(predicate: Callable[[], bool], seconds: float, interval: float) -> bool:
    """Poll `predicate` every `interval` seconds until it holds (True) or the
    safety net of ``allowance(seconds)`` runs out, measured again once
    before giving up (False)."""
    start = time.monotonic()
    remeasured = False
    while True:
        if predicate():
            return True
        if time.monotonic() > start + allowance(seconds):
            if remeasured:
                return False
            remeasured = True
            slowness(again=True)
            continue
        time.sleep(interval)


def wait_for(
    predicate: Callable[[], bool],
    what: str,
    *,
    proc: subprocess.Popen | None = None,
    seconds: float = 120.0,
    interval: float = 0.005,
) -> None:
    """Wait for the event `predicate` tests (`what` names it); fail the test
    if `proc` ends first, or kill `proc` and fail at the safety net."""
    ended: list[tuple] = []

    def happened() -> bool:
        if predicate():
            return True
        if proc is not None and proc.poll() is not None:
            ended.append(proc.communicate())
            return True
        return False

    if not until(happened, seconds, interval):
        if proc is not None:
            proc.kill()
            proc.communicate()
        pytest.fail(f"{what}: not after {allowance(seconds):.0f} s")
    if ended:
        pytest.fail(f"the run ended before {what}: {ended[0]}")
