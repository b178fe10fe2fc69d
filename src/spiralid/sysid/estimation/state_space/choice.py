"""A spiral search over a neural state space's size: its state order, hidden
units, encoder window and weight decay, and optionally the subsequence
length.

:func:`choose_state_space` runs :func:`spiralid.optim.minimize` over four
integer-rounded coordinates (order ``n``, hidden units ``h``, window
``w``, the decay's exponent in half decades; a fifth, an index into
`horizons`, when given). Each new point trains
``NeuralStateSpace(n, hidden=(h,), window=max(w, n))`` as ``identify(...,
method="oe")`` trains it (linear start, subsequences, early stopping on
held-back blocks of its own record) on the first part of the estimation
record, and scores its free run from rest, over the whole record, on the
held-back end. The search never sees a validation record. The best point
is then trained again on the whole estimation record.

The search, the range checks and the held-back split are
:mod:`~spiralid.sysid.estimation.core.choices`, shared with
:func:`~spiralid.sysid.choose_narx`: ``budget`` counts trainings, and
points that round to a choice already trained cost none.
"""

from __future__ import annotations

import time

from spiralid._checks import generator, integer
from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ...models.neural_state_space import NeuralStateSpace
from ..core.choices import (
    choice_result,
    decay_range,
    half_decades,
    held_back,
    held_back_fit,
    horizons_checked,
    int_range,
    run_search,
)
from ..core.identify import identify

__all__ = ["choose_state_space"]


def _window_range(window, order: tuple[int, int]) -> tuple[int, int]:
    """`window` checked: a range of integers >= 1 reaching the smallest
    order (below the order a candidate's window is its order, so a range
    wholly below every order would never be used)."""
    window = int_range(window, "window", 1)
    if window[1] < order[0]:
        raise ValueError(
            f"`window` must reach the smallest order, {order[0]} (a window "
            f"below the order is raised to it); got {window!r}"
        )
    return window


def choose_state_space(
    data: IOData,
    *,
    order: tuple[int, int] = (1, 6),
    hidden: tuple[int, int] = (2, 16),
    window: tuple[int, int] = (2, 16),
    log_decay: tuple[float, float] = (-5.0, -1.0),
    budget: int = 8,
    holdback: float = 0.25,
    rule: str = "learned-metric",
    n_points: int = 6,
    horizons: tuple[int, ...] | None = None,
    rng=None,
) -> OptimiserResult:
    """Choose a neural state space's order, hidden units, encoder window and
    weight decay by a spiral search, scoring each trained candidate on
    held-back data.

    Parameters
    ----------
    data : IOData
        Estimation record (one input, one output). Its last `holdback`
        share scores the candidates; the model returned is trained on all
        of it.
    order : (int, int)
        Inclusive range of the state order ``n`` (>= 1).
    hidden : (int, int)
        Inclusive range of the hidden units ``h`` of each network (>= 1).
    window : (int, int)
        Inclusive range of the encoder's window ``w`` (>= 1); a candidate's
        window is ``max(w, n)``, as the encoder needs at least ``n``
        samples, so the range must reach ``order[0]``.
    log_decay : (float, float)
        Inclusive range of ``log10`` of the weight decay, searched in steps
        of 0.5.
    budget : int
        Trainings at most in the search, 1 or more (a point that rounds to a
        choice already trained costs none), beside the final one. With 1,
        the choice is the search's first point, uniform in the ranges.
    holdback : float
        Share of `data` held back to score the candidates, in (0, 0.5]; it
        must hold at least 2 samples, and the output must vary over them.
    rule : str
        The spiral rule of :func:`spiralid.optim.minimize`.
    n_points : int
        The search's uniform first points, 2 or more (no more than `budget`
        are drawn, but never fewer than 2).
    horizons : sequence of int, optional
        Train every candidate on subsequences of one fixed length
        (``identify``'s ``horizon``) and search it among these (each >= 2)
        as a fifth coordinate, an index into them rounded to the nearest.
        None (default): the family's growing lengths (50, 100, 200).
    rng : int, Generator or None
        Randomness of the search and of the trainings.

    Returns
    -------
    OptimiserResult
        ``model`` (the best choice trained on the whole record),
        ``structure``, ``decay``, ``horizon`` (None without `horizons`),
        ``x`` (``[n, h, window, log10 decay]``, then the horizon), ``fun``
        (the best held-back fit's shortfall, ``100 - fit``), ``fit``,
        ``trials`` (one ``(n, h, window, log10 decay, held-back fit %)``
        per training, in order; with `horizons`, the horizon before the
        fit), ``nfev`` (trainings, the final one excluded), ``n_calls``
        (the search's evaluations, repeats included), ``elapsed``.

    Raises
    ------
    ValueError
        Before any training, for an argument out of its range, a held-back
        part of fewer than 2 samples or with a constant output, or ranges
        whose largest choice is too long for the samples before the
        held-back part.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(400)
    >>> y = np.tanh(lfilter([0.0, 0.5], [1.0, -0.8], u))
    >>> res = choose_state_space(IOData(u, y, ts=0.01), order=(1, 2),
    ...                          hidden=(1, 3), window=(2, 4), budget=2,
    ...                          n_points=2, horizons=(50,), rng=0)
    >>> res.nfev <= 2, res.model.structure == res.structure
    (True, True)
    """
    t0 = time.perf_counter()
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData; got {type(data).__name__}")
    order = int_range(order, "order", 1)
    hidden = int_range(hidden, "hidden", 1)
    window = _window_range(window, order)
    log_decay = decay_range(log_decay)
    budget = integer(budget, "budget", 1)
    n_points = integer(n_points, "n_points", 2)
    horizons = horizons_checked(horizons)
    gen = generator(rng)
    train, y_end = held_back(data, holdback)
    split = train.n

    def structure(n: int, h: int, w: int) -> NeuralStateSpace:
        return NeuralStateSpace(n, hidden=(h,), window=max(w, n))

    # The longest window (and the largest order) must fit before the search
    # starts, not fail at whichever point first reaches it.
    try:
        structure(order[1], hidden[1], window[1]).check_length(train, "data")
    except ValueError as e:
        raise ValueError(
            f"{e} before the held-back part (`holdback` = {holdback!r}), for the "
            "largest choice of `order` and `window`: narrow them, lower "
            "`holdback` or give a longer record"
        ) from None

    grid = [order, hidden, window, half_decades(log_decay)]
    if horizons is not None:
        grid.append((0, len(horizons) - 1))

    def choice_of(point: tuple) -> tuple:
        n, h, w, k = point[:4]
        key = (n, h, max(w, n), k / 2)
        return key + (() if horizons is None else (horizons[point[4]],))

    def fit(record: IOData, key: tuple):
        n, h, w, d = key[:4]
        options = {} if horizons is None else {"horizon": key[4]}
        return identify(
            record, structure(n, h, w), method="oe", decay=10.0**d, rng=gen, **options
        )

    def score(key: tuple) -> float:
        return held_back_fit(y_end, fit(train, key).simulate(data.u)[split:])

    trials, calls, message = run_search(
        score, grid, choice_of, budget=budget, rule=rule, n_points=n_points, rng=gen
    )

    def refit(key: tuple) -> dict:
        n, h, w, d = key[:4]
        return dict(
            model=fit(data, key),
            structure=structure(n, h, w),
            decay=10.0**d,
            horizon=None if horizons is None else key[4],
        )

    return choice_result(trials, calls, message, t0, refit)
