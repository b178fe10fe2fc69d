"""Multi-objective spiral search: SDA and Eb-SDA by decomposition.

The paper's closing future work is a multi-objective Eb-SDA. Here the
search follows MOEA/D (Zhang and Li, IEEE TEVC 11(6), 2007): the front is
split into ``m`` scalar subproblems, one per weight vector ``w_i``, each the
Tchebycheff distance to the ideal point ``z*``,

    g_i(f) = max_j w_ij (f_j - z*_j) / s_j,

with ``s_j`` the current spread of objective ``j`` (so objectives of
different units weigh alike). Point ``i`` of the spiral population belongs
to subproblem ``i``; its spiral centre ``x*_i`` is the best incumbent for
``g_i`` among the subproblems of the ``neighbours`` nearest weight vectors,
and it moves as in the single-objective search,
``x_i <- x*_i + r_i R(theta_i) (x_i - x*_i)``, with ``r_i, theta_i`` from
the rule. Eb-SDA's deviation ``d = |f(x_i) - min J|`` (eq. (4), (7), (8))
is read as ``d_i = g_i(f(x_i)) - g_i(f(x*_i))``: how far the point is, in
its own subproblem's scalar cost, from the centre it turns about. Each new
point replaces at most two neighbouring incumbents it improves (MOEA/D's
``n_r = 2``, which keeps the front spread).

The paper's rule constants are kept (``method="sda"``: ``r = 0.95``,
``theta = pi/4``; ``"ebsda"``: eq. (4), (7), (8)).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from spiralid._checks import box_bounds, generator, integer
from spiralid.optim.result import OptimiserResult
from spiralid.optim.rotation import rotate
from spiralid.optim.rules import SpiralRule

__all__ = [
    "hypervolume",
    "minimize_pareto",
    "non_dominated",
    "weight_vectors",
]

# Replacements per new point (MOEA/D's n_r) and the smallest weight (a zero
# weight would make a subproblem blind to an objective).
_REPLACE = 2
_MIN_WEIGHT = 1e-6
# A point within this share of the box's width of its centre (every
# coordinate) has converged onto it.
_SPENT = 1e-3


def non_dominated(objectives) -> np.ndarray:
    """Mask of the non-dominated rows of `objectives` (minimisation).

    Row ``a`` dominates row ``b`` when it is nowhere larger and somewhere
    smaller. Of rows that are exactly equal, only the first is kept.

    Parameters
    ----------
    objectives : array_like, shape (N, k)

    Returns
    -------
    ndarray of bool, shape (N,)

    Examples
    --------
    >>> non_dominated([[1, 3], [2, 2], [2, 3], [1, 3]]).tolist()
    [True, True, False, False]
    """
    f = _objective_array(objectives, "objectives")
    le = np.all(f[:, None, :] <= f[None, :, :], axis=2)  # le[a, b]: a <= b
    lt = np.any(f[:, None, :] < f[None, :, :], axis=2)
    dominated = np.any(le & lt, axis=0)
    equal = le & le.T
    earlier_twin = np.any(np.triu(equal, k=1), axis=0)
    return ~(dominated | earlier_twin)


def hypervolume(objectives, ref) -> float:
    """Volume dominated by `objectives` and bounded by `ref` (minimisation).

    Exact for 2 objectives (a sweep) and 3 (slices along the third, each a
    2-objective sweep). Points not strictly below `ref` in every objective
    add nothing.

    Parameters
    ----------
    objectives : array_like, shape (N, k), k in {2, 3}
    ref : array_like, shape (k,)

    Returns
    -------
    float

    Examples
    --------
    >>> hypervolume([[1, 3], [2, 2], [3, 1]], [4, 4])
    6.0
    """
    f = _objective_array(objectives, "objectives")
    r = np.asarray(ref, dtype=float)
    k = f.shape[1]
    if k not in (2, 3):
        raise ValueError(f"`objectives` must have 2 or 3 columns; got {k}")
    if r.shape != (k,) or not np.all(np.isfinite(r)):
        raise ValueError(f"`ref` must be a finite vector of length {k}; got {ref!r}")
    f = f[np.all(f < r, axis=1)]
    if f.shape[0] == 0:
        return 0.0
    f = f[non_dominated(f)]
    if k == 2:
        return _hypervolume_2d(f, r)
    order = np.argsort(f[:, 2], kind="stable")
    f = f[order]
    levels = np.r_[f[:, 2], r[2]]
    return float(
        sum(
            (levels[i + 1] - levels[i]) * _hypervolume_2d(f[: i + 1, :2], r[:2])
            for i in range(f.shape[0])
        )
    )


def _hypervolume_2d(f: np.ndarray, r: np.ndarray) -> float:
    f = f[non_dominated(f)]
    f = f[np.argsort(f[:, 0], kind="stable")]
    right = np.r_[f[1:, 0], r[0]]
    return float(np.sum((right - f[:, 0]) * (r[1] - f[:, 1])))


def weight_vectors(k: int, m: int) -> np.ndarray:
    """Evenly spread weight vectors on the simplex (Das and Dennis): for 2
    objectives `m` of them; for 3 the largest lattice with at most `m`.

    Examples
    --------
    >>> weight_vectors(2, 3).tolist()
    [[0.0, 1.0], [0.5, 0.5], [1.0, 0.0]]
    """
    k = integer(k, "k", 2)
    m = integer(m, "m", 2)
    if k == 2:
        a = np.linspace(0.0, 1.0, m)
        return np.column_stack([a, 1.0 - a])
    if k != 3:
        raise ValueError(f"`k` must be 2 or 3; got {k}")
    h = 1
    while (h + 2) * (h + 3) // 2 <= m:
        h += 1
    rows = [(i, j, h - i - j) for i in range(h + 1) for j in range(h + 1 - i)]
    return np.array(rows, dtype=float) / h


def _objective_array(value, name: str) -> np.ndarray:
    try:
        f = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be an (N, k) array of numbers") from None
    if f.ndim != 2 or f.shape[1] < 1:
        raise ValueError(f"`{name}` must have shape (N, k); got shape {f.shape}")
    if not np.all(np.isfinite(f)):
        raise ValueError(f"`{name}` must be finite; got NaN or infinite values")
    return f


def _evaluate(fun, x: np.ndarray, vectorized: bool, k: int | None) -> np.ndarray:
    """The objective vectors of the rows of `x`, checked: (m, k), finite."""
    if vectorized:
        f = np.asarray(fun(x.copy()), dtype=float)
    else:
        rows = [np.asarray(fun(row.copy()), dtype=float) for row in x]
        shapes = {r.shape for r in rows}
        if len(shapes) != 1:
            raise ValueError(
                "`fun` must return the same number of objectives for every "
                f"point; got shapes {sorted(shapes)}"
            )
        f = np.array(rows)
    if f.ndim != 2 or f.shape[0] != x.shape[0] or (k is not None and f.shape[1] != k):
        want = f"({x.shape[0]}, {'k' if k is None else k})"
        raise ValueError(
            f"`fun` must return {want} objective values for {x.shape[0]} points; "
            f"got shape {f.shape}"
        )
    bad = np.flatnonzero(~np.all(np.isfinite(f), axis=1))
    if bad.size:
        raise ValueError(
            f"`fun` returned a non-finite objective for {bad.size} point(s), the "
            f"first {x[bad[0]].tolist()!r:.120}: {f[bad[0]].tolist()!r}"
        )
    return f


def _tchebycheff(f: np.ndarray, w: np.ndarray, z: np.ndarray, s: np.ndarray):
    """``g(f | w) = max_j w_j (f_j - z_j) / s_j``; f (..., k), w (..., k)."""
    return np.max(w * (f - z) / s, axis=-1)


def minimize_pareto(
    fun: Callable,
    bounds,
    method="ebsda",
    *,
    n_points: int = 100,
    max_nfev: int = 10_000,
    neighbours: int = 10,
    ref_point=None,
    rng=None,
    vectorized: bool = False,
    callback: Callable | None = None,
    x0=None,
) -> OptimiserResult:
    """Approximate the Pareto front of a vector objective by a spiral search.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> (k,)`` objective values to minimise for ``x`` of shape
        (n,), or with ``vectorized=True`` ``fun(X) -> (m, k)`` for ``X`` of
        shape (m, n); ``k`` is 2 or 3. A non-finite value is an error.
    bounds : sequence of (low, high), (n, 2) array or scipy.optimize.Bounds
        The search box; points are kept inside it.
    method : {"ebsda", "sda", "lasda", "ebsda-scaled"} or SpiralRule
        The spiral rule (see :func:`spiralid.optim.minimize`), with the
        paper's constants.
    n_points : int
        Population size: one subproblem each (for 3 objectives the largest
        simplex lattice that fits).
    max_nfev : int
        Budget of objective evaluations (at least two populations).
    neighbours : int
        Subproblems whose incumbents a point may take as its centre and
        replace.
    ref_point : array_like, shape (k,), optional
        Reference point of the hypervolume ``history``; default the initial
        population's worst value of each objective plus a tenth of its range.
    rng : None, int or numpy.random.Generator
    vectorized : bool
        Whether `fun` takes a batch of points.
    callback : callable, optional
        ``callback(intermediate)`` after every iteration with the result so
        far; returning True stops the search.
    x0 : array_like, shape (q, n) or (n,), optional
        Known points (e.g. a single-objective estimate) that take the place
        of the first ``q`` uniform draws of the initial population (clipped
        into the box; at most the population size). The draws are made
        anyway, so a seed changes nothing else.

    Returns
    -------
    OptimiserResult
        ``x`` the non-dominated incumbents (shape (p, n)), ``fun`` their
        objective vectors (p, k), ``population`` and ``population_fun`` every
        subproblem's incumbent, ``weights``, ``ref_point``, ``history`` (the
        hypervolume of the non-dominated incumbents after the initial
        population and each iteration), ``status`` (1 when the budget ended
        it, 0 the callback), ``nit``, ``nfev``, ``n_restarts`` (0),
        ``elapsed``.

    Examples
    --------
    >>> import numpy as np
    >>> def two(x):  # Schaffer's problem: the front is x in [0, 2]
    ...     return np.column_stack([x[:, 0] ** 2, (x[:, 0] - 2) ** 2])
    >>> res = minimize_pareto(two, [(-5, 5)], n_points=20, max_nfev=2000,
    ...                       rng=0, vectorized=True)
    >>> res.x.shape[1], bool(np.mean((res.x >= 0) & (res.x <= 2)) > 0.9)
    (1, True)
    """
    t_start = time.perf_counter()
    lo, hi = box_bounds(bounds)
    from spiralid.optim.spiral import _parse_method

    rule = _parse_method(method)
    if not isinstance(rule, SpiralRule):
        raise ValueError(
            "`method` must be a rule that sets each point's radius and angle "
            f"(sda, ebsda, lasda, ebsda-scaled or a SpiralRule); got {method!r}"
        )
    m = integer(n_points, "n_points", 4)
    max_nfev = integer(max_nfev, "max_nfev", 2 * m)
    neighbours = integer(neighbours, "neighbours", 2)
    if callback is not None and not callable(callback):
        raise ValueError(f"`callback` must be callable or None; got {callback!r}")
    gen = generator(rng)
    n = lo.size

    x = gen.uniform(lo, hi, size=(m, n))
    if x0 is not None:
        seeds = np.atleast_2d(np.asarray(x0, dtype=float))
        if seeds.ndim != 2 or seeds.shape[1] != n or not np.all(np.isfinite(seeds)):
            raise ValueError(
                f"`x0` must be finite points of shape (q, {n}); got shape {seeds.shape}"
            )
        q = min(seeds.shape[0], m)
        x[:q] = np.clip(seeds[:q], lo, hi)
    f = _evaluate(fun, x, bool(vectorized), None)
    k = f.shape[1]
    if k not in (2, 3):
        raise ValueError(f"`fun` must return 2 or 3 objectives; got {k}")
    weights = np.maximum(weight_vectors(k, m), _MIN_WEIGHT)
    m = weights.shape[0]
    x, f = x[:m], f[:m]
    nfev = m
    if ref_point is None:
        spread = f.max(axis=0) - f.min(axis=0)
        ref = f.max(axis=0) + 0.1 * np.where(spread > 0, spread, 1.0)
    else:
        ref = np.asarray(ref_point, dtype=float)
        if ref.shape != (k,) or not np.all(np.isfinite(ref)):
            raise ValueError(
                f"`ref_point` must be a finite vector of length {k}; got {ref_point!r}"
            )
    distance = np.linalg.norm(weights[:, None] - weights[None], axis=2)
    near = np.argsort(distance, axis=1, kind="stable")[:, : min(neighbours, m)]

    incumbent, incumbent_f = x.copy(), f.copy()
    ideal = f.min(axis=0)
    history = [hypervolume(incumbent_f[non_dominated(incumbent_f)], ref)]
    nit, status, n_restarts = 0, 1, 0
    while nfev + m <= max_nfev:
        scale = np.maximum(incumbent_f.max(axis=0) - ideal, 1e-12)
        # Each point's centre: the best incumbent for its subproblem among
        # its neighbours'.
        g_near = _tchebycheff(incumbent_f[near], weights[:, None], ideal, scale)
        centre = near[np.arange(m), np.argmin(g_near, axis=1)]
        g_point = _tchebycheff(f, weights, ideal, scale)
        g_centre = _tchebycheff(incumbent_f[centre], weights, ideal, scale)
        r, theta = rule(np.maximum(g_point - g_centre, 0.0), gen)
        offset = x - incumbent[centre]
        theta = np.broadcast_to(np.asarray(theta, dtype=float), (m,))
        x = incumbent[centre] + np.reshape(r, (-1, 1)) * rotate(offset, theta)
        # A point that has reached its centre has nothing left to explore:
        # it starts again from a uniform draw (a restart per point).
        spent = np.max(np.abs(x - incumbent[centre]) / (hi - lo), axis=1) < _SPENT
        if spent.any():
            x[spent] = gen.uniform(lo, hi, size=(int(spent.sum()), n))
            n_restarts += int(spent.sum())
        np.clip(x, lo, hi, out=x)
        f = _evaluate(fun, x, bool(vectorized), k)
        nfev += m
        nit += 1
        ideal = np.minimum(ideal, f.min(axis=0))
        scale = np.maximum(incumbent_f.max(axis=0) - ideal, 1e-12)
        for i in gen.permutation(m):
            pool = near[i]
            better = _tchebycheff(f[i], weights[pool], ideal, scale) < _tchebycheff(
                incumbent_f[pool], weights[pool], ideal, scale
            )
            for j in pool[better][:_REPLACE]:
                incumbent[j], incumbent_f[j] = x[i], f[i]
        front = non_dominated(incumbent_f)
        history.append(hypervolume(incumbent_f[front], ref))
        if callback is not None and callback(
            OptimiserResult(x=incumbent[front], fun=incumbent_f[front], nit=nit)
        ):
            status = 0
            break
    front = non_dominated(incumbent_f)
    return OptimiserResult(
        x=incumbent[front],
        fun=incumbent_f[front],
        population=incumbent,
        population_fun=incumbent_f,
        weights=weights,
        ref_point=ref,
        status=status,
        success=True,
        message=(
            "The callback requested a stop."
            if status == 0
            else "Maximum number of function evaluations reached."
        ),
        nit=nit,
        nfev=nfev,
        n_restarts=n_restarts,
        history=np.asarray(history),
        elapsed=time.perf_counter() - t_start,
    )
