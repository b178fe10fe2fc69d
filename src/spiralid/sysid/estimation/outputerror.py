"""Output error: Levenberg-Marquardt on the simulation error, kept stable.

:func:`local_polish` is the local step of ``method="oe"`` and of
``refine=True``: ``scipy.optimize.least_squares`` (Levenberg-Marquardt,
analytic Jacobian) on the error :class:`~spiralid.sysid.PaperCost` defines,
with the denominator searched as reflection coefficients
``k = KMAX tanh(z)``, ``KMAX = 1 - 1e-6``, so every step is stable
(unstable poles of a start are first reflected into the unit circle,
``z -> 1 / conj(z)``). :func:`steiglitz_mcbride` gives the classical
output-error start. The estimators (:mod:`spiralid.sysid.estimation.estimators`) run
the polish from several starts and keep the lowest cost.
"""

from __future__ import annotations

import numpy as np
from scipy import optimize, signal

from ..data import IOData
from ..models.arx import ARX, arx_least_squares
from ..models.polynomials import step_up
from .parametrizations import KMAX, stabilise

__all__ = ["local_polish", "steiglitz_mcbride"]


def _step_up_jacobian(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Step-up with its Jacobian ``D[i, j] = d a_i / d k_j`` (forward mode)."""
    n = k.size
    a = np.zeros(n)
    jac = np.zeros((n, n))
    for j in range(n):
        prev, dprev = a[:j].copy(), jac[:j].copy()
        a[:j] = prev + k[j] * prev[::-1]
        jac[:j] = dprev + k[j] * dprev[::-1]
        jac[:j, j] += prev[::-1]
        a[j] = k[j]
        jac[j, j] = 1.0
    return a, jac


# One LM round's tolerances (step, cost, gradient); the rounds a polish may
# take when each runs into its evaluation cap, and the relative fall of the
# cost a capped round must bring for another to follow (less is the end of a
# flat valley, not a step LM can still take).
_TOL = 1e-12
_ROUNDS = 10
_GAIN = 1e-6


def local_polish(
    theta0: np.ndarray,
    arx: ARX,
    data: IOData,
    predictor: str,
    initial: str = "rest",
    max_nfev: int | None = None,
) -> tuple[np.ndarray, optimize.OptimizeResult]:
    """Levenberg-Marquardt polish of the `predictor`'s error as
    :class:`PaperCost` defines it, kept stable: the denominator is searched
    as ``k = kmax tanh(z)`` (reflection coefficients, so every step is
    stable) with ``z`` unconstrained. Analytic Jacobian:
    ``d yhat / d b_j = u(t-nk-j) / A`` and ``d yhat / d a_i = -yhat(t-i) / A``
    (simulation: sensitivities filtered from rest, with ``yhat`` zero before
    ``t = 0`` for ``initial="rest"`` and the measured initial state fixed
    for ``"measured"``), ``Phi`` (one-step).

    ``max_nfev`` caps the residual evaluations of one round of LM (default
    ``100 (p + 1)``, from the order); a round that reaches it is followed by
    another from where it stopped, up to ten rounds, while a round still
    lowers the cost by more than a millionth, so the polish ends where LM
    meets its tolerances (1e-12 relative on step, cost and gradient) or
    stops improving. The result records ``rounds``, the total ``nfev``,
    ``optimality`` (the gradient's largest component at the end) and
    ``capped`` (the last round reached its cap without the cost settling:
    it still fell by more than a millionth, or LM took no step at all)."""
    na, t0 = arx.na, arx.max_lag
    if predictor == "simulation" and initial == "rest":
        # From rest is the measured-past problem on the record preceded by
        # t0 zeros: the "measured" past is then the zero state, the input
        # before t = 0 is zero, and the residual covers all N samples.
        pad = np.zeros(t0)
        data = IOData(np.r_[pad, data.u], np.r_[pad, data.y], ts=data.ts)
    y = data.y
    yv = y[t0:]
    n_k = yv.size
    phi = arx.regressors(data)[t0:]
    ulags = arx.input_lags(data.u)[:, t0:]
    past = y[t0 - na : t0][::-1]

    def parts(x):
        th = np.tanh(x[:na])
        a, dadk = _step_up_jacobian(KMAX * th)
        return a, dadk * (KMAX * (1.0 - th * th)), x[na:]

    if predictor == "simulation":

        def simulate(a, b):
            xs = b @ ulags
            if na == 0:
                return xs
            den = np.r_[1.0, a]
            zi = signal.lfiltic([1.0], den, past)
            return signal.lfilter([1.0], den, xs, zi=zi)[0]

        def residual(x):
            a, _, b = parts(x)
            return simulate(a, b) - yv

        def jacobian(x):
            a, dadz, b = parts(x)
            yext = np.r_[y[:t0], simulate(a, b)]
            lagged = [-yext[t0 - i : t0 - i + n_k] for i in range(1, na + 1)]
            rows = np.vstack([*lagged, ulags]) if na else ulags
            sens = signal.lfilter([1.0], np.r_[1.0, a], rows, axis=1).T
            return np.hstack([sens[:, :na] @ dadz, sens[:, na:]])

    else:

        def residual(x):
            a, _, b = parts(x)
            return phi @ np.r_[a, b] - yv

        def jacobian(x):
            _, dadz, _ = parts(x)
            return np.hstack([phi[:, :na] @ dadz, phi[:, na:]])

    if max_nfev is None:
        max_nfev = 100 * (arx.n_params + 1)
    start = stabilise(np.asarray(theta0, dtype=float), arx)
    ratio = np.clip(start[:na] / KMAX, -1.0 + 1e-12, 1.0 - 1e-12)
    x = np.r_[np.arctanh(ratio), start[na:]]
    nfev = rounds = 0
    while rounds < _ROUNDS:
        rounds += 1
        res = optimize.least_squares(
            residual,
            x,
            jac=jacobian,
            method="lm",
            x_scale="jac",
            xtol=_TOL,
            ftol=_TOL,
            gtol=_TOL,
            max_nfev=max_nfev,
        )
        nfev += res.nfev
        # least_squares reports status 0 when it stopped at its cap: go on
        # from there while a round still lowers the cost, so the result is
        # a point where LM cannot improve, not where its count ran out.
        before = 0.5 * float(np.sum(residual(x) ** 2))
        gain = (before - res.cost) / before if before > 0 else 0.0
        improved = gain > _GAIN
        x = res.x
        if res.status != 0 or not improved:
            break
    res.nfev, res.rounds, res.max_nfev = nfev, rounds, max_nfev
    # Stationarity at the end: the gradient's largest component (SciPy's
    # first-order optimality) and whether the cap, not the cost settling,
    # ended it (a capped round that gained a little is the valley's end).
    valley_end = 0.0 < gain <= _GAIN
    res.capped = bool(res.status == 0 and not valley_end)
    if res.status == 0 and valley_end:
        res.message = (
            f"A round of {max_nfev} evaluations lowered the cost by less than "
            f"{_GAIN:g} of it: the end of a flat valley."
        )
    a, _, b = parts(res.x)
    return np.r_[a, b], res


def steiglitz_mcbride(
    data: IOData, arx: ARX, theta0=None, n_iter: int = 10
) -> np.ndarray:
    """Steiglitz-McBride iterations: an output-error start from least squares.

    Each iteration filters ``u`` and ``y`` by ``1 / A`` of the current
    estimate (from rest) and solves the ARX least-squares problem on the
    filtered signals; at a fixed point the equation error of the filtered
    data is the output error ``y - B / A u``, so the iterations move the
    least-squares estimate (biased towards the one-step error) towards an
    output-error estimate. This is the classical initialisation of
    output-error search (MATLAB's ``oe`` starts from an instrumental-
    variable or Steiglitz-McBride estimate). Unstable denominators are
    reflected into the unit circle before they are used as a filter.

    Parameters
    ----------
    data : IOData
    arx : ARX
    theta0 : array_like, shape (p,), optional
        Start; default the least-squares estimate.
    n_iter : int
        Maximum number of iterations (stops earlier at a fixed point).

    Returns
    -------
    theta : ndarray, shape (p,)
        Stable.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal(400)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> y = y + 0.5 * rng.standard_normal(400)   # output (not equation) noise
    >>> ls = arx_least_squares(IOData(u, y, ts=1.0), ARX(2, 2, 1))
    >>> sm = steiglitz_mcbride(IOData(u, y, ts=1.0), ARX(2, 2, 1))
    >>> true = np.array([-1.5, 0.7, 1.0, 0.5])
    >>> bool(np.linalg.norm(sm - true) < np.linalg.norm(ls - true))
    True
    """
    if not isinstance(data, IOData):
        raise ValueError(f"`data` must be an IOData; got {type(data).__name__}")
    if not isinstance(arx, ARX):
        raise ValueError(f"`arx` must be an ARX; got {type(arx).__name__}")
    if isinstance(n_iter, bool) or not isinstance(n_iter, int | np.integer):
        raise ValueError(f"`n_iter` must be an integer >= 0; got {n_iter!r}")
    if n_iter < 0:
        raise ValueError(f"`n_iter` must be an integer >= 0; got {n_iter!r}")
    na, t0 = arx.na, arx.max_lag
    if theta0 is None:
        theta = arx_least_squares(data, arx)
    else:
        arx.check_length(data)
        theta = np.array(theta0, dtype=float)
        if theta.shape != (arx.n_params,) or not np.all(np.isfinite(theta)):
            raise ValueError(
                f"`theta0` must be a finite vector of shape ({arx.n_params},) for "
                f"{arx}; got {theta0!r}"
            )
    if na == 0:
        # No denominator to filter by: the output error is the equation error.
        return theta
    theta[:na] = step_up(stabilise(theta, arx)[:na])
    for _ in range(int(n_iter)):
        den = np.r_[1.0, theta[:na]]
        filtered = IOData(
            signal.lfilter([1.0], den, data.u),
            signal.lfilter([1.0], den, data.y),
            ts=data.ts,
        )
        phi = arx.regressors(filtered)[t0:]
        # Filtering by a lightly damped 1/A spreads the columns' scales over
        # orders of magnitude: scale them so the rank test stays meaningful.
        scale = np.linalg.norm(phi, axis=0)
        scale[scale == 0.0] = 1.0
        new = np.linalg.lstsq(phi / scale, filtered.y[t0:], rcond=None)[0] / scale
        new[:na] = step_up(stabilise(new, arx)[:na])
        done = np.linalg.norm(new - theta) <= 1e-9 * np.linalg.norm(theta)
        theta = new
        if done:
            break
    return theta
