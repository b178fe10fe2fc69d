"""The neural state-space structure: :class:`NeuralStateSpace`, a linear
state-space model with a small network beside each of its two equations.

With the signals scaled (``u / u_scale``, ``y / y_scale``) and ``v = [x;
u]``::

    x(t + 1) = A x(t) + B u(t) + Vf tanh(Wf v + bf)
    y(t)     = C x(t) + D u(t) + vh . tanh(Wh v + bh)

The linear part ``(A, B, C, D)`` starts at a linear model's realisation and
the networks' output weights ``Vf``, ``vh`` at zero, so training starts at
the linear model exactly (NLSS2, Relan et al.; Beintema, Toth and
Schoukens 2021). Beside the model sits its **encoder**: the state at time
``t`` from the ``window`` samples before it, ``x(t) = E z(t)`` with ``z(t) =
[y(t-1) .. y(t-window), u(t-1) .. u(t-window)]`` (scaled), which starts
every training subsequence and, with ``simulate(u, y0=y)``, a free run
from measured samples. Its ``E`` starts at the linear start's exact state
reconstruction (observability matrix) and is trained with the rest.

The compiled loops are in :mod:`._nss_kernels`; the parameter vector is the
kernels' ``theta`` followed by ``E`` (``order x 2 window``, row by row).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._nss_kernels import nss_free_run
from .narx_lags import _one_layer, _order

__all__ = ["NeuralStateSpace"]

# The blocks of theta, in the kernels' order: name -> shape(order, hidden).
_BLOCKS = (
    ("A", lambda n, h: (n, n)),
    ("B", lambda n, h: (n,)),
    ("C", lambda n, h: (n,)),
    ("D", lambda n, h: (1,)),
    ("Wf", lambda n, h: (h, n + 1)),
    ("bf", lambda n, h: (h,)),
    ("Vf", lambda n, h: (n, h)),
    ("Wh", lambda n, h: (h, n + 1)),
    ("bh", lambda n, h: (h,)),
    ("vh", lambda n, h: (h,)),
)
#: The networks' weights (those weight decay shrinks); the linear part and
#: the encoder are not decayed, so the start is the linear model's optimum.
NETWORK_BLOCKS = ("Wf", "bf", "Vf", "Wh", "bh", "vh")


@dataclass(frozen=True)
class NeuralStateSpace:
    """Neural state-space structure of one input and one output.

    Parameters
    ----------
    order : int
        State dimension (>= 1); the linear start is the realisation of an
        ``ARX(order, order, 1)`` model.
    hidden : tuple of int
        Hidden units ``(h,)`` of each of the two networks (state and
        output), one tanh layer; ``()`` for none (a linear state-space
        model).
    window : int or None
        Past samples of the output and the input the encoder reads for a
        state (>= `order`, which a linear model of that order needs);
        default ``order + 2``.

    Notes
    -----
    Parameter vector: ``A, B, C, D, Wf, bf, Vf, Wh, bh, vh`` (see the module
    docstring), then the encoder's ``E``.

    Examples
    --------
    >>> NeuralStateSpace(2, hidden=(4,)).n_params  # 4+2+2+1 + 12+4+8 + 12+4+4 + 16
    69
    """

    order: int = 3
    hidden: tuple[int, ...] = (8,)
    window: int | None = None

    #: Nonlinear whatever the weights (validation adds the higher-order
    #: tests).
    is_linear = False
    #: The estimator table's family (a record of one output only).
    family = "neural-state-space"
    outputs_family = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "order", _order(self.order, "order", 1))
        object.__setattr__(self, "hidden", _one_layer(self.hidden))
        window = self.order + 2 if self.window is None else self.window
        object.__setattr__(self, "window", _order(window, "window", self.order))

    @property
    def h(self) -> int:
        """Hidden units of each network (0 without networks)."""
        return self.hidden[0] if self.hidden else 0

    @property
    def max_lag(self) -> int:
        """Measured samples a free run from measured samples starts after
        (the encoder's window)."""
        return self.window

    @property
    def n_theta(self) -> int:
        """Length of the model's parameters without the encoder."""
        return sum(int(np.prod(s(self.order, self.h))) for _, s in _BLOCKS)

    @property
    def n_params(self) -> int:
        """Length of the parameter vector (the encoder's ``E`` included)."""
        return self.n_theta + self.order * 2 * self.window

    def check_length(self, data, name: str = "data") -> None:
        """A one-line ValueError naming `name` when the record is too short
        for this structure (four encoder windows and ten samples).

        Parameters
        ----------
        data : IOData
        name : str
            The record's name in the message.
        """
        need = 4 * self.window + 10
        if data.n < need:
            raise ValueError(
                f"`{name}` must have at least {need} samples for {self}; got {data.n}"
            )

    def _params(self, params, name: str = "params") -> np.ndarray:
        arr = np.asarray(params, dtype=float)
        if arr.shape != (self.n_params,):
            raise ValueError(
                f"`{name}` must have shape ({self.n_params},) for {self}; got "
                f"shape {arr.shape}"
            )
        return arr

    def split(self, params) -> dict[str, np.ndarray]:
        """The named blocks (``A`` .. ``vh``, ``E``) of one parameter vector,
        as views.

        Parameters
        ----------
        params : array_like, shape (n_params,)
        """
        p = self._params(params)
        out, at = {}, 0
        for name, shape in _BLOCKS:
            s = shape(self.order, self.h)
            size = int(np.prod(s))
            out[name] = p[at : at + size].reshape(s)
            at += size
        out["E"] = p[at:].reshape(self.order, 2 * self.window)
        return out

    def network_mask(self) -> np.ndarray:
        """True at the networks' weights (:data:`NETWORK_BLOCKS`)."""
        mask = np.zeros(self.n_params, dtype=bool)
        at = 0
        for name, shape in _BLOCKS:
            size = int(np.prod(shape(self.order, self.h)))
            mask[at : at + size] = name in NETWORK_BLOCKS
            at += size
        return mask

    def regressors(self, ys: np.ndarray, us: np.ndarray, t) -> np.ndarray:
        """The encoder's inputs ``z(t)`` at each time of `t` (each >=
        `window`), shape (len(t), 2 window).

        Parameters
        ----------
        ys, us : ndarray, shape (N,)
            Scaled output and input.
        t : array_like of int
        """
        t = np.atleast_1d(np.asarray(t, dtype=np.intp))
        back = t[:, None] - 1 - np.arange(self.window)[None, :]
        return np.hstack([ys[back], us[back]])

    def free_run(self, params, us: np.ndarray, x0=None) -> np.ndarray:
        """Scaled free run from the state `x0` (default rest, the zero
        state) over the scaled inputs `us` (compiled).

        Parameters
        ----------
        params : array_like, shape (n_params,)
        us : ndarray, shape (N,)
        x0 : array_like, shape (order,), optional
        """
        p = self._params(params)
        x = np.zeros(self.order) if x0 is None else np.asarray(x0, dtype=float)
        out = np.empty(us.size)
        nss_free_run(
            np.ascontiguousarray(p[: self.n_theta]),
            np.ascontiguousarray(us, dtype=float),
            np.ascontiguousarray(x, dtype=float),
            self.order,
            self.h,
            out,
        )
        return out

    def from_linear(self, a, b, d: float = 0.0) -> np.ndarray:
        """Parameters equal to the (scaled) linear model ``A(q) y = B(q) u``
        with ``a_1..a_order`` and ``b_1..b_order`` (delay one, the ARX
        theta of ``ARX(order, order, 1)``) plus the feedthrough `d`: its
        observer canonical realisation, networks' output weights zero, and
        the encoder at the realisation's exact state from `window` past
        samples.

        Parameters
        ----------
        a, b : array_like, shape (order,)
            The scaled model's coefficients.
        d : float
            Direct feedthrough.
        """
        n = self.order
        a = np.asarray(a, dtype=float).ravel()
        b = np.asarray(b, dtype=float).ravel()
        if a.size != n or b.size != n:
            raise ValueError(
                f"`a` and `b` must have {n} coefficients each; got {a.size}, {b.size}"
            )
        p = np.zeros(self.n_params)
        blocks = self.split(p)
        blocks["A"][:, 0] = -a
        blocks["A"][: n - 1, 1:] += np.eye(n - 1)
        blocks["B"][:] = b
        blocks["C"][0] = 1.0
        blocks["D"][0] = d
        blocks["E"][:] = observer_encoder(
            blocks["A"], blocks["B"], blocks["C"], d, self.window
        )
        return p

    def to_dict(self) -> dict:
        """The structure's ``model.json`` fields."""
        return {"order": self.order, "hidden": list(self.hidden), "window": self.window}

    @classmethod
    def from_dict(cls, d: dict) -> NeuralStateSpace:
        """The structure :meth:`to_dict` wrote.

        Parameters
        ----------
        d : dict
        """
        return cls(int(d["order"]), tuple(d["hidden"]), int(d["window"]))

    def __str__(self) -> str:
        return (
            f"NeuralStateSpace(order={self.order}, hidden={self.hidden}, "
            f"window={self.window})"
        )


def observer_encoder(A, B, C, d: float, window: int) -> np.ndarray:
    """The matrix ``E`` with ``x(t) = E z(t)`` exact for the linear model
    ``(A, B, C, d)`` without noise: the state ``window`` steps back from the
    outputs through the observability matrix (least squares), carried
    forward through the inputs.

    Parameters
    ----------
    A : ndarray, shape (n, n)
    B, C : ndarray, shape (n,)
    d : float
    window : int
        Past samples of each signal (>= n).
    """
    n = A.shape[0]
    # y(s + i) = C A^i x(s) + sum_{j<i} C A^(i-1-j) B u(s + j) + d u(s + i),
    # s = t - window, i = 0..window-1; z holds y(t-1-k), u(t-1-k).
    powers = [np.eye(n)]
    for _ in range(window):
        powers.append(A @ powers[-1])
    obs = np.array([C @ powers[i] for i in range(window)])
    toeplitz = np.zeros((window, window))
    for i in range(window):
        toeplitz[i, i] = d
        for j in range(i):
            toeplitz[i, j] = C @ powers[i - 1 - j] @ B
    # x(t) = A^w x(s) + sum_j A^(w-1-j) B u(s + j)
    pinv = np.linalg.pinv(obs)
    reach = np.column_stack([powers[window - 1 - j] @ B for j in range(window)])
    from_y = powers[window] @ pinv  # (n, window), columns by s + i
    from_u = reach - powers[window] @ pinv @ toeplitz
    # Column s + i is z's entry window - 1 - i (newest first).
    return np.hstack([from_y[:, ::-1], from_u[:, ::-1]])
