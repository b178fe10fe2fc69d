"""Tamura & Yasuda's periodic and convergent settings, restarts, scale-free Eb-SDA.

The conditions tested are those the settings state (IEEE Trans. SMC:
Systems, 2020): the rotation's form and period, the rank condition on the
initial points, ``r = delta^(1/k_max)``, and ``r(k) = 1`` exactly while
``k <= k* + 2n - 1``.
"""

import math

import numpy as np
import pytest

from spiralid.optim import (
    RULES,
    ConvergentSpiral,
    ExponentialSpiral,
    PeriodicSpiral,
    Restarts,
    SpiralSearch,
    StepRateRule,
    descent_rotation,
    minimize,
    rank_condition,
)
from spiralid.optim.testfunctions import PROBLEMS, rastrigin, rosenbrock


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8])
def test_descent_rotation_is_orthogonal_with_period_2n(n):
    R = descent_rotation(n)
    eye = np.eye(n)
    np.testing.assert_array_equal(R @ R.T, eye)
    np.testing.assert_array_equal(np.linalg.matrix_power(R, n), -eye)
    np.testing.assert_array_equal(np.linalg.matrix_power(R, 2 * n), eye)
    # The printed form [[0^T, -1], [I_(n-1), 0]].
    expected = np.zeros((n, n))
    expected[0, -1] = -1.0
    expected[1:, :-1] = np.eye(n - 1)
    np.testing.assert_array_equal(R, expected)


@pytest.mark.parametrize("n", [2, 3, 6])
def test_rank_condition_holds_for_uniform_points(n):
    rng = np.random.default_rng(n)
    for _ in range(20):
        assert rank_condition(rng.uniform(-1, 1, size=(4, n)))


def test_rank_condition_fails_on_an_invariant_subspace():
    # (1, -1, 1) is R's eigenvector for -1 in 3-D: its spiral vectors span a line.
    d = np.array([1.0, -1.0, 1.0])
    assert not rank_condition(np.array([np.zeros(3), d, 2.5 * d]))
    # Any third point off that line restores it for every choice of centre.
    assert rank_condition(np.array([np.zeros(3), d, [0.3, 0.1, 0.2]]))
    # Nor does the invariant plane orthogonal to it help: rank 2 at most.
    assert not rank_condition(np.array([np.zeros(3), d, [0.3, 0.1, -0.2]]))


@pytest.mark.parametrize("n", [2, 3, 5])
def test_2n_spiral_directions_include_a_descent_direction(n):
    # What the rank condition buys: for any gradient g, some R^k d descends.
    rng = np.random.default_rng(10 + n)
    R = descent_rotation(n)
    for _ in range(200):
        d, g = rng.normal(size=n), rng.normal(size=n)
        directions = [np.linalg.matrix_power(R, k) @ d for k in range(2 * n)]
        assert min(g @ v for v in directions) < 0.0


@pytest.mark.parametrize(("k_max", "delta"), [(1, 0.5), (37, 1e-3), (500, 1e-6)])
def test_periodic_rate_contracts_by_delta_over_k_max(k_max, delta):
    rule = PeriodicSpiral(delta=delta)
    r = rule.step_rate(0, 0, 3, k_max)
    assert r == rule.step_rate(k_max - 1, 5, 3, k_max)  # constant
    assert math.isclose(r**k_max, delta, rel_tol=1e-12)


def test_periodic_schedule_spans_the_evaluation_budget():
    # 20 points, 1000 evaluations: (1000 - 20) // 19 = 51 iterations.
    res = minimize(
        rosenbrock,
        [(-2, 2)] * 3,
        "periodic",
        n_points=20,
        max_nfev=1000,
        rng=0,
        vectorized=True,
    )
    assert res.nit == 51
    assert np.all(res.mean_radius == res.mean_radius[0])
    assert math.isclose(res.mean_radius[0] ** 51, 1e-3, rel_tol=1e-12)
    assert np.all(np.isnan(res.mean_angle))


def test_periodic_offsets_shrink_exactly_by_the_rate_while_the_centre_stays():
    search = SpiralSearch(
        lambda x: float(x @ x),
        [(-1, 1)] * 4,
        "periodic",
        n_points=6,
        rng=1,
        max_iter=50,
    )
    R = descent_rotation(4)
    r = 1e-3 ** (1 / 50)
    for _ in range(50):
        before = search.population
        search.step()
        after = search.population
        if np.array_equal(after[0], before[0]):
            moved = after[1:] - after[0]
            expected = r * (before[1:] - before[0]) @ R.T
            # Rows may be reordered only when the centre changes.
            np.testing.assert_allclose(moved, expected, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("n", [1, 2, 4])
def test_convergent_rate_is_one_for_2n_iterations_after_a_centre_move(n):
    rule = ConvergentSpiral(h=0.3)
    for k_star in (0, 7):
        rates = [
            rule.step_rate(k, k_star, n, 100) for k in range(k_star, k_star + 3 * n)
        ]
        assert rates[: 2 * n] == [1.0] * (2 * n)
        assert rates[2 * n :] == [0.3] * n
    default = ConvergentSpiral(delta=1e-3).step_rate(10 * n, 0, n, 200)
    assert math.isclose(default, 1e-3 ** (1 / 200), rel_tol=1e-15)


def test_convergent_run_follows_its_rule_from_the_centre_updates():
    n = 3
    res = minimize(
        rastrigin,
        [(-5.12, 5.12)] * n,
        ConvergentSpiral(h=0.5),
        n_points=8,
        max_iter=300,
        rng=2,
        vectorized=True,
    )
    # k* from the record: the iterations after which the best cost fell.
    k_star = 0
    for k in range(res.nit):
        expected = 1.0 if k <= k_star + 2 * n - 1 else 0.5
        assert res.mean_radius[k] == expected, k
        if res.history[k + 1] < res.history[k]:
            k_star = k + 1
    assert 0.5 in res.mean_radius and 1.0 in res.mean_radius


def _rosenbrock_gradient(x):
    g = np.zeros_like(x)
    g[:-1] = -400.0 * x[:-1] * (x[1:] - x[:-1] ** 2) - 2.0 * (1.0 - x[:-1])
    g[1:] += 200.0 * (x[1:] - x[:-1] ** 2)
    return g


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_convergence_setting_reaches_a_stationary_point_of_rosenbrock(seed):
    # The guarantee: the centre approaches a stationary point. Stated
    # tolerance: |grad f(x*)| <= 1e-8 within 20,000 iterations of 10 points.
    res = minimize(
        rosenbrock,
        [(-2, 2)] * 2,
        ConvergentSpiral(h=0.5),
        n_points=10,
        max_iter=20_000,
        rng=seed,
        vectorized=True,
    )
    assert np.linalg.norm(_rosenbrock_gradient(res.x)) <= 1e-8
    np.testing.assert_allclose(res.x, [1.0, 1.0], atol=1e-8)


def test_convergence_setting_reaches_a_stationary_point_of_a_rotated_quadratic():
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    H = q @ np.diag([1.0, 30.0, 900.0]) @ q.T
    x_opt = np.array([0.3, -0.7, 0.1])

    def quadratic(x):
        d = x - x_opt
        return 0.5 * float(d @ H @ d)

    res = minimize(
        quadratic,
        [(-1, 1)] * 3,
        ConvergentSpiral(h=0.5),
        n_points=6,
        max_iter=5000,
        rng=0,
    )
    assert np.linalg.norm(H @ (res.x - x_opt)) <= 1e-8


def test_step_rate_rules_need_an_iteration_budget():
    with pytest.raises(
        ValueError, match=r"`max_iter` \(the iteration budget k_max\) is required"
    ):
        SpiralSearch(lambda x: 0.0, [(0, 1)], "periodic")


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: PeriodicSpiral(delta=1.0), r"^`delta` must be in \(0, 1\); got 1.0"),
        (lambda: ConvergentSpiral(h=0.0), r"^`h` must be in \(0, 1\); got 0.0"),
        (lambda: Restarts(growth=0.5), r"^`growth` must be >= 1"),
        (lambda: Restarts(stall=0), r"^`stall` must be an integer >= 1"),
        (
            lambda: ExponentialSpiral(scale_free="yes"),
            r"^`scale_free` must be True or False",
        ),
        (
            lambda: minimize(lambda x: 0.0, [(0, 1)], restarts="yes"),
            r"^`restarts` must be",
        ),
        (lambda: rank_condition(np.zeros(3)), r"^`points` must have shape \(m, n\)"),
    ],
)
def test_bad_settings(make, match):
    with pytest.raises((TypeError, ValueError), match=match):
        make()


class _Doubling(StepRateRule):
    def step_rate(self, k, k_star, n, k_max):
        return 2.0


class _Flat(StepRateRule):
    def rotation(self, n):
        return np.eye(n + 1)

    def step_rate(self, k, k_star, n, k_max):
        return 0.5


def test_custom_step_rate_rules_are_checked():
    with pytest.raises(
        ValueError, match=r"step_rate must return a number in \(0, 1\]; got 2.0"
    ):
        minimize(lambda x: 0.0, [(0, 1)] * 2, _Doubling(), max_iter=3)
    with pytest.raises(ValueError, match=r"rotation must be a finite \(2, 2\) matrix"):
        minimize(lambda x: 0.0, [(0, 1)] * 2, _Flat(), max_iter=3)


@pytest.mark.parametrize("scale", [2.0**-3, 2.0**4])
def test_scale_free_ebsda_ignores_the_cost_scale(scale):
    # Powers of two scale every cost exactly, so the searches match bit for bit.
    p = PROBLEMS["rastrigin"]
    kw = dict(n_points=20, max_iter=100, rng=4, vectorized=True)
    base = minimize(p.fun, p.bounds(4), "ebsda-scaled", **kw)
    scaled = minimize(lambda x: scale * p.fun(x), p.bounds(4), "ebsda-scaled", **kw)
    np.testing.assert_array_equal(base.x, scaled.x)
    np.testing.assert_array_equal(base.mean_radius, scaled.mean_radius)
    # The paper's rule does depend on the scale: the test can tell them apart.
    paper = minimize(p.fun, p.bounds(4), "ebsda", **kw)
    paper_scaled = minimize(lambda x: scale * p.fun(x), p.bounds(4), "ebsda", **kw)
    assert not np.array_equal(paper.mean_radius, paper_scaled.mean_radius)


def test_scale_free_deviations_are_relative_to_the_cost_spread():
    rule, paper = ExponentialSpiral(scale_free=True), ExponentialSpiral()
    d = np.array([0.5, 2.0, np.inf, 4.0])
    r, theta = rule(d, np.random.default_rng(0))
    r_ref, theta_ref = paper(d / 4.0, np.random.default_rng(0))
    np.testing.assert_array_equal(r, r_ref)
    np.testing.assert_array_equal(theta, theta_ref)


def test_restarts_collapse_criteria():
    rs = Restarts(tol_radius=1e-6, stall=5)
    assert rs.collapsed(np.full((3, 2), 1e-7), 10.0, 0)  # radius 1e-7 <= 1e-5
    assert not rs.collapsed(np.full((3, 2), 1e-4), 10.0, 4)
    assert rs.collapsed(np.full((3, 2), 1e-4), 10.0, 5)  # stalled
    assert Restarts().next_size(7) == 14 and Restarts(growth=1.5).next_size(7) == 11


@pytest.mark.parametrize("method", list(RULES))
def test_restarts_grow_the_population_within_the_budget(method):
    p = PROBLEMS["rastrigin"]
    sizes = []
    res = minimize(
        p.fun,
        p.bounds(3),
        method,
        n_points=10,
        max_nfev=6000,
        rng=5,
        vectorized=True,
        restarts=Restarts(stall=15),
        callback=lambda r: sizes.append(None),
    )
    assert res.n_restarts >= 1
    assert res.nfev <= 6000
    assert res.history.shape == (res.nit + res.n_restarts + 1,)
    assert np.all(np.diff(res.history) <= 0.0)
    assert res.fun == res.history[-1] == float(p.fun(res.x))
    assert len(sizes) == res.nit


def test_restarts_keep_the_best_of_all_runs_and_are_reproducible():
    p = PROBLEMS["rastrigin"]
    kw = dict(n_points=8, max_nfev=4000, vectorized=True, restarts=Restarts(stall=10))
    a = minimize(p.fun, p.bounds(2), "sda", rng=6, **kw)
    b = minimize(p.fun, p.bounds(2), "sda", rng=6, **kw)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.history, b.history)
    # nfev adds each run's population: 8, then 16, 32, ... per restart.
    sizes = [8 * 2**j for j in range(a.n_restarts + 1)]
    assert a.nfev >= sum(sizes)


def test_restarts_off_by_default():
    p = PROBLEMS["rastrigin"]
    kw = dict(n_points=8, max_nfev=4000, vectorized=True, rng=7)
    a = minimize(p.fun, p.bounds(2), "sda", **kw)
    b = minimize(p.fun, p.bounds(2), "sda", restarts=False, **kw)
    assert a.n_restarts == b.n_restarts == 0
    np.testing.assert_array_equal(a.history, b.history)
