"""The reproduction experiment: numbers, statistics and determinism."""

import json

import numpy as np
import pytest
from scipy import stats
from scipy.signal import lfilter

from spiralid import ARX, IOData
from spiralid.report.output import results_dict, summary_text
from spiralid.reproduction import HEADLINE_TEST, Configuration, Reproduction, reproduce

CONFIGS = (Configuration("SDA", "sda"), Configuration("Eb-SDA", "ebsda"))


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(7)
    u = rng.standard_normal(600)
    y = lfilter([0.0, 0.5, 0.25], [1.0, -1.2, 0.5], u) + 0.01 * rng.standard_normal(600)
    return IOData(u, y, ts=0.01)


@pytest.fixture(scope="module")
def rep(data):
    return reproduce(
        data, seeds=3, max_nfev=600, arx=ARX(2, 2, 1), configurations=CONFIGS, workers=1
    )


def _numbers(rep):
    d = results_dict(rep)
    for key in ("elapsed_seconds", "versions", "command"):
        d.pop(key)
    for runs in d["runs"].values():
        for r in runs:
            r.pop("seconds")
            r.pop("times")
    for r in d["baselines"].values():
        r.pop("seconds")
    return json.dumps(d, sort_keys=True)


def test_same_seeds_same_numbers_in_one_or_two_processes(data, rep):
    again = reproduce(
        data, seeds=3, max_nfev=600, arx=ARX(2, 2, 1), configurations=CONFIGS, workers=2
    )
    assert _numbers(again) == _numbers(rep)


def test_statistics_and_rank_sum_match_numpy_and_scipy(rep):
    costs = np.array([r.cost for r in rep.runs["SDA"]])
    s = rep.statistics("SDA")
    assert s["cost_mean"] == pytest.approx(costs.mean())
    assert s["cost_std"] == pytest.approx(costs.std(ddof=1))
    assert s["cost_median"] == pytest.approx(np.median(costs))
    assert (s["cost_best"], s["cost_worst"]) == (costs.min(), costs.max())
    other = [r.cost for r in rep.runs["Eb-SDA"]]
    expected = stats.mannwhitneyu(other, costs, alternative="two-sided")
    assert rep.ranksum("Eb-SDA", "SDA")["p_two_sided"] == pytest.approx(expected.pvalue)
    assert rep.best("SDA").cost == costs.min()


def test_runs_respect_the_budget_and_seeds(rep):
    for runs in rep.runs.values():
        assert [r.seed for r in runs] == [0, 1, 2]
        assert all(r.model.result.nfev <= 600 for r in runs)
        # Times are stamped once per history entry, from zero, increasing.
        for r in runs:
            assert r.times.size == r.history.size
            assert r.times[0] == 0 and np.all(np.diff(r.times) >= 0)


def test_baselines_and_table2(rep, data):
    # On noise-light data from an ARX(2, 2, 1) model, least squares is
    # near-perfect: validation fit well above 95 %.
    assert rep.baselines["LS"].fit_val > 95
    rows = {row["label"]: row for row in rep.table2()}
    assert set(rows) == {"SDA", "Eb-SDA", "LS", "OE"}
    lo, hi = rows["LS"]["error_range_validation"]
    model = rep.baselines["LS"].model
    err = data.y[rep.estimation.n :] - model.simulate(data.u)[rep.estimation.n :]
    assert (lo, hi) == pytest.approx((err.min(), err.max()))


def test_summary_and_verdict_are_honest(rep):
    text = summary_text(rep)
    assert "Table-2" in text and rep.verdict() in text
    test = rep.ranksum("Eb-SDA", "SDA")
    assert rep.verdict().startswith("Eb-SDA beat") == (
        test["p_two_sided"] < 0.05 and test["a12"] > 0.5
    )


def test_one_headline_test_in_summary_results_and_report(rep):
    """The verdict's test is the two-sided rank-sum test, named and quoted the
    same in summary_text, results.json and report.html; no one-sided p."""
    from spiralid.report.output import _html

    results = json.loads(json.dumps(results_dict(rep)))
    head = results["headline_test"]
    p = rep.ranksum("Eb-SDA", "SDA")["p_two_sided"]
    assert head["test"] == HEADLINE_TEST and "two-sided" in HEADLINE_TEST
    assert (head["a"], head["b"], head["p_two_sided"]) == ("Eb-SDA", "SDA", p)
    assert head["verdict"] == results["verdict"] == rep.verdict()
    assert f"two-sided Wilcoxon rank-sum p = {p:.3g}" in head["verdict"]
    text = summary_text(rep)
    page = _html(rep, {}, None)
    for where in (text, page):
        assert head["verdict"] in where
        assert f"Headline test: {HEADLINE_TEST}." in where
        assert "one-sided" not in where


def test_the_verdicts_are_computed_by_the_reproduction(rep):
    # The report only draws them; its old names are the same functions.
    from spiralid.report import output

    assert output.headline is Reproduction.headline
    assert output.verdict is Reproduction.verdict
    assert output.HEADLINE_TEST is HEADLINE_TEST
    assert [(t["a"], t["b"]) for t in rep.ranksums()] == [("Eb-SDA", "SDA")]
    ladder = rep.budget_verdict()
    assert ladder["rows"][-1]["budget"] == ladder["budgets"][-1]
    assert ladder["sentence"].startswith(f"At {ladder['budgets'][-1]:,} evaluations")
    assert rep.budget_verdict("Eb-SDA", "DE") == {"rows": [], "sentence": ""}
    assert rep.headline("Eb-SDA", "DE")["p_two_sided"] is None


def test_the_report_lists_each_best_model_s_modes_with_intervals(rep):
    from spiralid.report.output import _html

    page = _html(rep, {}, None)
    assert "<h2>Modes with 95 % intervals</h2>" in page
    oe = rep.best("OE").model.modes
    assert len(oe) == 1  # the record's one lightly damped pair
    lo, hi = oe.frequency_interval[0]
    assert f"[{lo:.4g}, {hi:.4g}]" in page


def test_bad_input(data):
    with pytest.raises(ValueError, match="`seeds`"):
        reproduce(data, seeds=[], arx=ARX(2, 2, 1))
    with pytest.raises(ValueError, match="`max_nfev`"):
        reproduce(data, max_nfev=1, arx=ARX(2, 2, 1))
    with pytest.raises(TypeError, match="`data`"):
        reproduce(np.zeros(10))


def test_units_reach_the_tables_and_results(data):
    from dataclasses import replace

    with_units = replace(data, input_unit="N m", output_unit="m/s^2")
    r = reproduce(
        with_units,
        seeds=1,
        max_nfev=100,
        n_points=10,
        arx=ARX(2, 2, 1),
        configurations=CONFIGS,
        workers=1,
    )
    assert "error range (modelling, m/s^2)" in summary_text(r)
    assert results_dict(r)["data"]["output_unit"] == "m/s^2"
    assert r.validations["SDA"][1].output_unit == "m/s^2"
