"""Which spiral identification delivers usable models, and what each
ingredient contributes.

Records (ARX(8, 8, 0), first 2/3 estimates, last 1/3 validates):

- ``rig``: the default rig record of ``spiralid reproduce``
  (``spiralid.reproduction.default_data()``: bang-bang experiment, end-point
  acceleration, 500 Hz).
- ``rig-long``: a 1.2 m beam instead of 0.9 m (modes move down).
- ``rig-payload``: a 0.1 kg payload at the tip.
- ``rig-noisy``: accelerometer noise 5 m/s^2 instead of 1.
- ``arm``: the real flexible arm (DaISy 96-009), ``ts = 0.01``, from rest.
- ``rig-8000``: the rig's experiment four times as long (24 pulses, 12,000
  samples: 8,000 estimate), for the scaling table.

Methods, each at the same budget of cost evaluations (default 20,000; 50
points):

- ``SDA``, ``Eb-SDA``: the paper's, raw coefficients with the penalty.
- ``modal``: Eb-SDA over the modal denominator and the raw numerator
  (16 coordinates), no projection.
- ``VP``: Eb-SDA over reflection coefficients, numerator projected out.
- ``modal+VP`` (SDA and Eb-SDA): modal denominator, numerator projected.
- ``modal+VP+restart``: the same with restarts after 20 stalled iterations.
- ``modal+VP+fseed``: 25 of the 50 first points at the frequency
  response's peaks.
- ``modal+VP+safe``: the first population holds the stabilised LS,
  Steiglitz-McBride and zero models.
- ``modal+VP+memetic``: Levenberg-Marquardt polish of the centre every 5
  iterations (10 evaluations each).
- ``spiral (no gradient)``: restarts and safe starts, no polish.
- ``Eb-SDA+fseed (no gradient)``: ``spiral``'s search (Eb-SDA, restarts
  after 20 stalled iterations) with 25 first points at the frequency
  response's peaks, no polish and no safe start: the comparison for the
  learned-metric rows below.
- ``learned-metric (modal+VP)``: the learned-metric spiral
  (``spiralid.optim.LearnedMetricSpiral``) over the modal coordinates,
  numerator projected out, with its restarts (polls and population
  periods); nothing else.
- ``learned-metric (no gradient)``: ``spiral``'s search with the
  learned-metric rule, restarts after 20 stalled periods, no polish and no
  safe start (no least-squares or Steiglitz-McBride model anywhere).
- ``learned-metric+fseed (no gradient)``: the same with 25 first points at
  the frequency response's peaks (the best of them starts the first poll).
- ``spiral``: the recommended method, ``identify(method="spiral")`` at its
  default budget of 10,000 evaluations: Eb-SDA, modal, VP, memetic,
  restarts, safe starts.
- ``spiral (learned-metric)``: the same with the learned-metric rule.
- ``DE``: SciPy's differential evolution over the paper's cost.
- ``CMA-ES``: pycma (``cma``, the ``bench`` extra) over the paper's cost in
  raw coefficients, started at the stabilised least-squares estimate with
  ``sigma0 = 0.1`` and per-coordinate scales the half-widths of the default
  box (so the first steps span 10 % of the box), ``popsize`` 13 (its default
  for 16 coordinates).
- ``CMA-ES (modal+VP)``: pycma over the same 8 modal coordinates and
  projected cost as ``modal+VP``, started at the box centre, ``sigma0 =
  0.3`` in coordinates scaled to the unit box, bounded to the box.
- ``OE``: output error (``identify(method="oe")``), deterministic.

Prints per record: median and worst estimation cost as a ratio to OE's,
seeds within 1 % of OE's cost (or below), median validation fit % (free run
from rest over the whole record, scored on the last third), median wall
time per identification, and the machine load.

Scaling with the order (``--scaling``): ``spiral`` (default budget, seeds
0..``--seeds``-1, ``stop`` from ``--stop``: ``work``, its default,
``converged``, the default before it, or ``budget``, the whole budget),
each identification run ``--repeats`` times (the median time), OE and LS at
ARX(n, n, 0) for n in
``--orders`` (default 2, 4, 8, 12, 16, 24, 32) on ``rig`` and ``rig-8000``;
median time, cost as a ratio to OE's (after the pole-zero cancellation,
which both apply), spiral's time as a ratio to OE's, and the growth
exponent ``k`` of ``time ~ n^k`` fitted by least squares on log-log over
n >= 4. Times are the process's processor seconds (BLAS on one thread),
which other jobs on a shared machine disturb far less than wall time.

Run: ``python benchmarks/identification.py [--seeds 20] [--budget 20000]
[--records rig,arm] [--methods spiral,OE] [--workers 2] [--jsonl runs.jsonl]``;
``--summarise runs.jsonl`` prints the tables of a finished or partial run.
BLAS is pinned to one thread: on a shared machine OpenBLAS threads
oversubscribe and small dense kernels get tens of times slower.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import dataclasses
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from spiralid.optim import Restarts, minimize
from spiralid.sysid import ARX, IOData, PaperCost, identify
from spiralid.sysid.estimation.core.identify import default_bounds
from spiralid.sysid.estimation.linear.modal import ModalParametrization
from spiralid.sysid.estimation.linear.varpro import ProjectedCost
from spiralid.sysid.estimation.spiral.projected import projected_spiral
from spiralid.sysid.estimation.spiral.recommended import SPIRAL_STOPS
from spiralid.sysid.models.polynomials import fold_reflection, step_up
from spiralid.sysid.validation.validate import fit_percent

ARX_8 = ARX(8, 8, 0)
RECORDS = ("rig", "rig-long", "rig-payload", "rig-noisy", "arm", "rig-8000")
SCALING_ORDERS = (2, 4, 8, 12, 16, 24, 32)


# -- records -------------------------------------------------------------------


def load_record(name: str, arm_csv: str | None = None) -> IOData:
    """The whole record (estimation is its first 2/3)."""
    from spiralid.fms import FlexibleManipulator, paper_experiment

    if name == "rig":
        from spiralid.reproduction import default_data

        return default_data()
    if name == "rig-long":
        return (
            paper_experiment()
            .run(FlexibleManipulator(length=1.2), rng=0)
            .iodata("end_acceleration")
        )
    if name == "rig-payload":
        return (
            paper_experiment()
            .run(FlexibleManipulator(payload_mass=0.1), rng=0)
            .iodata("end_acceleration")
        )
    if name == "rig-8000":
        exp = dataclasses.replace(paper_experiment(), duration=24.0, n_pulses=24)
        return exp.run(rng=0).iodata("end_acceleration")
    if name == "rig-noisy":
        exp = dataclasses.replace(paper_experiment(), accel_noise=5.0)
        return exp.run(rng=0).iodata("end_acceleration")
    if name == "arm":
        if arm_csv is not None:
            return IOData.from_csv(arm_csv, input="u", output="y", ts=0.01)
        from spiralid.datasets import robot_arm

        return robot_arm()
    raise ValueError(f"`record` must be one of {RECORDS}; got {name!r}")


# -- methods -------------------------------------------------------------------


class _Reflection:
    """Reflection coefficients of the denominator (for VP without modal)."""

    def __init__(self, na: int) -> None:
        self.bounds = np.tile([-1.0, 1.0], (na, 1))

    def to_denominator(self, x):
        return step_up(fold_reflection(np.asarray(x, dtype=float)))


def _paper(method):
    def run(est, seed, budget):
        return identify(est, ARX_8, method=method, rng=seed, max_nfev=budget).theta

    return run


def _modal_only(est, seed, budget):
    par = ModalParametrization(8, est.ts)
    cost = PaperCost(ARX_8, est)
    box = np.vstack([par.bounds, default_bounds(est, ARX_8)[8:]])

    def fun(x):
        x = np.atleast_2d(x)
        return cost(np.concatenate([par.to_denominator(x[:, :8]), x[:, 8:]], axis=1))

    res = minimize(
        fun,
        box,
        method="ebsda",
        rng=seed,
        vectorized=True,
        max_nfev=budget,
        options={"bounds_policy": "clip"},
    )
    return np.r_[par.to_denominator(res.x[:8]), res.x[8:]]


def _projected(parametrization, method="ebsda", **kw):
    def run(est, seed, budget):
        cost = ProjectedCost(ARX_8, est)
        par = parametrization(est)
        settings = dict(n_points=50, polish_every=None, polish_nfev=10, restarts=None)
        res = projected_spiral(
            cost, par, method, max_nfev=budget, rng=seed, **(settings | kw)
        )
        return res.x

    return run


def _modal(est):
    return ModalParametrization(8, est.ts)


def _identify(method, parametrization=None, budget_cap=None, **kw):
    def run(est, seed, budget):
        if budget_cap is not None:
            budget = min(budget, budget_cap)
        return identify(
            est,
            ARX_8,
            method=method,
            parametrization=parametrization,
            rng=seed,
            max_nfev=budget,
            **kw,
        ).theta

    return run


def _cma_coefficients(est, seed, budget):
    import cma

    from spiralid.sysid.estimation.linear.parametrizations import Coefficients

    cost = PaperCost(ARX_8, est)
    box = default_bounds(est, ARX_8)
    half = 0.5 * (box[:, 1] - box[:, 0])
    ls = identify(est, ARX_8, method="ls").theta
    x0 = Coefficients(est, ARX_8).from_theta(ls)  # stabilised LS
    es = cma.CMAEvolutionStrategy(
        x0,
        0.1,
        {
            "CMA_stds": half,
            "seed": seed + 1,
            "maxfevals": budget,
            "verbose": -9,
            "bounds": [box[:, 0], box[:, 1]],
        },
    )
    while not es.stop():
        pts = es.ask()
        es.tell(pts, list(cost(np.array(pts))))
    return np.asarray(es.result.xbest)


def _cma_modal(est, seed, budget):
    import cma

    cost = ProjectedCost(ARX_8, est)
    par = ModalParametrization(8, est.ts)
    lo, hi = par.bounds[:, 0], par.bounds[:, 1]

    def fun(unit):
        return cost(par.to_denominator(lo + np.asarray(unit) * (hi - lo)))

    es = cma.CMAEvolutionStrategy(
        np.full(8, 0.5),
        0.3,
        {"seed": seed + 1, "maxfevals": budget, "verbose": -9, "bounds": [0, 1]},
    )
    while not es.stop():
        pts = es.ask()
        es.tell(pts, list(fun(np.array(pts))))
    return cost.theta(par.to_denominator(lo + es.result.xbest * (hi - lo)))


def _oe(est, seed, budget):
    return identify(est, ARX_8, method="oe").theta


# name -> (run, uses a gradient step, deterministic)
METHODS = {
    "SDA": (_paper("sda"), False, False),
    "Eb-SDA": (_paper("ebsda"), False, False),
    "modal": (_modal_only, False, False),
    "VP": (_projected(lambda est: _Reflection(8)), False, False),
    "modal+VP (SDA)": (_identify("sda", "modal"), False, False),
    "modal+VP": (_identify("ebsda", "modal"), False, False),
    "modal+VP+restart": (
        _projected(_modal, restarts=Restarts(growth=1, stall=20)),
        False,
        False,
    ),
    "modal+VP+fseed": (
        _identify(
            "spiral",
            polish_every=None,
            restarts=False,
            safe_start=False,
            frequency_seeds=25,
        ),
        False,
        False,
    ),
    "modal+VP+safe": (
        _identify("spiral", polish_every=None, restarts=False),
        False,
        False,
    ),
    "modal+VP+memetic": (
        _identify("spiral", restarts=False, safe_start=False),
        True,
        False,
    ),
    "spiral (no gradient)": (_identify("spiral", polish_every=None), False, False),
    "Eb-SDA+fseed (no gradient)": (
        _identify("spiral", polish_every=None, safe_start=False, frequency_seeds=25),
        False,
        False,
    ),
    "learned-metric (modal+VP)": (
        _identify("learned-metric", "modal", restarts=True),
        False,
        False,
    ),
    "learned-metric (no gradient)": (
        _identify("spiral", rule="learned-metric", polish_every=None, safe_start=False),
        False,
        False,
    ),
    "learned-metric+fseed (no gradient)": (
        _identify(
            "spiral",
            rule="learned-metric",
            polish_every=None,
            safe_start=False,
            frequency_seeds=25,
        ),
        False,
        False,
    ),
    "spiral": (_identify("spiral", budget_cap=10_000), True, False),
    "spiral (learned-metric)": (
        _identify("spiral", budget_cap=10_000, rule="learned-metric"),
        True,
        False,
    ),
    "DE": (_paper("de"), False, False),
    "CMA-ES": (_cma_coefficients, False, False),
    "CMA-ES (modal+VP)": (_cma_modal, False, False),
    "OE": (_oe, True, True),
}


# -- running -------------------------------------------------------------------


def run_one(task):
    record, method, seed, budget, arm_csv = task
    data = load_record(record, arm_csv)
    est, _ = data.split(2 / 3)
    run = METHODS[method][0]
    t0 = time.perf_counter()
    theta = run(est, seed, budget)
    elapsed = time.perf_counter() - t0
    cost = float(PaperCost(ARX_8, est)(theta))
    y_sim = ARX_8.simulate(theta, data.u)
    fit = float(fit_percent(data.y[est.n :], y_sim[est.n :]))
    return dict(
        record=record, method=method, seed=seed, cost=cost, fit=fit, time=elapsed
    )


def summarise(rows, records, methods):
    lines = []
    for record in records:
        mine = [r for r in rows if r["record"] == record]
        oe = [r["cost"] for r in mine if r["method"] == "OE"]
        ref = min(oe) if oe else float("nan")
        lines.append(f"\n### {record} (OE cost {ref:.4g})\n")
        lines.append(
            "| method | median cost / OE | worst cost / OE | seeds within 1 % of OE "
            "| median validation fit % | median time s |"
        )
        lines.append("|---|---|---|---|---|---|")
        for method in methods:
            rs = [r for r in mine if r["method"] == method]
            if not rs:
                continue
            c = np.array([r["cost"] for r in rs]) / ref
            within = int(np.sum(c <= 1.01))
            lines.append(
                f"| {method} | {np.median(c):.4g} | {c.max():.4g} | "
                f"{within}/{len(rs)} | {np.median([r['fit'] for r in rs]):.1f} | "
                f"{np.median([r['time'] for r in rs]):.2f} |"
            )
    return "\n".join(lines)


def scaling_one(task):
    record, order, method, seed, stop, *rest = task
    repeats = rest[0] if rest else 1
    est, _ = load_record(record).split(2 / 3)
    arx = ARX(order, order, 0)
    kw = {"rng": seed, "stop": stop} if method == "spiral" else {}
    times, walls = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        fit = identify(est, arx, method=method.lower(), **kw)
        # Processor time of this one process (BLAS on one thread): on a
        # shared machine the wall time also counts the other jobs' share of
        # the cores. Each repeat gives the same fit (it is deterministic);
        # the median of the repeats' times damps the other jobs' cache traffic.
        times.append(time.process_time() - c0)
        walls.append(time.perf_counter() - t0)
    return dict(record=record, order=order, method=method, seed=seed,
                cost=float(fit.cost), time=float(np.median(times)),
                wall=float(np.median(walls)))  # fmt: skip


def growth_exponent(orders, times) -> float:
    """``k`` of ``time ~ n^k``: least squares on log-log over n >= 4."""
    keep = np.asarray(orders) >= 4
    logs = np.log(np.asarray(orders, dtype=float)[keep])
    return float(np.polyfit(logs, np.log(np.asarray(times)[keep]), 1)[0])


def _key(row):
    return row["record"], row["order"], row["method"]


def summarise_scaling(rows, records, orders):
    lines = []
    for record in records:
        lines.append(f"\n### {record}\n")
        lines.append(
            "| order | LS s | OE s | spiral s | spiral / OE time "
            "| spiral cost / OE (median, worst) | LS cost / OE |"
        )
        lines.append("|---|---|---|---|---|---|---|")
        med = {m: [] for m in ("LS", "OE", "spiral")}
        for n in orders:
            cell = {m: [r for r in rows if _key(r) == (record, n, m)] for m in med}
            t = {m: float(np.median([r["time"] for r in cell[m]])) for m in med}
            oe = cell["OE"][0]["cost"]
            ratio = np.array([r["cost"] for r in cell["spiral"]]) / oe
            for m in med:
                med[m].append(t[m])
            lines.append(
                f"| {n} | {t['LS']:.3f} | {t['OE']:.2f} | {t['spiral']:.2f} | "
                f"{t['spiral'] / t['OE']:.2f} | {np.median(ratio):.4f}, "
                f"{ratio.max():.4f} | {cell['LS'][0]['cost'] / oe:.3f} |"
            )
        k = {m: growth_exponent(orders, med[m]) for m in med}
        lines.append(
            f"\ngrowth exponent k (time ~ n^k, n >= 4): LS {k['LS']:.2f}, "
            f"OE {k['OE']:.2f}, spiral {k['spiral']:.2f}"
        )
    return "\n".join(lines)


def scaling(args) -> None:
    records = ("rig", "rig-8000")
    orders = [int(n) for n in args.orders.split(",")]
    tasks = [
        (record, n, method, seed)
        for record in records
        for n in orders
        for method, seeds in (("LS", 1), ("OE", 1), ("spiral", args.seeds))
        for seed in range(seeds)
    ]
    tasks = [(*task, args.stop, args.repeats) for task in tasks]
    scaling_one(("rig", 8, "spiral", 0, args.stop))  # warm the compiled kernels
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    # One worker: the times are the point, and two would share the cores.
    rows = [scaling_one(task) for task in tasks]
    print(summarise_scaling(rows, records, orders))
    print(
        f"\nspiral with stop={args.stop!r}; median of {args.repeats} repeat(s); "
        f"{len(tasks)} identifications in {time.perf_counter() - t0:.0f} s; "
        f"load average at start {load0[0]:.2f}, at end {os.getloadavg()[0]:.2f}"
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--budget", type=int, default=20_000)
    ap.add_argument("--records", default=",".join(RECORDS))
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument(
        "--arm", default=None, help="a CSV (u, y) to use instead of the shipped arm"
    )
    ap.add_argument(
        "--jsonl", default=None, help="append every run here as it finishes"
    )
    ap.add_argument(
        "--summarise",
        default=None,
        metavar="JSONL",
        help="print the tables of a (possibly partial) --jsonl file and exit",
    )
    ap.add_argument(
        "--scaling",
        action="store_true",
        help="print the scaling table (time and cost against order)",
    )
    ap.add_argument("--orders", default=",".join(map(str, SCALING_ORDERS)),
                    help="orders of the scaling table")  # fmt: skip
    ap.add_argument(
        "--stop",
        default=SPIRAL_STOPS[0],
        choices=SPIRAL_STOPS,
        help="the scaling table's spiral stop (its default 'work', 'converged' "
        "as before it, or the whole budget)",
    )
    ap.add_argument(
        "--repeats",
        type=int,
        default=1,
        help="the scaling table's runs of each identification (median time)",
    )
    args = ap.parse_args(argv)
    if args.scaling:
        scaling(args)
        return
    records = args.records.split(",")
    methods = args.methods.split(",")
    for m in methods:
        if m not in METHODS:
            ap.error(f"--methods: unknown {m!r}; choose from {list(METHODS)}")
    try:
        import cma  # noqa: F401
    except ImportError:
        dropped = [m for m in methods if m.startswith("CMA-ES")]
        if dropped and not args.summarise:
            print(f"pycma is not installed (pip install cma): leaving out {dropped}")
            methods = [m for m in methods if m not in dropped]
    if args.summarise:
        lines = Path(args.summarise).read_text().splitlines()
        rows = [json.loads(line) for line in lines if line.strip()]
        print(summarise(rows, records, methods))
        print(f"\n{len(rows)} identifications in {args.summarise}")
        return
    # Seed-major order: a run stopped early still has every method and
    # record, with fewer seeds.
    tasks = []
    for seed in range(args.seeds):
        for record in records:
            for method in methods:
                if METHODS[method][2] and seed > 0:
                    continue
                tasks.append((record, method, seed, args.budget, args.arm))
    # Warm the compiled kernels (and Numba's cache) once before timing.
    run_one(("rig", "spiral", 0, 2000, args.arm))
    t0 = time.perf_counter()
    load0 = os.getloadavg()
    sink = open(args.jsonl, "a") if args.jsonl else None
    rows = []
    with ProcessPoolExecutor(args.workers) as pool:
        for row in pool.map(run_one, tasks, chunksize=1):
            rows.append(row)
            if sink is not None:
                sink.write(json.dumps(row) + "\n")
                sink.flush()
    if sink is not None:
        sink.close()
    wall = time.perf_counter() - t0
    print(summarise(rows, records, methods))
    print(
        f"\n{len(tasks)} identifications, {args.seeds} seeds, budget {args.budget}, "
        f"{args.workers} workers: {wall:.0f} s wall; load average at start "
        f"{load0[0]:.2f}, at end {os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
