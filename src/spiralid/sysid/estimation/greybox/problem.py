"""What a grey-box fit minimises, and in which coordinates.

The search and the polish move the free parameters in a unit box: each
parameter's bounds map to ``[0, 1]``, linearly or, for a parameter on a log
scale, in ``log(value)``, so a parameter spanning decades is searched as
evenly as one spanning a few units, and the box is the projection of the
Levenberg-Marquardt polish.

The cost is the paper's eq. (2) on the free-run simulation error from the
structure's initial state: ``w sqrt(sum e^2) / N`` with ``w = 100 sqrt(N) /
rms(y)`` by default (the RMS error in percent of the output's). With
several outputs, each output's error is multiplied by its ``scale`` (one
over its noise's standard deviation, see :mod:`.fit`) before the sum, and
``y`` in ``w`` is the outputs so scaled: the outputs' errors count in
units of their noise, and the residual is ``N p`` long. A run that
blew up (a non-finite output, or a cost above it) costs ``penalty``: the
search goes on. A
continuous-time model has no denominator for eq. (3)'s pole test, so only
such a run is penalised.
"""

from __future__ import annotations

import copy

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
        The estimation record, of as many outputs as the structure's.
    structure : GreyBox
        The structure fitted.
    gain : "auto" or float
        Eq. (2)'s ``w``.
    penalty : float
        The cost of a run that blew up.
    scale : array_like, shape (p,), optional
        Each output's error multiplier; default one over each output's RMS
        (1 for a single output, whose cost is then the paper's).
    """

    def __init__(
        self, data: IOData, structure: GreyBox, gain="auto", penalty=1e6, scale=None
    ):
        if getattr(structure, "family", None) != GreyBox.family:
            raise TypeError(
                f"`structure` must be a GreyBox; got {type(structure).__name__}"
            )
        _check_outputs(data, structure)
        self.structure = structure
        self.u = np.asarray(data.u, dtype=float)
        self.y = np.asarray(data.y, dtype=float)
        self.n_outputs = data.n_outputs
        self.ts = float(data.ts)
        self.gain = gain
        self.scale = self._scale(scale)
        free = structure.free
        if not free.any():
            raise ValueError("`structure` has no free parameter: nothing to fit")
        self.free = free
        d = int(free.sum())
        if self.y.size <= 2 * d:
            # As many residuals beyond the parameters as parameters: fewer
            # leave the residual variance, so every interval, to chance.
            raise ValueError(
                f"`data` has {self.y.size} samples of its outputs; a grey box of "
                f"{d} free parameters needs more than {2 * d}"
            )
        params = [p for p in structure.all_parameters if p.free]
        self.log = np.array([p.log for p in params])
        low = np.array([p.bounds[0] for p in params])
        high = np.array([p.bounds[1] for p in params])
        self.bounds = (low, high)
        self.low = np.where(self.log, np.log(np.where(self.log, low, 1.0)), low)
        self.high = np.where(self.log, np.log(np.where(self.log, high, 1.0)), high)
        self.w = gain_value(gain, self.y * self.scale)
        self.penalty = positive(penalty, "penalty")
        self.nfev = 0

    def _scale(self, scale) -> np.ndarray | float:
        """`scale` checked, or its default (see the class docstring)."""
        if self.n_outputs == 1 and scale is None:
            return 1.0
        if scale is None:
            rms = np.sqrt(np.mean(self.y**2, axis=0))
            scale = 1.0 / np.maximum(rms, np.finfo(float).tiny)
        scale = np.asarray(scale, dtype=float).ravel()
        if scale.shape != (self.n_outputs,) or not np.all(
            np.isfinite(scale) & (scale > 0)
        ):
            raise ValueError(
                f"`scale` must be {self.n_outputs} finite numbers > 0 (one per "
                f"output); got {scale!r}"
            )
        return scale if self.n_outputs > 1 else float(scale[0])

    def rescaled(self, scale) -> GreyBoxProblem:
        """The same problem with other output scales (its ``nfev`` carried
        on)."""
        out = copy.copy(self)
        out.scale = out._scale(scale)
        out.w = gain_value(self.gain, out.y * out.scale)
        return out

    @property
    def n_free(self) -> int:
        return int(self.free.sum())

    def output_errors(self, residual: np.ndarray) -> np.ndarray:
        """The unscaled error, shape (N, p), of a :meth:`residual`."""
        return np.reshape(residual, (-1, self.n_outputs)) / self.scale

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
        v = np.where(self.log, np.exp(c), c)
        # exp(log(high)) may round a hair above high: the bound is the bound.
        inside = (np.asarray(z) >= 0.0) & (np.asarray(z) <= 1.0)
        return np.where(inside, np.clip(v, self.bounds[0], self.bounds[1]), v)

    def values(self, z) -> np.ndarray:
        """Every parameter's value at `z` clipped into the box (fixed ones at
        their value): a search that steps outside the bounds (the paper's
        SDA does) runs the model on the box's face, never beyond."""
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
        e = self.y - self.structure.simulate(self.values(z), self.u, self.ts)
        return e if self.n_outputs == 1 else (e * self.scale).ravel()

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

    def jacobian(self, z, residuals=None) -> np.ndarray:
        """``d residual / d z`` by forward differences, stepping inward at
        the box's upper face; `residuals` (a batch of points -> their
        residuals, e.g. on several processes) runs the ``n + 1``
        simulations, one by one by default."""
        z = np.asarray(z, dtype=float)
        steps = np.where(z + _STEP <= 1.0, _STEP, -_STEP)
        points = np.vstack([z, z + np.diag(steps)])
        if residuals is None:
            r0, *moved = (self.residual(p) for p in points)
        else:
            r0, *moved = residuals(points)
        pairs = zip(moved, steps, strict=True)
        return np.column_stack([(r - r0) / h for r, h in pairs])


def _check_outputs(data: IOData, structure: GreyBox) -> None:
    """The record holds as many outputs as the structure gives: a one-line
    ValueError naming the structure's output function otherwise."""
    if data.n_outputs == structure.n_outputs:
        return
    raise ValueError(
        f"{structure.output_source()} gives {structure.n_outputs} output(s) but "
        f"`data` holds "
        f"{data.n_outputs} ({', '.join(data.output_names)}): a grey box is fitted "
        "to a record of its outputs, in its order"
    )
