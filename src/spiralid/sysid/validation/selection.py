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
  parameters.

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

from ..estimation.pareto import ParetoIdentification
from ..models.fitted import FittedModel
from .validate import validate

__all__ = ["choose", "choose_order", "fits_by_order", "knee_point", "lowest_within"]


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


def _candidates(front) -> tuple[list, np.ndarray, list[int]]:
    """The models, their estimation costs and their sizes: a Pareto front's
    (size ``na + nb``, cost its first objective), or a sequence of fitted
    models of any structure (size the number of parameters)."""
    # A front is anything with models and their objectives (the front's
    # own type, or one built by hand).
    if hasattr(front, "models") and hasattr(front, "objectives"):
        if not front.models:
            raise ValueError("`front` must be a non-empty ParetoIdentification")
        sizes = [m.arx.na + m.arx.nb for m in front.models]
        return list(front.models), front.objectives[:, 0], sizes
    models = list(front) if isinstance(front, list | tuple) else None
    if not models or not all(isinstance(m, FittedModel) for m in models):
        raise ValueError(
            "`front` must be a ParetoIdentification or a non-empty list of "
            f"fitted models (identify's results); got {type(front).__name__}"
        )
    return models, np.array([m.cost for m in models]), [m.params.size for m in models]


def fits_by_order(front, data, *, warmup=None) -> dict[int, tuple[int, float]]:
    """Each order's lowest-cost model and its validation fit.

    Parameters
    ----------
    front : ParetoIdentification or list of FittedModel
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
    dict
        ``{order: (index into the models, fit %)}``, by increasing order:
        ``na + nb`` on a front (where "lowest cost" is its first
        objective), the number of parameters for a list (lowest
        estimation cost among models of equal size).
    """
    models, cost, sizes = _candidates(front)
    best: dict[int, int] = {}
    for i, order in enumerate(sizes):
        if order not in best or cost[i] < cost[best[order]]:
            best[order] = i
    return {
        order: (i, validate(models[i], data, warmup=warmup).fit_percent)
        for order, i in sorted(best.items())
    }


def choose_order(front, data, *, warmup=None, tolerance: float = 1.0) -> int:
    """Index of the lowest order's model whose held-out fit is within
    `tolerance` points of the best order's.

    Parameters
    ----------
    front : ParetoIdentification or list of FittedModel
        From :func:`~spiralid.sysid.identify_pareto` (orders ``na + nb``),
        or fitted models of any structures, e.g. NARX models of several
        lags and hidden sizes (order: the number of parameters).
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
    return lowest_within(fits_by_order(front, data, warmup=warmup), tolerance)


def lowest_within(fits: dict[int, tuple[int, float]], tolerance: float) -> int:
    """:func:`choose_order`'s rule on fits already computed: the index of
    the lowest order whose fit is within `tolerance` points of the best.

    Parameters
    ----------
    fits : dict
        :func:`fits_by_order`'s ``{order: (index, fit %)}``, by increasing
        order.
    tolerance : float
        Percentage points of fit a lower order may lose to the best.

    Returns
    -------
    int
        The chosen model's index.
    """
    tolerance = nonneg(tolerance, "tolerance")
    top = np.nanmax([fit for _, fit in fits.values()])
    return next(i for i, fit in fits.values() if fit >= top - tolerance)
