"""The grey-box family's methods, one entry each in the estimator table
(:data:`~spiralid.sysid.estimation.core.families.ESTIMATORS`):

- ``"spiral"`` (default): the learned-metric spiral
  (:func:`spiralid.optim.minimize` with ``method="learned-metric"``) over
  the free parameters in their unit box (log-scaled where a parameter has a
  log scale), seeded with the initial values, then Levenberg-Marquardt on
  the simulation error from the best point, projected into the box;
- ``"oe"``: that Levenberg-Marquardt alone, from the initial values;
- ``"sda"``, ``"ebsda"``: the paper's spiral searches over the same box and
  cost, as printed (no polish).

Every method ends with the Jacobian at its result, from which the
parameters' intervals come (:mod:`.intervals`).
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import integer
from spiralid.optim import minimize

from ...data import IOData
from ...models.greybox import GreyBox
from ...models.greybox_model import GreyBoxModel, LinearGreyBoxModel
from ..linear.levenberg import levenberg_marquardt
from .intervals import parameter_intervals
from .problem import GreyBoxProblem

__all__ = ["GREYBOX_METHODS", "fit_greybox"]

_COMMON = ("rng", "gain", "penalty")
#: method -> the options it takes beside identify's common ones.
GREYBOX_METHODS: dict[str, tuple[str, ...]] = {
    "spiral": (*_COMMON, "n_points", "max_nfev", "polish_nfev"),
    "oe": (*_COMMON, "polish_nfev"),
    "sda": (*_COMMON, "n_points", "max_nfev"),
    "ebsda": (*_COMMON, "n_points", "max_nfev"),
}
# Searches' default population and budget (simulations), and the polish's.
_N_POINTS = 20
_MAX_NFEV = 1000
_POLISH_NFEV = 200
_RULES = {"spiral": "learned-metric", "sda": "sda", "ebsda": "ebsda"}


def _polish(problem: GreyBoxProblem, z0: np.ndarray, max_nfev: int) -> np.ndarray:
    """Levenberg-Marquardt on the simulation error from `z0`, trial points
    clipped into the unit box."""
    result = levenberg_marquardt(
        problem.residual,
        problem.jacobian,
        z0,
        project=lambda z: np.clip(z, 0.0, 1.0),
        max_nfev=max_nfev,
    )
    return np.asarray(result.x, dtype=float)


def fit_greybox(data: IOData, structure: GreyBox, method: str, given: dict):
    """The grey box `structure` fitted to `data` by `method` (a key of
    :data:`GREYBOX_METHODS`), `given` identify's arguments by name.

    Returns
    -------
    GreyBoxModel or LinearGreyBoxModel
        As the structure's kind.
    """
    problem = GreyBoxProblem(
        data,
        structure,
        gain=given.get("gain", "auto"),
        penalty=given.get("penalty", 1e6),
    )
    polish_nfev = integer(given.get("polish_nfev", _POLISH_NFEV), "polish_nfev", 1)
    z = problem.z0
    if method in _RULES:
        n_points = integer(given.get("n_points", _N_POINTS), "n_points", 2)
        budget = integer(given.get("max_nfev", _MAX_NFEV), "max_nfev", n_points)
        found = minimize(
            problem,
            np.tile([0.0, 1.0], (problem.n_free, 1)),
            method=_RULES[method],
            n_points=n_points,
            max_nfev=budget,
            rng=given.get("rng"),
            x0=problem.z0,
        )
        # The point the cost evaluated (see GreyBoxProblem.values).
        z = np.clip(np.asarray(found.x, dtype=float), 0.0, 1.0)
    if method in ("spiral", "oe"):
        polished = _polish(problem, z, polish_nfev)
        if problem(polished) <= problem(z):
            z = polished
    residual = problem.residual(z)
    jac = problem.jacobian(z)
    intervals, notes = parameter_intervals(problem, z, residual, jac)
    kind = LinearGreyBoxModel if structure.kind == "linear" else GreyBoxModel
    return kind(
        structure=structure,
        values=problem.values(z),
        ts=problem.ts,
        method=method,
        cost=problem.cost_of(residual),
        intervals=intervals,
        undetermined=notes,
        output_name=str(data.output_name),
        nfev=problem.nfev,
        input_name=str(data.input_name),
        input_unit=data.input_unit,
        output_unit=data.output_unit,
        u_offset=data.u_offset,
        y_offset=data.y_offset,
    )
