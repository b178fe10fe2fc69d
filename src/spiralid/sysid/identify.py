"""identify(): data + ARX structure + method -> IdentifiedModel.

Methods
-------
``"sda"``, ``"ebsda"``, ``"lasda"``
    The spiral optimisers of :func:`spiralid.optim.minimize` over the
    paper's cost :class:`~spiralid.sysid.PaperCost` (eq. (2)-(3)).
``"ls"``
    Least squares, the exact minimiser of the one-step error.
``"oe"``
    Output error: ``scipy.optimize.least_squares`` (Levenberg-Marquardt,
    analytic Jacobian) on the simulation error of :class:`PaperCost`,
    started from least squares and from Steiglitz-McBride iterations
    (:func:`steiglitz_mcbride`), keeping the lower estimation cost; kept
    stable by searching the denominator
    as reflection coefficients ``k = kmax tanh(z)``, ``kmax = 1 - 1e-6``
    (unstable poles of the start are first reflected into the unit circle,
    ``z -> 1 / conj(z)``).

Initial condition of the simulation (``initial``)
-------------------------------------------------
The simulation error that ``"oe"``, ``refine=True`` and the spiral methods
with ``predictor="simulation"`` minimise starts either from rest
(``initial="rest"``, the default: ``e = y - lfilter(b, a, u)`` over all
``N`` samples, the paper's "actual input applied to the estimated model")
or from the measured past outputs at ``t0 = max_lag``
(``initial="measured"``). Use ``"rest"`` for records that start at rest
(the simulated rig's experiments); on such noisy records the measured
start is harmful, because for lightly damped models it maps the noise of
the ``na`` measured outputs into a large initial state (on the rig, OE from
rest validates at about 95.9 %, the measured-past optimum at 92.6 %). Use
``"measured"`` only for a record that starts in motion, such as the real
arm (a slice of a periodic sweep: OE from rest validates at about 89.7 %
there, from the measured past at 95.2 %). Least squares and the one-step
predictor do not depend on it.

Search space of the spiral methods (DESIGN.md items 12-13)
------------------------------------------------------------
``parametrization="coefficients"`` (paper-faithful): the optimiser moves
the raw coefficients ``[a, b]`` and unstable candidates pay the penalty;
the initial denominators are drawn uniformly in reflection coefficients
and mapped by the step-up recursion, so every initial point is stable
("feasible"). ``parametrization="reflection"``: the optimiser moves
``[k_1..k_na, b]``; each ``k`` is folded into ``(-1, 1)``
(:func:`~spiralid.sysid.polynomials.fold_reflection`) and mapped by step-up,
so every candidate is stable and the penalty never fires.

Default bounds: ``|a_i| <= binom(na, i)`` (every stable monic polynomial of
degree na lies in that box, so it loses no stable model), ``k_i`` in
``[-1, 1]``, and ``|b_j| <= s`` with ``s = 2 max_j |b_j^LS|`` scaled
from the least-squares estimate (``2 rms(y) / rms(u)`` if that is zero).
The RMS ratio alone is a poor scale for a sparse input: for the simulated
rig's bang-bang record it is 567 while the largest LS numerator
coefficient is 43.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from math import comb
from typing import Any

import numpy as np
from scipy import optimize, signal

from spiralid._checks import generator
from spiralid.optim import differential_evolution, minimize

from .arx import ARX, arx_least_squares
from .cost import INITIAL_CONDITIONS, PaperCost
from .data import IOData
from .polynomials import fold_reflection, step_down, step_up

__all__ = [
    "IdentifiedModel",
    "default_bounds",
    "feasible_initial_points",
    "identify",
    "steiglitz_mcbride",
]

_SPIRAL = ("sda", "ebsda", "lasda")
# Population searches over the paper's cost: the spiral ones and, as the
# baseline beside them, SciPy's differential evolution.
_SEARCH = (*_SPIRAL, "de")
_DE_OPTIONS = ("n_points", "max_iter", "max_nfev", "x0", "callback")
_METHODS = ("ls", "oe", *_SEARCH)
_PARAMETRIZATIONS = ("coefficients", "reflection")
_KMAX = 1.0 - 1e-6


@dataclass(eq=False)
class IdentifiedModel:
    """An estimated ARX model with how it was obtained.

    Attributes
    ----------
    theta : ndarray, shape (p,)
        ``[a_1..a_na, b_0..b_(nb-1)]``.
    arx : ARX
        The structure.
    ts : float
        Sample time in seconds.
    method, predictor, parametrization : str
        How it was estimated (``predictor`` is the one the cost uses).
    initial : {"rest", "measured"}
        Initial condition of the cost's simulation (see :class:`PaperCost`).
        :meth:`from_dict` reads a dict without it (saved before the option
        existed) as ``"measured"``, the rule that produced it.
    gain : float
        The cost's gain ``w``.
    penalty : float
        The cost's stability penalty.
    cost : float
        The paper's cost, eq. (2)-(3), of ``theta`` on the estimation data.
    result : object or None
        The optimiser's result (``SpiralResult`` for spiral methods,
        ``scipy.optimize.OptimizeResult`` for ``"oe"``, whose ``start`` says
        which start was kept); ``None`` for ``"ls"`` and after
        :meth:`from_dict`.
    refine_result : object or None
        The local polish's result when ``refine=True``.
    history : ndarray or None
        Best cost after each iteration of the spiral search.
    timings : dict
        Wall times in seconds: ``"search"``, ``"refine"``, ``"total"``.
    bounds : ndarray or None, shape (p, 2)
        The search box of a spiral method (in the searched parameters).
    """

    theta: np.ndarray
    arx: ARX
    ts: float
    method: str
    predictor: str = "simulation"
    parametrization: str = "coefficients"
    gain: float = float("nan")
    penalty: float = 1e6
    cost: float = float("nan")
    result: Any = None
    refine_result: Any = None
    history: np.ndarray | None = None
    timings: dict = field(default_factory=dict)
    bounds: np.ndarray | None = None
    input_name: str = "u"
    output_name: str = "y"
    # Last, so positional construction keeps its meaning.
    initial: str = "rest"

    def __post_init__(self) -> None:
        if not isinstance(self.initial, str) or self.initial not in INITIAL_CONDITIONS:
            raise ValueError(
                f"`initial` must be one of {INITIAL_CONDITIONS}; got {self.initial!r}"
            )
        self.theta = np.asarray(self.theta, dtype=float).copy()
        if self.theta.shape != (self.arx.n_params,):
            raise ValueError(
                f"`theta` must have shape ({self.arx.n_params},) for {self.arx}; "
                f"got {self.theta.shape}"
            )
        if not np.all(np.isfinite(self.theta)):
            bad = int(np.flatnonzero(~np.isfinite(self.theta))[0])
            raise ValueError(
                f"`theta` must be finite; got {self.theta[bad]!r} at index {bad}"
            )

    # -- model behaviour ---------------------------------------------------------

    def simulate(self, u) -> np.ndarray:
        """Free-run output from zero initial conditions (``IOData`` gives its u)."""
        return self.arx.simulate(self.theta, u)

    def predict(self, data: IOData) -> np.ndarray:
        """One-step-ahead prediction on `data`."""
        return self.arx.predict(self.theta, data)

    @property
    def polynomials(self) -> tuple[np.ndarray, np.ndarray]:
        """``(num, den)`` in ``z^-1``, equal lengths (see ``ARX.polynomials``)."""
        return self.arx.polynomials(self.theta)

    @property
    def poles(self) -> np.ndarray:
        return self.arx.poles(self.theta)

    @property
    def zeros(self) -> np.ndarray:
        return self.arx.zeros(self.theta)

    @property
    def is_stable(self) -> bool:
        return bool(self.arx.is_stable(self.theta))

    def tf_string(self, digits: int = 4) -> str:
        """Transfer function in z as eq. (9)-(10) print it."""
        return self.arx.tf_string(self.theta, digits=digits)

    def to_dlti(self) -> signal.dlti:
        """The model as a ``scipy.signal.dlti`` transfer function with ``dt = ts``."""
        num, den = self.polynomials
        # Leading zeros (nk > 0) are exact in positive powers of z; dropping
        # them avoids SciPy's "badly conditioned" warning.
        nz = np.flatnonzero(num)
        num = num[nz[0] :] if nz.size else num[-1:]
        return signal.dlti(num, den, dt=self.ts)

    def to_control(self):
        """The model as a python-control ``TransferFunction`` in z, ``dt = ts``.

        Needs python-control, an optional dependency:
        ``pip install "spiralid[control]"``.
        """
        try:
            import control
        except ImportError:
            raise ImportError(
                'to_control() needs python-control: pip install "spiralid[control]"'
            ) from None
        dlti = self.to_dlti()
        return control.tf(dlti.num, dlti.den, self.ts)

    # -- serialisation -----------------------------------------------------------

    def to_dict(self) -> dict:
        """A JSON-safe summary (the optimiser result is reduced to its history)."""
        res = self.result
        summary = None
        if res is not None:
            # Scalars only: least_squares' `fun` is the whole residual vector,
            # which would bloat a saved model by a record's worth of numbers.
            summary = {
                k: _jsonable(getattr(res, k))
                for k in ("fun", "nit", "nfev", "success", "message", "start")
                if hasattr(res, k) and np.ndim(getattr(res, k)) == 0
            }
        return {
            "theta": [float(v) for v in self.theta],
            "na": self.arx.na,
            "nb": self.arx.nb,
            "nk": self.arx.nk,
            "ts": float(self.ts),
            "method": self.method,
            "predictor": self.predictor,
            "parametrization": self.parametrization,
            "initial": self.initial,
            "gain": float(self.gain),
            "penalty": float(self.penalty),
            "cost": float(self.cost),
            "history": None
            if self.history is None
            else [float(v) for v in self.history],
            "timings": {k: float(v) for k, v in self.timings.items()},
            "bounds": None if self.bounds is None else np.asarray(self.bounds).tolist(),
            "input_name": self.input_name,
            "output_name": self.output_name,
            "result": summary,
        }

    @classmethod
    def from_dict(cls, d: dict) -> IdentifiedModel:
        """Rebuild from :meth:`to_dict` output (``result`` is not restored)."""
        try:
            arx = ARX(d["na"], d["nb"], d["nk"])
            return cls(
                theta=np.asarray(d["theta"], dtype=float),
                arx=arx,
                ts=float(d["ts"]),
                method=d["method"],
                predictor=d.get("predictor", "simulation"),
                parametrization=d.get("parametrization", "coefficients"),
                # Dicts saved before `initial` existed came from the
                # measured-past rule, which was then the only one.
                initial=d.get("initial", "measured"),
                gain=float(d.get("gain", float("nan"))),
                penalty=float(d.get("penalty", 1e6)),
                cost=float(d.get("cost", float("nan"))),
                history=None if d.get("history") is None else np.asarray(d["history"]),
                timings=dict(d.get("timings", {})),
                bounds=None if d.get("bounds") is None else np.asarray(d["bounds"]),
                input_name=d.get("input_name", "u"),
                output_name=d.get("output_name", "y"),
            )
        except KeyError as exc:
            raise ValueError(f"`d` must contain the key {exc.args[0]!r}") from None

    def __repr__(self) -> str:
        return (
            f"IdentifiedModel({self.arx}, method={self.method!r}, "
            f"predictor={self.predictor!r}, initial={self.initial!r}, "
            f"cost={self.cost:.6g}, "
            f"stable={self.is_stable})"
        )


def _jsonable(v):
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    return v


# -- bounds and parametrisation ----------------------------------------------------


def default_bounds(
    data: IOData, arx: ARX, parametrization: str = "coefficients"
) -> np.ndarray:
    """The default search box, shape (p, 2) (see the module docstring).

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(200)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> default_bounds(IOData(u, y, ts=1.0), ARX(2, 2, 1))[:2]
    array([[-2.,  2.],
           [-1.,  1.]])
    """
    if parametrization not in _PARAMETRIZATIONS:
        raise ValueError(
            f"`parametrization` must be one of {_PARAMETRIZATIONS}; "
            f"got {parametrization!r}"
        )
    theta_ls = arx_least_squares(data, arx)
    s = 2.0 * float(np.max(np.abs(theta_ls[arx.na :])))
    if s == 0.0:
        # An exactly zero estimate gives no scale: fall back to the RMS ratio.
        s = 2.0 * float(np.sqrt(np.mean(data.y**2) / np.mean(data.u**2)))
    box = np.empty((arx.n_params, 2))
    for i in range(arx.na):
        half = 1.0 if parametrization == "reflection" else float(comb(arx.na, i + 1))
        box[i] = (-half, half)
    box[arx.na :] = (-s, s)
    return box


def feasible_initial_points(box: np.ndarray, arx: ARX, m: int, rng=None) -> np.ndarray:
    """``m`` initial points "in the feasible region" (DESIGN.md item 12).

    Denominators: reflection coefficients uniform in (-1, 1) mapped by
    step-up, so every point is stable (a uniform draw in the coefficient box
    almost never is for na = 8); numerators uniform in their box.

    Returns
    -------
    ndarray, shape (m, p)
    """
    gen = np.random.default_rng(rng)
    na = arx.na
    k = gen.uniform(-1.0, 1.0, size=(m, na))
    b = gen.uniform(box[na:, 0], box[na:, 1], size=(m, arx.nb))
    return np.clip(np.concatenate([step_up(k), b], axis=1), box[:, 0], box[:, 1])


def _check_bounds(bounds, p: int) -> np.ndarray:
    try:
        box = np.asarray(bounds, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"`bounds` must be an array of shape ({p}, 2); got {bounds!r}"
        ) from None
    if box.shape != (p, 2):
        raise ValueError(f"`bounds` must have shape ({p}, 2); got shape {box.shape}")
    if not np.all(np.isfinite(box)) or np.any(box[:, 0] >= box[:, 1]):
        raise ValueError(
            f"`bounds` must be finite with lower < upper in each row; got {box}"
        )
    return box


def _reflection_to_theta(x: np.ndarray, na: int) -> np.ndarray:
    """Searched ``[k, b]`` -> ``[a, b]``; k folded into (-1, 1) first."""
    x = np.atleast_2d(x)
    a = step_up(fold_reflection(x[:, :na], _KMAX))
    return np.concatenate([a, x[:, na:]], axis=1)


def _stabilise(theta: np.ndarray, arx: ARX) -> np.ndarray:
    """Reflect poles with ``|z| >= 1`` into the unit circle; return ``[k, b]``."""
    na = arx.na
    a, b = theta[:na], theta[na:]
    if na == 0:
        return theta.copy()
    if not arx.is_stable(theta):
        roots = np.roots(np.r_[1.0, a])
        mag = np.abs(roots)
        out = mag >= 1.0
        roots[out] = 1.0 / np.conj(roots[out])
        # A root on the circle reflects onto itself: pull it just inside.
        roots = np.where(np.abs(roots) >= _KMAX, roots * _KMAX / np.abs(roots), roots)
        a = np.real(np.poly(roots))[1:]
    k = step_down(a)
    k = np.clip(np.nan_to_num(k, nan=0.0), -_KMAX, _KMAX)
    return np.r_[k, b]


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


def _local_polish(
    theta0: np.ndarray,
    arx: ARX,
    data: IOData,
    predictor: str,
    initial: str = "rest",
) -> tuple[np.ndarray, optimize.OptimizeResult]:
    """Levenberg-Marquardt polish of the `predictor`'s error as
    :class:`PaperCost` defines it, kept stable: the denominator is searched
    as ``k = kmax tanh(z)`` (reflection coefficients, so every step is
    stable) with ``z`` unconstrained. Analytic Jacobian:
    ``d yhat / d b_j = u(t-nk-j) / A`` and ``d yhat / d a_i = -yhat(t-i) / A``
    (simulation: sensitivities filtered from rest, with ``yhat`` zero before
    ``t = 0`` for ``initial="rest"`` and the measured initial state fixed
    for ``"measured"``), ``Phi`` (one-step)."""
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
        a, dadk = _step_up_jacobian(_KMAX * th)
        return a, dadk * (_KMAX * (1.0 - th * th)), x[na:]

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

    start = _stabilise(np.asarray(theta0, dtype=float), arx)
    ratio = np.clip(start[:na] / _KMAX, -1.0 + 1e-12, 1.0 - 1e-12)
    x0 = np.r_[np.arctanh(ratio), start[na:]]
    res = optimize.least_squares(
        residual,
        x0,
        jac=jacobian,
        method="lm",
        x_scale="jac",
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=100 * (arx.n_params + 1),
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
    theta[:na] = step_up(_stabilise(theta, arx)[:na])
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
        new[:na] = step_up(_stabilise(new, arx)[:na])
        done = np.linalg.norm(new - theta) <= 1e-9 * np.linalg.norm(theta)
        theta = new
        if done:
            break
    return theta


# -- the entry point ----------------------------------------------------------


def identify(
    data: IOData,
    arx: ARX,
    method: str = "ebsda",
    predictor: str = "simulation",
    parametrization: str = "coefficients",
    rng=None,
    refine: bool = False,
    gain: str | float = "auto",
    penalty: float = 1e6,
    bounds=None,
    initial: str = "rest",
    **optimiser_options,
) -> IdentifiedModel:
    """Estimate an ARX model from input-output data.

    Parameters
    ----------
    data : IOData
        Estimation record.
    arx : ARX
        Model structure, e.g. ``ARX(8, 8, 0)`` for eq. (6).
    method : {"ebsda", "sda", "lasda", "de", "ls", "oe"}
        Estimator (see the module docstring). ``"ls"`` minimises the
        one-step error and ``"oe"`` the simulation error whatever
        `predictor` says; `predictor` then only selects the reported cost.
        ``"de"`` is SciPy's differential evolution over the same cost, box
        and initial points as the spiral methods, a baseline beside them
        (:func:`spiralid.optim.differential_evolution`).
    predictor : {"simulation", "one-step"}
        The error of the paper's cost (DESIGN.md item 3).
    parametrization : {"coefficients", "reflection"}
        What the spiral optimiser searches (DESIGN.md items 12-13).
    rng : int, numpy.random.Generator or None
        Randomness of the spiral methods (initial points and the search).
    refine : bool
        Polish a spiral result locally with the ``"oe"`` machinery applied
        to the `predictor`'s error (kept only if it lowers the cost).
        Ignored by ``"ls"`` and ``"oe"``.
    gain, penalty
        The cost's gain ``w`` and stability penalty, see :class:`PaperCost`.
    bounds : array_like, shape (p, 2), optional
        Search box in the searched parameters (``[a, b]`` or ``[k, b]``);
        default :func:`default_bounds`.
    initial : {"rest", "measured"}, default "rest"
        Initial condition of the simulation error (the cost, ``"oe"`` and
        ``refine``), see :class:`PaperCost` and the module docstring:
        ``"rest"`` (paper-faithful) for records that start at rest,
        ``"measured"`` for records that start in motion.
    **optimiser_options
        Passed to :func:`spiralid.optim.minimize` (``n_points``, ``max_iter``,
        ``max_nfev``, ``target``, ``callback``, ``bounds_policy``, ``x0``...);
        for ``"de"`` only ``n_points``, ``max_iter``, ``max_nfev``, ``x0`` and
        ``callback``.

    Returns
    -------
    IdentifiedModel

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(300)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> fit = identify(IOData(u, y, ts=0.01), ARX(2, 2, 1), method="ls")
    >>> fit.theta.round(9), fit.is_stable
    (array([-1.5,  0.7,  1. ,  0.5]), True)
    """
    t_start = time.perf_counter()
    if not isinstance(data, IOData):
        raise ValueError(f"`data` must be an IOData; got {type(data).__name__}")
    if not isinstance(arx, ARX):
        raise ValueError(f"`arx` must be an ARX; got {type(arx).__name__}")
    if method not in _METHODS:
        raise ValueError(f"`method` must be one of {_METHODS}; got {method!r}")
    if parametrization not in _PARAMETRIZATIONS:
        raise ValueError(
            f"`parametrization` must be one of {_PARAMETRIZATIONS}; "
            f"got {parametrization!r}"
        )
    if not isinstance(refine, bool | np.bool_):
        raise ValueError(f"`refine` must be True or False; got {refine!r}")
    gen = generator(rng)
    if method not in _SEARCH and optimiser_options:
        raise ValueError(
            f"`optimiser_options` apply to the search methods {_SEARCH}; method "
            f"{method!r} got {sorted(optimiser_options)}"
        )
    if method == "de" and set(optimiser_options) - set(_DE_OPTIONS):
        raise ValueError(
            f"`optimiser_options` of method 'de' must be among {_DE_OPTIONS}; got "
            f"{sorted(set(optimiser_options) - set(_DE_OPTIONS))}"
        )
    cost = PaperCost(
        arx, data, predictor=predictor, gain=gain, penalty=penalty, initial=initial
    )
    common = dict(
        arx=arx,
        ts=data.ts,
        method=method,
        predictor=predictor,
        parametrization=parametrization,
        initial=initial,
        gain=cost.w,
        penalty=cost.penalty,
        input_name=data.input_name,
        output_name=data.output_name,
    )

    if method == "ls":
        theta = arx_least_squares(data, arx)
        t = time.perf_counter() - t_start
        return IdentifiedModel(
            theta,
            cost=cost(theta),
            timings={"search": t, "refine": 0.0, "total": t},
            **common,
        )

    if method == "oe":
        # Two standard starts, least squares and Steiglitz-McBride; the
        # simulation error is not convex, so each may stop in a different
        # local minimum. Keep the lower estimation cost (never the
        # validation fit: that would be selecting on the test data). With a
        # one-step `predictor` the selection is still on the simulation
        # error OE minimises, not on the reported cost.
        sim_cost = (
            cost
            if predictor == "simulation"
            else PaperCost(arx, data, gain=gain, penalty=penalty, initial=initial)
        )
        theta_ls = arx_least_squares(data, arx)
        best = None
        for name, start in (
            ("ls", theta_ls),
            ("steiglitz-mcbride", steiglitz_mcbride(data, arx, theta_ls)),
        ):
            cand, cand_res = _local_polish(start, arx, data, "simulation", initial)
            cand_res.start = name
            f = sim_cost(cand)
            if best is None or f < best[0]:
                best = (f, cand, cand_res)
        _, theta, res = best
        t = time.perf_counter() - t_start
        return IdentifiedModel(
            theta,
            cost=cost(theta),
            result=res,
            timings={"search": t, "refine": 0.0, "total": t},
            **common,
        )

    box = (
        default_bounds(data, arx, parametrization)
        if bounds is None
        else _check_bounds(bounds, arx.n_params)
    )
    na = arx.na
    if parametrization == "reflection":

        def fun(x):
            return cost(_reflection_to_theta(x, na))

        def to_theta(x):
            return _reflection_to_theta(x, na)[0]

    else:
        fun = cost

        def to_theta(x):
            return np.asarray(x, dtype=float)

        if "x0" not in optimiser_options:
            m = int(optimiser_options.get("n_points", 50))
            optimiser_options["x0"] = feasible_initial_points(box, arx, m, gen)
    if method == "de":
        res = differential_evolution(fun, box, rng=gen, **optimiser_options)
    else:
        res = minimize(
            fun, box, method=method, rng=gen, vectorized=True, **optimiser_options
        )
    t_search = time.perf_counter() - t_start
    theta = to_theta(res.x)
    best = cost(theta)
    ref_res = None
    t_refine = 0.0
    if refine:
        t0 = time.perf_counter()
        polished, ref_res = _local_polish(theta, arx, data, predictor, initial)
        new = cost(polished)
        if new <= best:
            theta, best = polished, new
        t_refine = time.perf_counter() - t0
    history = getattr(res, "history", None)
    return IdentifiedModel(
        theta,
        cost=best,
        result=res,
        refine_result=ref_res,
        history=None if history is None else np.asarray(history, dtype=float),
        timings={
            "search": t_search,
            "refine": t_refine,
            "total": time.perf_counter() - t_start,
        },
        bounds=box,
        **common,
    )
