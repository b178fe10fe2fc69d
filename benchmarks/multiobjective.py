"""The multi-objective spiral search against pymoo on ZDT, DTLZ and WFG.

Problems (pymoo's definitions and reference fronts): ZDT1-4 and ZDT6 (2
objectives, 30 or 10 variables), DTLZ1-7 (3 objectives, pymoo's default
sizes), ``dtlz2-4`` and ``dtlz2-5`` (DTLZ2 with 4 and 5 objectives and
pymoo's 10 variables) and ``wfg2`` (2 objectives, 24 variables: 4 position
and 20 distance ones; its front, in 5 disconnected pieces, computed here,
and its objectives divided by the front's nadir (2, 4) so that it spans the
unit square).
Optimisers at the same budget of evaluations: ``MO-learned-metric``,
``MO-Eb-SDA`` and ``MO-SDA`` (``spiralid.optim.minimize_pareto``, 100
points), ``MO-default`` (``minimize_pareto`` with no method: what a user
gets), ``MO-learned-metric-no-crossover`` (the poll without its crossover
pairs), pymoo's NSGA-II and SMS-EMOA (population 100), MOEA/D (Das-Dennis
weights, 99, 91 or 84 of them, 10 neighbours) and NSGA-III (population 100,
the spiral's own weight vectors as reference directions: 100, 91, 84 or,
for 5 objectives, 70 in two layers), and random search (the non-dominated
set of uniform draws). Hypervolume (moocore) from the
reference point 1.1 x the reference front's nadir (DTLZ5-7's fronts, which
pymoo would download, are computed here), and IGD+ to pymoo's reference
front (WFG2's and DTLZ2's with 4 objectives computed here); median and
interquartile range over seeds, and the two-sided rank-sum p-value against
NSGA-II per problem (``spiralid.study.statistics.rank_sum``); median wall
time per run and the optimiser's own time per evaluation (wall time minus
the time inside the problem's evaluation).

Run: ``python benchmarks/multiobjective.py [--seeds 20] [--budgets
25000,10000] [--problems zdt1,dtlz2] [--methods NSGA-II,MO-Eb-SDA]
[--workers 2] [--rows runs.jsonl]`` (pymoo and moocore:
``pip install pymoo moocore``, in the ``bench`` extra).

``--defaults`` is the defaults' case: ``minimize_pareto`` called with no
method (``MO-default``) beside the paper's Eb-SDA, NSGA-II and NSGA-III on
WFG2 and DTLZ2 with 5 objectives, 25,000 evaluations, 3 seeds (each of
``--seeds``, ``--budgets``, ``--problems`` and ``--methods`` given beside it
replaces its part). ``--points N`` (default 100) sets every method's
points, population and reference directions (``spiralid.optim.weight_vectors(k,
N)``; MOEA/D keeps its lattices at 100); its rows are labelled
``method@N``.
"""

import argparse
import functools
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from spiralid.choices import DEFAULT_PARETO_METHOD
from spiralid.optim import LearnedMetricSpiral, minimize_pareto
from spiralid.optim.front import weight_vectors
from spiralid.study.statistics import rank_sum

PROBLEMS = (
    *("zdt1", "zdt2", "zdt3", "zdt4", "zdt6"),
    *(f"dtlz{i}" for i in range(1, 8)),
    "dtlz2-4",
    "dtlz2-5",
    "wfg2",
)
# pymoo's name and arguments where the benchmark's name is not pymoo's.
_PYMOO = {
    "dtlz2-4": ("dtlz2", {"n_obj": 4}),
    "dtlz2-5": ("dtlz2", {"n_obj": 5}),
    "wfg2": ("wfg2", {"n_var": 24, "n_obj": 2}),
}
# Objectives divided by these (the true front's nadir) before the
# indicators: WFG's objective j spans [0, 2j].
_SCALE = {"wfg2": np.array([2.0, 4.0])}


def _wfg2_front():
    """WFG2's front for 2 objectives: the position y in [0, 1] gives
    (2 (1 - cos(pi y / 2)), 4 (1 - y cos^2(5 pi y))) with the distance
    variables at their optimum; its non-dominated part, 5 pieces."""
    y = np.linspace(0.0, 1.0, 200_001)
    f = np.column_stack(
        [
            2.0 * (1.0 - np.cos(np.pi * y / 2)),
            4.0 * (1.0 - y * np.cos(5 * np.pi * y) ** 2),
        ]
    )
    f = f[np.lexsort((f[:, 1], f[:, 0]))]
    keep = f[:, 1] < np.minimum.accumulate(np.r_[np.inf, f[:-1, 1]])
    return f[keep][::10]


def _offline_front(name):
    """DTLZ5-7's reference fronts, which pymoo downloads: computed here
    (3 objectives, g = 0 for DTLZ5/6 and g = 1 for DTLZ7)."""
    if name in ("dtlz5", "dtlz6"):
        # The degenerate front: a quarter circle in the plane f1 = f2.
        t = np.linspace(0.0, np.pi / 2, 1000)
        c = np.cos(t) / np.sqrt(2.0)
        return np.column_stack([c, c, np.sin(t)])
    if name == "wfg2":
        return _wfg2_front()
    if name in ("dtlz2-4", "dtlz2-5"):
        # The unit sphere's positive orthant: 455 and 495 points.
        from pymoo.util.ref_dirs import get_reference_directions

        k = int(name[-1])
        parts = {4: 12, 5: 8}[k]
        d = get_reference_directions("das-dennis", k, n_partitions=parts)
        return d / np.linalg.norm(d, axis=1, keepdims=True)
    if name == "dtlz7":
        import moocore

        g = np.linspace(0.0, 1.0, 200)
        f1, f2 = (v.ravel() for v in np.meshgrid(g, g))
        h = 3.0 - sum(f / 2.0 * (1.0 + np.sin(3.0 * np.pi * f)) for f in (f1, f2))
        f = np.column_stack([f1, f2, 2.0 * h])
        return f[moocore.is_nondominated(f)]
    return None


def _problem(name):
    """A fresh pymoo problem (each run times its own evaluations) and the
    reference front, computed once per process."""
    from pymoo.problems import get_problem

    pymoo_name, kwargs = _PYMOO.get(name, (name, {}))
    return get_problem(pymoo_name, **kwargs), _reference_front(name)


@functools.cache
def _reference_front(name):
    front = _offline_front(name)
    if front is not None:
        return front
    from pymoo.problems import get_problem

    problem = get_problem(name)
    front = problem.pareto_front()
    if front is None or len(front) < 2:
        from pymoo.util.ref_dirs import get_reference_directions

        front = problem.pareto_front(
            get_reference_directions("das-dennis", 3, n_partitions=12)
        )
    return np.asarray(front, dtype=float)


class _Timed:
    """Times the problem's own evaluations (every optimiser calls them)."""

    def __init__(self, problem):
        self.seconds = 0.0
        inner = problem._evaluate

        def timed(*args, **kwargs):
            start = time.perf_counter()
            try:
                return inner(*args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - start

        problem._evaluate = timed


def _spiral(method, archive=True):
    """A spiral run; `method` None leaves minimize_pareto's default."""
    rule = () if method is None else (method,)

    def run(problem, seed, budget, points=100):
        box = np.column_stack([problem.xl, problem.xu])
        res = minimize_pareto(
            lambda x: problem.evaluate(x), box, *rule, n_points=points,
            max_nfev=budget, rng=seed, vectorized=True, archive=archive,
        )  # fmt: skip
        return res.fun

    return run


def _pymoo(kind):
    def run(problem, seed, budget, points=100):
        from pymoo.algorithms.moo.moead import MOEAD
        from pymoo.algorithms.moo.nsga2 import NSGA2
        from pymoo.algorithms.moo.nsga3 import NSGA3
        from pymoo.algorithms.moo.sms import SMSEMOA
        from pymoo.optimize import minimize
        from pymoo.util.ref_dirs import get_reference_directions

        if kind == "NSGA-II":
            algorithm = NSGA2(pop_size=points)
        elif kind == "SMS-EMOA":
            algorithm = SMSEMOA(pop_size=points)
        elif kind == "NSGA-III":
            # The spiral's subproblems' weights as reference directions
            # (Das-Dennis, with NSGA-III's inner layer when the lattice has
            # no interior: 5 objectives at 100 points).
            dirs = weight_vectors(problem.n_obj, points)
            algorithm = NSGA3(dirs, pop_size=points)
        elif points == 100 and problem.n_obj in (2, 3, 4):
            parts = {2: 99, 3: 12, 4: 6}[problem.n_obj]
            dirs = get_reference_directions(
                "das-dennis", problem.n_obj, n_partitions=parts
            )
            algorithm = MOEAD(dirs, n_neighbors=10)
        else:
            dirs = weight_vectors(problem.n_obj, points)
            algorithm = MOEAD(dirs, n_neighbors=10)
        res = minimize(
            problem, algorithm, ("n_evals", budget), seed=seed, verbose=False
        )
        return np.atleast_2d(res.F)

    return run


def _random(problem, seed, budget, points=None):
    from spiralid.optim import non_dominated

    rng = np.random.default_rng(seed)
    x = rng.uniform(problem.xl, problem.xu, size=(budget, problem.n_var))
    f = problem.evaluate(x)
    keep = np.zeros(len(f), bool)
    for start in range(0, len(f), 2000):  # filter in chunks, then the union
        chunk = np.arange(start, min(start + 2000, len(f)))
        keep[chunk[non_dominated(f[chunk])]] = True
    idx = np.flatnonzero(keep)
    return f[idx[non_dominated(f[idx])]]


# NSGA-II first: every other row is tested against it.
METHODS = {
    "NSGA-II": _pymoo("NSGA-II"),
    "MO-learned-metric": _spiral("learned-metric"),
    # What a user gets: minimize_pareto with no method.
    "MO-default": _spiral(None),
    "MO-learned-metric-axes": _spiral(LearnedMetricSpiral(basis=False)),
    # Ablation: the poll without its crossover pairs.
    "MO-learned-metric-no-crossover": _spiral(LearnedMetricSpiral(crossover=0.0)),
    "MO-Eb-SDA": _spiral("ebsda"),
    "MO-SDA": _spiral("sda"),
    # Ablations: the non-dominated incumbents instead of the thinned archive.
    "MO-learned-metric-axes-no-archive": _spiral(
        LearnedMetricSpiral(basis=False), archive=False
    ),
    "MO-Eb-SDA-no-archive": _spiral("ebsda", archive=False),
    "MO-SDA-no-archive": _spiral("sda", archive=False),
    "MOEA/D": _pymoo("MOEA/D"),
    "SMS-EMOA": _pymoo("SMS-EMOA"),
    "NSGA-III": _pymoo("NSGA-III"),
    "random": _random,
}
# --defaults: minimize_pareto's default against NSGA-II and NSGA-III where
# the paper's Eb-SDA was weakest (a benchmark figure, not a timed test).
DEFAULTS_CASE = dict(
    seeds=3,
    budgets="25000",
    problems="wfg2,dtlz2-5",
    methods="NSGA-II,NSGA-III,MO-default,MO-Eb-SDA",
)


def _indicators(f, front, scale=None):
    import moocore

    if scale is not None:
        f, front = f / scale, front / scale
    ref = 1.1 * front.max(axis=0)
    hv = float(moocore.hypervolume(f, ref=ref))
    gap = np.maximum(f[None, :, :] - front[:, None, :], 0.0)
    igd_plus = float(np.mean(np.min(np.linalg.norm(gap, axis=2), axis=1)))
    return hv, igd_plus


def run_one(task):
    """One (problem, method, seed, budget): its indicators and times; a
    method ``name@N`` runs with N points."""
    name, method, seed, budget = task
    problem, front = _problem(name)
    timer = _Timed(problem)
    t0 = time.perf_counter()
    base, _, points = method.partition("@")
    f = METHODS[base](problem, seed, budget, int(points or 100))
    wall = time.perf_counter() - t0
    hv, igd_plus = _indicators(f, front, _SCALE.get(name))
    own_us = 1e6 * (wall - timer.seconds) / budget
    return name, method, seed, budget, hv, igd_plus, wall, own_us


def _present(rows) -> tuple[list, str]:
    """The methods of `rows` (labels, ``name@N`` with N points) in the
    order of METHODS, and NSGA-II's label."""
    labels = sorted(
        {r[1] for r in rows}, key=lambda m: list(METHODS).index(m.partition("@")[0])
    )
    nsga2 = next((m for m in labels if m.partition("@")[0] == "NSGA-II"), "NSGA-II")
    return labels, nsga2


def _compact(rows, problems, budget) -> None:
    """One line per problem: every method's median hypervolume, the best
    spiral's rank-sum p against NSGA-II; then each method's median wall time
    per run and own time per evaluation over all problems."""
    present, nsga2 = _present(rows)
    spirals = [m for m in present if m.startswith("MO-")]
    print(f"\nmedian hypervolume, {budget} evaluations\n")
    print("| problem | " + " | ".join(present) + " | best spiral, p vs NSGA-II |")
    print("|---" * (len(present) + 2) + "|")
    for name in problems:
        hv = {
            m: np.array([r[4] for r in rows if r[0] == name and r[1] == m])
            for m in present
        }
        cells = " | ".join(f"{np.median(hv[m]):.4g}" for m in present)
        if not spirals or nsga2 not in hv:
            print(f"| {name} | {cells} | |")
            continue
        best = max(spirals, key=lambda m: np.median(hv[m]))
        p = rank_sum(hv[best], hv[nsga2])["p_two_sided"]
        print(f"| {name} | {cells} | {best}, {p:.2g} |")
    for label, col in (("s/run", 6), ("own us/eval", 7)):
        cells = " | ".join(
            f"{np.median([r[col] for r in rows if r[1] == m]):.3g}" for m in present
        )
        print(f"| {label} (median) | {cells} | |")


def _table(rows, problems, budget, seeds) -> int:
    """Print one budget's table; return the problems where the best spiral
    is at or above NSGA-II's median hypervolume."""
    print(f"\n{budget} evaluations, {seeds} seeds\n")
    print(
        "| problem | method | median HV | HV IQR | median IGD+ | p vs NSGA-II "
        "| s/run | own us/eval |"
    )
    print("|---|---|---|---|---|---|---|---|")
    wins = 0
    present, nsga2 = _present(rows)
    spirals = [m for m in present if m.startswith("MO-")]
    for name in problems:
        hv = {}
        for method in present:
            mine = [r for r in rows if r[0] == name and r[1] == method]
            if not mine:
                continue
            hv[method] = np.array([r[4] for r in mine])
            q1, q3 = np.percentile(hv[method], [25, 75])
            p = (
                ""
                if method == nsga2 or nsga2 not in hv
                else f"{rank_sum(hv[method], hv[nsga2])['p_two_sided']:.3g}"
            )
            print(
                f"| {name} | {method} | {np.median(hv[method]):.4g} | "
                f"{q3 - q1:.3g} | {np.median([r[5] for r in mine]):.4g} | {p} | "
                f"{np.median([r[6] for r in mine]):.2f} | "
                f"{np.median([r[7] for r in mine]):.1f} |"
            )
        best = max((np.median(hv[m]) for m in spirals if m in hv), default=-np.inf)
        wins += bool(best >= np.median(hv.get(nsga2, np.inf)))
    print(
        f"\nbest spiral at or above NSGA-II's median hypervolume on {wins} of "
        f"{len(problems)} problems at {budget} evaluations"
    )
    return wins


def _defaults_table(rows, problems, budget) -> None:
    """The defaults' case: each method's median hypervolume per problem and
    the default's median over the best pymoo method's."""
    present, _ = _present(rows)
    others = [m for m in present if not m.startswith("MO-")]
    default = next((m for m in present if m.partition("@")[0] == "MO-default"), "")
    print(f"\nthe defaults' case, median hypervolume, {budget} evaluations\n")
    print("| problem | " + " | ".join(present) + " | MO-default / best pymoo |")
    print("|---" * (len(present) + 2) + "|")
    for name in problems:
        hv = {
            m: np.median([r[4] for r in rows if r[0] == name and r[1] == m])
            for m in present
        }
        cells = " | ".join(f"{hv[m]:.4g}" for m in present)
        best = max(others, key=lambda m: hv[m]) if others else None
        ratio = (
            f"{hv[default] / hv[best]:.3f} ({best})"
            if best and default and hv[best] > 0
            else ""
        )
        print(f"| {name} | {cells} | {ratio} |")


def _stored(path) -> list:
    if not path or not os.path.exists(path):
        return []
    with open(path) as rows:
        return [tuple(json.loads(line)) for line in rows if line.strip()]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, help="default 20")
    ap.add_argument("--budgets", help="default 25000,10000")
    ap.add_argument("--problems", help="default all of them")
    ap.add_argument("--methods", help="default all of them")
    ap.add_argument(
        "--defaults",
        action="store_true",
        help="the defaults' case: minimize_pareto with no method against "
        "NSGA-II, NSGA-III and Eb-SDA on wfg2 and dtlz2-5, 25000 "
        "evaluations, 3 seeds (options given beside it replace those parts)",
    )
    ap.add_argument(
        "--points",
        type=int,
        default=100,
        help="every method's points, population and reference directions",
    )
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument(
        "--rows",
        help="a JSON-lines file of finished runs: those already there are not "
        "run again, new ones are appended, the tables cover all of them",
    )
    args = ap.parse_args(argv)
    preset = DEFAULTS_CASE if args.defaults else dict(
        seeds=20, budgets="25000,10000", problems=",".join(PROBLEMS),
        methods=",".join(METHODS),
    )  # fmt: skip
    for name, value in preset.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    if args.defaults:
        print(
            f"minimize_pareto's default method: {DEFAULT_PARETO_METHOD!r} "
            f"(MO-default); the paper's Eb-SDA is 'ebsda' (MO-Eb-SDA)"
        )
    t_all, load0 = time.perf_counter(), os.getloadavg()[0]
    problems = args.problems.split(",")
    budgets = [int(b) for b in args.budgets.split(",")]
    unknown = [m for m in args.methods.split(",") if m not in METHODS]
    if unknown:
        ap.error(f"--methods must be among {', '.join(METHODS)}; got {unknown}")
    suffix = "" if args.points == 100 else f"@{args.points}"
    tasks = [
        (name, method + suffix, seed, budget)
        for budget in budgets
        for name in problems
        for method in args.methods.split(",")
        for seed in range(args.seeds)
    ]
    rows = _stored(args.rows)
    done = {tuple(r[:4]) for r in rows}
    todo = [t for t in tasks if t not in done]
    with ProcessPoolExecutor(args.workers) as pool:
        for row in pool.map(run_one, todo, chunksize=4):
            rows.append(row)
            if args.rows:
                with open(args.rows, "a") as out:
                    out.write(json.dumps(row) + "\n")
    rows = [r for r in rows if tuple(r[:4]) in set(tasks)]
    for budget in budgets:
        mine = [r for r in rows if r[3] == budget]
        _table(mine, problems, budget, args.seeds)
        _compact(mine, problems, budget)
        if args.defaults:
            _defaults_table(mine, problems, budget)
    print(
        f"\n{len(todo)} runs in {time.perf_counter() - t_all:.0f} s with "
        f"{args.workers} worker(s), load {load0:.2f} -> {os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
