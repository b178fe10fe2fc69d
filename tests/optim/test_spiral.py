"""The search loop, checked against hand-built steps and independent bookkeeping."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import Bounds

from spiralid.optim import (
    ConstantSpiral,
    ExponentialSpiral,
    OptimiserResult,
    SpiralRule,
    SpiralSearch,
    minimize,
    rotation_matrix,
)


def sphere(x):
    x = np.asarray(x)
    return np.sum(x * x, axis=-1)


class Recorder:
    """Wraps an objective and keeps every batch it was given."""

    def __init__(self, fun, vectorized=True):
        self.fun = fun
        self.vectorized = vectorized
        self.batches = []
        self.costs = []

    def __call__(self, x):
        x = np.array(x)
        self.batches.append(x if self.vectorized else x[None, :])
        out = self.fun(x)
        self.costs.append(np.atleast_1d(np.asarray(out, dtype=float)))
        return out

    @property
    def count(self):
        return sum(len(b) for b in self.batches)


class RecordingRule(SpiralRule):
    def __init__(self, inner):
        self.inner = inner
        self.calls = []

    def __call__(self, d, rng):
        r, theta = self.inner(d, rng)
        self.calls.append((np.array(d), r, theta))
        return r, theta


@pytest.mark.parametrize("radius", [0.95, 0.3, 1.0])
def test_sda_step_shrinks_every_distance_by_r(radius):
    rec = Recorder(sphere)
    search = SpiralSearch(
        rec,
        [(-3, 3)] * 5,
        ConstantSpiral(radius, 0.8),
        n_points=12,
        rng=1,
        vectorized=True,
    )
    before = search.population
    centre = before[0]
    search.step()
    moved = rec.batches[-1]
    ratio = np.linalg.norm(moved - centre, axis=1) / np.linalg.norm(
        before[1:] - centre, axis=1
    )
    np.testing.assert_allclose(ratio, radius, rtol=1e-12, atol=0)
    expected = centre + radius * (before[1:] - centre) @ rotation_matrix(5, 0.8).T
    np.testing.assert_allclose(moved, expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("n", [2, 7, 16])
def test_ebsda_step_matches_dense_per_point_update(n):
    rule = RecordingRule(ExponentialSpiral())
    rec = Recorder(lambda X: 0.05 * sphere(X))
    search = SpiralSearch(rec, [(-2, 2)] * n, rule, n_points=15, rng=4, vectorized=True)
    for _ in range(3):
        before, costs = search.population, search.costs
        search.step()
        d, r, theta = rule.calls[-1]
        np.testing.assert_allclose(d, costs[1:] - costs[0], rtol=1e-15)
        positive = d > 0
        np.testing.assert_array_equal(
            r[positive], ExponentialSpiral().radius(d[positive])
        )
        centre = before[0]
        for i in range(14):
            expected = centre + r[i] * rotation_matrix(n, theta[i]) @ (
                before[i + 1] - centre
            )
            np.testing.assert_allclose(rec.batches[-1][i], expected, rtol=0, atol=1e-12)


def test_centre_is_not_reevaluated_and_nfev_counts_calls():
    rec = Recorder(sphere)
    res = minimize(
        rec, [(-1, 1)] * 3, "ebsda", n_points=9, max_iter=17, rng=2, vectorized=True
    )
    assert [len(b) for b in rec.batches] == [9] + [8] * 17
    assert res.nfev == rec.count == 9 + 17 * 8
    assert res.nit == 17 and res.history.shape == (18,)
    assert res.mean_radius.shape == res.mean_angle.shape == (17,)


@settings(max_examples=25, deadline=None)
@given(
    fseed=st.integers(0, 2**32 - 1),
    seed=st.integers(0, 2**32 - 1),
    method=st.sampled_from(["sda", "ebsda", "lasda"]),
    nan_fraction=st.sampled_from([0.0, 0.3, 1.0]),
)
def test_best_never_increases_and_is_best_seen(fseed, seed, method, nan_fraction):
    g = np.random.default_rng(fseed)
    n = int(g.integers(1, 6))
    a = g.uniform(0.1, 10, n)
    b = g.uniform(-1, 1, n)
    w = g.normal(size=n) * 5
    amp = g.uniform(0, 3)
    thr = 1.0 - 2.0 * nan_fraction

    def fun(X):
        f = ((X - b) ** 2 * a).sum(axis=1) + amp * np.sin(X @ w)
        return np.where(X[:, 0] > thr, np.nan, f)

    rec = Recorder(fun)
    res = minimize(
        rec, [(-1, 1)] * n, method, n_points=8, max_iter=25, rng=seed, vectorized=True
    )
    h = res.history
    assert np.all(h[1:] <= h[:-1])
    # Independent bookkeeping: the best finite cost seen after each iteration.
    seen = [c[np.isfinite(c)] for c in rec.costs]
    best = np.minimum.accumulate([c.min() if c.size else np.inf for c in seen])
    np.testing.assert_array_equal(h, best)
    if np.isfinite(h[-1]):
        assert res.fun == h[-1]
        # (BLAS may round X @ w differently for a one-row batch.)
        assert fun(res.x[None, :])[0] == pytest.approx(res.fun, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("method", ["sda", "ebsda", "lasda"])
def test_same_seed_bit_for_bit(method):
    kw = dict(n_points=20, max_iter=60, vectorized=True)
    a = minimize(sphere, [(-5, 5)] * 6, method, rng=11, **kw)
    b = minimize(sphere, [(-5, 5)] * 6, method, rng=np.random.default_rng(11), **kw)
    c = minimize(sphere, [(-5, 5)] * 6, method, rng=12, **kw)
    for field in ("x", "history", "mean_radius", "mean_angle"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert a.fun == b.fun and a.nfev == b.nfev
    assert not np.array_equal(a.x, c.x)


@pytest.mark.parametrize("method", ["sda", "ebsda", "lasda"])
def test_per_point_and_vectorised_identical(method):
    def rastrigin(x):
        return 10.0 * x.shape[-1] + np.sum(
            x * x - 10.0 * np.cos(2 * np.pi * x), axis=-1
        )

    kw = dict(n_points=15, max_iter=80, rng=5)
    a = minimize(rastrigin, [(-5.12, 5.12)] * 4, method, vectorized=True, **kw)
    b = minimize(lambda x: float(rastrigin(x)), [(-5.12, 5.12)] * 4, method, **kw)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.history, b.history)


def test_per_point_and_vectorised_identical_with_zero_deviation_draws():
    # A plateau (cost 0 inside the unit ball) makes many d exactly 0, so
    # Eb-SDA draws radii and angles from rng every iteration.
    def plateau(x):
        return np.maximum(np.sum(x * x, axis=-1) - 1.0, 0.0)

    rule = RecordingRule(ExponentialSpiral())
    kw = dict(n_points=12, max_iter=40, rng=8)
    a = minimize(plateau, [(-2, 2)] * 3, rule, vectorized=True, **kw)
    b = minimize(lambda x: float(plateau(x)), [(-2, 2)] * 3, "ebsda", **kw)
    assert sum(int(np.sum(d == 0)) for d, _, _ in rule.calls) > 50
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.mean_radius, b.mean_radius)
    np.testing.assert_array_equal(a.mean_angle, b.mean_angle)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_2d_sphere_sda_default_budget(seed):
    res = minimize(sphere, [(-5, 5)] * 2, "sda", rng=seed, vectorized=True)
    assert res.success and res.nit == 500
    assert res.fun < 1e-12


# Issue 2 asks both methods to reach 1e-12 on the 2-D sphere within the
# default budget. Eb-SDA with the paper's constants does not: a point whose
# cost is close to the centre's (d -> 0) keeps r -> 1 - 0.9 / 101 ~ 0.991, so
# near the optimum, where every d is tiny, the swarm contracts by under 1 %
# per iteration. Measured over seeds 0-19 on [-5, 5]^2 (m = 50, 500
# iterations): final cost 1.5e-9 .. 8.3e-7, median 8.8e-8; 1e-12 is reached
# after 916 .. 1259 iterations. The constants are the paper's and are not
# retuned; the strict xfail below records the unmet item and fails the suite
# if it ever starts to pass, so this note cannot go stale silently.
@pytest.mark.xfail(
    strict=True,
    reason="issue 2 acceptance item not met by Eb-SDA with the paper's "
    "constants: 1.5e-9..8.3e-7 after 500 iterations",
)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_2d_sphere_ebsda_default_budget_below_1e12(seed):
    res = minimize(sphere, [(-5, 5)] * 2, "ebsda", rng=seed, vectorized=True)
    assert res.fun < 1e-12


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_2d_sphere_ebsda(seed):
    # What Eb-SDA does reach (see the note above): below 1e-6 in the default
    # budget (these seeds: 2.8e-8, 1.1e-7, 3.1e-8), below 1e-12 within 1500
    # iterations (these seeds: 1063, 1157, 1080).
    res = minimize(sphere, [(-5, 5)] * 2, "ebsda", rng=seed, vectorized=True)
    assert res.success and res.nit == 500 and res.fun < 1e-6
    res = minimize(
        sphere, [(-5, 5)] * 2, "ebsda", rng=seed, vectorized=True, max_iter=1500
    )
    assert res.fun < 1e-12


def test_bounds_forms_agree():
    lo, hi = np.array([-1.0, -2.0, 0.0]), np.array([1.0, 3.0, 0.5])
    forms = [list(zip(lo, hi, strict=True)), np.column_stack([lo, hi]), Bounds(lo, hi)]
    results = [minimize(sphere, f, n_points=6, max_iter=5, rng=3) for f in forms]
    for r in results[1:]:
        np.testing.assert_array_equal(r.x, results[0].x)


def test_initial_points_uniform_in_bounds():
    rec = Recorder(sphere)
    SpiralSearch(
        rec, [(2, 3), (-10, -9.5)], "sda", n_points=500, rng=0, vectorized=True
    )
    pts = rec.batches[0]
    assert np.all(pts[:, 0] >= 2) and np.all(pts[:, 0] < 3)
    assert np.all(pts[:, 1] >= -10) and np.all(pts[:, 1] < -9.5)
    # Means of U(2, 3) and U(-10, -9.5): 5 standard errors tolerance.
    assert abs(pts[:, 0].mean() - 2.5) < 5 * 1.0 / np.sqrt(12 * 500)
    assert abs(pts[:, 1].mean() + 9.75) < 5 * 0.5 / np.sqrt(12 * 500)


def test_x0_seeds_first_points():
    rec = Recorder(sphere)
    x0 = np.array([[0.1, 0.2], [0.3, -0.4], [-0.5, 0.6]])
    minimize(rec, [(-1, 1)] * 2, n_points=5, max_iter=1, rng=0, vectorized=True, x0=x0)
    np.testing.assert_array_equal(rec.batches[0][:3], x0)
    rec1 = Recorder(sphere)
    minimize(
        rec1, [(-1, 1)] * 2, n_points=5, max_iter=1, rng=0, vectorized=True, x0=x0[0]
    )
    np.testing.assert_array_equal(rec1.batches[0][0], x0[0])
    # A full population consumes no initial draws.
    full = np.random.default_rng(9).uniform(-1, 1, (5, 2))
    rec2 = Recorder(sphere)
    minimize(
        rec2, [(-1, 1)] * 2, n_points=5, max_iter=1, rng=0, vectorized=True, x0=full
    )
    np.testing.assert_array_equal(rec2.batches[0], full)


def test_max_nfev_budget():
    rec = Recorder(sphere)
    res = minimize(
        rec,
        [(-1, 1)] * 2,
        n_points=10,
        max_iter=10_000,
        max_nfev=100,
        rng=0,
        vectorized=True,
    )
    # 10 + 10 * 9 = 100 fits; one more iteration would need 109.
    assert res.nit == 10 and res.nfev == rec.count == 100
    assert res.message.startswith("Maximum number of function evaluations reached.")
    assert res.success


def test_target_stops_early():
    res = minimize(
        sphere, [(-5, 5)] * 2, "sda", rng=0, vectorized=True, options={"target": 1e-3}
    )
    assert res.success and res.fun <= 1e-3 and res.history[-2] > 1e-3
    assert res.nit < 500 and res.message == "Target cost reached."
    missed = minimize(
        sphere,
        [(-5, 5)] * 2,
        "sda",
        rng=0,
        vectorized=True,
        max_iter=2,
        options={"target": -1.0},
    )
    assert not missed.success and "target cost was not reached" in missed.message


def test_callback_receives_results_and_stops():
    seen = []

    def cb(intermediate):
        assert isinstance(intermediate, OptimiserResult)
        seen.append((intermediate.nit, intermediate.fun, len(intermediate.history)))
        return intermediate.nit == 7

    res = minimize(sphere, [(-5, 5)] * 3, rng=0, vectorized=True, callback=cb)
    assert [s[0] for s in seen] == list(range(1, 8))
    assert [s[2] for s in seen] == list(range(2, 9))
    assert res.nit == 7 and not res.success
    assert res.message == "The callback requested a stop."


def test_the_callback_may_move_the_centre_of_the_search_it_is_given():
    # One hook: the intermediate result carries the live search, so a
    # callback can polish the centre (the memetic search does) and the
    # evaluations it reports count toward the budget.
    moved = []

    def polish(intermediate):
        search = intermediate.search
        assert intermediate.nit == search.nit
        if search.nit == 3:
            moved.append(search.move_centre(np.zeros(2), 0.0, nfev=5))

    res = minimize(
        sphere,
        [(-5, 5)] * 2,
        "sda",
        rng=0,
        vectorized=True,
        max_iter=4,
        callback=polish,
    )
    assert moved == [True] and res.fun == 0.0
    assert res.nfev == 50 + 4 * 49 + 5


def test_an_unknown_keyword_is_python_s_one_line_type_error():
    # The settings of `options` are keys of that mapping, not keywords.
    for name in ("callbak", "max_time", "target", "bounds_policy"):
        with pytest.raises(TypeError) as refused:
            minimize(sphere, [(-5, 5)] * 2, **{name: None})
        assert str(refused.value) == (
            f"minimize() got an unexpected keyword argument {name!r}"
        )


def test_callback_sees_the_iteration_that_reaches_the_target():
    # Callers time-stamp `history` from the callback: one call per iteration.
    seen = []
    res = minimize(
        sphere,
        [(-5, 5)] * 2,
        "sda",
        rng=0,
        vectorized=True,
        options={"target": 1e-3},
        callback=lambda r: seen.append(r.fun) or True,
    )
    # The callback asked to stop after the first iteration, target unmet.
    assert len(seen) == 1 and res.nit == 1 and not res.success
    assert res.message.startswith("The callback requested a stop.")
    seen.clear()
    res = minimize(
        sphere,
        [(-5, 5)] * 2,
        "sda",
        rng=0,
        vectorized=True,
        options={"target": 1e-3},
        callback=lambda r: seen.append(r.fun),
    )
    assert res.message == "Target cost reached."
    assert len(seen) == res.nit == len(res.history) - 1
    np.testing.assert_array_equal(seen, res.history[1:])
    # Target met in the very iteration the callback asks to stop: target wins.
    kw = dict(n_points=10, rng=0, vectorized=True)
    h = minimize(sphere, [(-5, 5)] * 2, "sda", max_iter=1, **kw).history
    assert h[1] < h[0]
    both = minimize(
        sphere,
        [(-5, 5)] * 2,
        "sda",
        options={"target": h[1]},
        callback=lambda r: True,
        **kw,
    )
    assert both.nit == 1 and both.success and both.message == "Target cost reached."


@pytest.mark.parametrize("method", ["sda", "ebsda"])
def test_all_initial_costs_nonfinite_then_recovers(method):
    x0 = np.random.default_rng(0).uniform(0.3, 1.0, (10, 2))

    def fun(X):
        # Finite only in a small punctured disc around the first point, which
        # serves as centre while every cost is NaN; the others spiral into it.
        dist = np.linalg.norm(X - x0[0], axis=1)
        return np.where((dist > 0) & (dist < 0.05), sphere(X), np.nan)

    assert np.all(np.isnan(fun(x0)))
    res = minimize(
        fun,
        [(-1, 1)] * 2,
        method,
        n_points=10,
        max_iter=100,
        rng=0,
        vectorized=True,
        x0=x0,
    )
    assert np.isinf(res.history[0])
    assert np.isfinite(res.fun) and res.success
    assert "Every initial cost was non-finite" in res.message


def test_never_finite():
    res = minimize(
        lambda X: np.full(len(X), np.inf),
        [(-1, 1)] * 2,
        n_points=4,
        max_iter=5,
        rng=0,
        vectorized=True,
    )
    assert res.nit == 5 and not res.success
    assert np.all(np.isinf(res.history))
    assert "No finite cost was found." in res.message


def test_nonfinite_never_becomes_centre_and_gets_lower_limits():
    def fun(X):
        f = sphere(X)
        f[X[:, 0] > 0.5] = -np.inf
        f[X[:, 1] > 0.5] = np.nan
        return f

    rule = RecordingRule(ExponentialSpiral())
    search = SpiralSearch(fun, [(-1, 1)] * 2, rule, n_points=20, rng=1, vectorized=True)
    infinite = 0
    for _ in range(30):
        costs = search.costs
        assert np.isfinite(costs[0]) and costs[0] == np.nanmin(
            costs[np.isfinite(costs)]
        )
        search.step()
        d, r, theta = rule.calls[-1]
        bad = ~np.isfinite(costs[1:])
        np.testing.assert_array_equal(np.isinf(d), bad)
        np.testing.assert_array_equal(r[bad], 0.1)
        np.testing.assert_array_equal(theta[bad], 0.1)
        infinite += bad.sum()
    assert infinite > 0 and search.fun >= 0


def _one_step_from(x0, policy):
    # theta = pi in 2-D is R = -I: the step reflects each point through the centre.
    rec = Recorder(sphere)
    minimize(
        rec,
        [(-1, 1)] * 2,
        ConstantSpiral(1.0, np.pi),
        n_points=2,
        max_iter=1,
        rng=0,
        vectorized=True,
        x0=x0,
        options={"bounds_policy": policy},
    )
    return rec.batches[1][0]


def test_bounds_policies_by_hand():
    # Costs 0.49 and 0.5: the centre is (0.7, 0); the mover goes to (1.9, 0.5).
    x0 = [[0.7, 0.0], [-0.5, -0.5]]
    np.testing.assert_allclose(_one_step_from(x0, "none"), [1.9, 0.5], atol=1e-15)
    np.testing.assert_allclose(_one_step_from(x0, "clip"), [1.0, 0.5], atol=1e-15)
    # 1.9 reflects off 1 to 0.1; 0.5 is inside and left untouched.
    np.testing.assert_allclose(_one_step_from(x0, "reflect"), [0.1, 0.5], atol=1e-14)


def test_reflect_unfolds_an_overshoot_of_several_widths():
    # A custom rule with r = 5 and theta = pi sends x to c - 5 (x - c):
    # (-0.95, -0.95) about c = (0.9, 0) lands at (10.15, 4.75). Bouncing
    # between -1 and 1 by hand: 10.15 -> -8.15 -> 6.15 -> -4.15 -> 2.15
    # -> -0.15, and 4.75 -> -2.75 -> 0.75.
    rec = Recorder(sphere)
    minimize(
        rec,
        B2,
        _Returns((5.0, np.pi)),
        n_points=2,
        max_iter=1,
        vectorized=True,
        x0=[[0.9, 0.0], [-0.95, -0.95]],
        options={"bounds_policy": "reflect"},
    )
    np.testing.assert_allclose(rec.batches[1][0], [-0.15, 0.75], atol=1e-13)


def test_reflect_and_clip_keep_every_point_inside():
    for policy in ("clip", "reflect"):
        rec = Recorder(lambda X: np.sin(5 * X).sum(1))
        minimize(
            rec,
            [(-1, 2)] * 3,
            ConstantSpiral(1.0, 2.5),
            n_points=10,
            max_iter=30,
            rng=0,
            vectorized=True,
            options={"bounds_policy": policy},
        )
        pts = np.concatenate(rec.batches)
        assert pts.min() >= -1 and pts.max() <= 2


def test_search_is_an_iterator():
    search = SpiralSearch(sphere, [(-1, 1)] * 2, "sda", rng=0, vectorized=True)
    x, f = next(search)
    assert search.nit == 1 and f == search.fun and np.array_equal(x, search.x)
    res = search.result("max_iter")
    assert res.success and res.nit == 1 and res.history.shape == (2,)
    np.testing.assert_array_equal(res.mean_radius, [0.95])
    with pytest.raises(ValueError, match=r"^`status` must be one of .*got 'done'"):
        search.result("done")


B2 = [(-1, 1)] * 2


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (
            dict(bounds=[(1, 1), (0, 1)]),
            r"^`bounds` must have low < high .*dimension 0",
        ),
        (
            dict(bounds=[(0, 1), (2, -2)]),
            r"^`bounds` must have low < high .*dimension 1",
        ),
        (dict(bounds=[(0, np.nan)]), r"^`bounds` must be finite"),
        (dict(bounds=[(-np.inf, 0)]), r"^`bounds` must be finite"),
        (dict(bounds=[(-1e308, 1e308)]), r"^`bounds` must have a finite width"),
        (
            dict(bounds=[(0, 1, 2)]),
            r"^`bounds` must be a sequence .*got shape \(1, 3\)",
        ),
        (dict(bounds=[0, 1]), r"^`bounds` must be a sequence .*got shape \(2,\)"),
        (dict(bounds=[(0, 1), (0,)]), r"^`bounds` must be a sequence .*got \["),
        (dict(bounds=np.empty((0, 2))), r"^`bounds` must be a sequence .*\(0, 2\)"),
        (dict(bounds=Bounds(np.zeros((2, 2)), 1)), r"^`bounds` .*a Bounds needs 1-D"),
        (dict(bounds="ab"), r"^`bounds` must be a sequence"),
        (dict(n_points=1), r"^`n_points` must be an integer >= 2; got 1"),
        (dict(n_points=10.0), r"^`n_points` must be an integer >= 2; got 10\.0"),
        (dict(max_iter=0), r"^`max_iter` must be an integer >= 1; got 0"),
        (dict(max_nfev=5, n_points=6), r"^`max_nfev` must be an integer >= 6; got 5"),
        (dict(method="pso"), r"^`method` must be 'sda', .*got 'pso'"),
        (dict(method=ConstantSpiral), r"^`method` must be"),
        (
            dict(options={"bounds_policy": "wrap"}),
            r"^`bounds_policy` must be one of .*got 'wrap'",
        ),
        # An array would make `in` ambiguous (NumPy's own ValueError).
        (
            dict(options={"bounds_policy": np.array(["clip", "none"])}),
            r"^`bounds_policy` must be one of",
        ),
        (dict(options={"target": np.nan}), r"^`target` must be a real number or None"),
        (
            dict(options={"tagret": 1.0}),
            r"^`tagret` does not apply to the options of minimize\(\); the options "
            "that do: max_time, target, bounds_policy$",
        ),
        (dict(options=[("target", 1.0)]), r"^`options` must be a mapping of max_time"),
        (dict(callback=3), r"^`callback` must be callable or None; got 3"),
        (dict(fun=3), r"^`fun` must be callable; got 3"),
        (dict(x0=[0.0, 0.0, 0.0]), r"^`x0` must have shape \(2,\) or \(k, 2\).*\(3,\)"),
        (dict(x0=np.zeros((4, 2)), n_points=3), r"^`x0` must have shape .*n_points=3"),
        (dict(x0=[[0.5, 2.0]]), r"^`x0` must lie within `bounds`.*row 0"),
        (dict(x0=[np.nan, 0.0]), r"^`x0` must be finite"),
        (dict(rng="seed"), r"^`rng` must be None, a non-negative integer.*'seed'"),
        (dict(rng=1.5), r"^`rng` must be None, a non-negative integer.*1\.5"),
        (dict(rng=-1), r"^`rng` must be None, a non-negative integer.*-1"),
        # bool("no") is True: a string must not switch on batch evaluation.
        (dict(vectorized="no"), r"^`vectorized` must be True or False; got 'no'"),
    ],
)
def test_bad_input(kwargs, match):
    args = dict(fun=lambda x: float(x @ x), bounds=B2)
    args.update(kwargs)
    with pytest.raises((TypeError, ValueError), match=match):
        minimize(args.pop("fun"), args.pop("bounds"), **args)


def test_constant_radius_outside_range():
    with pytest.raises(ValueError, match=r"^`radius` must be in \(0, 1\]; got 1\.1"):
        minimize(sphere, B2, ConstantSpiral(radius=1.1))


def test_objective_wrong_shape():
    with pytest.raises(
        ValueError, match=r"^`fun` must return shape \(4,\) .*got shape \(4, 1\)"
    ):
        minimize(lambda X: sphere(X)[:, None], B2, n_points=4, vectorized=True)
    with pytest.raises(
        ValueError, match=r"^`fun` must return a scalar .*got shape \(2,\)"
    ):
        minimize(lambda x: x, B2, n_points=4)
    with pytest.raises(ValueError, match=r"^`fun` must return real numbers; got 'a'"):
        minimize(lambda x: "a", B2, n_points=4)
    # None would otherwise become NaN and rank worst without a word.
    with pytest.raises(ValueError, match=r"^`fun` must return real numbers; got None"):
        minimize(lambda x: None, B2, n_points=4)
    with pytest.raises(ValueError, match=r"^`fun` must return real numbers; got \["):
        minimize(lambda X: [None] * len(X), B2, n_points=4, vectorized=True)
    with pytest.raises(ValueError, match=r"^`fun` must return real numbers; got 1j"):
        minimize(lambda x: 1j, B2, n_points=4)
    # A shape error later in the run (not only on the initial batch) is caught too.
    calls = []

    def late(X):
        calls.append(1)
        return sphere(X) if len(calls) < 3 else sphere(X)[:-1]

    with pytest.raises(ValueError, match=r"^`fun` must return shape \(3,\)"):
        minimize(late, B2, n_points=4, vectorized=True)


def test_costs_of_opposite_sign_beyond_float_range():
    # |1e308 - (-1e308)| overflows: the deviation must be inf, silently.
    rule = RecordingRule(ExponentialSpiral())
    x0 = np.array([[0.0, 0.0], [0.5, 0.5], [-0.5, 0.5]])

    def fun(X):
        return np.where(X[:, 0] == 0.0, -1e308, 1e308)

    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        search = SpiralSearch(fun, B2, rule, n_points=3, rng=0, vectorized=True, x0=x0)
        search.step()
    d, r, theta = rule.calls[0]
    np.testing.assert_array_equal(d, [np.inf, np.inf])
    np.testing.assert_array_equal(r, [0.1, 0.1])
    np.testing.assert_array_equal(theta, [0.1, 0.1])


class _HalfTurn(SpiralRule):
    """Scalar radius, one angle per point (mixed outputs are allowed)."""

    def __init__(self, shape=None):
        self.shape = shape

    def __call__(self, d, rng):
        return 0.5, np.full(self.shape or d.shape, np.pi)


def test_custom_rule_mixed_scalar_and_per_point():
    # R(pi) = -I in 2-D: every point goes to x* - 0.5 (x - x*).
    rec = Recorder(sphere)
    search = SpiralSearch(rec, B2, _HalfTurn(), n_points=4, rng=0, vectorized=True)
    before = search.population
    search.step()
    expected = before[0] - 0.5 * (before[1:] - before[0])
    np.testing.assert_allclose(rec.batches[-1], expected, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(search.mean_radius, [0.5])
    np.testing.assert_array_equal(search.mean_angle, [np.pi])


def test_custom_rule_wrong_shape():
    with pytest.raises(ValueError, match=r"^`method` rule must return .*\(3,\); got"):
        SpiralSearch(sphere, B2, _HalfTurn((2,)), n_points=4, vectorized=True).step()


class _Returns(SpiralRule):
    def __init__(self, out):
        self.out = out

    def __call__(self, d, rng):
        return self.out


@pytest.mark.parametrize(
    ("out", "match"),
    [
        (0.5, r"must return \(radius, angle\).*got 0\.5"),
        (None, r"must return \(radius, angle\).*got None"),
        ((0.5, 0.1, 0.2), r"must return \(radius, angle\)"),
        (("a", 0.1), r"^`method` must be an array of real numbers; got 'a'"),
        # A NaN radius would silently send every moving point to NaN.
        ((np.nan, 0.1), r"must return \(radius, angle\).*non-finite"),
        ((0.5, np.array([0.1, np.inf, 0.1])), r"non-finite"),
    ],
)
def test_custom_rule_bad_output(out, match):
    search = SpiralSearch(sphere, B2, _Returns(out), n_points=4, vectorized=True)
    with pytest.raises((TypeError, ValueError), match=match):
        search.step()
