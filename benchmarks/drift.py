"""Drift: does the default method fit a record's drift with a pole slower
than the record? (issue 27, "Lower cost, worse model").

A synthetic drift record: a plant of two lightly damped modes (3 Hz, damping
0.02, and 11 Hz, damping 0.03; zero-order hold at ``ts = 0.01``) driven by
white noise, plus a random-walk output disturbance scaled to 3 % of the
plant output's RMS; 1500 samples, the first 2/3 estimate and the last 1/3
validate (``spiralid.sysid.validate`` with ``warmup`` the estimation part,
as ``spiralid identify`` validates: its fit %). For each seed and structure
(ARX(4, 4, 0) and ARX(8, 8, 0)) it identifies with the default method
(``"spiral"``, with its stability margin ``max_time_constant = N ts`` and
the pole-zero cancellation), output error (``"oe"``, the same), and with
``--unconstrained`` the default method without either
(``max_time_constant=None, cancel=False``), the behaviour before them.

Prints per seed the validation fit % of each, the largest pole radius
against ``r_max = exp(-ts / T)`` (``T = N ts`` of the estimation part), the
effective order after the cancellation, and a summary: on how many seeds
the default validates at least as well as OE minus 1 point, and how many
models keep every pole inside ``r_max``. No assertion on speed; the wall
times are printed.

Run: ``python benchmarks/drift.py [--seeds 10] [--orders 4,8] [--workers 2]
[--unconstrained]``. BLAS is pinned to one thread: on a shared machine
OpenBLAS threads oversubscribe and small dense kernels get tens of times
slower.
"""

import os

if __name__ == "__main__":
    # Before NumPy loads BLAS; not when a test imports the record from here.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy import signal

from spiralid.sysid import ARX, IOData, identify, validate

TS = 0.01
N = 1500
# (frequency Hz, damping ratio, static gain) of the plant's two modes.
MODES = ((3.0, 0.02, 1.0), (11.0, 0.03, 0.5))
DRIFT = 0.03
FRACTION = 2 / 3


def plant() -> tuple[np.ndarray, np.ndarray]:
    """``(b, a)`` of the two-mode plant sampled by zero-order hold."""
    num, den = np.zeros(1), np.ones(1)
    for f, zeta, gain in MODES:
        wn = 2 * np.pi * f
        d = np.array([1.0, 2 * zeta * wn, wn**2])
        num = np.polyadd(np.polymul(num, d), np.polymul([gain * wn**2], den))
        den = np.polymul(den, d)
    b, a, _ = signal.cont2discrete((num, den), TS, method="zoh")
    return np.ravel(b), np.ravel(a)


def record(seed: int, n: int = N, drift: float = DRIFT) -> IOData:
    """The plant's response to white noise plus a random walk at `drift`
    times the response's RMS."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    b, a = plant()
    y0 = signal.lfilter(b, a, u)
    walk = np.cumsum(rng.standard_normal(n))
    walk -= walk.mean()
    walk *= drift * np.sqrt(np.mean(y0**2) / np.mean(walk**2))
    return IOData(u, y0 + walk, ts=TS)


# name -> identify's keyword arguments
METHODS = {
    "default": {},
    "OE": {"method": "oe"},
    "unconstrained": {"max_time_constant": None, "cancel": False},
    "by cost": {"holdback": None},
}


def run_one(task) -> dict:
    """One identification: validation fit %, largest pole radius, effective
    order, estimation cost and wall time."""
    seed, order, name = task
    est, val = record(seed).split(FRACTION)
    t0 = time.perf_counter()
    model = identify(est, ARX(order, order, 0), rng=seed, **METHODS[name])
    elapsed = time.perf_counter() - t0
    return dict(
        seed=seed,
        order=order,
        method=name,
        fit=float(validate(model, val, warmup=est).fit_percent),
        radius=float(model.max_pole_radius),
        r_max=float(np.exp(-TS / (est.n * TS))),
        effective=model.effective_order,
        cost=float(model.cost),
        time=elapsed,
    )


def table(rows: list[dict], order: int, methods: list[str]) -> str:
    cell = {(r["seed"], r["method"]): r for r in rows if r["order"] == order}
    seeds = sorted({s for s, _ in cell})
    r_max = rows[0]["r_max"]
    head = ["seed"]
    for m in methods:
        head += [f"{m} fit %", f"{m} max |p|", f"{m} order"]
    lines = [
        f"\n### ARX({order}, {order}, 0): validation fit % (after the estimation "
        f"part), max |pole| against r_max = {r_max:.6f}\n",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    for s in seeds:
        row = [str(s)]
        for m in methods:
            r = cell[(s, m)]
            flag = "" if r["radius"] <= r["r_max"] else " (> r_max)"
            na, nb = r["effective"]
            row += [f"{r['fit']:.2f}", f"{r['radius']:.6f}{flag}", f"{na}, {nb}"]
        lines.append("| " + " | ".join(row) + " |")
    d = {s: cell[(s, "default")] for s in seeds}
    o = {s: cell[(s, "OE")] for s in seeds}
    held = sum(d[s]["fit"] >= o[s]["fit"] - 1.0 for s in seeds)
    inside = sum(d[s]["radius"] <= d[s]["r_max"] for s in seeds)
    lines.append(
        f"\ndefault >= OE - 1 point on {held}/{len(seeds)} seeds; default's "
        f"poles inside r_max on {inside}/{len(seeds)}; median fit: "
        + ", ".join(
            f"{m} {np.median([cell[(s, m)]['fit'] for s in seeds]):.2f}"
            for m in methods
        )
        + "; median time s: "
        + ", ".join(
            f"{m} {np.median([cell[(s, m)]['time'] for s in seeds]):.2f}"
            for m in methods
        )
    )
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--orders", default="4,8")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument(
        "--unconstrained",
        action="store_true",
        help="also the default method without the margin and the cancellation",
    )
    ap.add_argument(
        "--by-cost",
        action="store_true",
        help="also the default method choosing by the estimation cost alone "
        "(holdback=None)",
    )
    args = ap.parse_args(argv)
    orders = [int(v) for v in args.orders.split(",")]
    methods = ["default", "OE"] + (["unconstrained"] if args.unconstrained else [])
    methods += ["by cost"] if args.by_cost else []
    tasks = [(s, n, m) for n in orders for s in range(args.seeds) for m in methods]
    t0 = time.perf_counter()
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            rows = list(pool.map(run_one, tasks, chunksize=1))
    else:
        rows = [run_one(task) for task in tasks]
    for n in orders:
        print(table(rows, n, methods))
    print(
        f"\n{len(tasks)} identifications in {time.perf_counter() - t0:.0f} s; "
        f"load average {os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
