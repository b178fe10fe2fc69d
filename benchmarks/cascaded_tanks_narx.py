"""NARX training on subsequences against the free run, on the Cascaded
Tanks benchmark and on the nonlinear rig's end acceleration.

Cascaded Tanks (``spiralid.datasets.cascaded_tanks``): every model is
identified on the estimation record (shifted by its means, as
``benchmarks/real_records.py`` does) and scored by the benchmark's rule,
the RMS of the free-run error on the test record after its first 5 samples
(the free run starts from rest, the estimation record's mean level). The
rows: the linear model by output error (``ARX(2, 2, 1)``, method
``"oe"``), the NARX(2, 2, 1) with 8 tanh units by the default method
(free-run training, then on subsequences), by ``"oe"`` on the free run,
and by ``"oe"`` on subsequences (``training="subsequences"``: the default
held-back share in 10 blocks; and ``holdout=0``, 30 rounds a stage, no
early stopping); and, with ``--rows default-none,oe-sub-none``, the
default method and ``"oe"`` on subsequences with ``refit="none"`` (the
early-stopped network without the replay on the whole record).

Nonlinear rig (``--rig``): the paper's experiment on the nonlinear rig,
end acceleration, estimation on the first two thirds, validation fit on
the last, as ``benchmarks/nonparametric.py --goals``: the default ARX(8, 8,
0) against NARX(8, 8, 0) (10 units) by the default method (or
``--method``) with ``training="subsequences"``; the goal is the ARX fit
plus min(5, half the remaining misfit).

Seconds are processor time of this process (the machine is shared).

Usage: ``python benchmarks/cascaded_tanks_narx.py [--seeds 0-4] [--rows
oe-sub,oe-sub-all] [--rig [--method oe]]``
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
from spiralid.sysid import ARX, NARX, fit_percent, identify

SUB = {"method": "oe", "training": "subsequences"}
ROWS = {
    "arx-oe": ("ARX(2, 2, 1) by oe", lambda: ARX(2, 2, 1), {"method": "oe"}),
    "default": ("NARX, default method", lambda: NARX(2, 2, 1, hidden=(8,)), {}),
    "oe": (
        "NARX by oe, free run",
        lambda: NARX(2, 2, 1, hidden=(8,)),
        {"method": "oe"},
    ),
    "sub": (
        "NARX, default method, subsequences",
        lambda: NARX(2, 2, 1, hidden=(8,)),
        {"training": "subsequences"},
    ),
    "oe-sub": ("NARX by oe, subsequences", lambda: NARX(2, 2, 1, hidden=(8,)), SUB),
    "default-none": (
        "NARX, default method, refit='none'",
        lambda: NARX(2, 2, 1, hidden=(8,)),
        {"refit": "none"},
    ),
    "oe-sub-none": (
        "NARX by oe, subsequences, refit='none'",
        lambda: NARX(2, 2, 1, hidden=(8,)),
        {**SUB, "refit": "none"},
    ),
    "oe-sub-all": (
        "NARX by oe, subsequences, holdout=0",
        lambda: NARX(2, 2, 1, hidden=(8,)),
        {**SUB, "holdout": 0.0, "max_rounds": 30},
    ),
}


def tanks_rms(model, test) -> float:
    """The benchmark's score: RMS of the free-run error after 5 samples."""
    y = model.simulate(test.u)
    return float(np.sqrt(np.mean((test.y[5:] - y[5:]) ** 2)))


def tanks(rows, seeds) -> None:
    raw = cascaded_tanks()
    est, test = raw.detrend(), cascaded_tanks("test").detrend(like=raw)
    print("## Cascaded Tanks: test-record RMS (V), processor s per fit")
    print("| model | " + " | ".join(f"seed {s}" for s in seeds) + " | median | s |")
    print("|---|" + "---|" * (len(seeds) + 2))
    for key in rows:
        label, structure, options = ROWS[key]
        scores, cpu = [], []
        for seed in seeds:
            t0 = time.process_time()
            model = identify(est, structure(), rng=seed, **options)
            cpu.append(time.process_time() - t0)
            scores.append(tanks_rms(model, test))
            if key == "arx-oe":  # the linear model does not depend on the seed
                scores *= len(seeds)
                break
        cells = " | ".join(f"{s:.3f}" for s in scores)
        print(
            f"| {label} | {cells} | {np.median(scores):.3f} | "
            f"{min(cpu):.0f}-{max(cpu):.0f} |",
            flush=True,
        )
    best = ", ".join(f"{k} {v}" for k, v in CASCADED_TANKS_PUBLISHED.items())
    print(f"\nPublished: {best}")


def rig(seeds, method: str) -> None:
    from spiralid.fms import nonlinear_rig, paper_experiment

    print("\n## Nonlinear rig, end acceleration: validation fit %")
    print("| seed | ARX | NARX, subsequences | gain | target | met | s |")
    print("|---|---|---|---|---|---|---|")
    met = 0
    for seed in seeds:
        data = paper_experiment().run(rig=nonlinear_rig(), rng=seed)
        data = data.iodata("end_acceleration")
        est, val = data.split(2 / 3)
        arx = identify(est, ARX(8, 8, 0), rng=seed)
        t0 = time.process_time()
        narx = identify(
            est, NARX(8, 8, 0), method=method, training="subsequences", rng=seed
        )
        cpu = time.process_time() - t0
        fa = fit_percent(val.y, arx.simulate(data.u)[est.n :])
        fn = fit_percent(val.y, narx.simulate(data.u)[est.n :])
        target = fa + min(5.0, (100.0 - fa) / 2)
        met += fn >= target
        print(
            f"| {seed} | {fa:.2f} | {fn:.2f} | {fn - fa:+.2f} | {target:.2f} | "
            f"{'yes' if fn >= target else 'no'} | {cpu:.0f} |",
            flush=True,
        )
    print(f"\nGoal met on {met} of {len(seeds)} seeds.")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=seed_list, default=seed_list("0-4"))
    ap.add_argument("--rows", default=",".join(ROWS))
    ap.add_argument("--rig", action="store_true", help="the rig's table only")
    ap.add_argument("--method", default="spiral", help="the rig's NARX method")
    args = ap.parse_args()
    if args.rig:
        rig(args.seeds, args.method)
        return
    tanks(args.rows.split(","), args.seeds)


if __name__ == "__main__":
    main()
