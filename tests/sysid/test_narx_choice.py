"""choose_narx: a spiral search over a NARX's lags, hidden units and decay,
each point a gradient training scored on the held-back end."""

import re

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.sysid.estimation.narx.choice import choose_narx, round_choice

BOX = dict(lags=(1, 3), hidden=(1, 2), log_decay=(-3.0, -3.0))


@pytest.fixture(scope="module")
def second_order():
    """A second-order system behind a mild saturation: one past output
    cannot hold its two poles, two can."""
    rng = np.random.default_rng(3)
    u = rng.standard_normal(500)
    y = lfilter([0.0, 0.4], [1.0, -1.5, 0.7], u)
    return sid.IOData(u, np.tanh(0.5 * y), ts=0.01)


@pytest.fixture(scope="module")
def chosen(second_order):
    return choose_narx(second_order, **BOX, budget=6, n_points=4, rng=0)


@pytest.mark.parametrize(
    ("x", "expected"),
    [
        # Worked by hand: nearest integer, the decay in half decades.
        ([2.6, 7.4, -5.6], (3, 7, -3.0)),
        ([2.4, 7.6, -5.4], (2, 8, -2.5)),
        # Kept in the ranges (lags 1-8, hidden 1-16, decay 1e-5 to 1e-1).
        ([-3.0, 40.0, -30.0], (1, 16, -5.0)),
        ([9.4, 0.0, 0.4], (8, 1, -1.0)),
    ],
)
def test_a_point_rounds_to_the_nearest_choice_in_range(x, expected):
    assert round_choice(x, (1, 8), (1, 16), (-5.0, -1.0)) == expected


def test_a_decay_range_off_the_half_decades_rounds_inwards():
    # log10 decay in [-4.2, -2.7]: the half decades inside are -4, -3.5, -3.
    assert round_choice([1, 1, -9.0], (1, 2), (1, 2), (-4.2, -2.7))[2] == -4.0
    assert round_choice([1, 1, -5.0], (1, 2), (1, 2), (-4.2, -2.7))[2] == -3.0


def test_the_choice_holds_the_system_s_two_poles(second_order, chosen):
    n, _, d = chosen.x
    assert n >= 2
    assert d == -3.0

    # The free run of the refitted model on the whole record, against the
    # linear model of the system's order fitted by output error on its own:
    # the network contains that model, so it may add to it (91-93 % on seeds
    # 0, 2 and 3) or add nothing (86.4 %, its fit, on seeds 1 and 4-7), never
    # lose to it. An absolute bar of 90 % held on half the seeds only.
    def fit(model):
        y = second_order.y
        e = y - model.simulate(second_order.u)
        return 100 * (1 - np.linalg.norm(e) / np.linalg.norm(y - y.mean()))

    linear = sid.sysid.identify(second_order, sid.ARX(2, 2, 1), method="oe", rng=0)
    assert fit(linear) < 90.0  # the saturation is out of a linear model's reach
    assert fit(chosen.model) >= fit(linear) - 0.05


def test_one_lag_scores_below_two_on_the_held_back_end(chosen):
    fits = {(n, h): f for n, h, _, f in chosen.trials}
    ones = [f for (n, _), f in fits.items() if n == 1]
    more = [f for (n, _), f in fits.items() if n >= 2]
    assert ones and more
    assert max(ones) < max(more) - 5.0


def test_the_best_trial_is_chosen_and_refitted_on_the_whole_record(chosen):
    best = max(chosen.trials, key=lambda t: t[3])
    assert tuple(chosen.x) == best[:3]
    assert chosen.fit == best[3] and chosen.fun == pytest.approx(100 - best[3])
    n, h = int(chosen.x[0]), int(chosen.x[1])
    assert chosen.structure == sid.NARX(n, n, 1, hidden=(h,))
    assert chosen.model.structure == chosen.structure
    assert chosen.decay == pytest.approx(1e-3)


def test_the_budget_counts_trainings_not_search_calls(second_order, chosen):
    keys = [t[:3] for t in chosen.trials]
    assert len(keys) == len(set(keys)) == chosen.nfev <= 6
    few = choose_narx(second_order, **BOX, budget=2, n_points=2, rng=1)
    assert few.nfev == 2 and "budget of 2" in few.message


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        (dict(lags=(3, 1)), "lags"),
        (dict(hidden=4), "hidden"),
        (dict(hidden=(0, 2)), "hidden[0]"),
        (dict(log_decay=(-2.9, -2.6)), "log_decay"),
        (dict(budget=0), "budget"),
        (dict(holdback=0.0), "holdback"),
        (dict(holdback=0.7), "holdback"),
        (dict(nk=-1), "nk"),
        (dict(horizons=()), "horizons"),
        (dict(horizons=(20, 1)), "horizons[1]"),
    ],
)
def test_bad_arguments_are_refused_by_name(second_order, kwargs, name):
    with pytest.raises(ValueError, match=re.escape(f"`{name}`")):
        choose_narx(second_order, **kwargs)


def test_data_must_be_a_record():
    with pytest.raises(TypeError, match="`data` must be an IOData"):
        choose_narx(np.zeros(10))


def test_the_horizon_is_searched_with_training_on_subsequences(second_order):
    from spiralid.sysid.estimation.core.choices import held_back_fit as _held_back_fit

    res = choose_narx(
        second_order, **BOX, horizons=(10, 40), budget=4, n_points=3, rng=0
    )
    assert res.horizon in (10, 40) and res.x[3] == res.horizon
    assert all(len(t) == 5 and t[3] in (10, 40) for t in res.trials)
    # The best trial is the choice, refitted on the whole record, where it
    # is never above its linear start.
    assert res.fit == max(t[4] for t in res.trials)
    assert res.model.structure == res.structure
    assert res.model.result.linear_cost >= res.model.result.fun
    assert np.isfinite(
        _held_back_fit(second_order.y, res.model.simulate(second_order.u))
    )
