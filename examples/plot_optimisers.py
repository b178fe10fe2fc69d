"""
The spiral optimisers on test functions
=======================================

:func:`spiralid.optim.minimize` is a general-purpose optimiser: it knows
nothing of system identification. This page runs three of its rules on two
standard functions of :mod:`spiralid.optim.testfunctions` in 10 dimensions
and draws their convergence against the number of cost evaluations:

* ``"sda"``: Tamura and Yasuda's spiral with constant radius and angle;
* ``"ebsda"``: the paper's exponential-based rule, eq. (4), (7), (8);
* ``"learned-metric"`` with restarts: polls in a basis learned by Adaptive
  Encoding, with success-based steps (the README's "A spiral that learns
  the landscape's metric").

SciPy's differential evolution at the same budget
(:func:`spiralid.optim.differential_evolution`) is the population baseline
beside them. Each run gets 10,000 evaluations, 5 seeds per method: a small
version of the README's COCO/BBOB benchmark, which runs 24 functions, 15
instances and 1,000 evaluations per dimension.
"""

import matplotlib.pyplot as plt
import numpy as np

from spiralid.optim import differential_evolution, minimize, testfunctions

# %%
# Problems and budget
# -------------------
# Rosenbrock's function is a curved valley; Rastrigin's is a bowl covered
# with local minima. Each :class:`~spiralid.optim.testfunctions.Problem`
# carries its usual search box and its optimal value ``f_opt``.
dim, budget, seeds, n_points = 10, 10_000, range(5), 50
problems = {name: testfunctions.PROBLEMS[name] for name in ("rosenbrock", "rastrigin")}
for p in problems.values():
    print(f"{p.name}: box [{p.low}, {p.high}]^{dim}, f_opt = {p.f_opt}")

# %%
# Running the searches
# --------------------
# ``callback`` is called after every iteration with the result so far, so it
# can record the best cost against the evaluations spent (a spiral
# iteration costs ``n_points - 1`` evaluations, a learned-metric period
# ``2 n + 1``). ``minimize`` stops at ``max_iter`` (default 500) or at
# ``max_nfev``, whichever comes first: ``max_iter`` is raised here so that
# the budget alone decides. The functions are vectorised, so
# ``vectorized=True`` evaluates a whole population per call.
# Differential evolution's ``history`` holds the best cost after each
# generation of ``n_points`` evaluations.


def spiral_trace(problem, method, seed):
    trace = []
    res = minimize(
        problem.fun,
        problem.bounds(dim),
        method,
        n_points=n_points,
        max_nfev=budget,
        max_iter=budget,
        rng=seed,
        vectorized=True,
        restarts=method == "learned-metric",
        callback=lambda r: trace.append((r.nfev, r.fun)),
    )
    # history[0] is the best of the initial population of n_points points.
    return np.array([(n_points, res.history[0]), *trace]), res


def de_trace(problem, seed):
    res = differential_evolution(
        problem.fun, problem.bounds(dim), n_points=n_points, max_nfev=budget, rng=seed
    )
    nfev = n_points * np.arange(1, res.history.size + 1)
    return np.column_stack([nfev, res.history]), res


labels = ("SDA", "Eb-SDA", "learned-metric + restarts", "DE (SciPy)")
rules = {"SDA": "sda", "Eb-SDA": "ebsda", "learned-metric + restarts": "learned-metric"}
traces = {}
for name, problem in problems.items():
    for label in labels:
        for seed in seeds:
            if label in rules:
                trace, res = spiral_trace(problem, rules[label], seed)
            else:
                trace, res = de_trace(problem, seed)
            traces[name, label, seed] = (trace, res)

# %%
# Final precision
# ---------------
# The median over the seeds of ``f - f_opt`` at the end of the budget, and
# the evaluations each run used (a run ends before an iteration that would
# exceed the budget).
print(f"{'method':<27} " + " ".join(f"{name:>12}" for name in problems))
for label in labels:
    cells = []
    for name, problem in problems.items():
        final = [traces[name, label, s][1].fun - problem.f_opt for s in seeds]
        cells.append(f"{np.median(final):12.3g}")
    nfev = [traces[next(iter(problems)), label, s][1].nfev for s in seeds]
    print(f"{label:<27} " + " ".join(cells) + f"   (nfev {min(nfev)}-{max(nfev)})")

# %%
# Convergence
# -----------
# Median and interquartile band over the seeds of the best ``f - f_opt``
# found so far, against evaluations, on a common grid (each run's best cost
# is a step function of its evaluations).
grid = np.linspace(n_points, budget, 200)
fig, axes = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
for ax, (name, problem) in zip(axes, problems.items(), strict=True):
    for label in labels:
        curves = []
        for s in seeds:
            trace = traces[name, label, s][0]
            at = np.searchsorted(trace[:, 0], grid, side="right") - 1
            curves.append(np.where(at >= 0, trace[np.maximum(at, 0), 1], np.nan))
        gap = np.maximum(np.array(curves) - problem.f_opt, 1e-12)
        q1, median, q3 = np.nanpercentile(gap, [25, 50, 75], axis=0)
        (line,) = ax.plot(grid, median, label=label)
        ax.fill_between(grid, q1, q3, color=line.get_color(), alpha=0.2)
    ax.set_yscale("log")
    ax.set_title(f"{name}, n = {dim}")
    ax.set_xlabel("cost evaluations")
    ax.set_ylabel("best f - f_opt (floored at 1e-12)")
axes[0].legend(fontsize="small")
plt.show()
