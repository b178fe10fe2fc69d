"""The learned-metric spiral's start from ``x0`` and its local restarts
(``first_sigma``, ``local_sigma``): a first population run centred at
``x0`` (its mirrored pairs symmetric about it), population restarts
alternating between the best point so far and a uniform centre, one
generator one run, every point in the box."""

import numpy as np
import pytest

from spiralid.optim import LearnedMetricSearch, LearnedMetricSpiral, Restarts, minimize


def _sphere_off_centre(x):
    return float(np.sum((x - 0.3) ** 2))


def _recorded(seen):
    def fun(x):
        seen.append(np.array(x, dtype=float))
        return _sphere_off_centre(x)

    return fun


def test_the_first_run_is_a_population_around_x0_mirrored_about_it():
    seen = []
    x0 = np.array([1.0, -2.0, 0.5, 2.0])
    rule = LearnedMetricSpiral(first_sigma=0.1)
    search = LearnedMetricSearch(_recorded(seen), [(-5, 5)] * 4, rule, rng=1, x0=x0)
    assert search.regime == "population" and search.nfev == 1
    assert np.array_equal(seen[0], x0)  # evaluated first, no uniform draw
    search.step()
    # 4 + floor(3 ln 4) = 8 points as CMA-ES's default, then their mean.
    points = np.array(seen[1:9])
    half = len(points) // 2
    # Mirrored pairs x0 + s and x0 - s: each pair's midpoint is x0.
    assert len(seen) == 10  # the start, 8 points, their weighted mean
    midpoints = (points[:half] + points[half:]) / 2
    np.testing.assert_allclose(midpoints, np.tile(x0, (half, 1)), atol=1e-12)
    # The steps are on the scale of sigma times the box's width (10).
    spread = np.abs(points - x0).max()
    assert 0.05 < spread < 5.0, spread


def test_local_restarts_alternate_the_best_point_and_a_uniform_centre():
    rule = LearnedMetricSpiral(local_sigma=0.05)
    search = LearnedMetricSearch(_sphere_off_centre, [(-5, 5)] * 3, rule, rng=4)
    starts = []  # (centre, best point before) of each population restart
    for _ in range(8):
        for _ in range(10):
            search.step()
        best = search.x
        search.restart(20)
        if search.regime == "population":
            starts.append((search.centre, best))
    assert len(starts) >= 3
    for k, (centre, best) in enumerate(starts):
        # The local first, then a uniform one, and so on.
        assert np.array_equal(centre, best) == (k % 2 == 0), k


@pytest.mark.parametrize(
    "rule", [{"first_sigma": 0.3}, {"first_sigma": 0.3, "local_sigma": 0.1}]
)
def test_one_generator_one_run_and_every_point_in_the_box(rule):
    def run():
        seen = []
        fun = _recorded(seen)
        res = minimize(
            fun,
            [(-1, 2)] * 3,
            LearnedMetricSpiral(**rule),
            x0=[1.5, 1.5, -1.0],
            max_nfev=600,
            rng=np.random.default_rng(7),
            restarts=Restarts(tol_radius=1e-2),
            options={"bounds_policy": "clip"},
        )
        return res, np.array(seen)

    (res, seen), (again, seen_again) = run(), run()
    assert np.array_equal(seen, seen_again) and res.fun == again.fun
    assert np.array_equal(seen[0], [1.5, 1.5, -1.0])
    assert seen.min() >= -1.0 and seen.max() <= 2.0
    assert res.nfev == len(seen) <= 600 and res.n_restarts >= 1
    assert res.fun < 1e-6  # the sphere's minimum, 0.3 in every coordinate


@pytest.mark.parametrize("name", ["first_sigma", "local_sigma"])
@pytest.mark.parametrize("value", [0.0, 1.5, "a"])
def test_bad_steps_are_named(name, value):
    with pytest.raises((TypeError, ValueError), match=f"`{name}`"):
        LearnedMetricSpiral(**{name: value})
