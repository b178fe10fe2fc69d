"""``method="spiral"``, the recommended spiral identification: a spiral
search over the modal coordinates with the numerator projected out, its
safe and frequency starts, its restarts and stop, the polish beside output
error, and the choice among minima on a held-back end of the record."""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass

import numpy as np

from spiralid._checks import integer
from spiralid.optim import RULES, Restarts

from ..core.problem import EstimatorResult, Problem
from ..linear.local_estimators import (
    _cancel,
    _estimate_fir,
    _polish,
    _refine,
    _standard_starts,
)
from . import folds as fold_choice
from . import heldback
from .heldback import HOLDBACK

__all__ = ["SPIRAL_RESTARTS", "SPIRAL_STOPS", "WORK", "WorkShares"]


def _modal_starts(
    problem: Problem, modes, n_points: int, n_peaks: int, x0, standard: dict | None
):
    """First points of the modal search and the safe denominators.

    With the safe start (`standard`: output error's least-squares and
    Steiglitz-McBride starts): the stabilised least-squares,
    Steiglitz-McBride and zero models (modal coordinates, clipped to the
    box), and the exact denominators of the first two for the final check
    (the modal map can only approximate poles it cannot represent). Then
    `n_peaks` points at the frequency response's peaks, then the caller's
    `x0`.
    """
    from ...models.polynomials import step_up
    from ..linear.parametrizations import stabilise
    from .projected import frequency_seeds

    par, arx = problem.parametrization, problem.arx
    rows, safe = [], None
    if standard is not None:
        theta_ls, theta_sm = standard["ls"], standard["steiglitz-mcbride"]
        rows = [par.from_theta(th) for th in (theta_ls, theta_sm, 0 * theta_ls)]
        a_ls = step_up(stabilise(theta_ls, arx)[: arx.na])
        safe = np.array([a_ls, theta_sm[: arx.na]])
        if problem.max_radius is not None:
            # The safe denominators obey the margin as the search does.
            from ..linear.margin import project_denominator
            from ..linear.parametrizations import KMAX

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
SPIRAL_STOPS = ("work", "converged", "budget")


@dataclass(frozen=True)
class WorkShares:
    """What ``stop="work"`` lets the steps after output error spend, each a
    multiple of output error's own work ``W``: the residual evaluations of
    its two Levenberg-Marquardt polishes (from least squares and
    Steiglitz-McBride), which the method runs first.

    Output error's minimum is always among the minima the method keeps the
    lowest of, so its cost stays at or below output error's whatever these
    caps cut; they bound the time the rest adds to output error's.

    Parameters
    ----------
    search : float
        The search's evaluations (population and polish steps) per unit of
        ``W``. One evaluation of output error (with its share of the
        Jacobians) took the processor time of 10-35 projected-cost
        evaluations of one candidate at orders 2-32 on 2,000 and 8,000
        samples, so 2.5 is a sixth of output error's time or less.
    polish : float
        The cap of the polish from the search's best, in
        Levenberg-Marquardt evaluations per unit of ``W``.
    refit : float
        The held-back refits' evaluations together, per unit of ``W``
        (shared among the distinct minima, each still at most
        :data:`~spiralid.sysid.estimation.spiral.heldback.REFIT_NFEV` per
        parameter and one).
    cancel : float
        The cap of each polish of a reduced model in the pole-zero
        cancellation (``cancel``), per unit of ``W``: from the deflated
        model it can crawl for longer than output error took (1,390
        evaluations at ARX(24, 24, 0) on the rig, against 1,595 for output
        error's two polishes), and capped at 100 it removed the same two
        pairs, the cost 3e-4 higher.
    least : int
        The fewest evaluations any of these caps leaves: a few
        Levenberg-Marquardt steps (a search has at least two populations'
        worth).
    """

    search: float = 2.5
    polish: float = 0.1
    refit: float = 0.1
    cancel: float = 0.15
    least: int = 5

    def cap(self, share: float, work: int, least: int | None = None) -> int:
        """A cap of evaluations tied to output error's work.

        Parameters
        ----------
        share : float
            One of the shares above.
        work : int
            Output error's work ``W`` (residual evaluations).
        least : int, optional
            The floor; default :attr:`least`.

        Returns
        -------
        int
            ``round(share * work)``, at least `least`.
        """
        floor = self.least if least is None else least
        return max(int(floor), round(share * work))


#: The shares of ``stop="work"``, the default (:class:`WorkShares`).
WORK = WorkShares()


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
    folds: bool | str = fold_choice.DEFAULT,
    stop: str = "work",
    x0=None,
    max_iter: int | None = None,
    callback=None,
) -> EstimatorResult:
    """``"spiral"``: the recommended spiral identification.

    A spiral search (`rule`, default Eb-SDA) over the modal coordinates of
    the denominator with the numerator projected out
    (:class:`~spiralid.sysid.estimation.linear.parametrizations.Modal`), its centre
    polished
    every `polish_every` iterations by `polish_nfev` evaluations of
    Levenberg-Marquardt on the projected problem, a fresh population after
    ``restarts.stall`` iterations without progress (`restarts`, as
    :func:`~spiralid.optim.minimize` takes it: a
    :class:`~spiralid.optim.Restarts`, True for ``Restarts()`` or False;
    the default is :data:`SPIRAL_RESTARTS`;
    :func:`~spiralid.sysid.estimation.spiral.projected.projected_spiral`),
    `frequency_seeds`
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
    (:mod:`~spiralid.sysid.estimation.spiral.heldback`; ``result.selection`` and
    the message say which and why). ``holdback=None`` (or 0) chooses by the
    whole-record cost alone. The pole-zero cancellation (``cancel``) may
    then trade at most 1 % of the cost for a lower order (``fun_full`` is
    the cost before). The search, its polish and output error keep the
    stability margin (``max_time_constant``). Default budget ``max_nfev =
    10_000`` evaluations of the search, its polish steps included
    (``benchmarks/identification.py`` measures what each ingredient does).

    With ``folds=True`` the model is then chosen among the method's own,
    output error's model and output error with integrated noise by
    forward-chaining folds across the record
    (:mod:`~spiralid.sysid.estimation.spiral.folds`; applied after the
    modes-table step, by the ARX fit, ``model.selection`` says which and
    why), a choice a continuing drift cannot win as it wins the held-back
    end. ``folds="auto"`` runs them only where the modes table flagged a
    pole of the method's model before the flagged-pole removal; elsewhere
    the model and its cost are the method's own. Default False.

    `stop` says when the search ends: ``"converged"`` as soon as a fresh
    population (a restart) stalls without lowering the best cost by more
    than 1e-6 of it, i.e. it fell back into a basin already found or a
    worse one, or at the budget if that comes first
    (:class:`~spiralid.sysid.estimation.spiral.projected.PatientRestarts` with
    ``patience=1``; ``result.raw.converged`` says which); ``"work"`` (the
    default) as ``"converged"``, with output error's two polishes run
    first and the search's budget, the cap of the polish from its best and
    the held-back refits' evaluations each tied to their work
    (:class:`WorkShares`, :data:`WORK`; ``result.oe_work`` is that work and
    ``result.caps`` the caps), so the method adds a bounded share of output
    error's time to it; without the safe start or with
    ``polish_every=None`` there is no output error to measure and it is
    ``"converged"``. ``"budget"`` spends the whole budget
    (restarts drawn uniformly in the box rarely beat the first population,
    which holds the safe starts: ``benchmarks/identification.py
    --scaling`` measures all three). Every stop is deterministic: the same
    `rng` gives the same result.
    An FIR structure (``na = 0``) has no modes: its cost is quadratic in the
    numerator and the exact minimiser is returned without a search.
    """
    from spiralid.optim.spiral import _parse_method

    try:
        _parse_method(rule)
    except (TypeError, ValueError) as err:
        # Named as this method's option, not as minimize's `method`.
        raise type(err)(
            f"`rule` of method 'spiral' must be one of {', '.join(RULES)}, a "
            f"SpiralRule or a StepRateRule instance; got {rule!r}"
        ) from None
    from ..linear.parametrizations import Modal

    if problem.arx.na == 0:
        return _estimate_fir(problem)
    if not isinstance(problem.parametrization, Modal):
        raise ValueError(
            "`parametrization` must be 'modal' for method 'spiral' (it searches "
            "the modes with the numerator projected out); got "
            f"{problem.parametrization.name!r}"
        )
    holdback = _holdback_share(holdback)
    fold_choice.check(folds)
    restarts = _spiral_restarts(restarts)
    if stop not in SPIRAL_STOPS:
        raise ValueError(
            f"`stop` of method 'spiral' must be one of {', '.join(SPIRAL_STOPS)};"
            f" got {stop!r}"
        )
    if frequency_seeds:
        frequency_seeds = integer(frequency_seeds, "frequency_seeds", 0)
    # Checked before the work shares compute with them, so that a bad size
    # or budget is named rather than failing in arithmetic; the search
    # checks them again against each other.
    integer(n_points, "n_points", 2)
    if max_nfev is not None:
        integer(max_nfev, "max_nfev", n_points)
    settings = dict(
        rule=rule,
        n_points=n_points,
        max_nfev=10_000 if max_nfev is None else max_nfev,
        polish_every=polish_every,
        polish_nfev=polish_nfev,
        restarts=restarts if stop == "budget" else _patient(restarts),
        frequency_seeds=frequency_seeds,
        work=WORK if stop == "work" else None,
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
        _cancel(problem, result, problem.cost, result.caps.get("cancel"))
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
    from .projected import PatientRestarts

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
    then the held-back choice (:mod:`~spiralid.sysid.estimation.spiral.heldback`)."""
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
    paced = False
    if len(candidates) > 1:
        part = problem.restricted(problem.data[:start])
        nfev = heldback.refit_nfev(problem.arx.n_params)
        work = settings["work"]
        paced = work is not None and result.get("oe_work") is not None
        if paced:
            # The refits share a budget tied to output error's work.
            share = work.cap(work.refit, result.oe_work) // len(candidates)
            nfev = min(nfev, max(share, work.least))
            result.caps["refit"] = nfev
        for c in candidates:
            # A local refit without the held-back end stays in the minimum's
            # basin: the held-back error then judges the basin, not the data
            # it was fitted to.
            refit = _polish(part, {c.name: c.theta}, part.predictor, part.cost, nfev)
            c.theta_part = refit.x
            c.held_rms = heldback.held_back_rms(refit.x, problem.cost, start)
            c.capped = refit.status == 1
    # A refit cut short by output error's pace stays near the whole-record
    # fit, which saw the held-back end: its score is too kind to decide.
    chosen, lowest = heldback.select(candidates, trust_capped=not paced)
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
    work: WorkShares | None = None,
) -> EstimatorResult:
    """The search with its safe starts and the final polish beside output
    error (:func:`_estimate_recommended`), on `problem`'s record; with
    `work` output error's polish first and the search's budget and the
    polish from its best tied to its work (``stop="work"``)."""
    from .projected import projected_spiral

    t0 = time.perf_counter()
    par = problem.parametrization
    cost = par.projected(problem.cost)
    box = par.default_bounds() if problem.bounds is None else problem.bounds
    modes = copy.copy(par.modes)
    modes.bounds = box
    polishes = problem.refine or (problem.safe_start and polish_every is not None)
    # Output error's starts once: the search's first population and the
    # final polish share them.
    standard = _standard_starts(problem) if problem.safe_start else None
    oe, caps = None, {}
    if work is not None and polishes and standard is not None:
        # Output error first: its work sets what the rest may spend.
        oe = _polish(problem, standard, problem.predictor, problem.cost)
        max_nfev = min(max_nfev, work.cap(work.search, oe.work, 2 * n_points))
        # The polish's own default cap, which the shares never exceed.
        largest = 100 * (problem.arx.n_params + 1)
        caps = {
            "search": max_nfev,
            "polish": min(work.cap(work.polish, oe.work), largest),
            "cancel": min(work.cap(work.cancel, oe.work), largest),
        }
    start, safe = _modal_starts(problem, modes, n_points, frequency_seeds, x0, standard)
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
        # The search's own time; output error's polish is the refine's.
        elapsed=time.perf_counter() - t0 - (0.0 if oe is None else oe.elapsed),
        x_search=raw.z,
        bounds=box,
        safe_start=problem.safe_start,
        start=kept,
        n_polish=raw.n_polish,
        n_restarts=raw.n_restarts,
        refine=None,
        raw=raw,
        oe_work=None if oe is None else oe.work,
        caps=caps,
    )
    if polishes:
        # The safe start's promise, kept to the end: the result is never
        # above output error from the same stabilised least-squares and
        # Steiglitz-McBride starts, nor above a local polish of the search's
        # own best (the search's LM steps are capped, OE's run to its
        # tolerances). `polish_every=None` asks for no gradient step at all.
        if oe is None and standard is not None:
            oe = _polish(problem, standard, problem.predictor, problem.cost)
        _refine(problem, result, oe, caps.get("polish"))
        if oe is not None and problem.predictor == "simulation":
            # Output error's own polish of its own starts, uncapped: the
            # folds' "oe" candidate before its cancellation (popped by the
            # ARX fit, with the problem it is of).
            result.oe_fit = (problem, oe)
    return result
