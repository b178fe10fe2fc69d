"""The neural state-space family on the Cascaded Tanks benchmark, beside
its linear start and the NARX trained on subsequences.

Every model is identified on the estimation record (shifted by its means,
as ``benchmarks/cascaded_tanks_narx.py`` does) and scored by the
benchmark's rule, the RMS of the free-run error on the test record after
its first 5 samples: from rest (the estimation record's mean level), and,
as the benchmark allows, with those 5 samples setting the state (the
model's encoder, ``simulate(u, y0=y)``). Rows: the linear start
(``ARX(3, 3, 1)`` by ``"oe"``, realised), ``NeuralStateSpace(3,
hidden=(8,))`` by ``"oe"`` (the default subsequence lengths, held-back
share and decay), and the NARX(2, 2, 1) with 8 units by ``"oe"`` on
subsequences.

Seconds are processor time of this process (the machine may be shared).

Usage: ``python benchmarks/cascaded_tanks_nss.py [--seeds 0-4] [--narx]``
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from _cli import seed_list

from spiralid.datasets import CASCADED_TANKS_PUBLISHED, cascaded_tanks
from spiralid.sysid import NARX, NeuralStateSpace, identify


def tanks_rms(y, test) -> float:
    """The benchmark's score: RMS of the free-run error after 5 samples."""
    return float(np.sqrt(np.mean((test.y[5:] - y[5:]) ** 2)))


def row(label: str, scores, cpu=None) -> None:
    cells = " | ".join(f"{s:.3f}" for s in scores)
    seconds = "-" if cpu is None else f"{min(cpu):.0f}-{max(cpu):.0f}"
    print(f"| {label} | {cells} | {np.median(scores):.3f} | {seconds} |", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=seed_list, default=seed_list("0-4"))
    ap.add_argument("--narx", action="store_true", help="add the NARX row")
    args = ap.parse_args()
    raw = cascaded_tanks()
    est, test = raw.detrend(), cascaded_tanks("test").detrend(like=raw)
    print("## Cascaded Tanks: test-record RMS (V), processor s per fit")
    print(
        "| model | " + " | ".join(f"seed {s}" for s in args.seeds) + " | median | s |"
    )
    print("|---|" + "---|" * (len(args.seeds) + 2))
    rest, measured, linear, cpu = [], [], [], []
    for seed in args.seeds:
        t0 = time.process_time()
        model = identify(est, NeuralStateSpace(3, hidden=(8,)), method="oe", rng=seed)
        cpu.append(time.process_time() - t0)
        rest.append(tanks_rms(model.simulate(test.u), test))
        measured.append(tanks_rms(model.simulate(test.u, y0=test.y), test))
        linear.append(tanks_rms(model.linear_start.simulate(test.u), test))
    row("linear start, ARX(3, 3, 1) by oe", linear)
    row("neural state space, from rest", rest, cpu)
    row("neural state space, 5 samples set the state", measured, cpu)
    if args.narx:
        scores, cpu = [], []
        for seed in args.seeds:
            t0 = time.process_time()
            narx = identify(
                est,
                NARX(2, 2, 1, hidden=(8,)),
                method="oe",
                training="subsequences",
                rng=seed,
            )
            cpu.append(time.process_time() - t0)
            scores.append(tanks_rms(narx.simulate(test.u), test))
        row("NARX(2, 2, 1) by oe, subsequences", scores, cpu)
    best = ", ".join(f"{k} {v}" for k, v in CASCADED_TANKS_PUBLISHED.items())
    print(f"\nPublished: {best}")


if __name__ == "__main__":
    main()
