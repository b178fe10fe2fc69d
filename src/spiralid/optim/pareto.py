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
(thinned by SPEA2's truncation when it grows past four populations, the
thinned points remembered so that none of them dominates a later one
taken); the result is the archive thinned to ``n_points``, or with
``archive=False`` the non-dominated incumbents.

Any number ``k >= 2`` of objectives is taken. The weight vectors are
Das and Dennis's simplex lattice (with a second, inner lattice when the
objectives outnumber its divisions, as in NSGA-III); the hypervolume
history is exact for 2 and 3 objectives and a Monte-Carlo estimate with
its standard error beyond (``history_kind``, ``history_stderr``).

The paper's rule constants are kept (``method="sda"``: ``r = 0.95``,
``theta = pi/4``; ``"ebsda"``: eq. (4), (7), (8)). The default rule is the
learned-metric poll (:data:`DEFAULT_PARETO_METHOD`), the strongest of them
on the benchmark problems (docs/results/multiobjective.md); the paper's
Eb-SDA is ``method="ebsda"``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from spiralid._checks import box_bounds, generator, integer
from spiralid.choices import (
    DEFAULT_PARETO_METHOD,
    PARETO_METHOD_NAMES,
    require_names,
)
from spiralid.optim._decomposition import (
    Archive,
    PollMoves,
    SpiralMoves,
    Subproblems,
)
from spiralid.optim._loop import (
    STATUS_CODE,
    STOPS,
    check_max_time,
    check_objective,
    settings,
)
from spiralid.optim.front import (
    HypervolumeEstimate,
    _estimate,
    _front_below,
    hypervolume,
    hypervolume_mc,
    non_dominated,
    thin_front,
    weight_vectors,
)
from spiralid.optim.learned_rule import LearnedMetricSpiral
from spiralid.optim.result import OptimiserResult
from spiralid.optim.rules import SpiralRule
from spiralid.optim.spiral import RULES, _parse_method

__all__ = [
    "DEFAULT_PARETO_METHOD",
    "PARETO_METHODS",
    "PARETO_OPTIONS",
    "HypervolumeEstimate",
    "hypervolume",
    "hypervolume_mc",
    "minimize_pareto",
    "non_dominated",
    "thin_front",
    "weight_vectors",
]


def _point_wise(fun, x: np.ndarray, k: int | None) -> np.ndarray:
    """The objective vectors of `fun` called on each row of `x` in turn,
    every one of the same length (`k` when known)."""
    rows = [np.asarray(fun(row.copy()), dtype=float) for row in x]
    shapes = {r.shape for r in rows} | ({(k,)} if k is not None else set())
    if len(shapes) != 1:
        raise ValueError(
            "`fun` must return the same number of objectives for every "
            f"point; got shapes {sorted(shapes)}"
        )
    return np.array(rows)


def _evaluate(fun, x: np.ndarray, vectorized: bool, k: int | None) -> np.ndarray:
    """The objective vectors of the rows of `x`, checked: (m, k), finite."""
    if vectorized:
        f = np.asarray(fun(x.copy()), dtype=float)
    else:
        f = _point_wise(fun, x, k)
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


# The learned-metric options that belong to the single-objective search (its
# model step, its population periods, its step schedule without success
# steps): the poll per subproblem has no counterpart, so they are refused
# rather than ignored. Only `basis`, `grow`, `shrink` and
# `crossover` (which the single-objective search refuses in turn) apply.
_SINGLE_OBJECTIVE_ONLY = ("populations", "model_step", "success_steps")


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
    if isinstance(rule, LearnedMetricSpiral):
        default = LearnedMetricSpiral()
        for name in _SINGLE_OBJECTIVE_ONLY:
            if getattr(rule, name) != getattr(default, name):
                raise ValueError(
                    f"`{name}` of LearnedMetricSpiral does not apply to "
                    "minimize_pareto (only basis, grow, shrink and crossover do); got "
                    f"{name}={getattr(rule, name)!r}"
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


def _check_ref_point(ref_point, k: int | None = None) -> np.ndarray | None:
    """`ref_point` as a finite vector of length `k` (at least 2 before the
    objective count is known), or a ValueError naming it."""
    if ref_point is None:
        return None
    try:
        ref = np.asarray(ref_point, dtype=float)
    except (TypeError, ValueError):
        ref = np.full(0, np.nan)
    if k is None and ref.ndim == 1 and ref.size >= 2:
        k = ref.size
    if ref.shape != (k,) or not np.all(np.isfinite(ref)):
        length = "at least 2" if k is None else k
        raise ValueError(
            f"`ref_point` must be a finite vector of length {length}; got {ref_point!r}"
        )
    return ref


def _check_count(k: int, m: int, known_from: str) -> None:
    """One subproblem per weight vector needs at least the `k` corners of
    the simplex among the `m` points."""
    if m < k:
        raise ValueError(
            f"`n_points` must be at least the number of objectives ({k}, from "
            f"{known_from}); got {m}"
        )


def _reference_point(ref: np.ndarray | None, f: np.ndarray) -> np.ndarray:
    """The hypervolume's reference point: `ref`, checked against the
    objective count, or the initial population's worst plus a tenth of its
    range."""
    if ref is not None:
        return _check_ref_point(ref, f.shape[1])
    spread = f.max(axis=0) - f.min(axis=0)
    return f.max(axis=0) + 0.1 * np.where(spread > 0, spread, 1.0)


def _first_population(fun, x: np.ndarray, vectorized: bool, k: int | None):
    """The initial population's objective vectors, the objective count
    checked after the first point: without a reference point only `fun`'s
    answer tells the count, so one evaluation is spent before the check and
    none on the rest of the population. A vectorised `fun` gets a batch of
    that one point, then one batch of the rest."""
    f = _evaluate(fun, x[:1], vectorized, None)
    got = f.shape[1]
    if k is not None and got != k:
        raise ValueError(
            f"`fun` must return {k} objectives, as `ref_point` has; got {got}"
        )
    if got < 2:
        raise ValueError(f"`fun` must return at least 2 objectives; got {got}")
    _check_count(got, x.shape[0], "`fun`'s first point")
    return np.vstack([f, _evaluate(fun, x[1:], vectorized, got)])


# minimize_pareto()'s rarely used settings and their defaults: keys of its
# `options` mapping, as minimize() keeps its own (MINIMIZE_OPTIONS).
PARETO_OPTIONS = {"max_time": None, "neighbours": 10, "ref_point": None}


def minimize_pareto(
    fun: Callable,
    bounds,
    method=DEFAULT_PARETO_METHOD,
    *,
    n_points: int = 100,
    max_nfev: int = 10_000,
    archive: bool = True,
    rng=None,
    vectorized: bool = False,
    callback: Callable | None = None,
    x0=None,
    options: dict | None = None,
) -> OptimiserResult:
    """Approximate the Pareto front of a vector objective by a spiral search.

    Parameters
    ----------
    fun : callable
        ``fun(x) -> (k,)`` objective values to minimise for ``x`` of shape
        (n,), or with ``vectorized=True`` ``fun(X) -> (m, k)`` for ``X`` of
        shape (m, n); ``k >= 2``. A non-finite value is an error.
        Every other argument is checked before `fun` is first called. The
        count ``k`` is known then when ``ref_point`` is given (its length),
        and `n_points` is checked against it; otherwise ``k`` is checked
        after `fun`'s first point (a batch of that one point when
        vectorised), before the rest of the population is evaluated.
    bounds : sequence of (low, high), (n, 2) array or scipy.optimize.Bounds
        The search box; points are kept inside it.
    method : str, SpiralRule or LearnedMetricSpiral
        ``"learned-metric"`` (the default, :data:`DEFAULT_PARETO_METHOD`)
        polls a pair of directions per subproblem with a step per direction
        from success, half the subproblems a crossover pair instead at each
        iteration (its ``basis``, ``grow``, ``shrink`` and ``crossover``
        options apply; ``populations``, ``model_step`` and
        ``success_steps`` belong to the single-objective search, and a rule
        that turns one off is refused). ``"ebsda"`` (the paper's rule),
        ``"sda"``, ``"lasda"`` or ``"ebsda-scaled"``: the spiral rule (see
        :func:`spiralid.optim.minimize`), with the paper's constants.
    n_points : int
        Population size: one subproblem each (for 3 or more objectives the
        weight lattice of :func:`~spiralid.optim.front.weight_vectors` that
        fits: 91 for 3 objectives, 84 for 4, 70 for 5), and the most points
        the result holds; at least ``k``.
        Default 100, twice :func:`~spiralid.optim.minimize`'s 50, because
        it is also the front's resolution: 100 is MOEA/D's population for
        two objectives (Zhang and Li 2007) and gives 91 subproblems for
        three. With the default budget that is 49 iterations of the default
        rule (two points per subproblem each; 99 of a spiral rule, one
        point each), as :func:`~spiralid.sysid.identify_pareto`'s 50 points
        make with its 5,000 evaluations.
    max_nfev : int
        Budget of objective evaluations: at least the initial population
        and one iteration, two populations (three for
        ``"learned-metric"``, which evaluates two points per subproblem).
    archive : bool
        Keep every evaluated non-dominated point and return that archive
        thinned to at most `n_points` evenly spread points (SPEA2's
        truncation, :func:`~spiralid.optim.front.thin_front`; default);
        False returns the non-dominated incumbents of the subproblems.
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
    options : dict, optional
        The rarely used settings (:data:`PARETO_OPTIONS`, with their
        defaults), as :func:`~spiralid.optim.minimize` keeps its own; any
        other key is refused in one line naming it:

        ``max_time`` : float or None
            Wall-time limit in seconds (a finite number > 0; default None,
            no limit), checked after each iteration as in
            :func:`spiralid.optim.minimize`: the search ends after the
            iteration during which it passed.
        ``neighbours`` : int
            Subproblems whose incumbents a point may take as its centre and
            replace (default 10).
        ``ref_point`` : array_like, shape (k,), or None
            Reference point of the hypervolume ``history``; default the
            initial population's worst value of each objective plus a
            tenth of its range. Its length tells the objective count before
            any evaluation.

    Returns
    -------
    OptimiserResult
        ``x`` the front's points (shape (p, n)), ``fun`` their objective
        vectors (p, k), ``population`` and ``population_fun`` every
        subproblem's incumbent, ``weights``, ``ref_point``, ``history`` (the
        hypervolume of the archive, or of the non-dominated incumbents,
        after the initial population and each iteration), ``history_kind``
        (``"exact"`` for 2 and 3 objectives; for more a Monte-Carlo
        estimate, :func:`~spiralid.optim.front.hypervolume_mc`, from one set
        of 8,192 uniform draws of `rng` reused at every iteration),
        ``history_stderr`` (its standard errors, 0 when exact), ``status`` (1
        when the budget ended it, 3 the time limit, 0 the callback),
        ``message``, ``nit``, ``nfev``,
        ``n_restarts`` (points, or polls, started again), ``elapsed``.
        ``nfev`` counts every evaluation, the initial population's included
        (with 3 or more objectives more points than subproblems may be
        drawn).

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
    opts = settings(options, PARETO_OPTIONS, "the options of minimize_pareto()")
    lo, hi = box_bounds(bounds)
    rule = _parse_rule(method)
    m = integer(n_points, "n_points", 4)
    # The initial population and one iteration: a point per subproblem, or
    # the poll's two.
    per_point = 2 if isinstance(rule, LearnedMetricSpiral) else 1
    max_nfev = integer(max_nfev, "max_nfev", (1 + per_point) * m)
    max_time = check_max_time(opts["max_time"])
    neighbours = integer(opts["neighbours"], "neighbours", 2)
    if not isinstance(archive, bool):
        raise TypeError(f"`archive` must be True or False; got {archive!r}")
    if callback is not None and not callable(callback):
        raise TypeError(f"`callback` must be callable or None; got {callback!r}")
    gen = generator(rng)
    vectorized = check_objective(fun, vectorized)
    ref = _check_ref_point(opts["ref_point"])
    if ref is not None:
        _check_count(ref.size, m, "`ref_point`")

    x = _initial_points(gen, lo, hi, m, x0)
    f = _first_population(fun, x, vectorized, None if ref is None else ref.size)
    sub = Subproblems(f.shape[1], m, neighbours, x, f)
    search = _Search(
        fun,
        vectorized,
        sub,
        _moves(rule, sub, lo, hi, gen),
        Archive(sub.x, sub.f, sub.size) if archive else None,
        _Volume(_reference_point(ref, sub.f), gen),
        nfev=x.shape[0],
    )
    status = search.run(gen, max_nfev, max_time, callback, t_start)
    x_front, f_front = search.final()
    return OptimiserResult(
        x=x_front,
        fun=f_front,
        population=sub.x,
        population_fun=sub.f,
        weights=sub.weights,
        ref_point=search.volume.ref,
        status=STATUS_CODE[status],
        success=True,
        message=STOPS[status],
        nit=search.nit,
        nfev=search.nfev,
        n_restarts=search.moves.n_restarts,
        history=np.asarray(search.history),
        history_stderr=np.asarray(search.stderr),
        history_kind=search.volume.kind,
        elapsed=time.perf_counter() - t_start,
    )


def _moves(rule, sub: Subproblems, lo, hi, gen) -> PollMoves | SpiralMoves:
    """How the rule proposes each subproblem's next point."""
    if isinstance(rule, LearnedMetricSpiral):
        return PollMoves(rule, sub, lo, hi, gen)
    return SpiralMoves(rule, sub, lo, hi)


# Uniform draws of the Monte-Carlo hypervolume history (4 or more
# objectives): a standard error of at most 0.55 % of the box, for about a
# millisecond per iteration with a few hundred points.
_HISTORY_SAMPLES = 8192


class _Volume:
    """The history's hypervolume from `ref`: exact for 2 and 3 objectives,
    else estimated from one set of uniform draws (from `gen`) reused at
    every iteration, so that the history follows the front, not the draws.
    """

    def __init__(self, ref: np.ndarray, gen):
        self.ref = ref
        self.unit = None
        self.kind = "exact"
        if ref.size > 3:
            self.unit = gen.uniform(size=(_HISTORY_SAMPLES, ref.size))
            self.kind = f"monte-carlo ({_HISTORY_SAMPLES} samples)"

    def __call__(self, f: np.ndarray) -> tuple[float, float]:
        """The volume of `f` and its standard error (0 when exact)."""
        if self.unit is None:
            return hypervolume(f, self.ref), 0.0
        est = _estimate(*_front_below(f, self.ref), self.unit)
        return est.value, est.stderr


class _Search:
    """The decomposition's state through :func:`minimize_pareto`'s loop: the
    subproblems, their moves, the archive and the hypervolume history."""

    def __init__(self, fun, vectorized, sub, moves, store, volume, nfev: int):
        self.fun, self.vectorized = fun, vectorized
        self.sub, self.moves, self.store, self.volume = sub, moves, store, volume
        self.nfev, self.nit = nfev, 0
        self.history, self.stderr = [], []
        self._record()

    def _record(self) -> None:
        value, stderr = self.volume(self.front()[1])
        self.history.append(value)
        self.stderr.append(stderr)

    def incumbents(self) -> tuple[np.ndarray, np.ndarray]:
        keep = non_dominated(self.sub.f)
        return self.sub.x[keep], self.sub.f[keep]

    def front(self) -> tuple[np.ndarray, np.ndarray]:
        if self.store is None:
            return self.incumbents()
        return self.store.x, self.store.f

    def final(self) -> tuple[np.ndarray, np.ndarray]:
        return self.front() if self.store is None else self.store.final()

    def step(self, gen) -> None:
        """One iteration: a point per subproblem, evaluated and offered."""
        sub, moves = self.sub, self.moves
        y = moves.propose(sub, gen)
        fy = _evaluate(self.fun, y, self.vectorized, sub.f.shape[1])
        self.nfev += y.shape[0]
        self.nit += 1
        sub.see(fy)
        moves.learn(sub, y, fy)
        sub.offer(y, fy, moves.owners, gen)
        if self.store is not None:
            self.store.add(y, fy)
        self._record()

    def run(self, gen, max_nfev: int, max_time, callback, t_start: float) -> str:
        """Iterate until the budget, the time limit or the callback stops
        it; why it stopped (a key of ``STOPS``)."""
        while self.nfev + self.moves.batch <= max_nfev:
            self.step(gen)
            if callback is not None:
                x_now, f_now = self.incumbents()
                if callback(OptimiserResult(x=x_now, fun=f_now, nit=self.nit)):
                    return "callback"
            if max_time is not None and time.perf_counter() - t_start > max_time:
                return "max_time"
        return "max_nfev"
