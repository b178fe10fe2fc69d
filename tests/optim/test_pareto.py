"""The multi-objective spiral search and its building blocks, against brute
force, inclusion-exclusion and a known front."""

from itertools import combinations
from math import prod

import numpy as np
import pytest

from spiralid.optim import (
    LearnedMetricSpiral,
    hypervolume,
    minimize_pareto,
    non_dominated,
    thin_front,
)
from spiralid.optim.pareto import weight_vectors


def _brute_non_dominated(f):
    keep = []
    for i, a in enumerate(f):
        dominated = any(
            np.all(b <= a) and np.any(b < a) for j, b in enumerate(f) if j != i
        )
        twin = any(np.array_equal(b, a) for b in f[:i])
        keep.append(not dominated and not twin)
    return np.array(keep)


def _inclusion_exclusion(f, ref):
    total = 0.0
    for size in range(1, len(f) + 1):
        for subset in combinations(range(len(f)), size):
            corner = f[list(subset)].max(axis=0)
            total += (-1) ** (size + 1) * prod(np.maximum(ref - corner, 0.0))
    return total


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("k", [2, 3])
def test_non_dominated_filter_against_brute_force(seed, k):
    rng = np.random.default_rng(seed)
    # Small integers: many ties and exact duplicates.
    f = rng.integers(0, 4, size=(40, k)).astype(float)
    np.testing.assert_array_equal(non_dominated(f), _brute_non_dominated(f))


def test_hypervolume_hand_worked_cases():
    assert hypervolume([[1, 3], [2, 2], [3, 1]], [4, 4]) == 6.0
    assert hypervolume([[1, 1, 1]], [2, 2, 2]) == 1.0
    # Two boxes of volume 2 overlapping in a unit cube.
    assert hypervolume([[0, 1, 1], [1, 0, 1]], [2, 2, 2]) == 3.0
    assert hypervolume([[5, 5]], [4, 4]) == 0.0  # beyond the reference


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("k", [2, 3])
def test_hypervolume_against_inclusion_exclusion(seed, k):
    rng = np.random.default_rng(seed)
    f = rng.uniform(0.0, 1.0, size=(7, k))
    ref = np.full(k, 1.2)
    assert hypervolume(f, ref) == pytest.approx(_inclusion_exclusion(f, ref), 1e-12)


def test_weight_vectors_lie_on_the_simplex():
    for k, m in ((2, 11), (3, 100)):
        w = weight_vectors(k, m)
        assert w.shape[1] == k and w.shape[0] <= m
        np.testing.assert_allclose(w.sum(axis=1), 1.0)
        assert len({tuple(row) for row in w.round(12)}) == w.shape[0]
    assert weight_vectors(3, 100).shape[0] == 91  # H = 12: C(14, 2)


def _zdt1(x):
    f1 = x[:, 0]
    g = 1.0 + 9.0 * x[:, 1:].mean(axis=1)
    return np.column_stack([f1, g * (1.0 - np.sqrt(f1 / g))])


def _igd_plus(f, front):
    gap = np.maximum(f[None, :, :] - front[:, None, :], 0.0)
    return float(np.mean(np.min(np.linalg.norm(gap, axis=2), axis=1)))


def test_ebsda_approaches_the_zdt1_front():
    # ZDT1, 30 variables, 25,000 evaluations: measured IGD+ 0.05-0.11 over
    # seeds 0-2 (the true front's hypervolume from (1.1, 1.1) is 0.876).
    a = np.linspace(0.0, 1.0, 500)
    front = np.column_stack([a, 1.0 - np.sqrt(a)])
    res = minimize_pareto(
        _zdt1, [(0.0, 1.0)] * 30, "ebsda", n_points=100, max_nfev=25_000,
        rng=1, vectorized=True, options={"ref_point": [1.1, 1.1]},
    )  # fmt: skip
    assert _igd_plus(res.fun, front) < 0.2
    assert res.nfev <= 25_000 and res.status == 1
    assert np.all(non_dominated(res.fun))
    assert res.history[-1] > 2 * res.history[0]
    again = minimize_pareto(
        _zdt1, [(0.0, 1.0)] * 30, "ebsda", n_points=100, max_nfev=25_000,
        rng=1, vectorized=True, options={"ref_point": [1.1, 1.1]},
    )  # fmt: skip
    np.testing.assert_array_equal(res.x, again.x)


@pytest.mark.parametrize(
    "fun, match",
    [
        (lambda x: np.full((x.shape[0], 2), np.nan), "non-finite objective"),
        (lambda x: np.zeros((x.shape[0] - 1, 2)), r"must return \(1, k\)"),
        (lambda x: np.zeros((x.shape[0], 1)), "at least 2 objectives; got 1"),
    ],
)
def test_a_bad_objective_is_a_clear_error(fun, match):
    with pytest.raises(ValueError, match=match):
        minimize_pareto(fun, [(0, 1)] * 2, n_points=10, max_nfev=40, rng=0,
                        vectorized=True)  # fmt: skip


def test_the_default_rule_is_the_learned_metric_poll():
    # One named default (spiralid.choices) for minimize_pareto and
    # identify_pareto; the paper's Eb-SDA stays available by name.
    import inspect

    from spiralid.choices import DEFAULT_PARETO_METHOD
    from spiralid.optim import pareto
    from spiralid.sysid import identify_pareto

    assert DEFAULT_PARETO_METHOD == pareto.DEFAULT_PARETO_METHOD == "learned-metric"
    for fun in (minimize_pareto, identify_pareto):
        default = inspect.signature(fun).parameters["method"].default
        assert default is DEFAULT_PARETO_METHOD
    kw = dict(n_points=10, max_nfev=200, rng=0, vectorized=True)
    default = minimize_pareto(_zdt1, [(0, 1)] * 3, **kw)
    learned = minimize_pareto(_zdt1, [(0, 1)] * 3, "learned-metric", **kw)
    np.testing.assert_array_equal(default.x, learned.x)
    np.testing.assert_array_equal(default.history, learned.history)
    paper = minimize_pareto(_zdt1, [(0, 1)] * 3, "ebsda", **kw)
    assert paper.nit == 19 and default.nit == 9  # 1 and 2 points per subproblem


def test_the_budget_allows_the_initial_population_and_one_iteration():
    # A spiral rule evaluates a point per subproblem and iteration, the
    # learned-metric poll two: two populations, or three.
    kw = dict(n_points=10, rng=0, vectorized=True)
    assert minimize_pareto(_zdt1, [(0, 1)] * 2, "ebsda", max_nfev=20, **kw).nit == 1
    assert minimize_pareto(_zdt1, [(0, 1)] * 2, max_nfev=30, **kw).nit == 1
    with pytest.raises(ValueError, match=r"`max_nfev` must be an integer >= 30; "
                       r"got 29"):  # fmt: skip
        minimize_pareto(_zdt1, [(0, 1)] * 2, max_nfev=29, **kw)
    with pytest.raises(ValueError, match=r"`max_nfev` must be an integer >= 20"):
        minimize_pareto(_zdt1, [(0, 1)] * 2, "sda", max_nfev=19, **kw)


def test_step_rate_rules_are_refused():
    with pytest.raises(ValueError, match="`method` must be one of sda, ebsda"):
        minimize_pareto(_zdt1, [(0, 1)] * 2, "periodic", n_points=10, max_nfev=40)


def _later(bad):
    """An objective that turns bad after the first population (two calls:
    its first point, then the rest)."""
    calls = []

    def fun(x):
        calls.append(1)
        f = np.column_stack([x[:, 0], 1 - x[:, 0]])
        return bad(f) if len(calls) > 2 else f

    return fun


@pytest.mark.parametrize(
    "bad, match",
    [
        (lambda f: np.where(f > 0.5, np.nan, f), "non-finite objective"),
        # The default poll's iteration: two points for each of 10 subproblems.
        (lambda f: np.column_stack([f, f[:, :1]]), r"must return \(20, 2\)"),
        (lambda f: f[:, :1], r"must return \(20, 2\)"),
    ],
)
def test_an_objective_that_turns_bad_later_is_a_clear_error(bad, match):
    with pytest.raises(ValueError, match=match):
        minimize_pareto(_later(bad), [(0, 1)] * 2, n_points=10, max_nfev=40,
                        rng=0, vectorized=True)  # fmt: skip


def test_a_point_wise_objective_of_varying_length_is_a_clear_error():
    def fun(x):
        return [x[0], 1 - x[0]] if x[0] < 0.5 else [x[0], 1 - x[0], 0.0]

    with pytest.raises(ValueError, match="`fun` must return"):
        minimize_pareto(fun, [(0, 1)] * 2, n_points=10, max_nfev=40, rng=0)


def test_seed_points_take_the_first_places_of_the_population():
    seen = []

    def fun(x):
        seen.append(x.copy())
        return np.column_stack([x[:, 0], 1 - x[:, 0]])

    seeds = [[0.25, 0.5], [2.0, 0.5]]  # the second is clipped into the box
    minimize_pareto(fun, [(0, 1)] * 2, n_points=10, max_nfev=40, rng=0,
                    vectorized=True, x0=seeds)  # fmt: skip
    first = np.vstack(seen[:2])  # the first point, then the rest
    np.testing.assert_array_equal(first[:2], [[0.25, 0.5], [1.0, 0.5]])
    with pytest.raises(ValueError, match="`x0`"):
        minimize_pareto(fun, [(0, 1)] * 2, n_points=10, max_nfev=40,
                        vectorized=True, x0=[[0.1, 0.2, 0.3]])  # fmt: skip


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("k", [2, 3])
def test_hypervolume_against_moocore(seed, k):
    moocore = pytest.importorskip("moocore")
    rng = np.random.default_rng(seed)
    f = rng.uniform(0.0, 1.0, size=(600, k))
    f /= np.linalg.norm(f, axis=1, keepdims=True)  # a spherical front
    f[:100] = np.round(f[:100], 1)  # ties and duplicates
    ref = np.full(k, 1.1)
    assert hypervolume(f, ref) == pytest.approx(moocore.hypervolume(f, ref=ref), 1e-12)


def test_thin_front_keeps_the_extremes_and_spreads_the_rest():
    a = np.linspace(0.0, 1.0, 1001)
    line = np.column_stack([a, 1.0 - a])
    keep = thin_front(line, 11)
    assert keep.size == 11 and keep[0] == 0 and keep[-1] == 1000
    gaps = np.diff(line[keep, 0])
    # Even spacing would be 0.1; SPEA2's greedy truncation is uneven, but
    # never leaves a hole more than twice that or a pair closer than half.
    assert gaps.max() < 0.2 and gaps.min() > 0.05
    np.testing.assert_array_equal(thin_front(line[:5], 11), np.arange(5))
    with pytest.raises(ValueError, match="`size`"):
        thin_front(line, 0)


def test_the_archive_holds_exactly_the_non_dominated_evaluations():
    # Every evaluated vector is recorded; the archive (no thinning: the
    # front is smaller than n_points) must be their non-dominated set.
    seen = []

    def fun(x):
        f = np.round(_zdt1(x), 1)  # coarse values: ties and duplicates
        seen.append(f)
        return f

    res = minimize_pareto(fun, [(0.0, 1.0)] * 3, "ebsda", n_points=40,
                          max_nfev=2000, rng=0, vectorized=True)  # fmt: skip
    every = np.vstack(seen)
    front = every[non_dominated(every)]
    assert sorted(map(tuple, res.fun)) == sorted(map(tuple, front))


@pytest.mark.parametrize("method", ["ebsda", "learned-metric"])
def test_the_archive_is_thinned_to_n_points_and_barely_dominated(method):
    seen = []

    def fun(x):
        seen.append(_zdt1(x))
        return seen[-1]

    res = minimize_pareto(fun, [(0.0, 1.0)] * 10, method, n_points=30,
                          max_nfev=6000, rng=2, vectorized=True)  # fmt: skip
    every = np.vstack(seen)
    assert 2 <= res.fun.shape[0] <= 30 and np.all(non_dominated(res.fun))
    np.testing.assert_array_equal(res.fun, _zdt1(res.x))
    # A bounded archive deteriorates: a point thinned away no longer keeps
    # out a later one it dominates. The archive remembers the thinned points
    # for that (measured, seeds 0-3: 0 of 30 for Eb-SDA, 0-1 for the poll;
    # without the memory the poll's crossover pairs left 4-10 of 30).
    # Never more than a tenth of the front.
    dominated = np.any(
        np.all(every[:, None] <= res.fun[None], axis=2)
        & np.any(every[:, None] < res.fun[None], axis=2),
        axis=0,
    )
    assert dominated.mean() <= 0.1


@pytest.mark.parametrize("basis", [True, False])
def test_learned_metric_poll_reaches_zdt1(basis):
    # ZDT1, 30 variables, 25,000 evaluations: measured IGD+ 0.0027-0.0031
    # (NSGA-II of pymoo: 0.0035); the bar is 0.01.
    a = np.linspace(0.0, 1.0, 500)
    front = np.column_stack([a, 1.0 - np.sqrt(a)])
    rule = LearnedMetricSpiral(basis=basis)
    kwargs = dict(n_points=100, max_nfev=25_000, rng=0, vectorized=True)
    res = minimize_pareto(_zdt1, [(0.0, 1.0)] * 30, rule, **kwargs)
    assert _igd_plus(res.fun, front) < 0.01
    assert res.nfev <= 25_000 and res.fun.shape[0] <= 100
    again = minimize_pareto(_zdt1, [(0.0, 1.0)] * 30, rule, **kwargs)
    np.testing.assert_array_equal(res.x, again.x)


def test_learned_metric_poll_finds_the_segment_between_two_rotated_minima():
    # f_1, f_2: the same rotated quadratic (condition 1e4) about a and b.
    # The Pareto set is the segment [a, b] and the front
    # (t^2 c, (1 - t)^2 c), c = (a - b)^T H (a - b): analytic.
    n = 6
    q, _ = np.linalg.qr(np.random.default_rng(1).standard_normal((n, n)))
    h = q @ np.diag(10.0 ** np.linspace(0, 4, n)) @ q.T
    a, b = np.full(n, -1.0), np.full(n, 1.0)

    def fun(x):
        da, db = x - a, x - b
        return np.column_stack([np.einsum("ij,jk,ik->i", d, h, d) for d in (da, db)])

    c = (a - b) @ h @ (a - b)
    t = np.linspace(0.0, 1.0, 2001)
    front = np.column_stack([t**2 * c, (1 - t) ** 2 * c])
    res = minimize_pareto(fun, [(-5, 5)] * n, "learned-metric", n_points=50,
                          max_nfev=20_000, rng=0, vectorized=True)  # fmt: skip
    assert _igd_plus(res.fun, front) / c < 0.05
    # Each point's distance to the segment in the quadratic's own metric
    # (flat directions barely matter to either objective), relative to the
    # segment's length in it, sqrt(c).
    s = np.clip((res.x - a) @ h @ (b - a) / c, 0.0, 1.0)
    off = res.x - (a + s[:, None] * (b - a))
    assert np.median(np.sqrt(np.einsum("ij,jk,ik->i", off, h, off) / c)) < 0.05


def test_archive_must_be_a_bool():
    with pytest.raises(TypeError, match="`archive` must be True or False"):
        minimize_pareto(_zdt1, [(0, 1)] * 2, n_points=10, max_nfev=40, archive=1)


@pytest.mark.parametrize("option", ["populations", "model_step", "success_steps"])
def test_single_objective_options_of_the_learned_metric_rule_are_refused(option):
    rule = LearnedMetricSpiral(**{option: False})
    with pytest.raises(ValueError) as refused:
        minimize_pareto(_zdt1, [(0, 1)] * 2, rule, n_points=10, max_nfev=40)
    message = str(refused.value)
    assert message.startswith(f"`{option}` of LearnedMetricSpiral does not apply")
    assert (
        "minimize_pareto" in message and "basis, grow, shrink and crossover" in message
    )
    # The options that apply are taken, and a default passed by value is
    # the default.
    rule = LearnedMetricSpiral(basis=False, grow=3.0, **{option: True})
    minimize_pareto(_zdt1, [(0, 1)] * 2, rule, n_points=10, max_nfev=40, rng=0,
                    vectorized=True)  # fmt: skip


def test_arguments_and_the_objective_count_are_checked_before_spending():
    calls = []

    def four(x):
        calls.append(x)
        return [x[0], 1 - x[0], 0.0, 0.0]

    # The reference point tells the count before any evaluation.
    with pytest.raises(ValueError, match="`ref_point` must be a finite vector"):
        minimize_pareto(four, [(0, 1)] * 2, n_points=10, options={"ref_point": [1.0]})
    with pytest.raises(ValueError, match=r"`n_points` must be at least the number of "
                       r"objectives \(5, from `ref_point`\); got 4"):  # fmt: skip
        minimize_pareto(four, [(0, 1)] * 2, n_points=4,
                        options={"ref_point": [1.0] * 5})  # fmt: skip
    assert calls == []
    # Otherwise only fun's answer tells it: one point is spent.
    with pytest.raises(ValueError, match="must return 3 objectives, as `ref_point` "
                       "has; got 4"):  # fmt: skip
        minimize_pareto(four, [(0, 1)] * 2, n_points=10, max_nfev=40, rng=0,
                        options={"ref_point": [1.0] * 3})  # fmt: skip
    assert len(calls) == 1  # one point, not the whole population
    batches = []

    def five_batched(x):
        batches.append(x.shape[0])
        return np.zeros((x.shape[0], 5))

    with pytest.raises(ValueError, match=r"at least the number of objectives \(5, "
                       r"from `fun`'s first point\); got 4"):  # fmt: skip
        minimize_pareto(five_batched, [(0, 1)] * 2, n_points=4, max_nfev=400,
                        rng=0, vectorized=True)  # fmt: skip
    assert batches == [1]  # a batch of one point, not of the population
    with pytest.raises(ValueError, match="must return 3 objectives, as `ref_point` "
                       "has; got 2"):  # fmt: skip
        minimize_pareto(_zdt1, [(0, 1)] * 2, n_points=10, vectorized=True,
                        options={"ref_point": [1, 1, 1]})  # fmt: skip


def test_nfev_counts_every_evaluation_with_three_objectives():
    # 100 points draw 100 evaluations, for 91 subproblems.
    seen = []

    def three(x):
        seen.append(x.shape[0])
        return np.c_[x[:, 0], 1 - x[:, 0], x[:, 1]]

    res = minimize_pareto(three, [(0, 1)] * 3, n_points=100, max_nfev=400,
                          rng=0, vectorized=True)  # fmt: skip
    assert seen[:2] == [1, 99] and res.weights.shape[0] == 91
    assert res.nfev == sum(seen) <= 400
