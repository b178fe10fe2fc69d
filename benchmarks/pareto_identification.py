"""Pareto identification on the simulated rig and the real arm.

For each record (``rig``, ``rig-long``, ``rig-payload``, ``rig-noisy``: the
simulated rig and its three variants, as ``benchmarks/identification.py``
makes them, whose records it loads; ``arm``: the real DaISy arm), the first
2/3 estimates and the last 1/3 validates.
``spiralid.sysid.identify_pareto`` searches orders ``--orders`` (default
2..12, each ARX(n, n, 0)) against the simulation cost
(eq. 2) and the frequency-response error (dB), with the number of
parameters as a third objective, at ``--budget`` evaluations per order
(default 5000, 50 points, seeded with LS, Steiglitz-McBride and OE,
extremes polished by 200 evaluations) with the rule ``--method`` (default
``identify_pareto``'s, the learned-metric poll; the figures in
docs/results/multiobjective.md were measured with ``--method ebsda``, the
default then).

Printed per record and seed: the front's size; the knee model's structure,
its validation fit % (free run from rest over the whole record, scored on
the last third), and its first three natural frequencies and damping ratios
(``spectra.modes_from_poles`` over the lightly damped modes, damping below
0.3) against the finite-element model's (``FlexibleManipulator.modes()``;
none for the arm); and whether some front point costs at most 1.01 times
output error's cost at its own order (``identify(method="oe")``) with its
first three natural frequencies within 1 % of the finite-element model's
(for the arm: the cost test alone), with how many points pass the cost test
and the best such point; and the order where validation fit stops improving
(the lowest order whose output-error model validates within one point of the
best order's) beside the knee's order and the order ``choose_order`` picks
from the front by the same rule, applied to each order's lowest-cost front
model.

With ``--alone`` each record is run again with the search alone (no seeds,
no polish), to show what the spiral search itself finds.

Run: ``python benchmarks/pareto_identification.py [--seeds 1]
[--budget 5000] [--orders 2:12] [--records rig,arm] [--method ebsda]
[--alone]``.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time

import numpy as np
from identification import load_record

from spiralid.choices import DEFAULT_PARETO_METHOD, PARETO_METHOD_NAMES
from spiralid.fms import FlexibleManipulator
from spiralid.sysid import (
    ARX,
    choose_order,
    identify,
    identify_pareto,
    modes_from_poles,
    validate,
)

# The rig each simulated record comes from (as load_record builds them).
RIGS = {
    "rig": {},
    "rig-long": {"length": 1.2},
    "rig-payload": {"payload_mass": 0.1},
    "rig-noisy": {},  # the rig itself, with five times the accelerometer noise
}
RECORDS = (*RIGS, "arm")
MAX_DAMPING = 0.3


def _modes(model, n=3):
    m = modes_from_poles(model.poles, model.ts, max_damping=MAX_DAMPING)
    return m.frequency[:n], m.damping[:n]


def _fmt(values, digits=2):
    return "[" + ", ".join(f"{v:.{digits}f}" for v in values) + "]"


def _within(freq, fem, tol=0.01):
    return freq.size >= 3 and bool(np.all(np.abs(freq[:3] / fem[:3] - 1) <= tol))


def one(
    record, seed, orders, budget, points, seeded=True, method=DEFAULT_PARETO_METHOD
):
    data = load_record(record)
    est, val = data.split(2 / 3)
    fem = FlexibleManipulator(**RIGS[record]).modes()[:3] if record in RIGS else None
    oe_models = {n: identify(est, ARX(n, n, 0), method="oe") for n in orders}
    oe = {n: m.cost for n, m in oe_models.items()}
    # Where validation fit stops improving: the lowest order whose output
    # error model validates within one point of the best order's.
    oe_fit = {n: validate(m, val, warmup=est).fit_percent for n, m in oe_models.items()}
    enough = min(n for n in orders if oe_fit[n] >= max(oe_fit.values()) - 1.0)
    t = time.perf_counter()
    front = identify_pareto(
        est,
        orders,
        method=method,
        rng=seed,
        max_nfev=budget,
        n_points=points,
        seed_estimates=seeded,
        extremes_nfev=200 if seeded else 0,
    )
    elapsed = time.perf_counter() - t
    knee = front.knee_model
    by_fit = front.models[choose_order(front, val, warmup=est, tolerance=1.0)]
    fit_by_fit = validate(by_fit, val, warmup=est).fit_percent
    variant = "seeded, polished" if seeded else "search alone"
    fit = validate(knee, val, warmup=est).fit_percent
    f_knee, z_knee = _modes(knee)
    near_oe = [i for i, m in enumerate(front.models) if m.cost <= 1.01 * oe[m.arx.na]]
    hits = [
        i
        for i in near_oe
        if fem is not None and _within(_modes(front.models[i])[0], fem)
    ]
    lines = [
        f"{record} seed {seed} ({variant}): front {len(front)} models, "
        f"{front.nfev} evaluations, "
        f"{elapsed:.1f} s",
        f"  knee: point {front.knee}, {knee.arx}, cost {knee.cost:.3f} "
        f"(OE at this order {oe[knee.arx.na]:.3f}), frequency error "
        f"{front.objectives[front.knee, 1]:.2f} dB, validation fit {fit:.1f} %",
        f"  validation fit stops improving at order {enough} (OE's fit by order: "
        + ", ".join(f"{n}: {oe_fit[n]:.1f}" for n in orders)
        + f"); the knee is at order {knee.arx.na}; choose_order (1 point) picks "
        f"{by_fit.arx}, validation fit {fit_by_fit:.1f} %",
        f"  knee modes (Hz) {_fmt(f_knee)}, damping {_fmt(z_knee, 4)}"
        + ("" if fem is None else f"; FEM (Hz) {_fmt(fem)}"),
        f"  front points within 1 % of OE's cost at their order: {len(near_oe)}",
    ]
    if fem is not None:
        lines.append(
            "  ... and with the first three natural frequencies within 1 % of the "
            f"FEM's: {len(hits)}"
            + (
                f" (e.g. point {hits[0]}, {front.models[hits[0]].arx}, modes "
                f"{_fmt(_modes(front.models[hits[0]])[0])}, start "
                f"{front.models[hits[0]].result.start})"
                if hits
                else ""
            )
        )
    best = min(near_oe, key=lambda i: front.models[i].cost) if near_oe else None
    if best is not None:
        m = front.models[best]
        lines.append(
            f"  lowest-cost point {best}: {m.arx}, cost {m.cost:.3f}, start "
            f"{m.result.start}, modes {_fmt(_modes(m)[0])}"
        )
    starts = {}
    for m in front.models:
        starts[m.result.start] = starts.get(m.result.start, 0) + 1
    lines.append(f"  front points by origin: {starts}")
    orders_hit = (knee.arx.na == enough, by_fit.arx.na == enough)
    return "\n".join(lines), bool(hits), orders_hit


def _orders(text):
    lo, hi = (int(v) for v in text.split(":"))
    return list(range(lo, hi + 1))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=1)
    p.add_argument("--budget", type=int, default=5000)
    p.add_argument("--points", type=int, default=50)
    p.add_argument("--orders", type=_orders, default=_orders("2:12"))
    p.add_argument("--records", default=",".join(RECORDS))
    p.add_argument(
        "--method",
        choices=PARETO_METHOD_NAMES,
        default=DEFAULT_PARETO_METHOD,
        help="the search's rule (default: identify_pareto's)",
    )
    p.add_argument(
        "--alone",
        action="store_true",
        help="also run the search alone (no seeds, no polish)",
    )
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    print(
        f"orders {args.orders[0]}..{args.orders[-1]}, budget {args.budget} per "
        f"order, {args.points} points, {args.method}, seeds 0..{args.seeds - 1}; load "
        f"{os.getloadavg()[0]:.1f}"
    )
    for record in args.records.split(","):
        for seeded in (True, False) if args.alone else (True,):
            passed, knee_at, chosen_at = 0, 0, 0
            for seed in range(args.seeds):
                text, hit, (knee_hit, chosen_hit) = one(
                    record,
                    seed,
                    args.orders,
                    args.budget,
                    args.points,
                    seeded,
                    args.method,
                )
                print(text, flush=True)
                passed += hit
                knee_at += knee_hit
                chosen_at += chosen_hit
            print(
                f"{record}: at the order where validation fit stops improving, "
                f"the knee in {knee_at} and choose_order in {chosen_at} of "
                f"{args.seeds} seeds"
            )
            if record in RIGS:
                what = "seeded" if seeded else "search alone"
                print(
                    f"{record} ({what}): OE-cost-and-FEM-modes test met in "
                    f"{passed} of {args.seeds} seeds\n"
                )
    print(f"total {time.perf_counter() - t0:.0f} s; load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
