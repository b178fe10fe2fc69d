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
   of each period's polled points
   (:class:`~spiralid.optim.encoding.AdaptiveEncoding`): on a quadratic,
   ``B B^T`` approaches the inverse Hessian up to scale, so the poll becomes
   coordinate descent along the problem's principal axes.
3. **A step per direction from success.** ``s_j`` is multiplied by 2 after
   a success and by 1/2 after a failure (Loshchilov, Schoenauer & Sebag's
   Adaptive Coordinate Descent, GECCO 2011), instead of the budget schedule
   ``delta^(1/k_max)`` of the periodic setting.
4. **A model step.** The three costs on each direction's line give a
   parabola; after the period the centre tries the minimum of that diagonal
   quadratic in the learned basis (one evaluation).
5. **Two regimes of restarts** (with :func:`~spiralid.optim.minimize`'s
   ``restarts``). A poll is a local search: it stops where no direction at
   any step improves, which on a rugged or stepped landscape is anywhere.
   As BIPOP-CMA-ES (Hansen, BBOB 2009) alternates a local regime with one of
   growing populations, restarts alternate between a fresh poll (from the
   best of a new uniform population) and a *population period*: the pairs
   are ``x* +- sigma B z_l`` for ``lambda / 2`` random ``z_l`` (mirrored
   samples, the spiral's opposite directions; optionally orthogonal in
   blocks of ``n``, as the periodic directions are), the centre moves to the
   weighted mean of the best half, whose cost is evaluated, and ``sigma``
   follows the mean's path (cumulative step-size adaptation, the path in
   the latest basis's coordinates: ``path_frame``; after the first
   population run, without the bias the mirrored pairs give it:
   ``unbiased_sigma``). Averaging over the best half is what lets a large
   population see through local minima; the population doubles at each
   such restart, as in IPOP. The regime whose runs have spent fewer
   evaluations goes next (BIPOP's rule).
   A poll that crawls (its gains fall far slower than its steps' squares)
   is suspended for a population run, and resumed if that run does no
   better (``suspend_crawl``, ``crawl_window``, ``extend_closing``).

The search runs in the box scaled to the unit cube, so the basis starts as
the box's own axes and the first poll steps are a quarter of its widths. A
run has collapsed when every step is below ``tol_radius`` (of the unit
cube), or the run has found no point better than its own best for
``stall`` periods, or the basis is conditioned beyond 1e14.
"""

import math
from collections import deque
from collections.abc import Callable

import numpy as np

from spiralid._checks import integer
from spiralid.optim._kernels import add_rows, orthonormal_rows, poll_offsets
from spiralid.optim._loop import (
    Trace,
    apply_bounds,
    check_costs,
    point_in_box,
    seed_points,
    stop_report,
)
from spiralid.optim._search import _SCALAR, SearchBase
from spiralid.optim.encoding import AdaptiveEncoding
from spiralid.optim.learned_rule import LearnedMetricSpiral
from spiralid.optim.restarts import Restarts
from spiralid.optim.result import OptimiserResult

__all__ = ["LearnedMetricSearch", "LearnedMetricSpiral"]

# A basis conditioned beyond this has lost the directions it learned to
# rounding; the run counts as collapsed.
_MAX_CONDITION = 1e14
# A population period's first step, in the unit cube (the sigma0 = 2 that
# IPOP-CMA-ES is run with on [-5, 5]^n).
_SIGMA0 = 0.2
_TINY = float(np.finfo(float).tiny)
_FLOAT = np.dtype(np.float64)
# suspend_crawl: a poll crawls when, over its last `w` periods (at least
# _CRAWL_MIN_WINDOW, `crawl_window` n otherwise), its gains fell
# by less than 1/_CRAWL_RATIO of the fall its steps' squares predict (a
# converging run's gains shrink with the square of its steps) while the
# metric's condition grew by less than _CRAWL_CONDITION (a metric still being
# learned makes Rosenbrock and the discus look alike), its largest step is
# below _CRAWL_STEP of the box (Rosenbrock's valley is followed with larger
# ones) and the condition below _CRAWL_MAX_CONDITION (a metric at the cap is
# still stretching: the bent cigar). The population run that follows gets
# _HELD_SHARE of the poll's evaluations to do better.
_CRAWL_MIN_WINDOW = 30
_CRAWL_RATIO = 10.0
_CRAWL_CONDITION = 1.5
_CRAWL_STEP = 1e-3
_CRAWL_MAX_CONDITION = 1e7
_HELD_SHARE = 0.5
# extend_closing: past that share, the population run goes on while, at its
# rate over its last n periods, it would reach the poll's cost within
# _CLOSING_WINDOWS times as many.
_CLOSING_WINDOWS = 3


# The reductions ndarray.max() and .sum() call, without their Python
# wrappers: a few microseconds a period, on vectors of n.
_add_up = np.add.reduce
_maximum = np.maximum.reduce


def paired_mu_eff(order: np.ndarray, half: int, weights: np.ndarray) -> float:
    """The variance-effective selection mass of a mirrored sample's mean step.

    The sample is ``half`` pairs, rows ``l`` and ``l + half`` the two members
    of pair ``l`` (``+z_l`` and ``-z_l``); ``order`` holds the selected rows,
    best first, ``weights`` their recombination weights. The mean's step is
    ``sum_l c_l z_l`` with ``c_l`` the pair's two weights with opposite
    signs, so under blind selection its squared length is ``n`` times
    ``sum_l c_l^2`` on average; the returned ``1 / sum_l c_l^2`` is
    CMA-ES's ``mu_eff`` when no pair has both members selected and larger
    when pairs cancel.
    """
    order = np.asarray(order)
    # Summed in the order given, as np.add.at sums, in a third of its time.
    coef = np.bincount(
        order % half, np.where(order < half, weights, -weights), minlength=half
    )
    total = float(coef @ coef)
    # Weights decrease strictly, so a selected pair never cancels exactly;
    # the guard only keeps rounding from dividing by zero.
    return 1.0 / max(total, _TINY)


def default_population(n: int) -> int:
    """The first population period's size: twice CMA-ES's default
    ``4 + floor(3 ln n)``, as IPOP's first restart (even, for mirroring)."""
    return 2 * (4 + int(3.0 * math.log(n)))


class LearnedMetricSearch(SearchBase):
    """The learned-metric search you can step yourself;
    :func:`~spiralid.optim.minimize` drives one for a
    :class:`LearnedMetricSpiral`.

    Constructing it draws ``n_points`` uniform points (``x0`` first),
    evaluates them and takes the best as the centre of a poll. Each
    :meth:`step` is one period: ``2n`` evaluations and the model step's one
    for a poll, ``lambda + 1`` for a population period.

    Parameters
    ----------
    fun, bounds, method, n_points, rng, vectorized, x0
        As in :func:`~spiralid.optim.minimize`; ``method`` is a
        :class:`LearnedMetricSpiral`.
    bounds_policy : {"none", "clip", "reflect"}
        As the key of :func:`~spiralid.optim.minimize`'s ``options``.
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
        super().__init__(
            fun,
            bounds,
            rng=rng,
            vectorized=vectorized,
            bounds_policy=bounds_policy,
            max_iter=max_iter,
        )
        if not isinstance(method, LearnedMetricSpiral):
            raise ValueError(f"`method` must be a LearnedMetricSpiral; got {method!r}")
        if method.crossover != LearnedMetricSpiral.crossover:
            raise ValueError(
                "`crossover` of LearnedMetricSpiral applies to minimize_pareto "
                "only (it crosses subproblems' incumbents); got "
                f"crossover={method.crossover!r}"
            )
        self.rule = method
        self._width = self._hi - self._lo
        if not method.success_steps and self._k_max is None:
            raise ValueError("`max_iter` is required when success_steps=False")
        n = self._lo.size
        m = integer(n_points, "n_points", 1)
        self._best = (None, math.inf)
        self._spent = {"poll": 0, "population": 0}
        self._population = default_population(n) // 2
        self._population_runs = 0
        self._held = None
        self._held_nfev = 0
        self._resumed = False
        self._polled = np.empty((2 * n, n))
        self._polled_f = np.empty(2 * n)
        # A poll period's offsets: pair j is c + signed[2j : 2j + 2].
        self._signed = np.empty((2 * n, n))
        # The poll's views of each pair's points and offsets, made once
        # rather than sliced anew at every pair.
        self._pair_views = [
            (self._polled[2 * j : 2 * j + 2], self._signed[2 * j : 2 * j + 2])
            for j in range(n)
        ]
        self._local_next = True
        seeds = seed_points(x0, self._lo, self._hi, m)
        if method.first_sigma is None:
            self._start_poll(seeds, m)
        else:
            # A population run from x0 (first_sigma): no first draw, its
            # centre evaluated first; `m` stays what a restart's poll grows.
            self._m = m
            centre = seeds[0] if len(seeds) else None
            self._start_population(self._population, centre, method.first_sigma)
        self.initial_nonfinite = not math.isfinite(self._f)
        self.history = Trace(self.fun)
        self._mean_step = Trace()

    # -- evaluation ----------------------------------------------------------
    def _evaluate(self, x: np.ndarray) -> np.ndarray:
        """Costs of the rows of `x`, non-finite as inf; keeps the best."""
        out = self._costs(x)
        self.nfev += x.shape[0]
        # A sum of squares is finite only if every cost is (it is never
        # NaN for finite costs, and an overflow only sends it to the mask,
        # which then changes nothing): one call instead of two.
        if not math.isfinite(out.dot(out)):
            out[~np.isfinite(out)] = math.inf
        best = int(out.argmin())
        if out[best] < self._best[1] or self._best[0] is None:
            self._best = (x[best].copy(), float(out[best]))
        return out

    def _evaluate_one(self, x: np.ndarray) -> float:
        """:meth:`_evaluate` for one point, `x` of shape ``(1, n)``, as a
        float: the model step and a population's mean are evaluated every
        period, and the general path's array calls cost more than a
        cheap objective."""
        if self.vectorized:
            (cost,) = self._listed(self._fun(x.copy()), x)
        else:
            cost = float(check_costs(self._fun(x[0].copy()), (), _SCALAR))
        self.nfev += 1
        if not math.isfinite(cost):
            cost = math.inf
        if cost < self._best[1] or self._best[0] is None:
            self._best = (x[0].copy(), cost)
        return cost

    def _listed(self, raw, x: np.ndarray) -> list:
        """A vectorised objective's costs `raw` for the rows of `x` as
        Python floats, checked only when they are not already a float64
        vector of the right length (the hot loops' common case)."""
        out = np.asarray(raw)
        k = x.shape[0]
        if out.dtype is _FLOAT and out.shape == (k,):
            return out.tolist()
        if out.shape != (k,) or out.dtype.kind not in "biuf":
            # Only now build the message.
            check_costs(raw, (k,), self._batch_shape(x))
        return [float(v) for v in out.tolist()]

    # -- runs ------------------------------------------------------------------
    def _start_poll(self, seeds: np.ndarray, m: int) -> None:
        """Start a poll from the best of `m` points (`seeds` first)."""
        n = self._lo.size
        x = self._draw(seeds, m)
        f = self._evaluate(x)
        best = int(np.argmin(f))  # the first of equal costs, a seed if any
        self._c = x[best].copy()
        self._f = float(f[best])
        self._steps = np.full(n, 0.25)
        self._encoding = AdaptiveEncoding(n, n, max_condition=self.rule.max_condition)
        self._encoding.eigen_every = self.rule.eigen_every(self._encoding)
        self._regime = "poll"
        self._flat = False
        self._m = m
        self._run_nfev = self.nfev - m
        self._run_best = self._f
        self.last_move = self.nit
        self._resumed = False
        self._trail = []
        self._crawled = False

    def _start_population(
        self, size: int, centre: np.ndarray | None = None, sigma: float = _SIGMA0
    ) -> None:
        """Start a population run of `size` points around `centre` (a
        uniform one if None) with step `sigma` (of the unit cube)."""
        n = self._lo.size
        if centre is None:
            centre = self._lo + self._rng.uniform(size=n) * self._width
        self._c = np.array(centre, dtype=float)
        self._f = self._evaluate_one(self._c[None, :])
        self._lambda = size
        self._population_runs += 1
        self._sigma = sigma
        self._path = np.zeros(n)
        self._encoding = AdaptiveEncoding.for_population(n, size // 2)
        self._encoding.eigen_every = self.rule.eigen_every(self._encoding)
        # Cumulative step-size adaptation's constants (Hansen's tutorial,
        # 2016): mu_eff, c_sigma, d_sigma and E|N(0, I)|.
        mu_eff = 1.0 / float(np.sum(self._encoding.weights**2))
        c_s = (mu_eff + 2.0) / (n + mu_eff + 5.0)
        d_s = 1.0 + 2.0 * max(0.0, math.sqrt((mu_eff - 1.0) / (n + 1.0)) - 1.0) + c_s
        chi_n = math.sqrt(n) * (1.0 - 1.0 / (4.0 * n) + 1.0 / (21.0 * n * n))
        self._csa = (mu_eff, c_s, d_s, chi_n)
        self._regime = "population"
        self._flat = False
        self._run_nfev = self.nfev - 1
        self._run_best = self._f
        self.last_move = self.nit
        self._trail = []
        self._crawled = False

    def restart(self, n_points: int, max_iter: int | None = None) -> None:
        """Start a new run: a poll from the best of ``n_points`` fresh
        uniform points, or (with ``populations``) a population run when
        those have spent fewer evaluations; the best point so far stays
        :attr:`x`."""
        m = integer(n_points, "n_points", 1)
        self._set_budget(max_iter)
        self._spent[self._regime] += self.nfev - self._run_nfev
        if self._crawled:
            # The crawling poll waits; a population run goes next.
            self._held = (self._c, self._f, self._steps, self._encoding, self._m)
            self._held_nfev = self.nfev - self._run_nfev
            # The run's best over its last n + 1 periods (extend_closing).
            self._closing = deque(maxlen=self._lo.size + 1)
            self._population *= 2
            self._start_population(self._population)
        elif self._held is not None and self._held[1] < self._run_best:
            held, self._held = self._held, None
            self._resume(held)
        else:
            self._held = None  # the population run did better: drop the poll
            self._next_run(m)
        self.restarts += 1
        self.history.append(self.fun)

    def _next_run(self, m: int) -> None:
        """BIPOP's rule: the regime whose runs have spent fewer evaluations."""
        if self.rule.populations and self._spent["population"] <= self._spent["poll"]:
            self._population *= 2
            local = self.rule.local_sigma
            if local is not None and self._local_next:
                # BIPOP's local regime: around the best so far, not anew.
                self._start_population(self._population, self.x, local)
            else:
                self._start_population(self._population)
            self._local_next = not self._local_next
        else:
            self._start_poll(np.empty((0, self._lo.size)), m)

    def _resume(self, held: tuple) -> None:
        """Resume a suspended poll where it stopped, never to be suspended
        again."""
        self._c, self._f, self._steps, self._encoding, self._m = held
        self._regime = "poll"
        self._flat = False
        self._run_nfev = self.nfev
        self._run_best = self._f
        self.last_move = self.nit
        self._resumed = True
        self._trail = []
        self._crawled = False

    def _crawling(self) -> bool:
        """Whether the poll crawls (see `suspend_crawl`)."""
        w = max(_CRAWL_MIN_WINDOW, int(self.rule.crawl_window * self._lo.size))
        trail = self._trail
        if len(trail) <= 2 * w:
            return False
        (old, _, _), (mid, mid_step, mid_cond), (now, now_step, now_cond) = (
            trail[-2 * w - 1],
            trail[-w - 1],
            trail[-1],
        )
        if now_step <= 0.0:
            return False  # steps underflowed: a stopped poll, for tol_radius
        recent = mid - now
        fall = (mid_step / now_step) ** 2
        return (
            recent > 0.0
            and (old - mid) * _CRAWL_RATIO < recent * fall
            and now_cond < _CRAWL_CONDITION * mid_cond
            and now_step < _CRAWL_STEP
            and now_cond < _CRAWL_MAX_CONDITION
        )

    def next_step_cost(self) -> int:
        """At most this many evaluations in the next :meth:`step`."""
        if self._regime == "population":
            return self._lambda + 1
        return self.rule.poll_cost(self._lo.size)

    # -- a period ----------------------------------------------------------------
    def step(self) -> tuple[np.ndarray, float]:
        """One period of the current run's regime."""
        if self._regime == "population":
            self._generation()
        else:
            self._poll_period()
        self.nit += 1
        # A restarted run is judged on its own progress: counted from the
        # best of all runs, a population run still converging was cut after
        # `stall` periods above a poll's earlier best (bent cigar, D = 20).
        best = self._period_best if self.rule.run_stall else self._best[1]
        if best < self._run_best:
            self._run_best = best
            self.last_move = self.nit
        rule = self.rule
        lengths = self._step_lengths()
        if (
            rule.suspend_crawl
            and rule.populations
            and self._regime == "poll"
            and not self._resumed
        ):
            self._trail.append(
                (self._run_best, float(_maximum(lengths)), self._encoding.condition)
            )
            self._crawled = self._crawling()
        elif self._held is not None and self._regime == "population":
            self._closing.append(self._run_best)
        self.history.append(self.fun)
        # np.mean's own sum and division, without its 3 us of dispatch.
        self._mean_step.append(float(_add_up(lengths)) / lengths.size)
        return self.x, self.fun

    def _poll_period(self) -> None:
        """The ``n`` opposite pairs, the model step, the basis update."""
        rule = self.rule
        n = self._lo.size
        # Directions in the problem's coordinates, one per row, interleaved
        # with their opposites in `_signed`. Column-major, as NumPy made it
        # from the basis's transpose: the model step's product then sums in
        # the same order.
        directions = np.empty((n, n), order="F")
        poll_offsets(
            self._encoding.basis,
            self._steps,
            self._width,
            self._c,
            directions,
            self._signed,
            self._polled,
        )
        success, model = self._pairs()
        if rule.success_steps:
            self._steps *= np.where(success, rule.grow, rule.shrink)
        if rule.model_step and any(model):
            trial = (self._c + np.asarray(model) @ directions)[None, :]
            if self.bounds_policy != "none":
                apply_bounds(trial, self._lo, self._hi, self.bounds_policy)
            cost = self._evaluate_one(trial)
            if cost < self._f:
                self._c, self._f = trial[0], cost
        self._period_best = self._f
        if not rule.success_steps:
            self._steps *= rule.delta ** (1.0 / self._k_max)
        # One sort for both: its ends are the costs' minimum and maximum
        # (no NaN, non-finite costs being inf).
        f = self._polled_f
        # The method, without np.argsort's dispatch.
        order = f.argsort(kind="stable")
        self._flat = bool(f[order[0]] == f[order[-1]])
        if rule.basis:
            self._encoding.update((self._polled[order[:n]] - self._lo) / self._width)

    def _pairs(self) -> tuple[np.ndarray, list]:
        """Poll the period's pairs ``x* + signed[2j : 2j + 2]`` (``x* +- s_j
        b_j``, ``signed`` the offsets in ``self._signed``) in turn, moving
        the centre to the better of a pair when it improves on it. Returns,
        per pair, whether it did, and the minimum of the parabola through
        the three costs in units of the direction from the (possibly moved)
        centre (0 if not convex).

        The rows of ``self._polled`` hold every pair from the centre on
        entry (:func:`~spiralid.optim._kernels.poll_offsets` wrote them);
        after a move each later pair is recomputed from the new centre just
        before it is evaluated (two rows, not all the rows left at each
        move).

        The hot loop of the search, two evaluations an iteration: the state
        is held in local names and written back once (also if ``fun``
        raises), and the costs are read as floats without
        :meth:`_evaluate`'s array bookkeeping.
        """
        n = self._lo.size
        polled_f = self._polled_f
        fun, vectorized = self._fun, self.vectorized
        bounded = self.bounds_policy != "none"
        c, fc = self._c, self._f
        best_x, best_f = self._best
        # An array: np.where reads a list of bools element by element.
        success = np.zeros(n, dtype=bool)
        model = [0.0] * n
        # Two costs per pair evaluated, so also the count of evaluations.
        costs = []
        isfinite, inf = math.isfinite, math.inf
        moved = False
        try:
            for j, (pair, offsets) in enumerate(self._pair_views):
                if moved:
                    add_rows(c, offsets, pair)
                if bounded:
                    apply_bounds(pair, self._lo, self._hi, self.bounds_policy)
                if vectorized:
                    raw = fun(pair.copy())
                    # _listed's common case inline: a call per pair costs.
                    if (
                        type(raw) is np.ndarray
                        and raw.dtype is _FLOAT
                        and raw.shape == (2,)
                    ):
                        a, b = raw.tolist()
                    else:
                        a, b = self._listed(raw, pair)
                else:
                    a = float(check_costs(fun(pair[0].copy()), (), _SCALAR))
                    b = float(check_costs(fun(pair[1].copy()), (), _SCALAR))
                if not isfinite(a):
                    a = inf
                if not isfinite(b):
                    b = inf
                costs.append(a)
                costs.append(b)
                if a <= b:
                    better, side = a, 0
                else:
                    better, side = b, 1
                curvature = a + b - 2.0 * fc
                vertex = 0.5 * (b - a) / curvature if curvature > 0.0 else 0.0
                if better < fc:
                    # The centre and the best point may share one array:
                    # neither is ever written in place.
                    c, fc = pair[side].copy(), better
                    if better < best_f:
                        best_x, best_f = c, better
                    moved = True
                    success[j] = True
                    # From the moved centre, the vertex is one step nearer.
                    vertex = (vertex - (1.0 if side == 0 else -1.0)) if vertex else 0.0
                elif better < best_f:
                    best_x, best_f = pair[side].copy(), better
                model[j] = vertex
        finally:
            self.nfev += len(costs)
            self._c, self._f = c, fc
            self._best = (best_x, best_f)
        polled_f[:] = costs
        return success, model

    def _generation(self) -> None:
        """A population period: mirrored pairs ``x* +- sigma B z_l``, the
        centre to the weighted mean of the best half, cumulative step-size
        adaptation (Hansen's tutorial, 2016, its path in the frame
        ``path_frame`` names) and the basis update."""
        n = self._lo.size
        enc = self._encoding
        half = self._lambda // 2
        u_centre = (self._c - self._lo) / self._width
        if self.rule.sampling == "orthogonal":
            z = self._orthogonal(half)
        else:
            z = self._rng.standard_normal((half, n))
        steps = self._sigma * (z @ enc.basis.T)
        u = np.empty((2 * half, n))
        np.add(u_centre, steps, out=u[:half])
        np.subtract(u_centre, steps, out=u[half:])
        x = self._lo + u * self._width
        if self.bounds_policy != "none":
            apply_bounds(x, self._lo, self._hi, self.bounds_policy)
            u = (x - self._lo) / self._width
        f = self._evaluate(x)
        order = f.argsort(kind="stable")[: enc.weights.size]
        selected = u[order]
        # Selection among equal costs is blind: a plateau, as pycma's
        # tolflatfitness.
        self._flat = bool(f[order[0]] == f[order[-1]])
        mean = enc.weights @ selected
        mu_eff, c_s, d_s, chi_n = self._csa
        mu_path = (
            paired_mu_eff(order, half, enc.weights)
            if self.rule.unbiased_sigma and self._population_runs > 1
            else mu_eff
        )
        shift = mean - u_centre
        move = enc.inverse @ shift / self._sigma
        if self.rule.path_frame == "cma":
            move = (enc.basis / enc.lengths) @ move  # V D^-1 V^T
        self._path = (1.0 - c_s) * self._path + math.sqrt(
            c_s * (2.0 - c_s) * mu_path
        ) * move
        # numpy.linalg.norm's own sum for a vector, without its dispatch.
        norm = math.sqrt(float(self._path.dot(self._path)))
        enc.learn(
            math.sqrt(mu_eff) * shift / self._sigma,
            (selected - u_centre) / self._sigma,
            normalise=False,
        )
        self._sigma *= math.exp(min(1.0, c_s / d_s * (norm / chi_n - 1.0)))
        self._c = self._lo + mean * self._width
        self._f = self._evaluate_one(self._c[None, :])
        self._period_best = min(self._f, float(f[order[0]]))

    def _orthogonal(self, count: int) -> np.ndarray:
        """`count` directions, rows, in blocks of ``n`` orthogonal ones of a
        uniformly random rotation, with Gaussian vectors' lengths.

        Independent mirrored directions can nearly repeat one another; the
        blocks cover the space evenly, as the poll's period does. On BBOB it
        gains about 0.01 of the triples at D = 10 and 20, within the spread
        of a few instances, so it is an option, not the default (the figures
        are in the BBOB results)."""
        n = self._lo.size
        blocks = []
        for start in range(0, count, n):
            k = min(n, count - start)
            # Gram-Schmidt on Gaussian rows gives rows of a uniformly random
            # rotation (Mezzadri, 2007); each gets a Gaussian vector's length.
            g = self._rng.standard_normal((2 * k, n))
            lengths = np.sqrt(np.einsum("ij,ij->i", g[k:], g[k:]))
            blocks.append(orthonormal_rows(g[:k]) * lengths[:, None])
        return np.concatenate(blocks)

    def _step_lengths(self) -> np.ndarray:
        """Each direction's step length in the unit cube."""
        scale = self._sigma if self._regime == "population" else self._steps
        return scale * self._encoding.lengths

    # -- the centre and its state ---------------------------------------------
    def move_centre(self, x, fun: float, nfev: int = 0) -> bool:
        """Replace the centre by `x` of cost `fun` if that is lower (as
        :meth:`spiralid.optim.SpiralSearch.move_centre`)."""
        pt = point_in_box(x, self._lo, self._hi)
        self.nfev += integer(nfev, "nfev", 0)
        if not (math.isfinite(fun) and fun < self._f):
            return False
        self._c = pt.copy()
        self._f = float(fun)
        if self._f < self._best[1]:
            self._best = (self._c.copy(), self._f)
        self.last_move = self.nit
        self.history.set_last(self.fun)
        return True

    def _closes_in(self) -> bool:
        """Whether the population run, at its rate over its last ``n``
        periods, reaches the suspended poll's cost within ``3 n`` more
        (``extend_closing``; so far while it has run fewer than ``n``)."""
        if not self.rule.extend_closing:
            return False
        trail = self._closing
        if len(trail) < trail.maxlen:
            return True
        gain = trail[0] - trail[-1]
        return _CLOSING_WINDOWS * gain >= trail[-1] - self._held[1]

    def collapsed(self, restarts: Restarts) -> bool:
        """Whether the current run has collapsed by ``restarts``' criteria
        (see the module's description)."""
        if (
            self._held is not None
            and self._regime == "population"
            and self.nfev - self._run_nfev > _HELD_SHARE * self._held_nfev
            and self._run_best >= self._held[1]
            and not self._closes_in()
        ):
            return True  # the suspended poll is better: resume it
        return (
            self._crawled
            or self._flat
            or self.nit - self.last_move >= restarts.stall_for(self._lo.size)
            or float(_maximum(self._step_lengths())) <= restarts.tol_radius
            or self._encoding.condition > _MAX_CONDITION
        )

    @property
    def n_points(self) -> int:
        """Size of the current poll's initial population: what IPOP grows."""
        return self._m

    @property
    def regime(self) -> str:
        """The current run's regime: ``"poll"`` or ``"population"``."""
        return self._regime

    @property
    def centre(self) -> np.ndarray:
        """The current run's centre."""
        return self._c.copy()

    @property
    def centre_cost(self) -> float:
        """The cost of :attr:`centre`."""
        return float(self._f)

    @property
    def x(self) -> np.ndarray:
        """The best point evaluated so far."""
        return self._best[0].copy()

    @property
    def fun(self) -> float:
        """The cost of :attr:`x` (inf while no cost was finite)."""
        return self._best[1]

    @property
    def basis(self) -> np.ndarray:
        """The learned basis ``B`` (columns), in the unit cube's coordinates."""
        return self._encoding.basis.copy()

    @property
    def steps(self) -> np.ndarray:
        """Each poll direction's step ``s_j``."""
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
