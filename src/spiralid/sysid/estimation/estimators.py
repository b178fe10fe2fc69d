"""Estimators: one function per method, chosen by name from :data:`METHODS`.

As ``scipy.optimize`` has one ``_minimize_<method>`` per method,
:func:`~spiralid.sysid.identify` checks its arguments, gathers them in a
:class:`Problem` and calls ``METHODS[method].estimate(problem, **options)``.
Every estimator returns an :class:`EstimatorResult`, an ``OptimizeResult``
whose ``x`` is the ARX theta.

Methods
-------
``"sda"``, ``"ebsda"``, ``"lasda"`` (and every other rule in
:data:`spiralid.optim.RULES`)
    The spiral optimisers of :func:`spiralid.optim.minimize` over the
    paper's cost :class:`~spiralid.sysid.PaperCost` (eq. (2)-(3)), in a
    parametrisation of :mod:`spiralid.sysid.estimation.parametrizations`.
``"de"``
    SciPy's differential evolution over the same cost, box and initial
    points (:func:`spiralid.optim.differential_evolution`), a baseline.
``"ls"``
    Least squares, the exact minimiser of the one-step error.
``"oe"``
    Output error (:mod:`spiralid.sysid.estimation.outputerror`): Levenberg-Marquardt on
    the simulation error from the least-squares and the Steiglitz-McBride
    starts, keeping the lower estimation cost.

Budget
------
:func:`search_options` is the one budget rule (``identify``, the command
line and ``spiralid reproduce`` use it): a budget of evaluations
``max_nfev`` is the stop; without an explicit ``max_iter`` the iteration
cap is set to ``max_nfev``, which never binds first (every iteration costs
at least one evaluation). Without ``max_nfev`` the optimiser's own
``max_iter`` default (500) applies.

Safe start
----------
With ``safe_start=True`` a search's first population holds the stabilised
least-squares estimate and the zero model (mapped into the searched
coordinates and clipped into the box), and ``refine`` polishes from the
least-squares and Steiglitz-McBride starts too, beside the search's best.
The centre of a spiral search and the best member of DE never get worse,
and a polish is kept only if it lowers the cost, so the result costs no
more than either model (when the box holds them, as the default boxes
do). The paper's configurations leave it off (``Method.safe_start=False``
for ``sda``, ``ebsda``, ``lasda`` and ``de``): their first populations are
the paper's, so their numbers per seed stay as printed. A method added for
usable models turns it on in its table entry.

Stability margin and pole-zero cancellation
--------------------------------------------
``"spiral"`` and ``"oe"`` (``Method.margin``, ``Method.cancel``) keep every
pole inside radius ``exp(-ts / T)``, ``T`` the estimation record's length by
default (identify's ``max_time_constant``,
:mod:`~spiralid.sysid.estimation.margin`; also the polish of
``refine=True``), and remove a pole-zero pair closer than the record's
frequency resolution when that costs at most 1 % (identify's ``cancel``,
:mod:`~spiralid.sysid.estimation.cancellation`). The paper's searches and
``"de"`` keep eq. (3)'s penalty alone.

Status
------
``status`` is a key of :data:`STATUS`: ``1`` when the estimator stopped at
its evaluation cap (a search's ``max_nfev``; the Levenberg-Marquardt polish
of ``"oe"`` and ``refine`` at ``least_squares``' ``max_nfev``, before its
tolerances were met), ``2`` at an iteration cap, ``0`` otherwise. The polish
of ``refine`` is in ``result.refine`` with its own status.

Adding a method
---------------
Write ``_estimate_<name>(problem, **options) -> EstimatorResult`` here (or
in a module of its own that this one imports): a population search builds
on :func:`_search` with its optimiser, which gives it the parametrisation,
the box, the initial points, the safe start, the status and ``refine``.
Then add one entry to :data:`METHODS`::

    METHODS["name"] = Method(_estimate_name, search=True, safe_start=True)

``identify(method=...)``, the command line's ``--method`` choices and
``spiralid reproduce``'s configurations read that table; nothing else lists
methods. :data:`DEFAULT_METHOD` is the default of ``identify`` and of
``spiralid identify``.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from spiralid._checks import integer
from spiralid.choices import DEFAULT_METHOD, METHOD_NAMES, require_names
from spiralid.optim import (
    MINIMIZE_OPTIONS,
    RULES,
    Restarts,
    differential_evolution,
    minimize,
)
from spiralid.optim.result import STATUS, OptimiserResult

from ..data import IOData
from ..models.arx import ARX, arx_least_squares
from . import heldback
from . import narx as _narx
from .cost import PaperCost
from .heldback import HOLDBACK
from .outputerror import local_polish, steiglitz_mcbride
from .parametrizations import (
    DEFAULT_PARAMETRIZATION,
    Parametrization,
    make_parametrization,
)

__all__ = [
    "DEFAULT_METHOD",
    "METHODS",
    "SEARCH_PROBLEM_OPTIONS",
    "STATUS",
    "EstimatorResult",
    "Method",
    "Problem",
    "method_options",
    "search_options",
]


class EstimatorResult(OptimiserResult):
    """What every estimator returns: the optimisers' one result type
    (:class:`~spiralid.optim.OptimiserResult`, which behaves like
    ``scipy.optimize.OptimizeResult``) with the ARX theta as ``x``.

    Attributes
    ----------
    x : ndarray, shape (p,)
        The ARX theta ``[a_1..a_na, b_0..b_(nb-1)]``.
    fun : float
        Its cost on the estimation data (eq. (2)-(3), the problem's predictor).
    status : int
        A key of :data:`STATUS` (``1``: stopped at the evaluation cap).
    success : bool
        As the underlying optimiser says (a search that used its budget
        succeeded).
    message : str
        Why it stopped.
    nfev, nit : int
        Cost evaluations and iterations (the kept start's, for ``"oe"``).
    history : ndarray or None
        Best cost after each iteration of a search (index 0: the initial
        population).
    elapsed : float
        Seconds (the search alone, without ``refine``).
    x_search : ndarray, optional
        A search's best point in its searched coordinates.
    bounds : ndarray, optional
        A search's box, in its searched coordinates.
    safe_start : bool, optional
        Whether a search's first population held the safe start.
    optimality, at_bound : float, bool, optional
        A polish's end: the gradient's largest component (first-order
        optimality) and whether the end is on the stable region's edge
        (where the gradient need not vanish); status 1 when the evaluation
        cap, not a tolerance, ended it.
    start : str, optional
        Which start a polish kept (``"ls"``, ``"steiglitz-mcbride"``,
        ``"search"``); ``starts`` gives each start's cost.
    refine : EstimatorResult or None
        The polish of ``refine=True``; ``refine.accepted`` says whether it
        lowered the cost (otherwise ``x`` is the search's).
    cancelled : list of dict, optional
        The near-cancelling pole-zero pairs removed after the estimate
        (:func:`~spiralid.sysid.estimation.cancellation.reduce_order`);
        ``effective_order`` ``(na', nb')`` and ``x_full``, ``fun_full`` (the
        estimate before) with them.
    raw : object
        The underlying optimiser's own result.
    """


@dataclass
class Problem:
    """Everything an estimator needs, checked by :func:`identify`."""

    data: IOData
    arx: ARX
    cost: PaperCost
    predictor: str
    initial: str
    gain: str | float
    penalty: float
    parametrization: Parametrization
    rng: np.random.Generator
    bounds: np.ndarray | None = None
    refine: bool = False
    safe_start: bool = False
    # The stability margin r_max of the polish (and of the parametrisation
    # when the method applies it), None for none; and whether pole-zero
    # pairs are cancelled after the estimate.
    max_radius: float | None = None
    cancel: bool = False

    def restricted(self, data: IOData) -> Problem:
        """The same problem on another record (a part of this one): its cost
        and parametrisation rebuilt on `data`, the margin, box and
        randomness kept."""
        par = self.parametrization
        return replace(
            self,
            data=data,
            cost=PaperCost(
                self.arx,
                data,
                predictor=self.predictor,
                gain=self.gain,
                penalty=self.penalty,
                initial=self.initial,
            ),
            parametrization=make_parametrization(
                par.name, data, self.arx, par.max_radius
            ),
        )

    def simulation_cost(self) -> PaperCost:
        """The simulation cost output error minimises, whatever `predictor`."""
        if self.predictor == "simulation":
            return self.cost
        return PaperCost(
            self.arx,
            self.data,
            gain=self.gain,
            penalty=self.penalty,
            initial=self.initial,
        )


@dataclass(frozen=True)
class Method:
    """One entry of :data:`METHODS`.

    Attributes
    ----------
    estimate : callable
        ``estimate(problem, **options) -> EstimatorResult``.
    search : bool
        A population search over a parametrisation: takes optimiser options,
        ``rng``, ``bounds``, ``refine`` and ``safe_start``.
    options : tuple of str
        The optimiser options it accepts (the keyword-only parameters of
        what runs it, :func:`_keyword_options`); empty for a method that
        does not search.
    safe_start : bool
        Default of ``identify(safe_start=None)`` (see the module docstring).
    parametrization : str
        Default of ``identify(parametrization=None)``.
    narx : callable or None
        The estimator for a NARX structure,
        ``narx(problem: NARXProblem, **options) -> OptimizeResult`` (see
        :mod:`spiralid.sysid.estimation.narx`); None: ARX only.
    minimises : str or None
        The error the estimate minimises, for its covariance
        (:mod:`~spiralid.sysid.estimation.uncertainty`): a predictor name, or
        None for the cost's own predictor.
    margin : bool
        Applies identify's ``max_time_constant`` (by default the record's
        length) to its parametrisation and polish; a search without it
        applies it to ``refine``'s polish only.
    cancel : bool
        Default of ``identify(cancel=None)``: remove near-cancelling
        pole-zero pairs after the estimate; False: the option does not
        apply.
    narx_options : tuple of str
        The options of its NARX estimator (beside ``identify_narx``'s own
        ``holdout`` and ``decay``); empty without one.
    """

    estimate: Callable[..., EstimatorResult]
    search: bool = True
    options: tuple[str, ...] = ()
    safe_start: bool = False
    parametrization: str = DEFAULT_PARAMETRIZATION
    narx: Callable[..., OptimiserResult] | None = None
    minimises: str | None = None
    margin: bool = False
    cancel: bool = False
    narx_options: tuple[str, ...] = ()


def search_options(options: dict) -> dict:
    """The one budget rule: `options` with the iteration cap a budget implies.

    Examples
    --------
    >>> search_options({"n_points": 50, "max_nfev": 20_000})
    {'n_points': 50, 'max_nfev': 20000, 'max_iter': 20000}
    >>> search_options({"max_nfev": 1000, "max_iter": 10})   # both given: kept
    {'max_nfev': 1000, 'max_iter': 10}
    """
    out = dict(options)
    if out.get("max_nfev") is not None and out.get("max_iter") is None:
        # Every iteration costs at least one evaluation: this cap never
        # stops a run before its budget does.
        out["max_iter"] = out["max_nfev"]
    return out


# -- least squares and output error ---------------------------------------------


def _estimate_ls(problem: Problem) -> EstimatorResult:
    t0 = time.perf_counter()
    theta = arx_least_squares(problem.data, problem.arx)
    return EstimatorResult(
        x=theta,
        fun=float(problem.cost(theta)),
        status=0,
        success=True,
        message="Least-squares solution (exact minimiser of the one-step error).",
        nfev=0,
        nit=0,
        n_restarts=0,
        history=None,
        elapsed=time.perf_counter() - t0,
        raw=None,
    )


def _polish(
    problem: Problem,
    starts: dict[str, np.ndarray],
    predictor: str,
    cost: PaperCost,
    max_nfev: int | None = None,
) -> EstimatorResult:
    """Levenberg-Marquardt from every start; keep the lowest `cost` (ties:
    the first start). The simulation error is not convex, so each start may
    stop in a different local minimum; the choice is on the estimation cost,
    never on validation data. `max_nfev` caps each polish (None:
    :func:`~spiralid.sysid.estimation.outputerror.local_polish`'s own)."""
    t0 = time.perf_counter()
    best = None
    costs, thetas = {}, {}
    # Passed only when set, so local_polish's own default stays its own.
    cap = {} if max_nfev is None else {"max_nfev": max_nfev}
    for name, start in starts.items():
        theta, res = local_polish(
            start,
            problem.arx,
            problem.data,
            predictor,
            problem.initial,
            max_radius=problem.max_radius,
            **cap,
        )
        costs[name] = float(cost(theta))
        thetas[name] = theta
        if best is None or costs[name] < best[0]:
            best = (costs[name], name, theta, res)
    _, name, theta, res = best
    res.start = name
    capped = res.capped
    return EstimatorResult(
        x=theta,
        fun=float(problem.cost(theta)),
        status=1 if capped else 0,
        success=bool(res.success),
        message=(
            f"Stopped at the evaluation cap (max_nfev = {res.max_nfev}) before "
            "the tolerances were met."
            if capped
            else res.message
        ),
        nfev=int(res.nfev),
        optimality=float(res.optimality),
        at_bound=bool(res.at_bound),
        nit=int(res.nit),
        n_restarts=0,
        history=None,
        elapsed=time.perf_counter() - t0,
        start=name,
        starts=costs,
        thetas=thetas,
        raw=res,
    )


def _standard_starts(problem: Problem) -> dict[str, np.ndarray]:
    theta_ls = problem.parametrization.theta_ls
    return {
        "ls": theta_ls,
        "steiglitz-mcbride": steiglitz_mcbride(problem.data, problem.arx, theta_ls),
    }


def _estimate_oe(problem: Problem) -> EstimatorResult:
    # With a one-step `predictor` the selection is still on the simulation
    # error OE minimises, not on the reported cost.
    cost = problem.simulation_cost()
    result = _polish(problem, _standard_starts(problem), "simulation", cost)
    if problem.cancel:
        _cancel(problem, result, cost)
    return result


def _cancel(problem: Problem, result: EstimatorResult, cost: PaperCost) -> None:
    """Remove the near-cancelling pole-zero pairs that raise `cost` (the
    error the method minimises) by at most 1 %
    (:func:`~spiralid.sysid.estimation.cancellation.reduce_order`); each
    reduced model is polished by output error, with the same margin, from
    the deflated model (fresh starts at the reduced order would find other
    minima: that is choosing an order, not removing a pair)."""
    from .cancellation import effective, reduce_order

    def polish(start, reduced):
        theta, _ = local_polish(
            start,
            reduced,
            problem.data,
            "simulation",
            problem.initial,
            max_radius=problem.max_radius,
        )
        return theta

    theta, removed = reduce_order(result.x, problem.arx, problem.data.n, cost, polish)
    if not removed:
        return
    result.x_full, result.fun_full = result.x, result.fun
    result.x, result.fun = theta, float(problem.cost(theta))
    result.cancelled = removed
    k = sum(c["order"] for c in removed)
    result.effective_order = (problem.arx.na - k, problem.arx.nb - k)
    _, reduced = effective(theta, problem.arx, result.effective_order)
    result.message = (
        f"{result.message} Then {len(removed)} near-cancelling pole-zero "
        f"pair(s) removed: effective order {reduced}."
    )


# -- population searches -----------------------------------------------------------


def _safe_start_points(problem: Problem, box: np.ndarray) -> np.ndarray:
    """The stabilised least-squares estimate and the zero model, searched
    coordinates, clipped into the box."""
    par = problem.parametrization
    models = (par.theta_ls, np.zeros(problem.arx.n_params))
    points = np.array([par.from_theta(theta) for theta in models])
    return np.clip(points, box[:, 0], box[:, 1])


def _first_population(
    problem: Problem, box: np.ndarray, m: int, x0
) -> np.ndarray | None:
    """The given or drawn initial points, after the safe start's two."""
    seeds = _safe_start_points(problem, box) if problem.safe_start else None
    if x0 is not None:
        x0 = np.atleast_2d(np.asarray(x0, dtype=float))
        return x0 if seeds is None else np.concatenate([seeds, x0])
    n_seeds = 0 if seeds is None else seeds.shape[0]
    drawn = problem.parametrization.initial_points(box, m - n_seeds, problem.rng)
    parts = [p for p in (seeds, drawn) if p is not None]
    return np.concatenate(parts) if parts else None


def _search(
    problem: Problem,
    optimiser: Callable,
    options: dict,
) -> EstimatorResult:
    """A population search over the problem's parametrisation.

    ``optimiser(fun, box, x0=..., **options)`` runs it and returns an
    :class:`~spiralid.optim.OptimiserResult`, whose status is the estimator's.
    """
    t0 = time.perf_counter()
    par = problem.parametrization
    box = par.default_bounds() if problem.bounds is None else problem.bounds
    options = search_options(options)
    m = int(options.get("n_points", 50))
    x0 = _first_population(problem, box, m, options.pop("x0", None))
    raw = optimiser(par.objective(problem.cost), box, x0=x0, **options)
    theta = par.to_theta(raw.x)
    history = getattr(raw, "history", None)
    result = EstimatorResult(
        x=theta,
        fun=float(problem.cost(theta)),
        status=int(raw.status),
        success=bool(raw.success),
        message=str(raw.message),
        nfev=int(raw.nfev),
        nit=int(raw.nit),
        n_restarts=int(raw.n_restarts),
        history=None if history is None else np.asarray(history, dtype=float),
        elapsed=time.perf_counter() - t0,
        x_search=np.asarray(raw.x, dtype=float),
        bounds=box,
        safe_start=problem.safe_start,
        refine=None,
        raw=raw,
    )
    if problem.refine:
        _refine(problem, result)
    return result


def _refine(problem: Problem, result: EstimatorResult) -> None:
    """Polish the search's best locally; keep it only if it lowers the cost."""
    starts = {"search": result.x}
    if problem.safe_start:
        starts.update(_standard_starts(problem))
    polished = _polish(problem, starts, problem.predictor, problem.cost)
    polished.accepted = bool(polished.fun <= result.fun)
    if polished.accepted:
        result.x, result.fun = polished.x, polished.fun
    result.refine = polished


def _estimate_spiral(problem: Problem, *, rule: str, **options) -> EstimatorResult:
    def run(fun, box, **opts):
        opts["options"] = {k: opts.pop(k) for k in MINIMIZE_OPTIONS if k in opts}
        return minimize(fun, box, method=rule, rng=problem.rng, vectorized=True, **opts)

    return _search(problem, run, options)


def _estimate_de(problem: Problem, **options) -> EstimatorResult:
    def run(fun, box, **opts):
        return differential_evolution(fun, box, rng=problem.rng, **opts)

    return _search(problem, run, options)


def _modal_starts(problem: Problem, modes, n_points: int, n_peaks: int, x0):
    """First points of the modal search and the safe denominators.

    With the safe start: the stabilised least-squares, Steiglitz-McBride
    and zero models (modal coordinates, clipped to the box), and the exact
    denominators of the first two for the final check (the modal map can
    only approximate poles it cannot represent). Then `n_peaks` points at
    the frequency response's peaks, then the caller's `x0`.
    """
    from ..models.polynomials import step_up
    from .memetic import frequency_seeds
    from .parametrizations import stabilise

    par, arx = problem.parametrization, problem.arx
    rows, safe = [], None
    if problem.safe_start:
        theta_ls = par.theta_ls
        theta_sm = steiglitz_mcbride(problem.data, arx, theta_ls)
        rows = [par.from_theta(th) for th in (theta_ls, theta_sm, 0 * theta_ls)]
        a_ls = step_up(stabilise(theta_ls, arx)[: arx.na])
        safe = np.array([a_ls, theta_sm[: arx.na]])
        if problem.max_radius is not None:
            # The safe denominators obey the margin as the search does.
            from .margin import project_denominator
            from .parametrizations import KMAX

            safe = np.array(
                [project_denominator(a, problem.max_radius, KMAX) for a in safe]
            )
    if n_peaks:
        rows += list(frequency_seeds(problem.data, modes, int(n_peaks), problem.rng))
    if x0 is not None:
        rows += list(np.atleast_2d(np.asarray(x0, dtype=float)))
    if not rows:
        return None, safe
    box = modes.bounds
    return np.clip(np.array(rows[:n_points]), box[:, 0], box[:, 1]), safe


# The spiral method's restarts: a fresh population of the same size after
# 20 iterations without progress, not minimize's Restarts() (doubling
# population, max(30, 4 n) stalled iterations). The memetic polish keeps
# improving a stalled population by ever smaller steps, so it is cut off
# sooner, and the budget is one of evaluations, which a growing population
# would spend on fewer iterations; chosen with benchmarks/identification.py
# (docs/design-notes.md, "method='spiral'").
SPIRAL_RESTARTS = Restarts(growth=1.0, stall=20)

# The spiral method's stops (`stop`): the first is the default.
SPIRAL_STOPS = ("converged", "budget")


def _estimate_recommended(
    problem: Problem,
    *,
    rule: str = "ebsda",
    n_points: int = 50,
    max_nfev: int | None = None,
    polish_every: int | None = 5,
    polish_nfev: int = 10,
    restarts: bool | Restarts = SPIRAL_RESTARTS,
    frequency_seeds: int = 0,
    holdback: float | None = HOLDBACK,
    stop: str = "converged",
    x0=None,
    max_iter: int | None = None,
    callback=None,
) -> EstimatorResult:
    """``"spiral"``: the recommended spiral identification.

    A spiral search (`rule`, default Eb-SDA) over the modal coordinates of
    the denominator with the numerator projected out
    (:class:`~spiralid.sysid.estimation.parametrizations.Modal`), its centre polished
    every `polish_every` iterations by `polish_nfev` evaluations of
    Levenberg-Marquardt on the projected problem, a fresh population after
    ``restarts.stall`` iterations without progress (`restarts`, as
    :func:`~spiralid.optim.minimize` takes it: a
    :class:`~spiralid.optim.Restarts`, True for ``Restarts()`` or False;
    the default is :data:`SPIRAL_RESTARTS`;
    :func:`~spiralid.sysid.estimation.memetic.projected_spiral`), `frequency_seeds`
    initial points at the frequency response's peaks, and with the safe
    start the stabilised least-squares, Steiglitz-McBride and zero models in
    the first population. With the safe start (the default) the search's
    best is then polished by Levenberg-Marquardt beside output error from
    the stabilised least-squares and Steiglitz-McBride starts (as
    ``refine=True``): the result is never above output error's cost (unless
    ``polish_every=None``, which asks for no gradient step at all), unless
    the held-back choice below says otherwise.

    With `holdback` ``h`` (default 0.2) each distinct minimum of the whole
    estimation record (the polished search best, output error from least
    squares and from Steiglitz-McBride) is refitted locally on its first
    ``1 - h`` and scored by that refit's simulation error on the held-back
    end, and the lowest whole-record cost is kept unless another minimum
    validates clearly better on the held-back end
    (:mod:`~spiralid.sysid.estimation.heldback`; ``result.selection`` and
    the message say which and why). ``holdback=None`` (or 0) chooses by the
    whole-record cost alone. The pole-zero cancellation (``cancel``) may
    then trade at most 1 % of the cost for a lower order (``fun_full`` is
    the cost before). The search, its polish and output error keep the
    stability margin (``max_time_constant``). Default budget ``max_nfev =
    10_000`` evaluations of the search, its polish steps included
    (``benchmarks/identification.py`` measures what each ingredient does).

    `stop` says when the search ends: ``"converged"`` (the default) as soon
    as a fresh population (a restart) stalls without lowering the best cost
    by more than 1e-6 of it, i.e. it fell back into a basin already found
    or a worse one, or at the budget if that comes first
    (:class:`~spiralid.sysid.estimation.memetic.PatientRestarts` with
    ``patience=1``; ``result.raw.converged`` says which); ``"budget"``
    spends the whole budget, as before (restarts drawn uniformly in the
    box rarely beat the first population, which holds the safe starts:
    ``benchmarks/identification.py --scaling`` measures both).
    An FIR structure (``na = 0``) has no modes: its cost is quadratic in the
    numerator and the exact minimiser is returned without a search.
    """
    from spiralid.optim.spiral import _parse_method

    try:
        _parse_method(rule)
    except ValueError:
        # Named as this method's option, not as minimize's `method`.
        raise ValueError(
            f"`rule` of method 'spiral' must be one of {', '.join(RULES)}, a "
            f"SpiralRule or a StepRateRule instance; got {rule!r}"
        ) from None
    from .parametrizations import Modal

    if problem.arx.na == 0:
        return _estimate_fir(problem)
    if not isinstance(problem.parametrization, Modal):
        raise ValueError(
            "`parametrization` must be 'modal' for method 'spiral' (it searches "
            "the modes with the numerator projected out); got "
            f"{problem.parametrization.name!r}"
        )
    holdback = _holdback_share(holdback)
    restarts = _spiral_restarts(restarts)
    if stop not in SPIRAL_STOPS:
        raise ValueError(
            f"`stop` of method 'spiral' must be one of {', '.join(SPIRAL_STOPS)};"
            f" got {stop!r}"
        )
    if frequency_seeds:
        frequency_seeds = integer(frequency_seeds, "frequency_seeds", 0)
    settings = dict(
        rule=rule,
        n_points=n_points,
        max_nfev=10_000 if max_nfev is None else max_nfev,
        polish_every=polish_every,
        polish_nfev=polish_nfev,
        restarts=_patient(restarts) if stop == "converged" else restarts,
        frequency_seeds=frequency_seeds,
        x0=x0,
        max_iter=max_iter,
        callback=callback,
    )
    start = None
    if holdback and problem.safe_start and polish_every is not None:
        # Enough samples before the held-back end for the structure to be
        # estimated at all (its lags plus two samples a parameter).
        least = problem.arx.max_lag + 2 * problem.arx.n_params
        start = heldback.split(problem.data, holdback, least)
    if start is None:
        result = _spiral_search(problem, **settings)
        if holdback and problem.safe_start and polish_every is not None:
            result.message = (
                f"{result.message} The record is too short to hold back "
                f"{holdback:g} of it for {problem.arx}: chosen by the cost alone."
            )
    else:
        result = _choose_held_back(problem, start, holdback, settings)
    if problem.cancel:
        _cancel(problem, result, problem.cost)
    return result


def _spiral_restarts(restarts) -> Restarts | None:
    """`restarts` of method 'spiral' checked: a Restarts (True: the
    default ``Restarts()``) or None for False; a collapse radius other than
    the default is refused, as the memetic search restarts on stalls only."""
    from spiralid.optim.restarts import parse_restarts

    parsed = parse_restarts(restarts)
    if parsed is not None and parsed.tol_radius != Restarts.tol_radius:
        raise ValueError(
            "`restarts.tol_radius` does not apply to method 'spiral' (it "
            "restarts after `stall` iterations without progress, with `growth`);"
            f" got {parsed.tol_radius!r}"
        )
    return parsed


def _patient(restarts: Restarts | None):
    """`restarts` that also stop the search once a population finds no
    lower basin (``stop="converged"``); without restarts there is no second
    population to judge by, and the budget stays the only stop."""
    from .memetic import PatientRestarts

    if restarts is None:
        return None
    return PatientRestarts(
        growth=restarts.growth, tol_radius=restarts.tol_radius, stall=restarts.stall
    )


def _holdback_share(holdback) -> float:
    """`holdback` checked: a share in [0, 0.5), None being 0."""
    if holdback is None:
        return 0.0
    bad = isinstance(holdback, bool | np.bool_ | str)
    try:
        share = float(holdback)
    except (TypeError, ValueError):
        bad = True
    if bad or not 0.0 <= share < 0.5:
        raise ValueError(
            "`holdback` of method 'spiral' must be a share in [0, 0.5) of the "
            f"estimation record, or None; got {holdback!r}"
        )
    return share


def _choose_held_back(
    problem: Problem, start: int, holdback: float, settings: dict
) -> EstimatorResult:
    """The search and its polish on the whole record, each distinct minimum
    refitted locally on ``data[:start]`` and scored on ``data[start:]``,
    then the held-back choice (:mod:`~spiralid.sysid.estimation.heldback`)."""
    result = _spiral_search(problem, **settings)
    t0 = time.perf_counter()
    minima = dict(result.refine.thetas)
    costs = dict(result.refine.starts)
    if not result.refine.accepted:
        # The search's own best undercut its polish: that is the minimum.
        minima["search"], costs["search"] = result.x, result.fun
    # The distinct minima first: starts that ended in one minimum need one
    # refit, and a single minimum leaves nothing to choose (no refit).
    found = [
        heldback.Candidate(name, theta, None, theta, costs[name])
        for name, theta in minima.items()
    ]
    candidates = heldback.distinct(found, problem.cost)
    if len(candidates) > 1:
        part = problem.restricted(problem.data[:start])
        nfev = heldback.refit_nfev(problem.arx.n_params)
        for c in candidates:
            # A local refit without the held-back end stays in the minimum's
            # basin: the held-back error then judges the basin, not the data
            # it was fitted to.
            refit = _polish(part, {c.name: c.theta}, part.predictor, part.cost, nfev)
            c.theta_part = refit.x
            c.held_rms = heldback.held_back_rms(refit.x, problem.cost, start)
    chosen, lowest = heldback.select(candidates)
    selection = heldback.Selection(
        holdback, problem.data.n - start, candidates, chosen, lowest
    )
    winner = next(c for c in candidates if c.name == chosen)
    result.x, result.fun, result.start = winner.theta, winner.cost, chosen
    result.selection = selection
    result.message = f"{result.message} Then {selection.sentence()}."
    result.elapsed += time.perf_counter() - t0
    return result


def _spiral_search(
    problem: Problem,
    *,
    rule,
    n_points,
    max_nfev,
    polish_every,
    polish_nfev,
    restarts,
    frequency_seeds,
    x0,
    max_iter,
    callback,
) -> EstimatorResult:
    """The search with its safe starts and the final polish beside output
    error (:func:`_estimate_recommended`), on `problem`'s record."""
    from .memetic import projected_spiral

    t0 = time.perf_counter()
    par = problem.parametrization
    cost = par.projected(problem.cost)
    box = par.default_bounds() if problem.bounds is None else problem.bounds
    modes = copy.copy(par.modes)
    modes.bounds = box
    start, safe = _modal_starts(problem, modes, n_points, frequency_seeds, x0)
    raw = projected_spiral(
        cost,
        modes,
        rule,
        n_points=n_points,
        max_nfev=max_nfev,
        polish_every=polish_every,
        polish_nfev=polish_nfev,
        restarts=restarts,
        x0=start,
        max_iter=max_iter,
        callback=callback,
        rng=problem.rng,
    )
    theta, kept = raw.x, "search"
    if safe is not None:
        f_safe, b_safe = cost.evaluate(safe)
        i = int(np.argmin(f_safe))
        if f_safe[i] < raw.fun:
            theta = np.r_[safe[i], b_safe[i]]
            kept = ("ls", "steiglitz-mcbride")[i]
    result = EstimatorResult(
        x=theta,
        fun=float(problem.cost(theta)),
        status=int(raw.status),
        success=True,
        message=str(raw.message),
        nfev=int(raw.nfev),
        nit=int(raw.nit),
        history=raw.history,
        elapsed=time.perf_counter() - t0,
        x_search=raw.z,
        bounds=box,
        safe_start=problem.safe_start,
        start=kept,
        n_polish=raw.n_polish,
        n_restarts=raw.n_restarts,
        refine=None,
        raw=raw,
    )
    if problem.refine or (problem.safe_start and polish_every is not None):
        # The safe start's promise, kept to the end: the result is never
        # above output error from the same stabilised least-squares and
        # Steiglitz-McBride starts, nor above a local polish of the search's
        # own best (the search's LM steps are capped, OE's run to its
        # tolerances). `polish_every=None` asks for no gradient step at all.
        _refine(problem, result)
    return result


def _estimate_fir(problem: Problem) -> EstimatorResult:
    """An FIR model (``na = 0``): the simulation error is linear in the
    numerator, so its exact minimiser is one least-squares solve (a
    Levenberg-Marquardt step from least squares); no search can do better."""
    result = _polish(
        problem,
        {"ls": problem.parametrization.theta_ls},
        problem.predictor,
        problem.cost,
    )
    result.message = (
        "FIR model (na = 0): the cost is quadratic in the numerator; its exact "
        "minimiser, no search needed."
    )
    return result


def _keyword_options(function: Callable, own: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The keyword-only parameters of `function`, less those in `own` (what
    the estimator sets itself): a method's options come from the signature
    of what runs it, so the list cannot drift from the code."""
    import inspect

    return tuple(
        name
        for name, par in inspect.signature(function).parameters.items()
        if par.kind is inspect.Parameter.KEYWORD_ONLY and name not in own
    )


# minimize's keywords and the keys of its `options`, all passed flat here.
_MINIMIZE_OPTIONS = _keyword_options(
    minimize, own=("method", "rng", "vectorized", "options")
) + tuple(MINIMIZE_OPTIONS)

# One entry per method; its key is the name users pass.
METHODS: dict[str, Method] = {
    **{
        name: Method(
            partial(_estimate_spiral, rule=name),
            # The rule is the method's own, so a method bound to one rule
            # cannot be re-ruled.
            options=_MINIMIZE_OPTIONS,
            narx=partial(_narx.estimate_search, rule=name),
            narx_options=_MINIMIZE_OPTIONS,
        )
        for name in RULES
    },
    "de": Method(
        _estimate_de,
        options=_keyword_options(differential_evolution, own=("rng",)),
    ),
    "spiral": Method(
        _estimate_recommended,
        options=_keyword_options(_estimate_recommended),
        safe_start=True,
        parametrization="modal",
        narx=_narx.estimate_spiral,
        margin=True,
        cancel=True,
        narx_options=_keyword_options(_narx.estimate_spiral),
    ),
    "ls": Method(
        _estimate_ls,
        search=False,
        options=(),
        narx=_narx.estimate_ls,
        minimises="one-step",
        narx_options=_keyword_options(_narx.estimate_ls),
    ),
    "oe": Method(
        _estimate_oe,
        search=False,
        options=(),
        narx=_narx.estimate_oe,
        margin=True,
        cancel=True,
        narx_options=_keyword_options(_narx.estimate_oe),
    ),
}

# What identify() takes beside a search's optimiser options: what the
# search moves, its box, the polish after it and the safe start. Methods
# that do not search (ls, oe) take none of them.
SEARCH_PROBLEM_OPTIONS = ("parametrization", "bounds", "refine", "safe_start")


def method_options(method: str, narx: bool = False) -> tuple[str, ...]:
    """The options `method` takes through ``identify(**options)``: for an
    ARX structure a search's :data:`SEARCH_PROBLEM_OPTIONS` and its
    optimiser's, for a NARX structure its NARX estimator's (beside
    ``holdout`` and ``decay``). The one table the entry points, the command
    line and the tests read.

    Examples
    --------
    >>> method_options("ls")
    ()
    >>> method_options("ls", narx=True)
    ('max_rounds', 'patience')
    """
    spec = METHODS[method]
    if narx:
        return spec.narx_options
    return (*SEARCH_PROBLEM_OPTIONS, *spec.options) if spec.search else ()


require_names(METHODS, METHOD_NAMES, "spiralid.sysid.METHODS")
