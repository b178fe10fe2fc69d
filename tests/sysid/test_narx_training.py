"""NARX early stopping: the rule that ends Levenberg-Marquardt's rounds."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.optim.result import OptimiserResult
from spiralid.sysid import NARX, IOData, identify
from spiralid.sysid.estimation.core.options import identify_options
from spiralid.sysid.estimation.narx import problem as narx_problem
from spiralid.sysid.estimation.narx.problem import NARXProblem


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
        ("refit", "twice", "`refit`"),
    ],
)
def test_bad_early_stopping_options_are_one_line_errors(option, value, match):
    data = _problem().data
    with pytest.raises(ValueError, match=match):
        identify(data, NARX(2, 2, 1, hidden=(2,)), method="oe", **{option: value})


def _linear_record(n=600, seed=3):
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1.0, 1.0, n)
    y = lfilter([0.0, 0.5, 0.2], [1.0, -1.3, 0.6], u)
    return IOData(u, y + 0.02 * rng.standard_normal(n), ts=0.01)


def test_the_linear_start_is_the_default_arx_a_user_gets():
    from spiralid.sysid import ARX

    data = _linear_record()
    arx = identify(data, ARX(2, 2, 1), rng=5)
    narx = identify(data, NARX(2, 2, 1, hidden=(2,)), rng=5, max_nfev=200)
    start = dataclasses.replace(narx, params=np.asarray(narx.result.linear_params))
    gap = np.max(np.abs(start.simulate(data.u) - arx.simulate(data.u)))
    assert gap <= 1e-9 * np.std(data.y)


def test_early_stopping_starts_from_the_training_parts_linear_model():
    # The start scored on the held-back part must not have seen it: the
    # training start is the default ARX of the training part, drawn from
    # the generator after the whole record's (the refit's) start.
    from spiralid.sysid import ARX
    from spiralid.sysid.estimation.core.families import _default_arx
    from spiralid.sysid.estimation.narx.starts import _linear_starts

    data = _linear_record()
    problem = NARXProblem(
        data,
        NARX(2, 2, 1, hidden=(2,)),
        "simulation",
        "rest",
        0.2,
        np.random.default_rng(7),
    )
    problem.linear_estimator = _default_arx
    train, whole, _ = _linear_starts(problem)
    g = np.random.default_rng(7)
    by_hand_whole = identify(data, ARX(2, 2, 1), rng=g)
    by_hand_train = identify(data[: problem.split], ARX(2, 2, 1), rng=g)
    st = problem.structure
    for params, arx in ((whole, by_hand_whole), (train, by_hand_train)):
        theta = np.asarray(arx.theta)
        assert np.allclose(params, st.from_arx(theta[:2], theta[2:], problem.scaling))
    assert not np.allclose(train, whole)


def test_without_the_refit_the_network_never_ends_worse_on_held_back_data():
    # refit="none" returns the network the early stopping chose, trained on
    # the first four fifths only: on the held-back fifth it is no worse
    # than its start, the training part's default ARX (recomputed here).
    from spiralid.sysid import ARX

    data = _problem().data
    options = {"method": "oe", "rng": 0, "max_rounds": 20}
    none = identify(data, NARX(2, 2, 1, hidden=(3,)), refit="none", **options)
    replay = identify(data, NARX(2, 2, 1, hidden=(3,)), **options)
    assert not none.result.kept_linear and none.result.nit > 0
    # The same early stopping; only the refit differs.
    assert (none.result.start, none.result.nit) == (
        replay.result.start,
        replay.result.nit,
    )
    assert not np.allclose(none.params, replay.params)
    g = np.random.default_rng(0)
    identify(data, ARX(2, 2, 1), rng=g)  # the whole record's start comes first
    split = data.n - round(0.2 * data.n)
    start = identify(data[:split], ARX(2, 2, 1), rng=g)

    def held_back(y):
        return np.sqrt(np.mean((data.y[split:] - y[split:]) ** 2))

    assert held_back(none.simulate(data.u)) < held_back(start.simulate(data.u))
