"""choose_state_space: a spiral search over a neural state space's order,
hidden units, encoder window and decay, each point a training scored on the
held-back end of the estimation record."""

import re

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.sysid import IOData, NeuralStateSpace, choose_state_space, fit_percent
from spiralid.sysid.estimation.core.choices import nearest
from spiralid.sysid.estimation.core.identify import identify
from spiralid.sysid.estimation.state_space import choice as nss_choice

# Small and fast: one fixed subsequence length (no growing stages).
BOX = dict(
    order=(1, 3), hidden=(1, 2), window=(2, 4), log_decay=(-3.0, -2.0), horizons=(40,)
)


@pytest.fixture(scope="module")
def record():
    """A second-order system behind a saturation, 200 samples."""
    rng = np.random.default_rng(3)
    u = rng.standard_normal(200)
    y = lfilter([0.0, 0.4], [1.0, -1.5, 0.7], u)
    return IOData(u, np.tanh(0.5 * y), ts=0.01)


@pytest.fixture(scope="module")
def recorded(record):
    """The search with every training it ran kept (record length,
    structure, options, model)."""
    trained = []

    def recording(data, structure, **options):
        model = identify(data, structure, **options)
        trained.append((data.n, structure, options, model))
        return model

    mp = pytest.MonkeyPatch()
    mp.setattr(nss_choice, "identify", recording)
    try:
        res = choose_state_space(record, **BOX, budget=3, n_points=3, rng=0)
    finally:
        mp.undo()
    return res, trained


def test_the_chosen_candidate_has_the_best_held_back_fit(record, recorded):
    res, trained = recorded
    *search, (n_all, refit_st, refit_options, refit) = trained
    assert len(search) == res.nfev == len(res.trials) <= 3
    # Re-scored here by fit_percent on the last quarter (150 of 200 samples
    # trained), from each candidate's own free run from rest.
    split = 150
    rescored = [
        fit_percent(record.y[split:], m.simulate(record.u)[split:])
        for n, _, _, m in search
    ]
    assert all(n == split for n, *_ in search)
    for (*_, f), g in zip(res.trials, rescored, strict=True):
        assert f == pytest.approx(g, abs=1e-9)
    best = int(np.argmax(rescored))
    assert res.fit == pytest.approx(rescored[best], abs=1e-9)
    assert res.fun == pytest.approx(100 - res.fit)
    # The choice is that candidate, trained again on the whole record.
    st, options = search[best][1], search[best][2]
    assert n_all == record.n and refit is res.model
    assert refit_st == st == res.structure == res.model.structure
    assert refit_options["decay"] == options["decay"] == pytest.approx(res.decay)
    assert refit_options["horizon"] == options["horizon"] == res.horizon == 40
    n, h, w, d, horizon = res.x
    assert st == NeuralStateSpace(int(n), hidden=(int(h),), window=int(w))
    assert res.decay == pytest.approx(10.0**d) and horizon == 40


def test_every_trial_is_in_its_ranges(recorded):
    res, trained = recorded
    keys = [t[:5] for t in res.trials]
    assert len(set(keys)) == len(keys)
    for (n, h, w, d, horizon, _), (_, st, options, _) in zip(
        res.trials, trained, strict=False
    ):
        assert 1 <= n <= 3 and 1 <= h <= 3
        # The window is the point's, raised to the order when below it.
        assert max(2, n) <= w <= max(4, n)
        assert d in (-3.0, -2.5, -2.0) and horizon == 40
        assert st == NeuralStateSpace(n, hidden=(h,), window=w)
        assert options["decay"] == pytest.approx(10.0**d)


def test_the_choice_is_reproducible_with_one_rng(record):
    a, b = (
        choose_state_space(record, **BOX, budget=2, n_points=2, rng=5) for _ in range(2)
    )
    assert a.trials == b.trials
    assert np.array_equal(a.x, b.x)
    assert np.array_equal(a.model.params, b.model.params)
    assert a.nfev == 2 and "budget of 2" in a.message


def test_points_round_to_the_nearest_grid_point_in_range():
    # Worked by hand: nearest integer, then clipped into its range.
    assert nearest([2.6, 7.4, -5.6], [(1, 8), (1, 16), (-10, -2)]) == (3, 7, -6)
    assert nearest([-3.0, 40.0, 0.4], [(1, 8), (1, 16), (-10, -2)]) == (1, 16, -2)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        (dict(order=(3, 1)), "order"),
        (dict(order=()), "order"),
        (dict(hidden=4), "hidden"),
        (dict(hidden=(0, 2)), "hidden[0]"),
        (dict(window=(5, 2)), "window"),
        (dict(order=(4, 6), window=(1, 3)), "window"),
        (dict(log_decay=(-2.9, -2.6)), "log_decay"),
        (dict(budget=0), "budget"),
        (dict(n_points=1), "n_points"),
        (dict(holdback=0.0), "holdback"),
        (dict(holdback=0.7), "holdback"),
        (dict(horizons=()), "horizons"),
        (dict(horizons=(20, 1)), "horizons[1]"),
        # Order 60 needs a window of 60: 4 x 60 + 10 = 250 samples, and 150
        # come before the held-back quarter.
        (dict(order=(1, 60)), "data"),
    ],
)
def test_bad_arguments_are_refused_by_name_in_one_line(record, kwargs, name):
    with pytest.raises(ValueError, match=re.escape(f"`{name}`")) as err:
        choose_state_space(record, **kwargs)
    assert "\n" not in str(err.value)


def test_an_order_too_large_for_the_record_says_what_to_change(record):
    with pytest.raises(ValueError) as err:
        choose_state_space(record, order=(1, 60), window=(2, 5))
    message = str(err.value)
    assert "at least 250 samples" in message and "got 150" in message
    assert "largest choice of `order` and `window`" in message


def test_data_must_be_a_record():
    with pytest.raises(TypeError, match="`data` must be an IOData"):
        choose_state_space(np.zeros(10))


def test_it_is_exported_with_choose_narx():
    assert sid.sysid.choose_state_space is choose_state_space
    assert "choose_state_space" in sid.sysid.__all__


def test_judged_on_its_own_blocks_the_best_trained_candidate_is_returned(
    record, monkeypatch
):
    trained = []

    def recording(data, structure, **options):
        model = identify(data, structure, **options)
        trained.append((data.n, options["holdout"], model))
        return model

    monkeypatch.setattr(nss_choice, "identify", recording)
    res = choose_state_space(
        record, **BOX, holdback="blocks", budget=2, n_points=2, rng=1
    )
    # Every training on the whole record, none after the search.
    assert [(n, share) for n, share, _ in trained] == [(200, 0.2)] * res.nfev
    # The held-back blocks worked by hand: a fifth of 200 samples in 10
    # blocks of 4, each centred on the middle of a tenth of the record.
    held = np.zeros(200, dtype=bool)
    for i in range(10):
        held[20 * i + 8 : 20 * i + 12] = True
    fits = [
        fit_percent(record.y[held], m.simulate(record.u)[held]) for *_, m in trained
    ]
    for (*_, f), g in zip(res.trials, fits, strict=True):
        assert f == pytest.approx(g, abs=1e-9)
    assert res.model is trained[int(np.argmax(fits))][2]
    assert res.fit == pytest.approx(max(fits), abs=1e-9)


def test_a_holdback_neither_a_share_nor_blocks_is_refused_by_name(record):
    with pytest.raises((TypeError, ValueError), match="`holdback`"):
        choose_state_space(record, **BOX, holdback="end")
