"""Does the spiral have a job in NARX? Two candidates against gradient training.

(a) **The spiral over the weights, no gradient step.** The learned-metric
rule over the weights of small networks, NARX(2, 2, 1, hidden=(4,))
(29 weights) and NARX(4, 4, 1, hidden=(8,)) (89 weights), from the uniform
box (``identify(method="learned-metric")``) and seeded with the linear
start (the default method's ARX in the bypass, the box widened to hold it,
as ``"spiral"`` seeds Eb-SDA; a prototype here, see ``seeded_search``),
against the gradient baseline ``"oe"`` and the default ``"spiral"``
(Eb-SDA seeded, memetic polish). The searches get the same budget of
``--budget`` cost evaluations (a free run of the network each).

(b) **The spiral over the choices.** ``choose_narx``
(:mod:`spiralid.sysid.estimation.narx.choice`): a learned-metric search
over the lags (1-8), hidden units (1-16) and log10 weight decay (-5 to -1,
half decades), each point a gradient (``"oe"``) training on the first 3/4
of the estimation record scored by its free-run fit on the last 1/4; the
best refitted on the whole estimation record. Against: ``choose_order``
over a plain grid of the same number of trainings (lags 2, 4, 8 x hidden
2, 4, 8, 16, decay 1e-3, the same split, the smallest model within 1 point
of the best, refitted), a random search of the same number of trainings
over the same box (same score and refit), and the default NARX
(``identify(est, NARX(4, 4, 1))``: 10 units, method ``"spiral"``).

Records (as benchmarks/nonparametric.py): the nonlinear rig
(:func:`spiralid.fms.nonlinear_rig`) driven by a multilevel torque of
+-0.6 N m, 6 s at 500 Hz, default sensors; end-point acceleration and the
hub angle (models with one integrator). Split 2/3 estimation, 1/3
validation; every model runs free from rest over the whole record and is
scored on the validation third, which neither the training nor any choice
saw. A diverging free run counts as -999.

Printed: median validation fit % over the seeds with quartiles, median
seconds per fit (per whole choice in (b)), every seed's fit, and the load
average. The defaults (10 seeds for (a), 6 for (b)) are what
docs/results/narx.md shows: 4.1 and 13.6 min of CPU, 7.5 and 22.5 min of
wall time on 2 workers at load averages of 2.5-9 and 6-8 on 2 cores (each
worker got about a third of a core); ``--seeds-b 3``
halves (b).

Usage: ``python benchmarks/narx_spiral.py [--seeds 10] [--seeds-b 6]
[--workers 2] [--part a|b|ab] [--budget 3000] [--trainings 12]``
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

from spiralid.fms import Sensors, multilevel, nonlinear_rig
from spiralid.optim import minimize
from spiralid.sysid import NARX, IOData, choose_order, fit_percent, identify

RECORDS = ("nonlinear acc", "nonlinear hub")
SMALL = {"29 w": (2, 4), "89 w": (4, 8)}  # name: (lags, hidden units)


def record(name: str, seed: int) -> IOData:
    u = multilevel(0.6, 6.0, 500.0, min_hold=0.01, max_hold=0.05, rng=seed)
    rec = nonlinear_rig().simulate(
        u, rng=1000 + seed, sensors=Sensors(accel_noise=0.05)
    )
    return rec.iodata("hub_angle" if name.endswith("hub") else "end_acceleration")


def val_fit(model, data: IOData, n_est: int) -> float:
    y = model.simulate(data.u)[n_est:]
    if not np.all(np.isfinite(y)):
        return -999.0
    return max(fit_percent(data.y[n_est:], y), -999.0)


# -- (a) the spiral over the weights ------------------------------------------


def seeded_search(problem, *, rule: str = "learned-metric", max_nfev: int = 3000):
    """A spiral rule over the weights whose first population holds the
    linear start (hidden weights Glorot, output weights zero: the map is
    the linear model's), in the box widened to hold it; no gradient step.
    The NARX estimator protocol of identify_narx (``estimate(problem,
    **options)``)."""
    from spiralid.sysid.estimation.narx import starts as narx_starts
    from spiralid.sysid.estimation.narx import training as nx

    t0 = time.perf_counter()
    linear, what = narx_starts._linear_start(problem)
    start = narx_starts._starting_network(problem, linear)
    box = nx.default_box(problem, [start])
    raw = minimize(
        problem.objective,
        box,
        method=rule,
        rng=problem.rng,
        vectorized=True,
        x0=np.clip(start, box[:, 0], box[:, 1])[None, :],
        max_nfev=max_nfev,
        max_iter=max_nfev,
    )
    return nx.narx_result(
        problem,
        raw.x,
        t0,
        nit=int(raw.nit),
        linear_params=linear,
        linear_model=what,
        message=str(raw.message),
    )


def fit_weights(method: str, est: IOData, st: NARX, seed: int, budget: int):
    from spiralid.sysid.estimation.core.families import _default_arx
    from spiralid.sysid.estimation.narx.training import identify_narx

    if method.startswith("learned-metric, seeded"):
        if method.endswith("x budget"):
            budget *= int(method.split()[-3])
        return identify_narx(
            est,
            st,
            method="learned-metric",
            estimate=seeded_search,
            linear_estimator=_default_arx,
            rng=seed,
            max_nfev=budget,
        )
    opts = {} if method == "oe" else {"max_nfev": budget}
    return identify(est, st, method=method, rng=seed, **opts)


WEIGHT_METHODS = (
    "linear start (ARX)",
    "oe",
    "spiral",
    "learned-metric",
    "learned-metric, seeded",
    "learned-metric, seeded, 3 x budget",
)


class _Linear:
    """The linear start of a NARX fit as a model that runs free."""

    def __init__(self, model):
        self.model = model

    def simulate(self, u):
        from spiralid.sysid.models.narx import simulate_structure

        m = self.model
        return simulate_structure(m.structure, m.linear_params, m.scaling, u)


def run_a(job):
    name, seed, budget = job
    warnings.simplefilter("ignore")
    data = record(name, seed)
    est, _ = data.split(2 / 3)
    k = int(name.endswith("hub"))
    rows = []
    for size, (n, h) in SMALL.items():
        st = NARX(n, n, 1, hidden=(h,), integrator=k)
        for m in WEIGHT_METHODS[1:]:
            t0 = time.perf_counter()
            model = fit_weights(m, est, st, seed, budget)
            wall = time.perf_counter() - t0
            nfev = int(model.result.get("nfev", 0))
            if m == "oe":
                fit = val_fit(_Linear(model), data, est.n)
                rows.append((name, size, WEIGHT_METHODS[0], seed, fit, 0.0, 0))
            rows.append((name, size, m, seed, val_fit(model, data, est.n), wall, nfev))
    return rows


# -- (b) the spiral over the choices ------------------------------------------

GRID = [(n, h) for n in (2, 4, 8) for h in (2, 4, 8, 16)]
BOX = dict(lags=(1, 8), hidden=(1, 16), log_decay=(-5.0, -1.0))
HOLDBACK = 0.25


def _split(est: IOData):
    split = est.n - round(HOLDBACK * est.n)
    train = IOData(est.u[:split], est.y[:split], ts=est.ts)
    end = IOData(est.u[split:], est.y[split:], ts=est.ts)
    return train, end


def grid_choice(est: IOData, k: int, seed: int, trainings: int):
    """choose_order over the first `trainings` grid points (decay 1e-3),
    trained on the first 3/4 and chosen on the last 1/4, then refitted."""
    train, end = _split(est)
    grid = GRID[:trainings]
    models = [
        identify(train, NARX(n, n, 1, hidden=(h,), integrator=k), method="oe", rng=seed)
        for n, h in grid
    ]
    n, h = grid[choose_order(models, end, warmup=train, tolerance=1.0)]
    st = NARX(n, n, 1, hidden=(h,), integrator=k)
    return identify(est, st, method="oe", rng=seed), (n, h, -3.0)


def random_choice(est: IOData, k: int, seed: int, trainings: int):
    """`trainings` distinct uniform choices in choose_narx's box, each
    scored as choose_narx scores them; the best refitted."""
    from spiralid.sysid.estimation.core.choices import held_back_fit as _held_back_fit
    from spiralid.sysid.estimation.narx.choice import round_choice

    rng = np.random.default_rng(seed)
    train, end = _split(est)
    lo = np.array([0.5, 0.5, -10.5])
    hi = np.array([8.5, 16.5, -1.5])
    seen: dict = {}
    tries = 0
    while len(seen) < trainings and tries < 100 * trainings:
        tries += 1
        key = round_choice(rng.uniform(lo, hi), **BOX)
        if key in seen:
            continue
        n, h, d = key
        st = NARX(n, n, 1, hidden=(h,), integrator=k)
        m = identify(train, st, method="oe", decay=10.0**d, rng=seed)
        seen[key] = _held_back_fit(end.y, m.simulate(est.u)[train.n :])
    (n, h, d), _ = max(seen.items(), key=lambda kv: kv[1])
    st = NARX(n, n, 1, hidden=(h,), integrator=k)
    return identify(est, st, method="oe", decay=10.0**d, rng=seed), (n, h, d)


def spiral_choice(est, k, seed, trainings, rule="learned-metric"):
    from spiralid.sysid.estimation.narx.choice import choose_narx

    res = choose_narx(
        est,
        **BOX,
        budget=trainings,
        holdback=HOLDBACK,
        integrator=k,
        rule=rule,
        rng=seed,
    )
    return res.model, tuple(res.x)


def ebsda_choice(est: IOData, k: int, seed: int, trainings: int):
    return spiral_choice(est, k, seed, trainings, rule="ebsda")


def default_narx(est: IOData, k: int, seed: int, trainings: int):
    return identify(est, NARX(4, 4, 1, integrator=k), rng=seed), (4, 10, -3.0)


CHOICES = {
    "default NARX(4, 4, 1), 10 units, spiral": default_narx,
    "grid + choose_order": grid_choice,
    "random search": random_choice,
    "choose_narx (learned-metric)": spiral_choice,
    "choose_narx (Eb-SDA)": ebsda_choice,
}


def run_b(job):
    name, seed, trainings = job
    warnings.simplefilter("ignore")
    data = record(name, seed)
    est, _ = data.split(2 / 3)
    k = int(name.endswith("hub"))
    rows = []
    for label, fn in CHOICES.items():
        t0 = time.perf_counter()
        model, choice = fn(est, k, seed, trainings)
        wall = time.perf_counter() - t0
        rows.append((name, label, seed, val_fit(model, data, est.n), wall, choice))
    return rows


# -- tables -------------------------------------------------------------------


def _stats(fits) -> str:
    q1, med, q3 = np.percentile(np.asarray(fits, dtype=float), [25, 50, 75])
    return f"{med:.1f} | [{q1:.1f}, {q3:.1f}]"


def table_a(rows) -> None:
    print("\n## (a) spiral over the weights, no gradient step")
    print("| record | network | method | median fit % | quartiles | median s | nfev |")
    print("|---|---|---|---|---|---|---|")
    for name in dict.fromkeys(r[0] for r in rows):
        for size in SMALL:
            for m in WEIGHT_METHODS:
                sel = [r for r in rows if r[:3] == (name, size, m)]
                print(
                    f"| {name} | {size} | {m} | {_stats([r[4] for r in sel])} | "
                    f"{np.median([r[5] for r in sel]):.2f} | "
                    f"{np.median([r[6] for r in sel]):.0f} |"
                )
    print("\nPer seed (fit %):")
    for r in rows:
        print(f"#   {r[0]} {r[1]} seed {r[3]} {r[2]}: {r[4]:.2f}")


def table_b(rows) -> None:
    print("\n## (b) spiral over lags, hidden units and decay")
    print(
        "| record | choice | median fit % | quartiles | median s | chosen (n, h, d) |"
    )
    print("|---|---|---|---|---|---|")
    for name in dict.fromkeys(r[0] for r in rows):
        for label in CHOICES:
            sel = [r for r in rows if r[:2] == (name, label)]
            chosen = "; ".join(
                f"({c[0]:.0f}, {c[1]:.0f}, {c[2]:.1f})" for c in (r[5] for r in sel)
            )
            print(
                f"| {name} | {label} | {_stats([r[3] for r in sel])} | "
                f"{np.median([r[4] for r in sel]):.1f} | {chosen} |"
            )
    print("\nPer seed (fit %):")
    for r in rows:
        print(f"#   {r[0]} seed {r[2]} {r[1]}: {r[3]:.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10, help="seeds of (a)")
    ap.add_argument("--seeds-b", type=int, default=6, help="seeds of (b)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--part", default="ab")
    ap.add_argument("--records", default=",".join(RECORDS))
    ap.add_argument("--budget", type=int, default=3000, help="evaluations, (a)")
    ap.add_argument("--trainings", type=int, default=12, help="trainings, (b)")
    args = ap.parse_args()
    names = [r.strip() for r in args.records.split(",")]
    t_all = time.perf_counter()
    print(f"# load average at start: {os.getloadavg()}")

    def run(fn, jobs):
        if args.workers > 1:
            from multiprocessing import get_context

            with get_context("spawn").Pool(args.workers) as pool:
                return [r for res in pool.map(fn, jobs, chunksize=1) for r in res]
        return [r for j in jobs for r in fn(j)]

    if "a" in args.part:
        t0 = time.perf_counter()
        jobs = [(n, s, args.budget) for n in names for s in range(args.seeds)]
        rows = run(run_a, jobs)
        print(f"# (a): {args.seeds} seeds, {time.perf_counter() - t0:.0f} s wall")
        table_a(rows)
    if "b" in args.part:
        t0 = time.perf_counter()
        jobs = [(n, s, args.trainings) for n in names for s in range(args.seeds_b)]
        rows = run(run_b, jobs)
        print(f"\n# (b): {args.seeds_b} seeds, {time.perf_counter() - t0:.0f} s wall")
        table_b(rows)
    print(
        f"\n# total {time.perf_counter() - t_all:.0f} s wall, "
        f"{args.workers} workers; load average at end: {os.getloadavg()}"
    )


if __name__ == "__main__":
    main()
