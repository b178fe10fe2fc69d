"""Choosing among an estimation's distinct minima on held-back data.

A lower estimation cost is not a better model: the simulation error of a
flexible structure has several local minima, and the lowest one on the
estimation record may owe its edge to fitting that record's drift or noise
(a pole slower than the record, a near-cancelling pole-zero pair). The
recommended method (``"spiral"``,
:func:`~spiralid.sysid.estimation.spiral.recommended._estimate_recommended`
with ``holdback``) therefore takes each
distinct minimum it found on the whole estimation record (the search's
best, output error from least squares and from Steiglitz-McBride), refits
it locally on the first ``1 - h`` of the record (a Levenberg-Marquardt
polish from that minimum, so it stays in the minimum's basin), and scores
the refit by its simulation error on the held-back end ``h``. It keeps the
lowest whole-record cost unless another minimum's held-back error is lower
by more than :data:`MARGIN` (a relative share): the held-back part decides
only when it sees a real difference, so a record with one minimum keeps its
cost, and the chosen model is that minimum's whole-record fit.

The reported cost stays the paper's (eq. (2)-(3) over the whole estimation
record); the held-back scores are a choice, not a cost.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...data import IOData
from ..core.cost import PaperCost

__all__ = [
    "HOLDBACK",
    "MARGIN",
    "REFIT_NFEV",
    "Candidate",
    "Selection",
    "held_back_rms",
    "refit_nfev",
    "select",
]

#: The recommended method's default share of the estimation record held back
#: (as NARX's early stopping holds back 0.2).
HOLDBACK = 0.2

#: How much lower (relatively) another minimum's held-back RMS error must be
#: than the lowest-cost one's before it is chosen instead. Two points of
#: validation fit on a record where the errors are a few percent of the
#: output are a few percent of the error; below that the held-back part is
#: too short to tell minima apart.
MARGIN = 0.05

#: Each refit on the first part is capped at this many evaluations per
#: parameter (and one): it starts at a minimum of the whole record, which
#: moves little when a fifth of the record is left out, and it only has to
#: tell basins apart by more than MARGIN, not reach the part's tolerances.
#: Uncapped refits (``100 (p + 1)``, the polish's default) took longer than
#: output error itself at ARX(32, 32, 0); with the cap the choices and costs
#: were the same on ``benchmarks/selection.py``'s records (drift.py's among
#: them; docs/results/identification.md, "How it scales with the order").
REFIT_NFEV = 25


@dataclass
class Candidate:
    """One distinct minimum: where it came from, its local refit on the
    first part and that refit's held-back RMS error, and the whole-record
    fit with its cost. A minimum found alone is not refitted (there is
    nothing to choose): ``held_rms`` None and ``theta_part`` its
    whole-record fit. ``capped``: the refit stopped at its evaluation cap,
    not at its tolerances."""

    name: str
    theta_part: np.ndarray
    held_rms: float | None
    theta: np.ndarray
    cost: float
    capped: bool = False


@dataclass
class Selection:
    """What the held-back choice saw and decided (``result.selection``)."""

    holdback: float
    n_held: int
    candidates: list[Candidate] = field(default_factory=list)
    chosen: str = ""
    lowest_cost: str = ""

    @property
    def overrode_cost(self) -> bool:
        """The held-back choice is not the lowest whole-record cost."""
        return self.chosen != self.lowest_cost

    def to_dict(self) -> dict:
        return {
            "holdback": self.holdback,
            "n_held": self.n_held,
            "chosen": self.chosen,
            "lowest_cost": self.lowest_cost,
            "candidates": [
                {"start": c.name, "held_back_rms": c.held_rms, "cost": c.cost}
                for c in self.candidates
            ],
            "note": self.sentence(),
        }

    def sentence(self) -> str:
        """One line for a summary: what was chosen and why."""
        by_name = {c.name: c for c in self.candidates}
        chosen, lowest = by_name[self.chosen], by_name[self.lowest_cost]
        if len(self.candidates) == 1:
            # Nothing was scored: every start ended in this minimum.
            return (
                f"1 distinct minimum ({_words(self.chosen)}): nothing to choose "
                "on the held-back part"
            )
        if not self.overrode_cost:
            head = f"{len(self.candidates)} distinct minima; the lowest cost "
            where = (
                f"on the held-back {100 * self.holdback:.0f} % of the estimation record"
            )
            scored = [c for c in self.candidates if c.held_rms is not None]
            best = min(scored, key=lambda c: c.held_rms, default=chosen)
            if chosen.held_rms is None or best.held_rms >= chosen.held_rms:
                return f"{head}({_words(self.chosen)}) also validates best {where}"
            # Kept although another validates better: say why, not "best".
            rms = f"held-back RMS {best.held_rms:.3g} against {chosen.held_rms:.3g}"
            if best.capped and best.held_rms < (1.0 - MARGIN) * chosen.held_rms:
                why = (
                    f"({rms}), but its refit stopped at its evaluation cap, so "
                    "that score is not trusted"
                )
            else:
                why = f"by less than {100 * MARGIN:.0f} % ({rms})"
            return (
                f"{head}({_words(self.chosen)}) is kept: {_words(best.name)} "
                f"validates better {where} {why}"
            )
        return (
            f"the held-back {100 * self.holdback:.0f} % of the estimation record: "
            f"{_words(self.chosen)} (cost {chosen.cost:.4g}, held-back RMS "
            f"{chosen.held_rms:.3g}) over the lowest cost, {_words(self.lowest_cost)} "
            f"(cost {lowest.cost:.4g}, held-back RMS {lowest.held_rms:.3g})"
        )


#: The candidates' names in words.
_IN_WORDS = {
    "search": "the search's best",
    "ls": "output error from least squares",
    "steiglitz-mcbride": "output error from Steiglitz-McBride",
}


def _words(name: str) -> str:
    return _IN_WORDS.get(name, name)


def held_back_rms(theta, cost: PaperCost, start: int) -> float:
    """RMS of the simulation error over samples ``start..N-1`` of `cost`'s
    record, the model run over the whole record (so the held-back part
    starts from the state the earlier samples left, not from rest)."""
    y_sim = cost.simulate(theta)
    y = cost.data.y[cost.t0 :]
    e = (y - y_sim)[max(start - cost.t0, 0) :]
    rms = float(np.sqrt(np.mean(e**2)))
    return rms if np.isfinite(rms) else float("inf")


def split(data: IOData, holdback: float, min_samples: int) -> int | None:
    """The first held-back sample, or None when the first part would be
    shorter than `min_samples` (the record is too short to hold any back)."""
    start = round((1.0 - holdback) * data.n)
    if start < min_samples or data.n - start < 2:
        return None
    return start


def distinct(candidates: list[Candidate], cost: PaperCost) -> list[Candidate]:
    """Candidates whose simulated outputs (of the whole-record fits)
    differ: two runs closer than 1e-6 of the output's RMS are one minimum,
    found twice, and the one with the lower cost is kept (ties: the first),
    so the lowest cost among the distinct minima is the lowest of all."""
    scale = float(np.sqrt(np.mean(cost.data.y**2))) or 1.0
    kept, runs = [], []
    for c in sorted(candidates, key=lambda c: c.cost):
        run = cost.simulate(c.theta)
        if all(np.sqrt(np.mean((run - r) ** 2)) > 1e-6 * scale for r in runs):
            kept.append(c)
            runs.append(run)
    return kept


def refit_nfev(n_params: int) -> int:
    """The evaluation cap of each held-back refit, :data:`REFIT_NFEV` per
    parameter and one, a quarter of a full polish's default."""
    return REFIT_NFEV * (n_params + 1)


def select(candidates: list[Candidate], trust_capped: bool = True) -> tuple[str, str]:
    """``(chosen, lowest_cost)``: the lowest whole-record cost, unless
    another candidate's held-back RMS is lower by more than :data:`MARGIN`
    (then the lowest held-back RMS). One candidate is chosen unscored.

    Parameters
    ----------
    candidates : list of Candidate
    trust_capped : bool
        Whether a candidate whose refit stopped at its cap may be chosen
        over the lowest cost. A refit cut short stays near the whole-record
        fit, which saw the held-back end, so its score is too kind (on the
        arm at ARX(8, 8, 0) a Steiglitz-McBride minimum 10 % above the
        lowest cost scored 0.0223 after 11 evaluations, 0.0391 after 425).
    """
    lowest = min(candidates, key=lambda c: c.cost)
    if len(candidates) == 1:
        return lowest.name, lowest.name
    judged = [c for c in candidates if trust_capped or not c.capped or c is lowest]
    best = min(judged, key=lambda c: c.held_rms)
    if best.held_rms < (1.0 - MARGIN) * lowest.held_rms:
        return best.name, lowest.name
    return lowest.name, lowest.name
