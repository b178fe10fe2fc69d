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

import numpy as np

from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ...models.neural_state_space import NeuralStateSpace
from ..core.choices import Candidates, held_back_fit, int_range, spiral_choice
from ..core.identify import identify
from .training import _hold_mask

#: ``holdback=BLOCKS``: judge each candidate on its own training's held-back
#: blocks.
BLOCKS = "blocks"
# The share the trainings hold back in blocks (identify's default).
_HOLDOUT = 0.2

__all__ = ["BLOCKS", "choose_state_space"]


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
    holdback: float | str = 0.25,
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
    log_decay, budget, rule, n_points : as in choose_narx
        The range of ``log10`` decay (searched in half decades); the
        trainings at most beside the final one (>= 1; a point that rounds
        to a choice already trained costs none); the spiral rule; the
        search's first points (>= 2), as :func:`~spiralid.sysid.choose_narx`
        has them.
    holdback : float or "blocks"
        The share of `data` held back at its end to score the candidates,
        in (0, 0.5], as in ``choose_narx``. ``"blocks"``: every candidate
        is trained on the whole record and scored by its free run from
        rest on the blocks its own training held back for early stopping
        (a fifth of the record in 10 blocks spread over it); the best is
        returned as trained, with no refit.
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
        As :func:`~spiralid.sysid.choose_narx`'s, with ``x`` = ``[n, h,
        window, log10 decay]`` (then the horizon) and one ``(n, h, window,
        log10 decay, held-back fit %)`` per training in ``trials`` (the
        horizon before the fit with `horizons`); ``model`` is the best
        choice trained on the whole record.

    Raises
    ------
    ValueError
        Before any training, in one line naming the argument (as
        ``choose_narx``); for the largest order and window too long for the
        samples before the held-back part, naming `data`.

    Examples
    --------
    A first-order lag behind a saturation, 400 samples:

    >>> import numpy as np
    >>> u = np.random.default_rng(0).standard_normal(400)
    >>> x = np.zeros(401)
    >>> for t in range(400):
    ...     x[t + 1] = 0.8 * x[t] + 0.5 * u[t]
    >>> data = IOData(u, np.tanh(x[:-1]), ts=0.01)
    >>> res = choose_state_space(data, order=(1, 2), hidden=(1, 3),
    ...                          window=(2, 4), budget=2, n_points=2,
    ...                          horizons=(50,), rng=0)
    >>> res.nfev <= 2, res.model.structure == res.structure
    (True, True)
    """
    order = int_range(order, "order", 1)
    hidden = int_range(hidden, "hidden", 1)
    window = _window_range(window, order)

    def structure(n: int, h: int, w: int) -> NeuralStateSpace:
        return NeuralStateSpace(n, hidden=(h,), window=max(w, n))

    def train(record: IOData, st: NeuralStateSpace, decay: float, horizon, gen):
        options = {} if horizon is None else {"horizon": horizon}
        return identify(
            record, st, method="oe", decay=decay, holdout=_HOLDOUT, rng=gen, **options
        )

    candidates = Candidates(
        [order, hidden, window],
        structure,
        train,
        largest="`order` and `window`",
        # A window below the order is the order's: one choice, one training.
        normalise=lambda c: (c[0], c[1], max(c[2], c[0])),
        judge=_blocks_judge if holdback == BLOCKS else None,
    )
    return spiral_choice(
        data,
        candidates,
        log_decay=log_decay,
        budget=budget,
        holdback=holdback,
        rule=rule,
        n_points=n_points,
        horizons=horizons,
        rng=rng,
    )


def _blocks_judge(data: IOData):
    """The fit % of a model's free run from rest on the blocks its training
    held back (refused in one line when the output is constant there)."""
    held = _hold_mask(data.n, _HOLDOUT)
    y = data.y[held]
    if np.ptp(y) == 0.0:
        raise ValueError(
            "`holdback` = 'blocks': the output is constant over the held-back "
            "blocks of `data`; no variance to score a fit against"
        )
    return lambda model: held_back_fit(y, model.simulate(data.u)[held])
