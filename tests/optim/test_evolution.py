"""The differential-evolution baseline against SciPy's own and known optima."""

import numpy as np
import pytest
from scipy import optimize

from spiralid.optim import differential_evolution
from spiralid.optim.testfunctions import rastrigin, sphere


def test_finds_the_sphere_minimum_within_budget():
    res = differential_evolution(sphere, [(-5, 5)] * 3, max_nfev=6000, rng=0)
    assert res.fun < 1e-6
    np.testing.assert_allclose(res.x, 0.0, atol=1e-3)
    assert res.nfev <= 6000 and res.nfev == 50 * (res.nit + 1)


def test_same_search_as_scipy_for_the_same_population_and_generator():
    box = np.array([[-5.12, 5.12]] * 4)
    init = np.random.default_rng(1).uniform(box[:, 0], box[:, 1], size=(20, 4))
    ours = differential_evolution(
        rastrigin, box, n_points=20, max_iter=30, x0=init, rng=np.random.default_rng(2)
    )
    ref = optimize.differential_evolution(
        lambda x: rastrigin(x.T),
        box,
        maxiter=30,
        init=init,
        rng=np.random.default_rng(2),
        polish=False,
        tol=0.0,
        atol=0.0,
        updating="deferred",
        vectorized=True,
    )
    np.testing.assert_array_equal(ours.x, ref.x)
    assert ours.fun == ref.fun


def test_history_is_monotone_and_starts_at_the_initial_population():
    init = np.full((10, 2), 3.0)
    res = differential_evolution(
        sphere, [(-5, 5)] * 2, n_points=10, max_iter=20, x0=init, rng=0
    )
    assert res.history[0] == pytest.approx(18.0)
    assert np.all(np.diff(res.history) <= 0)
    assert res.history.size == res.nit + 1


def test_callback_stops_the_search_and_seeds_reproduce():
    calls = []
    res = differential_evolution(
        sphere, [(-1, 1)] * 2, callback=lambda r: calls.append(r.fun) or True, rng=0
    )
    assert len(calls) == 1 and res.nit == 1
    a = differential_evolution(sphere, [(-1, 1)] * 2, max_iter=5, rng=7)
    b = differential_evolution(sphere, [(-1, 1)] * 2, max_iter=5, rng=7)
    np.testing.assert_array_equal(a.x, b.x)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"bounds": [(1, 0)]}, "`bounds`"),
        ({"bounds": [(0, np.nan)]}, "`bounds`"),
        ({"n_points": 4}, "`n_points`"),
        ({"max_nfev": 60}, "`max_nfev`"),
        ({"x0": np.zeros((3, 3))}, "`x0`"),
        ({"x0": np.full((1, 2), 9.0)}, "`x0`"),
        ({"rng": "seed"}, "`rng`"),
        ({"callback": 3}, "`callback`"),
    ],
)
def test_bad_input(kwargs, match):
    args = {"bounds": [(-1, 1)] * 2, **kwargs}
    with pytest.raises((TypeError, ValueError), match=match):
        differential_evolution(sphere, **args)
