"""The grey-box family's methods, one entry each in the estimator table
(:data:`~spiralid.sysid.estimation.core.families.ESTIMATORS`):

- ``"spiral"`` (default): the learned-metric spiral
  (:func:`spiralid.optim.minimize` with ``method="learned-metric"``) over
  the free parameters in their unit box (log-scaled where a parameter has a
  log scale), seeded with the initial values, restarting once a run's steps
  are below a hundredth of the box (``_RESTARTS``), then Levenberg-Marquardt
  on the simulation error from the best point, projected into the box;
- ``"oe"``: that Levenberg-Marquardt alone, from the initial values;
- both beside a second fit over growing horizons (``horizons``, shares of
  the record): the search on the first share (with three times
  ``max_nfev`` over a tenth: a budget in samples, ``_search_budget``), the
  polish on each longer one in turn (``"spiral"`` first steps out of each
  shorter one's minimum along the directions it cannot determine,
  ``explore``, :func:`_explored`); the fit of lower cost on the whole
  record is kept;
- ``"sda"``, ``"ebsda"``: the paper's spiral searches over the same box and
  cost, as printed (no polish).

Every method ends with the Jacobian at its result, from which the
parameters' intervals come (:mod:`.intervals`).

Several outputs are weighted by their noise variance, which the record does
not state, so the weights are estimated: the fit above runs with each
output scaled by one over its RMS (every output counts as much, whatever
its unit); then each output's scale becomes one over the RMS of its error
at that fit (its noise's standard deviation, if the model is right) and
``"spiral"`` and ``"oe"`` polish again from there, up to
``_REWEIGHTS`` times, until no scale moves by more than a tenth. A
well-measured sensor then weighs more than a noisy one, as maximum
likelihood for Gaussian noise of unknown variances weighs them, and the
intervals come from the Jacobian so weighted (for ``"sda"`` and
``"ebsda"`` too: they are reweighted, not polished).
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import integer
from spiralid.optim import Restarts, minimize

from ...data import IOData
from ...models.greybox import GreyBox
from ...models.greybox_model import GreyBoxModel, LinearGreyBoxModel
from ..linear.levenberg import levenberg_marquardt
from .intervals import parameter_intervals, undetermined_directions
from .parallel import ParallelEvaluator
from .problem import GreyBoxProblem

__all__ = ["GREYBOX_METHODS", "fit_greybox"]

_COMMON = ("rng", "gain", "penalty", "workers")
_LOCAL = ("polish_nfev", "horizons")
#: method -> the options it takes beside identify's common ones.
GREYBOX_METHODS: dict[str, tuple[str, ...]] = {
    "spiral": (*_COMMON, "n_points", "max_nfev", *_LOCAL, "restarts", "explore"),
    "oe": (*_COMMON, *_LOCAL),
    "sda": (*_COMMON, "n_points", "max_nfev"),
    "ebsda": (*_COMMON, "n_points", "max_nfev"),
}
# Searches' default population and budget (simulations), and the polish's.
_N_POINTS = 20
_MAX_NFEV = 1000
_POLISH_NFEV = 200
# Restarts of spiral's search (the learned-metric spiral's, alternating
# fresh polls and population runs), a run counting as collapsed once its
# steps are all below a hundredth of the unit box: from there the polish
# takes over, and over a rugged cost (the rig's whole record, stick-slip)
# the poll sits in a local dip long before its steps reach the optimiser's
# 1e-9, so the budget goes to new runs instead. Against pycma's CMA-ES at
# equal evaluations (benchmarks/greybox_cmaes.py) it cut the rig's median
# cost by 2-3 times, to 1.4-1.9 times CMA-ES's (figures in the results).
_RESTARTS = Restarts(tol_radius=1e-2)
# The search's start is the learned-metric spiral's own (a poll from the best
# of 20 points, the initial values among them). A start from the initial
# values as CMA-ES's (LearnedMetricSpiral(first_sigma=1/sqrt(12),
# local_sigma=0.1), benchmarks/greybox_cmaes.py's spiral-x0) halved the
# rig's median cost with 6 free and fitted the Cascaded Tanks better, but
# was still behind CMA-ES with 4 free and lost seed 0's rig fit (95.66 %
# against 97.92 %, the stiction missed): not the default (figures in the
# results).
# The growing horizons (shares of the record) of spiral's and oe's second
# fit: over a tenth of the rig's record, its friction plane is smooth.
_HORIZONS = (0.1, 0.25, 0.5)
# The search on the first horizon simulates a share of the record, so it
# gets a whole number of `max_nfev` budgets, as many as keep its simulated
# samples near this share of the whole record's search (at least one):
# three over the default's first tenth, one over a quarter or more. With
# one, 7 of 20 seeds of the stick-slip rig's hub-angle fit ended in the
# plain Coulomb basin (94.8-95.8 %); with three, every seed found the
# stiction, at about a fifth more processor time a fit (figures in the
# results).
_HORIZON_SAMPLES = 0.3
# spiral's horizons step out of each shorter horizon's minimum along the
# directions that horizon cannot determine (those its intervals would drop,
# the least determined first, at most this many), these shares of the unit
# box each way, and polish from there: a short record can leave a parameter
# flat that the whole one needs (the stick-slip rig with an unknown
# payload: at a plain Coulomb minimum over the first tenth the breakaway
# level, below the Coulomb one, moves no sample, and the truth's stiction
# is 0.08 % lower there but 15 % lower over the whole record; one step
# length left 2 of 20 realisations in the plain Coulomb basin). Each of
# those polishes gets this share of `polish_nfev`: it only has to reach a
# basin and rank it, the next horizon's polish finishes it; with the whole
# budget, the Cascaded Tanks' and the DaISy arm's fits (whose horizons leave
# directions undetermined that lead nowhere) took 2.8 and 3.4 times as long.
_EXPLORED_DIRECTIONS = 2
_EXPLORE_STEPS = (0.25, -0.25, 0.5, -0.5)
_EXPLORE_POLISH = 0.25
_RULES = {"spiral": "learned-metric", "sda": "sda", "ebsda": "ebsda"}
# Rounds of reweighting the outputs and polishing again (several outputs).
_REWEIGHTS = 3
# A scale that moves by less than this share is settled.
_SETTLED = 0.1
# An output's noise is taken as at least this share of its RMS, so that an
# output the model fits exactly (a noise-free one) gets a finite weight.
_NOISE_FLOOR = 1e-6


def _polish(
    problem: GreyBoxProblem, z0: np.ndarray, max_nfev: int, pool: ParallelEvaluator
) -> np.ndarray:
    """Levenberg-Marquardt on the simulation error from `z0`, trial points
    clipped into the unit box, the Jacobian's simulations on `pool`."""
    result = levenberg_marquardt(
        problem.residual,
        lambda z: problem.jacobian(z, pool.residuals),
        z0,
        project=lambda z: np.clip(z, 0.0, 1.0),
        max_nfev=max_nfev,
    )
    return np.asarray(result.x, dtype=float)


def _search_budget(given: dict, n_points: int, share: float) -> int:
    """The search's simulations on a record `share` of the whole one's
    length: ``max_nfev`` times as many as keep its samples near
    ``_HORIZON_SAMPLES`` of the whole record's search, at least once."""
    budget = integer(given.get("max_nfev", _MAX_NFEV), "max_nfev", n_points)
    return budget * max(1, round(_HORIZON_SAMPLES / share))


def _search(
    problem: GreyBoxProblem,
    method: str,
    given: dict,
    pool: ParallelEvaluator,
    share: float = 1.0,
) -> np.ndarray:
    """The search's best unit-box point (the initial values' for a
    local-only method), on a record `share` of the whole one's length; a
    batch of points at a time on `pool`'s workers."""
    if method not in _RULES:
        return problem.z0
    n_points = integer(given.get("n_points", _N_POINTS), "n_points", 2)
    budget = _search_budget(given, n_points, share)
    parallel = pool.executor is not None
    found = minimize(
        pool.costs if parallel else problem,
        np.tile([0.0, 1.0], (problem.n_free, 1)),
        method=_RULES[method],
        n_points=n_points,
        max_nfev=budget,
        rng=given.get("rng"),
        vectorized=parallel,
        x0=problem.z0,
        restarts=given.get("restarts", _RESTARTS) if method == "spiral" else False,
        # The spiral's trial points outside the box are clipped onto it
        # (the paper's searches stay as printed: the problem clips what
        # they evaluate): a parameter's bounds are physical, and a point
        # beyond them would be reported as the fit.
        options={"bounds_policy": "clip"} if method == "spiral" else None,
    )
    return np.clip(np.asarray(found.x, dtype=float), 0.0, 1.0)


def _explored(
    stage: GreyBoxProblem,
    z: np.ndarray,
    polish_nfev: int,
    pool: ParallelEvaluator,
) -> np.ndarray:
    """The lowest cost on `stage` of `z` and of the polishes (a share
    ``_EXPLORE_POLISH`` of `polish_nfev`) from points
    stepped out of `z` (``_EXPLORE_STEPS``) along the directions that
    `stage`'s record cannot determine there (at most
    ``_EXPLORED_DIRECTIONS``); `z` itself where it determines them all."""
    jac = stage.jacobian(z, pool.residuals)
    weak = undetermined_directions(stage, stage.residual(z), jac)
    best, lowest = z, stage(z)
    budget = max(1, round(_EXPLORE_POLISH * polish_nfev))
    for direction in weak[:_EXPLORED_DIRECTIONS]:
        for step in _EXPLORE_STEPS:
            start = np.clip(z + step * direction, 0.0, 1.0)
            polished = _polish(stage, start, budget, pool)
            cost = stage(polished)
            if cost < lowest:
                best, lowest = polished, cost
    return best


def _horizon_lengths(value, n: int, n_free: int) -> list[int]:
    """The sample counts of `value`'s horizons (increasing shares of the
    record in (0, 1)), those too short for a fit left out, then `n`."""
    try:
        shares = np.asarray(value, dtype=float).ravel()
    except (TypeError, ValueError):
        raise TypeError(
            f"`horizons` must be a sequence of shares in (0, 1); got {value!r}"
        ) from None
    if np.any(~(shares > 0.0) | ~(shares < 1.0)) or np.any(np.diff(shares) <= 0):
        raise ValueError(
            f"`horizons` must be increasing shares in (0, 1); got {value!r}"
        )
    lengths = {round(float(f) * n) for f in shares}
    return [*sorted(k for k in lengths if 2 * n_free < k < n), n]


def _chain(
    stages: list[GreyBoxProblem],
    method: str,
    given: dict,
    polish_nfev: int,
    pool: ParallelEvaluator,
    explore: bool,
) -> np.ndarray:
    """The search on the first stage's record, then (``"spiral"``,
    ``"oe"``) the polish on each stage's in turn from the last result; with
    `explore`, each stage but the last explored (:func:`_explored`) before
    the next."""
    pool.problem = stages[0]
    share = stages[0].y.size / stages[-1].y.size
    z = _search(stages[0], method, given, pool, share)
    for stage in stages if method in ("spiral", "oe") else ():
        pool.problem = stage
        polished = _polish(stage, z, polish_nfev, pool)
        if stage(polished) <= stage(z):
            z = polished
        if explore and stage is not stages[-1]:
            z = _explored(stage, z, polish_nfev, pool)
    return z


def _explore(value) -> bool:
    """`explore` checked: a bool, or a one-line TypeError."""
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"`explore` must be True or False; got {value!r}")
    return bool(value)


def _problem(data: IOData, structure: GreyBox, given: dict) -> GreyBoxProblem:
    return GreyBoxProblem(
        data,
        structure,
        gain=given.get("gain", "auto"),
        penalty=given.get("penalty", 1e6),
    )


def _noise_scale(problem: GreyBoxProblem, residual: np.ndarray) -> np.ndarray:
    """One over each output's error RMS in `residual` (floored at
    ``_NOISE_FLOOR`` of the output's RMS)."""
    e = problem.output_errors(residual)
    floor = _NOISE_FLOOR * np.sqrt(np.mean(problem.y.reshape(e.shape) ** 2, axis=0))
    return 1.0 / np.maximum(np.sqrt(np.mean(e**2, axis=0)), floor)


def _reweighted(
    problem: GreyBoxProblem,
    z: np.ndarray,
    method: str,
    polish_nfev: int,
    pool: ParallelEvaluator,
) -> tuple[GreyBoxProblem, np.ndarray]:
    """The problem with each output weighted by its noise variance, and the
    fit polished under those weights (module docstring); a single output
    as it is."""
    if problem.n_outputs == 1:
        return problem, z
    for _ in range(_REWEIGHTS):
        scale = _noise_scale(problem, problem.residual(z))
        if np.all(np.abs(scale / problem.scale - 1.0) <= _SETTLED):
            break
        problem = problem.rescaled(scale)
        pool.problem = problem
        if method in ("spiral", "oe"):
            polished = _polish(problem, z, polish_nfev, pool)
            if problem(polished) <= problem(z):
                z = polished
    return problem, z


def _output_fits(problem: GreyBoxProblem, residual, names) -> dict[str, float]:
    """Each output's fit % (MATLAB's ``compare``: ``100 (1 - |e| / |y -
    mean y|)``) of the unscaled error in `residual`."""
    e = problem.output_errors(residual)
    y = problem.y.reshape(e.shape)
    spread = np.linalg.norm(y - y.mean(axis=0), axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        fits = 100.0 * (1.0 - np.linalg.norm(e, axis=0) / spread)
    return {str(n): float(f) for n, f in zip(names, fits, strict=True)}


def fit_greybox(data: IOData, structure: GreyBox, method: str, given: dict):
    """The grey box `structure` fitted to `data` by `method` (a key of
    :data:`GREYBOX_METHODS`), `given` identify's arguments by name.

    With ``horizons`` (``"spiral"`` and ``"oe"``), a second fit beside the
    one on the whole record: its search runs on the record's first share
    only and its polish on each longer share in turn, then on the whole
    record, each from the last one's result; the fit of lower cost on the
    whole record is the result. The error of a free run accumulates along
    the record (a hub that comes to rest elsewhere after each pulse), so
    over the whole record the cost can be rugged where over its start it is
    smooth, and the start's minimum lies in the whole record's basin.

    A record of several outputs is weighted by their noise variances,
    estimated from the fit's errors (module docstring).

    Returns
    -------
    GreyBoxModel or LinearGreyBoxModel
        As the structure's kind.
    """
    problem = _problem(data, structure, given)
    polish_nfev = integer(given.get("polish_nfev", _POLISH_NFEV), "polish_nfev", 1)
    explore = method == "spiral" and _explore(given.get("explore", True))
    chains = [[problem]]
    if method in ("spiral", "oe"):
        horizons = given.get("horizons", _HORIZONS)
        lengths = _horizon_lengths(horizons, problem.y.size, problem.n_free)
        if len(lengths) > 1:
            shorter = [_problem(data[:k], structure, given) for k in lengths[:-1]]
            chains.append([*shorter, problem])
    with ParallelEvaluator(problem, given.get("workers")) as pool:
        z = min(
            (
                _chain(chain, method, given, polish_nfev, pool, explore)
                for chain in chains
            ),
            key=problem,
        )
        problem.nfev += sum(stage.nfev for chain in chains[1:] for stage in chain[:-1])
        problem, z = _reweighted(problem, z, method, polish_nfev, pool)
        pool.problem = problem
        residual = problem.residual(z)
        jac = problem.jacobian(z, pool.residuals)
    intervals, notes = parameter_intervals(problem, z, residual, jac)
    kind = LinearGreyBoxModel if structure.kind == "linear" else GreyBoxModel
    return kind(
        structure=structure,
        values=problem.values(z),
        ts=problem.ts,
        method=method,
        cost=problem.cost_of(residual),
        intervals=intervals,
        undetermined=notes,
        output_name=data.output_name,
        nfev=problem.nfev,
        output_fits=_output_fits(problem, residual, data.output_names),
        weights=np.square(np.broadcast_to(problem.scale, (problem.n_outputs,))),
        input_name=str(data.input_name),
        input_unit=data.input_unit,
        output_unit=data.output_unit,
        u_offset=data.u_offset,
        y_offset=data.y_offset,
    )
