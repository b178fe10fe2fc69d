"""Issue 27, "Lower cost, worse model": on a record with drift the default
method keeps every pole inside the stability margin and validates about as
well as output error.

The record is benchmarks/drift.py's: two lightly damped modes (3 and 11 Hz)
driven by white noise, a random walk at 3 % of the output's RMS, 1500
samples, the first 2/3 estimate, the last 1/3 validates (after the
estimation part, as ``spiralid identify`` validates). Without the margin
the default put a pole at |z| = 0.99995-1 on 7 of 10 seeds at ARX(8, 8, 0).
Judged over ten seeds (a chaotic search: docs/design-notes.md): the margin
holds on every one by construction; the default is within one point of
OE's fit on 9 of 10 at ARX(8, 8, 0) when measured (seed 3 is the exception:
three real poles below 0.5 Hz with zeros within the record's resolution fit
the drift, each worth more than 1 % of the cost, so none is cancelled) and
on all at ARX(4, 4, 0); the test allows one more miss.
"""

import importlib.util
from functools import cache
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).parents[2] / "benchmarks" / "drift.py"
SEEDS = range(10)


def _drift():
    spec = importlib.util.spec_from_file_location("drift_benchmark", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


DRIFT = _drift()


@cache
def _rows(order: int) -> dict:
    return {
        (seed, name): DRIFT.run_one((seed, order, name))
        for seed in SEEDS
        for name in ("default", "OE")
    }


@pytest.mark.slow
@pytest.mark.parametrize("order", [4, 8])
def test_no_pole_is_slower_than_the_estimation_record(order):
    rows = _rows(order)
    outside = [
        (key, row["radius"], row["r_max"])
        for key, row in rows.items()
        if not row["radius"] <= row["r_max"]
    ]
    assert not outside
    # r_max is exp(-ts / T) with T the estimation part's length, N ts.
    est = DRIFT.record(0).split(DRIFT.FRACTION)[0]
    assert rows[(0, "default")]["r_max"] == pytest.approx(np.exp(-1.0 / est.n))


@pytest.mark.slow
@pytest.mark.parametrize(("order", "least"), [(4, 10), (8, 8)])
def test_the_default_validates_about_as_well_as_output_error(order, least):
    rows = _rows(order)
    held = [rows[(s, "default")]["fit"] >= rows[(s, "OE")]["fit"] - 1.0 for s in SEEDS]
    assert sum(held) >= least, [
        (s, rows[(s, "default")]["fit"], rows[(s, "OE")]["fit"]) for s in SEEDS
    ]
