"""NARX early stopping: the rule that ends Levenberg-Marquardt's rounds."""

import math

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.optim.result import OptimiserResult
from spiralid.sysid import NARX, IOData, identify
from spiralid.sysid.estimation import narx_problem
from spiralid.sysid.estimation.narx_problem import NARXProblem
from spiralid.sysid.estimation.options import identify_options


def _problem(holdout=0.2):
    rng = np.random.default_rng(0)
    u = rng.uniform(-1.5, 1.5, 300)
    y = lfilter([0.0, 0.6, 0.3], [1.0, -1.2, 0.5], np.tanh(2.0 * u))
    data = IOData(u, y, ts=0.01)
    return NARXProblem(
        data, NARX(2, 2, 1, hidden=(2,)), "simulation", "rest", holdout, rng
    )


class _Scripted:
    """Held-back costs scripted round by round: falling until `best`, then
    flat above the lowest, so the stop is a count worked by hand."""

    def __init__(self, best: int):
        self.best, self.calls = best, 0

    def __call__(self, p, predictor, pick):
        r = self.calls  # 0: the start, then one call per round
        self.calls += 1
        return 1000.0 - r if r <= self.best else 1001.0 - self.best


def _one_round(fun, jac, p, max_nfev, tol):
    # Each round moves the point and ends at its evaluation cap (stop 0), as
    # a polish that is still gaining does.
    return OptimiserResult(x=p + 1.0, stop=0)


@pytest.mark.parametrize(
    ("best", "share", "patience", "rounds_run"),
    [
        (40, 0.0, 3, 43),  # the fixed patience: 3 rounds after the best
        (40, 0.5, 3, 60),  # grows with the best round: ceil(0.5 * 40) = 20
        (3, 0.5, 3, 6),  # never below the fixed patience
        (60, 0.5, 3, 80),  # 60 + 30 rounds, capped by max_rounds
        (45, 0.5, 3, 68),  # ceil(22.5) = 23
    ],
)
def test_patience_grows_with_the_best_round(
    monkeypatch, best, share, patience, rounds_run
):
    problem = _problem()
    scripted = _Scripted(best)
    monkeypatch.setattr(problem, "_score", scripted)
    monkeypatch.setattr(narx_problem, "levenberg_marquardt", _one_round)
    p0 = np.zeros(problem.structure.n_params)
    p, best_round = problem.polish(p0, "simulation", 80, patience, share)
    expected_run = min(80, best + max(patience, math.ceil(share * best)))
    assert rounds_run == expected_run
    assert scripted.calls == 1 + rounds_run
    assert best_round == best
    # The point returned is the best round's: `best` unit moves from p0.
    np.testing.assert_array_equal(p, p0 + best)


def test_a_falling_held_back_cost_trains_past_fifty_rounds(monkeypatch):
    """The default method's final polish is not stopped at the former cap
    of 50 rounds while the held-back cost still falls."""
    problem = _problem()
    scripted = _Scripted(120)
    monkeypatch.setattr(problem, "_score", scripted)
    monkeypatch.setattr(narx_problem, "levenberg_marquardt", _one_round)
    p0 = np.zeros(problem.structure.n_params)
    _, best_round = problem.polish(p0, "simulation")
    assert best_round == 120


def test_spiral_takes_the_early_stopping_options():
    opts = identify_options("spiral", NARX(2, 2, 1))
    assert {"max_rounds", "patience", "patience_share"} <= set(opts)
    for method in ("ls", "oe"):
        assert "patience_share" in identify_options(method, NARX(2, 2, 1))


@pytest.mark.parametrize(
    ("option", "value", "match"),
    [
        ("patience_share", -0.5, "`patience_share`"),
        ("patience_share", float("nan"), "`patience_share`"),
        ("max_rounds", 0, "`max_rounds`"),
        ("patience", 0, "`patience`"),
    ],
)
def test_bad_early_stopping_options_are_one_line_errors(option, value, match):
    data = _problem().data
    with pytest.raises(ValueError, match=match):
        identify(data, NARX(2, 2, 1, hidden=(2,)), method="oe", **{option: value})
