"""The estimators that do not search, and the local polish the searches end
with: least squares (``"ls"``), output error (``"oe"``: Levenberg-Marquardt
from the least-squares and Steiglitz-McBride starts), the exact fit of an
FIR structure, ``refine``'s polish of a search's best and the removal of
near-cancelling pole-zero pairs."""

from __future__ import annotations

import time

import numpy as np

from ...models.arx import arx_least_squares
from ..core.cost import PaperCost
from ..core.problem import EstimatorResult, Problem
from .outputerror import local_polish, steiglitz_mcbride


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
    starts: dict[str, np.ndarray | tuple],
    predictor: str,
    cost: PaperCost,
    max_nfev: int | None = None,
) -> EstimatorResult:
    """Levenberg-Marquardt from every start; keep the lowest `cost` (ties:
    the first start). The simulation error is not convex, so each start may
    stop in a different local minimum; the choice is on the estimation cost,
    never on validation data. `max_nfev` caps each polish (None:
    :func:`~spiralid.sysid.estimation.linear.outputerror.local_polish`'s own).

    A start given as ``(theta, res)`` was polished already (an earlier
    result's ``runs``): it takes part in the choice without a second run.
    The result's ``runs`` holds every start's ``(theta, res)`` and ``work``
    their residual evaluations together (what the polishes cost, in the
    unit their caps are set in).

    Each polish after the first races the lowest squared error reached so
    far (``rival`` of
    :func:`~spiralid.sysid.estimation.linear.levenberg.levenberg_marquardt`): one
    that cannot reach it at its own pace is given up, since only the lowest
    is kept."""
    t0 = time.perf_counter()
    best = None
    costs, thetas, runs = {}, {}, {}
    # Passed only when set, so local_polish's own default stays its own.
    cap = {} if max_nfev is None else {"max_nfev": max_nfev}
    rival = None
    for name, start in starts.items():
        if isinstance(start, tuple):
            theta, res = start
        else:
            theta, res = local_polish(
                start,
                problem.arx,
                problem.data,
                predictor,
                problem.initial,
                max_radius=problem.max_radius,
                rival=rival,
                **cap,
            )
        squared = float(res.fun @ res.fun)
        rival = squared if rival is None else min(rival, squared)
        costs[name] = float(cost(theta))
        thetas[name] = theta
        runs[name] = (theta, res)
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
        runs=runs,
        work=sum(int(r.nfev) for _, r in runs.values()),
        raw=res,
    )


def _standard_starts(problem: Problem) -> dict[str, np.ndarray]:
    """Output error's starts: least squares and Steiglitz-McBride from it."""
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


def _cancel(
    problem: Problem,
    result: EstimatorResult,
    cost: PaperCost,
    max_nfev: int | None = None,
) -> None:
    """Remove the near-cancelling pole-zero pairs that raise `cost` (the
    error the method minimises) by at most 1 %
    (:func:`~spiralid.sysid.estimation.spiral.cancellation.reduce_order`); each
    reduced model is polished by output error, with the same margin, from
    the deflated model (fresh starts at the reduced order would find other
    minima: that is choosing an order, not removing a pair). `max_nfev`
    caps each of those polishes (None: the polish's own default)."""
    from ..spiral.cancellation import effective, reduce_order

    cap = {} if max_nfev is None else {"max_nfev": max_nfev}

    def polish(start, reduced):
        return _polish_reduced(problem, start, reduced, **cap)[0]

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


def _polish_reduced(problem: Problem, start, reduced, **cap):
    """Output error's polish of a reduced model from `start`, on the
    problem's record and initial condition, under its margin: what both the
    cancellation and the modes table's removals refit with."""
    return local_polish(
        start,
        reduced,
        problem.data,
        "simulation",
        problem.initial,
        max_radius=problem.max_radius,
        **cap,
    )


def _act_on_modes(
    problem: Problem,
    result: EstimatorResult,
    max_nfev: int | None = None,
) -> None:
    """Remove the poles the modes table flags (an interval that reaches
    ``|z| = 1``, a cancelling zero) where the likelihood-ratio test allows
    (:func:`~spiralid.sysid.estimation.spiral.spurious.remove_flagged`), after the
    cancellation: each reduced model is polished by output error from the
    deflated one, with the same margin; `max_nfev` caps each polish.
    ``result.diagnosis`` says what was removed and what was kept."""
    from ..spiral.cancellation import effective, pad
    from ..spiral.spurious import remove_flagged

    arx = problem.arx
    order = result.get("effective_order") or (arx.na, arx.nb)
    theta_r, arx_r = effective(result.x, arx, order)
    # With `max_nfev` (output error's pace: one cancellation polish's cap)
    # the polishes share that cap, so that a model with many flagged poles
    # adds a bounded share of output error's time (twice the cap took the
    # rig's ARX(16, 16, 0) to 2x output error's processor time); the poles
    # left untried when it is spent stay flagged, and the diagnosis says so.
    budget = [None if max_nfev is None else int(max_nfev)]

    def polish(start, reduced):
        left = budget[0]
        if left is not None and left < 5:
            return None
        cap = {} if left is None else {"max_nfev": min(int(max_nfev), left)}
        theta, res = _polish_reduced(problem, start, reduced, **cap)
        if left is not None:
            budget[0] = left - int(res.nfev)
        return theta

    def cost(theta):
        # Padded to the estimated structure: the paper's cost of the model.
        return float(problem.cost(pad(theta, arx_r, arx)))

    def error(theta):
        return problem.data.y - arx_r.simulate(theta, problem.data.u)

    theta, reduced, diagnosis = remove_flagged(
        theta_r, arx_r, problem.data, problem.initial, cost, polish, error
    )
    result.diagnosis = diagnosis
    if not diagnosis.removed:
        return
    if result.get("x_full") is None:
        result.x_full, result.fun_full = result.x, result.fun
    # `theta` is padded to the effective structure it started from; the
    # model's layout is the structure asked for.
    theta_red, _ = effective(theta, arx_r, (reduced.na, reduced.nb))
    result.x = pad(theta_red, reduced, arx)
    result.fun = float(problem.cost(result.x))
    removed = [
        {k: v for k, v in r.items() if k != "reasons"}
        | {"reason": "; ".join(r["reasons"])}
        for r in diagnosis.removed
    ]
    result.cancelled = [*(result.get("cancelled") or []), *removed]
    k = sum(c["order"] for c in result.cancelled)
    result.effective_order = (arx.na - k, arx.nb - k)
    result.message = (
        f"{result.message} Then {len(removed)} pole(s) the modes table flags "
        f"removed: effective order {reduced}."
    )


def _refine(
    problem: Problem,
    result: EstimatorResult,
    standard: EstimatorResult | None = None,
    max_nfev: int | None = None,
) -> None:
    """Polish the search's best locally; keep it only if it lowers the cost.

    With the safe start the polish also runs from the least-squares and
    Steiglitz-McBride starts, or takes `standard`, their polish made
    already (:func:`_polish`'s result), without running it again.
    `max_nfev` caps the polish from the search's best (None: the
    polish's own default)."""
    polished = _polish(
        problem, {"search": result.x}, problem.predictor, problem.cost, max_nfev
    )
    if problem.safe_start:
        if standard is None:
            standard = _polish(
                problem, _standard_starts(problem), problem.predictor, problem.cost
            )
        # One choice over all three, the search's first (it wins ties), as
        # one polish of the three starts makes it.
        elapsed = polished.elapsed + standard.elapsed
        polished = _polish(
            problem,
            {"search": polished.runs["search"], **standard.runs},
            problem.predictor,
            problem.cost,
        )
        polished.elapsed = elapsed
    polished.accepted = bool(polished.fun <= result.fun)
    if polished.accepted:
        result.x, result.fun = polished.x, polished.fun
    result.refine = polished


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
