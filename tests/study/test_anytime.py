"""The claim at every budget, read from stored histories."""

import numpy as np
import pytest
from scipy import stats

from spiralid.study.anytime import best_at, budget_verdicts, crossover, evaluations
from spiralid.study.statistics import holm, rank_sum
from spiralid.sysid import ARX, IOData, identify


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(5)
    u = rng.standard_normal(400)
    y = np.convolve(u, [0.0, 0.8, 0.4, -0.2])[:400] + 0.05 * rng.standard_normal(400)
    return IOData(u, y, ts=0.01)


@pytest.mark.parametrize("method", ["sda", "ebsda"])
@pytest.mark.parametrize("budget", [300, 777, 1500])
def test_best_at_a_budget_is_the_run_stopped_there(record, method, budget):
    # One long run's history against a run of the same seed stopped at the
    # budget: computed in this test run, so bit for bit.
    options = dict(method=method, rng=3, n_points=20)
    long = identify(record, ARX(2, 3, 1), max_nfev=4000, **options)
    short = identify(record, ARX(2, 3, 1), max_nfev=budget, **options)
    counts = evaluations(20, long.result["nfev"], len(long.history))
    assert best_at(long.history, counts, budget) == short.history[-1]
    assert counts[len(short.history) - 1] == short.result["nfev"]


def test_evaluation_counts_of_spiral_and_evolution_runs():
    # A spiral search keeps its centre: m, then m - 1 per iteration.
    np.testing.assert_array_equal(evaluations(50, 50 + 3 * 49, 4), [50, 99, 148, 197])
    # Differential evolution evaluates its whole population each generation.
    np.testing.assert_array_equal(evaluations(10, 40, 4), [10, 20, 30, 40])
    assert np.isnan(best_at([5.0, 4.0], np.array([50, 99]), 20))
    with pytest.raises(ValueError, match="initial population"):
        evaluations(50, 10, 3)


def test_crossover_finds_where_a_verdict_changes():
    budgets = [500, 1000, 2000, 5000, 20000]
    same = ["none"] * 5
    assert crossover(budgets, same) == []
    flip = ["A better", "A better", "none", "none", "B better"]
    assert crossover(budgets, flip) == [2000, 20000]


def _cells(rng, readings, shift):
    """Synthetic histories: A improves fast then stalls, B slowly but
    further (the shape of the paper's Fig. 6a, with the roles swapped)."""
    k = np.arange(41)
    cells = {}
    for rd in readings:
        for label, curve in (("A", 10 - 4 * (1 - np.exp(-k / 3))),
                             ("B", 10 - (6 + shift) * k / 40)):  # fmt: skip
            runs = [np.minimum.accumulate(curve + 0.05 * rng.standard_normal(41))
                    for _ in range(15)]  # fmt: skip
            cells[rd, label] = {"history": runs, "nfev": [20 + 40 * 19] * 15}
    return cells


def test_budget_verdicts_state_their_holm_family():
    readings = [("r1", "p", "q"), ("r2", "p", "q")]
    cells = _cells(np.random.default_rng(0), readings, shift=1.0)
    out = budget_verdicts(cells, readings, ("A", "B"), full_budget=780, n_points=20,
                          budgets=(100, 200, 400))  # fmt: skip
    assert out["budgets"] == [100, 200, 400, 780]
    # Every test made is in the family Holm corrects over.
    assert out["family"] == len(out["rows"]) == 2 * 4
    np.testing.assert_allclose(
        [r["p_holm"] for r in out["rows"]],
        holm([r["p_two_sided"] for r in out["rows"]]),
    )
    # A leads early, B ends lower: the verdict flips along the way.
    first, last = out["rows"][0], out["rows"][3]
    assert first["verdict"] == "A better" and last["verdict"] == "B better"
    assert out["crossovers"][readings[0]]


@pytest.mark.parametrize(
    "x, y",
    [
        ([3.0, 1.0, 4.0, 1.5, 9.0], [2.0, 6.0, 5.0, 3.5, 8.0]),
        ([1.0, 1.0, 2.0, 2.0, 3.0], [2.0, 2.0, 3.0, 3.0, 4.0]),  # ties
    ],
)
def test_the_one_rank_sum_matches_scipy_as_the_reproduction_used_it(x, y):
    # The reproduction called scipy.stats.mannwhitneyu directly; it now uses
    # the study's rank_sum, which must give the same p-values.
    t = rank_sum(x, y)
    assert t["p_two_sided"] == stats.mannwhitneyu(x, y, alternative="two-sided").pvalue
    assert t["p_less"] == stats.mannwhitneyu(x, y, alternative="less").pvalue
