"""The default's time, and the folds', against output error's, by order.

``spiral`` promises at most 1.5x output error's time; ``folds="auto"``
(the folds across the record where the modes table flags a pole) adds
output error with integrated noise and up to nine capped refits to it.
This script prints, for each record and order ``ARX(n, n, 0)``, the
processor seconds of this one process (``time.process_time``, BLAS on one
thread, so that other jobs on the machine count less than in wall time)
of the default (``folds=False``), of output error (``method="oe"``) and of
``folds="auto"``, the validation fit % of each (the free run on the last
third, the estimation part as warm-up) and what the folds chose (``-``
where they did not run). The records:

- ``process-<seed>``: ``benchmarks/drift_process.py``'s record (the
  slow process whose gain varies, plus a slow drift) of that seed;
- ``drift-<seed>``: ``benchmarks/drift.py``'s record (a linear plant plus a
  random walk) of that seed;
- ``rig``: the simulated rig's hub velocity (``paper_experiment()``,
  ``rng=0``).

Run: ``python benchmarks/folds_time.py [--orders 2,4,8,16]
[--records process-0,process-2,drift-0,rig] [--repeats 1]``.
Every identification with ``rng=0``. Speed is printed, never asserted;
the median of ``--repeats`` runs.
"""

import os

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time

import drift
import drift_process
import numpy as np

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.sysid import ARX, IOData, identify, validate

VARIANTS = {"default": {}, "OE": {"method": "oe"}, "auto": {"folds": "auto"}}
RECORDS = "process-0,process-2,drift-0,rig"


def split(name: str) -> tuple[IOData, IOData]:
    """The estimation and validation parts of a record by name."""
    if name == "rig":
        record = paper_experiment().run(FlexibleManipulator(), rng=0)
        return record.iodata("hub_velocity").split(2 / 3)
    stem, _, seed = name.rpartition("-")
    module = {"process": drift_process, "drift": drift}.get(stem)
    if module is None or not seed.isdigit():
        raise SystemExit(
            f"unknown record {name!r}: rig, drift-<seed> or process-<seed>"
        )
    return module.record(int(seed)).split(2 / 3)


def run(est: IOData, val: IOData, order: int, options: dict, repeats: int):
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        model = identify(est, ARX(order, order, 0), rng=0, **options)
        times.append(time.process_time() - t0)
    selection = getattr(model, "selection", None) or {}
    chosen = selection.get("chosen", "-") if "fold_ends" in selection else "-"
    return (
        float(np.median(times)),
        float(validate(model, val, warmup=est).fit_percent),
        chosen,
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--orders", default="2,4,8,16")
    ap.add_argument("--records", default=RECORDS)
    ap.add_argument("--repeats", type=int, default=1)
    args = ap.parse_args(argv)
    orders = [int(v) for v in args.orders.split(",")]
    # Compiled kernels first, so no row pays for them.
    identify(drift.record(0).split(2 / 3)[0], ARX(2, 2, 0), rng=0, folds=True)
    print(
        "| record | order | default s | OE s | `auto` s "
        "| fit %: default, OE, auto | chose |"
    )
    print("|---|---|---|---|---|---|---|")
    # Every name checked before the first identification.
    records = {name: split(name) for name in args.records.split(",")}
    for name, (est, val) in records.items():
        for n in orders:
            out = {
                k: run(est, val, n, options, args.repeats)
                for k, options in VARIANTS.items()
            }
            seconds = " | ".join(f"{v[0]:.2f}" for v in out.values())
            fits = ", ".join(f"{v[1]:.1f}" for v in out.values())
            print(
                f"| {name} | {n} | {seconds} | {fits} | {out['auto'][2]} |", flush=True
            )
    print(f"\nload average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
