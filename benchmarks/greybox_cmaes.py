"""The grey box's search against pycma's CMA-ES at equal evaluations.

Both minimise the same cost, the grey box's eq. (2) on the free-run
simulation error (:class:`~spiralid.sysid.estimation.greybox.problem.GreyBoxProblem`,
what ``identify(data, greybox)`` minimises), in the same coordinates: the
unit box of the free parameters, log-scaled where a parameter has a log
scale. Both start from the same point, the initial values' (``z0``), and
get the same budget of simulations (``--budget``, default 1,000, the
default fit's search budget):

- ``spiral``: the default fit's search itself (``method="spiral"``'s
  search part: the learned-metric spiral, its first run a population run
  centred at ``z0`` with step ``1 / sqrt(12)``, its restarts alternating
  around the best point so far and over the box, trial points clipped onto
  the box), seeded with the seed;
- ``spiral-x0``: the same with the learned-metric spiral's start from the
  initial values (``first_sigma = 1 / sqrt(12)``: a first population run
  centred at ``z0`` with CMA-ES's population and ``sigma0``;
  ``local_sigma = 0.1``: population restarts alternating around the best
  point so far and over the box);
- ``cma``: pycma's ``CMAEvolutionStrategy`` from ``z0`` with bounds
  ``[0, 1]`` (its default boundary handling), its default population
  (``4 + 3 ln n``) and ``sigma0 = 1 / sqrt(12)``, the spread of the uniform
  initial population the spiral draws over the box, seeded with
  ``seed + 1`` (pycma draws an unseeded stream for 0). Its first
  evaluation is ``z0`` itself (the spiral's population holds it). The last
  generation is cut at the budget, and if CMA-ES stops on its own earlier
  the evaluations it spent are printed.

Each search's best point is then polished by the default fit's
Levenberg-Marquardt (200 evaluations, the Jacobian's simulations
included; kept where it lowers the cost): the cost before and after the
polish is reported, per seed, then the median, the interquartile range and
the wins (lower cost by more than 1e-9 relative) over the seeds.

Problems (``--problems``):

- ``rig4``, ``rig6``: :class:`~spiralid.fms.greybox.RigGreyBox` with 4 and
  6 free parameters on the nonlinear rig's hub angle, as
  ``benchmarks/rig_greybox.py`` (the paper experiment, seed 0's record,
  its first two thirds; start: the preset with the friction off), the cost
  over the whole estimation record;
- ``rig4-tenth``, ``rig6-tenth``: the same over its first tenth, the record
  the default fit's horizons search on (over the whole record the friction
  plane is rugged);
- ``tanks``: ``tanks_greybox()`` (8 parameters and the 2 initial levels
  free) on the Cascaded Tanks estimation record.

The default fit's search over the horizons' first tenth has three times
the whole record's budget (``_search_budget``): ``--budget 3000`` on the
``-tenth`` problems compares the searches as that fit runs them.

With ``--whole-fit`` (``rig4``, ``rig6``) the whole default fit,
``identify(est, box, rng=seed)`` (both searches, the horizons, every
polish), runs once with each search in it at the fit's own budgets, and
its cost, its validation fit on the record's last third and its
simulations are printed.

BLAS runs on one thread unless set (as the command line does). Seconds
are the machine's and indicative.

    python benchmarks/greybox_cmaes.py --seeds 0-9 --problems tanks rig4
    python benchmarks/greybox_cmaes.py --searches spiral-x0 cma
    python benchmarks/greybox_cmaes.py --budget 3000 --problems rig4-tenth
    python benchmarks/greybox_cmaes.py --whole-fit --problems rig4 rig6
"""

from __future__ import annotations

import argparse
import contextlib
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time

import cma
import numpy as np
from _cli import seed_list
from rig_greybox import FREE, MODES, SIX, START, _hub_record

from spiralid.datasets import cascaded_tanks
from spiralid.datasets.tanks_model import tanks_greybox
from spiralid.fms.greybox import RigGreyBox
from spiralid.optim import LearnedMetricSpiral, minimize
from spiralid.sysid import identify, validate
from spiralid.sysid.estimation.greybox import fit
from spiralid.sysid.estimation.greybox.fit import (
    _N_POINTS,
    _POLISH_NFEV,
    _RESTARTS,
    _polish,
    _search,
    _search_budget,
)
from spiralid.sysid.estimation.greybox.parallel import ParallelEvaluator
from spiralid.sysid.estimation.greybox.problem import GreyBoxProblem

SIGMA0 = 1 / np.sqrt(12)
# ``spiral-x0``: a first population run centred at the initial values with
# CMA-ES's sigma0, population restarts alternating around the best point so
# far (a tenth of the box) and over the box.
X0_START = LearnedMetricSpiral(first_sigma=SIGMA0, local_sigma=0.1)


def _rig(free: list[str], share: float) -> GreyBoxProblem:
    est, _ = _hub_record(0)
    if share < 1:
        est = est[: round(share * est.n)]
    return GreyBoxProblem(est, RigGreyBox(free, START, n_modes=MODES))


PROBLEMS = {
    "rig4": lambda: _rig(FREE, 1.0),
    "rig6": lambda: _rig(SIX, 1.0),
    "rig4-tenth": lambda: _rig(FREE, 0.1),
    "rig6-tenth": lambda: _rig(SIX, 0.1),
    "tanks": lambda: GreyBoxProblem(cascaded_tanks(), tanks_greybox()),
}


def spiral(problem: GreyBoxProblem, seed: int, budget: int, pool) -> np.ndarray:
    return _search(problem, "spiral", {"rng": seed, "max_nfev": budget}, pool)


def cmaes(problem: GreyBoxProblem, seed: int, budget: int, pool) -> np.ndarray:
    es = cma.CMAEvolutionStrategy(
        problem.z0,
        SIGMA0,
        {"bounds": [0.0, 1.0], "seed": seed + 1, "verbose": -9, "maxfevals": budget},
    )
    # The start is evaluated first, as the spiral's population holds it:
    # the best found is never worse than the start for either.
    best, best_z, spent = problem(problem.z0), problem.z0, 1
    while spent < budget and not es.stop():
        points = es.ask()
        take = min(len(points), budget - spent)
        costs = [problem(np.asarray(z)) for z in points[:take]]
        spent += take
        i = int(np.argmin(costs))
        if costs[i] < best:
            best, best_z = costs[i], np.clip(np.asarray(points[i]), 0.0, 1.0)
        if take < len(points):
            break
        es.tell(points, costs)
    return best_z


def spiral_x0(problem: GreyBoxProblem, seed: int, budget: int, pool) -> np.ndarray:
    """The default fit's search with the learned-metric spiral's start from
    the initial values (``X0_START``), as ``_search`` runs it otherwise."""
    found = minimize(
        problem,
        np.tile([0.0, 1.0], (problem.n_free, 1)),
        method=X0_START,
        n_points=_N_POINTS,
        max_nfev=budget,
        rng=seed,
        x0=problem.z0,
        restarts=_RESTARTS,
        options={"bounds_policy": "clip"},
    )
    return np.clip(np.asarray(found.x, dtype=float), 0.0, 1.0)


SEARCHES = {"spiral": spiral, "cma": cmaes, "spiral-x0": spiral_x0}


def run(problem: GreyBoxProblem, search, seed: int, budget: int) -> tuple:
    """(cost found, cost after the polish, evaluations of the search,
    seconds)."""
    t0 = time.perf_counter()
    with ParallelEvaluator(problem, None) as pool:
        before = problem.nfev
        z = search(problem, seed, budget, pool)
        spent = problem.nfev - before
        found = problem(z)
        polished = _polish(problem, z, _POLISH_NFEV, pool)
        after = min(found, problem(polished))
    return found, after, spent, time.perf_counter() - t0


@contextlib.contextmanager
def _fit_searching_by(search):
    """``identify``'s grey-box fit with `search` in place of its own, at the
    same budgets (three over the horizons' first tenth)."""

    def swapped(problem, method, given, pool, share=1.0):
        budget = _search_budget(given, _N_POINTS, share)
        return search(problem, given["rng"], budget, pool)

    own, fit._search = fit._search, swapped
    try:
        yield
    finally:
        fit._search = own


def whole_fits(free: list[str], searches: list[str], seeds: list[int]) -> None:
    """The default fit (``identify(est, box, rng=seed)``: both searches,
    the horizons, the polishes) with each search in turn, on the hub
    record: its cost, validation fit on the last third and simulations."""
    est, val = _hub_record(0)
    box = RigGreyBox(free, START, n_modes=MODES)
    print(f"\n## the default fit, {len(free)} free, each search in it")
    print(" | ".join(["seed", *(f"{k} cost, val. %, nfev" for k in searches)]))
    rows = {label: [] for label in searches}
    for seed in seeds:
        cells = []
        for label in searches:
            with _fit_searching_by(SEARCHES[label]):
                model = identify(est, box, rng=seed)
            score = float(validate(model, val, warmup=est).fit_percent)
            rows[label].append((model.cost, score))
            cells.append(f"{model.cost:.5g}, {score:.2f}, {model.nfev}")
        print(" | ".join([f"{seed:4d}", *cells]), flush=True)
    if "cma" in rows:
        c = np.array(rows["cma"])
        for label in [key for key in rows if key != "cma"]:
            s = np.array(rows[label])
            print(f"  {label} against cma: median [IQR] over the seeds")
            _summary("cost", s[:, 0], c[:, 0])
            print(
                f"  validation fit %: median {np.median(s[:, 1]):.2f}, lowest "
                f"{s[:, 1].min():.2f}; cma {np.median(c[:, 1]):.2f}, lowest "
                f"{c[:, 1].min():.2f}"
            )


def _summary(label: str, a: np.ndarray, b: np.ndarray) -> None:
    def stats(x):
        q1, med, q3 = np.percentile(x, [25, 50, 75])
        return f"{med:10.4g} [{q1:.4g}, {q3:.4g}]"

    tol = 1e-9 * np.maximum(np.abs(a), np.abs(b))
    wins = int(np.sum(a < b - tol)), int(np.sum(b < a - tol))
    ties = len(a) - sum(wins)
    print(
        f"  {label:15s} spiral {stats(a)}   cma {stats(b)}   "
        f"wins spiral {wins[0]}, cma {wins[1]}, ties {ties}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=seed_list, default=list(range(10)))
    parser.add_argument("--budget", type=int, default=1000)
    parser.add_argument(
        "--problems",
        nargs="+",
        choices=list(PROBLEMS),
        help="default: every problem (rig4 and rig6 with --whole-fit)",
    )
    # One search alone reruns one side (CMA-ES's runs repeat bit for bit
    # with the seed), half the machine time of a run of both.
    parser.add_argument(
        "--searches", nargs="+", choices=list(SEARCHES), default=list(SEARCHES)
    )
    parser.add_argument(
        "--whole-fit",
        action="store_true",
        help="the default fit with each search in it (rig4, rig6 only)",
    )
    args = parser.parse_args()
    if args.whole_fit:
        rigs = {"rig4": FREE, "rig6": SIX}
        args.problems = args.problems or list(rigs)
        if not set(args.problems) <= set(rigs):
            parser.error("--whole-fit takes --problems rig4 and rig6 only")
        for name in args.problems:
            whole_fits(rigs[name], args.searches, args.seeds)
        return
    args.problems = args.problems or list(PROBLEMS)
    print(f"budget {args.budget} simulations, seeds {args.seeds}")
    for name in args.problems:
        problem = PROBLEMS[name]()
        problem(problem.z0)  # compiles the simulation once, outside the timing
        print(f"\n## {name}: {problem.n_free} free, N = {problem.y.size}")
        print(f"start cost {problem(problem.z0):.4g}")
        heads = [f"{label} found, polished, nfev, s" for label in args.searches]
        print(" | ".join(["seed", *heads]))
        rows = {label: [] for label in args.searches}
        for seed in args.seeds:
            cells = []
            for label in args.searches:
                out = run(problem, SEARCHES[label], seed, args.budget)
                rows[label].append(out)
                cells.append(f"{out[0]:.5g}, {out[1]:.5g}, {out[2]}, {out[3]:.0f}")
            print(" | ".join([f"{seed:4d}", *cells]), flush=True)
        if "cma" not in rows:
            continue
        c = np.array(rows["cma"])
        for label in [key for key in rows if key != "cma"]:
            s = np.array(rows[label])
            print(f"  {label} against cma: median [IQR] of the cost over the seeds")
            _summary("found", s[:, 0], c[:, 0])
            _summary("polished", s[:, 1], c[:, 1])


if __name__ == "__main__":
    main()
