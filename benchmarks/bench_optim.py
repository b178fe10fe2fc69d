"""Speed and quality of the spiral optimisers (prints tables; asserts nothing).

1. Numba compile time of the plane-sweep kernels, cold (empty cache) and
   warm (loading the on-disk cache), each in a fresh interpreter.
2. Time per point per iteration with a trivial vectorised objective (the
   sphere), m = 100 points, n = 2, 16, 50, for SDA, Eb-SDA and the linear
   rule. The objective's own time is measured separately and subtracted to
   give the optimiser's time. Target: <= 1 us per point-iteration at n = 16.
3. Quality at equal budget: 20 seeds, n = 10, 50 points, 24,550 objective
   evaluations (the default 500 iterations) for every method; median, best
   and worst final cost on six standard test functions (optimum 0 each),
   without bound handling as in the paper, plus Schwefel with clipping.

Run: ``.venv/bin/python benchmarks/bench_optim.py`` (about a minute).
"""

import os
import platform
import subprocess
import sys
import tempfile
import time

import numba
import numpy as np

from spiralid.optim import minimize
from spiralid.optim.testfunctions import PROBLEMS

METHODS = ("sda", "ebsda", "lasda")
LABELS = {"sda": "SDA", "ebsda": "Eb-SDA", "lasda": "LASDA"}

_COMPILE_SNIPPET = """
import time
import numpy as np
from spiralid.optim import _kernels
from spiralid.optim.rotation import _sweep_order

p = _sweep_order(4)
x = np.ones((3, 4))
f = np.array([1.0, 2.0, 0.5])
one = np.ones(1)
calls = {
    "sweep": lambda: _kernels.sweep(x, np.ones(3), p),
    "spiral_step": lambda: _kernels.spiral_step(x, np.ones(2), np.ones(2), p),
    "exponential": lambda: _kernels.exponential(f, one, one, one, one, one),
    "deviations": lambda: _kernels.deviations(f),
    "promote": lambda: _kernels.promote(x, f),
}
for name, call in calls.items():
    t = time.perf_counter()
    call()
    print(name, time.perf_counter() - t)
"""
KERNELS = ("sweep", "spiral_step", "exponential", "deviations", "promote")


def compile_times() -> None:
    print("1. Numba kernels: first call in a fresh interpreter (seconds)")
    print(f"{'cache':<7}" + "".join(f"{k:>13}" for k in KERNELS) + f"{'total':>9}")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for label in ("cold", "warm"):
            lines = subprocess.run(
                [sys.executable, "-c", _COMPILE_SNIPPET],
                env=env,
                capture_output=True,
                text=True,
                check=True,
            ).stdout.split("\n")
            t = dict(line.split() for line in lines if line)
            row = "".join(f"{float(t[k]):>13.3f}" for k in KERNELS)
            total = sum(float(t[k]) for k in KERNELS)
            print(f"{label:<7}{row}{total:>9.3f}")
    print()


def sphere(x):
    return np.einsum("ij,ij->i", x, x)


def per_point_iteration(method: str, n: int, m: int, iters: int) -> tuple:
    bounds = [(-5.0, 5.0)] * n
    minimize(sphere, bounds, method, n_points=m, max_iter=5, rng=0, vectorized=True)
    best_total = np.inf
    for rep in range(3):
        t = time.perf_counter()
        minimize(
            sphere, bounds, method, n_points=m, max_iter=iters, rng=rep, vectorized=True
        )
        best_total = min(best_total, time.perf_counter() - t)
    x = np.random.default_rng(0).uniform(-5, 5, (m - 1, n))
    best_obj = np.inf
    for _ in range(3):
        t = time.perf_counter()
        for _ in range(iters):
            sphere(x.copy())
        best_obj = min(best_obj, time.perf_counter() - t)
    scale = 1e6 / (iters * m)
    return best_total * scale, best_obj * scale


def timing_table() -> None:
    m, iters = 100, 2000
    print(
        f"2. Time per point per iteration (us), m = {m}, {iters} iterations, "
        "best of 3; objective = sphere"
    )
    print(f"{'n':>4} {'method':<8}{'total':>9}{'objective':>11}{'optimiser':>11}")
    for n in (2, 16, 50):
        for method in METHODS:
            total, obj = per_point_iteration(method, n, m, iters)
            print(
                f"{n:>4} {LABELS[method]:<8}{total:>9.3f}{obj:>11.3f}"
                f"{total - obj:>11.3f}"
            )
    print()


def quality_table() -> None:
    n, m, seeds = 10, 50, 20
    budget = m + 500 * (m - 1)
    print(
        f"3. Final cost at equal budget: n = {n}, {m} points, max_nfev = {budget}, "
        f"{seeds} seeds (0..{seeds - 1}); optimum 0 for all; bounds_policy='none'"
    )
    print(f"{'function':<12}{'method':<8}{'median':>12}{'best':>12}{'worst':>12}")
    rows = [(name, p, "none") for name, p in PROBLEMS.items()]
    rows.append(("schwefel*", PROBLEMS["schwefel"], "clip"))
    for name, p, policy in rows:
        for method in METHODS:
            costs = []
            for seed in range(seeds):
                res = minimize(
                    p.fun,
                    p.bounds(n),
                    method,
                    n_points=m,
                    max_iter=10**6,
                    max_nfev=budget,
                    rng=seed,
                    vectorized=True,
                    options={"bounds_policy": policy},
                )
                assert res.nfev == budget
                costs.append(res.fun)
            c = np.array(costs)
            print(
                f"{name:<12}{LABELS[method]:<8}{np.median(c):>12.3e}"
                f"{c.min():>12.3e}{c.max():>12.3e}"
            )
    print(
        "* bounds_policy='clip': Schwefel's minimum 0 holds only inside its box;\n"
        "  points that leave [-500, 500] reach negative values, as in the row above."
    )
    print()


def main() -> None:
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, "
        f"numba {numba.__version__}, {os.cpu_count()} CPUs, {platform.machine()}"
    )
    print()
    compile_times()
    timing_table()
    t = time.perf_counter()
    quality_table()
    print(f"(quality table took {time.perf_counter() - t:.1f} s)")


if __name__ == "__main__":
    main()
