"""Rank-sum, A12 and Holm against their definitions and SciPy."""

import itertools

import numpy as np
import pytest
from scipy import stats

from spiralid.study import a12, holm, rank_sum


def test_a12_is_the_pairwise_win_frequency():
    rng = np.random.default_rng(1)
    x, y = rng.integers(0, 5, 7), rng.integers(0, 5, 9)
    wins = sum((a < b) + 0.5 * (a == b) for a, b in itertools.product(x, y))
    assert a12(x, y) == pytest.approx(wins / (x.size * y.size), abs=1e-15)
    assert a12(x, y) + a12(y, x) == pytest.approx(1.0)


def test_a12_relates_to_mann_whitney_u():
    # U of y over x counts the pairs where y > x: A12(x, y) = U_y / (n m).
    rng = np.random.default_rng(2)
    x, y = rng.normal(size=8), rng.normal(size=11)
    u_y = stats.mannwhitneyu(y, x).statistic
    assert a12(x, y) == pytest.approx(u_y / (x.size * y.size))


def test_holm_hand_worked():
    # Sorted 0.01, 0.02, 0.03, 0.5 times 4, 3, 2, 1: 0.04, 0.06, 0.06, 0.5.
    out = holm([0.03, 0.5, 0.01, 0.02])
    np.testing.assert_allclose(out, [0.06, 0.5, 0.04, 0.06])
    assert holm([0.9, 0.8]).tolist() == [1.0, 1.0]


def test_holm_rejects_bad_pvalues():
    with pytest.raises(ValueError, match="pvalues"):
        holm([0.2, 1.5])


def test_rank_sum_matches_scipy_and_handles_all_equal():
    x, y = [1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.5]
    r = rank_sum(x, y)
    assert r["p_two_sided"] == stats.mannwhitneyu(x, y).pvalue
    assert r["a12"] == 1.0 and r["median_x"] == 2.5
    same = rank_sum([2.0, 2.0], [2.0, 2.0])
    assert same["p_two_sided"] == 1.0 and same["a12"] == 0.5


def test_rank_sum_rejects_nan():
    with pytest.raises(ValueError, match="`x`"):
        rank_sum([np.nan, 1.0], [1.0])
