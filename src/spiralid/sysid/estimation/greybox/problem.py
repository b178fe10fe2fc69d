"""What a grey-box fit minimises, and in which coordinates.

The search and the polish move the free parameters in a unit box: each
parameter's bounds map to ``[0, 1]``, linearly or, for a parameter on a log
scale, in ``log(value)``, so a parameter spanning decades is searched as
evenly as one spanning a few units, and the box is the projection of the
Levenberg-Marquardt polish.

The cost is the paper's eq. (2) on the free-run simulation error from the
structure's initial state: ``w sqrt(sum e^2) / N`` with ``w = 100 sqrt(N) /
rms(y)`` by default (the RMS error in percent of the output's). A run that
blew up (a non-finite output, or a cost above it) costs ``penalty``: the
search goes on. A
continuous-time model has no denominator for eq. (3)'s pole test, so only
such a run is penalised.
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import positive

from ...data import IOData
from ...models.greybox import GreyBox
from ..core.cost import cost_of_errors, gain_value

__all__ = ["GreyBoxProblem"]

# Forward-difference step of the Jacobian, in unit-box coordinates.
_STEP = 1e-6


class GreyBoxProblem:
    """The grey box `structure` on the record `data`: coordinates, cost,
    residual and Jacobian.

    Parameters
    ----------
    data : IOData
        The estimation record (one output).
    structure : GreyBox
        The structure fitted.
    gain : "auto" or float
        Eq. (2)'s ``w``.
    penalty : float
        The cost of a run that blew up.
    """

    def __init__(self, data: IOData, structure: GreyBox, gain="auto", penalty=1e6):
        if getattr(structure, "family", None) != GreyBox.family:
            raise TypeError(
                f"`structure` must be a GreyBox; got {type(structure).__name__}"
            )
        self.structure = structure
        self.u = np.asarray(data.u, dtype=float)
        self.y = np.asarray(data.y, dtype=float).ravel()
        self.ts = float(data.ts)
        free = structure.free
        if not free.any():
            raise ValueError("`structure` has no free parameter: nothing to fit")
        self.free = free
        d = int(free.sum())
        if self.y.size <= 2 * d:
            # As many residuals beyond the parameters as parameters: fewer
            # leave the residual variance, so every interval, to chance.
            raise ValueError(
                f"`data` has N = {self.y.size} samples; a grey box of {d} free "
                f"parameters needs more than {2 * d}"
            )
        params = [p for p in structure.parameters if p.free]
        self.log = np.array([p.log for p in params])
        low = np.array([p.bounds[0] for p in params])
        high = np.array([p.bounds[1] for p in params])
        self.low = np.where(self.log, np.log(np.where(self.log, low, 1.0)), low)
        self.high = np.where(self.log, np.log(np.where(self.log, high, 1.0)), high)
        self.w = gain_value(gain, self.y)
        self.penalty = positive(penalty, "penalty")
        self.nfev = 0

    @property
    def n_free(self) -> int:
        return int(self.free.sum())

    # -- coordinates ----------------------------------------------------------

    def to_box(self, free_values) -> np.ndarray:
        """The unit-box point of the free parameters' values."""
        v = np.asarray(free_values, dtype=float)
        c = np.where(self.log, np.log(np.where(self.log, v, 1.0)), v)
        return (c - self.low) / (self.high - self.low)

    def free_values(self, z) -> np.ndarray:
        """The free parameters' values at the unit-box point `z` (any
        real `z`, inside the box or not)."""
        c = self.low + np.asarray(z, dtype=float) * (self.high - self.low)
        return np.where(self.log, np.exp(c), c)

    def values(self, z) -> np.ndarray:
        """Every parameter's value at `z` projected into the box (fixed ones
        at their value): a search that steps outside the bounds (the
        paper's rules, as printed, do not keep to them) evaluates the
        nearest point inside, so no parameter ever leaves its bounds."""
        out = self.structure.initial_values
        out[self.free] = self.free_values(np.clip(z, 0.0, 1.0))
        return out

    @property
    def z0(self) -> np.ndarray:
        """The initial values' point."""
        return self.to_box(self.structure.initial_values[self.free])

    # -- cost, residual, Jacobian ------------------------------------------------

    def residual(self, z) -> np.ndarray:
        """The simulation error ``y - y_sim`` at `z` (non-finite where the
        run blew up)."""
        self.nfev += 1
        return self.y - self.structure.simulate(self.values(z), self.u, self.ts)

    def cost_of(self, e: np.ndarray) -> float:
        """Eq. (2) of the error `e`, or the penalty for a run that blew up
        (a non-finite error, or one costing more than the penalty, so that
        no finite run ranks behind a blown-up one)."""
        if not np.all(np.isfinite(e)):
            return self.penalty
        with np.errstate(over="ignore"):
            cost = float(cost_of_errors(e, self.w, True, self.penalty))
        return cost if cost < self.penalty else self.penalty

    def __call__(self, z) -> float:
        """The cost at the unit-box point `z`."""
        return self.cost_of(self.residual(z))

    def jacobian(self, z) -> np.ndarray:
        """``d residual / d z`` by forward differences, stepping inward at
        the box's upper face."""
        z = np.asarray(z, dtype=float)
        r0 = self.residual(z)
        jac = np.empty((r0.size, z.size))
        for j in range(z.size):
            h = _STEP if z[j] + _STEP <= 1.0 else -_STEP
            step = z.copy()
            step[j] += h
            jac[:, j] = (self.residual(step) - r0) / h
        return jac
