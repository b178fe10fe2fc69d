"""Step-up / step-down (Levinson) recursions and the Schur-Cohn test vs numpy.roots."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spiralid.sysid import (
    fold_reflection,
    is_stable_polynomial,
    random_stable_polynomial,
    step_down,
    step_up,
)


def _max_root(a):
    return np.abs(np.roots(np.r_[1.0, a])).max()


def test_hand_worked_degree_two():
    # (1 + k1 z^-1)(...) : a1 = k1 (1 + k2), a2 = k2.
    k = np.array([0.5, -0.25])
    np.testing.assert_allclose(step_up(k), [0.5 * 0.75, -0.25])


@pytest.mark.parametrize(("n", "kmax"), [(1, 1), (2, 1), (5, 1), (8, 1), (12, 0.95)])
def test_step_up_gives_roots_inside_and_round_trips(n, kmax):
    # Step-down divides by 1 - k^2: for high degrees with |k| near 1 the
    # round trip loses digits (7e-8 at n = 12), hence kmax there.
    rng = np.random.default_rng(n)
    k = rng.uniform(-kmax, kmax, size=(300, n))
    a = step_up(k)
    assert all(_max_root(row) < 1.0 for row in a)
    np.testing.assert_allclose(step_down(a), k, rtol=0, atol=1e-10)


def test_step_down_of_polynomial_from_roots_inside():
    rng = np.random.default_rng(3)
    for _ in range(50):
        r = rng.uniform(0.05, 0.97, 4) * np.exp(1j * rng.uniform(0, np.pi, 4))
        a = np.real(np.poly(np.r_[r, np.conj(r)]))[1:]
        k = step_down(a)
        assert np.all(np.abs(k) < 1)
        np.testing.assert_allclose(step_up(k), a, atol=1e-10)


def test_schur_cohn_matches_numpy_roots():
    rng = np.random.default_rng(4)
    for n in (1, 2, 3, 8):
        # Stable polynomials scaled by random factors: both kinds, many near
        # the boundary.
        a = step_up(rng.uniform(-1, 1, size=(2000, n)))
        a *= rng.uniform(0.7, 1.3, size=(2000, 1)) ** np.arange(1, n + 1)
        expected = np.array([_max_root(row) < 1.0 for row in a])
        assert 0 < expected.sum() < expected.size  # both kinds present
        np.testing.assert_array_equal(is_stable_polynomial(a), expected)


def test_unit_circle_counts_as_unstable():
    w = 0.3
    assert not is_stable_polynomial([-2 * np.cos(w), 1.0])  # poles exactly on |z| = 1
    assert not is_stable_polynomial([-1.0])  # pole at z = 1
    assert is_stable_polynomial([-2 * 0.999 * np.cos(w), 0.999**2])
    assert not is_stable_polynomial([np.nan, 0.1])


def test_unstable_step_down_exposes_k_outside():
    a = np.real(np.poly([1.2, 0.5, -0.3]))[1:]
    k = step_down(a)
    assert np.any(np.abs(k[np.isfinite(k)]) >= 1)


def test_random_stable_polynomial_is_stable_and_reproducible():
    a = random_stable_polynomial(8, size=500, rng=7)
    assert a.shape == (500, 8)
    assert all(_max_root(row) < 1 for row in a)
    np.testing.assert_array_equal(a, random_stable_polynomial(8, size=500, rng=7))
    from math import comb

    bound = np.array([comb(8, i) for i in range(1, 9)])
    assert np.all(np.abs(a) <= bound)


def test_fold_reflection_stays_inside_without_nan():
    x = np.array([-1e9, -5.5, -1.0, -0.2, 0.0, 0.7, 1.0, 2.3, 1e12, np.inf, np.nan])
    k = fold_reflection(x)
    assert np.all(np.isfinite(k)) and np.all(np.abs(k) < 1)
    np.testing.assert_array_equal(k[[3, 4, 5]], x[[3, 4, 5]])
    np.testing.assert_allclose(fold_reflection([1.2, -1.2, 3.5]), [0.8, -0.8, -0.5])


def test_bad_shapes():
    with pytest.raises(
        ValueError, match=r"`k` must be a 1-D array .* got shape \(2, 2, 2\)"
    ):
        step_up(np.zeros((2, 2, 2)))
    with pytest.raises(ValueError, match="`n` must be a non-negative integer; got -1"):
        random_stable_polynomial(-1)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.floats(-0.99, 0.99, allow_nan=False, allow_subnormal=False),
        min_size=1,
        max_size=10,
    )
)
def test_round_trip_property(k):
    k = np.asarray(k)
    a = step_up(k)
    assert is_stable_polynomial(a)
    assert np.abs(np.roots(np.r_[1.0, a])).max() < 1.0
    # Each step-down stage divides by 1 - k_i^2, so rounding grows with the
    # product of those factors: the tolerance scales with that condition.
    condition = np.prod(1.0 / (1.0 - k**2))
    np.testing.assert_allclose(step_down(a), k, rtol=0, atol=1e-12 * condition)
