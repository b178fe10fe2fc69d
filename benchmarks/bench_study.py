"""The default study (every reading of the paper, 20 seeds) on 1 and 2 workers.

Runs ``spiralid study``'s default specification (or the one given) through
:func:`spiralid.study.run_study` on a Dask ``LocalCluster`` with 1 worker and
then with 2, each into a fresh store, and prints both wall times, their ratio,
the machine's load, and the "where the claim holds" table of the 2-worker
store. The two stores must agree run for run (wall times aside): the script
checks that too.

Run: ``python benchmarks/bench_study.py [SPEC] [--workers 1 2] [--keep DIR]``
"""

import argparse
import os
import tempfile
import time
from pathlib import Path

from spiralid.report.study_output import study_summary
from spiralid.study import (
    ResultStore,
    analyse,
    load_spec,
    reproducible_part,
    run_study,
)


def _comparable(rows):
    return [reproducible_part(r) for r in rows]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec", nargs="?", default=None)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--keep", default=None, help="folder to keep the stores in")
    args = parser.parse_args()
    spec = load_spec(args.spec)
    folder = Path(args.keep or tempfile.mkdtemp(prefix="spiralid-bench-study-"))
    folder.mkdir(parents=True, exist_ok=True)
    print(
        f"specification: {args.spec or 'default (the paper grid)'}; "
        f"{len(spec.data)} records x {len(spec.predictors)} predictors x "
        f"{len(spec.parametrizations)} parametrisations x {len(spec.optimizers)} "
        f"optimisers x {len(spec.seeds)} seeds, budget {spec.budget}; "
        f"{os.cpu_count()} CPUs"
    )
    walls, stores = {}, {}
    for n in args.workers:
        store = folder / f"workers-{n}.sqlite"
        store.unlink(missing_ok=True)
        load0 = os.getloadavg()[0]
        t0 = time.perf_counter()
        run = run_study(spec, store, engine="dask", workers=n)
        walls[n] = time.perf_counter() - t0
        stores[n] = store
        print(
            f"{n} worker(s): {run.computed} runs in {walls[n]:.1f} s "
            f"({len(run.failures)} failed); load average before {load0:.2f}, "
            f"after {os.getloadavg()[0]:.2f}"
        )
    if len(walls) == 2:
        (a, wa), (b, wb) = sorted(walls.items())
        print(f"speed-up {a} -> {b} workers: {wa / wb:.2f}x")
    rows = {}
    for n, store in stores.items():
        with ResultStore.open(store, readonly=True) as db:
            rows[n] = sorted(_comparable(db.rows()), key=lambda r: r["key"])
    first, *others = rows.values()
    print("stores agree run for run:", all(o == first for o in others))
    with ResultStore.open(stores[max(stores)], readonly=True) as db:
        print()
        print(study_summary(analyse(db.rows(), spec)))


if __name__ == "__main__":
    main()
