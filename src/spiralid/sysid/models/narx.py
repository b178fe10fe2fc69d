"""NARX models: a nonlinear map of past outputs and inputs.

``y(t) = F(y(t-1)..y(t-ny), u(t-nk)..u(t-nk-nu+1)) + e(t)``

Two maps are built:

* :class:`NARX`: a multilayer perceptron with one hidden layer
  (``hidden=(h,)``), an activation (``"tanh"``, ``"logistic"`` or
  ``"linear"``) and, by default, a linear bypass beside the network
  (``linear=True``: ``F = l^T phi + v^T sigma(W phi + b) + c``). The bypass is
  the ARX model, so a network whose output weights are zero is exactly the
  least-squares ARX and training starts from it (see
  :mod:`spiralid.sysid.estimation.narx`).
* :class:`PolynomialNARX`: a sum of monomials of the regressors up to
  ``degree`` whose terms are chosen by forward-regression orthogonal least
  squares (Billings, *Nonlinear System Identification*, Wiley, 2013, ch. 3),
  the classical baseline.

Signals are scaled before they reach the map (:class:`Scaling`: input and
output minus their estimation-record mean, over their standard deviation),
so the weights of one record are comparable with another's and a
metaheuristic's box need not depend on units. ``integrator=True`` (the
hub angle) makes the map predict the output's increment from past
increments, ``y(t) = y(t-1) + F(dy(t-1)..dy(t-ny), u...)``: the NARX
analogue of ARX's known pole at z = 1.

Free run and one-step prediction run on the scaled signals in compiled
loops (Numba), vectorised over a population of parameter vectors for the
searches. "From rest" means every signal is zero (in physical units)
before ``t = 0``, as for ARX; "from measured samples" takes the first
``max_lag`` measured outputs as the initial history.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numba
import numpy as np

from ..data import IOData, check_signal, single_output_record
from . import _fields

__all__ = [
    "ACTIVATIONS",
    "NARX",
    "NARXModel",
    "PolynomialNARX",
    "Scaling",
]

# The one list of activations; the code is the compiled kernels' switch.
ACTIVATIONS = {"tanh": 0, "logistic": 1, "linear": 2}


def _integrators(value) -> int:
    """`integrator` as a count 0, 1 or 2 (False and True are 0 and 1)."""
    if isinstance(value, bool | np.bool_):
        return int(value)
    if isinstance(value, int | np.integer) and 0 <= value <= 2:
        return int(value)
    raise ValueError(f"`integrator` must be False, True, 0, 1 or 2; got {value!r}")


def _order(value, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ValueError(f"`{name}` must be an integer >= {minimum}; got {value!r}")
    if value < minimum:
        raise ValueError(f"`{name}` must be an integer >= {minimum}; got {value!r}")
    return int(value)


@dataclass(frozen=True)
class Scaling:
    """Affine scaling of the signals: ``(u - u_shift) / u_scale`` and the
    same for the output (for an integrating model, of its increment).

    Parameters
    ----------
    u_shift, u_scale, y_shift, y_scale : float
        Shifts and (positive) scales.
    """

    u_shift: float = 0.0
    u_scale: float = 1.0
    y_shift: float = 0.0
    y_scale: float = 1.0

    @classmethod
    def from_data(cls, data: IOData, integrator: bool = False) -> Scaling:
        """Mean and standard deviation of the estimation record's signals
        (of the output's increments for an integrating model, unshifted so
        that rest stays zero).

        Parameters
        ----------
        data : IOData
            Estimation record.
        integrator : bool
            Scale the output's increments instead of the output.
        """
        u, y = data.u, data.y
        us = float(np.std(u)) or 1.0
        if integrator:
            d = np.diff(y, prepend=0.0)
            return cls(float(np.mean(u)), us, 0.0, float(np.std(d)) or 1.0)
        return cls(float(np.mean(u)), us, float(np.mean(y)), float(np.std(y)) or 1.0)


# -- compiled kernels ---------------------------------------------------------


@numba.njit(cache=True, inline="always")
def _act(z, kind):  # pragma: no cover - compiled
    if kind == 0:
        return math.tanh(z)
    if kind == 1:
        return 1.0 / (1.0 + math.exp(-z))
    return z


@numba.njit(cache=True, inline="always")
def _dact(a, kind):  # pragma: no cover - compiled
    """Derivative from the activation's value."""
    if kind == 0:
        return 1.0 - a * a
    if kind == 1:
        return a * (1.0 - a)
    return 1.0


@numba.njit(cache=True)
def _mlp_free_run(
    P, ulag, hist, ny, h, kind, linear, out
):  # pragma: no cover - compiled
    """Free run of every parameter row of ``P``: ``out[j, t]``.

    ``hist`` holds the ``ny`` scaled outputs before ``t = 0`` (oldest
    first); ``ulag[t]`` the scaled input regressors of step ``t``.
    """
    m = P.shape[0]
    n_t = ulag.shape[0]
    nu = ulag.shape[1]
    n = ny + nu
    ob = h * n
    ov = ob + h
    oc = ov + h
    ol = oc + 1
    reg = np.empty(n)
    past = np.empty(n_t + ny)
    for j in range(m):
        for i in range(ny):
            past[i] = hist[i]
        for t in range(n_t):
            for i in range(ny):
                reg[i] = past[ny + t - 1 - i]
            for i in range(nu):
                reg[ny + i] = ulag[t, i]
            s = P[j, oc]
            if linear:
                for i in range(n):
                    s += P[j, ol + i] * reg[i]
            for k in range(h):
                z = P[j, ob + k]
                row = k * n
                for i in range(n):
                    z += P[j, row + i] * reg[i]
                s += P[j, ov + k] * _act(z, kind)
            if not math.isfinite(s) or abs(s) > 1e150:
                # A diverging candidate (linear activation) is cut off here
                # rather than overflowing; its cost is then infinite.
                for r in range(t, n_t):
                    out[j, r] = np.inf
                break
            out[j, t] = s
            past[ny + t] = s


@numba.njit(cache=True, inline="always")
def _fill_regressors(reg, past, ulag, t, ny):  # pragma: no cover - compiled
    """Step ``t``'s regressors: the ``ny`` outputs before it, newest first,
    then its inputs."""
    for i in range(ny):
        reg[i] = past[ny + t - 1 - i]
    for i in range(ulag.shape[1]):
        reg[ny + i] = ulag[t, i]


@numba.njit(cache=True, inline="always")
def _mlp_output(p, reg, h, kind, linear, act):  # pragma: no cover - compiled
    """The network's output at ``reg``, its hidden activations left in
    ``act`` for the derivatives."""
    n = reg.size
    ob = h * n
    ov = ob + h
    oc = ov + h
    ol = oc + 1
    s = p[oc]
    if linear:
        for i in range(n):
            s += p[ol + i] * reg[i]
    for k in range(h):
        z = p[ob + k]
        row = k * n
        for i in range(n):
            z += p[row + i] * reg[i]
        act[k] = _act(z, kind)
        s += p[ov + k] * act[k]
    return s


@numba.njit(cache=True, inline="always")
def _direct_sensitivity(
    p, reg, act, h, kind, linear, grad
):  # pragma: no cover - compiled
    """``grad = d out / d p`` with the regressors held fixed."""
    n = reg.size
    ob = h * n
    ov = ob + h
    oc = ov + h
    ol = oc + 1
    for q in range(p.size):
        grad[q] = 0.0
    for k in range(h):
        g = p[ov + k] * _dact(act[k], kind)
        row = k * n
        for i in range(n):
            grad[row + i] = g * reg[i]
        grad[ob + k] = g
        grad[ov + k] = act[k]
    grad[oc] = 1.0
    if linear:
        for i in range(n):
            grad[ol + i] = reg[i]


@numba.njit(cache=True, inline="always")
def _feedback_sensitivity(
    p, act, h, kind, linear, n, ny, t, dreg, sens
):  # pragma: no cover - compiled
    """Add to ``sens[t]`` the chain through the ``ny`` fed-back outputs:
    ``d out[t] / d reg[i]`` times the earlier ``sens[t - 1 - i]``."""
    ol = h * n + 2 * h + 1
    ov = h * n + h
    for i in range(ny):
        d = p[ol + i] if linear else 0.0
        for k in range(h):
            d += p[ov + k] * _dact(act[k], kind) * p[k * n + i]
        dreg[i] = d
    for i in range(ny):
        if t - 1 - i < 0 or dreg[i] == 0.0:
            continue
        for q in range(p.size):
            sens[t, q] += dreg[i] * sens[t - 1 - i, q]


@numba.njit(cache=True)
def _mlp_sensitivity(
    p, ulag, hist, ny, h, kind, linear, out, sens
):  # pragma: no cover - compiled
    """Free run of one parameter vector and its exact Jacobian
    ``sens[t] = d out[t] / d p`` by forward sensitivity (real-time
    recurrent learning): the direct derivative plus the chain through the
    ``ny`` fed-back outputs."""
    n_t = ulag.shape[0]
    n = ny + ulag.shape[1]
    reg = np.empty(n)
    act = np.empty(h)
    dreg = np.empty(ny)  # d out[t] / d reg[i] for the fed-back outputs
    past = np.empty(n_t + ny)
    for i in range(ny):
        past[i] = hist[i]
    for t in range(n_t):
        _fill_regressors(reg, past, ulag, t, ny)
        s = _mlp_output(p, reg, h, kind, linear, act)
        out[t] = s
        past[ny + t] = s
        _direct_sensitivity(p, reg, act, h, kind, linear, sens[t])
        _feedback_sensitivity(p, act, h, kind, linear, n, ny, t, dreg, sens)


@numba.njit(cache=True)
def _poly_free_run(coef, terms, ulag, hist, ny, out):  # pragma: no cover - compiled
    """Free run of a polynomial NARX: ``sum_j coef[j] prod_d reg[terms[j, d]]``
    with index 0 the constant 1 and ``i >= 1`` regressor ``i - 1``."""
    n_t = ulag.shape[0]
    nu = ulag.shape[1]
    n = ny + nu
    reg = np.empty(n + 1)
    reg[0] = 1.0
    past = np.empty(n_t + ny)
    for i in range(ny):
        past[i] = hist[i]
    for t in range(n_t):
        for i in range(ny):
            reg[1 + i] = past[ny + t - 1 - i]
        for i in range(nu):
            reg[1 + ny + i] = ulag[t, i]
        s = 0.0
        for j in range(coef.size):
            v = coef[j]
            for d in range(terms.shape[1]):
                v *= reg[terms[j, d]]
            s += v
        if not math.isfinite(s) or abs(s) > 1e150:
            for r in range(t, n_t):
                out[r] = np.inf
            break
        out[t] = s
        past[ny + t] = s


# -- structures ---------------------------------------------------------------


class _Lags:
    """What both structures share: lags, scaled signals and regressors."""

    ny: int
    nu: int
    nk: int
    integrator: bool

    @property
    def n_regressors(self) -> int:
        """``ny + nu``: past outputs (or increments) and inputs."""
        return self.ny + self.nu

    @property
    def max_lag(self) -> int:
        """Samples of measured history the first full regressor needs."""
        return max(self.ny + int(self.integrator > 0), self.nk + self.nu - 1)

    def check_length(self, data: IOData, name: str = "data") -> None:
        """Raise ``ValueError`` if `data` is too short for this structure.

        Parameters
        ----------
        data : IOData
        name : str
            The argument's name in the message.
        """
        need = self.max_lag + self.n_params + 1
        if data.n < need:
            raise ValueError(
                f"`{name}` is too short for {self}: needs at least {need} samples "
                f"({self.n_params} parameters after {self.max_lag} initial "
                f"samples, plus one); got {data.n}"
            )

    def _target(self, y: np.ndarray, s: Scaling) -> np.ndarray:
        """The scaled signal the map predicts (output or its increment)."""
        if self.integrator:
            return np.diff(y, prepend=0.0) / s.y_scale
        return (y - s.y_shift) / s.y_scale

    def input_lags(self, u: np.ndarray, s: Scaling) -> np.ndarray:
        """Scaled input regressors ``U[t, j] = u~(t - nk - j)``, rest before 0.

        Parameters
        ----------
        u : ndarray, shape (N,)
        s : Scaling
        """
        n = u.size
        us = (np.r_[np.zeros(self.nk + self.nu), u] - s.u_shift) / s.u_scale
        off = self.nk + self.nu
        out = np.empty((n, self.nu))
        for j in range(self.nu):
            lag = self.nk + j
            out[:, j] = us[off - lag : off - lag + n]
        return out

    def rest_history(self, s: Scaling) -> np.ndarray:
        """The ``ny`` scaled past outputs of a system at rest.

        Parameters
        ----------
        s : Scaling
        """
        z0 = 0.0 if self.integrator else (0.0 - s.y_shift) / s.y_scale
        return np.full(self.ny, z0)

    def regressors(self, u, y, s: Scaling) -> tuple[np.ndarray, np.ndarray]:
        """One-step regressors from measured signals and the scaled target.

        Parameters
        ----------
        u, y : ndarray, shape (N,)
            Measured input and output.
        s : Scaling

        Returns
        -------
        phi : ndarray, shape (N, ny + nu)
        target : ndarray, shape (N,)
        """
        z = self._target(y, s)
        n = z.size
        zp = np.r_[self.rest_history(s)[::-1], z]
        phi = np.empty((n, self.n_regressors))
        for i in range(self.ny):
            phi[:, i] = zp[self.ny - 1 - i : self.ny - 1 - i + n]
        phi[:, self.ny :] = self.input_lags(u, s)
        return phi, z

    def _unscale(self, z: np.ndarray, s: Scaling, y0: float = 0.0) -> np.ndarray:
        if self.integrator:
            return y0 + np.cumsum(z * s.y_scale, axis=-1)
        return s.y_shift + s.y_scale * z

    def _history(self, y, s: Scaling, initial: str):
        """Start of the free run: (first simulated index, scaled history,
        output before it)."""
        if initial == "rest":
            return 0, self.rest_history(s), 0.0
        t0 = self.max_lag
        z = self._target(np.asarray(y, dtype=float)[: t0 + 1], s)
        return t0, z[t0 - self.ny : t0], float(y[t0 - 1]) if t0 > 0 else 0.0


@dataclass(frozen=True)
class NARX(_Lags):
    """NARX structure with a multilayer-perceptron map.

    Parameters
    ----------
    ny : int
        Past outputs in the regressor (>= 1).
    nu : int
        Past inputs in the regressor (>= 1).
    nk : int
        Input delay: the newest input is ``u(t - nk)`` (>= 0).
    hidden : tuple of int
        Hidden-layer sizes: one layer ``(h,)``, or ``()`` for no network
        (then the model is the linear bypass alone, i.e. an ARX model).
    activation : {"tanh", "logistic", "linear"}
        The hidden units' activation.
    linear : bool
        Add the linear bypass ``l^T phi`` (default True).
    integrator : bool or int
        Known integrators of the linear start, 0, 1 or 2 (``True`` is 1).
        With one or two the map predicts the output's increment from past
        increments (see the module docstring), so a velocity-dependent
        friction is in its reach; the count says which linear model the
        bypass starts from: the default method's ARX with ``integrator=k``
        (two for a hub angle driven by a torque, a rigid body's double
        integrator), whose second integrator the bypass then holds as a
        pole at ``z = 1`` of the increments' model.

    Notes
    -----
    Parameter vector: ``W`` (``h x (ny + nu)``, row by row), ``b`` (``h``),
    ``v`` (``h``), ``c``, then ``l`` (``ny + nu``) when `linear`.

    Examples
    --------
    >>> NARX(2, 2, 1, hidden=(5,)).n_params   # 5 x 4 + 5 + 5 + 1 + 4
    35
    """

    ny: int
    nu: int
    nk: int = 1
    hidden: tuple[int, ...] = (10,)
    activation: str = "tanh"
    linear: bool = True
    integrator: bool | int = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "ny", _order(self.ny, "ny", 1))
        object.__setattr__(self, "nu", _order(self.nu, "nu", 1))
        object.__setattr__(self, "nk", _order(self.nk, "nk", 0))
        try:
            hidden = tuple(self.hidden)
        except TypeError:
            hidden = None
        if hidden is None or len(hidden) > 1:
            raise ValueError(
                "`hidden` must be () or one hidden layer (h,) (deeper networks are "
                f"not built); got {self.hidden!r}"
            )
        object.__setattr__(
            self, "hidden", tuple(_order(h, "hidden[0]", 1) for h in hidden)
        )
        if self.activation not in ACTIVATIONS:
            raise ValueError(
                f"`activation` must be one of {tuple(ACTIVATIONS)}; "
                f"got {self.activation!r}"
            )
        if not isinstance(self.linear, bool | np.bool_):
            raise ValueError(f"`linear` must be True or False; got {self.linear!r}")
        object.__setattr__(self, "linear", bool(self.linear))
        object.__setattr__(self, "integrator", _integrators(self.integrator))
        if not self.hidden and not self.linear:
            raise ValueError("`hidden=()` needs `linear=True` (nothing would remain)")

    @property
    def h(self) -> int:
        """Hidden units (0 without a network)."""
        return self.hidden[0] if self.hidden else 0

    @property
    def n_params(self) -> int:
        """Length of the parameter vector."""
        n = self.n_regressors
        return self.h * (n + 2) + 1 + (n if self.linear else 0)

    def _params(self, params, name: str = "params") -> tuple[np.ndarray, bool]:
        arr = np.asarray(params, dtype=float)
        if arr.ndim not in (1, 2) or arr.shape[-1] != self.n_params:
            raise ValueError(
                f"`{name}` must have shape ({self.n_params},) or (m, {self.n_params}) "
                f"for {self}; got shape {arr.shape}"
            )
        return np.ascontiguousarray(np.atleast_2d(arr)), arr.ndim == 1

    def split(self, params) -> dict[str, np.ndarray]:
        """The named blocks ``W, b, v, c, l`` of one parameter vector.

        Parameters
        ----------
        params : array_like, shape (n_params,)
        """
        p, _ = self._params(params)
        p = p[0]
        n, h = self.n_regressors, self.h
        ob, ov, oc = h * n, h * n + h, h * n + 2 * h
        return {
            "W": p[:ob].reshape(h, n),
            "b": p[ob:ov],
            "v": p[ov:oc],
            "c": p[oc : oc + 1],
            "l": p[oc + 1 :] if self.linear else np.zeros(n),
        }

    def evaluate(self, params, phi: np.ndarray) -> np.ndarray:
        """The map ``F(phi)`` (scaled), shape (N,) or (m, N).

        Parameters
        ----------
        params : array_like, shape (n_params,) or (m, n_params)
        phi : ndarray, shape (N, ny + nu)
            Scaled regressors.
        """
        P, single = self._params(params)
        n, h = self.n_regressors, self.h
        ob, ov, oc = h * n, h * n + h, h * n + 2 * h
        W = P[:, :ob].reshape(-1, h, n)
        z = np.einsum("mkn,tn->mtk", W, phi) + P[:, None, ob:ov]
        a = _activate(z, self.activation)
        out = np.einsum("mtk,mk->mt", a, P[:, ov:oc]) + P[:, oc : oc + 1]
        if self.linear:
            out += P[:, oc + 1 :] @ phi.T
        return out[0] if single else out

    def jacobian(self, params, phi: np.ndarray) -> np.ndarray:
        """Exact ``dF(phi_t) / d params``, shape (N, n_params).

        Parameters
        ----------
        params : array_like, shape (n_params,)
        phi : ndarray, shape (N, ny + nu)
        """
        d = self.split(params)
        n, h = self.n_regressors, self.h
        z = phi @ d["W"].T + d["b"]
        a = _activate(z, self.activation)
        g = d["v"] * _dactivate(a, self.activation)  # (N, h)
        cols = [(g[:, :, None] * phi[:, None, :]).reshape(phi.shape[0], h * n)]
        cols += [g, a, np.ones((phi.shape[0], 1))]
        if self.linear:
            cols.append(phi)
        return np.hstack(cols)

    def free_run_scaled(self, params, ulag, hist) -> np.ndarray:
        """Compiled free run of every parameter row (scaled map outputs).

        Parameters
        ----------
        params : array_like, shape (n_params,) or (m, n_params)
        ulag : ndarray, shape (N, nu)
            Scaled input regressors (:meth:`input_lags`).
        hist : ndarray, shape (ny,)
            Scaled outputs before the first step (oldest first).
        """
        P, single = self._params(params)
        out = np.empty((P.shape[0], ulag.shape[0]))
        _mlp_free_run(
            P,
            np.ascontiguousarray(ulag),
            np.ascontiguousarray(hist, dtype=float),
            self.ny,
            self.h,
            ACTIVATIONS[self.activation],
            self.linear,
            out,
        )
        return out[0] if single else out

    def free_run_jacobian(self, params, ulag, hist) -> tuple[np.ndarray, np.ndarray]:
        """Scaled free run of one parameter vector and its exact Jacobian.

        Parameters
        ----------
        params : array_like, shape (n_params,)
        ulag : ndarray, shape (N, nu)
        hist : ndarray, shape (ny,)
        """
        P, _ = self._params(params)
        n_t = ulag.shape[0]
        out = np.empty(n_t)
        sens = np.empty((n_t, self.n_params))
        _mlp_sensitivity(
            P[0],
            np.ascontiguousarray(ulag),
            np.ascontiguousarray(hist, dtype=float),
            self.ny,
            self.h,
            ACTIVATIONS[self.activation],
            self.linear,
            out,
            sens,
        )
        return out, sens

    def initial_params(self, rng: np.random.Generator, scale: float = 1.0):
        """Glorot-uniform hidden weights, zero biases and output weights,
        zero bypass: the network starts as the zero model's flat map, its
        units in their linear range.

        Parameters
        ----------
        rng : numpy.random.Generator
        scale : float
            Multiplies the Glorot limit.
        """
        n, h = self.n_regressors, self.h
        p = np.zeros(self.n_params)
        lim = scale * math.sqrt(6.0 / (n + h)) if h else 0.0
        p[: h * n] = rng.uniform(-lim, lim, h * n)
        ov = h * n + h
        p[ov : ov + h] = rng.uniform(-lim, lim, h)
        return p

    def from_arx(self, a, b, scaling: Scaling) -> np.ndarray:
        """Parameters of this structure that equal the ARX model ``(a, b)``
        (``A(q) y = B(q) u`` with ``a_1..a_ny``, ``b_0..b_(nu-1)``, delay
        ``nk``) through the linear bypass, network outputs zero. For an
        integrating structure ``(a, b)`` model the increments.

        Parameters
        ----------
        a : array_like, shape (ny,)
        b : array_like, shape (nu,)
        scaling : Scaling
        """
        if not self.linear:
            raise ValueError("`from_arx` needs the linear bypass (`linear=True`)")
        a = np.asarray(a, dtype=float)
        b = np.asarray(b, dtype=float)
        p = self.initial_params(np.random.default_rng(0), scale=0.0)
        oc = self.h * (self.n_regressors + 2)
        sy, su = scaling.y_scale, scaling.u_scale
        lin = np.r_[-a, b * su / sy]
        p[oc + 1 :] = lin
        # Offsets: y~ = (y - ys)/sy and u~ = (u - us)/su on both sides.
        shift_y = 0.0 if self.integrator else scaling.y_shift
        p[oc] = (-shift_y * (1.0 + np.sum(a)) + np.sum(b) * scaling.u_shift) / sy
        return p

    def __str__(self) -> str:
        extra = "" if self.linear else ", linear=False"
        if self.integrator:
            extra += f", integrator={self.integrator if self.integrator > 1 else True}"
        return (
            f"NARX({self.ny}, {self.nu}, {self.nk}, hidden={self.hidden}, "
            f"activation={self.activation!r}{extra})"
        )


def _activate(z, kind: str):
    if kind == "tanh":
        return np.tanh(z)
    if kind == "logistic":
        return 0.5 * (1.0 + np.tanh(0.5 * z))
    return z


def _dactivate(a, kind: str):
    if kind == "tanh":
        return 1.0 - a * a
    if kind == "logistic":
        return a * (1.0 - a)
    return np.ones_like(a)


@dataclass(frozen=True)
class PolynomialNARX(_Lags):
    """Polynomial NARX structure: monomials of the regressors up to `degree`.

    Parameters
    ----------
    ny, nu, nk : int
        Lags as for :class:`NARX`.
    degree : int
        Largest total degree of a term (1..3).
    n_terms : int or None
        Terms to keep (forward regression stops there); None: stop when the
        error reduction ratios left sum below `tolerance`.
    tolerance : float
        ``1 - sum(ERR)`` at which forward regression stops.
    integrator : bool
        Predict the increment (see the module docstring).
    terms : tuple of tuple of int, optional
        The chosen terms (indices of the regressors multiplied together),
        set by estimation; None before.

    Examples
    --------
    >>> PolynomialNARX(2, 2, 1, degree=2).n_candidates   # 1 + 4 + 10
    15
    """

    ny: int
    nu: int
    nk: int = 1
    degree: int = 2
    n_terms: int | None = 10
    tolerance: float = 1e-4
    integrator: bool = False
    terms: tuple[tuple[int, ...], ...] | None = field(default=None, compare=True)

    def __post_init__(self) -> None:
        object.__setattr__(self, "ny", _order(self.ny, "ny", 1))
        object.__setattr__(self, "nu", _order(self.nu, "nu", 1))
        object.__setattr__(self, "nk", _order(self.nk, "nk", 0))
        deg = _order(self.degree, "degree", 1)
        if deg > 3:
            raise ValueError(f"`degree` must be an integer in [1, 3]; got {deg!r}")
        object.__setattr__(self, "degree", deg)
        object.__setattr__(self, "integrator", _integrators(self.integrator))
        if self.n_terms is not None:
            object.__setattr__(self, "n_terms", _order(self.n_terms, "n_terms", 1))
        tol = self.tolerance
        if not (isinstance(tol, float | int) and 0.0 < tol < 1.0):
            raise ValueError(f"`tolerance` must be in (0, 1); got {tol!r}")
        if self.terms is not None:
            terms = tuple(tuple(int(i) for i in t) for t in self.terms)
            if any(
                len(t) != deg or min(t) < 0 or max(t) > self.n_regressors for t in terms
            ):
                raise ValueError(
                    f"`terms` must be tuples of {deg} indices in "
                    f"[0, {self.n_regressors}]; got {self.terms!r}"
                )
            object.__setattr__(self, "terms", terms)

    def candidates(self) -> list[tuple[int, ...]]:
        """Every monomial up to `degree` as sorted regressor indices (0: the
        constant 1, ``i``: regressor ``i - 1``)."""
        from itertools import combinations_with_replacement

        return list(
            combinations_with_replacement(range(self.n_regressors + 1), self.degree)
        )

    @property
    def n_candidates(self) -> int:
        """Number of candidate terms."""
        return len(self.candidates())

    @property
    def n_params(self) -> int:
        """Number of coefficients (the chosen terms, or the cap)."""
        if self.terms is not None:
            return len(self.terms)
        return self.n_terms or self.n_candidates

    def term_matrix(self, phi: np.ndarray, terms=None) -> np.ndarray:
        """Columns of the given terms (default the chosen, else all) over ``phi``.

        Parameters
        ----------
        phi : ndarray, shape (N, ny + nu)
        terms : sequence of tuple, optional
        """
        terms = self.terms if terms is None else terms
        if terms is None:
            terms = self.candidates()
        ext = np.hstack([np.ones((phi.shape[0], 1)), phi])
        return np.prod(ext[:, np.asarray(terms)], axis=2)

    def evaluate(self, params, phi: np.ndarray) -> np.ndarray:
        """The map ``F(phi)`` (scaled).

        Parameters
        ----------
        params : array_like, shape (n_terms,)
        phi : ndarray, shape (N, ny + nu)
        """
        return self.term_matrix(phi) @ np.asarray(params, dtype=float)

    def free_run_scaled(self, params, ulag, hist) -> np.ndarray:
        """Compiled free run (scaled map outputs), one per row of `params`.

        Parameters
        ----------
        params : array_like, shape (n_terms,) or (m, n_terms)
        ulag : ndarray, shape (N, nu)
        hist : ndarray, shape (ny,)
        """
        P = np.atleast_2d(np.asarray(params, dtype=float))
        out = np.empty((P.shape[0], ulag.shape[0]))
        terms = np.asarray(self.terms, dtype=np.int64).reshape(-1, self.degree)
        for j in range(P.shape[0]):
            _poly_free_run(
                np.ascontiguousarray(P[j]),
                terms,
                np.ascontiguousarray(ulag),
                np.ascontiguousarray(hist, dtype=float),
                self.ny,
                out[j],
            )
        return out[0] if np.ndim(params) == 1 else out

    def term_names(self) -> list[str]:
        """Readable names such as ``y(t-1)*u(t-2)``."""
        out = []
        ylab = "dy" if self.integrator else "y"
        for t in self.terms or ():
            parts = []
            for i in t:
                if i == 0:
                    continue
                if i <= self.ny:
                    parts.append(f"{ylab}(t-{i})")
                else:
                    parts.append(f"u(t-{self.nk + i - 1 - self.ny})")
            out.append("*".join(parts) or "1")
        return out

    def __str__(self) -> str:
        n = len(self.terms) if self.terms is not None else self.n_terms
        return (
            f"PolynomialNARX({self.ny}, {self.nu}, {self.nk}, degree={self.degree}, "
            f"terms={n})"
        )


# -- the fitted model -----------------------------------------------------------


@dataclass
class NARXModel:
    """An estimated NARX model: structure, parameters, scaling and provenance.

    What :func:`spiralid.sysid.identify` returns for a :class:`NARX` or
    :class:`PolynomialNARX` structure.

    Attributes
    ----------
    params : ndarray
        The parameter vector (weights, or polynomial coefficients).
    structure : NARX or PolynomialNARX
        The structure.
    scaling : Scaling
        The signals' scaling.
    ts : float
        Sample time (s).
    method : str
        Estimation method.
    predictor : {"simulation", "one-step"}
        The error the cost measured.
    initial : {"rest", "measured"}
        Start of the free run the cost measured.
    cost : float
        Estimation cost (the paper's eq. (2) with gain ``100 sqrt(K) /
        rms(y)``: the error's RMS in percent of the output's).
    result : OptimizeResult or None
        The estimator's result.
    history : ndarray or None
        Best cost per iteration of a search.
    timings : dict
        Wall times (s).
    input_name, output_name, input_unit, output_unit : str
        Signal names and units.
    u_offset, y_offset : float
        Offsets removed before estimation (the record's, as for ARX).
    gain, penalty : float
        The cost's gain and stability penalty.
    linear_params : ndarray or None
        The linear start: the parameters of this structure that equal the
        linear (ARX) model training started from, network outputs zero
        (None for a structure without the bypass, or a polynomial NARX).
    linear_model : str
        What the linear start is, e.g. ``"ARX(9, 8, 0), integrator=2, by
        spiral"``.
    """

    params: np.ndarray
    structure: NARX | PolynomialNARX
    scaling: Scaling
    ts: float
    method: str = ""
    predictor: str = "simulation"
    initial: str = "rest"
    cost: float = float("nan")
    result: Any = None
    history: np.ndarray | None = None
    timings: dict = field(default_factory=dict)
    input_name: str = "u"
    output_name: str = "y"
    input_unit: str = ""
    output_unit: str = ""
    u_offset: float = 0.0
    y_offset: float = 0.0
    gain: float = float("nan")
    penalty: float = 0.0
    linear_params: np.ndarray | None = None
    linear_model: str = ""

    kind = "narx"

    @property
    def linear_start(self) -> NARXModel | None:
        """The linear model training started from, as a NARXModel of the
        same structure (network outputs zero), or None without one."""
        if self.linear_params is None:
            return None
        return NARXModel(
            params=np.asarray(self.linear_params, dtype=float),
            structure=self.structure,
            scaling=self.scaling,
            ts=self.ts,
            method=self.method,
            predictor=self.predictor,
            initial=self.initial,
        )

    def simulate(self, u, y0=None) -> np.ndarray:
        """Free run over the input `u` from rest, or with ``y0`` (the measured
        output record) from its first ``max_lag`` samples.

        Parameters
        ----------
        u : array_like or IOData
            Input (an IOData contributes its ``u``).
        y0 : array_like, optional
            Measured output; its first ``max_lag`` samples start the run and
            are returned unchanged.

        Returns
        -------
        ndarray, shape (N,)
        """
        u = u.u if isinstance(u, IOData) else check_signal(u, "u")
        return simulate_structure(
            self.structure,
            self.params,
            self.scaling,
            u,
            None if y0 is None else check_signal(y0, "y0"),
        )

    def predict(self, data: IOData) -> np.ndarray:
        """One-step-ahead prediction from the measured past (rest before 0).

        Parameters
        ----------
        data : IOData
        """
        single_output_record(data, "a NARX model")
        phi, _ = self.structure.regressors(data.u, data.y, self.scaling)
        z = self.structure.evaluate(self.params, phi)
        s = self.scaling
        if self.structure.integrator:
            prev = np.r_[0.0, data.y[:-1]]
            return prev + z * s.y_scale
        return s.y_shift + s.y_scale * z

    @property
    def is_stable(self) -> bool:
        """True: stability of a nonlinear model is judged by its free run
        (:func:`~spiralid.sysid.validate` reports it), not by poles."""
        return True

    def to_dict(self, *, timings: bool = True) -> dict:
        """A JSON-safe dictionary; ``NARXModel.from_dict`` reads it back.

        Parameters
        ----------
        timings : bool
            Include the wall times.
        """
        st = self.structure
        if isinstance(st, NARX):
            sd = {
                "type": "mlp",
                "ny": st.ny,
                "nu": st.nu,
                "nk": st.nk,
                "hidden": list(st.hidden),
                "activation": st.activation,
                "linear": st.linear,
                "integrator": st.integrator,
            }
        else:
            sd = {
                "type": "polynomial",
                "ny": st.ny,
                "nu": st.nu,
                "nk": st.nk,
                "degree": st.degree,
                "integrator": st.integrator,
                "terms": [list(t) for t in st.terms],
                "term_names": st.term_names(),
            }
        res = self.result
        out = {
            "model": "narx",
            "structure": sd,
            "params": [float(v) for v in self.params],
            "scaling": {
                k: float(getattr(self.scaling, k))
                for k in ("u_shift", "u_scale", "y_shift", "y_scale")
            },
            "ts": float(self.ts),
            "method": self.method,
            "predictor": self.predictor,
            "initial": self.initial,
            "cost": float(self.cost),
            "gain": float(self.gain),
            "history": None
            if self.history is None
            else [float(v) for v in self.history],
            "timings": {k: float(v) for k, v in self.timings.items()},
            "input_name": self.input_name,
            "output_name": self.output_name,
            "input_unit": self.input_unit,
            "output_unit": self.output_unit,
            "u_offset": float(self.u_offset),
            "y_offset": float(self.y_offset),
            "linear_start": None
            if self.linear_params is None
            else {
                "model": self.linear_model,
                "params": [float(v) for v in self.linear_params],
            },
            "result": None
            if res is None
            else {
                k: (v if isinstance(v, bool | str) else float(v))
                for k, v in res.items()
                if k in ("fun", "nfev", "nit", "status", "success", "message")
            },
        }
        if not timings:
            del out["timings"]
        return out

    @classmethod
    def from_dict(cls, d: dict) -> NARXModel:
        """Rebuild from :meth:`to_dict` output (``result`` is not restored);
        a field that is missing or out of range (``ts <= 0``, an unknown
        method, a zero scale...) raises a ValueError that names it.

        Parameters
        ----------
        d : dict
        """
        if not isinstance(d, dict) or d.get("model") != "narx":
            raise ValueError("a NARX model must be a JSON object with model 'narx'")
        try:
            sd = dict(d["structure"])
            kind = sd.pop("type")
            if kind == "mlp":
                st = NARX(
                    sd["ny"],
                    sd["nu"],
                    sd["nk"],
                    hidden=tuple(sd["hidden"]),
                    activation=sd["activation"],
                    linear=sd["linear"],
                    integrator=sd["integrator"],
                )
            elif kind == "polynomial":
                terms = tuple(tuple(t) for t in sd["terms"])
                st = PolynomialNARX(
                    sd["ny"],
                    sd["nu"],
                    sd["nk"],
                    degree=sd["degree"],
                    n_terms=len(terms),
                    integrator=sd["integrator"],
                    terms=terms,
                )
            else:
                raise ValueError(
                    f"field 'structure.type' must be 'mlp' or 'polynomial'; "
                    f"got {kind!r}"
                )
            params = np.asarray(d["params"], dtype=float)
            if params.shape != (st.n_params,) or not np.all(np.isfinite(params)):
                raise ValueError(
                    f"field 'params' must hold {st.n_params} finite numbers for {st}"
                )
            scaling = d["scaling"]
            if not isinstance(scaling, dict):
                raise ValueError(
                    f"field 'scaling' must be an object; got {scaling!r:.80}"
                )
            # The scales divide the signals: zero, negative or non-finite
            # ones would only fail (or mislead) at the first simulation.
            sc = Scaling(
                **{
                    k: _fields.number(scaling, k, allowed, ok, where="scaling.")
                    for k, allowed, ok in (
                        ("u_shift", "a finite number", _fields.finite),
                        ("u_scale", "a number > 0", _fields.positive),
                        ("y_shift", "a finite number", _fields.finite),
                        ("y_scale", "a number > 0", _fields.positive),
                    )
                }
            )
            return cls(
                params=params,
                structure=st,
                scaling=sc,
                ts=_fields.number(d, "ts", "a number > 0", _fields.positive),
                method=_fields.method(d, _narx_methods()),
                predictor=d.get("predictor", "simulation"),
                initial=d.get("initial", "rest"),
                cost=_fields.number(d, "cost", "a number", _fields.anything, math.nan),
                gain=_fields.gain(d),
                history=None if d.get("history") is None else np.asarray(d["history"]),
                timings=dict(d.get("timings", {})),
                input_name=d.get("input_name", "u"),
                output_name=d.get("output_name", "y"),
                input_unit=str(d.get("input_unit", "")),
                output_unit=str(d.get("output_unit", "")),
                u_offset=_fields.number(
                    d, "u_offset", "a finite number", _fields.finite, 0.0
                ),
                y_offset=_fields.number(
                    d, "y_offset", "a finite number", _fields.finite, 0.0
                ),
                **_linear_start(d.get("linear_start"), st),
            )
        except KeyError as exc:
            raise ValueError(f"the field {exc.args[0]!r} is missing") from None

    def __repr__(self) -> str:
        return (
            f"NARXModel({self.structure}, method={self.method!r}, "
            f"predictor={self.predictor!r}, cost={self.cost:.6g})"
        )


def _linear_start(field, structure) -> dict:
    """NARXModel's linear-start fields from a model file's
    ``"linear_start"`` (absent or null in files written before it)."""
    if field is None:
        return {}
    if not isinstance(field, dict):
        raise ValueError(f"field 'linear_start' must be an object; got {field!r:.80}")
    params = np.asarray(field.get("params"), dtype=float)
    if params.shape != (structure.n_params,) or not np.all(np.isfinite(params)):
        raise ValueError(
            f"field 'linear_start.params' must hold {structure.n_params} finite "
            f"numbers for {structure}"
        )
    return {"linear_params": params, "linear_model": str(field.get("model", ""))}


def _narx_methods() -> tuple[str, ...]:
    """The methods a NARX model file may name (the names only: the models
    stage imports no estimator; tests/test_layout.py)."""
    from spiralid.choices import METHOD_NAMES

    return METHOD_NAMES


def simulate_structure(structure, params, scaling: Scaling, u, y0=None):
    """Free run of `structure` with `params` (one vector, or rows for the
    MLP) over `u`: from rest, or from the first ``max_lag`` samples of the
    measured output `y0`, which are returned unchanged."""
    ulag = structure.input_lags(u, scaling)
    if y0 is None:
        t0, hist, ystart = structure._history(None, scaling, "rest")
    else:
        if y0.size != u.size:
            raise ValueError(
                f"`y0` must have the input's length {u.size}; got {y0.size}"
            )
        t0, hist, ystart = structure._history(y0, scaling, "measured")
    z = structure.free_run_scaled(params, ulag[t0:], hist)
    y = structure._unscale(z, scaling, ystart)
    if t0 == 0:
        return y
    head = np.broadcast_to(y0[:t0], (*y.shape[:-1], t0))
    return np.concatenate([head, y], axis=-1)
