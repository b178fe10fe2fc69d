"""Differential evolution as a baseline beside the spiral searches.

A thin adapter over :func:`scipy.optimize.differential_evolution` with the
calling conventions of :func:`spiralid.optim.minimize`: a budget of
objective evaluations, a population of ``n_points`` seeded from ``x0``, a
vectorised objective taking ``(m, n)`` and returning ``(m,)``, and a best-cost
``history`` whose index 0 is the initial population. It lets the paper's
comparison ask whether a problem is hard for the spiral searches or for
population metaheuristics in general.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from scipy import optimize

from spiralid._checks import box_bounds, generator, integer
from spiralid.optim.result import OptimiserResult

__all__ = ["differential_evolution"]


def differential_evolution(
    fun: Callable[[np.ndarray], np.ndarray],
    bounds,
    *,
    n_points: int = 50,
    max_iter: int = 500,
    max_nfev: int | None = None,
    rng=None,
    x0=None,
    callback: Callable | None = None,
) -> OptimiserResult:
    """Minimise a vectorised `fun` by SciPy's differential evolution.

    SciPy's defaults otherwise (``best1bin``, mutation (0.5, 1),
    recombination 0.7), no final polish, convergence tolerances off so that
    the budget decides when it stops.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> cost`` for a population ``x`` of shape (m, n).
    bounds : array_like, shape (n, 2)
        Search box.
    n_points : int, default 50
        Population size (at least 5: DE's mutation draws 3 other members).
    max_iter : int, default 500
        Generations after the initial population.
    max_nfev : int, optional
        Budget of objective evaluations, counting the initial population;
        the run stops after the last whole generation that fits.
    rng : int, numpy.random.Generator or None
        Randomness of the initial draw and the search.
    x0 : array_like, shape (k, n), optional
        Initial members (k <= n_points); the rest are drawn uniformly in the
        box.
    callback : callable, optional
        ``callback(intermediate_result)`` after each generation; returning
        True stops the search.

    Returns
    -------
    OptimiserResult
        ``x, fun, nit, success, message`` as SciPy gives them, ``nfev``
        counting objective evaluations (SciPy counts vectorised calls),
        ``status`` (a key of :data:`~spiralid.optim.result.STATUS`: 1 when
        `max_nfev` left no room for another generation, 2 at `max_iter`, 0
        when the callback stopped it), ``n_restarts`` (0), ``history`` (best
        cost after each generation, index 0 the initial population) and
        ``elapsed`` (seconds).

    Examples
    --------
    >>> res = differential_evolution(
    ...     lambda x: (x**2).sum(axis=1), [(-5, 5)] * 2, max_nfev=3000, rng=0
    ... )
    >>> bool(res.fun < 1e-8), res.nfev <= 3000, res.history.size == res.nit + 1
    (True, True, True)
    """
    box = np.column_stack(box_bounds(bounds))
    n_points = integer(n_points, "n_points", 5)
    max_iter = integer(max_iter, "max_iter", 1)
    generations = max_iter
    if max_nfev is not None:
        # The initial population and one generation at least.
        max_nfev = integer(max_nfev, "max_nfev", 2 * n_points)
        generations = min(max_iter, max_nfev // n_points - 1)
    if callback is not None and not callable(callback):
        raise TypeError(f"`callback` must be callable or None; got {callback!r}")
    gen = generator(rng)
    n = box.shape[0]
    seeds = np.empty((0, n))
    if x0 is not None:
        seeds = np.atleast_2d(np.asarray(x0, dtype=float))
        if seeds.ndim != 2 or seeds.shape[1] != n or seeds.shape[0] > n_points:
            raise ValueError(
                f"`x0` must have shape (k, {n}) with k <= n_points = {n_points}; "
                f"got {seeds.shape}"
            )
        if np.any(seeds < box[:, 0]) or np.any(seeds > box[:, 1]):
            raise ValueError("`x0` must lie within `bounds`")
    # Draw only the members x0 does not give, so a full x0 leaves `rng` to
    # the search alone.
    drawn = gen.uniform(box[:, 0], box[:, 1], size=(n_points - seeds.shape[0], n))
    init = np.concatenate([seeds, drawn])

    history: list[float] = []
    nfev = 0

    def batch(x: np.ndarray) -> np.ndarray:
        # SciPy hands a vectorised objective the population as (n, m), and
        # counts calls rather than evaluations in its own `nfev`.
        nonlocal nfev
        nfev += x.shape[1]
        costs = np.asarray(fun(x.T), dtype=float)
        if not history:
            finite = costs[np.isfinite(costs)]
            history.append(float(finite.min()) if finite.size else np.inf)
        return np.where(np.isfinite(costs), costs, np.inf)

    # SciPy passes the OptimizeResult only to a parameter of this exact name.
    stopped = False

    def after_generation(intermediate_result: optimize.OptimizeResult) -> bool:
        nonlocal stopped
        history.append(float(intermediate_result.fun))
        stopped = callback is not None and bool(callback(intermediate_result))
        return stopped

    start = time.perf_counter()
    res = optimize.differential_evolution(
        batch,
        box,
        maxiter=generations,
        init=init,
        rng=gen,
        polish=False,
        tol=0.0,
        atol=0.0,
        updating="deferred",
        vectorized=True,
        callback=after_generation,
    )
    if stopped:
        status = 0
    else:
        status = 2 if res.nit >= max_iter else 1
    return OptimiserResult(
        x=res.x,
        fun=float(res.fun),
        status=status,
        success=bool(res.success),
        message=str(res.message),
        nit=int(res.nit),
        nfev=nfev,
        n_restarts=0,
        history=np.minimum.accumulate(np.asarray(history, dtype=float)),
        elapsed=time.perf_counter() - start,
        population=res.population,
    )
