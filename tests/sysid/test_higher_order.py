"""The Billings-Voon correlation tests."""

import numpy as np
import pytest

from spiralid.sysid import billings_voon


def _r(a, b, k):
    """Hand formula: sum_t a(t) b(t-k) / sqrt(sum a^2 sum b^2), means removed."""
    a = a - a.mean()
    b = b - b.mean()
    n = a.size
    s = sum(a[t] * b[t - k] for t in range(max(k, 0), min(n, n + k)))
    return s / np.sqrt(np.sum(a * a) * np.sum(b * b))


def test_values_against_hand_computation():
    u = np.array([0.5, -1.0, 2.0, 0.0, 1.5, -0.5, 1.0, -2.0, 0.3, 0.8])
    e = np.array([0.1, 0.4, -0.3, 0.2, -0.6, 0.5, 0.0, -0.1, 0.3, -0.2])
    bv = billings_voon(u, e, lags=3)
    t = bv.tests
    np.testing.assert_allclose(t["ee"].values, [_r(e, e, k) for k in (1, 2, 3)])
    np.testing.assert_allclose(t["ue"].values, [_r(e, u, k) for k in range(-3, 4)])
    ec, uc = e - e.mean(), u - u.mean()
    np.testing.assert_allclose(
        t["e(eu)"].values, [_r(ec, ec * uc, k) for k in (1, 2, 3)]
    )
    u2 = u**2 - np.mean(u**2)
    np.testing.assert_allclose(t["u2e"].values, [_r(e, u2, k) for k in range(-3, 4)])
    np.testing.assert_allclose(
        t["u2e2"].values, [_r(ec**2, u2, k) for k in range(-3, 4)]
    )
    assert t["ee"].bands[0.95] == pytest.approx(1.959964 / np.sqrt(10), rel=1e-6)
    # Ljung-Box by hand for the autocorrelation.
    r = t["ee"].values
    q = 10 * 12 * np.sum(r**2 / (10 - np.arange(1, 4)))
    assert t["ee"].statistic == pytest.approx(q)


def test_false_alarm_rate_on_white_noise_is_near_five_percent():
    rng = np.random.default_rng(11)
    trials = 300
    rejected = dict.fromkeys(("ee", "ue", "e(eu)", "u2e", "u2e2"), 0)
    for _ in range(trials):
        u, e = rng.standard_normal(1000), rng.standard_normal(1000)
        for name, ok in billings_voon(u, e, lags=10).passed.items():
            rejected[name] += not ok
    for name, count in rejected.items():
        # 5 % of 300 is 15; the binomial's 99.9 % range is about 5..29.
        assert 4 <= count <= 30, (name, count)


def test_nonlinear_residual_fails_the_higher_order_tests_only():
    rng = np.random.default_rng(5)
    u = rng.standard_normal(3000)
    e = rng.standard_normal(3000) + 0.6 * (np.r_[0.0, u[:-1]] ** 2 - 1.0)
    bv = billings_voon(u, e)
    assert bv.passed["ee"] and bv.passed["ue"]
    assert not bv.passed["u2e"]
    assert bv.n_passed < 5 and "u2e-" in bv.verdicts()


def test_bad_arguments():
    with pytest.raises(ValueError, match="`lags` must be"):
        billings_voon(np.ones(10), np.ones(10), lags=10)
    with pytest.raises(ValueError):
        billings_voon(np.ones(10), np.ones(9))
