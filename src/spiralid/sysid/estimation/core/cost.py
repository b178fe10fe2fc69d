"""The paper's cost, eq. (2)-(3): gained RMS error plus a stability penalty.

    f = w * sqrt(sum_t e(t)^2) / K                  all poles |z| < 1      (2)
    f = w * sqrt(sum_t e(t)^2) / K + penalty        otherwise              (3)

How we read it (docs/guide/paper.md, "How we read the paper"):

- ``predictor="simulation"`` (the paper's): ``e`` is the free-run
  simulation error, the model driven by the input alone with its own past
  outputs fed back. Where the run starts is ``initial``:

  ``initial="rest"`` (default, paper-faithful: "the actual input applied
  to the estimated model")
      zero initial conditions at ``t = 0`` (``u`` and the output are zero
      before the record), so ``e = y - lfilter(b, a, u)`` over *all* ``N``
      samples and ``K = N``. Use it for records that start at rest, such as
      the simulated rig's bang-bang experiments, and whenever the model will
      be validated or used from rest.
  ``initial="measured"``
      the free run starts at ``t0 = max_lag = max(na, nk + nb - 1)`` from
      the *measured* past outputs ``y(t0-na)..y(t0-1)`` (the first simulated
      sample equals the first one-step prediction) and ``K = N - t0``
      samples count. Use it only for a record that starts in motion, e.g.
      the real arm (a slice of a periodic sweep), where a zero start leaves
      a transient no parameter can remove. On noisy data it is harmful for
      lightly damped models: the map from the ``na`` measured past outputs
      to the initial state can amplify their noise by orders of magnitude
      (largest singular value ~1.3e4 for ARX(8, 8, 0) models of the rig),
      so the cost then favours models whose start-up transient happens to
      cancel that noise over models that simulate well from rest.

- ``predictor="one-step"``: ``e`` is the equation (one-step prediction)
  error ``y - Phi theta`` over the ``K = N - t0`` samples ``t >= t0``,
  whose regressors are all measured (see :mod:`spiralid.sysid.models.arx`);
  least squares is its exact minimiser. ``initial`` does not affect it.
- ``gain="auto"`` sets ``w = 100 sqrt(K) / rms(y)`` (rms over the same
  ``K`` samples), so ``f`` is the RMS error as a percentage of the RMS of
  the output *as given* (not detrended: detrend the data first if an
  offset should not count). The zero model costs exactly 100.
- Stability is decided from the denominator by the Schur-Cohn test (all
  reflection coefficients ``|k_j| < 1``; a pole on the circle counts as
  unstable) *before* any simulation. An unstable candidate is never
  simulated: its error term in eq. (3) is the one-step error term (the sum
  over ``t >= max_lag``, divided by the cost's ``K``), which is finite for
  every theta. So the penalty is present exactly when a pole has
  ``|z| >= 1``, and the cost is always finite.
"""

from __future__ import annotations

import numba
import numpy as np
from scipy.signal import lfilter, lfiltic

from spiralid._checks import nonneg, one_of, positive

from ...data import IOData, single_output_record
from ...models.arx import ARX, INITIAL_CONDITIONS, check_arx
from ...models.polynomials import is_stable_polynomial

__all__ = [
    "INITIAL_CONDITIONS",
    "PaperCost",
    "auto_gain",
    "cost_of_errors",
    "gain_value",
]


def gain_value(gain, y: np.ndarray) -> float:
    """Eq. (2)'s gain ``w``: :func:`auto_gain` of `y` for ``"auto"``, else
    `gain` checked as a finite number > 0 (a one-line error naming
    ``gain`` otherwise: ValueError for another string or a bad number,
    TypeError for another type)."""
    if isinstance(gain, str):
        if gain != "auto":
            raise ValueError(
                f"`gain` must be 'auto' or a finite number > 0; got {gain!r}"
            )
        return auto_gain(y)
    try:
        return positive(gain, "gain")
    except (TypeError, ValueError) as err:
        raise type(err)(
            f"`gain` must be 'auto' or a finite number > 0; got {gain!r}"
        ) from None


def auto_gain(y: np.ndarray) -> float:
    """``gain="auto"`` of eq. (2): ``w = 100 sqrt(K) / rms(y)`` over the `K`
    samples `y` the error is summed over (so the cost is the RMS error in
    percent of the output's RMS)."""
    rms = float(np.sqrt(np.mean(y * y)))
    if rms == 0.0:
        raise ValueError(
            "`data` has an all-zero output: nothing to fit (`gain` 'auto' is "
            "100 sqrt(K) / rms(y))"
        )
    return 100.0 * np.sqrt(y.size) / rms


def cost_of_errors(errors, w: float, stable, penalty: float):
    """Eq. (2)-(3) from the errors themselves: ``w sqrt(sum e^2) / K`` plus
    `penalty` where not `stable`; `errors` of shape (K,) or (m, K)."""
    e = np.asarray(errors, dtype=float)
    f = (w / e.shape[-1]) * np.sqrt(np.sum(e * e, axis=-1))
    return f + np.where(stable, 0.0, penalty)


_PREDICTORS = ("simulation", "one-step")


class PaperCost:
    """Eq. (2)-(3) for a whole population of ARX parameter vectors at once.

    Parameters
    ----------
    arx : ARX
        Model structure.
    data : IOData
        Estimation record.
    predictor : {"simulation", "one-step"}
        Which output error ``e`` the cost measures.
    gain : "auto" or float
        The gain ``w``; ``"auto"`` is ``100 sqrt(K) / rms(y)`` (percent RMS error).
    penalty : float
        Added when any pole has ``|z| >= 1`` (eq. (3)); >= 0.
    initial : {"rest", "measured"}, default "rest"
        Initial condition of the simulation (ignored by ``"one-step"``).
        ``"rest"``: zero initial conditions, all ``N`` samples scored
        (``K = N``), the paper's reading; right for records that start at
        rest. ``"measured"``: start at ``t0 = max_lag`` from the measured
        past outputs, ``K = N - t0``; only for records that start in motion
        (it amplifies output noise for lightly damped models, see the module
        docstring).

    Attributes
    ----------
    w : float
        The gain actually used.
    K : int
        Number of samples in the sums, ``data.n - t0``.
    t0 : int
        First sample of the sums: ``0`` for a simulation from rest,
        ``arx.max_lag`` otherwise.
    initial : str
        The initial condition of the simulation.
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
        initial: str = "rest",
    ) -> None:
        check_arx(arx)
        single_output_record(data, "PaperCost")
        one_of(predictor, "predictor", _PREDICTORS)
        one_of(initial, "initial", INITIAL_CONDITIONS)
        arx.check_length(data)
        pen = nonneg(penalty, "penalty")
        self.arx = arx
        self.data = data
        self.predictor = predictor
        self.penalty = pen
        self.initial = initial
        lag = arx.max_lag
        from_rest = predictor == "simulation" and initial == "rest"
        self.t0 = 0 if from_rest else lag
        self.K = data.n - self.t0
        y = data.y[self.t0 :]
        self.w = gain_value(gain, y)
        # The one-step error always sums over t >= max_lag (all regressors
        # measured); a simulation from rest only uses it for unstable
        # candidates.
        phi = arx.regressors(data)[lag:]
        y_lag = data.y[lag:]
        self.gram = phi.T @ phi
        self.phity = phi.T @ y_lag
        self.yty = float(y_lag @ y_lag)
        if from_rest:
            # Rest is the measured-past recursion on a record preceded by
            # max_lag zeros: one compiled kernel serves both, and the padded
            # first t0 samples are exactly the zero initial conditions.
            self._y = np.r_[np.zeros(lag), data.y]
            self._u = np.r_[np.zeros(lag), data.u]
        else:
            self._y = np.ascontiguousarray(data.y)
            self._u = np.ascontiguousarray(data.u)
        self._ulags = np.ascontiguousarray(arx.input_lags(data.u)[:, self.t0 :])

    @property
    def n_params(self) -> int:
        return self.arx.n_params

    def __repr__(self) -> str:
        return (
            f"PaperCost({self.arx}, K={self.K}, predictor={self.predictor!r}, "
            f"initial={self.initial!r}, w={self.w:.6g}, penalty={self.penalty:g})"
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
        # y'y - 2 theta'Phi'y + theta'Phi'Phi theta, in one matmul.
        sse = self.yty + np.sum(th * (th @ self.gram - 2.0 * self.phity), axis=1)
        # Rounding can leave a tiny negative where the fit is exact.
        sse = np.maximum(sse, 0.0)
        return float(sse[0]) if single else sse

    def _simulate_sse(self, th: np.ndarray, stable: np.ndarray) -> np.ndarray:
        sse = np.full(th.shape[0], np.inf)
        idx = np.flatnonzero(stable)
        if idx.size:
            sub = th if idx.size == th.shape[0] else th[idx]
            na = self.arx.na
            # Candidates along the fast axis: the recursion's dependency
            # chain runs in time, so the kernel vectorises across candidates.
            out = np.empty(idx.size)
            _arx_sse_kernel(
                self._u,
                np.ascontiguousarray(sub[:, na:].T),
                np.ascontiguousarray(sub[:, :na].T),
                self._y,
                self.arx.max_lag,
                self.arx.nk,
                out,
            )
            sse[idx] = out
        return sse

    def simulate(self, theta) -> np.ndarray:
        """The simulated output the simulation error compares with ``y[t0:]``.

        ``initial="rest"``: ``lfilter(num, den, u)`` over all ``N`` samples;
        ``"measured"``: free run for ``t >= t0`` from the measured past.
        """
        th, single = self._thetas(theta)
        if not single:
            raise ValueError(f"`theta` must be a single vector; got shape {th.shape}")
        na = self.arx.na
        den = np.r_[1.0, th[0, :na]]
        x = th[0, na:] @ self._ulags
        if self.t0 == 0:
            return lfilter([1.0], den, x)
        past = self._y[self.t0 - na : self.t0][::-1]
        zi = lfiltic([1.0], den, past) if na else None
        if zi is None:
            return x
        return lfilter([1.0], den, x, zi=zi)[0]

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
            sse = self._simulate_sse(th, stable)
            if not stable.all():
                # Unstable: not simulated; the error term of eq. (3) is the
                # (finite) one-step error term.
                sse[~stable] = self.sse_one_step(th[~stable])
        f = (self.w / self.K) * np.sqrt(sse)
        f[~stable] += self.penalty
        return float(f[0]) if single else f


@numba.njit(cache=True)
def _arx_sse_kernel(u, b, a, y, t0, nk, sse):  # pragma: no cover - compiled
    """sse[r] = sum_{t >= t0} (y(t) - yhat_r(t))^2 for candidates in columns.

    ``b[j, r]`` is candidate r's ``b_j``, ``a[i, r]`` its ``a_(i+1)``;
    ``A_r(q) yhat(t) = B_r(q) u(t)`` for ``t >= t0`` with ``yhat(t) = y(t)``
    for ``t < t0`` (the measured initial state). The last ``na`` outputs
    live in a ring buffer small enough for L1.
    """
    nb, m = b.shape
    na = a.shape[0]
    k = y.size - t0
    ring = np.empty((max(na, 1), m))
    for i in range(na):
        for r in range(m):
            ring[i, r] = y[t0 - na + i]
    acc = np.empty(m)
    for r in range(m):
        sse[r] = 0.0
    pos = 0  # ring row holding y(t - na)
    for t in range(t0, t0 + k):
        for r in range(m):
            acc[r] = 0.0
        for j in range(nb):
            uj = u[t - nk - j]  # t0 >= nk + nb - 1, so never before 0
            for r in range(m):
                acc[r] += b[j, r] * uj
        for i in range(na):
            row = pos + na - 1 - i  # y(t - 1 - i)
            if row >= na:
                row -= na
            for r in range(m):
                acc[r] -= a[i, r] * ring[row, r]
        yt = y[t]
        for r in range(m):
            d = yt - acc[r]
            sse[r] += d * d
        if na > 0:
            for r in range(m):
                ring[pos, r] = acc[r]
            pos += 1
            if pos == na:
                pos = 0
