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


def _verdict(p: float, a12: float, claim, alpha: float) -> str:
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
    rows = []
    for rd in readings:
        if (rd, claim[0]) not in cells or (rd, claim[1]) not in cells:
            continue
        at = {}
        for label in claim:
            cell = cells[rd, label]
            curves = [
                (np.asarray(h, dtype=float), evaluations(n_points, int(f), len(h)))
                for h, f in zip(cell["history"], cell["nfev"], strict=True)
            ]
            at[label] = [[best_at(h, c, b) for h, c in curves] for b in ladder]
        for i, b in enumerate(ladder):
            x, y = np.array(at[claim[0]][i]), np.array(at[claim[1]][i])
            if np.isnan(x).any() or np.isnan(y).any():
                continue  # a budget below the initial population
            t = rank_sum(x, y)
            rows.append({"reading": rd, "budget": b, **t})
    adjusted = holm([r["p_two_sided"] for r in rows]) if rows else []
    crossovers = {}
    for r, p in zip(rows, adjusted, strict=True):
        r["p_holm"] = float(p)
        r["verdict"] = _verdict(r["p_holm"], r["a12"], claim, alpha)
    for rd in readings:
        mine = [r for r in rows if r["reading"] == rd]
        if mine:
            crossovers[rd] = crossover(
                [r["budget"] for r in mine], [r["verdict"] for r in mine]
            )
    return {
        "budgets": ladder,
        # What the histories' evaluation counts are read with (the figures).
        "n_points": n_points,
        "family": len(rows),
        "rows": rows,
        "crossovers": crossovers,
    }
