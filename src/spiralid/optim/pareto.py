"""Multi-objective spiral search by decomposition: SDA, Eb-SDA and the
learned-metric poll.

The paper's closing future work is a multi-objective Eb-SDA. Here the
search follows MOEA/D (Zhang and Li, IEEE TEVC 11(6), 2007): the front is
split into ``m`` scalar subproblems, one per weight vector ``w_i``, each the
Tchebycheff distance to the ideal point ``z*``,

    g_i(f) = max_j w_ij (f_j - z*_j) / s_j,

with ``s_j`` the current spread of objective ``j`` (so objectives of
different units weigh alike). Subproblem ``i``'s centre ``x*_i`` is the best
incumbent for ``g_i`` among the subproblems of the ``neighbours`` nearest
weight vectors. With SDA or Eb-SDA its point moves as in the
single-objective search, ``x_i <- x*_i + r_i R(theta_i) (x_i - x*_i)``, with
``r_i, theta_i`` from the rule. Eb-SDA's deviation ``d = |f(x_i) - min J|``
(eq. (4), (7), (8)) is read as ``d_i = g_i(f(x_i)) - g_i(f(x*_i))``: how far
the point is, in its own subproblem's scalar cost, from the centre it turns
about. With the learned-metric rule each subproblem polls an opposite pair
of directions about its centre instead, with a step per direction from
success (:class:`~spiralid.optim._decomposition.PollMoves`). Each new point
replaces at most two neighbouring incumbents it improves (MOEA/D's
``n_r = 2``, which keeps the front spread).

Every evaluated point also enters an archive of the non-dominated points
(thinned by SPEA2's truncation when it grows past four populations); the
result is the archive thinned to ``n_points``, or with ``archive=False`` the
non-dominated incumbents.

The paper's rule constants are kept (``method="sda"``: ``r = 0.95``,
``theta = pi/4``; ``"ebsda"``: eq. (4), (7), (8)).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from spiralid._checks import box_bounds, generator, integer
from spiralid.choices import PARETO_METHOD_NAMES, require_names
from spiralid.optim._decomposition import (
    Archive,
    PollMoves,
    SpiralMoves,
    Subproblems,
)
from spiralid.optim._loop import STOPS, check_max_time, check_objective
from spiralid.optim.front import (
    hypervolume,
    non_dominated,
    thin_front,
    weight_vectors,
)
from spiralid.optim.learned import LearnedMetricSpiral
from spiralid.optim.result import OptimiserResult
from spiralid.optim.rules import SpiralRule
from spiralid.optim.spiral import RULES, _parse_method

__all__ = [
    "PARETO_METHODS",
    "hypervolume",
    "minimize_pareto",
    "non_dominated",
    "thin_front",
    "weight_vectors",
]


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


def _parse_rule(method) -> SpiralRule | LearnedMetricSpiral:
    # A name is checked against the Pareto rules first: the single-objective
    # list (with the step-rate rules) would offer names refused here.
    named = isinstance(method, str) and method.lower() in PARETO_METHODS
    rule = _parse_method(method) if named or not isinstance(method, str) else None
    if not isinstance(rule, SpiralRule | LearnedMetricSpiral):
        raise ValueError(
            f"`method` must be one of {', '.join(PARETO_METHODS)}, a SpiralRule "
            f"or a LearnedMetricSpiral; got {method!r}"
        )
    return rule


# The rules a multi-objective search can drive (by name): those that set each
# point's radius and angle, and the learned-metric poll; not the step-rate
# rules, whose step schedule belongs to a single centre.
require_names(
    (
        name
        for name in RULES
        if isinstance(_parse_method(name), SpiralRule | LearnedMetricSpiral)
    ),
    PARETO_METHOD_NAMES,
    "spiralid.optim.pareto.PARETO_METHODS",
)
PARETO_METHODS = PARETO_METHOD_NAMES


def _initial_points(gen, lo, hi, m: int, x0) -> np.ndarray:
    """`m` uniform draws, the first ones replaced by the seeds `x0`."""
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
    return x


def _reference_point(ref_point, f: np.ndarray) -> np.ndarray:
    k = f.shape[1]
    if ref_point is None:
        spread = f.max(axis=0) - f.min(axis=0)
        return f.max(axis=0) + 0.1 * np.where(spread > 0, spread, 1.0)
    ref = np.asarray(ref_point, dtype=float)
    if ref.shape != (k,) or not np.all(np.isfinite(ref)):
        raise ValueError(
            f"`ref_point` must be a finite vector of length {k}; got {ref_point!r}"
        )
    return ref


def minimize_pareto(
    fun: Callable,
    bounds,
    method="ebsda",
    *,
    n_points: int = 100,
    max_nfev: int = 10_000,
    max_time: float | None = None,
    neighbours: int = 10,
    archive: bool = True,
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
    method : str, SpiralRule or LearnedMetricSpiral
        ``"ebsda"``, ``"sda"``, ``"lasda"`` or ``"ebsda-scaled"``: the
        spiral rule (see :func:`spiralid.optim.minimize`), with the paper's
        constants; ``"learned-metric"`` polls a pair of directions
        per subproblem with a step per direction from success (its
        ``basis``, ``grow`` and ``shrink`` options apply; the others belong
        to the single-objective search).
    n_points : int
        Population size: one subproblem each (for 3 objectives the largest
        simplex lattice that fits), and the most points the result holds.
    max_nfev : int
        Budget of objective evaluations (at least two populations).
    max_time : float, optional
        Wall-time limit in seconds (a finite number > 0; default None, no
        limit), checked after each iteration as in
        :func:`spiralid.optim.minimize`: the search ends after the
        iteration during which it passed.
    neighbours : int
        Subproblems whose incumbents a point may take as its centre and
        replace.
    archive : bool
        Keep every evaluated non-dominated point and return that archive
        thinned to at most `n_points` evenly spread points (SPEA2's
        truncation, :func:`~spiralid.optim.front.thin_front`; default);
        False returns the non-dominated incumbents of the subproblems.
    ref_point : array_like, shape (k,), optional
        Reference point of the hypervolume ``history``; default the initial
        population's worst value of each objective plus a tenth of its range.
    rng : None, int or numpy.random.Generator
    vectorized : bool
        Whether `fun` takes a batch of points.
    callback : callable, optional
        ``callback(intermediate)`` after every iteration with the result so
        far (``x`` and ``fun`` of the non-dominated incumbents, ``nit``);
        returning True stops the search.
    x0 : array_like, shape (q, n) or (n,), optional
        Known points (e.g. a single-objective estimate) that take the place
        of the first ``q`` uniform draws of the initial population (clipped
        into the box; at most the population size). The draws are made
        anyway, so a seed changes nothing else.

    Returns
    -------
    OptimiserResult
        ``x`` the front's points (shape (p, n)), ``fun`` their objective
        vectors (p, k), ``population`` and ``population_fun`` every
        subproblem's incumbent, ``weights``, ``ref_point``, ``history`` (the
        hypervolume of the archive, or of the non-dominated incumbents,
        after the initial population and each iteration), ``status`` (1
        when the budget ended it, 3 the time limit, 0 the callback),
        ``message``, ``nit``, ``nfev``,
        ``n_restarts`` (points, or polls, started again), ``elapsed``.

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
    rule = _parse_rule(method)
    m = integer(n_points, "n_points", 4)
    max_nfev = integer(max_nfev, "max_nfev", 2 * m)
    max_time = check_max_time(max_time)
    neighbours = integer(neighbours, "neighbours", 2)
    if not isinstance(archive, bool):
        raise ValueError(f"`archive` must be True or False; got {archive!r}")
    if callback is not None and not callable(callback):
        raise ValueError(f"`callback` must be callable or None; got {callback!r}")
    gen = generator(rng)
    vectorized = check_objective(fun, vectorized)

    x = _initial_points(gen, lo, hi, m, x0)
    f = _evaluate(fun, x, vectorized, None)
    k = f.shape[1]
    if k not in (2, 3):
        raise ValueError(f"`fun` must return 2 or 3 objectives; got {k}")
    sub = Subproblems(k, m, neighbours, x, f)
    m = sub.size
    nfev = m
    ref = _reference_point(ref_point, sub.f)
    store = Archive(sub.x, sub.f, m) if archive else None
    if isinstance(rule, LearnedMetricSpiral):
        moves = PollMoves(rule, sub, lo, hi, gen)
    else:
        moves = SpiralMoves(rule, sub, lo, hi)

    def incumbents() -> tuple[np.ndarray, np.ndarray]:
        keep = non_dominated(sub.f)
        return sub.x[keep], sub.f[keep]

    def front() -> tuple[np.ndarray, np.ndarray]:
        return (store.x, store.f) if store is not None else incumbents()

    history = [hypervolume(front()[1], ref)]
    nit, status = 0, 1
    while nfev + moves.batch <= max_nfev:
        y = moves.propose(sub, gen)
        fy = _evaluate(fun, y, vectorized, k)
        nfev += y.shape[0]
        nit += 1
        sub.see(fy)
        moves.learn(sub, y, fy)
        sub.offer(y, fy, moves.owners, gen)
        if store is not None:
            store.add(y, fy)
        history.append(hypervolume(front()[1], ref))
        if callback is not None:
            x_now, f_now = incumbents()
            if callback(OptimiserResult(x=x_now, fun=f_now, nit=nit)):
                status = 0
                break
        if max_time is not None and time.perf_counter() - t_start > max_time:
            status = 3
            break
    x_front, f_front = store.final() if store is not None else front()
    return OptimiserResult(
        x=x_front,
        fun=f_front,
        population=sub.x,
        population_fun=sub.f,
        weights=sub.weights,
        ref_point=ref,
        status=status,
        success=True,
        message=STOPS[{0: "callback", 1: "max_nfev", 3: "max_time"}[status]],
        nit=nit,
        nfev=nfev,
        n_restarts=moves.n_restarts,
        history=np.asarray(history),
        elapsed=time.perf_counter() - t_start,
    )
