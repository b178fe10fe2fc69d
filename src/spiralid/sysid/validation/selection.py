"""Choosing a model from a Pareto front: every rule in one place.

A :class:`~spiralid.sysid.ParetoIdentification` offers three ways to pick
its model:

- its knee, ``front.knee`` (``front.knee_model``): where a unit of one
  objective costs most of the others, :func:`knee_point` on its objectives
  (front geometry, :func:`spiralid.optim.knee_point`, so
  :func:`~spiralid.sysid.identify_pareto` can compute it below this
  module);
- :func:`choose`: the lowest value of one objective under upper bounds on
  the others, e.g. the lowest cost whose frequency-response error is at
  most 3 dB;
- :func:`choose_order`: the lowest order that validates within a tolerance
  of the best order on a held-out record; it also chooses among fitted
  models of any structure (NARX lags and hidden sizes), by their number of
  parameters, every model validated (several may share a size).

The knee is a property of the front's shape and need not sit at the order
where a model stops improving on data it was not fitted to
(``benchmarks/pareto_identification.py`` measured it at that order in 2 of
15 runs). :func:`choose_order` asks the data instead: each order's
lowest-cost model is validated on a held-out record, and the lowest order
within ``tolerance`` points of fit of the best is chosen (the parsimony
rule of ``compare`` in MATLAB's System Identification Toolbox, applied
along the front). It validates, which is why the rules live here and not
beside :func:`~spiralid.sysid.identify_pareto` (estimation may not import
validation).
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import nonneg, one_of
from spiralid.optim.front import knee_point

from ..estimation.pareto.identify import ParetoIdentification
from ..models.protocol import is_fitted
from .validate import validate

__all__ = [
    "choose",
    "choose_order",
    "fits_by_order",
    "knee_point",
    "lowest_within",
    "validation_fits",
]


def choose(front: ParetoIdentification, minimise: str = "cost", **limits) -> int:
    """Index of the front point with the lowest `minimise` under bounds.

    Parameters
    ----------
    front : ParetoIdentification
        From :func:`~spiralid.sysid.identify_pareto`.
    minimise : str, default "cost"
        The objective to minimise, one of ``front.names``.
    **limits : float
        ``max_<objective>=bound`` for objectives in ``front.names``, e.g.
        ``choose(front, max_frequency=3.0)``: the lowest-cost model whose
        frequency-response error is at most 3 dB.

    Returns
    -------
    int
        Row index into ``front.models`` (ties: the first).
    """
    if not isinstance(front, ParetoIdentification):
        raise ValueError(
            f"`front` must be a ParetoIdentification; got {type(front).__name__}"
        )
    names = front.names
    one_of(minimise, "minimise", names)
    ok = np.ones(len(front), bool)
    for key, bound in limits.items():
        name = key.removeprefix("max_")
        if not key.startswith("max_") or name not in names:
            allowed = ", ".join(f"max_{n}" for n in names)
            raise ValueError(f"limits must be among {allowed}; got `{key}`")
        try:
            b = float(bound)
        except (TypeError, ValueError):
            b = float("nan")
        if not np.isfinite(b):
            raise ValueError(f"`{key}` must be a finite number; got {bound!r}")
        ok &= front.objectives[:, names.index(name)] <= b
    if not ok.any():
        raise ValueError(
            f"no front point meets {', '.join(f'{k}={v!r}' for k, v in limits.items())}"
        )
    column = np.where(ok, front.objectives[:, names.index(minimise)], np.inf)
    return int(np.argmin(column))


def _is_front(front) -> bool:
    """A front is anything with models and their objectives (the front's
    own type, or one built by hand); anything else should be a list of
    fitted models."""
    return hasattr(front, "models") and hasattr(front, "objectives")


def _candidates(front) -> tuple[list, np.ndarray, list[int]]:
    """The models, their estimation costs and their sizes: a Pareto front's
    (size ``na + nb``, cost its first objective), or a sequence of fitted
    models of any structure (size the number of parameters)."""
    if _is_front(front):
        if not front.models:
            raise ValueError("`front` must be a non-empty ParetoIdentification")
        sizes = [m.arx.na + m.arx.nb for m in front.models]
        return list(front.models), front.objectives[:, 0], sizes
    models = list(front) if isinstance(front, list | tuple) else None
    if not models or not all(is_fitted(m) for m in models):
        raise ValueError(
            "`front` must be a ParetoIdentification or a non-empty list of "
            f"fitted models (identify's results); got {type(front).__name__}"
        )
    return models, np.array([m.cost for m in models]), [m.params.size for m in models]


def validation_fits(front, data, *, warmup=None) -> list[tuple[int, int, float]]:
    """Every candidate's size and validation fit: what :func:`choose_order`
    chooses among.

    Parameters
    ----------
    front : ParetoIdentification or list of fitted models
        From :func:`~spiralid.sysid.identify_pareto`, or models of any
        structures (e.g. NARX models of several lags and hidden sizes, each
        from :func:`~spiralid.sysid.identify`).
    data : IOData
        A record the models were not estimated on (the validation third).
    warmup : IOData, optional
        The record before `data` (the estimation part), run first so the
        models start from its end, as :func:`validate` does.

    Returns
    -------
    list of (int, int, float)
        ``(size, index into the models, fit %)``, by increasing size, then
        index. On a front the candidates are each order's lowest-cost model
        (size ``na + nb``, cost its first objective: the front's other
        models of that order trade cost for its other objectives); in a
        list every model is one (size: its number of parameters), however
        many share a size.
    """
    models, cost, sizes = _candidates(front)
    if _is_front(front):
        best: dict[int, int] = {}
        for i, order in enumerate(sizes):
            if order not in best or cost[i] < cost[best[order]]:
                best[order] = i
        picked = sorted((order, i) for order, i in best.items())
    else:
        picked = sorted((size, i) for i, size in enumerate(sizes))
    return [
        (size, i, validate(models[i], data, warmup=warmup).fit_percent)
        for size, i in picked
    ]


def fits_by_order(front, data, *, warmup=None) -> dict[int, tuple[int, float]]:
    """Each order's candidate and its validation fit, keyed by order.

    Parameters
    ----------
    front : ParetoIdentification or list of fitted models
        As in :func:`validation_fits`; a list whose models all differ in
        size (the number of parameters), as one size keys one fit.
    data : IOData
        A record the models were not estimated on (the validation third).
    warmup : IOData, optional
        The record before `data` (the estimation part), run first so the
        models start from its end, as :func:`validate` does.

    Returns
    -------
    dict
        ``{order: (index into the models, fit %)}``, by increasing order:
        ``na + nb`` on a front (its lowest-cost model of that order), the
        number of parameters for a list.

    Raises
    ------
    ValueError
        For a list with two models of one size: a dict keyed by size would
        drop all but one, unvalidated. :func:`validation_fits` lists every
        model.
    """
    if not _is_front(front):
        _, _, sizes = _candidates(front)
        for size in sorted(set(sizes)):
            shared = [i for i, s in enumerate(sizes) if s == size]
            if len(shared) > 1:
                raise ValueError(
                    f"`front` holds {len(shared)} models of {size} parameters "
                    f"(at {', '.join(map(str, shared))}): fits_by_order keys "
                    "one fit per size; validation_fits gives every model's"
                )
    return {
        size: (i, fit) for size, i, fit in validation_fits(front, data, warmup=warmup)
    }


def choose_order(front, data, *, warmup=None, tolerance: float = 1.0) -> int:
    """Index of the lowest order's model whose held-out fit is within
    `tolerance` points of the best order's.

    Parameters
    ----------
    front : ParetoIdentification or list of fitted models
        From :func:`~spiralid.sysid.identify_pareto` (orders ``na + nb``,
        each order's lowest-cost model validated), or fitted models of any
        structures, e.g. NARX models of several lags and hidden sizes
        (order: the number of parameters; every model validated, and of
        several of the chosen size, the best-fitting taken).
    data : IOData
        A record the models were not estimated on. The chosen model's fit on
        that same record is then optimistic (it was chosen on it); validate
        on a third record for an unbiased figure.
    warmup : IOData, optional
        The record before `data`, as in :func:`validate`.
    tolerance : float, default 1.0
        Percentage points of fit a lower order may lose to the best.

    Returns
    -------
    int
        Index into ``front.models`` (or into the list).

    Examples
    --------
    >>> import spiralid as sid
    >>> est, val = sid.datasets.robot_arm().split(2 / 3)
    >>> front = sid.identify_pareto(est, range(2, 6), rng=0, max_nfev=600,
    ...                             n_points=12)
    >>> model = front.models[choose_order(front, val, warmup=est)]
    >>> model.arx.na in range(2, 6)
    True

    NARX lags and hidden sizes, each model fitted on the estimation part:

    >>> models = [sid.identify(est, sid.NARX(n, n, 1, hidden=(h,)), rng=0,
    ...                        method="ls")
    ...           for n in (2, 4) for h in (2, 6)]
    >>> best = models[choose_order(models, val, warmup=est)]
    >>> best.structure.ny in (2, 4)
    True
    """
    tolerance = nonneg(tolerance, "tolerance")
    return lowest_within(validation_fits(front, data, warmup=warmup), tolerance)


def lowest_within(fits, tolerance: float) -> int:
    """:func:`choose_order`'s rule on fits already computed: the index of
    the smallest candidate whose fit is within `tolerance` points of the
    best, and of candidates of that size, the best-fitting.

    Parameters
    ----------
    fits : list of (int, int, float) or dict
        :func:`validation_fits`'s ``(size, index, fit %)`` for every
        candidate, or :func:`fits_by_order`'s ``{order: (index, fit %)}``.
    tolerance : float
        Percentage points of fit a smaller candidate may lose to the best.

    Returns
    -------
    int
        The chosen model's index (ties: the first listed).

    Examples
    --------
    Sizes 10, 10 and 20: the second model is within 1 point of the best and
    fits better than the first of its size.

    >>> lowest_within([(10, 0, 80.0), (10, 1, 89.5), (20, 2, 90.0)], 1.0)
    1
    >>> lowest_within([(10, 0, 80.0), (10, 1, 89.5), (20, 2, 90.0)], 0.0)
    2
    """
    tolerance = nonneg(tolerance, "tolerance")
    if isinstance(fits, dict):
        fits = [(size, i, fit) for size, (i, fit) in fits.items()]
    fits = list(fits)
    scored = [(size, i, fit) for size, i, fit in fits if not np.isnan(fit)]
    if not scored:
        raise ValueError(
            "`fits` must hold at least one candidate whose fit is a number; "
            f"got {len(fits)} candidate(s), none"
        )
    top = max(fit for _, _, fit in scored)
    within = [c for c in scored if c[2] >= top - tolerance]
    size = min(c[0] for c in within)
    # max keeps the first of equal fits.
    return max((c for c in within if c[0] == size), key=lambda c: c[2])[1]
