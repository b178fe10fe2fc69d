"""The parameters' 95 % intervals and what the record cannot determine,
from the simulation error's Jacobian at the fit.

In the search's unit-box coordinates ``z`` the covariance is ``s^2 (J'J)^-1``
(``s^2`` the residual variance, ``J = d e / d z``) where the error is white,
and the sandwich ``(J'J)^-1 J' R J (J'J)^-1`` with ``R`` an autoregressive
model of its covariance where it is not
(:mod:`~spiralid.sysid.estimation.core.coloured`; each output's error
modelled on its own), both taken through the singular value decomposition
``J = U S V'``: ``V S^-1 G S^-1 V'`` with ``G = U' R U``. On a noise-free
record of the stick-slip rig the error is strongly coloured (the encoder's
quantisation, the modes left out) and the white intervals missed the
friction levels by 3-10 of their half-widths. A direction ``v_i`` whose
95 % half-width ``1.96 sqrt(G_ii) / S_i`` is wider than the whole box (or
whose ``S_i`` is below rounding) is one the record cannot determine: it is
dropped from the covariance, and every parameter it moves is named as not
determined, with no interval (a tiny interval from a pseudo-inverse would
claim the opposite). Each other parameter's interval ``z_j +- 1.96 sd_j`` is mapped
back to its unit through its coordinate: symmetric for a linear one,
symmetric in ``log`` (so positive, and wider above the value) for a
log-scaled one.
"""

from __future__ import annotations

import numpy as np

from ..core.coloured import error_gram
from .problem import GreyBoxProblem

__all__ = ["parameter_intervals", "undetermined_directions"]

_Z95 = 1.959963984540054
# Singular values below this share of the largest are rounding.
_RANK_TOL = 1e-8
# A parameter moved by more than this share of an undetermined direction is
# named as not determined.
_SHARE = 0.1


def parameter_intervals(
    problem: GreyBoxProblem, z: np.ndarray, residual: np.ndarray, jac: np.ndarray
) -> tuple[np.ndarray, list[str]]:
    """Every parameter's 95 % interval (NaN for a fixed or undetermined
    one) and one sentence per undetermined direction.

    Parameters
    ----------
    problem : GreyBoxProblem
        The fit's problem (coordinates and names).
    z : ndarray
        The fit in unit-box coordinates.
    residual : ndarray
        The simulation error there.
    jac : ndarray
        ``d residual / d z`` there.

    Returns
    -------
    intervals : ndarray, shape (n_parameters, 2)
    undetermined : list of str
    """
    n_all = problem.structure.free.size
    intervals = np.full((n_all, 2), np.nan)
    names = [p.name for p in problem.structure.all_parameters if p.free]
    if not _usable(residual, jac):
        return intervals, ["no interval: the fit's Jacobian is not finite"]
    sv, vt, gram, lost = _directions(problem, residual, jac)
    undetermined = np.zeros(z.size, dtype=bool)
    notes = []
    for i in np.flatnonzero(lost):
        moved = np.abs(vt[i]) > _SHARE
        undetermined |= moved
        terms = " ".join(f"{vt[i, j]:+.2f} {names[j]}" for j in np.flatnonzero(moved))
        notes.append(
            "not determined by the record: the direction "
            f"{terms} (unit-box coordinates; log scale where the parameter has one)"
        )
    keep = ~lost
    scaled = vt[keep].T / sv[keep]
    cov = scaled @ gram[np.ix_(keep, keep)] @ scaled.T
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    low = problem.free_values(z - _Z95 * sd)
    high = problem.free_values(z + _Z95 * sd)
    free_rows = np.flatnonzero(problem.free)
    for j, row in enumerate(free_rows):
        if not undetermined[j]:
            intervals[row] = low[j], high[j]
    return intervals, notes


def undetermined_directions(
    problem: GreyBoxProblem, residual: np.ndarray, jac: np.ndarray
) -> np.ndarray:
    """The unit-box directions (rows, the least determined first) that the
    record cannot determine: those :func:`parameter_intervals` drops."""
    if not _usable(residual, jac):
        return np.empty((0, jac.shape[1]))
    _, vt, _, lost = _directions(problem, residual, jac)
    return vt[lost][::-1]


def _usable(residual: np.ndarray, jac: np.ndarray) -> bool:
    """Whether the fit's error and Jacobian can say what the record
    determines: both finite, and a degree of freedom left."""
    finite = np.all(np.isfinite(jac)) and np.all(np.isfinite(residual))
    return bool(finite) and residual.size > jac.shape[1]


def _directions(problem: GreyBoxProblem, residual: np.ndarray, jac: np.ndarray):
    """The Jacobian's singular values and directions (``S``, ``V'``), the
    error's Gram matrix ``G`` in them (per degree of freedom), and which
    directions are lost: ``S_i`` below rounding, or a 95 % half-width
    ``1.96 sqrt(G_ii) / S_i`` wider than the box."""
    u, sv, vt = np.linalg.svd(jac, full_matrices=False)
    dof = residual.size - jac.shape[1]
    gram = _gram(residual, u, problem.n_outputs) * residual.size / dof
    smax = sv[0] if sv.size else 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        half = _Z95 * np.sqrt(np.diag(gram)) / sv
    return sv, vt, gram, (sv <= _RANK_TOL * smax) | (half > 1.0)


def _gram(residual: np.ndarray, u: np.ndarray, n_outputs: int) -> np.ndarray:
    """``U' R U`` summed over the outputs, each output's error (a column of
    the residual's ``(N, n_outputs)`` layout) with its own noise model."""
    e = residual.reshape(-1, n_outputs)
    basis = u.reshape(e.shape[0], n_outputs, -1)
    return sum(error_gram(e[:, k], basis[:, k]) for k in range(n_outputs))
