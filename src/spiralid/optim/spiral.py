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

The learned-metric rule does not move a population: :func:`minimize` drives
a :class:`~spiralid.optim.LearnedMetricSearch` for it through the same
calls (``step``, ``restart``, ``collapsed``, ``next_step_cost``,
``result``), so budget, callback, target and restarts behave alike.
"""

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spiralid._checks import box_bounds, integer, real_array
from spiralid.choices import RULE_NAMES, require_names
from spiralid.optim import _kernels
from spiralid.optim._loop import (
    apply_bounds,
    check_max_time,
    finite_or_inf,
    point_in_box,
    seed_points,
    settings,
    stop_report,
)
from spiralid.optim._search import SearchBase
from spiralid.optim.learned import LearnedMetricSearch, LearnedMetricSpiral
from spiralid.optim.restarts import MIN_ITER, Restarts, parse_restarts
from spiralid.optim.result import OptimiserResult
from spiralid.optim.rotation import _sweep_order, rotation_matrix
from spiralid.optim.rules import (
    ConstantSpiral,
    ConvergentSpiral,
    ExponentialSpiral,
    LinearSpiral,
    PeriodicSpiral,
    SpiralRule,
    StepRateRule,
)

__all__ = ["MINIMIZE_OPTIONS", "RULES", "SpiralSearch", "minimize"]

_METHODS = {
    "sda": ConstantSpiral,
    "ebsda": ExponentialSpiral,
    "lasda": LinearSpiral,
    "ebsda-scaled": lambda: ExponentialSpiral(scale_free=True),
    "periodic": PeriodicSpiral,
    "convergent": ConvergentSpiral,
    "learned-metric": LearnedMetricSpiral,
}
# Rules whose output is right by construction (exact types: a subclass may
# override __call__).
_BUILTIN = (ConstantSpiral, ExponentialSpiral, LinearSpiral)
require_names(_METHODS, RULE_NAMES, "spiralid.optim.RULES")
# The rules by name: minimize() accepts them, and spiralid.sysid.identify()
# offers each as an identification method.
RULES = _METHODS


def _parse_method(
    method, name: str = "method"
) -> SpiralRule | StepRateRule | LearnedMetricSpiral:
    """The rule `method` names or is; refused naming `name`, the argument
    the caller took it as (an estimator's ``rule``, say)."""
    if isinstance(method, SpiralRule | StepRateRule | LearnedMetricSpiral):
        return method
    if isinstance(method, str) and method.lower() in _METHODS:
        return _METHODS[method.lower()]()
    names = ", ".join(repr(name) for name in _METHODS)
    # An unknown name is a wrong value; anything else a wrong type.
    error = ValueError if isinstance(method, str) else TypeError
    raise error(
        f"`{name}` must be {names}, a SpiralRule or a StepRateRule instance; "
        f"got {method!r}"
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


class SpiralSearch(SearchBase):
    """A spiral search you can step yourself; :func:`minimize` drives one.

    Constructing it draws the initial population and evaluates it
    (``n_points`` evaluations). Each :meth:`step` (or ``next(search)``)
    performs one iteration: ``n_points - 1`` evaluations. Row 0 of
    :attr:`population` is always the centre, so ties keep the incumbent.

    Parameters
    ----------
    fun, bounds, method, n_points, rng, vectorized, x0
        As in :func:`minimize`.
    bounds_policy : {"none", "clip", "reflect"}
        As the key of :func:`minimize`'s ``options``.
    max_iter : int, optional
        Iteration budget ``k_max`` that a
        :class:`~spiralid.optim.StepRateRule` schedules its step rate over
        (required for those rules; the search itself does not stop there).

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
        max_iter: int | None = None,
    ):
        super().__init__(
            fun,
            bounds,
            rng=rng,
            vectorized=vectorized,
            bounds_policy=bounds_policy,
            max_iter=max_iter,
        )
        self.rule = _parse_method(method)
        if isinstance(self.rule, LearnedMetricSpiral):
            raise ValueError(
                "`method` LearnedMetricSpiral polls from the centre: step it "
                "with LearnedMetricSearch, or run it with minimize()"
            )
        self._builtin_rule = type(self.rule) in _BUILTIN
        m = integer(n_points, "n_points", 2)
        n = self._lo.size
        seeds = seed_points(x0, self._lo, self._hi, m)
        self._planes = _sweep_order(n)
        self._matrix = (None, None)
        self._fixed = None
        if isinstance(self.rule, StepRateRule):
            if max_iter is None:
                raise ValueError(
                    "`max_iter` (the iteration budget k_max) is required for a "
                    f"step-rate rule such as {type(self.rule).__name__}"
                )
            self._fixed = _fixed_rotation(self.rule, n)
        # The best of earlier runs (restarts), as (x, f); row 0 is this run's.
        self._archive = (None, math.inf)
        self._populate(seeds, m)
        self.initial_nonfinite = not math.isfinite(self._f[0])
        self.history = [self._best_cost()]
        self.mean_radius: list[float] = []
        self.mean_angle: list[float] = []

    def _populate(self, seeds: np.ndarray, m: int) -> None:
        """Draw and evaluate a new run's population; ``seeds`` come first."""
        self._x = x = self._draw(seeds, m)
        self._f = self._evaluate(x)
        self.nfev += m
        self._promote()
        # Iterations are counted from the run's start for step-rate rules.
        self._run_start = self.nit
        self.last_move = self.nit

    def restart(self, n_points: int, max_iter: int | None = None) -> None:
        """Replace the population by ``n_points`` fresh uniform points.

        The best point so far is kept aside (it stays :attr:`x`), so the
        new run explores from scratch as IPOP-CMA-ES does. ``max_iter`` is
        the new run's iteration budget for step-rate rules.
        """
        m = integer(n_points, "n_points", 2)
        self._set_budget(max_iter)
        f0 = float(self._f[0])
        if math.isfinite(f0) and f0 < self._archive[1]:
            self._archive = (self._x[0].copy(), f0)
        self._populate(np.empty((0, self._lo.size)), m)
        self.restarts += 1
        self.history.append(self._best_cost())

    def _evaluate(self, pts: np.ndarray) -> np.ndarray:
        return self._costs(pts)

    def _promote(self) -> None:
        """Move the best finite point to row 0 (ties keep the incumbent)."""
        _kernels.promote(self._x, self._f)

    def _best_cost(self) -> float:
        f0 = float(self._f[0])
        return min(f0 if math.isfinite(f0) else math.inf, self._archive[1])

    def _deviations(self) -> np.ndarray:
        """``|f(x_i) - min J|`` of the moving points; ``inf`` if non-finite."""
        return _kernels.deviations(self._f)

    def _rotation(self, theta: float) -> np.ndarray:
        cached_theta, matrix = self._matrix
        if cached_theta != theta:
            matrix = rotation_matrix(self._lo.size, theta)
            self._matrix = (theta, matrix)
        return matrix

    def step(self) -> tuple[np.ndarray, float]:
        """Perform one iteration; return the best point and cost."""
        x = self._x
        k = x.shape[0] - 1
        centre_cost = finite_or_inf(self._f[0])
        if self._fixed is not None:
            self._step_rate(x)
        else:
            self._step_angles(x, k)
        if self.bounds_policy != "none":
            apply_bounds(x[1:], self._lo, self._hi, self.bounds_policy)
        self._f[1:] = self._evaluate(x[1:])
        self.nfev += k
        self.nit += 1
        self._promote()
        self.history.append(self._best_cost())
        # Step 4 of the convergence setting: k* is the iteration at which
        # the centre last moved (it only moves to a strictly better cost).
        if float(self._f[0]) < centre_cost:
            self.last_move = self.nit
        return self.x, self.fun

    def _step_rate(self, x: np.ndarray) -> None:
        """x_i <- x* + r(k) R (x_i - x*) with the rule's fixed R."""
        k = self.nit - self._run_start
        r = self.rule.step_rate(
            k, self.last_move - self._run_start, self._lo.size, self._k_max
        )
        if not self._builtin_rule:
            r = float(r)
            if not 0.0 < r <= 1.0:
                raise ValueError(
                    f"`method` step_rate must return a number in (0, 1]; got {r!r}"
                )
        w = x[1:] - x[0]
        x[1:] = w @ self._fixed.T
        x[1:] *= r
        x[1:] += x[0]
        self.mean_radius.append(float(r))
        self.mean_angle.append(math.nan)

    def _step_angles(self, x: np.ndarray, k: int) -> None:
        """x_i <- x* + r_i R(theta_i) (x_i - x*) with the rule's r_i, theta_i."""
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

    def move_centre(self, x, fun: float, nfev: int = 0) -> bool:
        """Replace the centre by `x` of cost `fun` if that is lower.

        For a point found outside the spiral moves, e.g. a local polish of
        the centre in a memetic search; the rule's next moves rotate about
        it, and it counts as the centre moving (for restarts and step-rate
        rules). It must lie within the bounds. `nfev`, the evaluations spent
        finding it, is added to :attr:`nfev` whether or not it is taken.
        Returns whether it was taken.
        """
        pt = point_in_box(x, self._lo, self._hi)
        self.nfev += integer(nfev, "nfev", 0)
        if not (math.isfinite(fun) and fun < self._f[0]):
            return False
        self._x[0] = pt
        self._f[0] = fun
        self.last_move = self.nit
        self.history[-1] = self._best_cost()
        return True

    @property
    def x(self) -> np.ndarray:
        """The best point so far: the centre, or an earlier run's best."""
        if self._archive[1] < finite_or_inf(self._f[0]):
            return self._archive[0].copy()
        return self._x[0].copy()

    @property
    def fun(self) -> float:
        """The cost of :attr:`x`."""
        return min(float(self._f[0]), self._archive[1])

    @property
    def centre(self) -> np.ndarray:
        """The current run's centre (row 0 of :attr:`population`)."""
        return self._x[0].copy()

    def next_step_cost(self) -> int:
        """Evaluations of the next :meth:`step`: every point but the centre."""
        return self.n_points - 1

    @property
    def n_points(self) -> int:
        """Size of the current run's population."""
        return self._x.shape[0]

    def collapsed(self, restarts: Restarts) -> bool:
        """Whether the current run has collapsed by ``restarts``' criteria."""
        width = float(np.max(self._hi - self._lo))
        return restarts.collapsed(
            self._x[1:] - self._x[0], width, self.nit - self.last_move
        )

    @property
    def population(self) -> np.ndarray:
        """Current points, shape (n_points, n); row 0 is the centre."""
        return self._x.copy()

    @property
    def costs(self) -> np.ndarray:
        """Costs of :attr:`population`."""
        return self._f.copy()

    @property
    def centre_cost(self) -> float:
        """The cost of :attr:`centre` (the current run's best)."""
        return float(self._f[0])

    def result(self, status: str = "running", elapsed: float = 0.0, target=None):
        """Package the current state as an
        :class:`~spiralid.optim.result.OptimiserResult` (see :func:`minimize`).

        ``status`` is a key of the stop-message table: "max_iter",
        "max_nfev", "max_time", "target", "callback" or "running".
        """
        return OptimiserResult(
            x=self.x,
            fun=self.fun,
            **stop_report(status, self.fun, target, self.initial_nonfinite),
            nit=self.nit,
            nfev=self.nfev,
            n_restarts=self.restarts,
            history=np.array(self.history),
            elapsed=elapsed,
            mean_radius=np.array(self.mean_radius),
            mean_angle=np.array(self.mean_angle),
        )


def _fixed_rotation(rule: StepRateRule, n: int) -> np.ndarray:
    """The rule's rotation matrix, checked once for shape and finiteness."""
    R = np.array(rule.rotation(n), dtype=np.float64)
    if R.shape != (n, n) or not np.all(np.isfinite(R)):
        raise ValueError(
            f"`method` rotation must be a finite ({n}, {n}) matrix; got {R!r:.80}"
        )
    return R


# minimize()'s rarely used settings and their defaults: keys of its
# `options` mapping, as scipy.optimize.minimize takes its solvers' settings.
MINIMIZE_OPTIONS = {"max_time": None, "target": None, "bounds_policy": "none"}


def _target(target) -> float | None:
    """`target` as a float (None: no target), or a ValueError naming it."""
    if target is None:
        return None
    try:
        value = float(target)
    except (TypeError, ValueError):
        value = math.nan
    if math.isnan(value):
        raise ValueError(f"`target` must be a real number or None; got {target!r}")
    return value


@dataclass
class _Budget:
    """When :func:`minimize` stops: its caps, time limit and target."""

    max_iter: int
    n_points: int
    max_nfev: int | None
    max_time: float | None
    target: float | None
    start: float
    # A learned-metric period's evaluations, whatever the population; None
    # for a spiral, whose iteration moves every point but the centre.
    poll_cost: int | None = None

    @classmethod
    def check(cls, max_iter, n_points, max_nfev, max_time, target, start):
        """The budget from minimize's arguments, each checked by name."""
        max_iter = integer(max_iter, "max_iter", 1)
        m = integer(n_points, "n_points", 2)
        if max_nfev is not None:
            max_nfev = integer(max_nfev, "max_nfev", m)
        max_time = check_max_time(max_time)
        return cls(max_iter, m, max_nfev, max_time, _target(target), start)

    def per_step(self, m: int) -> int:
        """Evaluations an iteration of a population of m points costs."""
        return m - 1 if self.poll_cost is None else self.poll_cost

    def elapsed(self) -> float:
        return time.perf_counter() - self.start

    def iterations_left(self, m: int, nit: int, nfev: int) -> int:
        """What the budget allows a population of m after nit iterations and
        nfev evaluations: a step-rate rule's schedule spans it."""
        left = self.max_iter - nit
        if self.max_nfev is not None:
            left = min(left, (self.max_nfev - nfev) // self.per_step(m))
        return left

    def reached(self, search) -> bool:
        return self.target is not None and search.fun <= self.target

    def exhausted(self, search) -> str | None:
        """The cap the next iteration would pass, if any."""
        if search.nit >= self.max_iter:
            return "max_iter"
        if (
            self.max_nfev is not None
            and search.nfev + search.next_step_cost() > self.max_nfev
        ):
            return "max_nfev"
        return None

    def after_step(self, search, stop: bool) -> str | None:
        """Why to stop after an iteration; the target outranks the callback."""
        if self.reached(search):
            return "target"
        if stop:
            return "callback"
        if self.max_time is not None and self.elapsed() > self.max_time:
            return "max_time"
        return None


def _restart(search, restarts: Restarts | None, budget: _Budget) -> bool:
    """Restart a collapsed run if its grown population can still make
    ``MIN_ITER`` iterations; whether it did."""
    if restarts is None or not search.collapsed(restarts):
        return False
    grown = restarts.next_size(search.n_points)
    left = budget.iterations_left(grown, search.nit, search.nfev + grown)
    if left < MIN_ITER:
        return False
    search.restart(grown, max_iter=left)
    return True


def _call_back(callback, search, budget: _Budget) -> bool:
    """Run the callback on the result so far; whether it asked to stop."""
    # It sees every iteration, the last one included, so that callers can
    # time-stamp each entry of `history`.
    if callback is None:
        return False
    intermediate = search.result("running", budget.elapsed())
    intermediate.search = search
    return bool(callback(intermediate))


def minimize(
    fun: Callable,
    bounds,
    method="ebsda",
    *,
    n_points: int = 50,
    max_iter: int = 500,
    max_nfev: int | None = None,
    rng=None,
    vectorized: bool = False,
    x0=None,
    callback: Callable | None = None,
    restarts: bool | Restarts = False,
    options: dict | None = None,
) -> OptimiserResult:
    """Minimise ``fun`` with a spiral dynamic algorithm (SDA, Eb-SDA, LASDA).

    Parameters
    ----------
    fun : callable
        ``fun(x) -> float`` for ``x`` of shape (n,), or, with
        ``vectorized=True``, ``fun(X) -> (k,)`` for ``X`` of shape (k, n).
        Non-finite costs are allowed: they rank worst.
    bounds : sequence of (low, high), (n, 2) array or scipy.optimize.Bounds
        Box for the uniform initial points (finite, ``low < high``).
    method : str, SpiralRule or StepRateRule
        ``"ebsda"``: exponential radius and angle, eq. (4), (7), (8)
        (:class:`~spiralid.optim.ExponentialSpiral`); ``"sda"``: constant
        ``r = 0.95, theta = pi/4`` (:class:`~spiralid.optim.ConstantSpiral`);
        ``"lasda"``: linear adaptive (:class:`~spiralid.optim.LinearSpiral`);
        ``"ebsda-scaled"``: Eb-SDA with ``scale_free=True``;
        ``"periodic"`` and ``"convergent"``: Tamura & Yasuda's
        periodic-descent-direction and convergence settings
        (:class:`~spiralid.optim.PeriodicSpiral`,
        :class:`~spiralid.optim.ConvergentSpiral`), whose step rate is
        scheduled over the iteration budget (``max_iter``, or fewer if
        ``max_nfev`` allows fewer); ``"learned-metric"``: the periodic
        directions polled from the centre in a learned basis
        (:class:`~spiralid.optim.LearnedMetricSpiral`, driven by a
        :class:`~spiralid.optim.LearnedMetricSearch`: an iteration is a
        period of ``2n`` polls and a model step); or any rule object.
    n_points : int
        Number of search points ``m >= 2`` (for ``"learned-metric"``: the
        uniform points whose best starts the poll).
    max_iter : int
        Maximum number of iterations ``k_max >= 1``.
    max_nfev : int, optional
        Budget of objective evaluations (``>= n_points``). The search stops
        before an iteration that would exceed it, so ``nfev <= max_nfev``.
        See Returns for how evaluations are counted.
    rng : None, int or numpy.random.Generator
        Seed or generator; the same seed gives the same result bit for bit.
    vectorized : bool
        Whether ``fun`` takes a batch of points (see ``fun``).
    x0 : array_like, shape (n,) or (k, n), optional
        Seeds the first ``k <= n_points`` initial points (inside
        ``bounds``); the rest are drawn uniformly.
    callback : callable, optional
        ``callback(intermediate_result)`` after every iteration (the last
        one included) with the result so far; returning True stops the
        search. If ``target`` is reached in the same iteration, the stop is
        reported as reaching the target. ``intermediate_result.search`` is
        the live search (a :class:`SpiralSearch` or
        :class:`~spiralid.optim.LearnedMetricSearch`): the callback may move
        its centre (:meth:`SpiralSearch.move_centre`, e.g. a local polish of
        it, as the memetic identification search does) or restart it; the
        evaluations it reports there count toward `max_nfev`.
    restarts : bool or Restarts
        IPOP-style restarts (:class:`~spiralid.optim.Restarts`): when a run
        has collapsed, start again from fresh uniform points with a larger
        population, within the same ``max_iter`` and ``max_nfev``; the best
        point of all runs is returned. Off by default (the paper's
        configurations). A restart happens only if its population can still
        make 10 iterations within the budget. The learned-metric rule
        alternates fresh polls with population periods (see its module).
    options : dict, optional
        The rarely used settings (:data:`MINIMIZE_OPTIONS`, with their
        defaults), as ``scipy.optimize.minimize`` takes its solvers'; any
        other key is refused in one line naming it:

        ``max_time`` : float or None
            Wall-time limit in seconds (a finite number > 0; default None,
            no limit). Checked after each iteration: the search ends after
            the iteration during which the limit passed, so it overruns by
            up to one iteration. Where a time limit stops it, the result is
            not reproducible from the seed alone.
        ``target`` : float or None
            Stop as soon as the best cost is at or below ``target``
            (default None, no target).
        ``bounds_policy`` : {"none", "clip", "reflect"}
            What to do with points that leave the box. The paper has no
            bound handling, so ``"none"`` (the default) lets them go.

    Returns
    -------
    OptimiserResult
        ``x`` (the best point: the final centre, or an earlier run's best),
        ``fun`` (its cost; non-finite only if no finite cost was ever
        found), ``status`` (a key of :data:`~spiralid.optim.result.STATUS`:
        1 at ``max_nfev``, 2 at ``max_iter``, 3 at ``max_time``, 0 at
        ``target`` or the callback), ``success`` (it ended on its budget,
        its time or ``target`` with a finite cost, and ``target`` reached if
        given), ``message``,
        ``nit`` (over all runs), ``nfev`` (one per point: ``n_points`` for
        the initial population, then ``n_points - 1`` per iteration, as the
        centre does not move and is not re-evaluated; each restart adds its
        new population), ``n_restarts``, ``history`` (best cost so far after
        each iteration and each restart's initial population, index 0 the
        initial population, non-finite as ``inf``, never increasing),
        ``elapsed`` (seconds), and ``mean_radius``, ``mean_angle`` (mean
        radius and angle in radians over the moving points at each
        iteration, for plots of the rule's behaviour; a
        :class:`~spiralid.optim.StepRateRule` has no angle: NaN).

    Examples
    --------
    >>> import numpy as np
    >>> sphere = lambda x: float(np.sum(x**2))
    >>> res = minimize(sphere, [(-5, 5)] * 2, "sda", rng=0)
    >>> res.success, res.nit, res.nfev, bool(res.fun < 1e-12)
    (True, 500, 24550, True)
    >>> res = minimize(sphere, [(-5, 5)] * 2, "ebsda", rng=0,
    ...                options={"target": 1e-6})
    >>> res.message, bool(res.fun <= 1e-6)
    ('Target cost reached.', True)
    """
    start = time.perf_counter()
    opts = settings(options, MINIMIZE_OPTIONS, "the options of minimize()")
    budget = _Budget.check(
        max_iter, n_points, max_nfev, opts["max_time"], opts["target"], start
    )
    if callback is not None and not callable(callback):
        raise TypeError(f"`callback` must be callable or None; got {callback!r}")
    restarts = parse_restarts(restarts)
    rule = _parse_method(method)
    n = box_bounds(bounds)[0].size
    learned = isinstance(rule, LearnedMetricSpiral)
    if learned:
        budget.poll_cost = rule.poll_cost(n)
    Search = LearnedMetricSearch if learned else SpiralSearch
    m = budget.n_points
    search = Search(
        fun,
        bounds,
        rule,
        n_points=m,
        rng=rng,
        vectorized=vectorized,
        x0=x0,
        bounds_policy=opts["bounds_policy"],
        max_iter=max(budget.iterations_left(m, 0, m), 1),
    )
    status = "target" if budget.reached(search) else None
    while status is None:
        status = budget.exhausted(search)
        if status is not None:
            break
        if _restart(search, restarts, budget):
            status = "target" if budget.reached(search) else None
            continue
        search.step()
        status = budget.after_step(search, _call_back(callback, search, budget))
    return search.result(status, budget.elapsed(), budget.target)
