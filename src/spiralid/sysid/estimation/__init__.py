"""Estimation: from a record and a structure to a fitted model, grouped by
concern.

- :mod:`.core`: :func:`~spiralid.sysid.identify` and its option contract,
  the estimator table ``METHODS``, the problem every estimator takes and the
  result it returns, the paper's cost (eq. 2) and the covariance of an
  estimate.
- :mod:`.linear`: the local methods of an ARX model and the spaces a search
  moves in: parametrisations, the modal map, the stability margin,
  Levenberg-Marquardt with a projection, output error, variable projection
  and the frequency objective.
- :mod:`.spiral`: the spiral methods over an ARX model: the paper's
  population searches, ``method="spiral"`` with its projected spiral, and
  what it does after the search (held-back choice, margin choice,
  cancellation, acting on the modes table).
- :mod:`.narx`: training NARX models, choosing their lags, units and decay.
- :mod:`.shared`: several outputs with one denominator, and the subspace
  estimate of their poles.
- :mod:`.pareto`: :func:`~spiralid.sysid.identify_pareto`, its search and
  its options.
"""
