"""The learned-metric spiral: periodic directions polled in a learned basis.

Tamura & Yasuda's periodic-descent-direction setting
(:class:`~spiralid.optim.PeriodicSpiral`) turns each point's offset from the
centre through the ``2n`` directions ``R^k d`` of
:func:`~spiralid.optim.descent_rotation`; for ``d = e_1`` these are
``e_1, ..., e_n, -e_1, ..., -e_n``. One step rate for every direction, in
the problem's own coordinates, cannot follow an ill-conditioned or rotated
valley: on BBOB the spiral rules reach a third of IPOP-CMA-ES's targets.
:class:`LearnedMetricSpiral` keeps the periodic directions and learns the
metric they are taken in:

1. **Poll from the centre.** At step ``j`` of a period the centre ``x*``
   tries the opposite pair ``R^j d`` and ``R^(j+n) d = -R^j d``, scaled by
   the direction's step ``s_j``: ``x* +- s_j b_j``. The better of the two
   becomes the centre if it improves on it. A period (one iteration) is
   ``n`` pairs, ``2n`` evaluations.
2. **A learned basis.** The directions are the columns ``b_j`` of a basis
   ``B`` learned by Adaptive Encoding (Hansen, PPSN 2008) from the best half
   of each period's polled points (:class:`AdaptiveEncoding`): on a
   quadratic, ``B B^T`` approaches the inverse Hessian up to scale, so the
   poll becomes coordinate descent along the problem's principal axes.
3. **A step per direction from success.** ``s_j`` is multiplied by 2 after
   a success and by 1/2 after a failure (Loshchilov, Schoenauer & Sebag's
   Adaptive Coordinate Descent, GECCO 2011), instead of the budget schedule
   ``delta^(1/k_max)`` of the periodic setting.

The search runs in the box scaled to the unit cube, so the basis starts as
the box's own axes and the first steps are a quarter of its widths.
:func:`~spiralid.optim.minimize` drives it like every rule (same budget,
bounds policy, callback and result), ``restarts=True`` included: a run that
has collapsed (every step below ``tol_radius``, or no centre move for
``stall`` periods, or a basis conditioned beyond 1e14) starts again from the
best of a fresh uniform population, IPOP's growth applying to that
population.
"""

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spiralid._checks import box_bounds, generator, integer, positive
from spiralid.optim._loop import (
    Trace,
    apply_bounds,
    check_costs,
    check_policy,
    seed_points,
    stop_report,
)
from spiralid.optim.restarts import Restarts
from spiralid.optim.result import OptimiserResult

__all__ = ["AdaptiveEncoding", "LearnedMetricSearch", "LearnedMetricSpiral"]

_SCALAR = "a scalar when vectorized=False (pass vectorized=True for batches)"
# A basis conditioned beyond this has lost the directions it learned to
# rounding; the run counts as collapsed.
_MAX_CONDITION = 1e14


@dataclass(frozen=True)
class LearnedMetricSpiral:
    """The learned-metric spiral rule (see the module's description).

    Its ingredients can be switched off one at a time, to measure each.

    Parameters
    ----------
    basis : bool
        Learn the basis by Adaptive Encoding (default); False polls the
        box's own axes.
    success_steps : bool
        Adapt a step per direction from success (default); False shrinks
        every step by the periodic setting's ``delta^(1/k_max)`` per period.
    model_step : bool
        After each period, try the minimum of the diagonal quadratic model
        that the pairs' costs give in the learned basis (one evaluation;
        default).
    grow, shrink : float
        Step factors after a success (``> 1``) and a failure (in (0, 1));
        default 2 and 1/2, Adaptive Coordinate Descent's.
    delta : float
        Contraction over the run's budget when ``success_steps=False``.

    Examples
    --------
    >>> import numpy as np
    >>> from spiralid.optim import minimize
    >>> H = np.diag(10.0 ** np.linspace(0, 6, 5))  # condition 1e6
    >>> res = minimize(lambda x: float(x @ H @ x), [(-5, 5)] * 5,
    ...                LearnedMetricSpiral(), max_nfev=5000, rng=0)
    >>> bool(res.fun < 1e-10)
    True
    """

    basis: bool = True
    success_steps: bool = True
    model_step: bool = True
    grow: float = 2.0
    shrink: float = 0.5
    delta: float = 1e-3

    def __post_init__(self):
        for name in ("basis", "success_steps", "model_step"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"`{name}` must be True or False")
        grow = positive(self.grow, "grow")
        if grow <= 1.0:
            raise ValueError(f"`grow` must be > 1; got {self.grow!r}")
        for name in ("shrink", "delta"):
            value = positive(getattr(self, name), name)
            if value >= 1.0:
                raise ValueError(f"`{name}` must be in (0, 1); got {value!r}")
            object.__setattr__(self, name, value)
        object.__setattr__(self, "grow", grow)

    def evaluations_per_period(self, n: int) -> int:
        """At most this many evaluations per period (iteration) in dimension
        ``n``: ``2n`` polls and the model step's one."""
        return 2 * n + self.model_step


class AdaptiveEncoding:
    """A coordinate system learned from selected points (Hansen, PPSN 2008).

    Each :meth:`update` takes the ``mu`` best points of a sample, best first.
    Their weighted mean moves from the previous one; that step and the
    points' offsets from the previous mean, each normalised to length
    ``sqrt(n)`` in the current metric, update a covariance ``C`` (a rank-one
    term from the evolution path of the mean's steps, a rank-``mu`` term
    from the points). The basis is ``B = B_o D`` with ``C = B_o D^2 B_o^T``.
    On a convex quadratic ``C`` approaches the inverse Hessian up to scale.

    Parameters
    ----------
    n : int
        Dimension.
    mu : int
        Points per update; they get CMA-ES's log-decreasing weights.
    c_p, c_1, c_mu : float, optional
        Learning rates of the path and the rank-one and rank-``mu`` terms;
        defaults ``1/sqrt(n)``, ``0.5/n`` and ``0.5/n``, Adaptive
        Coordinate Descent's (Loshchilov et al., GECCO 2011).

    Examples
    --------
    >>> enc = AdaptiveEncoding(2, 2)
    >>> enc.basis.tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """

    def __init__(self, n: int, mu: int, *, c_p=None, c_1=None, c_mu=None):
        self.n = n = integer(n, "n", 1)
        mu = integer(mu, "mu", 1)
        w = np.log(mu + 0.5) - np.log(np.arange(1, mu + 1))
        self.weights = w / w.sum()
        self.c_p = 1.0 / math.sqrt(n) if c_p is None else positive(c_p, "c_p")
        self.c_1 = 0.5 / n if c_1 is None else positive(c_1, "c_1")
        self.c_mu = 0.5 / n if c_mu is None else positive(c_mu, "c_mu")
        if self.c_p > 1.0 or self.c_1 + self.c_mu > 1.0:
            raise ValueError("`c_p` and `c_1 + c_mu` must be at most 1")
        self.covariance = np.eye(n)
        self.basis = np.eye(n)
        self._inverse = np.eye(n)
        self.path = np.zeros(n)
        self.mean = None
        self.condition = 1.0

    def _normalised(self, steps: np.ndarray) -> np.ndarray:
        """Rows scaled to length sqrt(n) in the current metric (zero rows
        stay zero)."""
        lengths = np.linalg.norm(steps @ self._inverse.T, axis=1)
        scale = np.divide(
            math.sqrt(self.n), lengths, out=np.zeros_like(lengths), where=lengths > 0
        )
        return steps * scale[:, None]

    def update(self, points) -> None:
        """Learn from the ``mu`` best points of a sample, best first."""
        x = np.asarray(points, dtype=np.float64)
        if x.shape != (self.weights.size, self.n):
            raise ValueError(
                f"`points` must have shape ({self.weights.size}, {self.n}); "
                f"got {x.shape}"
            )
        mean = self.weights @ x
        if self.mean is None:
            self.mean = mean
            return
        old = self.mean
        self.mean = mean
        c_p, c_1, c_mu = self.c_p, self.c_1, self.c_mu
        z = self._normalised(np.vstack([mean - old, x - old]))
        self.path = (1.0 - c_p) * self.path + math.sqrt(c_p * (2.0 - c_p)) * z[0]
        rank_mu = (z[1:].T * self.weights) @ z[1:]
        C = (1.0 - c_1 - c_mu) * self.covariance
        C += c_1 * np.outer(self.path, self.path) + c_mu * rank_mu
        C = 0.5 * (C + C.T)
        values, vectors = np.linalg.eigh(C)
        if not (np.all(np.isfinite(values)) and values[0] > 0.0):
            # Rounding broke positive definiteness: keep the last metric.
            self.condition = math.inf
            return
        self.covariance = C
        d = np.sqrt(values)
        self.basis = vectors * d
        self._inverse = (vectors / d).T
        self.condition = float(values[-1] / values[0])


class LearnedMetricSearch:
    """The learned-metric poll you can step yourself; :func:`minimize`
    drives one for a :class:`LearnedMetricSpiral`.

    Constructing it draws ``n_points`` uniform points (``x0`` first),
    evaluates them and takes the best as the centre. Each :meth:`step` is
    one period: ``2n`` evaluations.

    Parameters
    ----------
    fun, bounds, method, n_points, rng, vectorized, x0, bounds_policy
        As in :func:`~spiralid.optim.minimize`; ``method`` is a
        :class:`LearnedMetricSpiral`.
    max_iter : int, optional
        The run's iteration budget, over which ``success_steps=False``
        schedules its contraction (required then).
    """

    def __init__(
        self,
        fun: Callable,
        bounds,
        method: LearnedMetricSpiral,
        *,
        n_points: int = 50,
        rng=None,
        vectorized: bool = False,
        x0=None,
        bounds_policy: str = "none",
        max_iter: int | None = None,
    ):
        if not callable(fun):
            raise ValueError(f"`fun` must be callable; got {fun!r}")
        if not isinstance(method, LearnedMetricSpiral):
            raise ValueError(f"`method` must be a LearnedMetricSpiral; got {method!r}")
        if not isinstance(vectorized, bool | np.bool_):
            raise ValueError(f"`vectorized` must be True or False; got {vectorized!r}")
        self._fun = fun
        self.rule = method
        self._lo, self._hi = box_bounds(bounds)
        self._width = self._hi - self._lo
        self.bounds_policy = check_policy(bounds_policy)
        self.vectorized = bool(vectorized)
        self._rng = generator(rng)
        self._k_max = None if max_iter is None else integer(max_iter, "max_iter", 1)
        if not method.success_steps and self._k_max is None:
            raise ValueError("`max_iter` is required when success_steps=False")
        n = self._lo.size
        m = integer(n_points, "n_points", 1)
        seeds = seed_points(x0, self._lo, self._hi, m)
        self.nfev = 0
        self.nit = 0
        self.restarts = 0
        self._archive = (None, math.inf)
        self._polled = np.empty((2 * n, n))
        self._polled_f = np.empty(2 * n)
        self._populate(seeds, m)
        self.initial_nonfinite = not math.isfinite(self._f)
        self.history = Trace(self.fun)
        self._mean_step = Trace()

    # -- evaluation ----------------------------------------------------------
    def _evaluate(self, x: np.ndarray) -> np.ndarray:
        k = x.shape[0]
        if self.vectorized:
            out = check_costs(self._fun(x.copy()), (k,), self._batch_shape(x))
            out = np.array(out, np.float64)
        else:
            out = np.empty(k)
            for i in range(k):
                out[i] = check_costs(self._fun(x[i].copy()), (), _SCALAR)
        self.nfev += k
        out[~np.isfinite(out)] = math.inf
        return out

    def _evaluate_pair(self, pair: np.ndarray) -> tuple[float, float]:
        """Costs of two points as floats, non-finite as inf: the poll's hot
        path, without the array bookkeeping of :meth:`_evaluate`."""
        if self.vectorized:
            out = check_costs(self._fun(pair.copy()), (2,), self._batch_shape(pair))
            a, b = float(out[0]), float(out[1])
        else:
            a = float(check_costs(self._fun(pair[0].copy()), (), _SCALAR))
            b = float(check_costs(self._fun(pair[1].copy()), (), _SCALAR))
        self.nfev += 2
        return (
            a if math.isfinite(a) else math.inf,
            b if math.isfinite(b) else math.inf,
        )

    @staticmethod
    def _batch_shape(x: np.ndarray) -> str:
        k, n = x.shape
        return f"shape ({k},) for a ({k}, {n}) batch when vectorized=True"

    def _populate(self, seeds: np.ndarray, m: int) -> None:
        """Start a run from the best of `m` points (`seeds` first)."""
        n = self._lo.size
        x = np.empty((m, n))
        k = seeds.shape[0]
        x[:k] = seeds
        x[k:] = self._rng.uniform(self._lo, self._hi, size=(m - k, n))
        f = self._evaluate(x)
        best = int(np.argmin(f))  # the first of equal costs, a seed if any
        self._c = x[best].copy()
        self._f = float(f[best])
        self._steps = np.full(n, 0.25)
        self._encoding = AdaptiveEncoding(n, n)
        self._run_start = self.nit
        self._m = m
        self.last_move = self.nit

    def restart(self, n_points: int, max_iter: int | None = None) -> None:
        """Start a new run from the best of ``n_points`` fresh uniform points
        with a fresh basis and steps; the best point so far stays :attr:`x`."""
        m = integer(n_points, "n_points", 1)
        if max_iter is not None:
            self._k_max = integer(max_iter, "max_iter", 1)
        if self._f < self._archive[1]:
            self._archive = (self.centre, self._f)
        self._populate(np.empty((0, self._lo.size)), m)
        self.restarts += 1
        self.history.append(self.fun)

    # -- the poll ------------------------------------------------------------
    def step(self) -> tuple[np.ndarray, float]:
        """One period: the ``n`` opposite pairs, the model step, then the
        basis update."""
        rule = self.rule
        n = self._lo.size
        # Directions in the problem's coordinates, one per row.
        directions = (self._encoding.basis.T * self._steps[:, None]) * self._width
        cost = self._f
        model = np.zeros(n)
        for j in range(n):
            success, model[j] = self._poll(j, directions[j])
            if rule.success_steps:
                self._steps[j] *= rule.grow if success else rule.shrink
        if rule.model_step and np.any(model):
            self._try(self._c + model @ directions)
        if not rule.success_steps:
            self._steps *= rule.delta ** (1.0 / self._k_max)
        if rule.basis:
            best = np.argsort(self._polled_f, kind="stable")[:n]
            self._encoding.update((self._polled[best] - self._lo) / self._width)
        self.nit += 1
        if self._f < cost:
            self.last_move = self.nit
        self.history.append(self.fun)
        self._mean_step.append(float(self._step_lengths().mean()))
        return self.x, self.fun

    def _poll(self, j: int, direction: np.ndarray) -> tuple[bool, float]:
        """Poll ``x* +- direction`` (step ``j`` of the period); move the
        centre to the better if it improves. Returns whether it did, and the
        minimum of the parabola through the three costs, in units of
        `direction` from the (possibly moved) centre (0 if not convex)."""
        pair = self._polled[2 * j : 2 * j + 2]
        np.add(self._c, direction, out=pair[0])
        np.subtract(self._c, direction, out=pair[1])
        if self.bounds_policy != "none":
            apply_bounds(pair, self._lo, self._hi, self.bounds_policy)
        a, b = self._evaluate_pair(pair)
        self._polled_f[2 * j] = a
        self._polled_f[2 * j + 1] = b
        curvature = a + b - 2.0 * self._f
        vertex = 0.5 * (b - a) / curvature if curvature > 0.0 else 0.0
        better, side = (a, 0) if a <= b else (b, 1)
        if not better < self._f:
            return False, vertex
        self._c = pair[side].copy()
        self._f = better
        return True, vertex - (1.0 if side == 0 else -1.0) if vertex else 0.0

    def _try(self, point: np.ndarray) -> None:
        """Evaluate one point; it becomes the centre if it improves."""
        trial = point[None, :]
        if self.bounds_policy != "none":
            apply_bounds(trial, self._lo, self._hi, self.bounds_policy)
        cost = float(self._evaluate(trial)[0])
        if cost < self._f:
            self._c, self._f = trial[0], cost

    def _step_lengths(self) -> np.ndarray:
        """Each direction's step length in the unit cube."""
        return self._steps * np.linalg.norm(self._encoding.basis, axis=0)

    def move_centre(self, x, fun: float, nfev: int = 0) -> bool:
        """Replace the centre by `x` of cost `fun` if that is lower (as
        :meth:`spiralid.optim.SpiralSearch.move_centre`)."""
        pt = np.asarray(x, dtype=np.float64)
        if pt.shape != self._lo.shape or not np.all(np.isfinite(pt)):
            raise ValueError(
                f"`x` must be a finite vector of shape {self._lo.shape}; got {x!r}"
            )
        if np.any((pt < self._lo) | (pt > self._hi)):
            raise ValueError("`x` must lie within `bounds`")
        self.nfev += integer(nfev, "nfev", 0)
        if not (math.isfinite(fun) and fun < self._f):
            return False
        self._c = pt.copy()
        self._f = float(fun)
        self.last_move = self.nit
        self.history.set_last(self.fun)
        return True

    def collapsed(self, restarts: Restarts) -> bool:
        """Whether the current run has collapsed by ``restarts``' criteria
        (see the module's description)."""
        n = self._lo.size
        stall = max(30, 4 * n) if restarts.stall is None else restarts.stall
        return (
            self.nit - self.last_move >= stall
            or float(self._step_lengths().max()) <= restarts.tol_radius
            or self._encoding.condition > _MAX_CONDITION
        )

    # -- state ---------------------------------------------------------------
    @property
    def n_points(self) -> int:
        """Size of the current run's initial population: what IPOP grows."""
        return self._m

    @property
    def centre(self) -> np.ndarray:
        """The current run's centre."""
        return self._c.copy()

    @property
    def x(self) -> np.ndarray:
        """The best point so far: the centre, or an earlier run's best."""
        if self._archive[1] < self._f:
            return self._archive[0].copy()
        return self.centre

    @property
    def fun(self) -> float:
        """The cost of :attr:`x`."""
        return min(self._f, self._archive[1])

    @property
    def basis(self) -> np.ndarray:
        """The learned basis ``B`` (columns), in the unit cube's coordinates."""
        return self._encoding.basis.copy()

    @property
    def steps(self) -> np.ndarray:
        """Each direction's step ``s_j``."""
        return self._steps.copy()

    def result(self, status: str = "running", elapsed: float = 0.0, target=None):
        """Package the current state as an
        :class:`~spiralid.optim.result.OptimiserResult` (see
        :func:`~spiralid.optim.minimize`)."""
        return OptimiserResult(
            x=self.x,
            fun=self.fun,
            **stop_report(status, self.fun, target, self.initial_nonfinite),
            nit=self.nit,
            nfev=self.nfev,
            n_restarts=self.restarts,
            history=self.history.array(),
            elapsed=elapsed,
            mean_radius=self._mean_step.array(),
            mean_angle=np.full(len(self._mean_step), math.nan),
        )
