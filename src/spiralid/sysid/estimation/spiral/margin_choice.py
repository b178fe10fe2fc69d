"""Keeping or lifting the default stability margin, by the held-back end.

The default margin (``max_time_constant="auto"``,
:mod:`~spiralid.sysid.estimation.linear.margin`) keeps every pole faster than the
estimation record is long, because a slower pole is usually a drift that
the model fits instead of the plant. Not always: a plant whose output
integrates once more than the model was told (the rig's hub angle with
``integrator=True``, a double integrator) or a mode genuinely slower than
the record needs such a pole, and without it the model is not a little
worse but useless (the hub angle validated at 17 % with the margin and
96 % without, docs/results/identification.md, "Integrating outputs").

So when the margin binds -- a minimum the estimation found has its
slowest pole at :data:`BINDING` or more of the margin's time constant --
that minimum is released: output error polishes it again without the
margin. If that lowers the whole estimation record's cost by less than
:data:`SCREEN` asks, the margin cost the fit nothing that matters and is
kept. Otherwise the two models are judged on data neither was fitted to,
as the recommended method judges its minima
(:mod:`~spiralid.sysid.estimation.spiral.heldback`): each is refitted locally on
the first ``1 - h`` of the record and scored by its simulation error on
the held-back end (the free one is output error's best without the margin
from the released minimum and from its own starts). The margin is lifted
only when the model without it
validates there with less than :data:`LIFT` of the margined model's error:
a drift can make the free model look a little better on a short held-back
end (on ``benchmarks/drift.py``'s record at ARX(8, 8, 0), 2 of 10 seeds
scored 10-25 % lower without the margin; the margin was kept on all 10),
not twice as good; a missing integrator does (the hub angle with
``integrator=True``: 4 to 25 times lower). An explicit
``max_time_constant`` is the user's, and is never lifted.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from ..core.problem import EstimatorResult, Problem
from ..linear.local_estimators import _cancel, _polish, _standard_starts
from ..linear.outputerror import local_polish
from ..linear.parametrizations import make_parametrization
from . import heldback

__all__ = [
    "BINDING",
    "LIFT",
    "SCREEN",
    "SCREEN_NFEV",
    "MarginChoice",
    "choose",
    "slowest_found",
]

#: The margin binds when the slowest pole's time constant is at least this
#: share of the margin's ``T``: the polish reflects a pole that crosses the
#: circle to just inside it, so a bound pole sits within a few percent of
#: ``T``, and a free one well below (on drift.py's record, 0.26-0.54 T).
BINDING = 0.95

#: Released, the model must cost less than this share of the margined one
#: on the whole estimation record before the held-back end is asked: the
#: margin cost the drift record at most 5.4 % (released costs 0.946-0.994
#: of it), a missing integrator 80-95 % (0.05-0.20), and the rig's spare
#: poles at high orders nothing (0.997-1.000), where the two refits would
#: have doubled output error's time.
SCREEN = 0.95

#: The release's first polish, which the screen judges, is capped at this
#: many evaluations per parameter (and one): two Levenberg-Marquardt steps.
#: Those took the hub angle's cost to 0.20-0.49 of the margined one (the
#: full polish to 0.05-0.20) and cost 0.26 s at ARX(24, 24, 0) on 8,000
#: samples, where the full release took 0.88 s against output error's 1.0.
SCREEN_NFEV = 2

#: The free model's held-back RMS error must be below this share of the
#: margined model's for the margin to be lifted (see the module's text).
LIFT = 0.5


@dataclass
class MarginChoice:
    """What the default margin did where it bound (``model.margin``): its
    time constant and the bound pole's (seconds), the released model's
    whole-record cost as a share of the margined one's, and the held-back
    scores (None when the release gained too little to ask)."""

    time_constant: float
    slowest: float
    released_cost: float
    holdback: float
    n_held: int
    held_back_rms: dict[str, float] | None
    lifted: bool

    def to_dict(self) -> dict:
        # Every field, in order, so a field added later is saved too.
        return {**asdict(self), "note": self.sentence()}

    def sentence(self) -> str:
        """One line for a summary: the margin, and why it stayed or went."""
        head = (
            f"the stability margin (time constant <= {self.time_constant:.4g} s) "
            f"held a pole at {self.slowest:.4g} s; released, that minimum costs "
            f"{self.released_cost:.3g}x the estimate"
        )
        rms = self.held_back_rms
        if rms is None:
            return f"{head}, too little to lift the margin (below {SCREEN:g}x needed)"
        scores = (
            f"held-back RMS {rms['free']:.3g} without it against "
            f"{rms['margin']:.3g} with it on the last {100 * self.holdback:.0f} % "
            "of the estimation record"
        )
        if self.lifted:
            return (
                f"{head} and validates better ({scores}): the margin was lifted (a "
                "pole slower than the record; if the output integrates, say so "
                "with `integrator`)"
            )
        return f"{head}, but the margin was kept ({scores}, not below {LIFT:g}x)"


def slowest_time_constant(a: np.ndarray, ts: float) -> float:
    """The largest time constant ``-ts / ln|p|`` of the poles of
    ``1 + a_1 z^-1 + ...`` (inf for a pole on or outside the unit circle,
    0 for none)."""
    radius = float(np.max(np.abs(np.roots(np.r_[1.0, a])), initial=0.0))
    if radius >= 1.0:
        return float("inf")
    return -ts / float(np.log(radius)) if radius > 0.0 else 0.0


def slowest_found(
    result: EstimatorResult, problem: Problem
) -> tuple[float, np.ndarray]:
    """The largest time constant among the minima `result` found, and that
    minimum: its estimate, or a polish from one of its starts (the
    recommended search may end in a minimum whose poles are clear of the
    margin while output error's, from least squares, is pressed on it)."""
    polished = result.get("refine") or result
    found = [result.x, *(polished.get("thetas") or {}).values()]
    na, ts = problem.arx.na, problem.data.ts
    slowest = [slowest_time_constant(theta[:na], ts) for theta in found]
    k = int(np.argmax(slowest))
    return slowest[k], found[k]


def choose(
    problem: Problem, result: EstimatorResult, holdback: float
) -> tuple[Problem, EstimatorResult, MarginChoice] | None:
    """The margined `result` or output error's without the margin, judged
    on the held-back end ``holdback`` of `problem`'s record: ``(problem,
    result, choice)`` of the one chosen (the problem without the margin if
    it was lifted), or None when the margin does not bind or the record is
    too short to hold any back."""
    if not holdback or problem.max_radius is None:
        return None
    ts = problem.data.ts
    limit = -ts / np.log(problem.max_radius)
    slowest, bound = slowest_found(result, problem)
    if slowest < BINDING * limit:
        return None
    least = problem.arx.max_lag + 2 * problem.arx.n_params
    start = heldback.split(problem.data, holdback, least)
    if start is None:
        return None
    free = replace(
        problem,
        max_radius=None,
        parametrization=make_parametrization(
            problem.parametrization.name, problem.data, problem.arx, None
        ),
    )
    gain, unbound = _released(free, result, bound)
    scores = None
    if unbound is not None:
        scores = {
            "margin": _held_back_rms(problem, result.x, start),
            "free": _held_back_rms(free, unbound.x, start),
        }
    lifted = scores is not None and scores["free"] < LIFT * scores["margin"]
    choice = MarginChoice(
        time_constant=limit,
        slowest=slowest,
        released_cost=gain,
        holdback=holdback,
        n_held=problem.data.n - start,
        held_back_rms=scores,
        lifted=lifted,
    )
    if not lifted:
        return problem, result, choice
    if free.cancel:
        # Only a model that is returned has its pairs removed: the removal's
        # polishes cost as much as the release, and a kept margin returns
        # the margined model, which had its own.
        _cancel(free, unbound, free.simulation_cost())
    unbound.elapsed += result.elapsed
    unbound.message = f"{result.message} Then {choice.sentence()}."
    return free, unbound, choice


def _released(
    free: Problem, result: EstimatorResult, bound: np.ndarray
) -> tuple[float, EstimatorResult | None]:
    """The bound minimum released: the cost of output error's best without
    the margin as a share of `result`'s, and that estimate (None when a
    few steps show it gains too little to ask the held-back end)."""
    cost = free.simulation_cost()
    # Two steps tell whether the held-back pole, moving out to where the
    # data put it, gains enough; only then is it polished in full.
    cap = SCREEN_NFEV * (free.arx.n_params + 1)
    first = _polish(free, {"released": bound}, "simulation", cost, cap)
    gain = float(cost(first.x) / cost(result.x))
    if gain >= SCREEN:
        return gain, None
    # From the bound minimum again (continued from the screen's two steps,
    # the polish ended in a worse minimum on one hub record), and from
    # output error's own starts, which found a lower minimum without the
    # margin on the rig's hub angle at ARX(8, 8, 0).
    starts = {"released": bound, **_standard_starts(free)}
    unbound = _polish(free, starts, "simulation", cost)
    return float(cost(unbound.x) / cost(result.x)), unbound


def _held_back_rms(problem: Problem, theta: np.ndarray, start: int) -> float:
    """`theta` refitted locally on the record before `start`, with
    `problem`'s margin, and scored on the rest: the refit has not seen the
    held-back end, so its error there judges the minimum, not the fit."""
    part = problem.data[:start]
    refit, _ = local_polish(
        theta,
        problem.arx,
        part,
        "simulation",
        problem.initial,
        max_radius=problem.max_radius,
        max_nfev=heldback.refit_nfev(problem.arx.n_params),
    )
    return heldback.held_back_rms(refit, problem.simulation_cost(), start)
