"""A fit's covariance when its error is not white.

For a least-squares estimate with error ``e`` and Jacobian ``J = d e / d
theta``, ``s^2 (J'J)^-1`` holds where ``e`` is white. A simulation (output
error) fit's error is the noise as the sensor saw it, and with it whatever
the model leaves out: coloured, often strongly. The estimate's asymptotic
covariance is then the sandwich ``(J'J)^-1 J' R J (J'J)^-1``, ``R`` the
error's covariance (Ljung, *System Identification*, 2nd ed., 1999, sec. 9.3,
the output-error case). Here ``R`` comes from an autoregressive model of
the error, ``A(q) e(t) = w(t)``, ``w`` white of variance ``sigma^2``
(Yule-Walker, order chosen by Akaike's criterion up to :data:`MAX_ORDER`):
``R = sigma^2 H H'`` with ``H`` the impulse response of ``1 / A`` as a
lower-triangular Toeplitz matrix, so ``J' R J = sigma^2 (H'J)' (H'J)``, and
``H'J`` is ``J`` filtered by ``1 / A`` backwards in time.

The model is fitted only where the error fails the Ljung-Box whiteness test
(:data:`LAGS` lags, level :data:`LEVEL`; Ljung and Box, Biometrika 65,
1978), the test ``validate`` reports: an error that passes keeps
``s^2 (J'J)^-1`` exactly.
"""

from __future__ import annotations

import numpy as np
from scipy import linalg, signal, stats

__all__ = ["LAGS", "LEVEL", "MAX_ORDER", "error_gram", "ljung_box", "noise_ar"]

#: Lags and level of the whiteness test that decides whether to model the
#: error's colour.
LAGS = 25
LEVEL = 0.99
#: The autoregressive noise model's largest order (and at most a tenth of
#: the samples).
MAX_ORDER = 32


def ljung_box(r: np.ndarray, n: int) -> float:
    """The Ljung-Box statistic ``Q = n (n + 2) sum_k r_k^2 / (n - k)`` of
    the normalised autocorrelations ``r = (r_1, .., r_L)`` of `n` samples:
    chi-square with ``L`` degrees of freedom for a white sequence.

    Examples
    --------
    >>> round(ljung_box(np.array([0.1, 0.0]), 100), 4)
    1.0303
    """
    k = np.arange(1, r.size + 1)
    return float(n * (n + 2) * np.sum(r**2 / (n - k)))


def _autocovariance(e: np.ndarray, lags: int) -> np.ndarray:
    """The biased (divide by ``N``) autocovariance at lags ``0..lags``
    (``lags < N``): one product a lag, not the full correlation's ``N^2``
    for the few lags used."""
    n = e.size
    return np.array([e[k:] @ e[: n - k] for k in range(lags + 1)]) / n


def noise_ar(e: np.ndarray) -> tuple[np.ndarray, float]:
    """An autoregressive model of `e`: ``(A, sigma^2)`` with ``A = [1, a_1,
    .., a_n]`` (so ``A(q) e = w``) and ``w``'s variance; ``([1], e'e / N)``
    when `e` passes the whiteness test (or is too short to test).

    Examples
    --------
    An AR(1) sequence of unit innovations gives its coefficient back; white
    noise passes the test and is left white:

    >>> rng = np.random.default_rng(0)
    >>> e = signal.lfilter([1.0], [1.0, -0.8], rng.standard_normal(20000))
    >>> a, s2 = noise_ar(e)
    >>> round(float(a[1]), 1), round(s2, 1)
    (-0.8, 1.0)
    >>> noise_ar(rng.standard_normal(2000))[0]
    array([1.])
    """
    n = e.size
    lags = min(LAGS, n - 1)
    centred = _autocovariance(e - e.mean(), max(lags, 0))
    if lags < 1 or centred[0] == 0.0:
        return np.ones(1), float(e @ e) / n
    q = ljung_box(centred[1:] / centred[0], n)
    if q <= stats.chi2.ppf(LEVEL, lags):
        return np.ones(1), float(e @ e) / n
    # The error as it is, mean and all: the mean is error too.
    top = min(MAX_ORDER, n // 10)
    r = _autocovariance(e, top)
    best = (n * np.log(r[0]), np.ones(1), r[0])
    for order in range(1, top + 1):
        a = linalg.solve_toeplitz(r[:order], r[1 : order + 1])
        s2 = r[0] - a @ r[1 : order + 1]
        if s2 <= 0.0:
            break
        aic = n * np.log(s2) + 2 * order
        if aic < best[0]:
            best = (aic, np.r_[1.0, -a], s2)
    return best[1], float(best[2])


def error_gram(e: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """``basis' R basis`` for the covariance ``R`` of the error `e` (shape
    ``(N,)``; `basis` shape ``(N, r)``): ``sigma^2 (H'basis)' (H'basis)``
    under :func:`noise_ar`'s model, ``(e'e / N) basis' basis`` for a white
    error."""
    a, s2 = noise_ar(e)
    if a.size == 1:
        return s2 * (basis.T @ basis)
    back = signal.lfilter([1.0], a, basis[::-1], axis=0)[::-1]
    return s2 * (back.T @ back)
