"""One structure's search for :func:`~spiralid.sysid.identify_pareto`: its
objectives on a population of searched points, its seeds (the
single-objective estimates), the archive of its incumbents, the polish of
each objective's extreme, and the candidate models they give."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from spiralid.optim._decomposition import Archive
from spiralid.optim.pareto import PARETO_OPTIONS, minimize_pareto

from ...data import IOData
from ...models.arx import ARX
from ..core.cost import PaperCost
from ..linear.frequency import FrequencyError
from ..linear.outputerror import steiglitz_mcbride
from ..linear.parametrizations import Modal, make_parametrization

_SEEDS = ("ls", "steiglitz-mcbride", "oe")


def _seed_thetas(data: IOData, arx: ARX, par, initial: str) -> dict[str, np.ndarray]:
    """The single-objective estimates that seed a search."""
    from ..core.identify import identify

    theta_ls = par.theta_ls
    return {
        "ls": theta_ls,
        "steiglitz-mcbride": steiglitz_mcbride(data, arx, theta_ls),
        "oe": identify(data, arx, method="oe", initial=initial).theta,
    }


def _candidates(par, cost: PaperCost):
    """``x -> (theta, cost)`` for a population of searched points; with the
    modal parametrisation the projected numerator is computed once."""
    if isinstance(par, Modal):
        projected = par.projected(cost)
        modes = par.modes

        def modal(x):
            a = modes.to_denominator(x)
            f, b = projected.evaluate(a)
            return np.concatenate([a, b], axis=1), f

        return modal

    def plain(x):
        theta = par.to_theta(x)
        return theta, cost(theta)

    return plain


def _objective_function(par, cost: PaperCost, error: FrequencyError, searched, gain):
    """``x -> (theta, objectives)`` for a population of searched points, the
    columns in the order of `searched`; an unstable candidate pays the
    cost's penalty in every objective."""
    candidates = _candidates(par, cost)
    one_step = (
        PaperCost(cost.arx, cost.data, "one-step", gain=gain, penalty=cost.penalty)
        if "one-step" in searched
        else None
    )

    def evaluate(x):
        theta, f_cost = candidates(np.atleast_2d(x))
        extra = np.where(cost.stable(theta), 0.0, cost.penalty)
        columns = {"cost": f_cost}
        if "frequency" in searched:
            columns["frequency"] = error(theta) + extra
        if one_step is not None:
            columns["one-step"] = one_step(theta)
        return theta, np.column_stack([columns[n] for n in searched])

    return evaluate


def _polish_extremes(evaluate, archive: Archive, box: np.ndarray, budget: int):
    """Each objective's best archived point polished on that objective alone
    by L-BFGS-B in the box (finite-difference gradient, at most `budget`
    evaluations each); returns the polished points and the evaluations."""
    from scipy.optimize import minimize

    points, used = [], 0
    for j in range(archive.f.shape[1]):
        start = archive.x[int(np.argmin(archive.f[:, j]))]
        res = minimize(
            lambda x, j=j: float(evaluate(x)[1][0, j]),
            start,
            method="L-BFGS-B",
            bounds=box,
            options={"maxfun": budget},
        )
        points.append(np.clip(res.x, box[:, 0], box[:, 1]))
        used += int(res.nfev)
    return np.array(points), used


@dataclass
class _StructureRun:
    """One structure's search: its candidates (theta, objectives, origin)."""

    arx: ARX
    res: object
    cost: PaperCost
    box: np.ndarray
    thetas: list = field(default_factory=list)
    rows: list = field(default_factory=list)
    starts: list = field(default_factory=list)
    nfev: int = 0


def _search_structure(
    data, arx, error, searched, method, gen, *, parametrization, cost,
    seed_estimates, extremes_nfev, initial, search, gain, count=None,
) -> _StructureRun:  # fmt: skip
    """Search one structure's front; collect the seeds, the archive of the
    search's incumbents and the polished extremes as candidates. `count`,
    if given, is told the number of points of every evaluation."""
    par = make_parametrization(parametrization, data, arx)
    evaluate = _objective_function(par, cost, error, searched, gain)
    if count is not None:
        evaluate = _counted(evaluate, count)
    box = par.default_bounds()
    seeds = _seed_thetas(data, arx, par, initial) if seed_estimates else {}
    x0 = np.array([par.from_theta(t) for t in seeds.values()]) if seeds else None
    # Every incumbent is a candidate model: an unbounded archive of them
    # (minimize_pareto's own, thinned one is not needed).
    archive = Archive(np.empty((0, box.shape[0])), np.empty((0, len(searched))))
    search = dict(search)
    options = {k: search.pop(k) for k in PARETO_OPTIONS if k in search}
    res = minimize_pareto(
        lambda x: evaluate(x)[1],
        box,
        method,
        **search,
        options=options,
        rng=gen,
        vectorized=True,
        x0=x0,
        archive=False,
        # A callback's falsy return lets the search go on.
        callback=lambda now: archive.add(now.x, now.fun),
    )
    archive.add(res.x, res.fun)
    run = _StructureRun(arx, res, cost, box, nfev=res.nfev)
    # Seeds first: of exact twins the first is kept, with its origin.
    points = [] if x0 is None else [(np.clip(x0, box[:, 0], box[:, 1]), list(seeds))]
    points.append((archive.x, ["search"] * archive.x.shape[0]))
    if extremes_nfev:
        polished, used = _polish_extremes(evaluate, archive, box, extremes_nfev)
        points.append((polished, ["polish"] * polished.shape[0]))
        run.nfev += used
    for x, origin in points:
        # Evaluated again for their theta (counted).
        theta, f = evaluate(x)
        run.nfev += x.shape[0]
        run.thetas.extend(theta)
        run.rows.extend(f)
        run.starts.extend(origin)
    return run


def _counted(evaluate, count: Callable[[int], None]):
    """`evaluate` that tells `count` how many points it evaluated."""

    def counted(x):
        out = evaluate(x)
        count(1 if np.ndim(x) == 1 else len(x))
        return out

    return counted


class _Progress:
    """``progress(done, total)`` of the evaluations of every structure's
    search, fed one evaluation call at a time; `total` is what the budgets
    allow (the seeds' and candidates' evaluations pass it: then it says the
    total)."""

    def __init__(self, progress: Callable[[int, int], None], total: int):
        self.progress, self.total, self.done = progress, max(int(total), 1), 0
        progress(0, self.total)

    def __call__(self, n: int) -> None:
        self.done += n
        self.progress(min(self.done, self.total), self.total)
