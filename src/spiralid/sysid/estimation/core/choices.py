"""What the spiral searches over a nonlinear model's discrete choices share:
:func:`~spiralid.sysid.choose_narx` (lags, hidden units, decay) and
:func:`~spiralid.sysid.choose_state_space` (state order, hidden units,
encoder window, decay), each optionally with the subsequence length.

Every choice is a point of an integer grid, one inclusive range a
coordinate (the decay's exponent in half decades, a horizon by its index).
:func:`run_search` runs :func:`spiralid.optim.minimize` over the box half
a unit beyond each range, rounds each point to the nearest grid point,
and calls ``score(choice)`` (a training on the first part of the
estimation record, scored on its held-back end) once per distinct choice:
points that round to a choice already trained cost nothing, so the
`budget` counts trainings, not the search's evaluations.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from spiralid._checks import generator, integer, real
from spiralid.optim import minimize
from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ..narx.subsequences import check_horizon

__all__ = [
    "Candidates",
    "half_decades",
    "held_back_fit",
    "int_range",
    "nearest",
    "spiral_choice",
]


class _BudgetSpent(Exception):
    """A new training was asked for after the last one the budget allows."""


def int_range(value, name: str, minimum: int) -> tuple[int, int]:
    """`value` checked as an inclusive range ``(low, high)`` of integers,
    each >= `minimum`, low <= high; one-line ValueError naming `name`."""
    try:
        lo, hi = value
    except (TypeError, ValueError):
        raise ValueError(
            f"`{name}` must be a pair (low, high); got {value!r}"
        ) from None
    lo, hi = integer(lo, f"{name}[0]", minimum), integer(hi, f"{name}[1]", minimum)
    if hi < lo:
        raise ValueError(f"`{name}` must have low <= high; got {value!r}")
    return lo, hi


def _decay_range(value) -> tuple[float, float]:
    """`log_decay` checked: a pair of numbers holding a multiple of 0.5."""
    try:
        lo, hi = value
    except (TypeError, ValueError):
        raise ValueError(
            f"`log_decay` must be a pair (low, high); got {value!r}"
        ) from None
    lo, hi = real(lo, "log_decay[0]"), real(hi, "log_decay[1]")
    if math.ceil(2 * lo) > math.floor(2 * hi):
        raise ValueError(
            f"`log_decay` must hold a multiple of 0.5 (low <= high); got {value!r}"
        )
    return lo, hi


def half_decades(log_decay: tuple[float, float]) -> tuple[int, int]:
    """The grid range of a checked `log_decay`: the half decades inside it,
    as integers (``log10 decay = k / 2``)."""
    return math.ceil(2 * log_decay[0]), math.floor(2 * log_decay[1])


def _horizons(value) -> tuple[int, ...] | None:
    """`horizons` checked: None, or a non-empty sequence of integers >= 2."""
    if value is None:
        return None
    try:
        items = tuple(value)
    except TypeError:
        items = ()
    if not items:
        raise ValueError(
            f"`horizons` must be None or a non-empty sequence of integers >= 2; "
            f"got {value!r}"
        )
    for i, h in enumerate(items):
        check_horizon(h, f"horizons[{i}]")
    return tuple(int(h) for h in items)


def held_back_fit(y: np.ndarray, yhat: np.ndarray) -> float:
    """MATLAB's ``compare`` fit in percent (as ``validate``); -inf for a
    free run that diverged. `y` varies (:func:`_held_back` checks it)."""
    if not np.all(np.isfinite(yhat)):
        return -math.inf
    spread = np.linalg.norm(y - y.mean())
    return float(100.0 * (1.0 - np.linalg.norm(y - yhat) / spread))


def _held_back(data: IOData, holdback) -> tuple[IOData, np.ndarray]:
    """The training part of `data` and the held-back output, its last
    `holdback` share (checked in (0, 0.5]): at least 2 samples, and an
    output that moves (a fit is scored on it)."""
    share = real(holdback, "holdback")
    if not 0.0 < share <= 0.5:
        raise ValueError(f"`holdback` must be a number in (0, 0.5]; got {holdback!r}")
    held = round(share * data.n)
    if held < 2:
        raise ValueError(
            f"`holdback` = {share!r} holds back {held} of the {data.n} samples "
            "of `data`: too few to score a fit (at least 2); raise `holdback` "
            "or give a longer record"
        )
    split = data.n - held
    train = IOData(data.u[:split], data.y[:split], ts=data.ts)
    y_end = data.y[split:]
    if np.ptp(y_end) == 0.0:
        raise ValueError(
            f"the held-back output (the last {held} samples of `data`, "
            f"`holdback` = {share!r}) is constant, every sample {float(y_end[0])!r}: "
            "no variance to score a fit against; hold back a part where the "
            "output moves"
        )
    return train, y_end


def nearest(x, grid) -> tuple[int, ...]:
    """The grid point nearest `x`: each coordinate rounded to an integer
    and kept in its inclusive range of `grid` (one ``(low, high)`` each).

    Examples
    --------
    >>> nearest([2.6, -9.0], [(1, 8), (-10, -2)])
    (3, -9)
    >>> nearest([0.2, 4.0], [(1, 8), (-10, -2)])
    (1, -2)
    """
    x = np.asarray(x, dtype=float)
    return tuple(
        int(np.clip(np.rint(v), lo, hi)) for v, (lo, hi) in zip(x, grid, strict=True)
    )


def _run_search(
    score, grid, choice_of, *, budget: int, rule: str, n_points: int, rng
) -> tuple[dict, int, str]:
    """The spiral search over `grid` until `budget` trainings are spent.

    Parameters
    ----------
    score : callable
        ``score(choice) -> held-back fit %`` (one training).
    grid : sequence of (int, int)
        Inclusive integer range of each coordinate.
    choice_of : callable
        ``choice_of(point) -> choice`` (a hashable tuple) of a grid point;
        points of one choice are scored once.
    budget, rule, n_points, rng
        Trainings at most; the spiral rule; the first points (at least 2,
        no more than `budget`); the search's generator.

    Returns
    -------
    (dict, int, str)
        The fit of each choice trained (in order), the search's evaluations
        and the message saying what ended it.
    """
    trials: dict[tuple, float] = {}
    calls = [0]

    def cost(x: np.ndarray) -> float:
        calls[0] += 1
        key = choice_of(nearest(x, grid))
        if key not in trials:
            if len(trials) >= budget:
                raise _BudgetSpent
            trials[key] = score(key)
        return 100.0 - trials[key]

    # Half a unit beyond each end, so the end values round in as often as
    # the inner ones.
    box = np.array([[lo - 0.5, hi + 0.5] for lo, hi in grid], dtype=float)
    try:
        # Repeats cost no training, so the call cap only ends a search that
        # keeps landing on choices it has trained.
        minimize(
            cost,
            box,
            method=rule,
            # At least 2, as the search needs; a first point beyond the
            # budget ends the search (budget=1 trains the first point only).
            n_points=max(2, min(n_points, budget)),
            max_nfev=50 * budget + n_points,
            rng=rng,
            restarts=True,
        )
        message = "The search ended before the budget."
    except _BudgetSpent:
        trainings = "training" if budget == 1 else "trainings"
        message = f"The budget of {budget} {trainings} was spent."
    return trials, calls[0], message


def _choice_result(trials: dict, calls: int, message: str, t0: float, fields_of):
    """The search's result: the best choice's ``x`` and ``fit`` (``fun`` =
    ``100 - fit``), every trial as ``(*choice, fit)``, the trainings
    (``nfev``), the search's evaluations (``n_calls``), the seconds since
    `t0` (``time.perf_counter``) and ``fields_of(best choice)`` (the refit
    model among them)."""
    key, best = max(trials.items(), key=lambda kv: kv[1])
    fields = fields_of(key)
    return OptimiserResult(
        x=np.array(key, dtype=float),
        fun=100.0 - best,
        fit=best,
        trials=[(*k, f) for k, f in trials.items()],
        nfev=len(trials),
        n_calls=calls,
        nit=0,
        success=True,
        status=0,
        message=message,
        elapsed=time.perf_counter() - t0,
        **fields,
    )


@dataclass(frozen=True)
class Candidates:
    """The candidates a chooser searches over: the grid of their structures,
    how each is built and trained, and how it is judged.

    Parameters
    ----------
    grid : sequence of (int, int)
        Checked inclusive ranges of the structure's coordinates.
    structure_of : callable
        ``structure_of(*coords)`` -> the structure of a choice.
    train : callable
        ``train(record, structure, decay, horizon, rng)`` -> a fitted model
        (``horizon`` None without `horizons`).
    largest : str
        The ranges named in the message when the largest choice is too long
        for the samples before the held-back part.
    normalise : callable, optional
        ``normalise(coords)`` -> the coordinates of the choice they stand
        for (points of one choice are trained once).
    judge : callable, optional
        ``judge(data)`` -> a function ``(model) -> held-back fit %`` of a
        model trained on all of the record `data` (its own held-back
        samples): every candidate is then trained on the whole record and
        the best returned as trained, no refit; `holdback` is not used.
    """

    grid: Sequence[tuple[int, int]]
    structure_of: Callable
    train: Callable
    largest: str
    normalise: Callable | None = None
    judge: Callable | None = None


def spiral_choice(
    data: IOData,
    candidates: Candidates,
    *,
    log_decay,
    budget,
    holdback,
    rule: str,
    n_points,
    horizons,
    rng,
) -> OptimiserResult:
    """The spiral's choice of a structure and its decay (and horizon), each
    candidate trained on the first part of `data` and scored by its free run
    from rest on the held-back end; the best trained again on all of `data`.

    Parameters
    ----------
    data : IOData
        The estimation record.
    candidates : Candidates
        The structures searched, their training and judge.
    log_decay, budget, holdback, rule, n_points, horizons, rng
        The chooser's arguments (checked here).

    Returns
    -------
    OptimiserResult
        As :func:`~spiralid.sysid.choose_narx` describes: ``x`` (the
        coordinates, ``log10 decay``, then the horizon), ``fun``, ``fit``,
        ``model``, ``structure``, ``decay``, ``horizon``, ``trials``,
        ``nfev``, ``n_calls``, ``elapsed``.
    """
    t0 = time.perf_counter()
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData; got {type(data).__name__}")
    grid, structure_of, train = (
        candidates.grid,
        candidates.structure_of,
        candidates.train,
    )
    largest, normalise, judge = (
        candidates.largest,
        candidates.normalise,
        candidates.judge,
    )
    log_decay = _decay_range(log_decay)
    budget = integer(budget, "budget", 1)
    n_points = integer(n_points, "n_points", 2)
    horizons = _horizons(horizons)
    gen = generator(rng)
    if judge:
        judge, (part, y_end) = judge(data), (data, None)
    else:
        part, y_end = _held_back(data, holdback)
    # Any choice in the ranges may be trained: the largest must fit before
    # the search starts, not fail at whichever point first reaches it.
    try:
        structure_of(*(hi for _, hi in grid)).check_length(part, "data")
    except ValueError as e:
        where = (
            "" if judge else f" before the held-back part (`holdback` = {holdback!r})"
        )
        raise ValueError(
            f"{e}{where}, for the largest choice of {largest}: narrow them, "
            "lower `holdback` or give a longer record"
        ) from None
    k = len(grid)
    full = [*grid, half_decades(log_decay)]
    if horizons is not None:
        full.append((0, len(horizons) - 1))

    def choice_of(point: tuple) -> tuple:
        coords = point[:k] if normalise is None else normalise(point[:k])
        tail = () if horizons is None else (horizons[point[k + 1]],)
        return (*coords, point[k] / 2, *tail)

    def fields(key: tuple, record: IOData = data) -> dict:
        st, horizon = structure_of(*key[:k]), None if horizons is None else key[k + 1]
        model = train(record, st, 10.0 ** key[k], horizon, gen)
        return dict(model=model, structure=st, decay=10.0 ** key[k], horizon=horizon)

    kept: dict[tuple, dict] = {}

    def score(key: tuple) -> float:
        kept[key] = fields(key, part)
        if judge:
            return judge(kept[key]["model"])
        return held_back_fit(y_end, kept[key]["model"].simulate(data.u)[part.n :])

    trials, calls, message = _run_search(
        score, full, choice_of, budget=budget, rule=rule, n_points=n_points, rng=gen
    )
    # Judged on its own held-back samples, the best is already trained on
    # the whole record.
    return _choice_result(trials, calls, message, t0, kept.get if judge else fields)
