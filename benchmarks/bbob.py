"""The spiral optimisers on COCO's ``bbob`` suite, with pycma and SciPy as
references.

Runs every spiral rule of :func:`spiralid.optim.minimize` (the paper's SDA,
Eb-SDA and LASDA, the scale-free Eb-SDA, Tamura & Yasuda's periodic and
convergent settings, the learned-metric spiral), each also with restarts;
the learned-metric spiral with one ingredient taken away at a time
(``learned-metric-axes``: the box's axes, no learned basis; ``-scheduled``:
the periodic setting's budget schedule instead of success-based steps;
``-no-model``: no model step; ``-polls-only``: restarts without population
periods; ``-orthogonal``: orthogonal instead of independent directions in
the population periods, an option added rather than an ingredient taken
away; ``-global-stall``: a run's stall counted from the best of all runs,
not its own; ``-lazy``: the basis decomposed every ``n // 10`` periods;
``-eager``: every period, population runs too (the default decomposes on
pycma's ``purecma`` gap, every second period of the first population run
at D = 40 and every period below);
``-uncapped``: the poll's metric's condition unbounded; ``-mirror-biased``:
every population run's step size with the mirrored pairs' bias;
``-fixed-share``: the population run after a suspended poll cut at half the
poll's evaluations even while it closes in on the poll;
``-long-crawl-window``: the crawl test over ``max(30, 4 n)`` periods, not
``max(30, 2 n)``; ``-cma-path``: the step-size path in CMA-ES's fixed
coordinates, an option added rather than an ingredient taken away);
IPOP-CMA-ES
and BIPOP-CMA-ES (pycma), SciPy's BFGS (finite differences) and
Nelder-Mead restarted from uniform points, and uniform random search,
through ``cocoex`` on the noiseless ``bbob`` suite at a
budget of ``budget x D`` evaluations per problem. It writes the standard
COCO data folder (``OUTPUT/exdata/<method>``, one per method) that
``cocopp`` post-processes (``OUTPUT/ppdata``), and prints per method and
dimension the fraction of (function, instance, target) triples reached for
COCO's 51 standard targets ``10^2 ... 10^-8`` on ``f - f_opt``, with wall
times and the optimiser's own time per evaluation (wall time minus the time
spent inside the COCO problem, observer logging included).

Needs the ``bench`` extra: ``pip install -e ".[bench]"``.

Full size (dimensions 2, 5, 10, 20; 24 functions; 15 instances; budget
1000 D; about an hour on 2 cores)::

    python benchmarks/bbob.py --output bbob-output --jobs 2

D = 40 for the three leading methods, instances 1-3 (21 minutes on one
loaded core)::

    python benchmarks/bbob.py --dims 40 --instances 1 2 3 \
        --methods learned-metric+restarts cma bipop-cma --output bbob-40

Instances that no setting was chosen on (``--instances`` picks positions in
COCO's default list, which holds instances 1-5 and 71-80;
``--instance-ids`` names instances themselves)::

    python benchmarks/bbob.py --dims 20 --instance-ids 16-30 \
        --methods learned-metric+restarts cma bipop-cma --output bbob-held-out

Reduced size, as the test suite runs it::

    python benchmarks/bbob.py --dims 2 --functions 1 8 15 --instances 1 \\
        --output /tmp/bbob-small
"""

import argparse
import json
import math
import multiprocessing
import os
import re
import sys
import time
from pathlib import Path

# One BLAS thread per process, set before NumPy loads: the tasks share two
# cores with each other and other jobs, and OpenBLAS's threads spinning for
# a core made a D = 40 eigendecomposition up to ten times slower under load
# (for pycma and the spiral alike), which the times per evaluation showed.
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402

from spiralid.optim import (  # noqa: E402
    RULES,
    LearnedMetricSpiral,
    Restarts,
    minimize,
)

TARGETS = 10.0 ** (2.0 - 0.2 * np.arange(51))  # COCO's 51 standard targets
DIMS = (2, 5, 10, 20)
FUNCTIONS = tuple(range(1, 25))
INSTANCES = tuple(range(1, 16))
# BBOB's five function groups.
GROUPS = {
    "separable": range(1, 6),
    "moderate": range(6, 10),
    "ill-conditioned": range(10, 15),
    "multimodal": range(15, 20),
    "weakly structured": range(20, 25),
}
RESTART = "+restarts"
# The learned-metric rule with one ingredient taken away at a time: the
# box's own axes instead of the learned basis, and the periodic setting's
# budget schedule instead of success-based steps.
INGREDIENTS = {
    "learned-metric-axes": LearnedMetricSpiral(basis=False),
    "learned-metric-scheduled": LearnedMetricSpiral(success_steps=False),
    "learned-metric-no-model": LearnedMetricSpiral(model_step=False),
    "learned-metric-polls-only": LearnedMetricSpiral(populations=False),
    "learned-metric-orthogonal": LearnedMetricSpiral(sampling="orthogonal"),
    "learned-metric-global-stall": LearnedMetricSpiral(run_stall=False),
    "learned-metric-lazy": LearnedMetricSpiral(basis_gap="n/10"),
    "learned-metric-eager": LearnedMetricSpiral(basis_gap="every"),
    "learned-metric-uncapped": LearnedMetricSpiral(max_condition=None),
    "learned-metric-no-suspend": LearnedMetricSpiral(suspend_crawl=False),
    "learned-metric-mirror-biased": LearnedMetricSpiral(unbiased_sigma=False),
    "learned-metric-fixed-share": LearnedMetricSpiral(extend_closing=False),
    "learned-metric-long-crawl-window": LearnedMetricSpiral(crawl_window=4.0),
    "learned-metric-cma-path": LearnedMetricSpiral(path_frame="cma"),
}
SPIRALS = (*RULES, *INGREDIENTS)
REFERENCES = ("cma", "bipop-cma", "bfgs", "nelder-mead", "random")
ALL_METHODS = (*SPIRALS, *(m + RESTART for m in SPIRALS), *REFERENCES)
# Every bbob function has its optimum in [-4, 4]^D; the search box is [-5, 5]^D.
SIGMA0 = 2.0


class _Timed:
    """The COCO problem as a vectorised objective that times its own calls."""

    def __init__(self, problem):
        self.problem = problem
        self.seconds = 0.0

    def __call__(self, X):
        start = time.perf_counter()
        out = np.fromiter((self.problem(x) for x in X), np.float64, len(X))
        self.seconds += time.perf_counter() - start
        return out


class _Spent(Exception):
    """The budget is spent or the final target hit: ends a run from inside."""


def _spiral(problem, objective, budget, rng, method, n_points):
    """A spiral search, ended by its budget or, as BIPOP-CMA-ES is, by the
    objective once the final target is hit (a callback would build the
    search's result after every period, and that is not the optimiser's
    time)."""
    name, restarts = method.removesuffix(RESTART), method.endswith(RESTART)
    bounds = np.column_stack([problem.lower_bounds, problem.upper_bounds])

    def until_target(X):
        out = objective(X)
        if problem.final_target_hit:
            raise _Spent
        return out

    try:
        minimize(
            until_target,
            bounds,
            INGREDIENTS.get(name, name),
            n_points=n_points,
            max_iter=budget,  # the evaluation budget binds first
            max_nfev=budget,
            rng=rng,
            vectorized=True,
            restarts=Restarts() if restarts else False,
        )
    except _Spent:
        pass


def _cma(problem, objective, budget, rng, method, n_points):
    """IPOP-CMA-ES (pycma): restarts doubling the population, same budget.

    Like the spiral searches, it stops before a generation that would pass
    the budget (pycma's own ``maxfevals`` is checked after a generation).
    """
    import cma

    popsize = None  # pycma's default 4 + 3 ln D first
    while (
        not problem.final_target_hit and problem.evaluations + (popsize or 1) <= budget
    ):
        x0 = rng.uniform(-4.0, 4.0, problem.dimension)
        options = {
            "maxfevals": budget - problem.evaluations,
            "seed": int(rng.integers(1, 2**31)),
            "verbose": -9,
        }
        if popsize is not None:
            options["popsize"] = popsize
        es = cma.CMAEvolutionStrategy(x0, SIGMA0, options)
        while (
            not es.stop()
            and not problem.final_target_hit
            and problem.evaluations + es.popsize <= budget
        ):
            X = es.ask()
            es.tell(X, objective(np.array(X)).tolist())
        popsize = 2 * es.popsize


def _capped(problem, objective, budget):
    """`objective` for one point, raising _Spent instead of passing `budget`
    or once the final target is hit."""

    def fun(x):
        if problem.final_target_hit or problem.evaluations + 1 > budget:
            raise _Spent
        return float(objective(np.asarray(x)[None, :])[0])

    return fun


def _bipop_cma(problem, objective, budget, rng, method, n_points):
    """BIPOP-CMA-ES (pycma's ``fmin2(..., bipop=True)``), same budget."""
    import cma

    fun = _capped(problem, objective, budget)
    options = {
        "seed": int(rng.integers(1, 2**31)),
        "verbose": -9,
        "maxfevals": budget,
    }
    try:
        cma.fmin2(
            fun,
            lambda: rng.uniform(-4.0, 4.0, problem.dimension),
            SIGMA0,
            options,
            restarts=1000,
            bipop=True,
        )
    except _Spent:
        pass


def _scipy_restarted(problem, objective, budget, rng, method, n_points):
    """SciPy's BFGS (finite-difference gradients) or Nelder-Mead, restarted
    from uniform points in [-4, 4]^D until the budget is spent."""
    from scipy import optimize

    fun = _capped(problem, objective, budget)
    name = {"bfgs": "BFGS", "nelder-mead": "Nelder-Mead"}[method]
    try:
        while problem.evaluations < budget and not problem.final_target_hit:
            x0 = rng.uniform(-4.0, 4.0, problem.dimension)
            left = budget - problem.evaluations
            options = {"maxiter": left} if name == "BFGS" else {"maxfev": left}
            if name == "Nelder-Mead":
                options.update(xatol=1e-11, fatol=1e-11, adaptive=True)
            else:
                options.update(gtol=1e-10)
            optimize.minimize(fun, x0, method=name, options=options)
    except _Spent:
        pass


def _random(problem, objective, budget, rng, method, n_points):
    lo, hi = problem.lower_bounds, problem.upper_bounds
    left = budget
    while left > 0 and not problem.final_target_hit:
        k = min(left, 100)
        objective(rng.uniform(lo, hi, size=(k, problem.dimension)))
        left -= k


def _runner(method):
    return {
        "cma": _cma,
        "bipop-cma": _bipop_cma,
        "bfgs": _scipy_restarted,
        "nelder-mead": _scipy_restarted,
        "random": _random,
    }.get(method, _spiral)


class _Sphere:
    """A stand-in problem for the warm-up: imports and compiled kernels load
    outside the timed runs."""

    dimension = 2
    lower_bounds = np.full(2, -5.0)
    upper_bounds = np.full(2, 5.0)
    final_target_hit = False

    def __init__(self):
        self.evaluations = 0

    def __call__(self, x):
        self.evaluations += 1
        return float(np.dot(x, x))


def _warm_up(run, method, n_points) -> None:
    problem = _Sphere()
    run(problem, _Timed(problem), 200, np.random.default_rng(0), method, n_points)


def run_task(method, dim, functions, instances, budget, output, n_points) -> None:
    """Run one method in one dimension; data and times go to its folder.

    Runs in its own process: cocoex writes relative to the working
    directory. The folder ``exdata/<method>/D<dim>`` gets the COCO data
    (cocopp reads the method's folder with every dimension below it) and
    ``timing.json``, written last, which marks the task complete.
    """
    import cocoex

    os.chdir(output)  # cocoex writes to ./exdata/<result_folder>
    cocoex.log_level("warning")
    # A string names COCO's instance numbers themselves (instances held out
    # of the default list); a list picks positions in the default list.
    held_out = isinstance(instances, str)
    suite = cocoex.Suite(
        "bbob",
        f"instances: {instances}" if held_out else "",
        f"dimensions:{dim} "
        f"function_indices:{','.join(map(str, functions))}"
        + ("" if held_out else f" instance_indices:{','.join(map(str, instances))}"),
    )
    folder = f"{method}/D{dim}"
    observer = cocoex.Observer(
        "bbob", f"result_folder: {folder} algorithm_name: {method}"
    )
    run = _runner(method)
    _warm_up(run, method, n_points)
    wall = inside = 0.0
    evals = 0
    for problem in suite:
        problem.observe_with(observer)
        objective = _Timed(problem)
        seed = [dim, problem.id_function, problem.id_instance]
        rng = np.random.default_rng(seed)
        start = time.perf_counter()
        run(problem, objective, budget * dim, rng, method, n_points)
        wall += time.perf_counter() - start
        inside += objective.seconds
        evals += problem.evaluations
        problem.free()
    timing = {"wall_s": wall, "objective_s": inside, "evaluations": evals}
    (output / "exdata" / folder / "timing.json").write_text(json.dumps(timing))


_INFO_DATA = re.compile(r"^(data_f\d+/\S+\.dat), (.*)$")
_INSTANCE = re.compile(r"(\d+):(\d+)\|")


def final_deltas(folder: Path) -> dict:
    """``{(dim, function, instance): best f - f_opt}`` from a COCO data folder.

    The ``.info`` files name each data file and its instances in order; the
    ``.dat`` file holds one block per instance, whose last line's third
    column is the best noise-free ``f - f_opt`` (10 significant digits).
    """
    out = {}
    for info in sorted(folder.glob("**/*.info")):
        header = None
        for line in info.read_text().splitlines():
            if line.startswith("suite"):
                header = dict(re.findall(r"(funcId|DIM) = (\d+)", line))
            match = _INFO_DATA.match(line.strip())
            if match is None or header is None:
                continue
            ids = [int(i) for i, _ in _INSTANCE.findall(match.group(2))]
            blocks = _blocks(info.parent / match.group(1))
            if len(blocks) != len(ids):
                raise ValueError(f"{info}: {len(ids)} instances, {len(blocks)} blocks")
            for iid, delta in zip(ids, blocks, strict=True):
                out[(int(header["DIM"]), int(header["funcId"]), iid)] = delta
    return out


def _blocks(dat: Path) -> list[float]:
    deltas, last = [], None
    for line in dat.read_text().splitlines():
        if line.startswith("%"):
            if last is not None:
                deltas.append(last)
            last = None
        elif line.strip():
            last = float(line.split()[2])
    if last is not None:
        deltas.append(last)
    return deltas


def fraction_reached(deltas: dict, dim: int, functions=None) -> tuple[float, int]:
    """Fraction of (function, instance, target) triples reached in ``dim``
    (over ``functions`` only, if given)."""
    values = np.array(
        [
            v
            for (d, f, _), v in deltas.items()
            if d == dim and (functions is None or f in functions)
        ]
    )
    if values.size == 0:
        return math.nan, 0
    hit = values[:, None] <= TARGETS[None, :]
    return float(hit.mean()), values.size


def _parse(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dims", type=int, nargs="+", default=list(DIMS))
    parser.add_argument("--functions", type=int, nargs="+", default=list(FUNCTIONS))
    parser.add_argument("--instances", type=int, nargs="+", default=list(INSTANCES))
    parser.add_argument(
        "--instance-ids",
        default="",
        help="COCO instance numbers instead of --instances' positions in the "
        "default list (1-5 and 71-80), e.g. 16-30 for instances no setting "
        "was chosen on",
    )
    parser.add_argument(
        "--budget", type=int, default=1000, help="evaluations per dimension"
    )
    parser.add_argument(
        "--methods", nargs="+", default=list(ALL_METHODS), choices=ALL_METHODS
    )
    parser.add_argument(
        "--n-points", type=int, default=50, help="spiral population without restarts"
    )
    parser.add_argument(
        "--restart-points",
        type=int,
        default=10,
        help="first population of the restart variants (IPOP starts small)",
    )
    parser.add_argument("--output", type=Path, default=Path("bbob-output"))
    parser.add_argument("--jobs", type=int, default=1, help="processes")
    parser.add_argument("--cocopp", action="store_true", help="run cocopp after")
    parser.add_argument("--force", action="store_true", help="reuse OUTPUT")
    parser.add_argument(
        "--report",
        action="store_true",
        help="only tabulate the complete tasks already in OUTPUT",
    )
    parser.add_argument(
        "--markdown",
        action="store_true",
        help="also print the results' tables (by method, group and function)",
    )
    return parser.parse_args(argv)


def main(argv=None) -> dict:
    args = _parse(argv)
    out = args.output.resolve()
    start = time.perf_counter()
    if not args.report:
        if out.exists() and any(out.iterdir()) and not args.force:
            sys.exit(f"bbob.py: --output {out} is not empty (--force reuses it)")
        (out / "exdata").mkdir(parents=True, exist_ok=True)
        # Small dimensions first, so that an interrupted run leaves whole
        # dimensions behind (--report tabulates them).
        tasks = [
            (
                m,
                d,
                args.functions,
                args.instance_ids or args.instances,
                args.budget,
                out,
                _points(args, m),
            )
            for d in sorted(args.dims)
            for m in args.methods
        ]
        # One process per task, even with --jobs 1: cocoex writes relative
        # to the working directory.
        context = multiprocessing.get_context("fork")
        with context.Pool(args.jobs, maxtasksperchild=1) as pool:
            pool.starmap(run_task, tasks, chunksize=1)
    total = time.perf_counter() - start
    summary = _summarise(args, out)
    _print(args, summary, total)
    if args.markdown:
        _markdown(args, summary)
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    if args.cocopp:
        _postprocess(out, args.methods)
    return summary


def _points(args, method: str) -> int:
    return args.restart_points if method.endswith(RESTART) else args.n_points


def _summarise(args, out) -> dict:
    """One row per complete (method, dimension) task, dimension first."""
    summary = {}
    for dim in sorted(args.dims):
        for method in args.methods:
            folder = _data_folder(out, method) / f"D{dim}"
            if not (folder / "timing.json").exists():
                continue
            timing = json.loads((folder / "timing.json").read_text())
            wall, inside = timing["wall_s"], timing["objective_s"]
            evals = timing["evaluations"]
            deltas = final_deltas(folder)
            fraction, problems = fraction_reached(deltas, dim)
            summary[f"{method} D={dim}"] = {
                "method": method,
                "dim": dim,
                "fraction": fraction,
                "groups": {
                    group: fraction_reached(deltas, dim, functions)[0]
                    for group, functions in GROUPS.items()
                },
                "functions": {
                    f"f{f}": fraction_reached(deltas, dim, [f])[0]
                    for f in sorted(args.functions)
                },
                "problems": problems,
                "wall_s": wall,
                "evaluations": evals,
                "objective_us_per_eval": 1e6 * inside / max(evals, 1),
                "overhead_us_per_eval": 1e6 * (wall - inside) / max(evals, 1),
            }
    return summary


def _data_folder(out: Path, method: str) -> Path:
    return out / "exdata" / method


def _print(args, summary, total) -> None:
    import platform

    load = os.getloadavg()
    print(
        f"bbob: D = {args.dims}, {len(args.functions)} functions, "
        + (
            f"instances {args.instance_ids}, "
            if args.instance_ids
            else f"{len(args.instances)} instances, "
        )
        + f"budget {args.budget} D, "
        f"spiral population {args.n_points} ({args.restart_points} first with "
        f"restarts); {total:.0f} s wall with "
        f"{args.jobs} process(es); load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; "
        f"Python {platform.python_version()}"
    )
    print(
        f"{'method':<24}{'D':>4}{'fraction':>10}{'problems':>10}{'wall s':>9}"
        f"{'evals':>11}{'f us/ev':>9}{'opt us/ev':>11}"
    )
    for row in summary.values():
        print(
            f"{row['method']:<24}{row['dim']:>4}{row['fraction']:>10.3f}"
            f"{row['problems']:>10}{row['wall_s']:>9.1f}{row['evaluations']:>11}"
            f"{row['objective_us_per_eval']:>9.2f}{row['overhead_us_per_eval']:>11.2f}"
        )


def _markdown(args, summary) -> None:
    """Fractions, then the optimiser's time per evaluation, method by D."""
    dims = [
        d for d in sorted(args.dims) if any(r["dim"] == d for r in summary.values())
    ]
    for key, what, fmt in (
        ("fraction", "fraction of (function, instance, target) triples", ".3f"),
        ("overhead_us_per_eval", "optimiser's time per evaluation, us", ".1f"),
    ):
        print(f"\n{what}\n")
        print("| method | " + " | ".join(f"D = {d}" for d in dims) + " |")
        print("|---|" + "---|" * len(dims))
        for method in args.methods:
            cells = []
            for d in dims:
                row = summary.get(f"{method} D={d}")
                cells.append("" if row is None else format(row[key], fmt))
            print(f"| {method} | " + " | ".join(cells) + " |")
    largest = dims[-1]
    print(f"\nfraction by function group, D = {largest}\n")
    print("| method | " + " | ".join(GROUPS) + " |")
    print("|---|" + "---|" * len(GROUPS))
    for method in args.methods:
        row = summary.get(f"{method} D={largest}")
        if row is not None:
            cells = [format(row["groups"][g], ".3f") for g in GROUPS]
            print(f"| {method} | " + " | ".join(cells) + " |")
    print(f"\nfraction by function, D = {largest}\n")
    rows = [summary.get(f"{method} D={largest}") for method in args.methods]
    shown = [(m, r) for m, r in zip(args.methods, rows, strict=True) if r]
    print("| function | " + " | ".join(m for m, _ in shown) + " |")
    print("|---|" + "---|" * len(shown))
    for f in sorted(args.functions):
        cells = [format(r["functions"][f"f{f}"], ".3f") for _, r in shown]
        print(f"| f{f} | " + " | ".join(cells) + " |")
    walls = {
        d: sum(r["wall_s"] for r in summary.values() if r["dim"] == d) for d in dims
    }
    print(
        "\nwall time per dimension, all methods, s: "
        + ", ".join(f"D = {d}: {w:.0f}" for d, w in walls.items())
    )


def _postprocess(out: Path, methods) -> None:
    import cocopp

    folders = " ".join(str(_data_folder(out, m)) for m in methods)
    cocopp.genericsettings.isConv = False
    cocopp.main(f"-o {out / 'ppdata'} {folders}")


if __name__ == "__main__":
    main()
