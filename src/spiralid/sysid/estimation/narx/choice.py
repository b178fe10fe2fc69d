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
is compared with a grid of the same number of trainings.

Measured (docs/results/narx.md, ``benchmarks/narx_spiral.py``): on the
nonlinear rig the search gains 14-16 points of validation fit over the
default ``NARX(4, 4, 1)``, mostly by choosing more lags, but a random search
of the same budget does as well: with a dozen trainings in three
coordinates the spiral rule has little to learn from.
"""

from __future__ import annotations

import math
import time

import numpy as np

from spiralid._checks import generator, integer, real
from spiralid.optim import minimize
from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ...models.narx import NARX
from ..core.identify import identify
from .subsequences import check_horizon

__all__ = ["choose_narx", "round_choice"]


class _BudgetSpent(Exception):
    """A new training was asked for after the last one the budget allows."""


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
    x = np.asarray(x, dtype=float)
    n = int(np.clip(np.rint(x[0]), lags[0], lags[1]))
    h = int(np.clip(np.rint(x[1]), hidden[0], hidden[1]))
    lo, hi = math.ceil(2 * log_decay[0]), math.floor(2 * log_decay[1])
    d = int(np.clip(np.rint(x[2]), lo, hi)) / 2
    return n, h, d


def _range(value, name: str, minimum: int) -> tuple[int, int]:
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


def _held_back_fit(y: np.ndarray, yhat: np.ndarray) -> float:
    """MATLAB's ``compare`` fit in percent (as ``validate``); -inf for a
    free run that diverged. `y` varies (choose_narx checks it)."""
    if not np.all(np.isfinite(yhat)):
        return -math.inf
    spread = np.linalg.norm(y - y.mean())
    return float(100.0 * (1.0 - np.linalg.norm(y - yhat) / spread))


def _held_back(data: IOData, share: float) -> tuple[IOData, np.ndarray]:
    """The training part of `data` and the held-back output, its last
    `share`: at least 2 samples, and an output that moves (a fit is scored
    on it)."""
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


def _search(cost, ranges, rule, n_points: int, budget: int, gen) -> str:
    """The spiral search of `cost` over the `ranges` (lags, hidden units,
    log10 decay) until `budget` trainings are spent; the message saying
    what ended it."""
    lags, hidden, log_decay, horizons = ranges
    # Half a unit beyond each end, so the end values round in as often as
    # the inner ones.
    rows = [
        [lags[0] - 0.5, lags[1] + 0.5],
        [hidden[0] - 0.5, hidden[1] + 0.5],
        [math.ceil(2 * log_decay[0]) - 0.5, math.floor(2 * log_decay[1]) + 0.5],
    ]
    if horizons is not None:
        rows.append([-0.5, len(horizons) - 0.5])
    box = np.array(rows)
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
            rng=gen,
            restarts=True,
        )
    except _BudgetSpent:
        trainings = "training" if budget == 1 else "trainings"
        return f"The budget of {budget} {trainings} was spent."
    return "The search ended before the budget."


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
    t0 = time.perf_counter()
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData; got {type(data).__name__}")
    nk = integer(nk, "nk", 0)
    lags = _range(lags, "lags", 1)
    hidden = _range(hidden, "hidden", 1)
    log_decay = _decay_range(log_decay)
    budget = integer(budget, "budget", 1)
    n_points = integer(n_points, "n_points", 2)
    integrator = integer(integrator, "integrator", 0)
    share = real(holdback, "holdback")
    if not 0.0 < share <= 0.5:
        raise ValueError(f"`holdback` must be a number in (0, 0.5]; got {holdback!r}")
    horizons = _horizons(horizons)
    gen = generator(rng)
    train, y_end = _held_back(data, share)
    split = train.n

    def structure(n: int, h: int) -> NARX:
        return NARX(n, n, nk, hidden=(h,), integrator=integrator)

    # Any choice in the ranges may be trained: the largest must fit before
    # the search starts, not fail at whichever point first reaches it.
    try:
        structure(lags[1], hidden[1]).check_length(train, "data")
    except ValueError as e:
        raise ValueError(
            f"{e} before the held-back part (`holdback` = {share!r}), for the "
            "largest choice of `lags` and `hidden`: narrow them, lower "
            "`holdback` or give a longer record"
        ) from None

    trials: dict[tuple, float] = {}
    calls = [0]

    def key_of(x: np.ndarray) -> tuple:
        key = round_choice(x, lags, hidden, log_decay)
        if horizons is None:
            return key
        i = int(np.clip(np.rint(x[3]), 0, len(horizons) - 1))
        return (*key, horizons[i])

    def fit(record: IOData, key: tuple):
        n, h, d = key[:3]
        training = {} if horizons is None else {"training": "subsequences"}
        if horizons is not None:
            training["horizon"] = key[3]
        return identify(
            record, structure(n, h), method="oe", decay=10.0**d, rng=gen, **training
        )

    def cost(x: np.ndarray) -> float:
        calls[0] += 1
        key = key_of(x)
        if key not in trials:
            if len(trials) >= budget:
                raise _BudgetSpent
            model = fit(train, key)
            trials[key] = _held_back_fit(y_end, model.simulate(data.u)[split:])
        return 100.0 - trials[key]

    ranges = (lags, hidden, log_decay, horizons)
    message = _search(cost, ranges, rule, n_points, budget, gen)
    key, best = max(trials.items(), key=lambda kv: kv[1])
    n, h, d = key[:3]
    model = fit(data, key)
    return OptimiserResult(
        x=np.array(key, dtype=float),
        fun=100.0 - best,
        fit=best,
        model=model,
        structure=structure(n, h),
        decay=10.0**d,
        horizon=None if horizons is None else key[3],
        trials=[(*key, f) for key, f in trials.items()],
        nfev=len(trials),
        n_calls=calls[0],
        nit=0,
        success=True,
        status=0,
        message=message,
        elapsed=time.perf_counter() - t0,
    )
