"""NARX training on subsequences: the stretches' residual against a
hand-rolled recursion, its Jacobian against finite differences, the
held-back blocks, the curriculum, the linear-start guarantee and the
refusals."""

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import NARX, IOData, identify
from spiralid.sysid.estimation.narx.problem import NARXProblem, _interleaved
from spiralid.sysid.estimation.narx.starts import _starts
from spiralid.sysid.estimation.narx.subsequences import (
    HORIZONS,
    curriculum,
    subsequence_residual,
    subsequence_starts,
    train_stages,
)


def _record(n=300, seed=0, noise=0.05):
    # A NARX system: a saturating input into a first-order lag.
    rng = np.random.default_rng(seed)
    u = 1.5 * rng.standard_normal(n)
    y = lfilter([0.0, 1.0], [1.0, -0.7], np.tanh(1.5 * u))
    return IOData(u, y + noise * rng.standard_normal(n), ts=0.1)


def _problem(st, data, holdout=0.2, blocks=1):
    return NARXProblem(
        data, st, "simulation", "rest", holdout, np.random.default_rng(1), blocks
    )


def _fd(f, p, eps=1e-6):
    return np.array(
        [(f(p + eps * e) - f(p - eps * e)) / (2 * eps) for e in np.eye(p.size)]
    ).T


def test_starts_are_half_a_horizon_apart_and_the_last_ends_at_the_stop():
    np.testing.assert_array_equal(subsequence_starts(2, 20, 8), [2, 6, 10, 12])
    np.testing.assert_array_equal(subsequence_starts(0, 10, 10), [0])
    np.testing.assert_array_equal(subsequence_starts(3, 8, 2), [3, 4, 5, 6])


def test_held_back_blocks_share_and_disjointness():
    train, hold = _interleaved(4, 1004, 0.2, 10)
    assert np.intersect1d(train, hold).size == 0
    assert train.size + hold.size == 1000
    assert hold.size == 200
    # Ten blocks: the held-back indices break into ten runs, the last at the end.
    assert np.count_nonzero(np.diff(hold) > 1) == 9 and hold[-1] == 1003


def test_curriculum_stops_at_the_training_part():
    # The free run of the training part (None) ends the curriculum.
    assert curriculum(None, 2, 1024) == (*HORIZONS, None)
    assert curriculum(None, 2, 62) == (10, 30, None)
    assert curriculum(50, 2, 1024) == (50,)
    assert curriculum(5000, 2, 1024) == (1022,)


@pytest.mark.parametrize("integrator", [0, 1])
def test_residual_is_each_stretch_run_from_its_measured_history(integrator):
    data = _record(120)
    if integrator:
        data = IOData(data.u, np.cumsum(data.y), ts=data.ts)
    st = NARX(2, 2, 1, hidden=(3,), integrator=integrator)
    pr = _problem(st, data, holdout=0.2, blocks=3)
    p = 0.3 * np.random.default_rng(2).standard_normal(st.n_params)
    horizon = 12
    fun, jac, m = subsequence_residual(pr, horizon)
    r = fun(p)
    assert r.size == m
    # The same stretches by a plain recursion of the map, one step at a time.
    held = np.zeros(data.n, dtype=bool)
    held[pr.hold] = True
    s = pr.scaling
    back = st.ny + integrator
    expected = []
    for t in subsequence_starts(st.max_lag, int(np.flatnonzero(~held)[-1]) + 1, 12):
        if held[t - back : t].any():
            continue
        past = list(pr.target[t - st.ny : t])
        level = data.y[t - 1] / s.y_scale
        for k in range(horizon):
            phi = np.r_[past[::-1][: st.ny], pr.ulag[t + k]]
            z = float(st.evaluate(p, phi[None, :])[0])
            past.append(z)
            past = past[1:]
            if integrator:
                level += z
                pred, meas = level, data.y[t + k] / s.y_scale
            else:
                pred, meas = z, pr.target[t + k]
            if not held[t + k]:
                expected.append(meas - pred)
    np.testing.assert_allclose(r, expected, atol=1e-10)
    np.testing.assert_allclose(jac(p), _fd(fun, p), atol=1e-6)


def test_training_never_ends_above_its_start_on_the_held_back_blocks():
    # A large network on a short noisy record: training overfits, and the
    # held-back blocks must keep the start whenever it scores lower there.
    data = _record(160, seed=4, noise=0.3)
    st = NARX(3, 3, 1, hidden=(12,))
    pr = _problem(st, data, holdout=0.2, blocks=10)
    pr.decay = 0.0
    start, _, _, _ = _starts(pr)
    options = dict(max_rounds=20, patience=3, patience_share=0.0)
    p, schedule = train_stages(pr, start, "simulation", (10, 30, 100), options)
    assert [h for h, _ in schedule] == [10, 30, 100]
    assert pr._score(p, "simulation", 1) <= pr._score(start, "simulation", 1)


def test_identify_trains_on_subsequences_and_beats_its_linear_start():
    data = _record(400, seed=5, noise=0.02)
    model = identify(
        data, NARX(2, 2, 1, hidden=(4,)), method="oe", training="subsequences", rng=0
    )
    res = model.result
    assert res.fun <= res.linear_cost
    # The nonlinear record: the network has something to learn.
    assert res.fun < 0.9 * res.linear_cost
    again = identify(
        data, NARX(2, 2, 1, hidden=(4,)), method="oe", training="subsequences", rng=0
    )
    np.testing.assert_array_equal(model.params, again.params)


def test_cascaded_tanks_training_keeps_to_its_linear_start_or_below():
    from spiralid.datasets import cascaded_tanks

    est = cascaded_tanks().detrend()
    model = identify(
        est, NARX(2, 2, 1, hidden=(4,)), method="oe", training="subsequences", rng=0
    )
    assert model.result.fun <= model.result.linear_cost


@pytest.mark.parametrize(
    ("options", "name"),
    [
        (dict(training="sub"), "training"),
        (dict(training="subsequences", horizon=1), "horizon"),
        (dict(training="subsequences", horizon=True), "horizon"),
        (dict(training="subsequences", horizon=2.5), "horizon"),
        (dict(horizon=20), "horizon"),
        (dict(training="subsequences", predictor="one-step"), "training"),
    ],
)
def test_bad_training_options_are_refused_in_one_line(options, name):
    with pytest.raises(ValueError, match=f"`{name}`"):
        identify(_record(100), NARX(2, 2, 1, hidden=(2,)), method="oe", **options)


@pytest.mark.parametrize(
    "options",
    [
        dict(method="oe", horizon=25),
        dict(method="oe", holdout=0.0),
        dict(method="spiral", max_nfev=300, n_points=10),
    ],
)
def test_every_method_and_split_trains_on_subsequences(options):
    data = _record(300, seed=6, noise=0.02)
    model = identify(
        data, NARX(2, 2, 1, hidden=(3,)), training="subsequences", rng=0, **options
    )
    res = model.result
    assert res.fun <= res.linear_cost
    assert res.fun < 0.5 * res.linear_cost
