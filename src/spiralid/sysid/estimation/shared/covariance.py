"""The covariance of every parameter of a shared-denominator fit.

The modes' intervals need the covariance of ``a`` alone, which variable
projection gives with the numerators projected out
(:mod:`~spiralid.sysid.estimation.shared.denominator`). A mode's shape is
a function of ``a`` and of every numerator (each output's residue,
:mod:`~spiralid.sysid.models.shapes`), so its intervals need the
covariance of ``theta = [a, b_1, .., b_p]``: ``s^2 (J' J)^-1`` of the
weighted simulation error of every output, stacked, with ``J`` its
Jacobian in ``theta`` (output ``i``'s rows hold ``a``'s columns and
``b_i``'s, zeros elsewhere; each from
:func:`~spiralid.sysid.estimation.linear.outputerror.error_functions`, from
rest, as the fit). Its ``a`` block is the projected covariance (at the
optimum the two agree: Golub and Pereyra). As there, a square-root factor
``R = s S^-1 V^T`` from the SVD ``J = U S V^T`` is kept rather than the
covariance, whose normal equations square the condition of ``J``.
"""

from __future__ import annotations

import numpy as np

from ...data import IOData
from ...models.polynomials import is_stable_polynomial
from ..linear.outputerror import error_functions

__all__ = ["parameter_factor"]


def parameter_factor(cost, a, b) -> np.ndarray | None:
    """``R`` with ``C = R^T R`` the covariance of ``[a, b_1, .., b_p]``.

    Parameters
    ----------
    cost : SharedProjectedCost
        The joint cost the fit minimised (its outputs' records, with their
        inputs summed for their integrators, and its weights).
    a : array_like, shape (na,)
        The shared denominator at the optimum.
    b : array_like, shape (p, m nb)
        Each output's numerators there (``[b_i1, .., b_im]`` with several
        inputs).

    Returns
    -------
    ndarray, shape (na + p m nb, na + p m nb), or None
        None where `a` is unstable, the record too short for the
        parameters, or a direction undetermined (a singular value of ``J``
        below 1e-12 of the largest).
    """
    a = np.asarray(a, dtype=float).ravel()
    b = np.atleast_2d(np.asarray(b, dtype=float))
    if not is_stable_polynomial(a):
        return None
    blocks, residual = [], []
    for i, (w, part) in enumerate(zip(np.sqrt(cost.weights), cost.parts, strict=True)):
        block, res = _output_block(cost.arx, part.data, a, b, i)
        blocks.append(w * block)
        residual.append(w * res)
    jac = np.vstack(blocks)
    r = np.concatenate(residual)
    dof = jac.shape[0] - jac.shape[1]
    if dof <= 0:
        return None
    try:
        _, sv, vt = np.linalg.svd(jac, full_matrices=False)
    except np.linalg.LinAlgError:
        return None
    if not sv[-1] > 1e-12 * sv[0]:
        return None
    return np.sqrt(float(r @ r) / dof) * vt / sv[:, None]


def _output_block(arx, data, a, b, i: int) -> tuple[np.ndarray, np.ndarray]:
    """Output `i`'s rows of the Jacobian in ``[a, b_1, .., b_p]`` and its
    simulation error from rest. With several inputs the output is the sum
    of each input's ``B_ij / A`` response (superposition): each pair's
    Jacobian from :func:`error_functions` on that input (the measured
    output given to the first pair only, zeros to the others, so the
    residuals add up to the output's), its ``a`` columns summed."""
    u = np.asarray(data.u, dtype=float).reshape(data.n, -1)
    m, na = u.shape[1], a.size
    nb = b.shape[1] // m
    block = np.zeros((data.n, na + b.size))
    total = 0.0
    for j in range(m):
        y = data.y if j == 0 else np.zeros(data.n)
        res, jac = error_functions(
            arx, IOData(u[:, j], y, ts=data.ts), "simulation", "rest"
        )
        theta = np.r_[a, b[i, j * nb : (j + 1) * nb]]
        j_ij = np.asarray(jac(theta), dtype=float)
        block[:, :na] += j_ij[:, :na]
        first = na + (i * m + j) * nb
        block[:, first : first + nb] = j_ij[:, na:]
        total = total + res(theta)
    return block, total
