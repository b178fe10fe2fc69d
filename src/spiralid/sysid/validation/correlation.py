"""Residual correlation tests: whiteness and independence from the input.

A model is adequate when what it leaves unexplained looks like white noise
that owes nothing to the input (Ljung, *System Identification*, 2nd ed.,
1999, section 16.6; MATLAB's ``resid``). Two tests are offered:

* :func:`whiteness_test`: normalised autocorrelation of the residual at lags
  ``1..lags``;
* :func:`independence_test`: normalised cross-correlation between input and
  residual at lags ``-lags..lags`` (both signs, as ``resid`` shows them).

Both return a :class:`CorrelationTest` carrying the correlations, the usual
confidence bands ``+-z/sqrt(N)`` for each level (what one draws and looks at),
and a verdict per level from a joint chi-square statistic. The verdict is joint
rather than "every lag inside the band" because that rule rejects white noise
far too often: with 25 lags at 95 % its false-alarm rate is
``1 - 0.95**25 = 72 %``. The joint statistics have false-alarm rate
``1 - level`` under the null hypothesis. A test with no degrees of freedom
(a constant input) has nothing to test: its verdicts are None and
:attr:`CorrelationTest.applicable` is False, so it reads "not applicable",
never "pass".
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import linalg, stats

from ..estimation.core.coloured import ljung_box
from ..signals import check_pair, check_signal

__all__ = [
    "CorrelationTest",
    "correlation",
    "independence_test",
    "whiteness_test",
]

_DEFAULT_LEVELS = (0.95, 0.99)


@dataclass(frozen=True)
class CorrelationTest:
    """Outcome of a residual correlation test.

    Attributes
    ----------
    kind : str
        ``"autocorrelation"`` (whiteness) or ``"cross-correlation"``
        (input-residual independence).
    lags : ndarray of int
        Lags at which the correlation was evaluated.
    values : ndarray
        Normalised correlation at those lags (in [-1, 1]).
    n_samples : int
        Record length N.
    levels : tuple of float
        Confidence levels, e.g. ``(0.95, 0.99)``.
    bands : dict
        ``{level: z / sqrt(N)}`` with ``z`` the two-sided normal quantile: the
        band a single lag of a white residual stays inside with probability
        ``level``.
    n_outside : dict
        ``{level: number of lags outside the band}``.
    statistic : float
        Joint test statistic (chi-square distributed with ``dof`` degrees of
        freedom under the null hypothesis).
    dof : int
        Degrees of freedom of ``statistic``.
    p_value : float
        ``P(chi2(dof) >= statistic)`` (1 when ``dof`` is 0).
    passed : dict
        ``{level: statistic <= chi2.ppf(level, dof)}``; ``{level: None}``
        when the test has no degrees of freedom (see :attr:`applicable`).
    band_scale : float
        Standard deviation of a single correlation under the null hypothesis,
        in units of ``1/sqrt(N)``: 1 for the whiteness test; for the
        cross-correlation test ``sqrt(P_00)`` from Bartlett's formula, larger
        than 1 when both the input and the residual are coloured.
        ``band_scale * bands[level]`` is the per-lag band that accounts for
        that colour (what the verdict effectively uses).
    """

    kind: str
    lags: np.ndarray
    values: np.ndarray
    n_samples: int
    levels: tuple[float, ...]
    bands: dict[float, float]
    n_outside: dict[float, int]
    statistic: float
    dof: int
    p_value: float
    passed: dict[float, bool | None] = field(default_factory=dict)
    band_scale: float = 1.0

    @property
    def applicable(self) -> bool:
        """Whether the test has anything to test: False with no degrees of
        freedom (a constant input, or the ``u^2`` of a binary one, is
        uncorrelated with anything), when its verdicts are None, neither
        pass nor fail."""
        return self.dof > 0

    def to_dict(self) -> dict:
        """JSON-safe dictionary (level keys become strings such as ``"0.95"``;
        a test that does not apply has ``"applicable": false`` and null
        verdicts)."""
        return {
            "kind": self.kind,
            "lags": [int(k) for k in self.lags],
            "values": [float(v) for v in self.values],
            "n_samples": int(self.n_samples),
            "levels": [float(lv) for lv in self.levels],
            "bands": {str(k): float(v) for k, v in self.bands.items()},
            "n_outside": {str(k): int(v) for k, v in self.n_outside.items()},
            "statistic": float(self.statistic),
            "dof": int(self.dof),
            "p_value": float(self.p_value),
            "passed": {
                str(k): None if v is None else bool(v) for k, v in self.passed.items()
            },
            "band_scale": float(self.band_scale),
            "applicable": self.applicable,
        }


def check_lags(lags, n: int) -> int:
    if isinstance(lags, bool) or not isinstance(lags, int | np.integer):
        raise ValueError(f"`lags` must be an integer; got {lags!r}")
    if lags >= 1 and lags >= n:
        # The record, not the number of lags, is what a user usually has
        # wrong: say so first.
        raise ValueError(
            f"the record is too short for the residual tests: `lags` must be in "
            f"[1, N - 1] = [1, {n - 1}] for a record of N = {n} samples; "
            f"got {lags!r}"
        )
    if not 1 <= lags < n:
        raise ValueError(
            f"`lags` must be in [1, N - 1] = [1, {n - 1}] for a record of "
            f"N = {n} samples; got {lags!r}"
        )
    return int(lags)


def _check_levels(levels) -> tuple[float, ...]:
    try:
        out = tuple(float(lv) for lv in levels)
    except TypeError:
        raise ValueError(
            f"`levels` must be a sequence of floats in (0, 1); got {levels!r}"
        ) from None
    if not out or not all(0.0 < lv < 1.0 for lv in out):
        raise ValueError(f"`levels` must be floats in (0, 1); got {levels!r}")
    return out


def correlation(a, b, max_lag: int) -> np.ndarray:
    """Normalised cross-correlation ``r_ab(k)`` for ``k = -max_lag..max_lag``.

    ``r_ab(k) = sum_t a(t) b(t - k) / sqrt(sum a^2 sum b^2)`` after removing
    each signal's mean: the biased (divide-by-N) estimator Ljung (1999,
    eq. (16.61)) and MATLAB's ``resid`` use, so ``r_aa(0) = 1`` and ``|r| <= 1``.
    Positive ``k`` relates ``a`` now to ``b`` in the past.

    Parameters
    ----------
    a, b : array_like, shape (N,)
        Signals of equal length.
    max_lag : int
        Largest lag, ``1 <= max_lag < N``.

    Returns
    -------
    ndarray, shape (2 * max_lag + 1,)
        Correlations at lags ``-max_lag..max_lag``.

    Examples
    --------
    >>> import numpy as np
    >>> r = correlation([1.0, 2.0, 3.0, 4.0], [1.0, 2.0, 3.0, 4.0], 1)
    >>> np.round(r, 4).tolist()
    [0.25, 1.0, 0.25]
    """
    a, b = check_pair(a, b, "a", "b")
    n = a.size
    max_lag = check_lags(max_lag, n)
    a = a - a.mean()
    b = b - b.mean()
    # Norms, not the product of the squared sums, which overflows first.
    scale = float(np.linalg.norm(a) * np.linalg.norm(b))
    out = np.zeros(2 * max_lag + 1)
    if scale == 0.0:
        # A constant signal is uncorrelated with anything; report zeros rather
        # than NaN so that the tests below can still give a verdict.
        return out
    for i, k in enumerate(range(-max_lag, max_lag + 1)):
        if k >= 0:
            out[i] = np.dot(a[k:], b[: n - k])
        else:
            out[i] = np.dot(a[: n + k], b[-k:])
    return out / scale


def _bands(levels, n):
    return {lv: float(stats.norm.ppf(0.5 + lv / 2.0) / np.sqrt(n)) for lv in levels}


def _finish(
    kind, lags, values, n, levels, statistic, dof, band_scale=1.0
) -> CorrelationTest:
    bands = _bands(levels, n)
    p_value = float(stats.chi2.sf(statistic, dof)) if dof > 0 else 1.0
    return CorrelationTest(
        kind=kind,
        lags=lags,
        values=values,
        n_samples=n,
        levels=levels,
        bands=bands,
        n_outside={lv: int(np.sum(np.abs(values) > b)) for lv, b in bands.items()},
        statistic=float(statistic),
        dof=int(dof),
        p_value=p_value,
        # No degrees of freedom: a statistic of 0 "passes" any level, but
        # there was nothing to test, so the verdict is None, not True.
        passed={
            lv: bool(statistic <= stats.chi2.ppf(lv, dof)) if dof > 0 else None
            for lv in levels
        },
        band_scale=float(band_scale),
    )


def whiteness_test(e, lags: int = 25, levels=_DEFAULT_LEVELS) -> CorrelationTest:
    """Test whether a residual is white from its autocorrelation.

    The verdict uses the Ljung-Box statistic
    ``Q = N (N + 2) sum_{k=1}^{L} r(k)^2 / (N - k)``, chi-square with ``L``
    degrees of freedom for a white residual (Ljung & Box, Biometrika 65, 1978;
    Ljung 1999, section 16.6 gives the ``N sum r^2`` form it refines).

    Parameters
    ----------
    e : array_like, shape (N,)
        Residual (prediction or simulation error).
    lags : int, default 25
        Lags ``1..lags`` are tested; ``1 <= lags < N``.
    levels : sequence of float, default (0.95, 0.99)
        Confidence levels for the bands and verdicts.

    Returns
    -------
    CorrelationTest

    Examples
    --------
    >>> import numpy as np
    >>> e = np.random.default_rng(0).standard_normal(1000)
    >>> t = whiteness_test(e)
    >>> t.passed[0.95], round(t.bands[0.95], 4)
    (True, 0.062)
    """
    e = check_signal(e, "e")
    n = e.size
    lags = check_lags(lags, n)
    levels = _check_levels(levels)
    r = correlation(e, e, lags)[lags + 1 :]
    k = np.arange(1, lags + 1)
    return _finish("autocorrelation", k, r, n, levels, ljung_box(r, n), lags)


def independence_test(
    u, e, lags: int = 25, levels=_DEFAULT_LEVELS, *, rtol: float = 1e-6
) -> CorrelationTest:
    """Test whether a residual is independent of the input.

    Correlations ``r_eu(k)`` are taken at lags ``k = -lags..lags``, the two
    signs MATLAB's ``resid`` shows: ``k > 0`` relates the residual to past
    inputs (dynamics the model missed), ``k < 0`` to future inputs (feedback
    in the data). The bands are ``+-z/sqrt(N)``, exact for a white residual.

    The verdict uses ``zeta = N r^T P^+ r``, chi-square with ``rank(P)``
    degrees of freedom (Ljung 1999, section 16.6). ``P`` is the large-sample
    covariance of ``sqrt(N) r`` for a residual independent of the input
    (Bartlett's formula), ``P_ij = sum_{|m|<=L} rho_e(m) rho_u(m + k_i - k_j)``,
    so the test stays calibrated when the input or the residual is coloured
    (a sine sweep makes neighbouring lags strongly correlated, and treating
    them as independent would reject good models). Eigen-directions of ``P``
    below ``rtol`` times its largest eigenvalue carry no information and are
    dropped from the statistic and its degrees of freedom.

    Parameters
    ----------
    u : array_like, shape (N,)
        Input signal.
    e : array_like, shape (N,)
        Residual.
    lags : int, default 25
        Largest absolute lag; ``1 <= lags < N``.
    levels : sequence of float, default (0.95, 0.99)
        Confidence levels.
    rtol : float, default 1e-6
        Relative eigenvalue cut-off for the pseudo-inverse of ``P``.

    Returns
    -------
    CorrelationTest

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal(1000)
    >>> independence_test(u, rng.standard_normal(1000)).passed[0.95]
    True
    >>> independence_test(u, np.convolve(u, [0.0, 1.0, 0.5])[:1000]).passed[0.99]
    False
    """
    u, e = check_pair(u, e, "u", "e")
    n = e.size
    lags = check_lags(lags, n)
    levels = _check_levels(levels)
    if not (np.isfinite(rtol) and 0.0 < rtol < 1.0):
        raise ValueError(f"`rtol` must be in (0, 1); got {rtol!r}")
    r = correlation(e, u, lags)
    k = np.arange(-lags, lags + 1)
    # rho_u is needed up to lag 3L: m (|m| <= L) plus k_i - k_j (|.| <= 2L).
    big = min(3 * lags, n - 1)
    rho_u = np.zeros(6 * lags + 1)
    rho_u[3 * lags - big : 3 * lags + big + 1] = correlation(u, u, big)
    rho_e = correlation(e, e, lags)
    d = k[:, None] - k[None, :]
    m = np.arange(-lags, lags + 1)
    cov = np.einsum("m,ijm->ij", rho_e, rho_u[3 * lags + d[..., None] + m])
    cov = 0.5 * (cov + cov.T)
    w, v = linalg.eigh(cov)
    keep = w > rtol * max(w.max(), 0.0)
    scale = float(np.sqrt(max(cov[lags, lags], 0.0)))
    if not keep.any():
        return _finish("cross-correlation", k, r, n, levels, 0.0, 0, scale)
    proj = v[:, keep].T @ r
    zeta = n * float(np.sum(proj**2 / w[keep]))
    return _finish("cross-correlation", k, r, n, levels, zeta, int(keep.sum()), scale)
