"""A spiral search over the choices a NARX user struggles with: the lags,
the hidden units and the weight decay, and with training on subsequences
their length.

:func:`choose_narx` runs :func:`spiralid.optim.minimize` over three
integer-rounded coordinates (lags ``n``, hidden units ``h``, and the
weight decay's exponent in half decades). Each new point trains
``NARX(n, n, nk, hidden=(h,))`` by gradient training (``identify``'s
``"oe"``: Levenberg-Marquardt with early stopping) on the first part of
the estimation record and scores its free run, over the whole record from
rest, on the held-back end. The search never sees a validation record. The
best point is then trained again on the whole estimation record.

Points that round to a structure already trained are not trained again:
``budget`` counts trainings, not the search's evaluations, so the search
is compared with a grid of the same number of trainings. The search
itself, the checks of the ranges and the held-back split are
:mod:`~spiralid.sysid.estimation.core.choices`, which
:func:`~spiralid.sysid.choose_state_space` shares.

Measured (docs/results/narx.md, ``benchmarks/narx_spiral.py``): on the
nonlinear rig the search gains 14-16 points of validation fit over the
default ``NARX(4, 4, 1)``, mostly by choosing more lags, but a random search
of the same budget does as well: with a dozen trainings in three
coordinates the spiral rule has little to learn from.
"""

from __future__ import annotations

from spiralid._checks import integer
from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ...models.narx import NARX
from ..core.choices import (
    Candidates,
    half_decades,
    int_range,
    nearest,
    spiral_choice,
)
from ..core.identify import identify

__all__ = ["choose_narx", "round_choice"]


def round_choice(x, lags, hidden, log_decay) -> tuple[int, int, float]:
    """The NARX choice a search point stands for.

    Parameters
    ----------
    x : array_like, shape (3,)
        Lags, hidden units and the decay's exponent in half decades
        (``log10(decay) = x[2] / 2``), as the search moves them.
    lags, hidden : (int, int)
        Inclusive ranges of the lags and hidden units.
    log_decay : (float, float)
        Inclusive range of ``log10(decay)``.

    Returns
    -------
    (int, int, float)
        ``(n, h, log10 decay)``: each coordinate rounded to the nearest
        integer (half decades for the decay) and kept in its range.

    Examples
    --------
    >>> round_choice([2.6, 7.4, -5.6], (1, 8), (1, 16), (-5, -1))
    (3, 7, -3.0)
    >>> round_choice([0.2, 20.0, 0.4], (1, 8), (1, 16), (-5, -1))
    (1, 16, -1.0)
    """
    n, h, k = nearest(list(x)[:3], [lags, hidden, half_decades(log_decay)])
    return n, h, k / 2


def choose_narx(
    data: IOData,
    *,
    nk: int = 1,
    lags: tuple[int, int] = (1, 8),
    hidden: tuple[int, int] = (1, 16),
    log_decay: tuple[float, float] = (-5.0, -1.0),
    budget: int = 12,
    holdback: float = 0.25,
    rule: str = "learned-metric",
    n_points: int = 6,
    integrator: int = 0,
    horizons: tuple[int, ...] | None = None,
    rng=None,
) -> OptimiserResult:
    """Choose a NARX's lags, hidden units and weight decay by a spiral
    search, scoring each gradient-trained candidate on held-back data.

    Parameters
    ----------
    data : IOData
        Estimation record (single output). Its last `holdback` share scores
        the candidates; the model returned is trained on all of it.
    nk : int
        Input delay of every candidate.
    lags : (int, int)
        Inclusive range of the lags ``n`` (``ny = nu = n``).
    hidden : (int, int)
        Inclusive range of the hidden units ``h``.
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
    integrator : int
        Integrators of every candidate (``NARX(..., integrator=...)``).
    horizons : sequence of int, optional
        Train every candidate on subsequences (``identify``'s
        ``training="subsequences"``) and search their length among these
        (each >= 2) as a fourth coordinate, an index into them rounded to
        the nearest. None (default): free-run training, three coordinates.
    rng : int, Generator or None
        Randomness of the search and of the trainings.

    Returns
    -------
    OptimiserResult
        ``model`` (the best choice trained on the whole record),
        ``structure``, ``decay``, ``horizon`` (None without `horizons`),
        ``x`` (``[n, h, log10 decay]``, then the horizon), ``fun``
        (the best held-back fit's shortfall, ``100 - fit``), ``fit``,
        ``trials`` (one ``(n, h, log10 decay, held-back fit %)`` per
        training, in order; with `horizons`, the horizon before the fit),
        ``nfev`` (trainings, the final one excluded),
        ``n_calls`` (the search's evaluations, repeats included),
        ``elapsed``.

    Raises
    ------
    ValueError
        Before any training, for an argument out of its range, a held-back
        part of fewer than 2 samples or with a constant output (no fit can
        be scored on it), or ranges whose largest choice,
        ``NARX(lags[1], lags[1], nk, hidden=(hidden[1],))``, is too large
        for the samples before the held-back part.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(400)
    >>> y = np.tanh(lfilter([0.0, 0.5], [1.0, -0.8], u))
    >>> res = choose_narx(IOData(u, y, ts=0.01), lags=(1, 2), hidden=(1, 3),
    ...                   budget=3, n_points=3, rng=0)
    >>> res.nfev <= 3, res.model.structure == res.structure
    (True, True)
    """
    nk = integer(nk, "nk", 0)
    lags = int_range(lags, "lags", 1)
    hidden = int_range(hidden, "hidden", 1)
    integrator = integer(integrator, "integrator", 0)

    def structure(n: int, h: int) -> NARX:
        return NARX(n, n, nk, hidden=(h,), integrator=integrator)

    def train(record: IOData, st: NARX, decay: float, horizon, gen):
        training = {} if horizon is None else {"training": "subsequences"}
        if horizon is not None:
            training["horizon"] = horizon
        return identify(record, st, method="oe", decay=decay, rng=gen, **training)

    return spiral_choice(
        data,
        Candidates([lags, hidden], structure, train, largest="`lags` and `hidden`"),
        log_decay=log_decay,
        budget=budget,
        holdback=holdback,
        rule=rule,
        n_points=n_points,
        horizons=horizons,
        rng=rng,
    )
