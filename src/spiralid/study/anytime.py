"""The claim at every budget, from the runs already stored.

Every stored run keeps its convergence history: the best cost after the
initial population and after each iteration. The best cost a run had after
``k`` evaluations is therefore known for every ``k`` up to its budget
without running anything again, and the claim (Eb-SDA ends lower than SDA)
can be tested at a ladder of budgets, as the paper's Fig. 6a reads it: SDA
may lead at first, Eb-SDA overtake it later, or the reverse.

:func:`best_at` reads one history; :func:`budget_verdicts` tests the claim
per reading at every budget of a ladder, with the Holm correction over the
whole family (readings x budgets: every test made); :func:`crossover` finds
where a reading's verdict changes.
"""

from __future__ import annotations

import numpy as np

from .statistics import holm, rank_sum

__all__ = ["BUDGETS", "best_at", "budget_verdicts", "crossover", "evaluations"]

# The ladder of budgets (evaluations); the study's own budget is added.
BUDGETS = (500, 1_000, 2_000, 5_000, 10_000)


def evaluations(n_points: int, nfev: int, length: int) -> np.ndarray:
    """Evaluations spent when each entry of a history of `length` entries was
    recorded: the initial population (`n_points`), then a constant number
    per iteration, read off the run's final count `nfev` (``n_points - 1``
    for a spiral search, whose centre is kept; ``n_points`` for differential
    evolution)."""
    if length < 1 or nfev < n_points:
        raise ValueError(
            f"a history needs its initial population: length {length}, nfev "
            f"{nfev}, n_points {n_points}"
        )
    if length == 1:
        return np.array([n_points])
    per_iteration = (nfev - n_points) / (length - 1)
    return n_points + np.round(per_iteration * np.arange(length)).astype(int)


def best_at(history, counts: np.ndarray, budget: int) -> float:
    """The best cost of a run after at most `budget` evaluations (NaN if its
    initial population alone exceeds it)."""
    history = np.asarray(history, dtype=float)
    last = int(np.searchsorted(counts, budget, side="right")) - 1
    return float(history[last]) if last >= 0 else float("nan")


def crossover(budgets, verdicts) -> list[int]:
    """The budgets at which a verdict differs from the one at the budget
    before it (empty when it holds all along)."""
    return [
        int(b)
        for b, prev, cur in zip(budgets[1:], verdicts[:-1], verdicts[1:], strict=True)
        if cur != prev
    ]


def verdict(p: float, a12: float, claim, alpha: float) -> str:
    """The verdict on `claim` (better, reference) from a Holm-adjusted
    p-value and the A12 effect size, at level `alpha`."""
    if p >= alpha:
        return "no significant difference"
    return f"{claim[0]} better" if a12 > 0.5 else f"{claim[1]} better"


def budget_verdicts(cells: dict, readings, claim, full_budget: int, n_points: int,
                    alpha: float = 0.05, budgets=BUDGETS) -> dict:  # fmt: skip
    """The claim per reading at every budget of the ladder.

    Parameters
    ----------
    cells : dict of (reading, label) to dict
        :class:`~spiralid.study.StudyResults`'s cells (``history`` and
        ``nfev`` per run).
    readings : list of reading
    claim : (str, str)
        The labels claimed better and its reference.
    full_budget, n_points : int
        The study's budget and population.
    alpha : float
        Family-wise level of the Holm correction over every test made.

    Returns
    -------
    dict
        ``budgets``; ``family`` (the number of tests Holm corrects over:
        readings tested x budgets); ``rows``, one per reading and budget
        with both medians, ``p_two_sided``, ``p_holm``, ``a12`` and
        ``verdict``; ``crossovers``, per reading the budgets where its
        verdict changes.
    """
    ladder = sorted({*(b for b in budgets if b < full_budget), int(full_budget)})
    rows = [
        row
        for rd in readings
        if (rd, claim[0]) in cells and (rd, claim[1]) in cells
        for row in _reading_rows(cells, rd, claim, ladder, n_points)
    ]
    adjusted = holm([r["p_two_sided"] for r in rows]) if rows else []
    for r, p in zip(rows, adjusted, strict=True):
        r["p_holm"] = float(p)
        r["verdict"] = verdict(r["p_holm"], r["a12"], claim, alpha)
    return {
        "budgets": ladder,
        # What the histories' evaluation counts are read with (the figures).
        "n_points": n_points,
        "family": len(rows),
        "rows": rows,
        "crossovers": _crossovers(rows, readings),
    }


def _best_per_budget(cell: dict, ladder, n_points: int) -> list[list[float]]:
    """Each run's best cost at each budget of the ladder (rows: budgets)."""
    curves = [
        (np.asarray(h, dtype=float), evaluations(n_points, int(f), len(h)))
        for h, f in zip(cell["history"], cell["nfev"], strict=True)
    ]
    return [[best_at(h, c, b) for h, c in curves] for b in ladder]


def _reading_rows(cells: dict, rd, claim, ladder, n_points: int) -> list[dict]:
    """The rank-sum test of one reading's claim at every budget its initial
    populations fit in (Holm's correction comes later, over the family)."""
    ours, theirs = (
        _best_per_budget(cells[rd, label], ladder, n_points) for label in claim
    )
    rows = []
    for b, x, y in zip(ladder, ours, theirs, strict=True):
        x, y = np.array(x), np.array(y)
        if np.isnan(x).any() or np.isnan(y).any():
            continue  # a budget below the initial population
        rows.append({"reading": rd, "budget": b, **rank_sum(x, y)})
    return rows


def _crossovers(rows: list[dict], readings) -> dict:
    """Per reading tested, the budgets where its verdict changes."""
    crossovers = {}
    for rd in readings:
        mine = [r for r in rows if r["reading"] == rd]
        if mine:
            crossovers[rd] = crossover(
                [r["budget"] for r in mine], [r["verdict"] for r in mine]
            )
    return crossovers
