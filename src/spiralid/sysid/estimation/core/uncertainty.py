"""The covariance of an estimate: ``s^2 (J^T J)^-1`` at the optimum.

For a least-squares criterion ``V = sum e_t^2`` minimised at ``theta``, with
white errors of variance ``sigma^2``, the estimate is asymptotically normal
with covariance ``sigma^2 (J^T J)^-1``, ``J = d e / d theta`` (Ljung, *System
Identification*, 2nd ed., sec. 9.2). ``sigma^2`` is estimated by ``s^2 =
e^T e / (N - p)``. The error is the one the estimator minimised: the
simulation error for output error, ``refine`` and the searches with the
simulation predictor (the paper's eq. (2) is that error's RMS, scaled), the
one-step error for least squares; ``J`` is the analytic Jacobian the polish
uses (:func:`~spiralid.sysid.estimation.linear.outputerror.error_functions`).

The interval is honest where the model's structure holds the plant and the
error is white; for an output-error model of a record with coloured noise it
is too narrow. :attr:`spiralid.sysid.IdentifiedModel.modes` carries it into
modal frequencies and damping ratios.
"""

from __future__ import annotations

import numpy as np

from ...data import IOData
from ...models.arx import ARX
from ..linear.outputerror import error_functions

__all__ = ["parameter_covariance"]


def parameter_covariance(
    theta,
    arx: ARX,
    data: IOData,
    predictor: str,
    initial: str = "rest",
    *,
    factor: bool = False,
):
    """The covariance of `theta` and the error variance ``s^2``.

    Parameters
    ----------
    theta : array_like, shape (p,)
        The estimate, ``[a_1..a_na, b_0..]``, at a minimum of the error.
    arx : ARX
        The structure.
    data : IOData
        The record that estimated `theta`.
    predictor : {"simulation", "one-step"}
        The error the estimator minimised.
    initial : {"rest", "measured"}
        The simulation's initial condition (see :class:`PaperCost`).
    factor : bool, default False
        Also return a square-root factor ``R`` with ``covariance = R^T R``
        (``R = s S^-1 V^T`` from the SVD ``J = U S V^T``), or None when a
        direction is undetermined. A quadratic form ``g^T C g`` computed as
        ``|R g|^2`` keeps its precision where forming ``C`` squares the
        condition of ``J`` (a delta-method variance near a well-determined
        direction can otherwise round to zero).

    Returns
    -------
    covariance : ndarray, shape (p, p)
        ``s^2 (J^T J)^-1``, from the singular values of ``J``; a direction
        the data do not determine (a singular value below ``1e-12`` of the
        largest, e.g. an exact pole-zero cancellation) gets an infinite
        variance.
    s2 : float
        ``e^T e / (N - p)``.
    factor : ndarray or None, shape (p, p)
        Only with ``factor=True``.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> rng = np.random.default_rng(1)
    >>> u = rng.standard_normal(2000)
    >>> y = lfilter([0.0, 1.0], [1.0, -0.8], u) + 0.1 * rng.standard_normal(2000)
    >>> data, arx = IOData(u, y, ts=1.0), ARX(1, 1, 1)
    >>> from spiralid.sysid import identify
    >>> fit = identify(data, arx, method="oe")
    >>> cov, s2 = parameter_covariance(fit.theta, arx, data, "simulation")
    >>> round(float(np.sqrt(s2)), 2)
    0.1
    """
    theta = np.asarray(theta, dtype=float)
    residual, jacobian = error_functions(arx, data, predictor, initial)
    e = residual(theta)
    jac = np.asarray(jacobian(theta), dtype=float)
    n, p = jac.shape
    if n <= p:
        raise ValueError(
            f"`data` has {n} error samples for {p} parameters: too short for a "
            "covariance"
        )
    s2 = float(e @ e) / (n - p)
    _, sv, vt = np.linalg.svd(jac, full_matrices=False)
    with np.errstate(divide="ignore"):
        inverse = np.where(sv > 1e-12 * sv[0], 1.0 / sv**2, np.inf)
    root = None
    if np.all(np.isfinite(inverse)):
        covariance = s2 * (vt.T * inverse) @ vt
        root = np.sqrt(s2) * vt / sv[:, None]
    else:
        # inf * 0 would give NaN: the undetermined directions' variance is
        # infinite on every coefficient they touch.
        finite = np.isfinite(inverse)
        covariance = s2 * (vt[finite].T * inverse[finite]) @ vt[finite]
        touched = np.any(np.abs(vt[~finite]) > 1e-12, axis=0)
        covariance[np.ix_(touched, touched)] = np.inf
    return (covariance, s2, root) if factor else (covariance, s2)
