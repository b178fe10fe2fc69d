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

import numpy as np

from spiralid._checks import integer, real
from spiralid.optim import minimize
from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ..narx.subsequences import check_horizon

__all__ = [
    "choice_result",
    "decay_range",
    "half_decades",
    "held_back",
    "held_back_fit",
    "horizons_checked",
    "int_range",
    "nearest",
    "run_search",
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


def decay_range(value) -> tuple[float, float]:
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


def horizons_checked(value) -> tuple[int, ...] | None:
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
    free run that diverged. `y` varies (:func:`held_back` checks it)."""
    if not np.all(np.isfinite(yhat)):
        return -math.inf
    spread = np.linalg.norm(y - y.mean())
    return float(100.0 * (1.0 - np.linalg.norm(y - yhat) / spread))


def held_back(data: IOData, holdback) -> tuple[IOData, np.ndarray]:
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


def run_search(
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


def choice_result(trials: dict, calls: int, message: str, t0: float, fields_of):
    """The search's result: the best choice's ``x`` and ``fit`` (``fun`` =
    ``100 - fit``), every trial as ``(*choice, fit)``, the trainings
    (``nfev``), the search's evaluations (``n_calls``), the seconds since
    `t0` (``time.perf_counter``) and ``fields_of(best choice)``, the
    caller's fields (its refit model among them)."""
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
