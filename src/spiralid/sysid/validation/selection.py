"""Choosing a model order from a Pareto front by held-out fit.

The knee of :class:`~spiralid.sysid.ParetoIdentification` is a property of
the front's shape and need not sit at the order where a model stops
improving on data it was not fitted to (``benchmarks/pareto_identification.py``
measured it at that order in 2 of 15 runs). :func:`choose_order` asks the data
instead: each order's lowest-cost model is validated on a held-out record,
and the lowest order within ``tolerance`` points of fit of the best is
chosen (the parsimony rule of ``compare`` in MATLAB's System
Identification Toolbox, applied along the front).
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import nonneg

from .validate import validate

__all__ = ["choose_order", "fits_by_order"]


def fits_by_order(front, data, *, warmup=None) -> dict[int, tuple[int, float]]:
    """Each order's lowest-cost model on the front and its validation fit.

    Parameters
    ----------
    front : ParetoIdentification
        From :func:`~spiralid.sysid.identify_pareto`.
    data : IOData
        A record the models were not estimated on (the validation third).
    warmup : IOData, optional
        The record before `data` (the estimation part), run first so the
        models start from its end, as :func:`validate` does.

    Returns
    -------
    dict
        ``{na + nb: (index into front.models, fit %)}``, by increasing order.
        "Lowest cost" is the front's first objective.
    """
    if not getattr(front, "models", None):
        raise ValueError("`front` must be a non-empty ParetoIdentification")
    cost = front.objectives[:, 0]
    best: dict[int, int] = {}
    for i, model in enumerate(front.models):
        order = model.arx.na + model.arx.nb
        if order not in best or cost[i] < cost[best[order]]:
            best[order] = i
    return {
        order: (i, validate(front.models[i], data, warmup=warmup).fit_percent)
        for order, i in sorted(best.items())
    }


def choose_order(front, data, *, warmup=None, tolerance: float = 1.0) -> int:
    """Index of the lowest order's model whose held-out fit is within
    `tolerance` points of the best order's.

    Parameters
    ----------
    front : ParetoIdentification
        From :func:`~spiralid.sysid.identify_pareto`.
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
        Index into ``front.models``.

    Examples
    --------
    >>> import spiralid as sid
    >>> est, val = sid.datasets.robot_arm().split(2 / 3)
    >>> front = sid.identify_pareto(est, range(2, 6), rng=0, max_nfev=600,
    ...                             n_points=12)
    >>> model = front.models[choose_order(front, val, warmup=est)]
    >>> model.arx.na in range(2, 6)
    True
    """
    tolerance = nonneg(tolerance, "tolerance")
    fits = fits_by_order(front, data, warmup=warmup)
    top = np.nanmax([fit for _, fit in fits.values()])
    return next(i for i, fit in fits.values() if fit >= top - tolerance)
