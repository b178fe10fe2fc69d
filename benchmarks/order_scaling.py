"""Time, cost, validation fit and stability against the order, ARX(n, n, 0).

``python benchmarks/order_scaling.py --jsonl rows.jsonl`` runs output error
(``oe``), the default (``spiral``, seed 0), SciPy's plain
``least_squares(method="lm")`` on the simulation error from least squares
(no stability bound) and, when nfoursid is installed (the ``bench`` extra),
its N4SID (PO-MOESP, block rows max(2n, 32)) state-space model of the
same order, on the paper's
record (``rig``: 2,000 estimation samples) and on a record four times as
long (``rig-8000``: 8,000), orders 8, 16, 24, 32, 48 and 64, and prints the
table of docs/results/identification.md ("How it scales with the order").

Processor seconds of this one process (``time.process_time``, BLAS on one
thread), one run per identification, on whatever else the machine is
doing. The cost is eq. (2) without its penalty, 100 times the RMS of the
simulation error from rest over the RMS of the output (so that an unstable
model, which the paper's penalty would rank last, is compared on its
error); the fit is the validation fit of the free run from rest on the last
third. ``stable`` is every pole inside the unit circle, and ``r_max`` the
largest pole radius. ``--summarise rows.jsonl`` prints the table of a
(possibly partial) file; rows are appended as each identification ends, so
a long run can be read before it finishes.
"""

from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from scipy import optimize, signal

from spiralid.sysid import ARX, identify
from spiralid.sysid.estimation.core.cost import auto_gain
from spiralid.sysid.estimation.linear.outputerror import error_functions
from spiralid.sysid.models.arx import arx_least_squares
from spiralid.sysid.validation.validate import fit_percent

ORDERS = (8, 16, 24, 32, 48, 64)
RECORDS = ("rig", "rig-8000")
METHODS = ("OE", "spiral", "SciPy LM", "N4SID")


def load(record: str):
    """The record and its estimation part (the first 2/3)."""
    from identification import load_record

    data = load_record(record)
    est, _ = data.split(2 / 3)
    return data, est


def _scipy_lm(est, arx):
    residual, jacobian = error_functions(arx, est, "simulation")
    theta0 = arx_least_squares(est, arx)
    return optimize.least_squares(residual, theta0, jac=jacobian, method="lm").x


def _n4sid(est, order):
    import pandas as pd
    from nfoursid.nfoursid import NFourSID

    frame = pd.DataFrame({"u": est.u, "y": est.y})
    # Block rows: twice the order, at least 32 (order + 2, the least the
    # method takes, validated at 1.9 % at ARX(8, 8, 0)'s order; 32 at 96.6 %).
    rows = max(2 * order, 32)
    n4 = NFourSID(frame, output_columns=["y"], input_columns=["u"],
                  num_block_rows=rows)  # fmt: skip
    n4.subspace_identification()
    ss, _ = n4.system_identification(rank=order)
    return ss.a, ss.b, ss.c, ss.d


def _simulate_ss(model, u):
    a, b, c, d = model
    return signal.dlsim((a, b, c, d, 1.0), u)[1].ravel()


def run_one(record: str, order: int, method: str) -> dict:
    data, est = load(record)
    arx = ARX(order, order, 0)
    c0 = time.process_time()
    if method == "OE":
        theta = identify(est, arx, method="oe").theta
    elif method == "spiral":
        theta = identify(est, arx, method="spiral", rng=0).theta
    elif method == "SciPy LM":
        theta = _scipy_lm(est, arx)
    else:
        model = _n4sid(est, order)
    seconds = time.process_time() - c0
    if method == "N4SID":
        y_all = _simulate_ss(model, data.u)
        poles = np.linalg.eigvals(model[0])
    else:
        num, den = arx.polynomials(theta)
        y_all = signal.lfilter(num, den, data.u)
        poles = np.roots(den)
    e = y_all[: est.n] - est.y
    cost = float(auto_gain(est.y) / e.size * np.sqrt(e @ e))
    radius = float(np.max(np.abs(poles))) if poles.size else 0.0
    fit = float(fit_percent(data.y[est.n :], y_all[est.n :]))
    stable = bool(radius < 1.0)
    return dict(record=record, order=order, method=method, seconds=seconds,
                cost=cost, fit=fit, stable=stable, radius=radius)  # fmt: skip


def summarise(rows: list[dict]) -> str:
    lines = []
    for record in RECORDS:
        mine = [r for r in rows if r["record"] == record]
        if not mine:
            continue
        lines.append(f"\n### {record}\n")
        head = "| order |"
        for m in METHODS:
            head += f" {m} s | cost | fit % | max pole |"
        lines.append(head + " OE / SciPy time | spiral / SciPy time |")
        lines.append("|---" * (1 + 4 * len(METHODS) + 2) + "|")
        for n in sorted({r["order"] for r in mine}):
            cell = {r["method"]: r for r in mine if r["order"] == n}
            line = f"| {n} |"
            for m in METHODS:
                r = cell.get(m)
                if r is None:
                    line += " | | | |"
                    continue
                mark = "" if r["stable"] else " (unstable)"
                line += (f" {r['seconds']:.2f} | {r['cost']:.4f} | {r['fit']:.1f} | "
                         f"{r['radius']:.6f}{mark} |")  # fmt: skip
            ref = cell.get("SciPy LM")
            for m in ("OE", "spiral"):
                if ref is None or m not in cell:
                    line += " |"
                else:
                    line += f" {cell[m]['seconds'] / ref['seconds']:.1f} |"
            lines.append(line)
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--orders", default=",".join(map(str, ORDERS)))
    ap.add_argument("--records", default=",".join(RECORDS))
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--jsonl", default=None, help="append every row here")
    ap.add_argument("--summarise", default=None, metavar="JSONL",
                    help="print the table of a (possibly partial) file")  # fmt: skip
    args = ap.parse_args(argv)
    if args.summarise:
        with open(args.summarise) as f:
            print(summarise([json.loads(line) for line in f if line.strip()]))
        return
    methods = args.methods.split(",")
    try:
        import nfoursid  # noqa: F401
    except ImportError:
        if "N4SID" in methods:
            print("nfoursid is not installed (the bench extra): leaving out N4SID")
            methods.remove("N4SID")
    run_one("rig", 8, "spiral")  # warm the compiled kernels
    rows = []
    sink = open(args.jsonl, "a") if args.jsonl else None
    for record in args.records.split(","):
        for n in map(int, args.orders.split(",")):
            for m in methods:
                row = run_one(record, n, m)
                rows.append(row)
                if sink is not None:
                    sink.write(json.dumps(row) + "\n")
                    sink.flush()
    print(summarise(rows))
    load = os.getloadavg()
    print(f"\nload average at the end {load[0]:.2f}")


if __name__ == "__main__":
    main()
