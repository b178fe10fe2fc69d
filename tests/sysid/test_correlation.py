"""Residual correlation tests against hand computations and known answers."""

import numpy as np
import pytest
from scipy import signal, stats

from spiralid.sysid.validation.correlation import (
    correlation,
    independence_test,
    whiteness_test,
)


def ar1(rng, n, pole):
    return signal.lfilter([1.0], [1.0, -pole], rng.standard_normal(n))


def test_correlation_matches_numpy_correlate():
    rng = np.random.default_rng(1)
    a, b = rng.standard_normal(200), rng.standard_normal(200)
    r = correlation(a, b, 7)
    a0, b0 = a - a.mean(), b - b.mean()
    full = np.correlate(a0, b0, mode="full")  # index N-1 is lag 0
    expected = full[199 - 7 : 199 + 8] / np.sqrt(a0 @ a0 * (b0 @ b0))
    np.testing.assert_allclose(r, expected, rtol=1e-12, atol=1e-15)
    # positive lag relates a now to b in the past: a delayed copy peaks there
    d = np.r_[np.zeros(3), b[:-3]]
    assert np.argmax(correlation(d, b, 7)) == 7 + 3


def test_bands_are_z_over_sqrt_n():
    e = np.random.default_rng(0).standard_normal(400)
    t = whiteness_test(e, lags=10)
    assert t.bands[0.95] == pytest.approx(1.959964 / 20.0, rel=1e-6)
    assert t.bands[0.99] == pytest.approx(2.575829 / 20.0, rel=1e-6)
    assert t.n_outside[0.95] == np.sum(np.abs(t.values) > 1.959964 / 20.0)
    assert list(t.lags) == list(range(1, 11))


def test_whiteness_statistic_is_ljung_box_written_out():
    e = np.random.default_rng(2).standard_normal(300)
    t = whiteness_test(e, lags=12)
    n = e.size
    e0 = e - e.mean()
    r = np.array([e0[k:] @ e0[: n - k] for k in range(1, 13)]) / (e0 @ e0)
    q = n * (n + 2) * sum(r[k - 1] ** 2 / (n - k) for k in range(1, 13))
    assert t.statistic == pytest.approx(q, rel=1e-12)
    assert t.dof == 12
    assert t.p_value == pytest.approx(stats.chi2.sf(q, 12), rel=1e-12)
    assert t.passed[0.95] == (q <= stats.chi2.ppf(0.95, 12))


def test_white_noise_passes_in_most_of_20_seeds():
    passed = [
        whiteness_test(np.random.default_rng(s).standard_normal(1000)).passed[0.95]
        for s in range(20)
    ]
    assert sum(passed) >= 16


def test_whiteness_false_alarm_rate_is_near_five_percent():
    # 300 seeds: binomial sd of the rate is 1.3 %, window is about +-3.5 sd
    rate = np.mean(
        [
            whiteness_test(np.random.default_rng(s).standard_normal(800)).passed[0.95]
            for s in range(300)
        ]
    )
    assert 0.90 <= rate <= 0.995


def test_every_lag_inside_band_would_reject_white_noise_too_often():
    # Why the verdict is joint: with 25 lags the per-lag rule fails ~72 %.
    inside = [
        whiteness_test(np.random.default_rng(s).standard_normal(1000)).n_outside[0.95]
        == 0
        for s in range(100)
    ]
    assert np.mean(inside) < 0.5


def test_coloured_residual_fails_whiteness():
    for s in range(20):
        t = whiteness_test(ar1(np.random.default_rng(s), 1000, 0.9))
        assert not t.passed[0.95] and not t.passed[0.99]
        assert t.values[0] > 0.8  # r(1) of AR(1) is its pole


def test_cross_correlation_fails_when_residual_is_filtered_input():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(1000)
    e = signal.lfilter([0.0, 0.5, 0.3], [1.0], u) + 0.5 * rng.standard_normal(1000)
    t = independence_test(u, e)
    assert not t.passed[0.99]
    assert list(t.lags) == list(range(-25, 26))
    # the residual follows the input one and two samples later: lags +1, +2
    assert set(np.argsort(np.abs(t.values))[-2:] - 25) == {1, 2}


@pytest.mark.parametrize(
    ("u_pole", "e_pole"), [(0.0, 0.0), (0.9, 0.0), (0.9, 0.7)], ids=str
)
def test_cross_correlation_false_alarm_rate_with_coloured_signals(u_pole, e_pole):
    # Independent u and e: ~95 % pass even when both are coloured, because
    # the statistic uses Bartlett's covariance of the correlations.
    passes = []
    for s in range(150):
        rng = np.random.default_rng(s)
        u, e = ar1(rng, 800, u_pole), ar1(rng, 800, e_pole)
        passes.append(independence_test(u, e).passed[0.95])
    assert 0.88 <= np.mean(passes) <= 1.0


def test_constant_residual_gives_zero_correlation_and_a_verdict():
    t = whiteness_test(np.ones(100), lags=5)
    assert np.all(t.values == 0.0) and t.passed[0.99]


def test_a_test_without_degrees_of_freedom_has_no_verdict():
    """A constant input is uncorrelated with anything: nothing to test, so
    neither pass nor fail, where the statistic of 0 would read "pass"."""
    e = np.random.default_rng(3).standard_normal(300)
    t = independence_test(np.full(300, 2.0), e, lags=6)
    assert t.dof == 0 and not t.applicable
    assert t.passed == {0.95: None, 0.99: None}
    d = t.to_dict()
    assert d["applicable"] is False and d["passed"] == {"0.95": None, "0.99": None}


def test_an_ordinary_test_still_passes_or_fails_by_chi_square():
    """Applicable tests keep their chi-square verdicts, True or False."""
    rng = np.random.default_rng(4)
    u = rng.standard_normal(600)
    for e, expected in (
        (rng.standard_normal(600), True),
        (np.convolve(u, [0.0, 1.0, 0.5])[:600], False),
    ):
        t = independence_test(u, e, lags=8)
        assert t.applicable and t.dof > 0
        for lv in t.levels:
            crit = stats.chi2.ppf(lv, t.dof)
            assert t.passed[lv] is bool(t.statistic <= crit)
        assert t.passed[0.99] is expected
        assert t.to_dict()["applicable"] is True


def test_to_dict_is_json_safe():
    import json

    t = independence_test(np.arange(50.0) % 7, np.random.default_rng(0).random(50), 5)
    d = json.loads(json.dumps(t.to_dict()))
    assert d["kind"] == "cross-correlation" and len(d["values"]) == 11


@pytest.mark.parametrize("lags", [0, -1, 100, 150])
def test_bad_lags(lags):
    with pytest.raises(ValueError, match=r"`lags` must be in \[1, N - 1\]"):
        whiteness_test(np.zeros(100), lags=lags)


def test_bad_inputs():
    with pytest.raises(ValueError, match="`lags` must be an integer"):
        whiteness_test(np.zeros(100), lags=2.5)
    with pytest.raises(ValueError, match="`u` and `e` must have the same length"):
        independence_test(np.zeros(100), np.zeros(99))
    with pytest.raises(ValueError, match="`e` must be finite; got nan at sample 3"):
        whiteness_test([0.0, 1.0, 2.0, np.nan, 1.0, 0.0], lags=2)
    with pytest.raises(ValueError, match="`e` must be a 1-D signal"):
        whiteness_test(np.zeros((10, 2)), lags=2)
    with pytest.raises(ValueError, match="`levels` must be floats in"):
        whiteness_test(np.zeros(10), lags=2, levels=(95,))
    with pytest.raises(ValueError, match="`rtol` must be in"):
        independence_test(np.zeros(10), np.zeros(10), 2, rtol=0.0)


def test_cross_band_scale_matches_bartlett_for_two_ar1_signals():
    # sum_m rho_e(m) rho_u(m) = sum_m (0.9 * 0.7)^|m| = (1 + 0.63) / (1 - 0.63)
    rng = np.random.default_rng(5)
    u, e = ar1(rng, 20000, 0.9), ar1(rng, 20000, 0.7)
    t = independence_test(u, e)
    assert t.band_scale == pytest.approx(np.sqrt(1.63 / 0.37), rel=0.1)
    assert whiteness_test(e).band_scale == 1.0
    white = independence_test(rng.standard_normal(5000), rng.standard_normal(5000))
    assert white.band_scale == pytest.approx(1.0, abs=0.1)
