"""The NARX structure whose map is a multilayer perceptron, beside a
linear bypass that is the ARX model (see :mod:`.narx`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spiralid._checks import one_of

from ._narx_kernels import _mlp_free_run, _mlp_sensitivity
from .narx_lags import Scaling, _integrators, _Lags, _one_layer, _order

__all__ = ["ACTIVATIONS", "NARX"]

# The one list of activations; the code is the compiled kernels' switch.
ACTIVATIONS = {"tanh": 0, "logistic": 1, "linear": 2}


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
        Input delay: the newest input is ``u(t - nk)`` (>= 0). The default
        is 1, where :class:`ARX`'s is 0: the paper's ARX(8, 8, 0) of
        eq. (6) lets the torque act within the sample, while a NARX is
        strictly causal by convention (Billings' regressors start at
        ``u(t - 1)``), and the pinned NARX results are at ``nk = 1``.
        Pass ``nk`` explicitly to compare the two on the same lags.
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
        object.__setattr__(self, "hidden", _one_layer(self.hidden))
        one_of(self.activation, "activation", ACTIVATIONS)
        if not isinstance(self.linear, bool | np.bool_):
            raise TypeError(f"`linear` must be True or False; got {self.linear!r}")
        object.__setattr__(self, "linear", bool(self.linear))
        object.__setattr__(self, "integrator", _integrators(self.integrator))
        if not self.hidden and not self.linear:
            raise ValueError("`hidden=()` needs `linear=True` (nothing would remain)")

    @property
    def h(self) -> int:
        """Hidden units (0 without a network)."""
        return self.hidden[0] if self.hidden else 0

    #: A network is nonlinear (its validation adds the higher-order tests),
    #: even when training kept its output weights at zero.
    is_linear = False

    #: The estimator table's family (a record of one output only).
    family = "narx"
    outputs_family = None

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
