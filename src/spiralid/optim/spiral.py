"""The spiral search loop: :func:`minimize` over a :class:`SpiralSearch`.

The algorithm is the paper's Figure-4 (after Tamura & Yasuda 2011):

1. Draw ``m`` initial points uniformly in the bounds (or take them from
   ``x0``); the centre ``x*`` is the best of them.
2. Move every point: ``x_i(k+1) = x* + r_i R(theta_i) (x_i(k) - x*)``, with
   ``r_i, theta_i`` from the rule (constant for SDA, eq. (4), (7), (8) for
   Eb-SDA).
3. The centre becomes the best current point. The centre's own point does
   not move (``x_i - x* = 0``), so its cost is kept, not re-evaluated, and
   the best cost never gets worse.
4. Repeat until a stopping criterion holds.

Non-finite costs (NaN, +-inf) rank worst and never become the centre. If
no initial cost is finite, the first initial point serves as the centre
until a finite cost turns up (every deviation is then ``inf``).
"""

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import Bounds

from spiralid._checks import generator, integer, real_array
from spiralid.optim import _kernels
from spiralid.optim.rotation import _sweep_order, rotation_matrix
from spiralid.optim.rules import (
    ConstantSpiral,
    ExponentialSpiral,
    LinearSpiral,
    SpiralRule,
)

__all__ = ["RULES", "SpiralResult", "SpiralSearch", "minimize"]

# Every stop message comes from here, so `message` is always one of these
# (plus the notes below).
_STATUS = {
    "max_iter": "Maximum number of iterations reached.",
    "max_nfev": "Maximum number of function evaluations reached.",
    "target": "Target cost reached.",
    "callback": "The callback requested a stop.",
    "running": "In progress.",
}
_NOTES = {
    "initial_nonfinite": (
        "Every initial cost was non-finite; the first initial point served as "
        "centre until a finite cost was found."
    ),
    "never_finite": "No finite cost was found.",
    "target_missed": "The target cost was not reached.",
}

_METHODS = {"sda": ConstantSpiral, "ebsda": ExponentialSpiral, "lasda": LinearSpiral}
# The one list of rule names: minimize() accepts them, and
# spiralid.sysid.identify() offers each as an identification method.
RULES = _METHODS
_POLICIES = ("none", "clip", "reflect")


@dataclass
class SpiralResult:
    """Outcome of a spiral search.

    Attributes
    ----------
    x : ndarray, shape (n,)
        Best point found (the final centre).
    fun : float
        Its cost as returned by the objective (non-finite only if no finite
        cost was ever found).
    nit : int
        Iterations performed.
    nfev : int
        Objective evaluations, one per point: ``n_points`` for the initial
        population, then ``n_points - 1`` per iteration (the centre does not
        move and is not re-evaluated), i.e. ``n_points + nit (n_points - 1)``.
    success : bool
        True if the search ended on its iteration or evaluation budget or
        on ``target``, with a finite cost (and ``target`` reached if given).
    message : str
        Why the search stopped.
    history : ndarray, shape (nit + 1,)
        Best cost after each iteration; index 0 is the initial population.
        Non-finite costs are recorded as ``inf``, so it never increases.
    elapsed : float
        Wall-clock seconds, objective evaluations included.
    mean_radius, mean_angle : ndarray, shape (nit,)
        Mean radius and angle (radians) over the moving points at each
        iteration, for plots of the rule's behaviour.
    """

    x: np.ndarray
    fun: float
    nit: int
    nfev: int
    success: bool
    message: str
    history: np.ndarray
    elapsed: float
    mean_radius: np.ndarray
    mean_angle: np.ndarray


def _parse_bounds(bounds) -> tuple[np.ndarray, np.ndarray]:
    what = (
        "`bounds` must be a sequence of (low, high) pairs, an (n, 2) array or "
        "a scipy.optimize.Bounds"
    )
    try:
        if isinstance(bounds, Bounds):
            lo = np.asarray(bounds.lb, dtype=np.float64)
            hi = np.asarray(bounds.ub, dtype=np.float64)
            if lo.ndim > 1 or hi.ndim > 1 or (lo.ndim == 0 and hi.ndim == 0):
                raise ValueError(
                    f"{what}; a Bounds needs 1-D lb/ub; got lb={bounds.lb!r}, "
                    f"ub={bounds.ub!r}"
                )
            lo, hi = (np.array(a) for a in np.broadcast_arrays(lo, hi))
        else:
            arr = np.asarray(bounds, dtype=np.float64)
            if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
                raise ValueError(f"{what}; got shape {arr.shape}")
            lo, hi = arr[:, 0].copy(), arr[:, 1].copy()
    except (TypeError, ValueError) as err:
        if str(err).startswith("`bounds`"):
            raise
        raise ValueError(f"{what}; got {bounds!r}") from None
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ValueError(f"`bounds` must be finite; got low={lo!r}, high={hi!r}")
    bad = np.flatnonzero(lo >= hi)
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"`bounds` must have low < high in every dimension; got "
            f"({lo[i]!r}, {hi[i]!r}) in dimension {i}"
        )
    with np.errstate(over="ignore"):
        width = hi - lo
    if not np.all(np.isfinite(width)):
        raise ValueError(
            f"`bounds` must have a finite width high - low; got low={lo!r}, high={hi!r}"
        )
    return lo, hi


def _parse_method(method) -> SpiralRule:
    if isinstance(method, SpiralRule):
        return method
    if isinstance(method, str) and method.lower() in _METHODS:
        return _METHODS[method.lower()]()
    names = ", ".join(repr(name) for name in _METHODS)
    raise ValueError(
        f"`method` must be {names} or a SpiralRule instance; got {method!r}"
    )


def _rule_output(out, k: int) -> tuple:
    """Check a custom rule's ``(r, theta)``: finite scalars or one per mover."""
    what = (
        "`method` rule must return (radius, angle), each a finite scalar or "
        f"shape ({k},)"
    )
    try:
        r, theta = out
    except (TypeError, ValueError):
        raise ValueError(f"{what}; got {out!r}") from None
    checked = []
    for value in (r, theta):
        arr = real_array(value, "method")
        if arr.ndim != 0 and arr.shape != (k,):
            raise ValueError(f"{what}; got shape {arr.shape}")
        # A NaN radius or angle would turn every mover into NaN silently.
        if not np.isfinite(arr).all():
            raise ValueError(f"{what}; got non-finite values {value!r}")
        checked.append(arr)
    return tuple(checked)


def _costs(raw, shape: tuple, what: str) -> np.ndarray:
    """Check what the objective returned: real numbers of the given shape."""
    arr = np.asarray(raw)
    # None or strings (object arrays) would turn into NaN or fail deep in
    # NumPy; complex costs cannot be ranked.
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"`fun` must return real numbers; got {raw!r:.80}")
    if arr.shape != shape:
        raise ValueError(f"`fun` must return {what}; got shape {arr.shape}")
    return arr


class SpiralSearch:
    """A spiral search you can step yourself; :func:`minimize` drives one.

    Constructing it draws the initial population and evaluates it
    (``n_points`` evaluations). Each :meth:`step` (or ``next(search)``)
    performs one iteration: ``n_points - 1`` evaluations. Row 0 of
    :attr:`population` is always the centre, so ties keep the incumbent.

    Parameters
    ----------
    fun, bounds, method, n_points, rng, vectorized, x0, bounds_policy
        As in :func:`minimize`.

    Examples
    --------
    >>> import numpy as np
    >>> search = SpiralSearch(lambda x: float(x @ x), [(-5, 5)] * 2, "sda", rng=0)
    >>> for _ in range(200):
    ...     x, f = search.step()
    >>> search.nit, search.nfev, bool(f < 1e-6)
    (200, 9850, True)
    """

    def __init__(
        self,
        fun: Callable,
        bounds,
        method="ebsda",
        *,
        n_points: int = 50,
        rng=None,
        vectorized: bool = False,
        x0=None,
        bounds_policy: str = "none",
    ):
        if not callable(fun):
            raise ValueError(f"`fun` must be callable; got {fun!r}")
        self._fun = fun
        self._lo, self._hi = _parse_bounds(bounds)
        self.rule = _parse_method(method)
        # Exact types: a subclass may override __call__.
        self._builtin_rule = type(self.rule) in _METHODS.values()
        m = integer(n_points, "n_points", 2)
        if not isinstance(bounds_policy, str) or bounds_policy not in _POLICIES:
            raise ValueError(
                f"`bounds_policy` must be one of {_POLICIES}; got {bounds_policy!r}"
            )
        self.bounds_policy = bounds_policy
        if not isinstance(vectorized, bool | np.bool_):
            raise ValueError(f"`vectorized` must be True or False; got {vectorized!r}")
        self.vectorized = bool(vectorized)
        n = self._lo.size
        seeds = self._parse_x0(x0, m, n)
        self._rng = generator(rng)
        x = np.empty((m, n))
        k = seeds.shape[0]
        x[:k] = seeds
        x[k:] = self._rng.uniform(self._lo, self._hi, size=(m - k, n))
        self._x = x
        self._f = self._evaluate(x)
        self.nfev = m
        self.nit = 0
        self._planes = _sweep_order(n)
        self._matrix = (None, None)
        self._promote()
        self.initial_nonfinite = not math.isfinite(self._f[0])
        self.history = [self._best_cost()]
        self.mean_radius: list[float] = []
        self.mean_angle: list[float] = []

    def _parse_x0(self, x0, m: int, n: int) -> np.ndarray:
        if x0 is None:
            return np.empty((0, n))
        try:
            arr = np.array(x0, dtype=np.float64, ndmin=1)
        except (TypeError, ValueError):
            raise ValueError(
                f"`x0` must be an array of shape ({n},) or (k, {n}) with "
                f"1 <= k <= n_points={m}; got {x0!r}"
            ) from None
        if arr.ndim == 1:
            arr = arr.reshape(1, -1)
        if arr.ndim != 2 or arr.shape[1] != n or not 1 <= arr.shape[0] <= m:
            raise ValueError(
                f"`x0` must have shape ({n},) or (k, {n}) with 1 <= k <= "
                f"n_points={m}; got shape {np.shape(x0)}"
            )
        if not np.all(np.isfinite(arr)):
            raise ValueError("`x0` must be finite; got non-finite entries")
        outside = np.flatnonzero(np.any((arr < self._lo) | (arr > self._hi), axis=1))
        if outside.size:
            raise ValueError(
                f"`x0` must lie within `bounds`; got {outside.size} point(s) "
                f"outside, the first being row {int(outside[0])}"
            )
        return arr

    def _evaluate(self, pts: np.ndarray) -> np.ndarray:
        k = pts.shape[0]
        if self.vectorized:
            what = (
                f"shape ({k},) for a ({k}, {pts.shape[1]}) batch when vectorized=True"
            )
            # A copy: the search reorders its costs in place, and the caller
            # may keep the array it returned.
            return np.array(_costs(self._fun(pts.copy()), (k,), what), np.float64)
        what = "a scalar when vectorized=False (pass vectorized=True for batches)"
        out = np.empty(k)
        for i in range(k):
            out[i] = _costs(self._fun(pts[i].copy()), (), what)
        return out

    def _promote(self) -> None:
        """Move the best finite point to row 0 (ties keep the incumbent)."""
        _kernels.promote(self._x, self._f)

    def _best_cost(self) -> float:
        f0 = float(self._f[0])
        return f0 if math.isfinite(f0) else math.inf

    def _deviations(self) -> np.ndarray:
        """``|f(x_i) - min J|`` of the moving points; ``inf`` if non-finite."""
        return _kernels.deviations(self._f)

    def _rotation(self, theta: float) -> np.ndarray:
        cached_theta, matrix = self._matrix
        if cached_theta != theta:
            matrix = rotation_matrix(self._lo.size, theta)
            self._matrix = (theta, matrix)
        return matrix

    def _apply_bounds(self, moving: np.ndarray) -> None:
        lo, hi = self._lo, self._hi
        if self.bounds_policy == "clip":
            np.clip(moving, lo, hi, out=moving)
        elif self.bounds_policy == "reflect":
            out = (moving < lo) | (moving > hi)
            if out.any():
                # Only touch escaped coordinates so that points inside the
                # box are not perturbed by rounding.
                w = hi - lo
                y = np.mod(moving - lo, 2.0 * w)
                y = np.where(y > w, 2.0 * w - y, y)
                moving[out] = (lo + y)[out]

    def step(self) -> tuple[np.ndarray, float]:
        """Perform one iteration; return the best point and cost."""
        x = self._x
        k = x.shape[0] - 1
        out = self.rule(self._deviations(), self._rng)
        # The built-in rules give finite values of the right shape by
        # construction; checking them would cost about a tenth of the
        # optimiser's own time per iteration.
        r, theta = out if self._builtin_rule else _rule_output(out, k)
        if np.ndim(theta) == 0 and np.ndim(r) == 0:
            # One angle for all points: one dense product beats the sweep.
            r = float(r)
            theta = float(theta)
            w = x[1:] - x[0]
            x[1:] = w @ self._rotation(theta).T
            x[1:] *= r
            x[1:] += x[0]
            self.mean_radius.append(r)
            self.mean_angle.append(theta)
        else:
            r = np.full(k, r) if np.ndim(r) == 0 else r
            theta = np.full(k, theta) if np.ndim(theta) == 0 else theta
            _kernels.spiral_step(x, r, theta, self._planes)
            self.mean_radius.append(float(r.sum()) / k)
            self.mean_angle.append(float(theta.sum()) / k)
        if self.bounds_policy != "none":
            self._apply_bounds(x[1:])
        self._f[1:] = self._evaluate(x[1:])
        self.nfev += k
        self.nit += 1
        self._promote()
        self.history.append(self._best_cost())
        return self.x, float(self._f[0])

    def __iter__(self):
        return self

    def __next__(self) -> tuple[np.ndarray, float]:
        return self.step()

    @property
    def x(self) -> np.ndarray:
        """The centre: best point so far."""
        return self._x[0].copy()

    @property
    def fun(self) -> float:
        """The centre's cost."""
        return float(self._f[0])

    @property
    def population(self) -> np.ndarray:
        """Current points, shape (n_points, n); row 0 is the centre."""
        return self._x.copy()

    @property
    def costs(self) -> np.ndarray:
        """Costs of :attr:`population`."""
        return self._f.copy()

    def result(self, status: str = "running", elapsed: float = 0.0, target=None):
        """Package the current state as a :class:`SpiralResult`.

        ``status`` is a key of the stop-message table: "max_iter",
        "max_nfev", "target", "callback" or "running".
        """
        if status not in _STATUS:
            raise ValueError(
                f"`status` must be one of {tuple(_STATUS)}; got {status!r}"
            )
        fun = self.fun
        finite = math.isfinite(fun)
        reached = target is None or (finite and fun <= target)
        notes = [_STATUS[status]]
        if self.initial_nonfinite and finite:
            notes.append(_NOTES["initial_nonfinite"])
        if not finite:
            notes.append(_NOTES["never_finite"])
        if status != "running" and not reached and finite:
            notes.append(_NOTES["target_missed"])
        success = status in ("max_iter", "max_nfev", "target") and finite and reached
        return SpiralResult(
            x=self.x,
            fun=fun,
            nit=self.nit,
            nfev=self.nfev,
            success=success,
            message=" ".join(notes),
            history=np.array(self.history),
            elapsed=elapsed,
            mean_radius=np.array(self.mean_radius),
            mean_angle=np.array(self.mean_angle),
        )


def minimize(
    fun: Callable,
    bounds,
    method="ebsda",
    *,
    n_points: int = 50,
    max_iter: int = 500,
    max_nfev: int | None = None,
    target: float | None = None,
    rng=None,
    vectorized: bool = False,
    x0=None,
    callback: Callable | None = None,
    bounds_policy: str = "none",
) -> SpiralResult:
    """Minimise ``fun`` with a spiral dynamic algorithm (SDA, Eb-SDA, LASDA).

    Parameters
    ----------
    fun : callable
        ``fun(x) -> float`` for ``x`` of shape (n,), or, with
        ``vectorized=True``, ``fun(X) -> (k,)`` for ``X`` of shape (k, n).
        Non-finite costs are allowed: they rank worst.
    bounds : sequence of (low, high), (n, 2) array or scipy.optimize.Bounds
        Box for the uniform initial points (finite, ``low < high``).
    method : {"ebsda", "sda", "lasda"} or SpiralRule
        ``"ebsda"``: exponential radius and angle, eq. (4), (7), (8)
        (:class:`~spiralid.optim.ExponentialSpiral`); ``"sda"``: constant
        ``r = 0.95, theta = pi/4`` (:class:`~spiralid.optim.ConstantSpiral`);
        ``"lasda"``: linear adaptive (:class:`~spiralid.optim.LinearSpiral`);
        or any rule object.
    n_points : int
        Number of search points ``m >= 2``.
    max_iter : int
        Maximum number of iterations ``k_max >= 1``.
    max_nfev : int, optional
        Budget of objective evaluations (``>= n_points``). The search stops
        before an iteration that would exceed it, so ``nfev <= max_nfev``.
        See :class:`SpiralResult` for how evaluations are counted.
    target : float, optional
        Stop as soon as the best cost is at or below ``target``.
    rng : None, int or numpy.random.Generator
        Seed or generator; the same seed gives the same result bit for bit.
    vectorized : bool
        Whether ``fun`` takes a batch of points (see ``fun``).
    x0 : array_like, shape (n,) or (k, n), optional
        Seeds the first ``k <= n_points`` initial points (inside
        ``bounds``); the rest are drawn uniformly.
    callback : callable, optional
        ``callback(intermediate_result)`` after every iteration (the last
        one included) with a :class:`SpiralResult`; returning True stops the
        search. If ``target`` is reached in the same iteration, the stop is
        reported as reaching the target.
    bounds_policy : {"none", "clip", "reflect"}
        What to do with points that leave the box. The paper has no bound
        handling, so ``"none"`` (the default) lets them go.

    Returns
    -------
    SpiralResult

    Examples
    --------
    >>> import numpy as np
    >>> sphere = lambda x: float(np.sum(x**2))
    >>> res = minimize(sphere, [(-5, 5)] * 2, "sda", rng=0)
    >>> res.success, res.nit, res.nfev, bool(res.fun < 1e-12)
    (True, 500, 24550, True)
    >>> res = minimize(sphere, [(-5, 5)] * 2, "ebsda", rng=0, target=1e-6)
    >>> res.message, bool(res.fun <= 1e-6)
    ('Target cost reached.', True)
    """
    start = time.perf_counter()
    max_iter = integer(max_iter, "max_iter", 1)
    m = integer(n_points, "n_points", 2)
    if max_nfev is not None:
        max_nfev = integer(max_nfev, "max_nfev", m)
    if target is not None:
        try:
            target = float(target)
        except (TypeError, ValueError):
            raise ValueError(
                f"`target` must be a real number or None; got {target!r}"
            ) from None
        if math.isnan(target):
            raise ValueError(f"`target` must be a real number or None; got {target!r}")
    if callback is not None and not callable(callback):
        raise ValueError(f"`callback` must be callable or None; got {callback!r}")
    search = SpiralSearch(
        fun,
        bounds,
        method,
        n_points=m,
        rng=rng,
        vectorized=vectorized,
        x0=x0,
        bounds_policy=bounds_policy,
    )
    status = None
    if target is not None and search.history[-1] <= target:
        status = "target"
    while status is None:
        if search.nit >= max_iter:
            status = "max_iter"
            break
        if max_nfev is not None and search.nfev + (m - 1) > max_nfev:
            status = "max_nfev"
            break
        search.step()
        # The callback sees every iteration, the last one included, so that
        # callers can time-stamp each entry of `history`.
        stop = callback is not None and callback(
            search.result("running", time.perf_counter() - start)
        )
        if target is not None and search.history[-1] <= target:
            status = "target"
        elif stop:
            status = "callback"
    return search.result(status, time.perf_counter() - start, target)
