"""What "models that validate" changed (issue 27): the default method now,
against itself before the stability margin, the cancellation and the
held-back choice, against choosing by cost alone, and against output error.

Records (first 2/3 estimate, last 1/3 validates after the estimation part,
as ``spiralid identify`` does):

- the simulated rig's four outputs (``paper_experiment``, seed 0), the hub
  angle with ``integrator=2`` (the rigid body), the others without;
- the shipped real arm (DaISy 96-009, ``spiralid.datasets.robot_arm``);
- benchmarks/drift.py's drift record, seeds 0-4.

Structures ARX(4, 4, 1) and ARX(8, 8, 0). Routes:

- ``default``: ``identify(est, arx, rng=0)``;
- ``by cost``: the same with ``holdback=None`` (no held-back choice);
- ``before``: ``max_time_constant=None, cancel=False, holdback=None``, the
  default before issue 27;
- ``OE``: ``method="oe"``.

Prints per record and structure the estimation cost (eq. 2) of each route,
the default's cost relative to ``before`` (the goal: within 1 % where no
near-cancellation or held-back override occurs), whether a pair was
cancelled or the held-back choice overrode the lowest cost, and the
validation fit % of every route. Wall times are printed, never asserted.

Run: ``python benchmarks/selection.py [--workers 2]``.
"""

import os

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import importlib.util
import statistics
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from spiralid.sysid import ARX, identify, validate

ROUTES = {
    "default": {},
    "by cost": {"holdback": None},
    "before": {"max_time_constant": None, "cancel": False, "holdback": None},
    "OE": {"method": "oe"},
}
STRUCTURES = (ARX(4, 4, 1), ARX(8, 8, 0))
RIG_OUTPUTS = ("hub_angle", "hub_velocity", "end_acceleration", "tip_deflection")


def _drift_module():
    path = Path(__file__).with_name("drift.py")
    spec = importlib.util.spec_from_file_location("drift_benchmark", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def record(name: str):
    """``(estimation, validation, integrator)`` of a record by name."""
    if name.startswith("rig:"):
        from spiralid.fms import FlexibleManipulator, paper_experiment

        output = name.split(":", 1)[1]
        data = paper_experiment().run(FlexibleManipulator(), rng=0).iodata(output)
        integrator = 2 if output == "hub_angle" else 0
    elif name == "arm":
        from spiralid.datasets import robot_arm

        data, integrator = robot_arm(), 0
    else:
        seed = int(name.split(":", 1)[1])
        data, integrator = _drift_module().record(seed), 0
    est, val = data.split(2 / 3)
    return est, val, integrator


def run_one(task) -> dict:
    name, arx, route = task
    est, val, integrator = record(name)
    options = dict(ROUTES[route])
    if options.get("method") != "oe" and route != "default":
        options.setdefault("method", "spiral")
    t0 = time.perf_counter()
    model = identify(est, arx, rng=0, integrator=integrator, **options)
    seconds = time.perf_counter() - t0
    sel = model.selection
    return dict(
        record=name,
        arx=str(arx),
        route=route,
        cost=float(model.cost),
        fit=float(validate(model, val, warmup=est).fit_percent),
        cancelled=bool(model.cancellations),
        overrode=bool(sel is not None and sel["chosen"] != sel["lowest_cost"]),
        time=seconds,
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--drift-seeds", type=int, default=5)
    args = ap.parse_args(argv)
    names = [f"rig:{o}" for o in RIG_OUTPUTS] + ["arm"]
    names += [f"drift:{s}" for s in range(args.drift_seeds)]
    tasks = [(n, arx, r) for n in names for arx in STRUCTURES for r in ROUTES]
    t0 = time.perf_counter()
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            rows = list(pool.map(run_one, tasks, chunksize=1))
    else:
        rows = [run_one(t) for t in tasks]
    cell = {(r["record"], r["arx"], r["route"]): r for r in rows}
    routes = list(ROUTES)
    head = ["record", "structure"]
    head += [f"{r} cost" for r in routes] + ["default / before", "note"]
    head += [f"{r} fit %" for r in routes]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    within = plain = 0
    for n in names:
        for arx in STRUCTURES:
            row = {r: cell[(n, str(arx), r)] for r in routes}
            d = row["default"]
            ratio = d["cost"] / row["before"]["cost"]
            note = ", ".join(
                word
                for word, flag in (
                    ("cancelled", d["cancelled"]),
                    ("held-back override", d["overrode"]),
                )
                if flag
            )
            if not note:
                plain += 1
                within += ratio <= 1.01
            line = [n, str(arx)] + [f"{row[r]['cost']:.4g}" for r in routes]
            line += [f"{ratio:.4f}", note or "-"]
            line += [f"{row[r]['fit']:.2f}" for r in routes]
            print("| " + " | ".join(line) + " |")
    print(
        f"\nwhere nothing was cancelled or overridden, the default's cost is "
        f"within 1 % of before on {within}/{plain}; "
        + "; ".join(
            f"median time {r} "
            f"{statistics.median(x['time'] for x in rows if x['route'] == r):.2f} s"
            for r in routes
        )
        + f"; {len(tasks)} identifications in {time.perf_counter() - t0:.0f} s, "
        f"load average {os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
