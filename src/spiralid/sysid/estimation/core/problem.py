"""What every estimator takes and returns: the :class:`Problem`
:func:`~spiralid.sysid.identify` checks and gathers, and the
:class:`EstimatorResult` every estimator of
:data:`~spiralid.sysid.estimation.core.estimators.METHODS` returns."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ...models.arx import ARX
from ..linear.margin import AUTO
from ..linear.parametrizations import Parametrization, make_parametrization
from .cost import PaperCost

__all__ = ["IDENTIFY_DEFAULTS", "EstimatorResult", "Problem"]

# identify's arguments by name with their defaults; an argument equal to
# its default is never refused, whatever the method or structure.
IDENTIFY_DEFAULTS = dict(
    predictor="simulation",
    initial="rest",
    rng=None,
    gain="auto",
    penalty=1e6,
    integrator=False,
    max_time_constant=AUTO,
    cancel=None,
    noise="white",
    parametrization=None,
    bounds=None,
    refine=False,
    safe_start=None,
    # A NARX's early stopping, weight decay and training (identify_narx's).
    holdout=0.2,
    decay=1e-3,
    training="free-run",
    horizon=None,
)


class EstimatorResult(OptimiserResult):
    """What every estimator returns: the optimisers' one result type
    (:class:`~spiralid.optim.OptimiserResult`, which behaves like
    ``scipy.optimize.OptimizeResult``) with the ARX theta as ``x``.

    Attributes
    ----------
    x : ndarray, shape (p,)
        The ARX theta ``[a_1..a_na, b_0..b_(nb-1)]``.
    fun : float
        Its cost on the estimation data (eq. (2)-(3), the problem's predictor).
    status : int
        A key of :data:`STATUS` (``1``: stopped at the evaluation cap).
    success : bool
        As the underlying optimiser says (a search that used its budget
        succeeded).
    message : str
        Why it stopped.
    nfev, nit : int
        Cost evaluations and iterations (the kept start's, for ``"oe"``).
    history : ndarray or None
        Best cost after each iteration of a search (index 0: the initial
        population).
    elapsed : float
        Seconds (the search alone, without ``refine``).
    x_search : ndarray, optional
        A search's best point in its searched coordinates.
    bounds : ndarray, optional
        A search's box, in its searched coordinates.
    safe_start : bool, optional
        Whether a search's first population held the safe start.
    optimality, at_bound : float, bool, optional
        A polish's end: the gradient's largest component (first-order
        optimality) and whether the end is on the stable region's edge
        (where the gradient need not vanish); status 1 when the evaluation
        cap, not a tolerance, ended it.
    start : str, optional
        Which start a polish kept (``"ls"``, ``"steiglitz-mcbride"``,
        ``"search"``); ``starts`` gives each start's cost.
    refine : EstimatorResult or None
        The polish of ``refine=True``; ``refine.accepted`` says whether it
        lowered the cost (otherwise ``x`` is the search's).
    cancelled : list of dict, optional
        The near-cancelling pole-zero pairs removed after the estimate
        (:func:`~spiralid.sysid.estimation.spiral.cancellation.reduce_order`);
        ``effective_order`` ``(na', nb')`` and ``x_full``, ``fun_full`` (the
        estimate before) with them.
    raw : object
        The underlying optimiser's own result.
    """


@dataclass
class Problem:
    """Everything an estimator needs, checked by :func:`identify`."""

    data: IOData
    arx: ARX
    cost: PaperCost
    predictor: str
    initial: str
    gain: str | float
    penalty: float
    parametrization: Parametrization
    rng: np.random.Generator
    bounds: np.ndarray | None = None
    refine: bool = False
    safe_start: bool = False
    # The stability margin r_max of the polish (and of the parametrisation
    # when the method applies it), None for none; and whether pole-zero
    # pairs are cancelled after the estimate.
    max_radius: float | None = None
    cancel: bool = False

    def restricted(self, data: IOData) -> Problem:
        """The same problem on another record (a part of this one): its cost
        and parametrisation rebuilt on `data`, the margin, box and
        randomness kept."""
        par = self.parametrization
        return replace(
            self,
            data=data,
            cost=PaperCost(
                self.arx,
                data,
                predictor=self.predictor,
                gain=self.gain,
                penalty=self.penalty,
                initial=self.initial,
            ),
            parametrization=make_parametrization(
                par.name, data, self.arx, par.max_radius
            ),
        )

    def simulation_cost(self) -> PaperCost:
        """The simulation cost output error minimises, whatever `predictor`."""
        if self.predictor == "simulation":
            return self.cost
        return PaperCost(
            self.arx,
            self.data,
            gain=self.gain,
            penalty=self.penalty,
            initial=self.initial,
        )
