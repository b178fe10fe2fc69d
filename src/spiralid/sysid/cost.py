"""The paper's cost, eq. (2)-(3): gained RMS error plus a stability penalty.

    f = w * sqrt(sum_t e(t)^2) / K                  all poles |z| < 1      (2)
    f = w * sqrt(sum_t e(t)^2) / K + penalty        otherwise              (3)

How we read it (DESIGN.md items 2-3):

- ``gain="auto"`` sets ``w = 100 sqrt(K) / rms(y)``, so ``f`` is the RMS
  error as a percentage of the RMS of the output *as given* (not detrended:
  detrend the data first if an offset should not count).
- ``predictor="simulation"``: ``e`` is the free-run simulation error from
  the input alone; ``"one-step"``: ``e`` is the equation (one-step
  prediction) error ``y - Phi theta``. Both sum over all ``K = N`` samples
  with zero initial conditions (see :mod:`spiralid.sysid.arx`).
- Stability is decided from the denominator (Schur-Cohn test, exact for
  ``|z| >= 1``) *before* any simulation. An unstable candidate is never
  simulated: its error term in eq. (3) is the one-step error term, which
  is finite for every theta. So the penalty is present exactly when a pole
  has ``|z| >= 1``, and the cost is always finite.
"""

from __future__ import annotations

import numba
import numpy as np

from .arx import ARX
from .data import IOData
from .polynomials import is_stable_polynomial

__all__ = ["PaperCost"]

_PREDICTORS = ("simulation", "one-step")


class PaperCost:
    """Eq. (2)-(3) for a whole population of ARX parameter vectors at once.

    Parameters
    ----------
    arx : ARX
        Model structure.
    data : IOData
        Estimation record (``K = data.n`` samples).
    predictor : {"simulation", "one-step"}
        Which output error ``e`` the cost measures.
    gain : "auto" or float
        The gain ``w``; ``"auto"`` is ``100 sqrt(K) / rms(y)`` (percent RMS error).
    penalty : float
        Added when any pole has ``|z| >= 1`` (eq. (3)); >= 0.

    Attributes
    ----------
    w : float
        The gain actually used.
    K : int
        Number of samples.
    gram, phity, yty
        ``Phi' Phi``, ``Phi' y`` and ``y' y``: the one-step error is
        ``y'y - 2 theta' Phi'y + theta' Phi'Phi theta``, O(p^2) per candidate.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> from spiralid.sysid import ARX, IOData
    >>> u = np.random.default_rng(0).standard_normal(300)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> cost = PaperCost(ARX(2, 2, 1), IOData(u, y, ts=1.0))
    >>> round(float(cost([-1.5, 0.7, 1.0, 0.5])), 9)   # the true model: zero error
    0.0
    >>> round(float(cost([0.0, 0.0, 0.0, 0.0])), 9)    # zero output: 100 % error
    100.0
    >>> cost([[-1.5, 0.7, 1.0, 0.5], [-2.0, 1.5, 1.0, 0.5]]) > 1e6   # 2nd unstable
    array([False,  True])
    """

    def __init__(
        self,
        arx: ARX,
        data: IOData,
        predictor: str = "simulation",
        gain: str | float = "auto",
        penalty: float = 1e6,
    ) -> None:
        if not isinstance(arx, ARX):
            raise ValueError(f"`arx` must be an ARX; got {type(arx).__name__}")
        if not isinstance(data, IOData):
            raise ValueError(f"`data` must be an IOData; got {type(data).__name__}")
        if predictor not in _PREDICTORS:
            raise ValueError(
                f"`predictor` must be one of {_PREDICTORS}; got {predictor!r}"
            )
        arx.check_length(data)
        try:
            pen = float(penalty)
        except (TypeError, ValueError):
            raise ValueError(
                f"`penalty` must be a finite number >= 0; got {penalty!r}"
            ) from None
        if not (np.isfinite(pen) and pen >= 0):
            raise ValueError(f"`penalty` must be a finite number >= 0; got {penalty!r}")
        self.arx = arx
        self.data = data
        self.predictor = predictor
        self.penalty = pen
        self.K = data.n
        y = data.y
        if isinstance(gain, str):
            if gain != "auto":
                raise ValueError(
                    f"`gain` must be 'auto' or a positive number; got {gain!r}"
                )
            rms = float(np.sqrt(np.mean(y * y)))
            if rms == 0.0:
                raise ValueError(
                    "`gain` 'auto' needs a non-zero output; `data.y` is all zero"
                )
            self.w = 100.0 * np.sqrt(self.K) / rms
        else:
            try:
                w = float(gain)
            except (TypeError, ValueError):
                raise ValueError(
                    f"`gain` must be 'auto' or a positive number; got {gain!r}"
                ) from None
            if not (np.isfinite(w) and w > 0):
                raise ValueError(
                    f"`gain` must be 'auto' or a positive number; got {gain!r}"
                )
            self.w = w
        phi = arx.regressors(data)
        self.gram = phi.T @ phi
        self.phity = phi.T @ y
        self.yty = float(y @ y)
        self._y = np.ascontiguousarray(y)
        self._ulags = arx.input_lags(data.u)

    @property
    def n_params(self) -> int:
        return self.arx.n_params

    def __repr__(self) -> str:
        return (
            f"PaperCost({self.arx}, K={self.K}, predictor={self.predictor!r}, "
            f"w={self.w:.6g}, penalty={self.penalty:g})"
        )

    def _thetas(self, thetas):
        arr = np.asarray(thetas, dtype=float)
        p = self.n_params
        if arr.ndim not in (1, 2) or arr.shape[-1] != p:
            raise ValueError(
                f"`thetas` must have shape ({p},) or (m, {p}); got shape {arr.shape}"
            )
        return np.atleast_2d(arr), arr.ndim == 1

    def stable(self, thetas) -> np.ndarray | bool:
        """True where every pole has ``|z| < 1`` (no penalty)."""
        th, single = self._thetas(thetas)
        ok = is_stable_polynomial(th[:, : self.arx.na])
        return bool(ok[0]) if single else ok

    def sse_one_step(self, thetas) -> np.ndarray | float:
        """``sum e^2`` of the one-step error via the Gram matrix, O(p^2) each."""
        th, single = self._thetas(thetas)
        quad = np.einsum("ij,jk,ik->i", th, self.gram, th, optimize=False)
        sse = self.yty - 2.0 * (th @ self.phity) + quad
        # Rounding can leave a tiny negative where the fit is exact.
        sse = np.maximum(sse, 0.0)
        return float(sse[0]) if single else sse

    def sse_simulation(self, thetas) -> np.ndarray | float:
        """``sum e^2`` of the simulation error; ``inf`` for unstable candidates
        (they are not simulated)."""
        th, single = self._thetas(thetas)
        stable = is_stable_polynomial(th[:, : self.arx.na])
        sse = np.full(th.shape[0], np.inf)
        if stable.any():
            x = th[:, self.arx.na :] @ self._ulags
            _ar_filter_sse(
                x, np.ascontiguousarray(th[:, : self.arx.na]), self._y, stable, sse
            )
        return float(sse[0]) if single else sse

    def __call__(self, thetas) -> np.ndarray | float:
        """Evaluate eq. (2)-(3).

        Parameters
        ----------
        thetas : array_like, shape (p,) or (m, p)

        Returns
        -------
        float or ndarray, shape (m,)
        """
        th, single = self._thetas(thetas)
        stable = is_stable_polynomial(th[:, : self.arx.na])
        if self.predictor == "one-step":
            sse = self.sse_one_step(th)
        else:
            sse = np.empty(th.shape[0])
            if stable.any():
                x = th[:, self.arx.na :] @ self._ulags
                _ar_filter_sse(
                    x, np.ascontiguousarray(th[:, : self.arx.na]), self._y, stable, sse
                )
            if not stable.all():
                # Unstable: not simulated; the error term of eq. (3) is the
                # (finite) one-step error term.
                sse[~stable] = self.sse_one_step(th[~stable])
        f = self.w * np.sqrt(sse) / self.K + np.where(stable, 0.0, self.penalty)
        return float(f[0]) if single else f


@numba.njit(cache=True)
def _ar_filter_sse(x, a, y, mask, sse):  # pragma: no cover - compiled
    """sse[r] = ||y - x[r] / A_r||^2 for rows with mask[r]; others untouched."""
    m, n = x.shape
    na = a.shape[1]
    buf = np.zeros(n + na)
    for r in range(m):
        if not mask[r]:
            continue
        for i in range(na):
            buf[i] = 0.0
        acc_sse = 0.0
        for t in range(n):
            acc = x[r, t]
            for i in range(na):
                acc -= a[r, i] * buf[na + t - 1 - i]
            buf[na + t] = acc
            d = y[t] - acc
            acc_sse += d * d
        sse[r] = acc_sse
