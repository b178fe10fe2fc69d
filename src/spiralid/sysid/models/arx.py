"""The ARX model structure of eq. (1), (5)-(6): regressors, prediction,
simulation, poles and zeros, and the least-squares estimate.

The model is

    y(t) + a_1 y(t-1) + ... + a_na y(t-na) = b_0 u(t-nk) + ... + b_(nb-1) u(t-nk-nb+1)

with parameter vector ``theta = [a_1..a_na, b_0..b_(nb-1)]``. The paper's
eq. (6) is ``ARX(8, 8, 0)`` (b_0 multiplies z^8, as docs/guide/paper.md reads it); its
printed eq. (9)-(10) have ``nk = 1``.

Initial samples: the first ``t0 = max_lag = max(na, nk + nb - 1)`` samples
of a record serve as initial conditions. The regression matrix of
:meth:`ARX.regressors` has all ``N`` rows (zero for samples before
``t = 0``, so :meth:`ARX.predict` returns ``N`` values), but estimation and
the paper's cost use only rows ``t >= t0``, where every regressor is a
measured sample: :func:`arx_least_squares` is the exact minimiser of that
one-step error, which is the one
:class:`~spiralid.sysid.PaperCost` evaluates. (Zero-filling the first rows
instead makes the least-squares ARX(8, 8, 0) of the real flexible arm
unstable: its record starts in motion.) :meth:`ARX.simulate` is the free
run from zero initial conditions, exactly ``scipy.signal.lfilter``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from scipy import signal

from spiralid._checks import integer

from ..data import IOData, single_output_record
from ..signals import check_signal
from .polynomials import is_stable_polynomial

__all__ = ["ARX", "INITIAL_CONDITIONS", "arx_least_squares", "check_arx"]

# How a free run starts: from rest (zero past samples) or from the record's
# first measured samples.
INITIAL_CONDITIONS = ("rest", "measured")


def check_arx(value, name: str = "arx") -> None:
    """`value` is an ARX structure (its ``family`` is ``"arx"``), or a
    one-line TypeError naming the argument `name`."""
    if getattr(value, "family", None) != "arx":
        raise TypeError(f"`{name}` must be an ARX; got {type(value).__name__}")


@dataclass(frozen=True)
class ARX:
    """ARX(na, nb, nk) structure: ``na`` poles, ``nb`` numerator taps, delay ``nk``.

    Parameters
    ----------
    na : int
        Number of denominator coefficients ``a_1..a_na`` (>= 0).
    nb : int
        Number of numerator coefficients ``b_0..b_(nb-1)`` (>= 1).
    nk : int
        Input delay in samples: ``b_0`` multiplies ``u(t - nk)`` (>= 0).

    Examples
    --------
    >>> import numpy as np
    >>> arx = ARX(2, 2, 1)
    >>> theta = np.array([-1.5, 0.7, 1.0, 0.5])
    >>> arx.n_params
    4
    >>> arx.simulate(theta, [1.0, 0.0, 0.0, 0.0])    # impulse response
    array([0. , 1. , 2. , 2.3])
    >>> print(arx.tf_string(theta))
    (z + 0.5) / (z^2 - 1.5 z + 0.7)
    """

    na: int
    nb: int
    nk: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "na", integer(self.na, "na", 0))
        object.__setattr__(self, "nb", integer(self.nb, "nb", 1))
        object.__setattr__(self, "nk", integer(self.nk, "nk", 0))

    # -- bookkeeping -------------------------------------------------------------

    @property
    def n_params(self) -> int:
        """Length of ``theta``: ``na + nb``."""
        return self.na + self.nb

    #: Linear in the signals: poles, modes and the linear residual tests apply.
    is_linear = True

    #: The family whose estimators fit this structure: the first key of
    #: the estimator table (:data:`~spiralid.sysid.estimation.core.families.
    #: ESTIMATORS`), on a record of one output and of several.
    family = "arx"
    outputs_family = "shared-denominator"

    @property
    def max_lag(self) -> int:
        """Largest lag in the regressors, ``max(na, nk + nb - 1)``."""
        return max(self.na, self.nk + self.nb - 1)

    @property
    def min_samples(self) -> int:
        """Shortest record accepted for estimation: ``max_lag + n_params + 1``."""
        return self.max_lag + self.n_params + 1

    def check_length(self, data: IOData, name: str = "data") -> None:
        """Raise ``ValueError`` if `data` is too short to estimate this structure."""
        if data.n < self.min_samples:
            raise ValueError(
                f"`{name}` is too short for {self}: needs at least {self.min_samples} "
                f"samples ({self.n_params} parameters after {self.max_lag} initial "
                f"samples, plus one); got {data.n}"
            )

    def _theta(self, theta, name: str = "theta") -> tuple[np.ndarray, bool]:
        arr = np.asarray(theta, dtype=float)
        if arr.ndim not in (1, 2) or arr.shape[-1] != self.n_params:
            raise ValueError(
                f"`{name}` must have shape ({self.n_params},) or (m, {self.n_params}) "
                f"for {self}; got shape {arr.shape}"
            )
        return np.atleast_2d(arr), arr.ndim == 1

    def polynomials(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator as coefficient arrays in ``z^-1``.

        Both are padded with trailing zeros to the common length
        ``L = max(na + 1, nk + nb)``, so they are at once the ``lfilter``
        convention (powers of ``z^-1``) and the positive-power convention of
        ``scipy.signal.dlti`` / ``tf2ss`` (multiply through by ``z^(L-1)``).

        Returns
        -------
        num, den : ndarray, shape (L,) or (m, L)
        """
        th, single = self._theta(theta)
        m = th.shape[0]
        L = max(self.na + 1, self.nk + self.nb)
        num = np.zeros((m, L))
        den = np.zeros((m, L))
        den[:, 0] = 1.0
        den[:, 1 : self.na + 1] = th[:, : self.na]
        num[:, self.nk : self.nk + self.nb] = th[:, self.na :]
        return (num[0], den[0]) if single else (num, den)

    # -- signals -----------------------------------------------------------------

    def regressors(self, data: IOData) -> np.ndarray:
        """The regression matrix ``Phi`` of the one-step predictor.

        Row ``t`` is ``[-y(t-1)..-y(t-na), u(t-nk)..u(t-nk-nb+1)]`` with zero
        for every sample before ``t = 0``, so ``y = Phi @ theta + e``.
        Estimation uses rows ``max_lag:`` only (see the module docstring).

        Returns
        -------
        ndarray, shape (N, n_params)
        """
        single_output_record(data, "the ARX regressors")
        u, y = data.u, data.y
        n = u.size
        phi = np.zeros((n, self.n_params))
        for i in range(1, self.na + 1):
            if i < n:
                phi[i:, i - 1] = -y[: n - i]
        for j in range(self.nb):
            lag = self.nk + j
            if lag < n:
                phi[lag:, self.na + j] = u[: n - lag]
        return phi

    def predict(self, theta, data: IOData) -> np.ndarray:
        """One-step-ahead prediction ``Phi @ theta`` (uses measured past outputs).

        The first ``max_lag`` values use zero for samples before ``t = 0``.

        Returns
        -------
        ndarray, shape (N,) or (m, N)
        """
        th, single = self._theta(theta)
        yhat = th @ self.regressors(data).T
        return yhat[0] if single else yhat

    def input_lags(self, u) -> np.ndarray:
        """Lagged inputs ``U[j, t] = u(t - nk - j)``, shape (nb, N), zero before 0."""
        u = check_signal(u, "u")
        n = u.size
        lags = np.zeros((self.nb, n))
        for j in range(self.nb):
            lag = self.nk + j
            if lag < n:
                lags[j, lag:] = u[: n - lag]
        return lags

    def simulate(self, theta, u) -> np.ndarray:
        """Free-run simulation from zero initial conditions (input only).

        Equals ``scipy.signal.lfilter(num, den, u)`` with
        ``num, den = self.polynomials(theta)``.

        Parameters
        ----------
        theta : array_like, shape (p,) or (m, p)
        u : array_like or IOData
            The input signal (an ``IOData`` contributes its ``u``).

        Returns
        -------
        ndarray, shape (N,) or (m, N)
        """
        th, single = self._theta(theta)
        u = u.u if isinstance(u, IOData) else check_signal(u, "u")
        if single:
            num, den = self.polynomials(th[0])
            return signal.lfilter(num, den, u)
        x = th[:, self.na :] @ self.input_lags(u)
        out = np.empty_like(x)
        _ar_filter_batch(x, np.ascontiguousarray(th[:, : self.na]), out)
        return out

    # -- poles and zeros ---------------------------------------------------------

    def poles(self, theta) -> np.ndarray:
        """Poles in z: roots of ``z^(L-1) A(z)`` (including poles at the origin
        when ``nk + nb - 1 > na``).

        Returns
        -------
        ndarray of complex, shape (L-1,) or (m, L-1)
        """
        th, single = self._theta(theta)
        _, den = self.polynomials(th)
        m, L = den.shape
        if L == 1:
            out = np.zeros((m, 0), dtype=complex)
        else:
            comp = np.zeros((m, L - 1, L - 1))
            comp[:, 0, :] = -den[:, 1:]
            idx = np.arange(L - 2)
            comp[:, idx + 1, idx] = 1.0
            out = np.linalg.eigvals(comp).astype(complex)
        return out[0] if single else out

    def zeros(self, theta) -> np.ndarray | list[np.ndarray]:
        """Finite zeros in z: roots of ``z^(L-1) B(z)``.

        A 2-D population gives a list of arrays (the count can vary when a
        leading numerator coefficient is zero).
        """
        th, single = self._theta(theta)
        num, _ = self.polynomials(th)
        out = [np.roots(row).astype(complex) for row in num]
        return out[0] if single else out

    def is_stable(self, theta) -> bool | np.ndarray:
        """Every pole strictly inside the unit circle (Schur-Cohn test)."""
        th, single = self._theta(theta)
        stable = is_stable_polynomial(th[:, : self.na])
        return bool(stable[0]) if single else stable

    def tf_string(self, theta, digits: int = 4, var: str = "z") -> str:
        """The transfer function in positive powers of z, as eq. (9)-(10) print it.

        Examples
        --------
        >>> print(ARX(2, 2, 0).tf_string([-1.5, 0.7, 0.25, -0.125]))
        (0.25 z^2 - 0.125 z) / (z^2 - 1.5 z + 0.7)
        """
        th, single = self._theta(theta)
        if not single:
            raise ValueError(f"`theta` must be a single vector; got shape {th.shape}")
        num, den = self.polynomials(th[0])
        return f"({_poly_str(num, digits, var)}) / ({_poly_str(den, digits, var)})"

    def __str__(self) -> str:
        return f"ARX({self.na}, {self.nb}, {self.nk})"


def _poly_str(coef: np.ndarray, digits: int, var: str) -> str:
    deg = coef.size - 1
    terms = []
    for i, c in enumerate(coef):
        if c == 0:
            continue
        power = deg - i
        mag = abs(c)
        mono = "" if power == 0 else (var if power == 1 else f"{var}^{power}")
        text = f"{mag:.{digits}g}"
        if mono:
            text = mono if mag == 1 else f"{text} {mono}"
        sign = "-" if c < 0 else "+"
        terms.append((sign, text))
    if not terms:
        return "0"
    first_sign, first = terms[0]
    out = ("-" if first_sign == "-" else "") + first
    for sign, text in terms[1:]:
        out += f" {sign} {text}"
    return out


@numba.njit(cache=True)
def _ar_filter_batch(x, a, out):  # pragma: no cover - compiled
    """out[r] = x[r] filtered by 1 / A_r(z^-1), zero initial conditions."""
    m, n = x.shape
    na = a.shape[1]
    for r in range(m):
        for t in range(n):
            acc = x[r, t]
            top = na if t >= na else t
            for i in range(top):
                acc -= a[r, i] * out[r, t - 1 - i]
            out[r, t] = acc


def arx_least_squares(data: IOData, arx: ARX) -> np.ndarray:
    """Least-squares ARX estimate: the exact minimiser of the one-step error.

    Minimises ``sum_{t >= max_lag} (y(t) - phi(t)' theta)^2``, the one-step
    error of :class:`~spiralid.sysid.PaperCost` (eq. (2)); the first
    ``max_lag`` samples are initial conditions.

    Parameters
    ----------
    data : IOData
    arx : ARX

    Returns
    -------
    theta : ndarray, shape (n_params,)

    Raises
    ------
    ValueError
        If the record is too short, the input is constant (it does not excite
        the system) or the regressors are otherwise rank deficient.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(200)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> arx_least_squares(IOData(u, y, ts=1.0), ARX(2, 2, 1)).round(9)
    array([-1.5,  0.7,  1. ,  0.5])
    """
    single_output_record(data, "arx_least_squares")
    check_arx(arx)
    arx.check_length(data)
    if np.ptp(data.u) == 0.0:
        raise ValueError(
            f"`data` has a constant input ({float(data.u[0])!r}): it does not excite "
            f"the system, so no {arx} model can be identified from it"
        )
    t0 = arx.max_lag
    phi = arx.regressors(data)[t0:]
    theta, _, rank, _ = np.linalg.lstsq(phi, data.y[t0:], rcond=None)
    if rank < arx.n_params:
        raise ValueError(
            f"`data` does not excite the system enough for {arx}: the regression "
            f"matrix has rank {rank} < {arx.n_params} parameters"
        )
    return theta
