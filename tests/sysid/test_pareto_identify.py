"""identify_pareto: a front of stable, validatable ARX models."""

from types import SimpleNamespace

import numpy as np
import pytest

import spiralid as sid
from spiralid.optim import minimize_pareto  # noqa: F401  (the search it runs)
from spiralid.optim.pareto import non_dominated
from spiralid.sysid import ARX, PaperCost, choose, identify_pareto, knee_point
from spiralid.sysid.estimation.linear.frequency import FrequencyError

SMALL = dict(max_nfev=600, n_points=20, extremes_nfev=50)


@pytest.fixture(scope="module")
def arm():
    return sid.datasets.robot_arm().split(2 / 3)


@pytest.fixture(scope="module")
def front(arm):
    est, _ = arm
    return identify_pareto(est, ARX(4, 4, 0), rng=0, **SMALL)


def test_every_front_model_is_stable_and_validates(arm, front):
    est, val = arm
    assert len(front) >= 2
    for model in front.models:
        assert model.is_stable
        rep = sid.validate(model, val, warmup=est)
        assert rep.stable and np.isfinite(rep.fit_percent)
    # Saved and read back as identify's models are.
    again = sid.IdentifiedModel.from_dict(front.knee_model.to_dict())
    np.testing.assert_array_equal(again.theta, front.knee_model.theta)


def test_the_front_is_non_dominated_and_its_values_are_recomputable(arm, front):
    est, _ = arm
    assert non_dominated(front.objectives).all()
    assert np.all(np.diff(front.objectives[:, 0]) >= 0)  # sorted by cost
    cost = PaperCost(ARX(4, 4, 0), est)
    error = FrequencyError(ARX(4, 4, 0), front.frequency)
    for model, row in zip(front.models, front.objectives, strict=True):
        assert row[0] == pytest.approx(cost(model.theta), rel=1e-9)
        assert row[1] == pytest.approx(error(model.theta), rel=1e-9)
        assert model.cost == pytest.approx(row[0], rel=1e-9)
        assert model.result.objectives == {"cost": row[0], "frequency": row[1]}


def test_the_seeded_front_reaches_output_error(arm, front):
    est, _ = arm
    oe = sid.identify(est, ARX(4, 4, 0), method="oe")
    assert front.objectives[:, 0].min() <= oe.cost * (1 + 1e-6)
    assert front.seeded
    assert {m.result.start for m in front.models} <= {
        "search", "polish", "ls", "steiglitz-mcbride", "oe"
    }  # fmt: skip


def test_same_seed_same_front(arm, front):
    est, _ = arm
    again = identify_pareto(est, ARX(4, 4, 0), rng=0, **SMALL)
    np.testing.assert_array_equal(again.objectives, front.objectives)
    for a, b in zip(again.models, front.models, strict=True):
        np.testing.assert_array_equal(a.theta, b.theta)
    assert again.knee == front.knee


def test_several_orders_add_the_order_objective(arm):
    est, val = arm
    front = identify_pareto(est, [2, 4], rng=1, seed_estimates=False, **SMALL)
    assert front.names == ("cost", "frequency", "order")
    assert non_dominated(front.objectives).all()
    for model, row in zip(front.models, front.objectives, strict=True):
        assert row[2] == model.arx.n_params and model.arx.na in (2, 4)
        assert model.is_stable
        sid.validate(model, val, warmup=est)
    assert set(front.hypervolume) == {"ARX(2, 2, 0)", "ARX(4, 4, 0)"}
    # The incumbents' hypervolume need not grow (MOEA/D replaces incumbents).
    assert all(h.size > 1 and np.all(h >= 0) for h in front.hypervolume.values())


def test_the_paper_coefficients_search_keeps_only_stable_models(arm):
    est, _ = arm
    front = identify_pareto(est, ARX(2, 2, 0), parametrization="coefficients",
                            rng=0, **SMALL)  # fmt: skip
    assert all(m.is_stable for m in front.models)
    assert front.objectives[:, 0].max() < 1e6  # no penalised point


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"objectives": ("cost", "gain")}, "`objectives` must be among"),
        ({"objectives": "cost"}, "`objectives` must be a list"),
        ({"objectives": ("cost",)}, "`objectives` must name 2 or 3"),
        ({"objectives": ("cost", "cost")}, "must not repeat"),
        ({"objectives": ("cost", "frequency", "order")}, "needs several orders"),
        ({"orders": [2, 0]}, "`orders` must be"),
        ({"orders": [2, 2]}, "`orders` must not repeat"),
        ({"orders": "2:12"}, "`orders` must be"),
        ({"orders": []}, "`orders` must be"),
        ({"orders": [2.5]}, "`orders` must be"),
        ({"method": "periodic"}, "`method` must be one of"),
        ({"seed_estimates": "yes"}, "`seed_estimates`"),
        ({"extremes_nfev": -1}, "`extremes_nfev`"),
        ({"max_nfev": 10}, "`max_nfev`"),
    ],
)
def test_bad_arguments_are_clear_errors_naming_them(arm, kwargs, match):
    est, _ = arm
    args = {"orders": ARX(2, 2, 0), **SMALL, **kwargs}
    orders = args.pop("orders")
    with pytest.raises((TypeError, ValueError), match=match):
        identify_pareto(est, orders, **args)


def test_several_orders_with_three_searched_objectives_is_refused(arm):
    est, _ = arm
    with pytest.raises(ValueError, match="`objectives` must name 2 or 3"):
        identify_pareto(est, [2, 3], ("cost", "frequency", "one-step"), **SMALL)


def test_three_searched_objectives_on_one_structure(arm):
    est, _ = arm
    front = identify_pareto(est, ARX(2, 2, 0), ("cost", "frequency", "one-step"),
                            rng=0, **SMALL)  # fmt: skip
    assert front.objectives.shape[1] == 3
    one_step = PaperCost(ARX(2, 2, 0), est, "one-step")
    for model, row in zip(front.models, front.objectives, strict=True):
        assert row[2] == pytest.approx(one_step(model.theta), rel=1e-9)


def test_knee_is_farthest_from_the_extremes_line():
    # Normalised, the line runs from (0, 1) to (1, 0); (0.1, 0.2) is
    # farthest below it.
    f = [[0, 10], [1, 2], [5, 1], [10, 0]]
    assert knee_point(f) == 1
    # A straight front has no knee: every point is on the line; the first.
    assert knee_point([[0, 2], [1, 1], [2, 0]]) == 0
    # One point, or extremes that coincide: the one nearest the ideal point.
    assert knee_point([[3, 4]]) == 0
    # Three objectives: the plane through the three extremes.
    f3 = [[0, 1, 1], [1, 0, 1], [1, 1, 0], [0.2, 0.2, 0.2], [0.5, 0.5, 0.4]]
    assert knee_point(f3) == 3
    with pytest.raises(ValueError, match="`objectives`"):
        knee_point([[np.nan, 1.0]])


def test_choose_the_lowest_cost_under_a_bound(front):
    i = choose(front, max_frequency=front.objectives[:, 1].max())
    assert i == 0  # no bound binds: the lowest cost
    bound = np.median(front.objectives[:, 1])
    j = choose(front, max_frequency=bound)
    ok = front.objectives[:, 1] <= bound
    assert ok[j] and front.objectives[j, 0] == front.objectives[ok, 0].min()
    k = choose(front, "frequency", max_cost=front.objectives[:, 0].min())
    assert k == 0
    with pytest.raises(ValueError, match="no front point meets"):
        choose(front, max_frequency=-1.0)
    with pytest.raises(ValueError, match="max_cost, max_frequency"):
        choose(front, max_gain=1.0)
    with pytest.raises(ValueError, match="`minimise`"):
        choose(front, "order")
    with pytest.raises(ValueError, match="`max_cost`"):
        choose(front, max_cost="a lot")
    with pytest.raises(ValueError, match="`front` must be a ParetoIdentification"):
        choose(front.objectives)


def test_the_selection_rules_are_in_one_module(front):
    # The knee is front geometry (optim), re-exported beside the rules that
    # choose by bounds and by held-out fit.
    from spiralid.sysid.validation import selection

    assert knee_point is sid.optim.knee_point is selection.knee_point
    assert choose is sid.choose is selection.choose
    assert sid.choose_order is selection.choose_order
    assert front.knee == knee_point(front.objectives)
    assert not hasattr(front, "choose")


def _synthetic_front():
    # A known ARX(2, 2, 0) plant with a little equation noise (least squares
    # is then consistent); the "front" holds least-squares models of orders
    # 1..4 with their costs.
    rng = np.random.default_rng(0)
    u = rng.standard_normal(1500)
    e = 0.05 * rng.standard_normal(u.size)
    y = np.zeros_like(u)
    for t in range(2, u.size):
        y[t] = 1.5 * y[t - 1] - 0.7 * y[t - 2] + u[t] + 0.5 * u[t - 1] + e[t]
    est, val = sid.IOData(u, y, ts=0.01).split(2 / 3)
    models = [sid.identify(est, ARX(n, n, 0), method="ls") for n in (1, 2, 3, 4)]
    objectives = np.array([[m.cost, 2 * m.arx.na] for m in models])
    return SimpleNamespace(models=models, objectives=objectives), est, val


def test_choose_order_takes_the_lowest_order_that_fits_as_well():
    front, est, val = _synthetic_front()
    fits = sid.sysid.fits_by_order(front, val, warmup=est)
    by_hand = {
        2 * n: (i, sid.validate(front.models[i], val, warmup=est).fit_percent)
        for i, n in enumerate((1, 2, 3, 4))
    }
    assert fits == by_hand
    # ARX(1, 1) cannot follow a second-order plant; ARX(2, 2) is the plant.
    assert fits[2][1] < fits[4][1] - 10
    assert sid.choose_order(front, val, warmup=est) == 1
    # With no tolerance the best-fitting order wins, whichever it is.
    best = max(fits.values(), key=lambda pair: pair[1])[0]
    assert sid.choose_order(front, val, warmup=est, tolerance=0.0) == best
    with pytest.raises(ValueError, match="`tolerance`"):
        sid.choose_order(front, val, tolerance=-1.0)
