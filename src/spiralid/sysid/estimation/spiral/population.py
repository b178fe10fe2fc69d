"""The population searches of the paper's methods (the spiral rules) and of
differential evolution over a parametrisation, with the one budget rule
(:func:`search_options`), the safe start's first population and
``refine``."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from spiralid._checks import integer
from spiralid.optim import MINIMIZE_OPTIONS, differential_evolution, minimize

from ..core.problem import EstimatorResult, Problem
from ..linear.local_estimators import _refine

__all__ = ["search_options"]


def search_options(options: dict) -> dict:
    """The one budget rule: `options` with the iteration cap a budget implies.

    The cap is a copy of ``max_nfev``, so ``max_nfev`` is checked here: a
    budget of the wrong type or below 1 is refused naming ``max_nfev``, the
    argument the caller passed, rather than the ``max_iter`` copied from it.

    Examples
    --------
    >>> search_options({"n_points": 50, "max_nfev": 20_000})
    {'n_points': 50, 'max_nfev': 20000, 'max_iter': 20000}
    >>> search_options({"max_nfev": 1000, "max_iter": 10})   # both given: kept
    {'max_nfev': 1000, 'max_iter': 10}
    """
    out = dict(options)
    budget = out.get("max_nfev")
    if budget is not None and out.get("max_iter") is None:
        integer(budget, "max_nfev", 1)
        # Every iteration costs at least one evaluation: this cap never
        # stops a run before its budget does.
        out["max_iter"] = budget
    return out


def _safe_start_points(problem: Problem, box: np.ndarray) -> np.ndarray:
    """The stabilised least-squares estimate and the zero model, searched
    coordinates, clipped into the box."""
    par = problem.parametrization
    models = (par.theta_ls, np.zeros(problem.arx.n_params))
    points = np.array([par.from_theta(theta) for theta in models])
    return np.clip(points, box[:, 0], box[:, 1])


def _first_population(
    problem: Problem, box: np.ndarray, m: int, x0
) -> np.ndarray | None:
    """The given or drawn initial points, after the safe start's two."""
    seeds = _safe_start_points(problem, box) if problem.safe_start else None
    if x0 is not None:
        x0 = np.atleast_2d(np.asarray(x0, dtype=float))
        return x0 if seeds is None else np.concatenate([seeds, x0])
    n_seeds = 0 if seeds is None else seeds.shape[0]
    drawn = problem.parametrization.initial_points(box, m - n_seeds, problem.rng)
    parts = [p for p in (seeds, drawn) if p is not None]
    return np.concatenate(parts) if parts else None


def _search(
    problem: Problem,
    optimiser: Callable,
    options: dict,
) -> EstimatorResult:
    """A population search over the problem's parametrisation.

    ``optimiser(fun, box, x0=..., **options)`` runs it and returns an
    :class:`~spiralid.optim.OptimiserResult`, whose status is the estimator's.
    """
    t0 = time.perf_counter()
    par = problem.parametrization
    box = par.default_bounds() if problem.bounds is None else problem.bounds
    options = search_options(options)
    m = integer(options.get("n_points", 50), "n_points", 2)
    x0 = _first_population(problem, box, m, options.pop("x0", None))
    raw = optimiser(par.objective(problem.cost), box, x0=x0, **options)
    theta = par.to_theta(raw.x)
    history = getattr(raw, "history", None)
    result = EstimatorResult(
        x=theta,
        fun=float(problem.cost(theta)),
        status=int(raw.status),
        success=bool(raw.success),
        message=str(raw.message),
        nfev=int(raw.nfev),
        nit=int(raw.nit),
        n_restarts=int(raw.n_restarts),
        history=None if history is None else np.asarray(history, dtype=float),
        elapsed=time.perf_counter() - t0,
        x_search=np.asarray(raw.x, dtype=float),
        bounds=box,
        safe_start=problem.safe_start,
        refine=None,
        raw=raw,
    )
    if problem.refine:
        _refine(problem, result)
    return result


def _estimate_spiral(problem: Problem, *, rule: str, **options) -> EstimatorResult:
    def run(fun, box, **opts):
        opts["options"] = {k: opts.pop(k) for k in MINIMIZE_OPTIONS if k in opts}
        return minimize(fun, box, method=rule, rng=problem.rng, vectorized=True, **opts)

    return _search(problem, run, options)


def _estimate_de(problem: Problem, **options) -> EstimatorResult:
    def run(fun, box, **opts):
        return differential_evolution(fun, box, rng=problem.rng, **opts)

    return _search(problem, run, options)
